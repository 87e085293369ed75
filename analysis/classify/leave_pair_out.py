"""Thesis Procedure 1: ROC AUC with one failed and one normal run held out, over all pairs or a seeded
subset, optionally time-matched; one pair's AUCs for every (preprocessing, classifier) cell at once."""

from __future__ import annotations

import warnings
from functools import partial

import numpy as np
import pandas as pd
from joblib import Parallel, delayed
from sklearn import config_context
from sklearn.base import BaseEstimator, clone
from sklearn.metrics import roc_auc_score
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import StandardScaler
from threadpoolctl import threadpool_limits

from analysis.classify.by_run import ByRun, run_steps
from analysis.classify.labels import make_labels
from analysis.classify.preprocessing import ESTIMATED, make_pipeline, preprocessing_steps
from analysis.classify.roc import binary_auc
from analysis.evaluate import Data, Given, LeavePairOut, evaluate
from faultgen import children


class UndefinedAUCWarning(UserWarning):
    """Some held-out pairs had no AUC (one class only in the pair or in its training set)."""


def check_inputs(X, y, groups, failed_groups, normal_groups):
    """``X`` (n_samples, n_features) as floats, ``y`` and ``groups`` (n_samples,) as arrays, and the
    failed and normal runs as lists, checked for :func:`leave_pair_out_auc` and
    :func:`analysis.classify.evaluate`.

    Raises
    ------
    ValueError
        On shapes that do not match (named with the shape expected), no failed or no normal run,
        a run in both lists, or a run without samples in ``groups`` (the run named).
    """
    X, y, groups = np.asarray(X, dtype=float), np.asarray(y), np.asarray(groups)
    if X.ndim != 2:
        raise ValueError(f"X must have shape (n_samples, n_features), got shape {X.shape}")
    for name, a in (("y", y), ("groups", groups)):
        if a.shape != (X.shape[0],):
            raise ValueError(f"{name} must have shape ({X.shape[0]},) like X's rows, got {a.shape}")
    failed, normal = list(failed_groups), list(normal_groups)
    if not failed or not normal:
        raise ValueError(f"need at least one failed and one normal run, got {len(failed)} failed and "
                         f"{len(normal)} normal")
    both = set(failed) & set(normal)
    if both:
        raise ValueError(f"run {min(both, key=str)!r} is both failed and normal")
    present = set(pd.unique(groups).tolist())
    for g in failed + normal:
        if g not in present:
            raise ValueError(f"run {g!r} has no samples in groups")
    return X, y, groups, failed, normal


def matched_rows(labels, groups, pair) -> np.ndarray:
    """Rows a time-matched AUC compares: the failed samples of ``pair``'s failed run and the
    samples of its normal run at the same positions in its record (k-th sample against k-th
    sample, counted from the start; positions the normal run does not reach are left out).

    Returns
    -------
    ndarray of bool of shape (n_samples,)
    """
    failed, normal = pair
    failed_rows, normal_rows = np.flatnonzero(groups == failed), np.flatnonzero(groups == normal)
    positions = np.flatnonzero(labels[failed_rows] == 1)
    positions = positions[positions < normal_rows.size]
    rows = np.zeros(len(groups), dtype=bool)
    rows[failed_rows[positions]] = rows[normal_rows[positions]] = True
    return rows


def _fold(groups, fold) -> tuple[tuple, np.ndarray, np.ndarray]:
    """(pair, train rows, held-out rows as a mask) of ``fold``, a (pair, (train, test)) of
    :class:`analysis.evaluate.LeavePairOut`."""
    pair, (train, test) = fold
    held = np.zeros(len(groups), dtype=bool)
    held[test] = True
    return pair, train, held


def _pair_auc(factory, X, labels, groups, fold, matched: bool = False) -> float:
    pair, train, held = _fold(groups, fold)
    # the held-out runs are scored whole (differencing needs each sample's predecessor); a
    # time-matched AUC then ranks only the failed samples against the same days of the normal run
    test = matched_rows(labels, groups, pair)[held] if matched else slice(None)
    truth = labels[held][test]
    if np.unique(labels[train]).size < 2 or np.unique(truth).size < 2:
        return np.nan
    model = factory() if callable(factory) and not isinstance(factory, BaseEstimator) else factory
    rows = np.flatnonzero(held)
    scores = _scores(model, Data(X, groups, labels), train, rows, "leave-pair-out")
    return float(roc_auc_score(truth, scores[test]))


def _scores(model, data: Data, train: np.ndarray, test: np.ndarray, name: str, make=None) -> np.ndarray:
    """The scores of ``data``'s ``test`` rows by ``model`` fitted on its ``train`` rows run by run
    (:func:`analysis.evaluate.evaluate`, the fold given; :class:`analysis.classify.ByRun`, ``make``
    its way to a new ``model``), shape (len(test),)."""
    found = evaluate(ByRun(model, make), data, Given([(train, test)]), None, name, alarms=False, test_by="fold")
    return found.scores[test]


def pair_cells(X, estimated, groups, held_out, label_sets, names, models, random_state, matched) -> np.ndarray:
    """AUCs of one held-out pair of runs for every (preprocessing, classifier) cell under each of
    ``label_sets``, in ``product(names, models)`` order: each preprocessing fitted once on the
    training runs (its steps learn no labels: the same for every label set), then every classifier
    a label set asks for on its output, through the harness. The same numbers as :func:`_pair_auc`
    on each cell's whole pipeline.

    Parameters
    ----------
    X : ndarray of shape (n_samples, n_features) or None
        None when every name starts with ``+estM``.
    estimated : ndarray of shape (n_samples, n_estimated) or None
        Appended to ``X`` for the ``+estM`` names (None when there are none).
    groups : ndarray of shape (n_samples,)
    held_out : (run, run)
        The pair held out (:class:`analysis.evaluate.LeavePairOut`: the model learns every other run).
    label_sets : list of (labels, (failed, normal), classifiers)
        The labels of each set, its pair in that order (the failed run's failed samples for
        ``matched``) and the columns of ``models`` to fit on them.

    Returns
    -------
    ndarray of shape (len(label_sets), len(names) * len(models))
        NaN for a cell not asked for, and for every cell of a label set whose pair or training runs
        have one class only.
    """
    train, test_rows = next(LeavePairOut([held_out[0]], [held_out[1]]).split(groups=groups))
    held = np.zeros(len(groups), dtype=bool)
    held[test_rows] = True
    out = np.full((len(label_sets), len(names) * len(models)), np.nan)
    scored = []  # (index, labels, rows compared, truth, classifiers) of the sets with both classes
    for i, (labels, pair, columns) in enumerate(label_sets):
        test = matched_rows(labels, groups, pair)[held] if matched else slice(None)
        truth = labels[held][test]
        if np.unique(labels[train]).size == 2 and np.unique(truth).size == 2:
            scored.append((i, labels, test, truth, set(columns)))
    if not scored:
        return out
    X_est = None if estimated is None else (estimated if X is None else np.hstack([X, estimated]))
    # each classifier built once (the harness fits a new one per cell, made or cloned: below); its
    # parameters are classify's own or checked by evaluate's caller, so scikit-learn's parameter
    # checks are skipped per fit
    classifiers = {column: make_pipeline(model, "control", random_state=random_state) for column, model in models.items()}
    # a named classifier's fits are built anew (scikit-learn's clone reads every parameter by
    # inspect.signature: 2800 LR fits in the default run), a caller's estimator cloned
    builds = {column: partial(_built_tail, model, random_state) if isinstance(model, str) else None
              for column, model in models.items()}
    with config_context(skip_parameter_validation=True):
        _fill_cells(out, X, X_est, groups, train, held, scored, names, classifiers, builds)
    return out


def _built_tail(name: str, random_state):
    """A new unfitted classifier ``name`` (:data:`CLASSIFIERS`) without its :func:`label_free_head`,
    what cloning that tail of :func:`pair_cells`'s pipeline gives (the same parameters)."""
    return label_free_head(make_pipeline(name, "control", random_state=random_state))[1]


def _fill_cells(out, X, X_est, groups, train, held, scored, names, classifiers, builds) -> None:
    """:func:`pair_cells`'s AUCs into ``out`` (label set, cell): each preprocessing fitted once on the
    training runs, then each classifier's leading label-free steps (:func:`label_free_head`) once,
    shared by the label sets and by the classifiers with the same steps, then the rest of each
    classifier of each label set in ``scored`` on their output (built by ``builds[column]`` where
    not None, else cloned)."""
    asked = set().union(*(columns for *_, columns in scored))
    heads = {column: label_free_head(clf) for column, clf in classifiers.items() if column in asked}
    keys = _head_keys(heads)
    for r, name in enumerate(names):
        data = X_est if name.startswith(ESTIMATED) else X
        steps = [step for _, step in preprocessing_steps(name)]
        X_train = run_steps(steps, data[train], groups[train], fit=True)
        X_test = run_steps(steps, data[held], groups[held])
        rows, run_of, n_train = np.vstack([X_train, X_test]), np.r_[groups[train], groups[held]], len(X_train)
        inputs = _head_outputs(heads, keys, rows, n_train)
        # rows checked finite here once, not by every fit's and prediction's input checks
        with config_context(assume_finite=all(np.isfinite(Xc).all() for Xc, _ in inputs.values())):
            _classify(out, r, name, inputs, run_of, n_train, train, held, scored, builds)


def _classify(out, r, name, inputs, run_of, n_train, train, held, scored, builds) -> None:
    """Row ``r`` of ``out``: each classifier (the keys of ``builds``, in order) asked for by each label
    set of ``scored`` on ``inputs`` (:func:`_head_outputs`), through the harness, and its AUC."""
    for i, labels, test, truth, columns in scored:
        # the preprocessed rows, train then held out, one fold given: each classifier through the harness
        y = np.r_[labels[train], labels[held]]
        for c, column in enumerate(builds):
            if column in columns:
                Xc, tail = inputs[column]
                scores = _scores(tail, Data(Xc, run_of, y), np.arange(n_train), np.arange(n_train, len(Xc)),
                                 f"{column} {name}", builds[column])
                out[i, r * len(builds) + c] = binary_auc(truth, scores[test])


#: Steps that learn no labels and look at no neighbouring rows: a classifier's leading ones are
#: fitted once per held-out pair and row, for every label set (the class itself, not a subclass).
LABEL_FREE = (StandardScaler,)


def label_free_head(model) -> tuple[list, object]:
    """(the leading :data:`LABEL_FREE` steps of a Pipeline ``model``, what follows them: its last
    step alone or a Pipeline of the rest); ``([], model)`` for any other model. Fitting the head on
    the training rows and the rest on its output is what fitting ``model`` does, number for number."""
    if not isinstance(model, Pipeline):
        return [], model
    k = 0
    while k < len(model.steps) - 1 and type(model.steps[k][1]) in LABEL_FREE:
        k += 1
    rest = model.steps[k:]
    return [step for _, step in model.steps[:k]], rest[0][1] if len(rest) == 1 else Pipeline(rest)


def _head_keys(heads: dict) -> dict:
    """Column -> what its head is (its steps' types and parameters): heads with the same key are
    the same steps, fitted once (:func:`_head_outputs`)."""
    return {column: repr([(type(step), sorted(step.get_params(deep=False).items())) for step in head])
            for column, (head, _) in heads.items()}


def _head_outputs(heads: dict, keys: dict, rows: np.ndarray, n_train: int) -> dict:
    """Column -> (``rows``, the first ``n_train`` the training rows, through its head fitted on the
    training rows, its tail); a head fitted once for every column with the same key (:func:`_head_keys`).
    The rows taken as the harness takes them (a copy of each fold's rows)."""
    done: dict[str, np.ndarray] = {}
    out = {}
    for column, (head, tail) in heads.items():
        if keys[column] not in done:
            done[keys[column]] = _through(head, rows, n_train) if head else rows
        out[column] = done[keys[column]], tail
    return out


def _through(head: list, rows: np.ndarray, n_train: int) -> np.ndarray:
    """``rows`` through clones of ``head``'s steps fitted on the first ``n_train`` (fit_transform),
    the rest transformed, each part a copy of its rows as the harness takes a fold's."""
    train, test = rows[np.arange(n_train)], rows[np.arange(n_train, len(rows))]
    for step in head:
        step = clone(step)
        train = step.fit_transform(train)
        test = step.transform(test)
    return np.vstack([train, test])


def folds(failed, normal, groups, n_pairs: int | None = None, random_state: int | None = 0) -> list[tuple]:
    """The held-out pairs of Procedure 1 (:class:`analysis.evaluate.LeavePairOut`, the protocol) with
    their rows: a list of (pair, (train indices, test indices))."""
    protocol = LeavePairOut(failed, normal, n_pairs, random_state)
    return list(zip(protocol.pairs(), protocol.split(groups=groups), strict=True))


def leave_pair_out_auc(pipeline_factory, X, y, groups, failed_groups, normal_groups, *,
                       n_pairs: int | None = None, random_state: int | None = 0, label_rule=None,
                       matched: bool = False, n_jobs: int | None = None, return_pairs: bool = False):
    """ROC AUC with one failed and one normal run held out, thesis Procedure 1.

    For each pair (failed run ``i``, normal run ``j``): fit a new model on the samples of all
    other runs (:func:`fit_by_run`), score the samples of ``i`` and ``j`` (:func:`score_by_run`)
    and compute ``sklearn.metrics.roc_auc_score`` against their labels.

    Parameters
    ----------
    pipeline_factory : callable or estimator
        ``pipeline_factory()`` returns a new, unfitted model (e.g.
        ``lambda: make_pipeline("lr", "+diff")``); an estimator is cloned instead.
    X : array-like of shape (n_samples, n_features)
        Samples of all runs; each run's rows in time order.
    y : array-like of shape (n_samples,)
        Labels or what ``label_rule`` reads; see :func:`make_labels`.
    groups : array-like of shape (n_samples,)
        Run of each sample.
    failed_groups, normal_groups : sequence
        Runs with and without wear; runs in neither are always in the training set.
    n_pairs : int or None, default=None
        None: every pair (``len(failed) * len(normal)``). An int: that many pairs, drawn with
        ``random_state`` (:func:`analysis.evaluate.select_pairs`).
    random_state : int or None, default=0
        Seed of the pair subset.
    label_rule : None, float or callable, default=None
        See :func:`make_labels`; None means ``y`` holds 0/1 labels.
    matched : bool, default=False
        A time control: rank the failed samples of ``i`` only against the samples of ``j`` at the
        same positions in its record (:func:`matched_rows`), not against ``i``'s own earlier
        samples and ``j``'s other days. When a failed run's failed samples are its last ones
        (labels by wear), anything that changes along a record (season, a life-average indicator
        settling) tells late from early samples without any fault; matched, it cannot. Changes
        nothing where every sample of ``i`` is failed and the runs are as long (the thesis's
        window, ``analysis.benchmark.classification_table(horizon=...)``).
    n_jobs : int or None, default=None
        Pairs in parallel with joblib (None: one at a time).
    return_pairs : bool, default=False
        Also return the pairs.

    Returns
    -------
    aucs : ndarray of shape (n_pairs,)
        One AUC per pair, in the order of :func:`analysis.evaluate.select_pairs`. NaN where it is undefined: the
        held-out pair has one class only (e.g. the failed run never reaches the wear threshold,
        so all its samples are 0 like the normal run's), or the training runs do. An
        :class:`UndefinedAUCWarning` says how many; aggregate with ``np.nanmean``.
    pairs : list of (failed, normal)
        Only with ``return_pairs=True``.

    Raises
    ------
    ValueError
        On shapes that do not match, a run missing from ``groups`` or in both lists, or labels
        that are not 0/1 (see :func:`make_labels`).
    """
    X, y, groups, failed, normal = check_inputs(X, y, groups, failed_groups, normal_groups)
    labels = make_labels(y, groups, failed, label_rule)
    held_out = folds(failed, normal, groups, n_pairs, random_state)
    pairs = [pair for pair, _ in held_out]
    if n_jobs is None:
        with threadpool_limits(limits=1):  # small fits: see evaluate
            aucs = [_pair_auc(pipeline_factory, X, labels, groups, f, matched) for f in held_out]
    else:
        jobs = (delayed(_pair_auc)(pipeline_factory, X, labels, groups, f, matched) for f in held_out)
        with children.safe_path():  # loky's workers and trackers: no joblib.py of this folder
            aucs = Parallel(n_jobs=n_jobs)(jobs)
    aucs = np.asarray(aucs, dtype=float)
    n_nan = int(np.isnan(aucs).sum())
    if n_nan:
        warnings.warn(f"{n_nan} of {len(pairs)} held-out pairs have no AUC (one class only in the pair "
                      "or in its training runs); they are NaN", UndefinedAUCWarning, stacklevel=2)
    return (aucs, pairs) if return_pairs else aucs
