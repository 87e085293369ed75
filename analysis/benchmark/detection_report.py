"""A detection table (:mod:`analysis.benchmark.detection`) in words: what its columns mean (simulated or
imported), what the false-alarm rate measured under each protocol, the summary per task and axis, and
the advice that fits its dataset."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import numpy as np
import pandas as pd

from analysis import isolation, scoring
from analysis.benchmark.tables import MEASURED_NEXT, TOO_FEW_CYCLES, UNDECIDED, markdown

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
    notes += _learned_fault_notes(table, imported, seeds)
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
    notes += _location_notes(table, imported)
    noisy = table[table["alarms_before_fault_pct"] >= 50]
    if len(noisy):
        notes.append(f"note: {len(noisy)} of {len(table)} runs alarm on at least half of their samples before the "
                     + ("first log labelled worn" if imported else "fault begins") + " (alarms_before_fault_pct): the monitor does not describe their healthy operation, so their "
                     "detections say little")
    return "\n".join(notes)


def _learned_fault_notes(table: pd.DataFrame, imported: bool, seeds: str) -> list[str]:
    """The note on runs left out of :func:`detection_advice`'s summary because their monitor learned
    the fault (trained_on_fault), with a remedy (``seeds``: how to sweep the grid with several seeds);
    none if there are none."""
    notes = []
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
    return notes


def _location_notes(table: pd.DataFrame, imported: bool) -> list[str]:
    """The note on why no detected run of :func:`detection_advice`'s table was located (too few samples
    before the onset, undecided, another axis); none if one was located or none was detected."""
    notes = []
    counted = table[~table["trained_on_fault"]] if "trained_on_fault" in table else table
    detected = counted[counted["detected"]]
    if len(detected) and not detected["located"].astype(bool).any() and table.attrs.get("locate") == "contribution":
        notes.append(f"note: located_pct is 0 (of {len(detected)} detected runs): the largest contribution to the "
                     "monitor's Q and T2 at the alarm was another axis's, or tied")
    elif len(detected) and not detected["located"].astype(bool).any():  # located_pct 0: say why
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
    return notes


def location_verdict(table: pd.DataFrame) -> str:
    """The share of detected runs (those the summary counts) located at their worn axis, against naming
    one of the robot's N axes at random (1/N; N from the table's ``n_axes`` attribute, else the
    largest worn axis): a one-sided binomial test at 5 %, and its verdict."""
    from scipy.stats import binomtest

    counted = table[~table["trained_on_fault"]] if "trained_on_fault" in table else table
    detected = counted[counted["detected"].astype(bool)] if len(counted) else counted
    method = table.attrs.get("locate", "cross-correlation")
    if not len(detected):
        return f"location ({method}): no detected run to locate"
    n_axes = int(table.attrs.get("n_axes") or table["worn_axis"].max())
    located = int(detected["located"].astype(bool).sum())
    p = binomtest(located, len(detected), 1.0 / n_axes, alternative="greater").pvalue
    verdict = "above chance" if p < 0.05 else "not above chance"
    return (f"location ({method}): {located} of {len(detected)} detected runs located at the worn axis "
            f"({100.0 * located / len(detected):.1f} %) against {100.0 / n_axes:.1f} % naming one of {n_axes} axes "
            f"at random (binomial p = {p:.2g}): {verdict}")


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


def detection_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per task and per worn axis (and over all): runs counted, left_out (runs whose monitor learned
    the fault as normal, ``trained_on_fault``: their detections say nothing, so none of the other
    columns rests on them), mean false-alarm rate (%), share detected (%), median onset cycle and
    true wear at detection (%), share located (%)."""
    def percent(flags):
        return 100.0 * flags.mean() if len(flags) else np.nan

    def detected(flags):  # the share of worn runs with an onset (analysis.scoring)
        return 100.0 * scoring.detected_share(flags)

    learned = table["trained_on_fault"].astype(bool) if "trained_on_fault" in table else pd.Series(False, table.index)
    aggregate = dict(runs=("run", "size"), false_alarm_pct=("false_alarm_pct", "mean"),
                     detected_pct=("detected", detected), median_onset_cycle=("onset_cycle", "median"),
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


def detection_text(table: pd.DataFrame, summary: pd.DataFrame, protocol: str = "auto") -> str:
    """What ``faultgen detect`` prints of a :func:`detection_table` and its :func:`detection_summary`: the
    table, what its columns mean, the summary with what its false-alarm rate measured (and the runs
    left out of it), and :func:`detection_advice` (``protocol``: the one asked for)."""
    lines = [markdown(table, digits=4),
             "\n".join(f"  {name}: {meaning}" for name, meaning in detection_columns(table).items())]
    left_out = int(table["trained_on_fault"].sum()) if "trained_on_fault" in table else 0
    rests = (f"of {len(table) - left_out} of {len(table)} runs: {left_out} left out, their monitor learned the fault; "
             if left_out else "")
    lines.append(f"\nsummary ({rests}false_alarm_pct, %: {false_alarm_meaning(table['protocol'])}):")
    lines.append(markdown(summary, digits=4))
    lines.append(location_verdict(table))
    advice = detection_advice(table, protocol)
    if advice:
        lines.append(advice)
    return "\n".join(lines)
