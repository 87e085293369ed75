"""Run isolators, detectors and classifiers over a faultgen dataset; tables in the thesis's layouts.

- :func:`isolation_table`: every isolator on every run with one worn axis, at each wear level
  (data up to the first cycle whose true wear reaches it), thesis Table 6.2, and on every run
  without wear, where naming any axis is a false isolation; :func:`isolation_confusion` counts
  true axis (or none) against named axis (or undecided) per isolator.
- :func:`detection_table`: PCA monitoring (Q statistic) of each worn run against the run without
  wear of the same robot, task and seed; onset of wear and its location, thesis Table 3.5.
- :func:`classification_table`: AUC of LR / SVM / RF / stacking over preprocessing combinations,
  leave one worn and one unworn run out, thesis Table 5.2.

Each takes a dataset path and returns a pandas DataFrame; :func:`write_outputs` writes a table as
CSV and Markdown (and a PNG heatmap for isolation).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from tqdm.auto import tqdm

from analysis import isolation
from analysis.monitoring import detect_onset, fit_q_monitor, varying_columns
from faultgen import axes
from faultgen.checks import is_whole
from faultgen.data import dataset, reader
from faultgen.model import robots
from faultgen.simulation import sensors

#: Wear levels of thesis Table 6.2, in percent.
WEAR_LEVELS = (1.0, 5.0, 10.0, 15.0)
#: What an isolator's answer means where it is not an axis number 1..6.
UNDECIDED, TOO_FEW_CYCLES = 0, -1
#: The true axis of a run without wear, in the tables.
NO_FAULT = 0


def axis_label(value: int) -> str:
    """How an axis number is printed: "1".."6", "none" or "undecided" for 0 (a run without wear's
    true axis, or an isolator that names none), "too few cycles" for -1."""
    return {UNDECIDED: "undecided", TOO_FEW_CYCLES: "too few cycles"}.get(int(value), str(int(value)))


def default_isolators(bins: Iterable[int] = (5, 10)) -> dict[str, object]:
    """Transfer entropy with each bin count (thesis ch. 6), cross-correlation (ch. 3.4.2), and the
    other registered isolators with their defaults."""
    chosen = {f"te{b}": isolation.make("transfer_entropy", bins=b) for b in bins}
    for name in isolation.ISOLATORS:
        if name != "transfer_entropy":
            chosen[name] = isolation.make(name)
    return chosen


@contextmanager
def opened(source):
    """A :class:`faultgen.data.reader.Dataset` from a path (opened here, closed after) or as given."""
    if isinstance(source, reader.Dataset):
        yield source
    else:
        with reader.open(source) as data:
            yield data


def fault_progress(run: reader.Run, axis: int) -> np.ndarray:
    """Per recorded cycle, the worn axis's true friction multiplier; for a run whose fault is not
    friction wear (``run.fault``: a growing backlash, cogging, offset), 1 + its parameter's
    change as a fraction of the final change, so that a level of L % means L % of the final value."""
    if run.fault is None:
        return run.array("friction_multiplier")[:, axes.index(axis)]
    return 1.0 + run.fault_level / 100.0


def level_cycle(multiplier: np.ndarray, level: float) -> int | None:
    """Index of the first recorded cycle whose true wear reaches ``level`` percent, or None."""
    reached = np.flatnonzero((multiplier - 1.0) * 100.0 >= level - 1e-9)
    return int(reached[0]) if reached.size else None


def isolation_table(path, isolators: Mapping[str, object] | None = None, levels: Iterable[float] = WEAR_LEVELS,
                    signal: str = "mean_abs_torque", progress: bool = True,
                    speed_window: tuple[float, float] | None = None) -> pd.DataFrame:
    """Which axis each isolator names as the source, per run and wear level, healthy runs included.

    For a run wearing one axis, the isolator sees the per-cycle ``signal`` (n_cycles, 6) of the
    recorded cycles up to and including the first one whose true wear reaches the level (thesis
    ch. 6.4: 10 % wear is cycle 86 of the exp4 schedule; for a fault other than friction wear, the
    level is a share of its final value, :func:`fault_progress`); it is right when it names that axis.
    A run without wear is shown, for each level, as many cycles as the worn runs of its robot and
    task saw at that level; it is right only when the isolator names no axis (undecided): naming
    one is a false isolation. Runs wearing several axes are skipped.

    A dataset imported from logs (``faultgen logs import``) has no measured wear, only logs
    labelled worn by its events: each worn unit is one case, its logs up to and including the
    first labelled worn (``levels`` do not apply; ``wear_pct`` holds :data:`LABELLED_WORN`, a
    mark), and ``attrs["imported"]`` is True.

    With ``speed_window`` (low, high) in rad/s of motor speed, the per-cycle signal is the mean
    |motor torque| over the samples whose motor speed lies in the window (thesis ch. 6.3.2,
    :func:`analysis.features.speed_window_mean`); an axis of a run with a cycle that has no such
    sample keeps its whole-cycle ``signal`` (column ``windowed``: the axes that were windowed).

    Returns
    -------
    DataFrame with one row per (run, level, isolator): robot, task, run, worn_axis (0: no wear),
    wear_pct (the level; 0 for a run without wear), cycles (samples seen), isolator, predicted
    (0: undecided; -1: too few cycles for the isolator), correct, windowed, n_axes (the run's
    robot's axes N), needed (the fewest cycles the isolator runs on; NaN for a plugin). A case with
    too few cycles is not applicable: :func:`isolation_accuracy` leaves it out.

    Raises
    ------
    ValueError
        If an isolator's parameters are invalid (e.g. bins < 2; the message names it), or the
        dataset has no run with exactly one worn axis.
    """
    from sklearn.base import clone

    isolators = dict(isolators or default_isolators())
    probe = np.random.default_rng(0).standard_normal((200, 6))
    for name, prototype in isolators.items():  # bad parameters (bins < 2, ...) raise here, named
        try:
            fitted = clone(prototype).fit(probe)
        except ValueError as err:
            raise ValueError(f"isolator {name}: {err}") from err
        if not hasattr(fitted, "source_axis_"):
            raise ValueError(f"isolator {name}: fit(X) set no source_axis_ (the isolator contract of "
                             "analysis.isolation: 1-based axis, 0 when undecided)")
    with opened(path) as data:
        runs = [r for r in data.runs if len(r.worn_axes) <= 1]
        values = {r.id: r.array(signal) for r in runs}
        windowed = {r.id: np.zeros(values[r.id].shape[1], dtype=bool) for r in runs}
        if speed_window:  # the windowed mean where every cycle has samples in the window
            from analysis.features import speed_window_mean

            for run in runs:
                inside = speed_window_mean(run.signal("tau_m"), run.signal("qd_m"), *speed_window)
                run.forget("tau_m", "qd_m")  # large: not kept
                windowed[run.id] = ~np.isnan(inside).any(axis=0)
                values[run.id] = np.where(windowed[run.id], inside, values[run.id])
        worn = [r for r in runs if len(r.worn_axes) == 1]
        if not worn:
            raise ValueError(f"{data.path} has no run with exactly one worn axis to isolate")
        imported = all(r.measured for r in data.runs)
        if imported:  # no wear is measured: one case per unit, up to its first log labelled worn
            levels = [LABELLED_WORN]
        # cycles seen per (setup, level): what the worn runs saw, shown to the healthy runs of the same
        # robot, program, friction and conditions (reader.Run.setup) too
        seen: dict[tuple, int] = {}
        cases = []
        for run in worn:
            axis = run.worn_axes[0]
            grown = fault_progress(run, axis)
            for level in levels:
                k = level_cycle(grown, level)
                if k is not None:
                    seen.setdefault((run.setup, level), k + 1)
                    cases.append((run, axis, level, k + 1))
        for run in runs:
            if not run.worn_axes:
                cases += [(run, NO_FAULT, 0.0, n) for (setup, _), n in seen.items() if setup == run.setup]
    needed = {name: isolation.min_rows(prototype) for name, prototype in isolators.items()}
    rows = []
    for run, axis, level, n in tqdm(cases, desc="isolation", unit="case", disable=not progress):
        X = values[run.id][:n]
        for name, prototype in isolators.items():
            try:
                predicted = int(clone(prototype).fit(X).source_axis_)
            except ValueError:  # too few cycles for this isolator at this level: not isolated
                predicted = TOO_FEW_CYCLES
            rows.append(dict(robot=run.robot, task=run.task, run=run.id, worn_axis=axis,
                             wear_pct=level, cycles=n, isolator=name, predicted=predicted,
                             answer=axis_label(predicted), correct=predicted == axis,
                             windowed=" ".join(str(a + 1) for a in np.flatnonzero(windowed[run.id])),
                             n_axes=X.shape[1], needed=np.nan if needed[name] is None else needed[name]))
    table = pd.DataFrame(rows)
    table.attrs["imported"] = imported
    return table


#: The ``wear_pct`` of an imported dataset's cases in :func:`isolation_table`: a mark for "up to the
#: first log labelled worn" (a worn log's friction multiplier, :data:`faultgen.data.fleetlogs.WORN_MARK`,
#: read as a wear), not a measured wear.
LABELLED_WORN = 100.0


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


def motor_speed_coverage(path, speed_window: tuple[float, float]) -> pd.DataFrame:
    """How a motor-speed window maps to each robot's and task's motor speeds: per robot, task and
    axis, the 50th and 99th percentile of |motor speed| (rad/s) over the runs without wear, and
    the share of their samples inside the window (%)."""
    rows = []
    with opened(path) as data:
        for run in data.healthy:
            qd_m = run.signal("qd_m")
            speed = np.abs(qd_m).reshape(-1, qd_m.shape[-1])
            inside = (speed >= speed_window[0]) & (speed <= speed_window[1])
            for a in range(speed.shape[1]):
                rows.append(dict(robot=run.robot, task=run.task, run=run.id, axis=axes.number(a),
                                 p50_rad_s=np.percentile(speed[:, a], 50), p99_rad_s=np.percentile(speed[:, a], 99),
                                 in_window_pct=100.0 * inside[:, a].mean()))
    table = pd.DataFrame(rows)
    return table.groupby(["robot", "task", "axis"])[["p50_rad_s", "p99_rad_s", "in_window_pct"]].mean().round(1)


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


def _table_axes(table: pd.DataFrame) -> int:
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
    n_axes = _table_axes(table)
    answers = [UNDECIDED, *range(1, n_axes + 1), TOO_FEW_CYCLES]
    counts = (table.groupby(["isolator", "worn_axis", "predicted"]).size().unstack("predicted")
              .reindex(columns=answers, fill_value=0).fillna(0).astype(int))
    isolators = list(dict.fromkeys(table["isolator"]))
    counts = counts.reindex(pd.MultiIndex.from_product([isolators, range(n_axes + 1)]), fill_value=0)
    counts.index = counts.index.set_names(["isolator", "true axis"]).set_levels(
        ["none", *map(str, range(1, n_axes + 1))], level=1)
    counts.columns = [axis_label(a) for a in answers]
    return counts


def confusion_figure(confusion: pd.DataFrame, out: Path) -> Path:
    """PNG of :func:`isolation_confusion`: one matrix per isolator, counts in the cells."""
    from matplotlib.figure import Figure

    isolators = list(dict.fromkeys(confusion.index.get_level_values("isolator")))
    cols = min(3, len(isolators))
    rows = -(-len(isolators) // cols)
    fig = Figure(figsize=(4.6 * cols, 4.0 * rows))
    panels = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax, name in zip(panels, isolators, strict=False):
        matrix = confusion.loc[name]
        values = matrix.to_numpy(dtype=float)
        share = values / np.maximum(values.sum(axis=1, keepdims=True), 1)
        ax.imshow(share, vmin=0, vmax=1, cmap="Blues", aspect="auto")
        for i in range(values.shape[0]):
            for j in range(values.shape[1]):
                if values[i, j]:
                    ax.text(j, i, f"{values[i, j]:.0f}", ha="center", va="center",
                            color="white" if share[i, j] > 0.6 else "black", fontsize=8)
        ax.set_xticks(range(values.shape[1]), ["undec.", *map(str, range(1, values.shape[1] - 1)), "short"],
                      fontsize=8)
        ax.set_yticks(range(values.shape[0]), matrix.index, fontsize=8)
        ax.set(title=name, xlabel="named axis", ylabel="true worn axis")
    for ax in panels[len(isolators):]:
        ax.set_visible(False)
    fig.suptitle("isolation confusion: true worn axis (none = run without wear) x named axis "
                 "(undec. = undecided, short = too few cycles); shade: share of the row")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    return out


def isolation_accuracy(table: pd.DataFrame) -> pd.DataFrame:
    """Accuracy in percent per task and wear level (rows) and isolator (columns), Table 6.2.

    One rule everywhere: a case the isolator ran on is right when it names the worn axis, or, on a
    run without wear, when it names none (undecided); so an isolator that runs and never decides
    scores 100 % on "no fault" and 0 % elsewhere. A case it could not run on (fewer cycles than it
    needs: predicted -1) is not applicable and left out; a cell with no applicable case is NaN,
    which :func:`isolation_accuracy_text` spells "not applicable: N cycles < M needed"."""
    applicable = table[table["predicted"] != TOO_FEW_CYCLES]
    accuracy = (applicable.groupby(["task", "wear_pct", "isolator"])["correct"].mean().mul(100)
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
    n_axes = _table_axes(table)
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
        lines.append("| " + " | ".join([task, _level_label(level, imported), *marks, *acc]) + " |")
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


def _level_label(level: float, imported: bool = False) -> str:
    return "no fault" if level == 0 else "to first worn" if imported else f"{level:g}"


def isolation_heatmap(table: pd.DataFrame, out: Path) -> Path:
    """PNG heatmap of accuracy: isolators (rows) x task and wear level (columns)."""
    from matplotlib.figure import Figure

    accuracy = isolation_accuracy(table).T  # isolators x (task, wear)
    fig = Figure(figsize=(max(6.0, 0.7 * accuracy.shape[1] + 2), 0.5 * accuracy.shape[0] + 2))
    ax = fig.subplots()
    image = ax.imshow(accuracy.to_numpy(dtype=float), vmin=0, vmax=100, cmap="viridis", aspect="auto")
    ax.set_yticks(range(accuracy.shape[0]), accuracy.index)
    imported = bool(table.attrs.get("imported"))
    ax.set_xticks(range(accuracy.shape[1]), [f"{t} {_level_label(w, imported)}" + (" %" if w and not imported else "")
                                             for t, w in accuracy.columns], fontsize=8, rotation=35, ha="right")
    for i in range(accuracy.shape[0]):
        for j in range(accuracy.shape[1]):
            value = accuracy.iat[i, j]
            ax.text(j, i, "n/a" if np.isnan(value) else f"{value:.0f}", ha="center", va="center",
                    color="white" if np.isnan(value) or value < 60 else "black")
    fig.colorbar(image, ax=ax, label="source axis isolated (%)")
    ax.set_title("isolation accuracy per task and " + ("case (logs up to the first labelled worn)" if imported
                                                     else "wear level") + " (n/a: too few cycles for the isolator)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    return out


def group_cycles(cycles: np.ndarray, period: int | None) -> np.ndarray:
    """Group index of each recorded cycle: ``(cycle - 1) // period`` (e.g. the hour, for period 60
    one-minute cycles), or one group per recorded cycle when ``period`` is None."""
    return np.arange(len(cycles)) if period is None else (cycles - 1) // period


#: Where the detector learns normal operation (``faultgen detect --protocol``):
#: other-seeds: the runs without wear of the same robot, task and friction model but other seeds
#: (other units); first-cycles: the first samples of the tested run itself (its "first days",
#: thesis ch. 4); same-run: the run without wear of the same seed (thesis ch. 3.4, optimistic: its
#: noise is the tested run's). auto: on a fleet first-cycles (each robot is a unit of its own);
#: on a sweep other-seeds where the dataset has them, else first-cycles where the run has more
#: samples than it learns from, else same-run where the run without wear of the seed exists.
PROTOCOLS = ("auto", "other-seeds", "first-cycles", "same-run")

#: The samples first-cycles learns from when ``first`` is not given; a run with no more samples
#: than this learns from its first half (:func:`fitted_first`).
FIRST = 20
#: The fewest samples ``auto`` lets a fleet's robot learn from (a PCA monitor and its folds).
MIN_FIRST = 5


def fitted_first(first: int | None, n_samples: int) -> int:
    """The samples first-cycles learns from on a run of ``n_samples``: ``first`` as given, else
    :data:`FIRST`, or half the run (rounded down) when the run has no more samples than that."""
    if first is not None:
        return first
    return FIRST if n_samples > FIRST else n_samples // 2


def detection_table(path, variance: float = 0.75, alpha: float = 0.05, persistence: int = 1,
                    period: int | None = None, progress: bool = True, detector=None, protocol: str = "auto",
                    first: int | None = None, limit_folds: int | None = 20, return_charts: bool = False):
    """Onset of wear by PCA monitoring and its location, per worn run (thesis ch. 3.4, Table 3.5),
    with the false-alarm rate on healthy data the monitor did not learn from.

    Features per sample: for each axis, the KL divergence (eq. 5.4) of the 12-bin histogram of
    |motor torque|, normalised by the largest |motor torque| of the training data rounded up to a
    whole percent of the peak motor torque (thesis ch. 3.4: "normalized with respect to maximum
    torque and binned into twelve equal-sized intervals"; :func:`detection_scale`). The bins are
    formed from each cycle's fine counts (:func:`torque_record`), so a run recorded with signals and
    the same run recorded without give the same table (daily records, a fleet's, have only their
    stored 12-bin histograms, binned to the motor's peak torque, and use those). The divergence is
    taken against the run's first sample under same-run (the thesis's), and against the mean histogram
    of the training samples under the held-out protocols: one noisy first cycle shifts every later
    divergence of its run, which a monitor that learned other runs reads as a fault (j2, three
    seeds, other-seeds, 95 % limit, in-sample: 19.1 % false alarms against the first sample,
    8.7 % against the training mean, on 2026-11-22's physics). A sample is one recorded cycle, or
    all the cycles of a ``period`` (60 for the c2 preset's hours of one-minute cycles). A PCA
    monitor (components for ``variance`` of the variance, thesis: 75 %; features constant in
    training are left out) learns
    normal operation as ``protocol`` says (:data:`PROTOCOLS`; ``first`` samples for first-cycles,
    None: :func:`fitted_first`, 20 or half a shorter run);
    wear is detected at the first sample (after the training ones, and at or after the first
    sample with true wear or fault above 0: ``fault_begins_cycle``) whose Q statistic exceeds its
    ``1 - alpha`` limit for ``persistence`` samples in a row; alarms before the fault begins are
    false alarms (``alarms_before_fault_pct``), never a detection (a fleet's failing robots wear
    from a drawn onset day). Under the held-out protocols the Q
    limit is estimated out of sample over ``limit_folds`` folds of the training samples, at most
    one fold per training sample (:class:`~analysis.monitoring.PCAMonitor` ``cv``; None: in-sample,
    eq. 2.6 as in the thesis):
    j2, three seeds, other-seeds, alpha 5 %: 9.0 % false alarms in-sample, 6.2 % with 20 folds;
    same-run always uses the in-sample limit; its location is the axis the
    cross-correlation isolator names (ch. 3.4.2) on the KL features up to that sample.

    The false-alarm rate is the share of alarm samples on runs without wear that the monitor did
    not learn from (:func:`false_alarm_meaning`): under other-seeds the run of the tested seed;
    under first-cycles every healthy run of the same robot, task and friction model (else of the
    same robot model: a fleet's healthy robots), each judged by the protocol itself, a monitor
    learnt from its own first ``first`` samples, after them. Under same-run it is measured on the
    training run itself (in-sample, said in the ``protocol`` column).

    ``detector``, a scikit-learn estimator whose ``fit(X)`` learns healthy samples and whose
    ``predict(X)`` gives one alarm (truthy) per sample, replaces the PCA monitor (``variance`` and
    ``alpha`` are then unused); it sees the same features.

    Returns
    -------
    DataFrame, one row per worn run: robot, task, run, seed, worn_axis, final_wear_pct, protocol
    (as used; "same-run (in-sample)"), trained_on (runs, or cycles of the run), false_alarm_pct
    (NaN without a healthy run to measure it on), false_alarm_runs (how many), fault_begins_cycle,
    trained_on_fault (the fault began inside the first-cycles training samples),
    alarms_before_fault_pct (alarm share of the tested run's samples after training and before the
    fault begins; NaN if none), features (axes used), detected, onset (sample index, 0-based; NaN
    if not detected), onset_cycle (1-based cycle of that sample's first recorded cycle),
    onset_wear_pct, located_axis (0: undecided), located. With ``return_charts`` also a dict run
    id -> its chart data (per sample: cycle, wear_pct, alarm, t2, q; t2_limit, q_limit, trained,
    begins, onset), what :func:`detection_figure` draws.

    Raises
    ------
    ValueError
        If ``protocol`` is unknown, or the dataset lacks the healthy data it needs (the message
        says what is missing and which protocol or grid provides it).
    """
    if protocol not in PROTOCOLS:
        raise ValueError(f"unknown protocol {protocol!r}; expected one of: {', '.join(PROTOCOLS)}")
    if limit_folds is not None and not is_whole(limit_folds, 2):
        raise ValueError(f"limit_folds = {limit_folds!r}; expected None (the in-sample Q limit) or a number of folds >= 2")
    with opened(path) as data:
        table, charts = _detection(data, variance, alpha, persistence, period, progress, detector, protocol, first,
                                   limit_folds)
        table.attrs.update(dataset_kind=data.kind, command=data.command, first=first, limit_folds=limit_folds,
                           alpha=alpha, protocol_reasons=charts.pop("_reasons"),
                           imported=bool(data.runs) and all(run.measured for run in data.runs))
    return (table, charts) if return_charts else table


def _auto_protocol(kind: str, others: list, own, n_samples: int, first: int | None) -> tuple[str, str]:
    """The protocol ``auto`` picks for one worn run, and why (a sentence for the user). On a fleet
    ``first`` is fitted to the record (:func:`fitted_first`); a sweep's choice is as before."""
    n_first = fitted_first(first, n_samples)
    if kind == "fleet" and MIN_FIRST <= n_first < n_samples:
        return "first-cycles", (f"a fleet: each robot is a unit of its own and learns its first {n_first} days "
                                "(thesis ch. 4, one-to-one)")
    if others:
        return "other-seeds", "the dataset has runs without wear of other seeds (other units)"
    if (first or FIRST) < n_samples:
        return "first-cycles", (f"no run without wear of another seed; each run learns its first {first or FIRST} "
                                "samples (sweep --seed 0 --seed 1 --seed 2 for other-seeds)")
    if own is not None:
        return "same-run", (f"no run without wear of another seed and runs of {n_samples} samples, too few to "
                            "learn from their first ones; the run without wear of the same seed (in-sample)")
    raise ValueError(f"no protocol fits: no run without wear of another seed or of the same seed, and runs of "
                     f"{n_samples} samples, too few to learn from their first ones (--first); record more cycles "
                     "or sweep with --axis 0 and several seeds")


def _detection(data: reader.Dataset, variance, alpha, persistence, period, progress, detector, protocol, first,
               limit_folds) -> tuple[pd.DataFrame, dict]:
    path = data.path
    runs = data.runs
    healthy = data.healthy
    torque: dict[str, np.ndarray | StoredHistograms] = {}

    def torque_of(run: reader.Run) -> np.ndarray | StoredHistograms:
        """A run's per-cycle |motor torque| counts (:func:`torque_record`), read once."""
        if run.id not in torque:
            torque[run.id] = torque_record(run)
        return torque[run.id]

    def similar(run: reader.Run) -> list[reader.Run]:
        """Healthy runs to measure false alarms on under first-cycles: of the same kind (robot,
        task, friction), else of the same robot model (a fleet's robots each have their own task),
        else all."""
        for match in (lambda r: _same_unit_kind(r, run), lambda r: r.robot == run.robot, lambda r: True):
            chosen = [r for r in healthy if match(r)]
            if chosen:
                return chosen
        return []

    monitors: dict[tuple, tuple] = {}
    far: dict[str, tuple] = {}  # runs whose Q limit lies FAR_LIMIT times above every Q they were tested on
    false_alarms: dict[tuple, float] = {}  # per monitor: its rate on the held-out healthy runs
    rows, charts, reasons = [], {}, {}
    for run in tqdm(runs, desc="detection", unit="run", disable=not progress):
        if len(run.worn_axes) != 1:
            continue
        axis = run.worn_axes[0]
        same = [r for r in healthy if _same_unit_kind(r, run)]
        own = next((r for r in same if r.seed == run.seed), None)
        others = [r for r in same if r.seed != run.seed]
        sample_of = group_cycles(run.recorded, period)
        samples = np.unique(sample_of)
        n_samples = len(samples)
        used_protocol, n_first = protocol, fitted_first(first, n_samples)
        if protocol == "auto":  # a fleet's robots are units of their own: each learns its first days (thesis ch. 4)
            used_protocol, reason = _auto_protocol(data.kind, others, own, n_samples, first)
            if run.measured and used_protocol == "first-cycles":
                reason = (f"units imported from logs: each unit learns its first {fitted_first(first, n_samples)} logs "
                          "(thesis ch. 4, one-to-one)")
            reasons[used_protocol] = reason
        if used_protocol == "other-seeds":
            if not others:
                raise ValueError(f"{path}: protocol other-seeds needs runs without wear of {run.robot} "
                                 f"{run.task} with another seed than {run.seed}; this dataset has none"
                                 f"{_unlike(run, healthy)}. Sweep "
                                 "several seeds (--seed 0 --seed 1 --seed 2) or use --protocol first-cycles")
            training = [(r.id, torque_of(r), r.recorded) for r in others]
            key, trained_on, heldout, skip = tuple(r.id for r in others), " ".join(r.id for r in others), \
                [own] if own else [], 0
            if own is None and len(others) > 1:  # no healthy run of the tested seed: each other one in turn
                heldout = [("leave-one-out", r, [o for o in others if o is not r]) for r in others]
        elif used_protocol == "first-cycles":
            if n_samples <= n_first:
                raise ValueError(f"{path}: protocol first-cycles learns from the first {n_first} samples of a run and "
                                 f"needs more; {run.id} has {n_samples}. Give a smaller --first, record more cycles, "
                                 "or sweep several seeds (--seed 0 --seed 1 --seed 2) for --protocol other-seeds")
            keep = np.isin(sample_of, samples[:n_first])
            training = [(run.id, torque_of(run)[keep], run.recorded[keep])]
            key, trained_on, heldout, skip = (run.id, n_first), f"samples 1-{n_first} of the run", similar(run), n_first
        else:  # same-run
            if own is None:
                raise ValueError(f"{path}: protocol same-run needs the run without wear of {run.robot} "
                                 f"{run.task} seed {run.seed}; this dataset has none{_unlike(run, healthy)}: use "
                                 "--protocol first-cycles (or auto)")
            training = [(own.id, torque_of(own), own.recorded)]
            key, trained_on, heldout, skip = (own.id,), own.id, [own], 0
        held_out = used_protocol != "same-run"
        if key not in monitors:  # one monitor serves every worn run that learns from the same data
            monitors[key] = _fit_monitor(training, period, variance, alpha, detector, fixed_reference=held_out,
                                         folds=limit_folds if held_out else None)

        if used_protocol == "same-run":
            used_protocol = "same-run (in-sample)"
        scale, reference, used, monitor = monitors[key]
        worn, groups = _kl_features(torque_of(run), run.recorded, scale, period, reference)
        alarms = np.asarray(monitor.predict(worn[:, used]), dtype=bool)
        # the fault's first sample: an alarm before it is a false alarm, never a detection
        begins = run.fault_begins
        start = len(alarms) if begins is None else int(groups[begins])
        first_tested = max(skip, start)
        onset = detect_onset(alarms[first_tested:], persistence=persistence)
        onset = None if onset is None else onset + first_tested
        before = alarms[skip:start]
        if key not in false_alarms:
            rates, counts = [], [0, 0]  # and alarms, samples over the healthy runs: the interval
            for normal_run in heldout:
                if isinstance(normal_run, tuple):  # other-seeds: a monitor of the other healthy runs judges it
                    _, normal_run, rest = normal_run
                    n_scale, n_reference, n_used, n_monitor = _fit_monitor(
                        [(r.id, torque_of(r), r.recorded) for r in rest], period, variance, alpha, detector,
                        fixed_reference=True, folds=limit_folds)
                    normal, _ = _kl_features(torque_of(normal_run), normal_run.recorded, n_scale, period, n_reference)
                    flags = np.asarray(n_monitor.predict(normal[:, n_used]), dtype=bool)
                elif used_protocol == "first-cycles" and normal_run is not run:  # the protocol on a healthy robot
                    normal_of = group_cycles(normal_run.recorded, period)
                    if len(np.unique(normal_of)) <= n_first:
                        continue
                    own_keep = np.isin(normal_of, np.unique(normal_of)[:n_first])
                    fitted = _fit_monitor([(normal_run.id, torque_of(normal_run)[own_keep],
                                            normal_run.recorded[own_keep])], period, variance, alpha, detector,
                                          fixed_reference=True, folds=limit_folds)
                    n_scale, n_reference, n_used, n_monitor = fitted
                    normal, _ = _kl_features(torque_of(normal_run), normal_run.recorded, n_scale, period, n_reference)
                    flags = np.asarray(n_monitor.predict(normal[:, n_used]), dtype=bool)[n_first:]
                else:
                    normal, _ = _kl_features(torque_of(normal_run), normal_run.recorded, scale, period, reference)
                    flags = np.asarray(monitor.predict(normal[:, used]), dtype=bool)[skip:]
                rates.append(100.0 * float(np.mean(flags)))
                counts[0] += int(np.sum(flags))
                counts[1] += int(flags.size)
            false_alarms[key] = (float(np.mean(rates)) if rates else np.nan, len(rates), false_alarm_interval(*counts))
        false_alarm, n_normal, (low, high) = false_alarms[key]
        wear = fault_progress(run, axis) * 100.0 - 100.0
        located = locate_onset(worn, onset)
        rows.append(dict(robot=run.robot, task=run.task, run=run.id, seed=run.seed,
                         worn_axis=axis, final_wear_pct=round(float(wear[-1]), 2), protocol=used_protocol,
                         trained_on=trained_on, false_alarm_pct=round(false_alarm, 2), false_alarm_runs=n_normal,
                         false_alarm_ci_pct=f"{low:.1f}-{high:.1f}" if np.isfinite(low) else "",
                         false_alarm_above_alpha=bool(low > 100.0 * alpha),
                         fault_begins_cycle=np.nan if begins is None else int(run.recorded[begins]),
                         trained_on_fault=begins is not None and int(groups[begins]) < skip,
                         alarms_before_fault_pct=round(100.0 * float(before.mean()), 2) if before.size else np.nan,
                         features=" ".join(str(u + 1) for u in used), detected=onset is not None,
                         onset=np.nan if onset is None else int(onset),
                         onset_cycle=np.nan if onset is None else int(run.recorded[groups == onset][0]),
                         onset_wear_pct=np.nan if onset is None else round(float(wear[groups == onset].max()), 2),
                         located_axis=located, located=located == axis))
        if run.measured:  # no wear is measured: a worn log's friction_multiplier is a mark, not a percentage
            del rows[-1]["final_wear_pct"], rows[-1]["onset_wear_pct"]
        chart = {"sample": np.arange(len(alarms)),
                 "cycle": np.array([run.recorded[groups == g][0] for g in range(len(alarms))]),
                 "wear_pct": np.array([wear[groups == g].max() for g in range(len(alarms))]), "alarm": alarms}
        if hasattr(monitor, "score_samples") and hasattr(monitor, "q_limit_"):
            t2, q = monitor.score_samples(worn[:, used])
            chart.update(t2=t2, q=q, t2_limit=monitor.t2_limit_, q_limit=monitor.q_limit_)
            tested = q[skip:] if skip < len(q) else q
            if tested.size and monitor.q_limit_ >= FAR_LIMIT * max(float(tested.max()), 1e-300):
                far[run.id] = (float(monitor.q_limit_), float(tested.min()), float(tested.max()), trained_on)
        charts[run.id] = dict(chart, trained=skip, onset=onset, begins=None if begins is None else int(groups[begins]),
                              protocol=used_protocol, robot=run.robot, task=run.task, worn_axis=axis)
    table = pd.DataFrame(rows)
    # what detection_advice needs: the sample each fault begins at (what --first must stay below)
    table.attrs["fault_begins_sample"] = {r: c["begins"] for r, c in charts.items() if c["begins"] is not None}
    table.attrs["q_limit_far"] = far
    charts["_reasons"] = reasons
    return table, charts


def locate_onset(features: np.ndarray, onset: int | None) -> int:
    """The axis (1..N) the cross-correlation isolator (thesis ch. 3.4.2) names on ``features``
    (n_samples, N) up to and including the ``onset`` sample, as ``faultgen detect`` locates (with
    or without ``--train``); :data:`UNDECIDED` without an onset, :data:`TOO_FEW_CYCLES` when too
    few samples precede it to cross-correlate (said, not undecided)."""
    if onset is None:
        return UNDECIDED
    try:
        return int(isolation.make("cross_correlation").fit(features[: onset + 1]).source_axis_)
    except ValueError:
        return TOO_FEW_CYCLES


#: A Q limit this many times the largest Q of the samples a run is tested on (two decades) is said
#: by :func:`detection_advice`: Q cannot alarm there, and the usual cause is a learning sample unlike
#: the others (an outlying day or log), whose out-of-fold residual sets the limit.
FAR_LIMIT = 100.0

#: What the columns of :func:`detection_table` mean, printed under it by ``faultgen detect``.
DETECTION_COLUMNS = {
    "onset": "the first sample (0-based) of the first run of PERSISTENCE alarms at or after the fault begins",
    "onset_cycle": "the 1-based cycle (a day in a fleet) of that sample",
    "fault_begins_cycle": "the first recorded cycle with true wear (fault) above 0; an alarm before it is a "
                          "false alarm (alarms_before_fault_pct), never a detection",
    "false_alarm_pct": "share of alarm samples on healthy runs (false_alarm_runs of them); see the protocol",
    "trained_on_fault": "the fault began inside the samples the monitor learned from (first-cycles): it learned "
                        "faulty data as normal",
}


#: :data:`DETECTION_COLUMNS` as they read on a dataset imported from logs (``faultgen logs import``).
MEASURED_DETECTION_COLUMNS = {
    **DETECTION_COLUMNS,
    "onset": "the first sample (0-based) of the first run of PERSISTENCE alarms at or after the first log labelled "
             "worn",
    "onset_cycle": "the 1-based log (in stamp order) of that sample",
    "fault_begins_cycle": "the first log labelled worn by events.csv (an onset or failure event); an alarm before it "
                          "is counted as a false alarm (alarms_before_fault_pct), never a detection",
    "false_alarm_pct": "share of alarm samples on units without a log labelled worn (false_alarm_runs of them; "
                       "unknown logs among them); see the protocol",
    "trained_on_fault": "the first log labelled worn lies inside the logs the monitor learned from: it learned worn "
                        "logs as normal",
}


def detection_columns(table: pd.DataFrame) -> dict[str, str]:
    """What the columns of a :func:`detection_table` mean, for its dataset (simulated or imported)."""
    return MEASURED_DETECTION_COLUMNS if table.attrs.get("imported") else DETECTION_COLUMNS


def false_alarm_meaning(protocols: Iterable[str]) -> str:
    """What ``false_alarm_pct`` measured under each of ``protocols`` (as the table's column names them)."""
    meaning = {
        "other-seeds": "the monitor judging the run without wear of the tested seed, which it did not learn from "
                       "(without one: each other healthy run judged by a monitor of the rest)",
        "first-cycles": "each healthy run of the same kind (else robot model) judged by a monitor learnt from its "
                        "own first samples, after them: held out",
        "same-run (in-sample)": "the training run itself: in-sample, optimistic",
    }
    return "; ".join(f"{p}: {meaning.get(p, p)}" for p in dict.fromkeys(protocols))


def detection_advice(table: pd.DataFrame, protocol: str = "auto") -> str:
    """Notes on a :func:`detection_table` that fit its dataset (a sweep or a fleet): runs left out of
    the summary because the monitor learned the fault, held-out false-alarm rates above the
    nominal alpha, runs detected too early to locate, alarms before the fault began, and which
    data would serve better (only advice the dataset can follow). Empty when there is nothing to
    say."""
    notes = []
    kind = table.attrs.get("dataset_kind", "sweep")
    command = table.attrs.get("command", "")
    imported = bool(table.attrs.get("imported"))
    for run, (limit, low, high, learned_from) in table.attrs.get("q_limit_far", {}).items():
        notes.append(f"note: the Q limit of {run} ({limit:.3g}, learned from {learned_from}) lies "
                     f"{np.log10(limit / max(high, 1e-300)):.1f} decades above every Q it was tested on "
                     f"({low:.3g}-{high:.3g}), so Q cannot alarm there: a learning "
                     + ("log" if imported else "sample") + " unlike the others (one outlying "
                     + ("log" if imported else "day or cycle") + ") sets the out-of-fold limit. Look at those "
                     + ("logs" if imported else "samples") + " (the grey span of the figure) and learn from others "
                     "(--first), or take the in-sample limit (--limit-folds 0)")
    seeds = (f"sweep this dataset's grid again with several seeds: `{_with_seeds(command)}`"
             if command.startswith("faultgen sweep") else "sweep its grid with several seeds (--seed 0 --seed 1 --seed 2)")
    held_in = table[table["protocol"] != "other-seeds"]
    if protocol == "auto" and len(held_in) and kind != "fleet":
        notes.append(f"note: this dataset lacks runs without wear of other seeds, so {len(held_in)} of {len(table)} "
                     f"runs were judged by a monitor that learned from {', '.join(sorted(set(held_in['protocol'])))}. "
                     f"For false alarms on healthy runs of other units, {seeds}")
    if imported and (table["protocol"] == "first-cycles").any():
        notes.append("note: each imported unit learns its own first logs (first-cycles, thesis ch. 4 OTO); "
                     "false_alarm_pct is that protocol on the units without a log labelled worn")
    elif kind == "fleet" and (table["protocol"] == "first-cycles").any():
        notes.append("note: a fleet's robots each learn their own first days (first-cycles, thesis ch. 4 OTO); "
                     "false_alarm_pct is that protocol on the fleet's healthy robots. For monitors learnt from other "
                     "robots, compared with their own, run `faultgen training-source` on a 60-day fleet")
    learned = table[table["trained_on_fault"]] if "trained_on_fault" in table else table.iloc[:0]
    if len(learned):
        begins = table.attrs.get("fault_begins_sample", {})
        earliest = min((begins.get(r, np.inf) for r in learned["run"]), default=np.inf)
        folds = table.attrs.get("limit_folds") or 0
        fewest = max(folds, 3)  # a monitor's training samples: --limit-folds folds, else a few
        where = (f"at sample {int(earliest)}, cycle {int(learned['fault_begins_cycle'].min())}"
                 if np.isfinite(earliest) else f"at cycle {int(learned['fault_begins_cycle'].min())}")
        if np.isfinite(earliest) and earliest - 1 >= fewest:
            remedy = f"A --first of {int(earliest) - 1} (or fewer, at least {fewest}) keeps training before it"
        elif imported:
            remedy = (f"No --first avoids it (the monitor needs at least {fewest} learning logs"
                      f"{f' with --limit-folds {folds}' if folds else ''}): learn normal operation from units without "
                      "a log labelled worn or from another dataset (--train OTHER.h5), or, where a unit's events.csv "
                      f"onset comes too early, {MEASURED_NEXT}")
        else:
            remedy = (f"No --first avoids it (the monitor needs at least {fewest} training samples"
                      f"{f' with --limit-folds {folds}' if folds else ''}); learn from runs without wear instead: "
                      f"{seeds} for --protocol other-seeds, or record cycles before the wear begins")
        began = "the first log labelled worn lies" if imported else "the fault began"
        notes.append(f"note: {len(learned)} of {len(table)} runs are left out of the summary: {began} inside "
                     f"the samples their monitor learned as normal (trained_on_fault; earliest {where}), so their "
                     f"detections say nothing. {remedy}")
    alpha = 100.0 * table.attrs.get("alpha", 0.05)
    high = table[table["false_alarm_above_alpha"] & ~table["protocol"].str.startswith("same-run")] \
        if "false_alarm_above_alpha" in table else table.iloc[:0]
    if len(high):
        worst = high.loc[high["false_alarm_pct"].idxmax()]
        notes.append(f"note: in {len(high)} of {len(table)} runs the held-out false-alarm rate is above the nominal "
                     f"{alpha:g} % by more than its 95 % interval (e.g. {worst['run']}: {worst['false_alarm_pct']:g} %, "
                     f"interval {worst['false_alarm_ci_pct']} %): the Q limit does not hold on healthy data the monitor "
                     "did not learn, so alarms come sooner than alpha promises; more training data or --limit-folds "
                     "helps")
    counted = table[~table["trained_on_fault"]] if "trained_on_fault" in table else table
    detected = counted[counted["detected"]]
    if len(detected) and not detected["located"].astype(bool).any():  # located_pct 0: say why
        need = isolation.min_rows(isolation.make("cross_correlation"))
        short = detected[detected["located_axis"] == TOO_FEW_CYCLES]
        undecided = detected[detected["located_axis"] == UNDECIDED]
        why = []
        if len(short):
            why.append(f"in {len(short)} the onset came after {int(short['onset'].max()) + 1} samples or fewer, too few "
                       f"to locate (cross-correlation needs at least {need})")
        if len(undecided):
            samples = undecided["onset"].astype(int) + 1
            why.append(f"in {len(undecided)} cross-correlation named no axis (undecided) on the "
                       f"{int(samples.min())}-{int(samples.max())} samples up to the onset: no axis's features led "
                       "the others'")
        wrong = len(detected) - len(short) - len(undecided)
        if wrong:
            why.append(f"in {wrong} it named another axis than the worn one")
        more = ("more logs before the onset (longer records of the units; the first log labelled worn comes from "
                "events.csv)" if imported else "more samples before the onset: record more cycles (--record all)")
        notes.append(f"note: located_pct is 0 (of {len(detected)} detected runs): {'; '.join(why)}. Location needs "
                     + more)
    noisy = table[table["alarms_before_fault_pct"] >= 50]
    if len(noisy):
        notes.append(f"note: {len(noisy)} of {len(table)} runs alarm on at least half of their samples before the "
                     + ("first log labelled worn" if imported else "fault begins") + " (alarms_before_fault_pct): the monitor does not describe their healthy operation, so their "
                     "detections say little")
    return "\n".join(notes)


def _with_seeds(command: str) -> str:
    """The sweep ``command`` that made a dataset, with three seeds and a new output file."""
    import shlex

    words, kept, out = shlex.split(command), [], Path("sweep.h5")
    while words:
        word = words.pop(0)
        if word in ("-o", "--out", "--seed") and words:
            value = words.pop(0)
            out = Path(value) if word != "--seed" else out
        elif word not in ("--no-progress", "--resume", "--overwrite"):
            kept.append(word)
    return shlex.join([*kept, "--seed", "0", "--seed", "1", "--seed", "2", "-o", str(out.with_name(out.stem + "-seeds.h5"))])


def detection_figure(charts: dict, out: Path, most: int = 40) -> Path:
    """PNG of the Q and T2 charts of :func:`detection_table` (``return_charts=True``): per worn run
    (every one, up to ``most``: the title then says how many are shown), Q and T2 against the
    cycle (a day in a fleet) on a log scale, with the
    limit (dashed), the samples the monitor learned from (shaded), where the fault begins (dotted)
    and the onset called (red). A detector without statistics shows its alarms instead."""
    from matplotlib.figure import Figure

    shown = list(charts.items())[:most]
    # constrained layout leaves the title its own room above the first row
    fig = Figure(figsize=(11, 2.3 * max(1, len(shown)) + 0.8), layout="constrained")
    panels = fig.subplots(max(1, len(shown)), 2, squeeze=False)
    for (run_id, chart), row in zip(shown, panels, strict=False):
        x = chart["cycle"]
        for ax, name in zip(row, ("q", "t2"), strict=True):
            if name in chart:
                ax.semilogy(x, np.maximum(chart[name], 1e-12), ".-", lw=0.8, ms=3, color="C0")
                ax.axhline(chart[f"{name}_limit"], ls="--", color="k", lw=0.8)
            else:
                ax.step(x, chart["alarm"].astype(int), where="mid")
            if chart["trained"]:
                ax.axvspan(x[0], x[min(chart["trained"], len(x)) - 1], color="0.85", lw=0)
            if chart["begins"] is not None:
                ax.axvline(x[chart["begins"]], ls=":", color="C2", lw=1.2)
            if chart["onset"] is not None:
                ax.axvline(x[chart["onset"]], color="C3", lw=1.2)
            ax.set_ylabel({"q": "Q", "t2": "T2"}[name])
            ax.set_title(f"{run_id} (axis {chart['worn_axis']}, {chart['protocol']})", fontsize=8)
    for ax in panels[-1]:
        ax.set_xlabel("cycle (a day in a fleet)")
    count = (f"all {len(charts)} worn runs" if len(shown) == len(charts)
             else f"the first {len(shown)} of {len(charts)} worn runs (every run in the table)")
    fig.suptitle(f"PCA monitoring, {count}: Q (left) and T2 (right); dashed: 1 - alpha limit; grey: learned as "
                 "normal;\ndotted green: fault begins; red: onset called", fontsize=9)
    fig.savefig(out, dpi=100)
    return out


def detection_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per task and per worn axis (and over all): runs counted, left_out (runs whose monitor learned
    the fault as normal, ``trained_on_fault``: their detections say nothing, so none of the other
    columns rests on them), mean false-alarm rate (%), share detected (%), median onset cycle and
    true wear at detection (%), share located (%)."""
    def percent(flags):
        return 100.0 * flags.mean() if len(flags) else np.nan

    learned = table["trained_on_fault"].astype(bool) if "trained_on_fault" in table else pd.Series(False, table.index)
    aggregate = dict(runs=("run", "size"), false_alarm_pct=("false_alarm_pct", "mean"),
                     detected_pct=("detected", percent), median_onset_cycle=("onset_cycle", "median"),
                     median_onset_wear_pct=("onset_wear_pct", "median"), located_pct=("located", percent))
    if "onset_wear_pct" not in table:  # units imported from logs: no wear is measured
        del aggregate["median_onset_wear_pct"]
    parts = []
    for key, label in (("task", "task"), ("worn_axis", "worn axis"), (None, "all")):
        by = table[key].astype(str) if key else pd.Series("all", index=table.index)
        kept = table[~learned].groupby(by[~learned]).agg(**aggregate).reindex(sorted(set(by)))
        kept["runs"] = kept["runs"].fillna(0).astype(int)
        kept.insert(1, "left_out", learned.groupby(by).sum().reindex(kept.index).astype(int))
        parts.append(kept.assign(by=label))
    out = pd.concat(parts).rename_axis("group").reset_index()
    return out.set_index(["by", "group"]).round(2)


def false_alarm_interval(alarms: int, samples: int, level: float = 0.95) -> tuple[float, float]:
    """Clopper-Pearson ``level`` interval of a false-alarm rate, % (``scipy.stats.binomtest``),
    from the alarms among the healthy samples judged; (nan, nan) without samples. Samples of a run
    are correlated, so the interval is if anything too narrow: a rate whose interval lies above
    the nominal alpha is above it."""
    if samples == 0:
        return np.nan, np.nan
    from scipy.stats import binomtest

    ci = binomtest(int(alarms), int(samples)).proportion_ci(confidence_level=level, method="exact")
    return round(100.0 * ci.low, 2), round(100.0 * ci.high, 2)


def _same_unit_kind(a: reader.Run, b: reader.Run) -> bool:
    """Whether ``a`` and ``b`` may be compared: same robot, program (its hash), friction model and
    operating conditions (:attr:`faultgen.data.reader.Run.setup`)."""
    return a.setup == b.setup


def _unlike(run: reader.Run, healthy: Iterable[reader.Run]) -> str:
    """For an error: the healthy runs of ``run``'s robot and task label that differ in setup, and how."""
    unlike = [(r, reader.difference(run, r)) for r in healthy if (r.robot, r.task) == (run.robot, run.task)]
    unlike = [(r, why) for r, why in unlike if why]
    if not unlike:
        return ""
    return (f" ({len(unlike)} runs without wear of that label are not comparable with it: {unlike[0][0].id} differs "
            f"in {unlike[0][1]})")


def _fit_monitor(training: list, period: int | None, variance: float, alpha: float, detector=None,
                 fixed_reference: bool = False, folds: int | None = None):
    """The torque scale (:func:`detection_scale`), the KL reference (None: each run's first
    sample), the features used and the monitor (or ``detector``) fitted on the KL features of
    ``training``, a list of (run id, its :func:`torque_record`, cycles). With ``fixed_reference``
    the reference is the mean histogram of all training samples, shared by every run the monitor
    judges; ``folds`` is the PCA monitor's ``cv`` (out-of-sample Q limit)."""
    from sklearn.base import clone

    stored = [isinstance(t, StoredHistograms) for _, t, _ in training]
    scale = None if any(stored) else detection_scale([t for _, t, _ in training])
    reference = None
    if fixed_reference:
        reference = np.concatenate([_histograms(t, cycles, scale, period)[0] for _, t, cycles in training]).mean(axis=0)
    normal = np.vstack([_kl_features(t, cycles, scale, period, reference)[0] for _, t, cycles in training])
    used = varying_columns(normal)  # features constant in training are left out
    if detector is not None:
        return scale, reference, used, clone(detector).fit(normal[:, used])
    if folds is not None:
        folds = min(folds, len(normal))  # at most one fold per training sample
    try:
        return scale, reference, used, fit_q_monitor(normal[:, used], variance, alpha, cv=folds)
    except ValueError as err:
        if folds is None:
            raise
        raise ValueError(f"the out-of-sample Q limit over {folds} folds of {len(normal)} training samples: {err}; "
                         "give fewer folds (--limit-folds 5) or 0 (the in-sample limit)") from None


def torque_record(run: reader.Run) -> np.ndarray | StoredHistograms:
    """What detection bins a run's |motor torque| from: its per-cycle counts in fine bins of
    0 .. peak motor torque (``torque_counts``, (n_cycles, 6, 1200),
    :func:`faultgen.simulation.sensors.torque_counts`), read as stored, or computed from the
    stored signals for a file written before the counts existed; the two are equal bit for bit
    for the same run. A run that has neither (a daily record, or an old file without signals)
    gives its 12-bin ``torque_hist`` (:class:`StoredHistograms`).

    Raises
    ------
    faultgen.data.dataset.DatasetError
        If the run has no counts and lacks ``tau_m`` though it says it has signals, or lacks
        ``torque_hist``.
    """
    if run.has("torque_counts"):  # the stored counts: a small array, where the signals are the largest part
        return run.array("torque_counts")
    if run.has_signals:
        tau_m = run.signal("tau_m")
        run.forget("tau_m")  # the largest array of a file: not kept
        return sensors.torque_counts(tau_m, robots.load(run.robot).motor_torque_limit)
    return StoredHistograms(run.array("torque_hist"))


def detection_scale(counts: list[np.ndarray]) -> np.ndarray:
    """The range of detection's 12 torque bins per axis, as fine bins of :func:`torque_record`
    per detection bin: the training data's largest |motor torque| rounded up to the next whole
    percent of the peak motor torque (thesis ch. 3.4 normalises by the largest torque; rounded so
    that a run's stored counts give the same bins as its signals).

    Parameters
    ----------
    counts : list of ndarray of shape (n_cycles, 6, 1200)
        The training runs' torque counts.

    Returns
    -------
    ndarray of int, shape (6,)
        Fine bins per detection bin, 1 .. 100 (the scale in percent of peak torque).
    """
    occupied = np.any(np.concatenate(counts) > 0, axis=0)  # (6, 1200)
    highest = sensors.TORQUE_COUNT_BINS - 1 - np.argmax(occupied[:, ::-1], axis=1)
    return highest // sensors.HISTOGRAM_BINS + 1


def binned_torque(counts: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """12-bin |torque| histograms per cycle, (n_cycles, 6, 12), from fine counts (n_cycles, 6,
    1200) and ``scale`` fine bins per bin (:func:`detection_scale`); larger values in the last."""
    counts = counts.astype(np.int64)
    hist = np.stack([np.add.reduceat(counts[:, axis], np.arange(sensors.HISTOGRAM_BINS) * step, axis=-1)
                     for axis, step in enumerate(scale)], axis=1)
    return hist / counts.sum(axis=-1, keepdims=True)


@dataclass(frozen=True)
class StoredHistograms:
    """The per-cycle torque histograms a run recorded without signals or counts (``torque_hist``,
    (n, 6, 12), binned over 0 .. the motor's peak torque), standing in for its counts in detection."""

    hist: np.ndarray

    def __getitem__(self, rows) -> StoredHistograms:
        """The histograms of some cycles (``rows``, as for an array of counts)."""
        return StoredHistograms(self.hist[rows])


def _histograms(torque: np.ndarray | StoredHistograms, cycles: np.ndarray, scale: np.ndarray | None,
                period: int | None) -> tuple[np.ndarray, np.ndarray]:
    """12-bin |torque| histograms per sample (n_samples, 6, 12), a sample being a recorded cycle or
    a ``period`` of them, and per recorded cycle the index of its sample. ``torque`` is a
    :func:`torque_record`; stored 12-bin histograms are used as they are (``scale`` unused)."""
    hist = torque.hist if isinstance(torque, StoredHistograms) else binned_torque(torque, scale)
    groups = group_cycles(cycles, period)
    _, index = np.unique(groups, return_inverse=True)
    return np.stack([hist[index == g].mean(axis=0) for g in range(index.max() + 1)]), index


def _kl_features(torque: np.ndarray, cycles: np.ndarray, scale: np.ndarray, period: int | None,
                 reference: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """KL divergence per axis of the (grouped) |torque| histograms against the run's first sample
    (thesis ch. 3.4), or against a fixed ``reference`` histogram (6, 12).

    Returns the features (n_samples, 6) and, per recorded cycle, the index of its sample.
    """
    from analysis.features import HistogramKL, kl_divergence

    grouped, index = _histograms(torque, cycles, scale, period)
    if reference is None:
        return HistogramKL(reference="first").fit_transform(grouped), index
    return kl_divergence(grouped, reference[None]), index


#: Samples the thesis's classifiers saw per robot before its prediction horizon (ch. 5.3.3: "T-13
#: to T-3" for a horizon of 3 days, T the failure day).
THESIS_WINDOW = 10


def classification_table(path, wear_threshold: float = 10.0, n_pairs: int | None = 20, random_state: int = 0,
                         progress: bool = True, horizon: int | None = None, chance: bool = False,
                         short: bool = False, **kwargs) -> pd.DataFrame:
    """Mean and std of leave-pair-out AUC per preprocessing (rows) and classifier (columns), Table 5.2.

    Samples are recorded cycles (days in a fleet), in time order; the features per axis are those
    of thesis Table 5.1: the speed and torque indicators (:func:`analysis.features.duty_indicators`
    over the run's samples, each standing for the same production time) and the KL divergence of
    the angle, speed and torque histograms against the run's first sample (ch. 5.3.1-5.3.2); the
    estimated speed and torque of the "+estM" rows are each sample's own average speed and
    average load torque (what :func:`analysis.features.estimates_from_indicators` gives back).
    A dataset with runs simulated before the duty was recorded (no ``average_speed``) uses the
    mean absolute and RMS motor torque in place of the indicators and has no "+estM" rows.
    Labels: 1 for samples of a worn run whose true wear is at least ``wear_threshold`` percent, 0
    otherwise; groups are runs (a "robot" of Procedure 1). With ``horizon`` the thesis's protocol
    instead (ch. 5.3.3; its Table 5.2 used 3 days): each run keeps the samples from ``horizon +``
    :data:`THESIS_WINDOW` to ``horizon`` before its last one (the failure day T of a failing
    robot; T-13 to T-3), features computed over the whole record first, and every kept sample of a
    worn run is labelled 1 (the robot's state), of an unworn run 0. With ``chance`` (and no
    ``permutations``) every row's chance level is measured on :data:`CHANCE_CLASSIFIER`
    (:func:`row_chance`) and every cell judged against it; with ``permutations`` each cell against
    its own; either way :func:`with_verdict` adds the chance level, the p-value and
    ``above_chance``, and ``attrs`` hold ``pairs`` (held-out pairs scored) and ``chance_source``
    ("cell": every cell measured; a classifier's name: only its cells, the default; None: not measured). With ``short`` (and no ``preprocessing``) only the rows of
    :data:`analysis.classify.SHORT_TABLE` the dataset has (no "+estM" ones without the duty).
    ``kwargs`` go to :func:`analysis.classify.evaluate` (``n_jobs``: pairs in parallel).

    Raises
    ------
    ValueError
        If ``horizon`` is not an integer >= 0 or a run is too short for it (the message names the
        run and its samples), or the training sets would lack a class (see
        :func:`_check_training_sets`).
    """
    from analysis.classify import ESTIMATED, SHORT_TABLE, evaluate, select_pairs

    inputs = classification_inputs(path, wear_threshold, horizon)
    dropped = _without_stacking(path, inputs, kwargs)
    if short and kwargs.get("preprocessing") is None:
        kwargs["preprocessing"] = [n for n in SHORT_TABLE
                                   if inputs.estimated is not None or not n.startswith(ESTIMATED)]
    table = evaluate(inputs.X, inputs.y, inputs.groups, inputs.failed, inputs.normal, n_pairs=n_pairs,
                     random_state=random_state, progress=progress, estimated=inputs.estimated, **kwargs)
    null_values = {key: np.array(v) for key, v in table.attrs.pop("null_values", {}).items()}
    source = "cell" if null_values else None
    if chance and not null_values:  # the cheapest classifier's cells, each against its own chance level
        columns = list(dict.fromkeys(table.columns.get_level_values(0)))
        judged = CHANCE_CLASSIFIER if CHANCE_CLASSIFIER in columns else columns[0]
        rows = list(table.index)
        measured = row_chance(inputs, rows, n_pairs=n_pairs, random_state=random_state, n_jobs=kwargs.get("n_jobs"),
                              matched=kwargs.get("matched", False), classifier=judged)
        null_values = {f"{judged} {row}": measured[row] for row in rows}
        source = judged
    table = with_verdict(table, null_values)
    table.attrs.update(pairs=len(select_pairs(inputs.failed, inputs.normal, n_pairs, random_state)),
                       chance_source=source, imported=inputs.imported, notes=[dropped] if dropped else [])
    return table


#: What a dataset imported from logs (``faultgen logs import``) can do next, in an analysis's advice.
MEASURED_NEXT = ("label more logs in the logs folder's events.csv (`onset` or `failure` rows for worn axes, `healthy` "
                 "rows for units inspected healthy) and import again, or run `faultgen monitor LOGS --robot ROBOT -o "
                 "OUT` on the folder, which needs no labels (each unit judged against its calibrated twin)")

#: Fewest worn runs (with failed samples) a training set of the stacking classifier needs: its
#: inner cross-validation splits the training runs into folds by run (:func:`analysis.classify.run_folds`),
#: and the base classifiers of a fold need failed samples in the runs outside it.
STACKING_WORN_RUNS = 2


def _without_stacking(path, inputs: ClassificationInputs, kwargs: dict) -> str:
    """Drop the stacking classifier from ``kwargs["classifiers"]`` (default: every classifier)
    when a leave-pair-out training set holds failed samples of fewer than
    :data:`STACKING_WORN_RUNS` runs (its inner folds by run would train on one class: scikit-learn's
    "needs samples of at least 2 classes"); returns the note saying so, "" when kept. Asked for by
    name (``--classifier stacking``) it is refused instead.

    Raises
    ------
    ValueError
        If stacking was asked for by name and cannot be fitted, or it was the only classifier.
    """
    from analysis.classify import CLASSIFIERS

    named = kwargs.get("classifiers")
    classifiers = list(named) if named is not None else list(CLASSIFIERS)
    if "stacking" not in classifiers:
        return ""
    carriers = sorted({g for g, label in zip(inputs.groups, inputs.y, strict=True) if label and g in inputs.failed},
                      key=str)
    if len(carriers) - 1 >= STACKING_WORN_RUNS:  # one worn run is held out with each pair
        return ""
    needs = STACKING_WORN_RUNS + 1
    if inputs.imported:
        what = (f"failed samples (logs labelled worn) in {len(carriers)} unit(s) ({', '.join(map(str, carriers))}); with "
                f"one held out, its inner folds by unit need worn logs of at least {STACKING_WORN_RUNS} other units: "
                f"events.csv needs an `onset` or `failure` row for the worn axis of at least {needs} units in all")
    else:
        what = (f"failed samples in {len(carriers)} worn run(s); with one held out, its inner folds by run need failed "
                f"samples of at least {STACKING_WORN_RUNS} other runs ({needs} worn runs in all)")
    others = [c for c in classifiers if c != "stacking"]
    if named is not None and "stacking" in named or not others:
        raise ValueError(f"{path}: the stacking classifier cannot be fitted here: the dataset has {what}"
                         + (f" ({inputs.imported})" if inputs.imported else "")
                         + "; leave it out (--classifier lr --classifier svm --classifier rf)")
    kwargs["classifiers"] = others
    return f"note: stacking left out: the dataset has {what}."


@dataclass(frozen=True, eq=False)
class ClassificationInputs:
    """What :func:`analysis.classify.evaluate` classifies: features ``X`` (n_samples, 30), the
    estimated quantities (n_samples, 12) or None, 0/1 labels ``y``, the run of each sample
    (``groups``), and the worn (``failed``) and unworn (``normal``) runs."""

    X: np.ndarray
    estimated: np.ndarray | None
    y: np.ndarray
    groups: np.ndarray
    failed: list
    normal: list
    imported: str = ""


def imported_labels(runs) -> str:
    """The labels of a dataset's units imported from logs (``faultgen logs import``), in words:
    logs worn (and in which units), healthy and unknown, from their events (``label``); "" when no
    run is imported."""
    from faultgen.data import logfolder

    measured = [run for run in runs if run.measured]
    if not measured:
        return ""
    worn = healthy = unknown = 0
    worn_units = []
    for run in measured:
        label = run.array("label")
        is_worn = np.any(label == logfolder.WORN, axis=1)
        is_healthy = np.all(label == logfolder.HEALTHY, axis=1)
        worn, healthy = worn + int(is_worn.sum()), healthy + int(is_healthy.sum())
        unknown += int(len(label) - is_worn.sum() - is_healthy.sum())
        if is_worn.any():
            worn_units.append(run.id)
    return (f"labels from events.csv: {worn} logs worn in {len(worn_units)} unit(s)"
            + (f" ({', '.join(worn_units[:6])}{', ...' if len(worn_units) > 6 else ''})" if worn_units else "")
            + f", {healthy} healthy, {unknown} unknown (counted as not worn)")


def classification_inputs(path, wear_threshold: float = 10.0, horizon: int | None = None) -> ClassificationInputs:
    """Table 5.1's features and labels of every run of a dataset (see :func:`classification_table`).

    Raises
    ------
    ValueError
        As :func:`classification_table`.
    """
    if horizon is not None and not is_whole(horizon, 0):
        raise ValueError(f"horizon = {horizon!r}: expected an integer >= 0 (samples before the last one)")
    with opened(path) as data:
        duty = all(run.has(*dataset.DUTY_ARRAYS) for run in data.runs)
        levels = tuple(dataset.DUTY_ARRAYS) if duty else ("mean_abs_torque", "rms_torque")
        names = (*levels, "angle_hist", "speed_hist", "torque_hist", "friction_multiplier")
        records = [(run, {name: run.array(name) for name in names}) for run in data.runs]
        path = data.path
        imported = imported_labels(data.runs)
        fault_levels = {run.id: run.fault_level for run, _ in records if run.fault is not None}
    X, estimated, y, groups, failed, normal = [], [], [], [], [], []
    for run, arrays in records:
        run_id = run.id
        X.append(_table_5_1(arrays, duty))
        if duty:
            estimated.append(np.hstack([arrays["average_speed"], arrays["average_load_torque"]]))
        wear = (arrays["friction_multiplier"].max(axis=1) - 1.0) * 100.0
        if run.fault is not None:  # a fault other than friction wear: its share of the final value
            wear = fault_levels[run_id]
        y.append((wear >= wear_threshold).astype(int))
        if horizon is not None:  # the thesis's window and the robot's state
            n = len(wear)
            if n < horizon + THESIS_WINDOW + 1:
                raise ValueError(f"{path}: run {run_id} has {n} samples; horizon {horizon} needs at least "
                                 f"{horizon + THESIS_WINDOW + 1} (a window of {THESIS_WINDOW + 1} ending {horizon} "
                                 "before the last)")
            keep = slice(n - 1 - horizon - THESIS_WINDOW, n - horizon)
            X[-1] = X[-1][keep]
            if duty:
                estimated[-1] = estimated[-1][keep]
            y[-1] = np.full(THESIS_WINDOW + 1, int(len(run.worn_axes) > 0))
        groups.append(np.full(len(y[-1]), run_id, dtype=object))
        (failed if len(run.worn_axes) else normal).append(run_id)
    widths = {x.shape[1] // 5: g[0] for x, g in zip(X, groups, strict=True)}  # 5 features per axis
    if len(widths) > 1:
        runs = ", ".join(f"{run}: {n} axes" for n, run in sorted(widths.items()))
        raise ValueError(f"{path}: runs of robots with different numbers of axes ({runs}) cannot share one "
                         "classifier, whose features are per axis; classify each robot model's runs apart (e.g. a "
                         "fleet of one --robot)")
    if not failed or not normal:
        if imported:
            raise ValueError(f"{path}: classification needs units with and without logs labelled worn (has "
                             f"{len(failed)} with, {len(normal)} without; {imported}): events.csv needs `onset` or "
                             "`failure` rows for worn units and `healthy` rows for inspected ones")
        raise ValueError(f"{path}: classification needs runs with and without wear (has {len(failed)} worn, "
                         f"{len(normal)} unworn)")
    _check_training_sets(path, y, groups, failed, normal,
                         ("labelled worn by events.csv" if imported else f"true wear >= {wear_threshold:g} %")
                         if horizon is None else f"worn runs' last {THESIS_WINDOW + 1} before the horizon", imported)
    return ClassificationInputs(np.vstack(X), np.vstack(estimated) if duty else None, np.concatenate(y),
                                np.concatenate(groups), failed, normal, imported)


#: Label exchanges of the chance level ``faultgen classify`` measures per row by default: with 19
#: the smallest permutation p-value is 1/20, so a cell can be above chance at the 5 % level.
CHANCE_PERMUTATIONS = 19

#: The classifier whose AUC with exchanged labels is each row's chance level by default: the
#: cheapest (a row costs 19 of its fits per pair, about half the default table's time in all).
CHANCE_CLASSIFIER = "lr"

#: A cell is above chance when its permutation p-value is at most this.
CHANCE_ALPHA = 0.05


def row_chance(inputs: ClassificationInputs, rows: list[str], n_pairs: int | None = 20, random_state: int = 0,
               permutations: int = CHANCE_PERMUTATIONS, n_jobs: int | None = None, matched: bool = False,
               classifier: str = CHANCE_CLASSIFIER) -> dict[str, np.ndarray]:
    """The chance level of each preprocessing row on these robots: the mean leave-pair-out AUC of
    ``classifier`` on ``permutations`` label sets with the runs' roles exchanged
    (:func:`analysis.classify.permuted_roles`), on the same pairs as the table.

    Robots of one kind (process, model) look alike, so chance is not 0.5. It is measured on one
    classifier per row; one that fits runs more closely (rf, stacking) may have a higher chance
    level, which ``faultgen classify --permutations K`` measures cell by cell.

    Returns
    -------
    dict: row -> ndarray of shape (permutations,), the exchanged mean AUCs.
    """
    from analysis.classify import evaluate

    table = evaluate(inputs.X, inputs.y, inputs.groups, inputs.failed, inputs.normal, classifiers=[classifier],
                     preprocessing=rows, estimated=inputs.estimated, n_pairs=n_pairs, random_state=random_state,
                     permutations=permutations, n_jobs=n_jobs, matched=matched)
    return {row: np.array(table.attrs["null_values"][f"{classifier} {row}"]) for row in rows}


def with_verdict(table: pd.DataFrame, null_values: Mapping[str, np.ndarray]) -> pd.DataFrame:
    """``table`` (:func:`analysis.classify.evaluate`) with each cell judged against chance: per
    classifier ``null`` (the mean exchanged AUC), ``p`` (:func:`analysis.classify.null_p_value`
    of the cell's mean AUC against ``null_values["<classifier> <row>"]``) and ``above`` (p at most
    :data:`CHANCE_ALPHA`; None for a classifier without null values: not judged). Without
    ``null_values`` the table is returned as it is (not measured)."""
    from analysis.classify import null_p_value

    if not null_values:
        return table
    out = {}
    for column in dict.fromkeys(table.columns.get_level_values(0)):
        out[column, "mean"], out[column, "std"] = table[column, "mean"], table[column, "std"]
        if f"{column} {table.index[0]}" not in null_values:  # not measured: no verdict, not a False one
            out[column, "null"] = out[column, "p"] = pd.Series(np.nan, index=table.index)
            out[column, "above"] = pd.Series(None, index=table.index, dtype=object)
            continue
        null = {row: null_values[f"{column} {row}"] for row in table.index}
        out[column, "null"] = pd.Series({row: float(np.nanmean(v)) for row, v in null.items()})
        out[column, "p"] = pd.Series({row: null_p_value(table.loc[row, (column, "mean")], null[row])
                                      for row in table.index})
        out[column, "above"] = (out[column, "p"] <= CHANCE_ALPHA).astype(object)
    judged = pd.DataFrame(out, index=table.index)
    judged.columns = judged.columns.set_names(table.columns.names)
    judged.attrs.update(table.attrs, permutations=min(len(v) for v in null_values.values()))
    return judged


def classification_verdict(table: pd.DataFrame, command: str = "faultgen classify FILE") -> str:
    """One line saying whether any judged cell of a :func:`classification_table` is above chance,
    which classifiers were not judged, and when none is above, that its AUCs are no finding and
    what would help."""
    if "above" not in table.columns.get_level_values(-1):
        return (f"verdict: not judged: the chance level was not measured (`{command} --permutations 19` measures it), "
                "so these AUCs cannot be read as better than chance")
    above = table.xs("above", axis=1, level=-1)
    judged = [c for c in above.columns if above[c].notna().all()]
    above = above[judged].astype(bool)
    means, null = table.xs("mean", axis=1, level=-1)[judged], table.xs("null", axis=1, level=-1)[judged]
    unjudged = [c for c in table.columns.get_level_values(0).unique() if c not in judged]
    others = (f"; {', '.join(unjudged)} not judged (their chance level may be higher than {', '.join(judged)}'s: "
              f"`{command} --permutations 19` measures every cell)" if unjudged else "")
    k = int(table.attrs.get("permutations", 0))
    if above.to_numpy().any():
        best = means.where(above).stack().idxmax()
        return (f"verdict: {int(above.to_numpy().sum())} of {above.size} judged cells above chance at the "
                f"{100 * CHANCE_ALPHA:g} % level (best: {best[1]} {best[0]}, AUC {means.loc[best]:.2f} against chance "
                f"{null.loc[best]:.2f}, p {table.loc[best[0], (best[1], 'p')]:.2f}); at {100 * CHANCE_ALPHA:g} % each, "
                f"{CHANCE_ALPHA * above.size:.2g} of {above.size} would pass by chance alone on average{others}")
    reason = (f" (with {k} label exchanges p cannot go below {1 / (k + 1):.2f}: use --permutations 19)"
              if k and 1 / (k + 1) > CHANCE_ALPHA else "")
    return (f"verdict: no judged cell is above chance at the {100 * CHANCE_ALPHA:g} % level{reason}: the AUCs of "
            f"{', '.join(judged)} ({np.nanmin(means.to_numpy()):.2f}-{np.nanmax(means.to_numpy()):.2f}) are what it reaches "
            f"with the runs' labels exchanged (chance {np.nanmin(null.to_numpy()):.2f}-{np.nanmax(null.to_numpy()):.2f}), "
            "so they do not show that worn samples are told from healthy ones. More data would help: "
            + (f"more labelled logs: {MEASURED_NEXT}" if table.attrs.get("imported") else
               "more worn and unworn runs (several seeds: --seed 0 --seed 1 --seed 2, or more robots in a fleet) and "
               "more recorded cycles per run (--record all, more --cycles or --days)") + others)


def classification_printed(table: pd.DataFrame) -> pd.DataFrame:
    """A :func:`classification_table` as ``faultgen classify`` prints it: per classifier mean, std
    and, where judged, p; the chance level (one column when only one classifier or every one
    shares it, else per classifier) and ``above_chance``, the classifiers above chance in the row
    ("none"; the unjudged ones are named in the verdict)."""
    if "above" not in table.columns.get_level_values(-1):
        return table
    classifiers = list(dict.fromkeys(table.columns.get_level_values(0)))
    judged = [c for c in classifiers if table[c, "above"].notna().all()]
    null = table.xs("null", axis=1, level=-1)[judged]
    shared = bool((null.nunique(axis=1) <= 1).all())
    out = {}
    for c in classifiers:
        out[c, "mean"], out[c, "std"] = table[c, "mean"], table[c, "std"]
        if c in judged:
            out[c, "p"] = table[c, "p"]
            if not shared:
                out[c, "chance"] = table[c, "null"]
    if shared:
        out["chance", ""] = null.iloc[:, 0]
    above = table.xs("above", axis=1, level=-1)[judged].astype(bool)
    out["above_chance", ""] = above.apply(lambda row: " ".join(c for c in judged if row[c]) or "none", axis=1)
    return pd.DataFrame(out, index=table.index)


def classification_tidy(table: pd.DataFrame) -> pd.DataFrame:
    """A :func:`classification_table` as a tidy table: one row per (preprocessing, classifier)
    cell, one header row; columns preprocessing, steps (what the combination does, in order),
    classifier, auc_mean, auc_std and, where chance was measured, auc_null (the chance level), p,
    above_chance (p at most :data:`CHANCE_ALPHA`; empty where the cell was not judged: by default
    only each row's lr cell is)."""
    from analysis.classify import describe_preprocessing

    long = table.stack(0, future_stack=True).reset_index()
    long = long.rename(columns={long.columns[1]: "classifier"})
    long = long.rename(columns={"mean": "auc_mean", "std": "auc_std", "null": "auc_null", "above": "above_chance"})
    long.insert(1, "steps", long["preprocessing"].map(describe_preprocessing))
    long.columns.name = None
    return long


def classification_caption(table: pd.DataFrame, *, n_pairs: int | None, horizon: int | None, wear_threshold: float,
                           matched: bool, command: str, short: bool = False) -> str:
    """The caption of a classification table: what the cells are (and over how many held-out pairs,
    as scored: ``attrs["pairs"]``), how samples were labelled, the chance level and how each cell
    is judged against it (per cell, per row on lr, or not measured with the command that measures
    it), why two orders of the same steps are two rows (when both are), and with ``short`` (the
    default rows of ``faultgen classify``) how to get every row."""
    imported = table.attrs.get("imported", "")
    labels = (f"the thesis's window (T-{horizon + 10} to T-{horizon}) labelled by the robot's state" if horizon is not None
              else f"every log labelled worn by events.csv is a failed sample ({imported})" if imported
              else f"every sample labelled failed when its true wear reaches {wear_threshold:g} %")
    pairs = table.attrs.get("pairs", "every" if n_pairs is None else n_pairs)
    parts = [f"Leave-pair-out ROC AUC (mean and std over {pairs} held-out "
             f"(worn, unworn) run pair(s), thesis Procedure 1 and Table 5.2) per preprocessing (rows) and classifier; "
             f"{labels}{'; time-matched (--matched-days)' if matched else ''}."]
    source = table.attrs.get("chance_source")
    k = table.attrs.get("permutations", 0)
    level = f"p at most {CHANCE_ALPHA:g}"
    if source == "cell":
        parts.append(f"Chance level measured per cell: null, the mean AUC with the runs' labels exchanged ({k} times), "
                     f"and p, the permutation p-value of the AUC; above_chance: {level}.")
    elif source is not None:
        parts.append(f"Chance level per row (column chance): the mean AUC of {source} on that row with the runs' "
                     f"labels exchanged {k} times (robots of one kind look alike, so it is not 0.5); p: {source}'s AUC "
                     f"against those {k} exchanged AUCs; above_chance: the classifiers with {level}. The other "
                     f"classifiers are not judged (one that fits runs more closely can have a higher chance level, "
                     f"docs/analysis.md): `{command} --permutations 19` measures every cell.")
    else:
        parts.append(f"Chance level not measured, so no cell can be read as better than chance: "
                     f"`{command} --permutations 19` measures it per cell.")
    if source is not None and k and 1 / (k + 1) > CHANCE_ALPHA:
        parts.append(f"With {k} exchanges p cannot go below {1 / (k + 1):.2f}, so no cell can be above chance at "
                     f"{CHANCE_ALPHA:g}: use --permutations 19 or more.")
    if {"+diff+pca+var3", "+diff+var3+pca"} <= set(table.index):
        parts.append("Token order is step order: +diff+pca+var3 concatenates windows of PCA scores, +diff+var3+pca "
                     "takes PCA of the concatenated windows; the thesis's Table 5.2 lists both.")
    if short:
        parts.append("Rows: each step alone and the fullest combinations; every row of Table 5.2: "
                     f"`{command} --full`.")
    parts += [note.removeprefix("note: ").capitalize() for note in table.attrs.get("notes", [])]
    return " ".join(parts)


def classification_heatmap(table: pd.DataFrame, out: Path) -> Path:
    """PNG heatmap of a classification table's mean AUC (preprocessing x classifier), coloured
    around the chance level (the mean of the measured ones, else 0.5, said in the title), the
    value in each cell, its p and a star where it is above chance, where measured."""
    from matplotlib.colors import TwoSlopeNorm
    from matplotlib.figure import Figure

    means = table.xs("mean", axis=1, level=-1)
    measured = "null" in table.columns.get_level_values(-1)
    centre = float(np.nanmean(table.xs("null", axis=1, level=-1).to_numpy(dtype=float))) if measured else 0.5
    what = "mean of the measured chance levels" if measured else "0.5, chance not measured"
    fig = Figure(figsize=(1.3 * means.shape[1] + 3.2, 0.38 * means.shape[0] + 1.8))
    ax = fig.subplots()
    image = ax.imshow(means.to_numpy(dtype=float), cmap="RdBu_r", aspect="auto",
                      norm=TwoSlopeNorm(vcenter=min(max(centre, 0.01), 0.99), vmin=0.0, vmax=1.0))
    ax.set_xticks(range(means.shape[1]), means.columns)
    ax.set_yticks(range(means.shape[0]), means.index, fontsize=8)
    for i in range(means.shape[0]):
        for j in range(means.shape[1]):
            text = f"{means.iat[i, j]:.2f}"
            if measured:
                column = means.columns[j]
                above, p = table[(column, "above")].iat[i], table[(column, "p")].iat[i]
                if pd.notna(above) and pd.notna(p):  # not judged: None or NaN (NaN is truthy), no p, no star
                    text += f"\np {p:.2f}" + (" *" if bool(above) else "")
            ax.text(j, i, text, ha="center", va="center", fontsize=7)
    fig.colorbar(image, ax=ax, label=f"AUC (white: {centre:.2f}, {what})")
    title = "leave-pair-out AUC per preprocessing and classifier"
    if measured:
        above = int((table.xs("above", axis=1, level=-1) == True).to_numpy().sum())  # noqa: E712 (None: not judged)
        title += f"\n*: above chance (p <= {CHANCE_ALPHA:g}): {above} cells; without p: not judged"
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    return out


def _table_5_1(arrays: dict, duty: bool) -> np.ndarray:
    """A run's control features (n_samples, 30): per axis the speed and torque indicators (with
    ``duty``; else the mean absolute and RMS motor torque) and the KL divergences of the angle,
    speed and torque histograms against the first sample (thesis Table 5.1 without the estimates)."""
    from analysis.features import HistogramKL, duty_indicators

    kl = [HistogramKL(reference="first").fit_transform(arrays[h]) for h in ("angle_hist", "speed_hist", "torque_hist")]
    levels = (duty_indicators(arrays["average_speed"], arrays["average_load_torque"]) if duty
              else (arrays["mean_abs_torque"], arrays["rms_torque"]))
    return np.hstack([*levels, *kl])


#: Columns holding an axis number that may be 0 (undecided) or -1 (too few cycles).
AXIS_COLUMNS = {"predicted", "located_axis"}


#: Fewest samples of each class a training set needs: the stacking classifier's 5-fold
#: cross-validation (:func:`analysis.classify.stacking`) splits each class five ways.
MIN_CLASS_SAMPLES = 5


def _check_training_sets(path, y: list, groups: list, failed: list, normal: list, failed_means: str,
                         imported: str = "") -> None:
    """Refuse a dataset whose leave-pair-out training sets lack a class, saying what it lacks
    (``failed_means``: what makes a sample failed, for the message; ``imported``: the labels of an
    imported dataset, :func:`imported_labels`, named with what events.csv needs)."""
    per_run = {g[0]: (int(labels.sum()), int(len(labels) - labels.sum())) for labels, g in zip(y, groups, strict=True)}
    totals = np.sum(list(per_run.values()), axis=0)
    fewest = min((totals[0] - per_run[f][0] - per_run[n][0], totals[1] - per_run[f][1] - per_run[n][1])
                 for f in failed for n in normal)
    if min(fewest) < MIN_CLASS_SAMPLES and imported:
        raise ValueError(
            f"{path}: its labels are too few for leave-pair-out classification: with one unit with worn logs and one "
            f"without held out, the smallest training set has {fewest[0]} failed samples ({failed_means}) and "
            f"{fewest[1]} normal ones, and the classifiers need at least {MIN_CLASS_SAMPLES} of each ({imported}). "
            "events.csv needs `onset` or `failure` rows for the worn axes of more units (at least 2 with worn logs) "
            "and `healthy` rows for units inspected healthy")
    if min(fewest) < MIN_CLASS_SAMPLES:
        raise ValueError(
            f"{path}: this dataset lacks runs for leave-pair-out classification: with one worn and one unworn run "
            f"held out, the smallest training set has {fewest[0]} failed samples ({failed_means}) "
            f"and {fewest[1]} normal ones, and the classifiers need at least {MIN_CLASS_SAMPLES} of each "
            f"({len(failed)} worn and {len(normal)} unworn runs here). Use `faultgen sweep --preset quick` (18 worn, "
            "3 unworn runs) or a grid with more runs and recorded cycles")


def markdown(table: pd.DataFrame, digits: int = 3) -> str:
    """A DataFrame as a Markdown table (index included unless it is a plain range)."""
    frame = table if isinstance(table.index, pd.RangeIndex) else table.reset_index()
    if isinstance(frame.columns, pd.MultiIndex):  # ("lr", "mean") -> "lr mean"
        frame = frame.set_axis([" ".join(str(p) for p in c if p) for c in frame.columns], axis=1)
    for column in AXIS_COLUMNS & set(frame.columns):  # 0 and -1 are not axes: say what they mean
        frame = frame.assign(**{column: frame[column].map(axis_label)})
    cells = [[f"{v:.{digits}g}" if isinstance(v, float) else str(v) for v in row] for row in frame.itertuples(index=False)]
    head = [str(c) for c in frame.columns]
    return "\n".join(["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
                     + ["| " + " | ".join(row) + " |" for row in cells])


def write_outputs(table: pd.DataFrame, stem: Path, text: str | None = None) -> list[Path]:
    """Write ``table`` as ``<stem>.csv`` and ``text`` (default: the table) as ``<stem>.md``."""
    stem = Path(stem)
    csv, md = stem.with_suffix(".csv"), stem.with_suffix(".md")
    from faultgen.data import cells

    cells.escaped(table).to_csv(csv, index=not isinstance(table.index, pd.RangeIndex))
    md.write_text((text or markdown(table)) + "\n")
    return [csv, md]
