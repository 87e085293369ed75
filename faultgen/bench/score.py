"""``faultgen bench score``: one score for anyone's detector or isolator on a track's test units.

The method learns from ``train.h5`` only and is shown the records of ``test.h5`` (no labels);
``test_labels.csv`` is read afterwards, by this module, to score its answers.

**Detector** (``--detector mod:Class``, the contract of ``faultgen detect``, :mod:`analysis.plugins`,
or a baseline): per robot and task of the test units, a new estimator learns the train units of
that robot and task: a scikit-learn classifier (``sklearn.base.is_classifier``) ``fit(X, y)`` on
all their records with ``y`` = 1 where the record's fault level is >= 10 % (Table 5.2's rule),
any other estimator ``fit(X)`` on the records of the healthy ones. X holds, per record, the per-axis
features of :data:`faultgen.bench.files.FEATURES` (shape (n_records, 4 N)). Then for each test
unit, its score per record (``decision_function``, else ``predict_proba[:, 1]``, else the alarms;
larger: more likely faulty) and its alarms (``predict``).

- **AUROC** of the scores: positives the records whose fault level is >= 10 %, negatives those at
  0 % (records in between are left out); chance 0.5.
- **False-alarm rate**: the share of alarmed records of the healthy test units.
- **Detection at 5 % false alarms**: the share of worn records (>= 10 %) whose score exceeds the
  threshold that 5 % of the healthy test units' records exceed (the ROC curve of worn records
  against the healthy units' records at a false-positive rate of :data:`FAR`, interpolated between
  its points: a random threshold between two scores); chance 5 %.
- **Detection delay**: per failing unit, the onset (the first of 3 alarms in a row,
  :func:`analysis.monitoring.detect_onset`, as ``faultgen detect``, but looked for from the first
  record: :data:`RULES`) minus the record where the fault
  starts, and minus the record where it reaches 10 %, in cycles (days for daily records); the
  median over the units detected, and the share detected. The share's chance (:func:`_chance_share`)
  is the larger of the share a detector alarming at random at the false-alarm rate detects
  (:func:`faultgen.bench.verdicts.chance_detected`, per unit by its records) and the share of
  healthy units where the method's own alarms make an onset; ``detected_minus_chance`` is the
  difference, bootstrapped with the false-alarm rate, and ``chance_range95`` the central 95 % of
  the share a detector detecting each unit with that chance gets on this many units
  (:func:`faultgen.bench.verdicts.chance_range`).

**Isolator** (``--isolator``, the contract of ``bench-isolators``): ``fit(X)`` on each failing test
unit's per-cycle mean absolute motor torque (n_records, N) names a source axis (0: undecided). Its
**top-1 accuracy** is the share naming the worn axis; chance 1/N. On the healthy units, the share
left undecided is reported beside it. An isolator that also sets ``fault_`` (a fault name of the
labels: "friction_wear", "backlash", "cogging") is scored on it too on a track with several fault
types (the faults track): ``fault_type_accuracy``, chance 1 / the number of fault types.

The onset, false-alarm rate, share detected, delays and top-1 accuracy are computed by
:mod:`analysis.scoring`, the one scoring path ``faultgen detect`` and ``bench-isolators`` use too,
under :data:`RULES` (:data:`analysis.scoring.BENCH_RULES`; why they differ from ``detect``'s: that
module's docstring).

Every figure has a 95 % percentile bootstrap interval over test units (:data:`RESAMPLES`
resamples of the units with replacement, seed 0), and its verdict against its chance level
(:mod:`faultgen.bench.verdicts`): above, at or below chance. An isolator whose need of records
(:func:`faultgen.bench.verdicts.records_needed`) the track's units do not meet gets a warning in
``results["warnings"]``.
"""

from __future__ import annotations

import datetime
import json
import warnings
from pathlib import Path

import numpy as np
from sklearn.metrics import roc_auc_score, roc_curve

from analysis import scoring
from analysis.classify.roc import binary_auc
from analysis.evaluate import Data, OwnHistory, TrackSplit, evaluate
from faultgen.bench import files, verdicts
from faultgen.data import atomic

RESAMPLES = 1000
WORN_PCT = 10.0
#: The rules every figure is scored by (:data:`analysis.scoring.BENCH_RULES`: the onset from the first
#: record, the healthy units' records pooled, 3 alarms in a row, "too few cycles" undecided).
RULES = scoring.BENCH_RULES
#: The false-alarm rate at which the detection rate is read (a share of the healthy units' records).
FAR = 0.05


def _interval(units: list, statistic, seed: int = 0) -> list[float]:
    """95 % percentile bootstrap interval of ``statistic(units)`` over resampled units ([nan, nan]
    when no resample gives a finite value)."""
    rng = np.random.default_rng(seed)
    values = []
    for _ in range(RESAMPLES):
        sample = [units[i] for i in rng.integers(len(units), size=len(units))]
        value = statistic(sample)
        if np.isfinite(value):
            values.append(value)
    if not values:
        return [float("nan"), float("nan")]
    return [float(np.percentile(values, 2.5)), float(np.percentile(values, 97.5))]


def _figure(units: list, statistic, chance: float | None = None) -> dict:
    value = statistic(units) if units else float("nan")
    out = {"value": float(value), "ci95": _interval(units, statistic) if units else [float("nan")] * 2,
           "units": len(units)}
    if chance is not None:
        out["chance"] = chance
    return out


def _auroc(units: list) -> float:
    scores = np.concatenate([u["scores"][u["mask"]] for u in units])
    labels = np.concatenate([u["positive"][u["mask"]] for u in units])
    if labels.all() or not labels.any():
        return float("nan")
    if not np.isfinite(scores).all():  # scikit-learn's own error, naming what is wrong
        return float(roc_auc_score(labels, scores))
    return binary_auc(labels, scores)  # roc_auc_score's float without its checks: 1000 bootstrap resamples


def _roc(truth: np.ndarray, scores: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``roc_curve(truth, scores, drop_intermediate=False)``'s false- and true-positive rates, the
    same floats, by scikit-learn's steps (1.6-1.9) without its input checks (the bootstrap calls it
    1000 times on arrays :func:`_detection_at_far` checked): the scores in descending order, the
    positives and negatives counted up to the last row of each distinct score (whole numbers, exact
    whatever the order within ties), a point (0, 0) first, each count divided by its total.
    ``truth``: 0/1, both present; ``scores``: finite."""
    order = np.argsort(scores, kind="stable")[::-1]
    ranked = scores[order]
    ends = np.append(np.flatnonzero(np.diff(ranked)), ranked.size - 1)
    tps = np.cumsum(truth[order].astype(float))[ends]
    fps = 1 + ends.astype(float) - tps
    return np.append(0.0, fps) / fps[-1], np.append(0.0, tps) / tps[-1]


def _detection_at_far(units: list) -> float:
    """Share of worn records (>= 10 %) of the failing units alarmed at the threshold that a share
    :data:`FAR` of the healthy units' records exceed (the ROC curve at that false-positive rate,
    linear between its points: ties broken at random); NaN without both kinds of record."""
    healthy = [u["scores"] for u in units if u["unit"].fault == "none"]
    worn = [u["scores"][u["positive"]] for u in units if u["unit"].fault != "none"]
    negatives = np.concatenate(healthy) if healthy else np.zeros(0)
    positives = np.concatenate(worn) if worn else np.zeros(0)
    if not negatives.size or not positives.size:
        return float("nan")
    truth = np.concatenate((np.zeros(negatives.size), np.ones(positives.size)))
    scores = np.concatenate((negatives, positives))
    if np.isfinite(scores).all():
        fpr, tpr = _roc(truth, scores)
    else:  # scikit-learn's own error, naming what is wrong
        fpr, tpr, _ = roc_curve(truth, scores, drop_intermediate=False)
    last = np.append(np.diff(fpr) > 0, True)  # per false-positive rate its highest true-positive rate
    return float(np.interp(FAR, fpr[last], tpr[last]))


def _detected_minus_chance(units: list) -> float:
    """Share of failing units detected minus its chance, :func:`_chance_share` (NaN without both
    healthy and failing units)."""
    failing = [u for u in units if u["unit"].fault != "none"]
    chance = _chance_share(units)
    return scoring.detected_share([u["detected"] for u in failing]) - chance if np.isfinite(chance) else float("nan")


def _chance_share(units: list, parts: bool = False):
    """The share of failing units a detector "detects" by chance: the larger of (a) the share a
    detector alarming on each record independently at the healthy units' false-alarm rate detects
    (:func:`faultgen.bench.verdicts.chance_detected`, per failing unit by its records) and (b) the
    share of healthy units in which the detector's own alarms make an onset (its false alarms come
    in runs). With ``parts``: (chance, a, b). NaN without both healthy and failing units."""
    healthy = [u for u in units if u["unit"].fault == "none"]
    failing = [u for u in units if u["unit"].fault != "none"]
    if not healthy or not failing:
        return (float("nan"),) * 3 if parts else float("nan")
    rate = scoring.false_alarm_rate([u["alarms"] for u in healthy], RULES)
    random = float(np.mean(verdicts.chance_detected([len(u["alarms"]) for u in failing], rate, RULES.persistence)))
    own = scoring.detected_share([u["detected"] for u in healthy])
    return (max(random, own), random, own) if parts else max(random, own)


def detector_results(method, name: str, train: list[files.Unit], test: list[files.Unit]) -> dict:
    """Fit ``method`` per robot and task on ``train`` (labelled units) and judge ``test`` (units whose
    labels :func:`faultgen.bench.files.attach_labels` added; the method never sees them)."""
    units = [*train, *test]
    data = Data.of_units([u.features() for u in units], [f"{k}:{u.id}" for k, u in enumerate(units)],
                         [u.fault_level >= WORN_PCT for u in units], [u.fault == "none" for u in units])
    sizes = [len(u.fault_level) for u in units]
    protocol = TrackSplit(np.repeat([k >= len(train) for k in range(len(units))], sizes),
                          np.repeat([f"{u.robot}/{u.task}" for u in units], sizes))
    scores = evaluate(method, data, protocol, RULES, name)  # per robot and task: fit on train, judge test
    judged = []
    for setup in sorted({(u.robot, u.task) for u in test}):  # the units in the order the folds tested them
        for k, unit in ((k, u) for k, u in enumerate(test, len(train)) if (u.robot, u.task) == setup):
            unit_scores, alarms = scores.of(data.rows(f"{k}:{unit.id}"))
            level = unit.fault_level
            judged.append({"unit": unit, "scores": unit_scores, "alarms": alarms, "positive": level >= WORN_PCT,
                           "mask": (level >= WORN_PCT) | (level <= 0)})
    delays = []
    for row in judged:
        unit = row["unit"]
        start = scoring.fault_start(unit.fault_level)  # the onset is looked for from the first record (RULES)
        onset = scoring.onset(row["alarms"], RULES, fault_start=start)
        row["detected"] = onset is not None
        if unit.fault == "none":
            continue
        cycles = unit.arrays["cycles"]
        delays.append({
            "unit": unit.id, "detected": onset is not None,
            "after_start": scoring.delay(onset, cycles, start),
            "after_10pct": scoring.delay(onset, cycles, scoring.first_reaching(unit.fault_level, WORN_PCT))})
    healthy = [r for r in judged if r["unit"].fault == "none"]

    def median(key):
        return lambda rows: float(np.nanmedian([r[key] for r in rows])) if any(
            np.isfinite(r[key]) for r in rows) else float("nan")

    sample = test[0].sample if test else "cycle"
    far = _figure(healthy, lambda rows: scoring.false_alarm_rate([r["alarms"] for r in rows], RULES))
    detected = _figure(delays, lambda rows: scoring.detected_share([r["detected"] for r in rows]))
    detected["chance"], detected["chance_random_alarms"], detected["healthy_units_detected"] = _chance_share(
        judged, parts=True)
    detected["chance_range95"] = verdicts.chance_range(len(delays), detected["chance"])
    return {
        "auroc": _figure(judged, _auroc, chance=0.5),
        "false_alarm_rate": far,
        "detection_at_5pct_far": _figure(judged, _detection_at_far, chance=FAR),
        "detected_share": detected,
        "detected_minus_chance": _figure(judged, _detected_minus_chance, chance=0.0),
        f"delay_after_start_{sample}s": _figure(delays, median("after_start")),
        f"delay_after_10pct_{sample}s": _figure(delays, median("after_10pct")),
        "per_unit": [{k: v for k, v in d.items()} for d in delays],
    }


def isolator_results(method, name: str, test: list[files.Unit]) -> dict:
    """Each test unit's source axis (and fault, if the isolator names one) from ``method`` fitted on
    its mean absolute motor torque."""
    ids = [f"{k}:{unit.id}" for k, unit in enumerate(test)]
    data = Data.of_units([unit.arrays["mean_abs_torque"] for unit in test], ids)
    scores = evaluate(method, data, OwnHistory([(i, None) for i in ids]), RULES, name, role="isolator")
    answers = [{"unit": unit.id, "worn_axis": unit.worn_axis, "named": axis, "n_axes": unit.n_axes,
                "fault": unit.fault, "named_fault": None if fault is None else str(fault)}
               for unit, (axis, fault) in zip(test, scores.named)]
    failing = [a for a in answers if a["worn_axis"]]
    healthy = [a for a in answers if not a["worn_axis"]]
    n_axes = max((a["n_axes"] for a in answers), default=6)
    out = {
        "top1_accuracy": _figure(failing, lambda rows: scoring.top1_accuracy(
            [r["named"] for r in rows], [r["worn_axis"] for r in rows], RULES), chance=1.0 / n_axes),
        # a healthy unit's true axis is none: its top-1 accuracy is the share left undecided
        "undecided_on_healthy": _figure(healthy, lambda rows: scoring.top1_accuracy(
            [r["named"] for r in rows], [scoring.UNDECIDED] * len(rows), RULES)),
    }
    need = verdicts.records_needed(method)
    records = sorted(len(unit.arrays["mean_abs_torque"]) for unit in test)
    if need is not None and records and records[0] < need[0]:
        span = f"{records[0]}" if records[0] == records[-1] else f"{records[0]}-{records[-1]}"
        out["warnings"] = [f"the track's units have {span} records; {name} needs at least {need[0]} ({need[1]}): "
                           "its figure here says nothing"]
    kinds = sorted({a["fault"] for a in failing})
    if len(kinds) > 1 and any(a["named_fault"] is not None for a in answers):  # the faults track: which fault
        out["fault_type_accuracy"] = _figure(
            failing, lambda rows: float(np.mean([r["named_fault"] == r["fault"] for r in rows])), chance=1.0 / len(kinds))
    return {**out, "per_unit": answers}


def score(folder: str | Path, method, name: str, role: str, track: str | None = None,
          allow_modified: bool = False) -> dict:
    """Score ``method`` (an unfitted estimator in ``role`` "detector" or "isolator") on the benchmark
    files in ``folder``; returns the results (the JSON :func:`write` writes), with ``comparable``:
    whether the folder equals its track version's frozen manifest (:func:`faultgen.bench.make.compare`).

    ``allow_modified``: score a folder that differs from the frozen manifest anyway, its results
    marked not comparable (``comparable`` False, ``modified``: the differing files and arrays, named
    in the verdict lines).

    Raises
    ------
    ValueError
        If the folder's files are missing, leave the folder or are not benchmark files (links to other
        files, declared shapes, missing attributes: :func:`faultgen.bench.files.read_with_attrs`,
        :func:`faultgen.bench.files.attach_labels`), are of another track than ``track``, or, without
        ``allow_modified``, differ from the track version's frozen manifest (naming the file and array).
    """
    from faultgen.bench import make

    folder = Path(folder)
    train = files.read(folder / "train.h5")
    test, made = files.read_with_attrs(folder / "test.h5", ("track", "version", "size"))
    if track is not None and made.get("track") != track:
        raise ValueError(f"{folder} holds track {made.get('track')!r}, not {track!r}")
    checked = make.compare(folder, made, allow_modified)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # convergence and constant-feature warnings of baselines
        if role == "detector":
            labelled = files.attach_labels(test, folder / "test_labels.csv")
            results = detector_results(method, name, train, labelled)
        else:
            results = isolator_results(method, name, files.attach_labels(test, folder / "test_labels.csv"))
    return {"method": name, "role": role, **{k: str(v) for k, v in made.items()}, **checked,
            "date": datetime.date.today().isoformat(), "resamples": RESAMPLES, "results": results}


def _cell(figure: dict, scale: float = 100.0, digits: int = 1) -> str:
    """'value [low, high]' of a figure, times ``scale`` (100: a share in %), "-" when undefined."""
    value, (low, high) = figure["value"] * scale, (x * scale for x in figure["ci95"])
    if not np.isfinite(value):
        return "-"
    return f"{value:.{digits}f} [{low:.{digits}f}, {high:.{digits}f}]"


#: The columns of a leaderboard row (docs/leaderboard.md), header and separator.
HEADER = ("| track | method | AUROC [95 % CI] | false alarms % | detection % at 5 % false alarms (chance 5) | "
          "detected % (chance at the false-alarm rate) | delay after 10 % wear | isolation top-1 % | verdict | "
          "command | date |")
SEPARATOR = "|" + " --- |" * HEADER.count(" | ") + " --- |"


def _escaped(cell: str) -> str:
    """A table cell's text with its pipes escaped (a pipe, even in a code span, ends a cell)."""
    return cell.replace("|", "\\|")


def markdown_row(results: dict, command: str) -> str:
    """One row of the leaderboard (docs/leaderboard.md) for ``results``: the cells of :data:`HEADER`."""
    r = results["results"]
    track = f"{results.get('track')} v{results.get('version')}" + (f" ({results['size']})" if results.get("size") != "full" else "")
    if results["role"] == "detector":
        delay = next(v for k, v in r.items() if k.startswith("delay_after_10pct"))
        detected = _cell(r["detected_share"])
        if detected != "-" and np.isfinite(r["detected_share"]["chance"]):
            detected += f" (chance {100 * r['detected_share']['chance']:.1f})"
        cells = [_cell(r["auroc"], scale=1.0, digits=3), _cell(r["false_alarm_rate"]),
                 _cell(r["detection_at_5pct_far"]), detected, _cell(delay, scale=1.0), "-"]
    else:
        cells = ["-"] * 5 + [_cell(r["top1_accuracy"]) + f" (chance {100 * r['top1_accuracy']['chance']:.1f})"]
        if "fault_type_accuracy" in r:
            cells[-1] += (f"; fault type {_cell(r['fault_type_accuracy'])} "
                          f"(chance {100 * r['fault_type_accuracy']['chance']:.1f})")
    cells = [track, results["method"], *cells, verdicts.summary(results), f"`{command}`", results["date"]]
    return "| " + " | ".join(_escaped(c) for c in cells) + " |"


def markdown(results: dict, command: str) -> str:
    """``OUT.md``: a Markdown table (:data:`HEADER`, :data:`SEPARATOR`, the row) and below it one
    line per figure with its verdict (:func:`faultgen.bench.verdicts.lines`), warnings first."""
    lines = "\n".join(f"- {line}" for line in verdicts.lines(results))
    return f"{HEADER}\n{SEPARATOR}\n{markdown_row(results, command)}\n\n{lines}\n"


def write(results: dict, out: str | Path, command: str) -> tuple[Path, Path]:
    """``OUT.json`` (the results and the verdict lines) and ``OUT.md`` (:func:`markdown`), as one set."""
    out = Path(out)
    json_path, md_path = out.with_name(out.name + ".json"), out.with_name(out.name + ".md")
    with atomic.output_set([json_path, md_path]) as staged:
        staged(json_path).write_text(json.dumps({**results, "verdicts": verdicts.lines(results), "command": command},
                                                indent=1, default=_plain) + "\n")
        staged(md_path).write_text(markdown(results, command))
    return json_path, md_path


def _plain(value):
    if isinstance(value, (np.integer, np.bool_)):
        return value.item()
    if isinstance(value, np.floating):
        return float(value)
    raise TypeError(f"{type(value).__name__} is not JSON")
