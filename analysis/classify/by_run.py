"""Fitting and scoring a pipeline on the rows of several runs: the sequence steps (differences,
windows) applied to each run on its own, every other step to all rows; stacking's inner folds split
by run."""

from __future__ import annotations

import numpy as np
import pandas as pd
from sklearn.base import BaseEstimator, ClassifierMixin, clone
from sklearn.ensemble import StackingClassifier
from sklearn.pipeline import Pipeline

from analysis.features import Difference, WindowConcat

#: Step types applied to each run on its own (they look at neighbouring rows; both are stateless).
SEQUENCE_STEPS = (Difference, WindowConcat)


def _steps(estimator) -> list:
    if isinstance(estimator, Pipeline):
        return [s for _, s in estimator.steps if s is not None and s != "passthrough"]
    return [estimator]


def _per_run(step, X: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """What ``step.fit_transform`` gives on each run's rows on its own, rows back in their places:
    ``X`` checked once (``step.fit``), then every run at once by row index (each row's predecessor
    in its run; a run's first row is its own), the same numbers bit for bit."""
    X = np.asarray(X, dtype=float)
    step.fit(X)
    previous = previous_rows(groups)
    if isinstance(step, Difference):  # |X_k - X_(k-1)|, 0 for a run's first row
        out = np.abs(X - X[previous])
        out[previous == np.arange(len(X))] = 0.0
        return out
    lags = [np.arange(len(X))]  # WindowConcat: lag l is the l-th predecessor, a run's first row repeated
    for _ in range(int(step.width) - 1):
        lags.append(previous[lags[-1]])
    return np.hstack([X[rows] for rows in reversed(lags)])


def previous_rows(groups) -> np.ndarray:
    """The row before each row in its run (``groups``: the run of each row, each run's rows in time
    order), a run's first row its own index; shape (n_rows,)."""
    codes = pd.factorize(np.asarray(groups))[0]
    order = np.argsort(codes, kind="stable")
    before = np.r_[order[:1], order[:-1]]
    first = np.r_[True, codes[order][1:] != codes[order][:-1]] if len(order) else np.zeros(0, dtype=bool)
    before[first] = order[first]
    previous = np.empty(len(codes), dtype=int)
    previous[order] = before
    return previous


def _transform(estimator, X, groups, y=None, fit: bool = False) -> tuple[np.ndarray, object]:
    steps = _steps(estimator)
    return run_steps(steps[:-1], X, groups, y, fit), steps[-1]


def fit_by_run(estimator, X, y, groups):
    """Fit ``estimator`` (a Pipeline or a classifier) in place on rows of several runs.

    Steps of :data:`SEQUENCE_STEPS` are applied to each run's rows separately (rows of one
    run in time order); every other step is fitted on all rows, in pipeline order.

    Parameters
    ----------
    estimator : Pipeline or classifier
        Unfitted; fitted in place.
    X : ndarray of shape (n_samples, n_features)
    y : ndarray of shape (n_samples,)
    groups : ndarray of shape (n_samples,)
        Run of each row.

    Returns
    -------
    The fitted ``estimator``.
    """
    groups = np.asarray(groups)
    Xt, final = _transform(estimator, np.asarray(X), groups, y, fit=True)
    if isinstance(final, StackingClassifier) and isinstance(final.cv, int | None):
        final.set_params(cv=run_folds(y, groups, 5 if final.cv is None else final.cv))
    final.fit(Xt, y)
    return estimator


def run_folds(y, groups, n_splits: int = 5) -> list[tuple[np.ndarray, np.ndarray]]:
    """Cross-validation folds that split by run, not by sample: every run's samples in one fold
    (``StratifiedGroupKFold``, classes balanced across folds as far as whole runs allow).

    :func:`fit_by_run` gives these to a stacking classifier's inner cross-validation: split by
    sample, its base classifiers learn other days of the very runs whose out-of-fold outputs
    train the meta-classifier, which then learns how the base outputs look on known robots
    (docs/analysis.md, "stacking"). Fewer runs than ``n_splits``: one fold per run.

    Returns
    -------
    list of (train indices, test indices)
    """
    from sklearn.model_selection import StratifiedGroupKFold

    y, groups = np.asarray(y), np.asarray(groups)
    n_runs = len(pd.unique(groups))
    folds = StratifiedGroupKFold(n_splits=max(2, min(n_splits, n_runs)))
    return list(folds.split(np.zeros((len(y), 1)), y, groups))


def score_by_run(estimator, X, groups) -> np.ndarray:
    """Score of the positive class (label 1) per row, from an estimator fitted by :func:`fit_by_run`.

    The probability of class 1 where the final step has ``predict_proba``, otherwise its
    ``decision_function`` (SVM): either ranks the rows, which is all ROC AUC needs.

    Returns
    -------
    ndarray of shape (n_samples,)
    """
    Xt, final = _transform(estimator, np.asarray(X), np.asarray(groups))
    classes = list(final.classes_)
    if hasattr(final, "predict_proba"):
        return final.predict_proba(Xt)[:, classes.index(1)]
    return final.decision_function(Xt)  # binary: positive means classes_[1] = 1


def run_steps(steps: list, X: np.ndarray, groups: np.ndarray, y=None, fit: bool = False) -> np.ndarray:
    """Apply preprocessing ``steps`` (fitted in place with ``fit``) as :func:`fit_by_run` does."""
    Xt = X
    for step in steps:
        if isinstance(step, SEQUENCE_STEPS):
            Xt = _per_run(step, Xt, groups)
        elif fit:
            Xt = step.fit_transform(Xt, y)
        else:
            Xt = step.transform(Xt)
    return Xt


class ByRun(ClassifierMixin, BaseEstimator):
    """``estimator`` (a Pipeline or a classifier) fitted and scored run by run, as the evaluation
    harness (:func:`analysis.evaluate.evaluate`) takes a method: ``fit(X, y, groups)`` is
    :func:`fit_by_run` on a clone, ``decision_function(X, groups)`` :func:`score_by_run` (X of shape
    (n_samples, n_features), groups the run of each row; None: one run). Scores of shape (n_samples,).

    ``make`` (None, or a callable without arguments): a new unfitted estimator with ``estimator``'s
    parameters, what ``fit`` fits instead of a clone (scikit-learn's ``clone`` reads the parameters
    through ``inspect.signature`` at every call; building anew does not: the same fit, number for
    number, for a caller that builds ``estimator`` the same way)."""

    def __init__(self, estimator, make=None):
        self.estimator = estimator
        self.make = make

    def __sklearn_clone__(self):
        # scikit-learn's clone protocol (>= 1.3): fit clones (or makes) ``estimator`` and never
        # changes it, so a clone shares it unfitted instead of deep-copying it first
        return type(self)(self.estimator, self.make)

    def fit(self, X, y, groups=None):
        groups = np.zeros(len(X)) if groups is None else groups
        fresh = clone(self.estimator) if self.make is None else self.make()
        self.estimator_ = fit_by_run(fresh, X, y, groups)
        self.classes_ = _steps(self.estimator_)[-1].classes_
        return self

    def decision_function(self, X, groups=None) -> np.ndarray:
        return score_by_run(self.estimator_, X, np.zeros(len(X)) if groups is None else groups)
