"""What the classifiers of thesis ch. 5 see of a dataset: Table 5.1's features and the labels of every
run (or the thesis's window before the horizon), and the check that every leave-pair-out training set
holds both classes."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.benchmark.truth import opened
from faultgen.checks import is_whole
from faultgen.data import dataset

#: Samples the thesis's classifiers saw per robot before its prediction horizon (ch. 5.3.3: "T-13
#: to T-3" for a horizon of 3 days, T the failure day).
THESIS_WINDOW = 10


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


def _table_5_1(arrays: dict, duty: bool) -> np.ndarray:
    """A run's control features (n_samples, 30): per axis the speed and torque indicators (with
    ``duty``; else the mean absolute and RMS motor torque) and the KL divergences of the angle,
    speed and torque histograms against the first sample (thesis Table 5.1 without the estimates)."""
    from analysis.features import HistogramKL, duty_indicators

    kl = [HistogramKL(reference="first").fit_transform(arrays[h]) for h in ("angle_hist", "speed_hist", "torque_hist")]
    levels = (duty_indicators(arrays["average_speed"], arrays["average_load_torque"]) if duty
              else (arrays["mean_abs_torque"], arrays["rms_torque"]))
    return np.hstack([*levels, *kl])


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
