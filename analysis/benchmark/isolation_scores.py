"""An isolation table (:mod:`analysis.benchmark.isolation_answers`) scored: accuracy per task and wear level
under one rule, the cases decided, the confusion of true and named axis, Table 6.2's Markdown layout,
the CSV form of an imported dataset's table, and the isolators a short dataset starves."""

from __future__ import annotations

import numpy as np
import pandas as pd

from analysis import scoring
from analysis.benchmark.isolation_answers import LABELLED_WORN, motor_speed_coverage
from analysis.benchmark.tables import MEASURED_NEXT, TOO_FEW_CYCLES, UNDECIDED, axis_label, markdown
from analysis.benchmark.truth import NO_FAULT


def isolation_levels(table: pd.DataFrame, frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` (indexed by task and ``wear_pct``, as :func:`isolation_accuracy`) with its levels
    as ``faultgen bench-isolators`` prints them: 0 "no fault"; on an imported dataset the index
    level is ``logs`` and its cases "to first worn" (up to the first log labelled worn)."""
    frame = frame.rename(index={0.0: "no fault"}, level="wear_pct")
    if table.attrs.get("imported"):
        frame = frame.rename(index={LABELLED_WORN: "to first worn"}, level="wear_pct")
        frame.index = frame.index.set_names("logs", level="wear_pct")
    return frame


def isolation_csv(table: pd.DataFrame) -> pd.DataFrame:
    """An :func:`isolation_table` as its CSV holds it: on an imported dataset ``wear_pct`` becomes
    ``logs``, "no fault" or "to first worn" (no wear is measured)."""
    if not table.attrs.get("imported"):
        return table
    logs = np.where(table["wear_pct"] == 0, "no fault", "to first worn")
    return table.drop(columns="wear_pct").assign(logs=logs)[
        [*(c if c != "wear_pct" else "logs" for c in table.columns)]]


#: Cycles per run from which a silent isolator is the method's doing, not the dataset's: thesis
#: Table 6.2 shows the isolators 49 to 94 cycles (1 % to 15 % wear of exp4 over 100).
ENOUGH_CYCLES = 49


def starved_isolators(table: pd.DataFrame, share: float = 0.5) -> list[str]:
    """Isolators that named no axis (undecided or too few cycles) in at least ``share`` of the worn
    cases of an :func:`isolation_table` whose runs were shown fewer than :data:`ENOUGH_CYCLES`
    cycles: a sign the dataset records too few cycles for them. Empty when the runs were long."""
    if table["cycles"].max() >= ENOUGH_CYCLES:
        return []
    worn = table[table["worn_axis"] != NO_FAULT]
    silent = worn["predicted"].isin([UNDECIDED, TOO_FEW_CYCLES]).groupby(worn["isolator"], sort=False).mean()
    return [name for name, value in silent.items() if value >= share]


def table_axes(table: pd.DataFrame) -> int:
    """The most axes of a robot in an :func:`isolation_table` (its ``n_axes`` column; a table made
    before that column existed: six)."""
    return int(table["n_axes"].max()) if "n_axes" in table else 6


def isolation_confusion(table: pd.DataFrame) -> pd.DataFrame:
    """Counts of true axis (rows: none, 1..N) against named axis (columns: undecided, 1..N, too
    few cycles) per isolator, over every run and level of an :func:`isolation_table` (N the most
    axes of its robots).

    Returns
    -------
    DataFrame indexed by (isolator, true axis), one column per answer, integer counts; labels as
    :func:`axis_label` prints them, with "none" for the true axis of a run without wear.
    """
    n_axes = table_axes(table)
    answers = [UNDECIDED, *range(1, n_axes + 1), TOO_FEW_CYCLES]
    counts = (table.groupby(["isolator", "worn_axis", "predicted"]).size().unstack("predicted")
              .reindex(columns=answers, fill_value=0).fillna(0).astype(int))
    isolators = list(dict.fromkeys(table["isolator"]))
    counts = counts.reindex(pd.MultiIndex.from_product([isolators, range(n_axes + 1)]), fill_value=0)
    counts.index = counts.index.set_names(["isolator", "true axis"]).set_levels(
        ["none", *map(str, range(1, n_axes + 1))], level=1)
    counts.columns = [axis_label(a) for a in answers]
    return counts


def isolation_accuracy(table: pd.DataFrame) -> pd.DataFrame:
    """Accuracy in percent per task and wear level (rows) and isolator (columns), Table 6.2.

    One rule everywhere: a case the isolator ran on is right when it names the worn axis, or, on a
    run without wear, when it names none (undecided); so an isolator that runs and never decides
    scores 100 % on "no fault" and 0 % elsewhere. A case it could not run on (fewer cycles than it
    needs: predicted -1) is not applicable and left out; a cell with no applicable case is NaN,
    which :func:`isolation_accuracy_text` spells "not applicable: N cycles < M needed". Each cell is
    :func:`analysis.scoring.top1_accuracy` under :data:`analysis.scoring.ISOLATION_TABLE_RULES`, the
    figure ``bench score``'s top-1 accuracy is (there a unit too short is undecided)."""
    groups = table.groupby(["task", "wear_pct", "isolator"])[["predicted", "worn_axis"]]
    rules = scoring.ISOLATION_TABLE_RULES
    cells = groups.apply(lambda g: scoring.top1_accuracy(g["predicted"], g["worn_axis"], rules))
    accuracy = (cells.dropna().mul(100)
                .reindex(pd.MultiIndex.from_frame(table[["task", "wear_pct", "isolator"]].drop_duplicates()))
                .unstack("isolator"))
    return accuracy.sort_index().astype(float).round(1)


def isolation_accuracy_text(table: pd.DataFrame) -> pd.DataFrame:
    """:func:`isolation_accuracy` as text: each cell its percentage, or where no case was
    applicable "not applicable: N cycles < M needed" (N the most cycles its cases saw, M the
    isolator's need)."""
    accuracy = isolation_accuracy(table)
    seen = table.groupby(["task", "wear_pct", "isolator"])[["cycles", "needed"]].max()
    out = accuracy.astype(object)
    for key in accuracy.index:
        for name in accuracy.columns:
            value = accuracy.loc[key, name]
            if np.isnan(value):
                cycles, need = seen.loc[(*key, name)]
                out.loc[key, name] = (f"not applicable: {int(cycles)} cycles < {int(need)} needed" if np.isfinite(need)
                                      else f"not applicable: {int(cycles)} cycles too few")
            else:
                out.loc[key, name] = f"{value:.1f}"
    return out


def isolation_decided(table: pd.DataFrame) -> pd.DataFrame:
    """Share of cases in which each isolator named an axis (right or wrong), %, per task and wear
    level (rows; "no fault": runs without wear) and isolator (columns). An isolator that never
    decides scores 100 % on the "no fault" rows of :func:`isolation_accuracy` and 0 % on the
    others; this table says so."""
    named = ~table["predicted"].isin([UNDECIDED, TOO_FEW_CYCLES])
    decided = named.groupby([table["task"], table["wear_pct"], table["isolator"]]).mean().mul(100).unstack("isolator")
    return decided.round(1)


def isolation_markdown(table: pd.DataFrame, marked: str | None = None) -> str:
    """Table 6.2 layout: per task and wear level, a mark per source axis for ``marked`` (default:
    ``te10``, as the thesis, else the first isolator), then the accuracy of every isolator."""
    isolators = list(dict.fromkeys(table["isolator"]))
    marked = marked or ("te10" if "te10" in isolators else isolators[0])
    accuracy = isolation_accuracy_text(table)
    n_axes = table_axes(table)
    imported = bool(table.attrs.get("imported"))
    head = (["task", "logs" if imported else "wear %"] + [f"axis {a}" for a in range(1, n_axes + 1)]
            + [f"accuracy {name} (%)" for name in isolators])
    lines = ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
    for (task, level), group in table[table["isolator"] == marked].groupby(["task", "wear_pct"]):
        marks = []
        for axis in range(1, n_axes + 1):
            row = group[group["worn_axis"] == axis]
            marks.append("-" if row.empty else ("✓" if bool(row["correct"].iloc[0]) else "✗"))
        acc = [accuracy.loc[(task, level), name] for name in isolators]
        lines.append("| " + " | ".join([task, level_label(level, imported), *marks, *acc]) + " |")
    decided = isolation_levels(table, isolation_decided(table))
    cases = (" Units imported from logs: each worn unit is one case, its logs up to the first labelled worn by "
             "events.csv (\"to first worn\"); no wear is measured." if imported else "")
    return (f"Marks: {marked} (✓ source axis isolated, ✗ not, - no run). {ACCURACY_RULE}{cases}\n\n"
            + "\n".join(lines)
            + "\n\nCases in which each isolator named an axis, right or wrong (%; the rest undecided or too few "
            "cycles):\n\n"
            + markdown(decided, digits=4))


#: How :func:`isolation_accuracy` scores, said wherever its numbers are printed.
ACCURACY_RULE = ("Accuracy: the share of cases an isolator ran on in which it named the worn axis, or on rows \"no "
                 "fault\" (runs without wear) named none (naming an axis there is a false isolation); so one that "
                 "never decides scores 100 % on \"no fault\" and 0 % elsewhere. Cases with fewer cycles than it needs "
                 "are not scored: \"not applicable: N cycles < M needed\".")


def level_label(level: float, imported: bool = False) -> str:
    """A wear level as the tables and figures print it: "no fault" for 0, "to first worn" on an
    imported dataset, else the percentage (``5``, ``10``)."""
    return "no fault" if level == 0 else "to first worn" if imported else f"{level:g}"


def isolation_report(table: pd.DataFrame, path=None, window: tuple[float, float] | None = None) -> str:
    """What ``faultgen bench-isolators`` prints of an isolation table: with a motor-speed ``window``
    (rad/s), how it covers the motor speeds of the dataset at ``path``; the accuracy per task and
    level under :data:`ACCURACY_RULE`, the cases decided, and a note on isolators the dataset starves
    of cycles (or of logs, for an imported dataset)."""
    lines = []
    if window is not None:
        lines.append(f"motor speeds against the window {window[0]:g}-{window[1]:g} rad/s (runs without wear):")
        lines.append(markdown(motor_speed_coverage(path, window), digits=4))
    imported = bool(table.attrs.get("imported"))
    if imported:
        lines.append("units imported from logs: no wear is measured; each worn unit is one case, its logs up to the "
                     "first labelled worn by events.csv (\"to first worn\"; --levels does not apply)")
    lines.append(markdown(isolation_levels(table, isolation_accuracy_text(table)), digits=4))
    lines.append(ACCURACY_RULE + " In the CSV, predicted 0 is undecided and -1 too few cycles (column answer "
                 "spells it; needed: the isolator's fewest cycles).")
    lines.append("\ncases in which each isolator named an axis, right or wrong (%; the rest undecided or too few "
                 "cycles):")
    lines.append(markdown(isolation_levels(table, isolation_decided(table)), digits=4))
    lines.append(isolation_verdicts(table))
    starved = starved_isolators(table)
    if starved and imported:
        lines.append(f"note: this dataset lacks logs: with at most {int(table['cycles'].max())} logs per unit up to "
                     f"its first labelled worn, {', '.join(starved)} named no axis (undecided, or too few logs to run) "
                     "in most worn cases. These isolators need tens of records (thesis Table 6.2: up to 86) before the "
                     f"first worn one: longer records of the units; {MEASURED_NEXT}")
    elif starved:
        lines.append(f"note: this dataset lacks cycles: with at most {int(table['cycles'].max())} recorded cycles per "
                     f"run, {', '.join(starved)} named no axis (undecided, or too few cycles to run) in most worn "
                     "cases. These isolators need tens of cycles (thesis Table 6.2: up to 86, every cycle recorded): "
                     "use `faultgen sweep --preset j2`, or --record with more cycles")
    return "\n".join(lines)


def isolation_verdicts(table: pd.DataFrame) -> str:
    """Per isolator, its accuracy over every worn case it ran on (all tasks and levels; the runs
    without wear are the table's "no fault" rows) against naming one of the robot's N axes at random
    (1/N): a one-sided binomial test at 5 %, and its verdict."""
    from scipy.stats import binomtest

    n_axes = table_axes(table)
    worn = table[(table["worn_axis"] != NO_FAULT) & (table["predicted"] != TOO_FEW_CYCLES)]
    lines = [f"worn cases, every level, against {100.0 / n_axes:.1f} % (one of {n_axes} axes at random; "
             "one-sided binomial test at 5 %):"]
    for name in dict.fromkeys(table["isolator"]):
        cases = worn[worn["isolator"] == name]
        if not len(cases):
            lines.append(f"  {name}: no worn case with enough cycles: not judged")
            continue
        right = int(cases["correct"].sum())
        p = binomtest(right, len(cases), 1.0 / n_axes, alternative="greater").pvalue
        lines.append(f"  {name}: {right} of {len(cases)} ({100.0 * right / len(cases):.1f} %), p = {p:.2g}: "
                     + ("above chance" if p < 0.05 else "not above chance"))
    return "\n".join(lines)
