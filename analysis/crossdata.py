"""Train on one dataset, test on another: the ``--train OTHER.h5`` of ``faultgen detect``,
``classify`` and ``bench-isolators``.

Where a monitor learns "normal" from is the question of thesis ch. 4. Every output names its
protocol (:data:`OWN`, :data:`OTHER`, :data:`TWIN`):

- **own history**: each unit learns from its own first records (ch. 4 one-to-one, OTO); the
  commands without ``--train`` (detect's ``first-cycles``, and its other protocols within one dataset);
- **another dataset**: the model learns from the healthy units of ``--train`` (ch. 4 one-to-many,
  OTM, across datasets: nominal simulated data for measured logs, one fleet for another);
- **the twin**: ``--train`` is the simulated wear of a calibrated twin of the tested units (a
  dataset whose ``grid`` JSON has a ``twin`` table, written by ``faultgen monitor``).

**Comparable features.** Both datasets must hold the features the method reads, in the same units
(the stored ``units`` attributes), for robots with the same axes, joint ranges, speed limits
(``tasks.toml`` ``[limits]``) and peak motor torques: the design ranges of the 12-bin histograms
(:func:`check_comparable`), as each run stored them (:attr:`faultgen.data.reader.Run.limits` and
:attr:`~faultgen.data.reader.Run.drivetrain`: no robot's files are read). A simulated dataset and an
import of the same robot's logs are.

**Per-unit normalisation** (ch. 4: one robot's raw signal says more about its task than about
its condition; the thesis differenced it, here each unit is referred to its own start): every
unit's features, training and tested alike, are centred and scaled by their mean and standard
deviation over the unit's own first ``baseline`` records (:func:`unit_normalised`), which must be
healthy; what the model learns is then how a unit moves away from its own start.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from tqdm.auto import tqdm

from analysis import isolation, registry, scoring
from analysis.benchmark.detection import locate_onset
from analysis.benchmark.truth import fault_progress, opened
from analysis.evaluate import Data, TrackSplit, evaluate
from analysis.features import kl_divergence
from analysis.monitoring import fit_q_monitor, reconstruction_contributions, varying_columns
from faultgen.data import reader

OWN, OTHER, TWIN = "own history", "another dataset", "the twin"
#: The stored per-record arrays the methods read, whose units both datasets must share.
FEATURES = ("mean_abs_torque", "torque_hist", "angle_hist", "speed_hist")


def protocol(train: reader.Dataset, baseline: int) -> str:
    """The protocol line of a model trained on ``train``: :data:`TWIN` or :data:`OTHER`, the file and
    the normalisation."""
    kind = TWIN if isinstance(train.grid, dict) and "twin" in train.grid else OTHER
    return (f"{kind} ({train.path.name}), each unit's features centred and scaled by its own first {baseline} "
            "records")


def _robot_ranges(run: reader.Run) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
    """The axes, joint range (N, 2) rad, speed limit (N,) rad/s and peak motor torque (N,) N m a run
    stored of its robot."""
    drive, limits = run.drivetrain, run.limits
    return drive.n_axes, limits.joint_range, limits.velocity, drive.motor_torque_limit


def check_comparable(train: reader.Dataset, test: reader.Dataset) -> None:
    """Refuse two datasets whose features do not compare (module docstring).

    Raises
    ------
    ValueError
        Naming the robots and what differs (axes, joint range, speed limit, peak motor torque), or
        the array and its units in each file; or a file written before its runs stored their limits
        whose robot cannot be loaded on this machine.
    """
    ranges = {}  # (robot, model digest) -> what its first run in train, else in test, stored of it
    for data in (train, test):
        first = {}
        for run in data.runs:
            first.setdefault((run.robot, run.model_sha256), run)
        for key in sorted(first):
            if key not in ranges:
                try:
                    ranges[key] = _robot_ranges(first[key])
                except ValueError as err:
                    raise ValueError(f"{data.path}: robot {key[0]!r} of its runs cannot be loaded to check that its "
                                     f"features compare: {err}") from None
    first = next(iter(ranges))
    what = ("axes", "joint range", "speed limit (tasks.toml [limits])", "peak motor torque")
    for key, values in ranges.items():
        for label, a, b in zip(what, ranges[first], values, strict=True):
            if not np.allclose(a, b, rtol=1e-9, atol=0):
                models = "" if key[0] != first[0] else f" (models {first[1][:12]} and {key[1][:12]})"
                raise ValueError(f"robots {first[0]!r} and {key[0]!r}{models} of {train.path} and {test.path} differ in "
                                 f"their {label} "
                                 f"({np.round(a, 4).tolist()} against {np.round(b, 4).tolist()}): their histograms "
                                 "do not share bins, so a model of one does not judge the other")
    for name in FEATURES:
        units = {}
        for data in (train, test):
            for run in data.runs:
                if not run.has(name):
                    raise ValueError(f"{data.path}: run {run.id} has no {name}; both datasets need it")
                units.setdefault(run.units(name), data.path)
        if len(units) > 1:
            raise ValueError(f"{name} is in different units: " + ", ".join(f"{u!r} in {p}" for u, p in units.items()))


def unit_normalised(X: np.ndarray, baseline: int) -> np.ndarray:
    """``X`` (n_records, n_features) centred and scaled by its first ``baseline`` rows' mean and
    sample standard deviation (a feature constant there is scaled by the largest of 1e-9 of its
    largest magnitude and 1e-12, so it does not divide by zero)."""
    X = np.asarray(X, dtype=float)
    start = X[:baseline]
    spread = start.std(axis=0, ddof=1) if len(start) > 1 else np.zeros(X.shape[1])
    floor = np.maximum(1e-9 * np.abs(X).max(axis=0, initial=0.0), 1e-12)
    return (X - start.mean(axis=0)) / np.maximum(spread, floor)


def unit_detection_features(run: reader.Run, baseline: int) -> np.ndarray:
    """A unit's detection features (n_records, N): the KL divergence of each record's 12-bin |motor
    torque| histogram (``torque_hist``, stored alike by every dataset) from the mean histogram of its
    first ``baseline`` records (thesis ch. 3.4), :func:`unit_normalised`."""
    hist = run.array("torque_hist")
    kl = kl_divergence(hist, hist[:baseline].mean(axis=0)[None])
    return unit_normalised(kl, baseline)


def _long_enough(runs, baseline: int, path, what: str) -> list[reader.Run]:
    chosen = [run for run in runs if len(run.recorded) > baseline]
    if not chosen:
        raise ValueError(f"{path}: no {what} with more than {baseline} records (the baseline each unit is referred "
                         "to); give a smaller --first, or record longer")
    return chosen


def detection_across(test, train, *, first: int = 20, variance: float = 0.75, alpha: float = 0.05,
                     persistence: int = 3, limit_folds: int | None = 20, detector=None,
                     progress: bool = True) -> tuple[pd.DataFrame, dict]:
    """:func:`analysis.benchmark.detection_table`'s table and charts for a PCA monitor (or
    ``detector``) learnt from the healthy runs of ``train`` and applied to every run of ``test``
    with one worn axis, features per unit normalised (module docstring; ``first`` records of each
    unit are its baseline, not tested). False alarms: the share of alarm records of ``test``'s
    healthy runs after their baseline.

    Raises
    ------
    ValueError
        If the datasets do not compare (:func:`check_comparable`), ``train`` has no healthy run or
        a tested run is no longer than its baseline.
    """
    with opened(test) as data, opened(train) as source:
        check_comparable(source, data)
        label = protocol(source, first)
        learnt = _long_enough(source.healthy, first, source.path, "run without wear")
        normal = [unit_detection_features(run, first) for run in learnt]
        used = varying_columns(np.vstack(normal))
        rules = scoring.DETECT_RULES.with_persistence(persistence)  # as detect's: from the fault's first sample
        judged = [run for run in data.healthy if len(run.recorded) > first]
        worn = [r for r in data.runs if len(r.worn_axes) == 1]
        for run in worn:
            _long_enough([run], first, data.path, f"tested run ({run.id})")
        # one track split: the healthy runs of train learnt, the healthy runs of test after their baseline and
        # the worn runs whole tested, each run on its own (analysis.evaluate)
        units = ([x[:, used] for x in normal] + [unit_detection_features(r, first)[first:, used] for r in judged]
                 + [unit_detection_features(r, first)[:, used] for r in worn])
        ids = [f"train/{r.id}" for r in learnt] + [f"healthy/{r.id}" for r in judged] + [f"worn/{r.id}" for r in worn]
        records = Data.of_units(units, ids, healthy_units=[True] * (len(learnt) + len(judged)) + [False] * len(worn))
        is_test = np.repeat([k >= len(learnt) for k in range(len(ids))], [len(x) for x in units])
        method = detector if detector is not None else registry.make("pca_monitor", variance=variance, alpha=alpha,
                                                                    statistic="q", cv=limit_folds)[1]
        found = evaluate(method, records, TrackSplit(is_test, np.zeros(len(is_test))), rules,
                         type(method).__name__, scores=False, fit=None if detector is not None else fit_q_monitor)
        monitor = found.fitted[0] if found.fitted else None
        flags = [found.alarms[records.rows(f"healthy/{run.id}")] for run in judged]
        false_alarm = scoring.false_alarm_rate(flags, rules, scale=100.0)  # the mean of each run's rate
        rows, charts = [], {}
        for run in tqdm(worn, desc="detection", unit="run", disable=not progress):
            axis = run.worn_axes[0]
            tested = records.rows(f"worn/{run.id}")
            features, alarms = records.features(tested), found.alarms[tested]
            begins = run.fault_begins
            onset = found.onset(tested, fault_start=begins, skip=first)
            before = scoring.before_fault(alarms, begins, first)
            wear = fault_progress(run, axis) * 100.0 - 100.0
            located = locate_onset(features, onset)
            rows.append(dict(robot=run.robot, task=run.task, run=run.id, seed=run.seed, worn_axis=axis,
                             final_wear_pct=round(float(wear[-1]), 2), protocol=label,
                             trained_on=f"{len(learnt)} runs without wear of {source.path.name}",
                             false_alarm_pct=round(false_alarm, 2), false_alarm_runs=len(flags),
                             fault_begins_cycle=np.nan if begins is None else int(run.recorded[begins]),
                             trained_on_fault=begins is not None and begins < first,
                             alarms_before_fault_pct=round(100.0 * float(before.mean()), 2) if before.size else np.nan,
                             features=" ".join(str(u + 1) for u in used), detected=onset is not None,
                             onset=np.nan if onset is None else int(onset),
                             onset_cycle=np.nan if onset is None else int(run.recorded[onset]),
                             onset_wear_pct=np.nan if onset is None else round(float(wear[onset]), 2),
                             located_axis=located, located=bool(scoring.isolation_right(located, axis))))
            chart = {"sample": np.arange(len(alarms)), "cycle": run.recorded, "wear_pct": wear, "alarm": alarms}
            if hasattr(monitor, "score_samples") and hasattr(monitor, "q_limit_"):
                t2, q = monitor.score_samples(features)
                chart.update(t2=t2, q=q, t2_limit=monitor.t2_limit_, q_limit=monitor.q_limit_)
            charts[run.id] = dict(chart, trained=first, onset=onset, begins=begins, protocol=label, robot=run.robot,
                                  task=run.task, worn_axis=axis)
        table = pd.DataFrame(rows)
        table.attrs["dataset_kind"] = data.kind
    return table, charts


class ReferencePCAContribution(isolation.PCAContributionIsolator):
    """:class:`analysis.isolation.PCAContributionIsolator` whose principal components come from
    another dataset: ``reference`` (m, N), the training units' per-cycle signal, each unit
    already :func:`unit_normalised`. The tested run is standardised by its own first
    ``n_reference`` cycles (its baseline) and its residual off the reference's components scored
    per axis by reconstruction-based contribution to Q (thesis eq. 3.3-3.4; Alcala and Qin 2009)."""

    def __init__(self, reference=None, n_reference=20, variance=0.9):
        super().__init__(n_reference=n_reference, variance=variance)
        self.reference = reference

    def _scores(self, X: np.ndarray) -> np.ndarray:
        baseline = X[: self.n_reference]
        self.mean_ = baseline.mean(axis=0)
        std = baseline.std(axis=0, ddof=1)
        self.scale_ = np.where(std > 0, std, 1.0)
        reference = np.asarray(self.reference, dtype=float)
        _, sv, vt = np.linalg.svd(reference - reference.mean(axis=0), full_matrices=False)
        self.n_components_ = isolation.kept_components(sv, self.variance, X.shape[1])
        self.components_ = vt[: self.n_components_]
        Z = (X[self.n_reference:] - self.mean_) / self.scale_
        residual_projector = np.eye(X.shape[1]) - self.components_.T @ self.components_
        return reconstruction_contributions(Z, residual_projector).mean(axis=0)


def trained_isolators(isolators: dict, train, test, baseline: int = 20,
                      signal: str = "mean_abs_torque") -> tuple[dict, str]:
    """``isolators`` with the one that learns normal operation (``pca_contribution``) learning it from
    ``train``'s healthy runs (:class:`ReferencePCAContribution`, each unit's per-cycle ``signal``
    normalised by its own first ``baseline`` cycles), and the protocol line that says so; the
    others read the tested run alone (its own history)."""
    with opened(test) as data, opened(train) as source:
        check_comparable(source, data)
        learnt = _long_enough(source.healthy, baseline, source.path, "run without wear")
        reference = np.vstack([unit_normalised(run.array(signal), baseline) for run in learnt])
        line = protocol(source, baseline)
    chosen = {name: (ReferencePCAContribution(reference, n_reference=baseline)
                     if isinstance(estimator, isolation.PCAContributionIsolator) else estimator)
              for name, estimator in isolators.items()}
    return chosen, (f"pca_contribution: {line}; the other isolators: {OWN} (each tested run's own cycles, "
                    "nothing learnt elsewhere)")


def classification_across(test, train, *, wear_threshold: float = 10.0, baseline: int = 5,
                          classifiers=("lr", "svm", "rf", "stacking"), preprocessing=None,
                          permutations: int = 19, random_state: int = 0, progress: bool = True) -> pd.DataFrame:
    """AUC of each classifier and preprocessing (thesis Table 5.2's cells) fitted on every run of
    ``train`` and scored on every sample of ``test``: Table 5.1's features of each run, each run's
    rows :func:`unit_normalised` by its first ``baseline`` samples; a sample is failed when its
    wear (or label) reaches ``wear_threshold`` %. The verdict of each AUC: ``null``, the mean AUC of
    the same scores against ``permutations`` label sets with ``test``'s runs' roles exchanged
    (:func:`analysis.classify.permuted_roles`), and ``p``, its permutation p-value.

    Returns
    -------
    DataFrame
        Index preprocessing, columns (classifier, auc | null | p); ``attrs["protocol"]``.

    Raises
    ------
    ValueError
        If the datasets do not compare, or either lacks failed or normal samples.
    """
    from sklearn.metrics import roc_auc_score

    from analysis.benchmark.classification_features import classification_inputs
    from analysis.classify import ESTIMATED, SHORT_TABLE, ByRun, make_pipeline, null_p_value, permuted_roles

    with opened(test) as data, opened(train) as source:
        check_comparable(source, data)
        line = protocol(source, baseline)
    sets = {}
    for name, path in (("train", train), ("test", test)):
        inputs = classification_inputs(path, wear_threshold)
        X = inputs.X if inputs.estimated is None else np.hstack([inputs.X, inputs.estimated])
        for run in dict.fromkeys(inputs.groups):
            rows = inputs.groups == run
            X[rows] = unit_normalised(X[rows], baseline)
        sets[name] = (X, inputs.X.shape[1], inputs)
    if preprocessing is None:
        preprocessing = [n for n in SHORT_TABLE if not n.startswith(ESTIMATED)
                         or all(s[2].estimated is not None for s in sets.values())]
    X_test, width, tested = sets["test"]
    null_sets = permuted_roles(tested.y, tested.groups, tested.failed, tested.normal, permutations,
                               random_state=random_state) if permutations else []
    X_train, train_width, fitted = sets["train"]
    rows = {}
    cells = [(p, c) for p in preprocessing for c in classifiers]
    for pre, classifier in tqdm(cells, desc="classify", unit="cell", disable=not progress):
        columns = slice(None) if pre.startswith(ESTIMATED) else slice(0, train_width)
        method = ByRun(make_pipeline(classifier, pre, random_state=random_state))
        scores = _across(method, f"{classifier} {pre}", (X_train[:, columns], fitted),
                         (X_test[:, slice(None) if pre.startswith(ESTIMATED) else slice(0, width)], tested))
        auc = float(roc_auc_score(tested.y, scores))
        null = np.array([roc_auc_score(labels, scores) if 0 < labels.sum() < len(labels) else np.nan
                         for labels, _, _ in null_sets])
        rows.setdefault(pre, {}).update({(classifier, "auc"): auc,
                                         (classifier, "null"): float(np.nanmean(null)) if null.size else np.nan,
                                         (classifier, "p"): null_p_value(auc, null) if null.size else np.nan})
    table = pd.DataFrame.from_dict(rows, orient="index")
    table.columns = pd.MultiIndex.from_tuples(table.columns)
    table.index.name = "preprocessing"
    table.attrs["protocol"] = (f"{line}; trained on {len(fitted.failed)} worn and {len(fitted.normal)} unworn runs, "
                               f"tested on {len(tested.failed)} worn and {len(tested.normal)} unworn runs of "
                               f"{data.path.name}")
    return table


def _across(method, name: str, train: tuple, test: tuple) -> np.ndarray:
    """``method`` fitted on the train dataset's rows and scored on the test dataset's
    (:func:`analysis.evaluate.evaluate`, the two files as one track split); ``train`` and ``test``
    each (X (n_rows, n_features), its classification inputs: ``y``, ``groups``). The scores of the
    test rows, shape (n_test_rows,)."""
    (X_train, fitted), (X_test, tested) = train, test
    is_test = np.r_[np.zeros(len(X_train), dtype=bool), np.ones(len(X_test), dtype=bool)]
    groups = np.array([f"train/{g}" for g in fitted.groups] + [f"test/{g}" for g in tested.groups], dtype=object)
    width = max(X_train.shape[1], X_test.shape[1])
    X = np.full((len(is_test), width), np.nan)
    X[~is_test, :X_train.shape[1]], X[is_test, :X_test.shape[1]] = X_train, X_test
    data = Data(X, groups, np.r_[np.asarray(fitted.y), np.zeros(len(X_test), dtype=np.asarray(fitted.y).dtype)],
                width=np.where(is_test, X_test.shape[1], X_train.shape[1]))
    scores = evaluate(method, data, TrackSplit(is_test, np.zeros(len(is_test))), None, name, alarms=False,
                      test_by="fold")
    return scores.scores[is_test]

