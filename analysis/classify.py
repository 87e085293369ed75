"""Fault detection by classification: classifiers, preprocessing combinations, thesis ch. 5.

- :data:`CLASSIFIERS`: LR, SVM (RBF), RF and the LR + SVM stack with an LR meta-classifier
  (ch. 5.2), each a factory of a scikit-learn ``Pipeline``;
- :data:`PREPROCESSING` and :func:`preprocessing_steps`: the combinations of Table 5.2 ("control",
  "+diff", "+var3", "+pca", "+diff+var3+pca", ...) as lists of transformer steps, and
  :func:`make_pipeline` to put one in front of a classifier;
- :func:`leave_pair_out_auc`: Procedure 1, leave one failed and one normal robot out, ROC AUC;
- :func:`permuted_roles`: the chance level of Procedure 1 on the same robots, labels exchanged
  between runs (a group-level permutation test);
- :func:`compare_preprocessing`: Procedure 2, Levene, then Welch ANOVA + Games-Howell or ANOVA +
  Tukey HSD (pingouin);
- :func:`evaluate`: every classifier with every combination, Table 5.2's layout.

In faultgen terms a "robot" is a run (a *group*), its samples are the run's recorded cycles in
time order (rows of a per-cycle feature matrix, e.g. mean absolute motor torque and the KL
divergences of the histograms, one column per axis and feature), a "failed" robot is a run with
wear and a "normal" one a run without.

Runs and sequence steps: :class:`~analysis.features.Difference` and
:class:`~analysis.features.WindowConcat` treat every array they transform as one time series.
:func:`fit_by_run` and :func:`score_by_run` (used by :func:`leave_pair_out_auc`) therefore apply
these steps to each run separately, so no difference or window spans two runs, and fit every
other step on all rows at once. A pipeline fitted with plain ``Pipeline.fit`` on several runs
stacked is fine for one run but joins consecutive runs at their boundaries.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from itertools import product

import numpy as np
import pandas as pd
from joblib import Parallel, delayed
from sklearn.base import BaseEstimator, clone
from sklearn.decomposition import PCA
from sklearn.ensemble import RandomForestClassifier, StackingClassifier
from sklearn.linear_model import LogisticRegression
from sklearn.metrics import roc_auc_score
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.svm import SVC
from threadpoolctl import threadpool_limits
from tqdm.auto import tqdm

from analysis.features import Difference, WindowConcat
from faultgen import children
from faultgen.checks import is_whole

#: Step types applied to each run on its own (they look at neighbouring rows; both are stateless).
SEQUENCE_STEPS = (Difference, WindowConcat)

#: Fraction of the variance the principal components of "+pca" keep (thesis ch. 5.3.2: > 90 %).
PCA_VARIANCE = 0.9

#: Significance level of Procedure 2 (thesis ch. 5.3.4).
ALPHA = 0.05


class UndefinedAUCWarning(UserWarning):
    """Some held-out pairs had no AUC (one class only in the pair or in its training set)."""


# --------------------------------------------------------------------------------------------
# Classifiers (thesis ch. 5.2)


def _lr(random_state: int | None = 0) -> LogisticRegression:
    return LogisticRegression(max_iter=1000, random_state=random_state)


def _svc(random_state: int | None = 0) -> SVC:
    # No Platt scaling (probability=False): AUC needs only a ranking, which decision_function
    # gives without SVC's internal cross-validation (slower, and random).
    return SVC(kernel="rbf", C=1.0, gamma="scale", random_state=random_state)


def logistic_regression(random_state: int | None = 0) -> Pipeline:
    """LR (thesis eq. 5.2) on standardised features: ``StandardScaler`` -> ``LogisticRegression``."""
    return Pipeline([("scale", StandardScaler()), ("lr", _lr(random_state))])


def support_vector_machine(random_state: int | None = 0) -> Pipeline:
    """SVM with a Gaussian RBF kernel (thesis eq. 5.3), ``C = 1``, ``gamma = "scale"``, on
    standardised features. Scores are ``decision_function`` values (a ranking is all AUC needs)."""
    return Pipeline([("scale", StandardScaler()), ("svm", _svc(random_state))])


def random_forest(random_state: int | None = 0) -> Pipeline:
    """Random forest of 100 trees, seeded; trees need no scaling."""
    return Pipeline([("rf", RandomForestClassifier(n_estimators=100, random_state=random_state))])


def stacking(random_state: int | None = 0, inner_cv: str = "run") -> Pipeline:
    """Ensemble stack of thesis Fig. 5-3: LR and SVM base classifiers, LR meta-classifier.

    The meta-classifier is trained on 5-fold cross-validated base outputs (LR probabilities, SVM
    decision values), on standardised features. ``inner_cv="run"``: :func:`fit_by_run` splits the
    folds by run (:func:`run_folds`), so the base outputs it learns from are, as at test time,
    those of robots the base classifiers did not see. ``"sample"``: scikit-learn's stratified
    folds over samples, what faultgen used before (a run's days on both sides of a fold).
    Measured (docs/analysis.md, "Stacking's inner cross-validation"): on the default 26-robot
    fleet the two splits are within 0.10 of each other (by run higher with PCA, lower elsewhere),
    both below LR alone; on an 8-robot fleet by run scores far lower, below chance without
    differencing (grouped folds on few robots bias the out-of-fold outputs against the labels).
    """
    from sklearn.model_selection import StratifiedKFold

    if inner_cv not in ("run", "sample"):
        raise ValueError(f"inner_cv = {inner_cv!r}; expected 'run' or 'sample'")
    stack = StackingClassifier(estimators=[("lr", _lr(random_state)), ("svm", _svc(random_state))],
                               final_estimator=_lr(random_state), cv=5 if inner_cv == "run" else StratifiedKFold(5))
    return Pipeline([("scale", StandardScaler()), ("stacking", stack)])


#: Classifier name -> factory ``f(random_state=0) -> Pipeline`` (thesis ch. 5.2; "stacking" is ES).
CLASSIFIERS: dict[str, Callable[..., Pipeline]] = {
    "lr": logistic_regression,
    "svm": support_vector_machine,
    "rf": random_forest,
    "stacking": stacking,
}


# --------------------------------------------------------------------------------------------
# Preprocessing combinations (thesis ch. 5.3.2, Table 5.2)

#: Token of a combination that appends the estimated-quantities block to the input (no step).
ESTIMATED = "+estM"

#: The fifteen combinations of thesis Table 5.2, in its order.
TABLE_5_2 = (
    "control", "+estM", "+diff", "+pca", "+var3", "+estM+diff", "+estM+pca", "+estM+var3", "+diff+pca",
    "+var3+pca", "+estM+diff+pca", "+estM+var3+pca", "+diff+pca+var3", "+diff+var3+pca",
    "+estM+diff+var3+pca",
)

#: The rows ``faultgen classify`` computes unless asked for more (``--full``): each step of Table 5.2
#: alone and the fullest combination without and with the estimates, in Table 5.2's order; 7 of
#: the 19 of :data:`PREPROCESSING`, at about 0.36 of their cost (docs/performance.md, "classify").
SHORT_TABLE = ("control", "+estM", "+diff", "+pca", "+var3", "+diff+var3+pca", "+estM+diff+var3+pca")


def preprocessing_steps(name: str) -> list[tuple[str, BaseEstimator]]:
    """Transformer steps of a combination such as ``"+diff+var3+pca"``, applied in its order.

    Tokens (thesis ch. 5.3.2): ``+diff``, :class:`~analysis.features.Difference`; ``+var<n>``,
    :class:`~analysis.features.WindowConcat` of width ``n`` ("+var3", "+var5"); ``+pca``,
    ``StandardScaler`` then ``PCA`` keeping :data:`PCA_VARIANCE` of the variance (the features
    have different units, so they are standardised first); ``+estM``, no step: it says that the
    input carries the block of estimated quantities (see :func:`evaluate`), which comes before
    every other step, as in the thesis (estimates are added before differencing). ``"control"``
    (or ``""``) is no step.

    Returns
    -------
    list of (str, estimator)
        New, unfitted steps named ``diff``, ``var3``, ``pca_scale``, ``pca``; a repeated token
        gets a numbered name (``diff_2``).

    Raises
    ------
    ValueError
        For an unknown token or ``+estM`` anywhere but first; the message names the token.
    """
    if name in ("control", ""):
        return []
    if not name.startswith("+"):
        raise ValueError(f"preprocessing {name!r}: expected 'control' or tokens like '+diff+var3+pca'")
    tokens = ["+" + t for t in name[1:].split("+")]
    steps: list[tuple[str, BaseEstimator]] = []
    for k, token in enumerate(tokens):
        if token == ESTIMATED:
            if k:
                raise ValueError(f"preprocessing {name!r}: {ESTIMATED} must come first (estimated "
                                 "quantities are added before any other step)")
            continue
        if token == "+diff":
            new = [("diff", Difference())]
        elif token == "+pca":
            new = [("pca_scale", StandardScaler()), ("pca", PCA(n_components=PCA_VARIANCE))]
        elif token.startswith("+var") and token[4:].isdigit() and int(token[4:]) >= 1:
            new = [(token[1:], WindowConcat(width=int(token[4:])))]
        else:
            raise ValueError(f"preprocessing {name!r}: unknown token {token!r}; expected +diff, +var<n>, "
                             f"+pca or {ESTIMATED} (first)")
        names = {n for n, _ in steps}
        for step_name, step in new:
            unique, i = step_name, 2
            while unique in names:
                unique, i = f"{step_name}_{i}", i + 1
            steps.append((unique, step))
    return steps


def describe_preprocessing(name: str) -> str:
    """What a combination does, step by step in its order, e.g. ``"+diff+pca+var3"`` -> "difference,
    then PCA (90 % variance), then windows of 3": the order of the tokens is the order of the steps."""
    words = []
    for step_name, step in preprocessing_steps(name):
        if isinstance(step, Difference):
            words.append("difference")
        elif isinstance(step, WindowConcat):
            words.append(f"windows of {step.width}")
        elif isinstance(step, PCA):
            words.append(f"PCA of the standardised features ({100 * PCA_VARIANCE:g} % variance)")
    return ", then ".join((["estimates added"] if name.startswith(ESTIMATED) else []) + words) or "none"


#: Combination name -> its steps (templates: :func:`make_pipeline` clones them). Table 5.2's
#: fifteen, "+var5" and the var3 / var5 pairs the thesis compares (ch. 5.4.2), and "+diff+var3".
PREPROCESSING: dict[str, list[tuple[str, BaseEstimator]]] = {
    name: preprocessing_steps(name)
    for name in (*TABLE_5_2, "+var5", "+diff+var3", "+diff+var5+pca", "+estM+diff+var5+pca")
}


def make_pipeline(classifier: str | BaseEstimator = "lr",
                  preprocessing: str | Sequence[tuple[str, BaseEstimator]] = "control",
                  random_state: int | None = 0) -> Pipeline:
    """One flat ``Pipeline``: preprocessing steps, then the classifier's steps.

    Parameters
    ----------
    classifier : str or estimator, default="lr"
        A key of :data:`CLASSIFIERS` (built with ``random_state``) or an estimator / Pipeline
        (cloned).
    preprocessing : str or list of (name, transformer), default="control"
        A combination name (any that :func:`preprocessing_steps` parses, e.g. a key of
        :data:`PREPROCESSING`) or steps (cloned).
    random_state : int or None, default=0
        Seed of the named classifiers.

    Returns
    -------
    Pipeline
        Unfitted; ``clone`` and ``get_params`` work as for any Pipeline.

    Raises
    ------
    ValueError
        For an unknown classifier or combination, or a step name used twice.
    """
    if isinstance(classifier, str):
        if classifier not in CLASSIFIERS:
            raise ValueError(f"unknown classifier {classifier!r}; expected one of: {', '.join(CLASSIFIERS)}")
        model = CLASSIFIERS[classifier](random_state=random_state)
    else:
        model = clone(classifier)
    if isinstance(preprocessing, str):
        pre = preprocessing_steps(preprocessing)
    else:
        pre = [(n, clone(s)) for n, s in preprocessing]
    tail = list(model.steps) if isinstance(model, Pipeline) else [("classifier", model)]
    names = [n for n, _ in pre] + [n for n, _ in tail]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ValueError(f"step name(s) {', '.join(map(repr, dup))} used twice in the pipeline")
    return Pipeline(pre + tail)


# --------------------------------------------------------------------------------------------
# Fitting and scoring run by run


def _steps(estimator) -> list:
    if isinstance(estimator, Pipeline):
        return [s for _, s in estimator.steps if s is not None and s != "passthrough"]
    return [estimator]


def _per_run(step, X: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """``step.fit_transform`` on each run's rows on its own, rows back in their places."""
    out = None
    for g in pd.unique(groups):
        idx = np.flatnonzero(groups == g)
        part = np.asarray(step.fit_transform(X[idx]))
        if out is None:
            out = np.empty((X.shape[0], *part.shape[1:]), dtype=part.dtype)
        out[idx] = part
    return out


def _transform(estimator, X, groups, y=None, fit: bool = False) -> tuple[np.ndarray, object]:
    steps = _steps(estimator)
    return _run_steps(steps[:-1], X, groups, y, fit), steps[-1]


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


# --------------------------------------------------------------------------------------------
# Labels


def last_samples(n: int) -> Callable:
    """Labelling rule: the last ``n`` samples of each failed run are 1, all others 0.

    The thesis's rule (ch. 5.3.3): the samples shortly before the failure are "failed". Use as
    ``label_rule=last_samples(10)``; ``y`` is then ignored.
    """
    if not is_whole(n, 1):
        raise ValueError(f"n = {n!r}; expected an integer >= 1")

    def rule(y, groups, failed_groups):
        labels = np.zeros(len(groups), dtype=int)
        for g in failed_groups:
            labels[np.flatnonzero(groups == g)[-n:]] = 1
        return labels

    return rule


def make_labels(y, groups, failed_groups, label_rule=None) -> np.ndarray:
    """Class label (0 normal, 1 failed) of every sample.

    Parameters
    ----------
    y : array-like of shape (n_samples,)
        Labels (``label_rule=None``) or the quantity a rule reads, e.g. the true wear in percent.
    groups : ndarray of shape (n_samples,)
    failed_groups : sequence
        Runs with wear.
    label_rule : None, float or callable, default=None
        ``None`` (default): ``y`` already holds the labels, 0/1 or bool (e.g.
        :func:`analysis.benchmark.classification_table`, 1 where the true wear reaches 10 %).
        A float ``t``: ``y`` is the wear of each sample, labelled 1 in a failed run where
        ``y >= t``. A callable ``rule(y, groups, failed_groups) -> labels``, e.g.
        :func:`last_samples`.

    Returns
    -------
    ndarray of int of shape (n_samples,)

    Raises
    ------
    ValueError
        If the labels are not 0/1 or a sample of a run outside ``failed_groups`` is labelled 1
        (a normal robot has no failed samples; the message names the run).
    """
    y, groups = np.asarray(y), np.asarray(groups)
    if label_rule is None:
        labels = y
    elif callable(label_rule):
        labels = np.asarray(label_rule(y, groups, failed_groups))
    else:
        labels = np.isin(groups, list(failed_groups)) & (np.asarray(y, dtype=float) >= float(label_rule))
    if labels.shape != groups.shape:
        raise ValueError(f"labels have shape {labels.shape}, expected {groups.shape}")
    if labels.dtype != bool and not np.isin(labels, (0, 1)).all():
        bad = labels[~np.isin(labels, (0, 1))][0]
        raise ValueError(f"label {bad!r} is not 0 or 1; pass label_rule to turn y into labels")
    labels = labels.astype(int)
    wrong = np.flatnonzero((labels == 1) & ~np.isin(groups, list(failed_groups)))
    if wrong.size:
        raise ValueError(f"run {groups[wrong[0]]!r} is not a failed run but has samples labelled 1")
    return labels


# --------------------------------------------------------------------------------------------
# Procedure 1


def _check_inputs(X, y, groups, failed_groups, normal_groups):
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


#: Most held-out pairs one evaluation fits (each pair fits every classifier of every combination):
#: "every pair" of a dataset with more is refused before any fit (``faultgen classify --pairs``).
MAX_PAIRS = 100_000


def select_pairs(failed_groups, normal_groups, n_pairs: int | None = None,
                 random_state: int | None = 0) -> list[tuple]:
    """(failed, normal) pairs of Procedure 1: all, failed-major, or ``n_pairs`` of them.

    A subset is drawn without replacement with ``numpy.random.default_rng(random_state)`` and
    kept in the same order as the full list, so equal arguments give equal pairs.

    Raises
    ------
    ValueError
        If ``n_pairs`` is below 1, or every pair is asked for (``None``, or at least as many as
        there are) and there are more than :data:`MAX_PAIRS`.
    """
    total = len(failed_groups) * len(normal_groups)
    if (n_pairs is None or n_pairs >= total) and total > MAX_PAIRS:
        raise ValueError(
            f"every pair of {len(failed_groups)} worn x {len(normal_groups)} unworn runs is {total} held-out "
            f"pairs, more than {MAX_PAIRS} (each fits every classifier); draw some with --pairs N (n_pairs)"
        )
    pairs = list(product(failed_groups, normal_groups))
    if n_pairs is None or n_pairs >= len(pairs):
        return pairs
    if n_pairs < 1:
        raise ValueError(f"n_pairs = {n_pairs!r}; expected None or an integer >= 1")
    chosen = np.sort(np.random.default_rng(random_state).choice(len(pairs), size=n_pairs, replace=False))
    return [pairs[i] for i in chosen]


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


def _pair_auc(factory, X, labels, groups, pair, matched: bool = False) -> float:
    held = np.isin(groups, list(pair))
    train = ~held
    # the held-out runs are scored whole (differencing needs each sample's predecessor); a
    # time-matched AUC then ranks only the failed samples against the same days of the normal run
    test = matched_rows(labels, groups, pair)[held] if matched else slice(None)
    truth = labels[held][test]
    if np.unique(labels[train]).size < 2 or np.unique(truth).size < 2:
        return np.nan
    model = factory() if callable(factory) and not isinstance(factory, BaseEstimator) else clone(factory)
    fit_by_run(model, X[train], labels[train], groups[train])
    return float(roc_auc_score(truth, score_by_run(model, X[held], groups[held])[test]))


def _run_steps(steps: list, X: np.ndarray, groups: np.ndarray, y=None, fit: bool = False) -> np.ndarray:
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


def _pair_cells(X, X_est, labels, groups, pair, names, models, random_state, matched) -> np.ndarray:
    """AUCs of one held-out pair for every (preprocessing, classifier) cell, in ``product(names,
    models)`` order: each preprocessing fitted once on the training runs, then every classifier on
    its output. The same numbers as :func:`_pair_auc` on each cell's whole pipeline."""
    held = np.isin(groups, list(pair))
    train = ~held
    test = matched_rows(labels, groups, pair)[held] if matched else slice(None)
    truth = labels[held][test]
    out = np.full(len(names) * len(models), np.nan)
    if np.unique(labels[train]).size < 2 or np.unique(truth).size < 2:
        return out
    k = 0
    for name in names:
        data = X_est if name.startswith(ESTIMATED) else X
        steps = [step for _, step in preprocessing_steps(name)]
        X_train = _run_steps(steps, data[train], groups[train], labels[train], fit=True)
        X_test = _run_steps(steps, data[held], groups[held])
        for model in models.values():
            clf = make_pipeline(model, "control", random_state=random_state)
            fit_by_run(clf, X_train, labels[train], groups[train])
            out[k] = roc_auc_score(truth, score_by_run(clf, X_test, groups[held])[test])
            k += 1
    return out


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
        ``random_state`` (:func:`select_pairs`).
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
        One AUC per pair, in the order of :func:`select_pairs`. NaN where it is undefined: the
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
    X, y, groups, failed, normal = _check_inputs(X, y, groups, failed_groups, normal_groups)
    labels = make_labels(y, groups, failed, label_rule)
    pairs = select_pairs(failed, normal, n_pairs, random_state)
    if n_jobs is None:
        with threadpool_limits(limits=1):  # small fits: see evaluate
            aucs = [_pair_auc(pipeline_factory, X, labels, groups, p, matched) for p in pairs]
    else:
        jobs = (delayed(_pair_auc)(pipeline_factory, X, labels, groups, p, matched) for p in pairs)
        with children.safe_path():  # loky's workers and trackers: no joblib.py of this folder (issue 61)
            aucs = Parallel(n_jobs=n_jobs)(jobs)
    aucs = np.asarray(aucs, dtype=float)
    n_nan = int(np.isnan(aucs).sum())
    if n_nan:
        warnings.warn(f"{n_nan} of {len(pairs)} held-out pairs have no AUC (one class only in the pair "
                      "or in its training runs); they are NaN", UndefinedAUCWarning, stacklevel=2)
    return (aucs, pairs) if return_pairs else aucs


def permuted_roles(labels, groups, failed_groups, normal_groups, n_permutations: int,
                   random_state: int | None = 0) -> list[tuple[np.ndarray, list, list]]:
    """Label sets of Procedure 1 with the runs' roles exchanged at random: the null of a permutation test.

    Each permutation gives every run the label sequence of another run with as many samples (a
    random permutation within each sample count), so a run that inherits a failed run's
    sequence becomes failed. The number of failed runs and every label sequence are kept; only
    their link to the features is broken. Leave-pair-out AUC on these labels is the chance level
    of the dataset's robots: when samples of one robot are alike a held-out pair is ranked robot
    against robot, so it spreads widely around 0.5 (Ojala & Garriga 2010, JMLR 11, test 1,
    labels permuted at the level at which they were given).

    Parameters
    ----------
    labels : array-like of shape (n_samples,)
        0/1 labels (:func:`make_labels`).
    groups : array-like of shape (n_samples,)
        Run of each sample; each run's rows in time order.
    failed_groups, normal_groups : sequence
        Runs with and without wear.
    n_permutations : int
        Label sets to draw, >= 1.
    random_state : int or None, default=0
        Seed of ``numpy.random.default_rng``.

    Returns
    -------
    list of (labels, failed, normal)
        ``n_permutations`` label arrays of shape (n_samples,) and the runs that are failed and
        normal under each; a run takes the role of the run whose sequence it got (none if that run
        is in neither list).

    Raises
    ------
    ValueError
        If ``n_permutations`` is not an integer >= 1.
    """
    if not is_whole(n_permutations, 1):
        raise ValueError(f"n_permutations = {n_permutations!r}; expected an integer >= 1")
    labels, groups = np.asarray(labels), np.asarray(groups)
    failed, normal = set(failed_groups), set(normal_groups)
    runs = list(pd.unique(groups))
    rows = {g: np.flatnonzero(groups == g) for g in runs}
    strata: dict[int, list] = {}
    for g in runs:
        strata.setdefault(rows[g].size, []).append(g)
    rng = np.random.default_rng(random_state)
    out = []
    for _ in range(n_permutations):
        permuted, new_failed, new_normal = np.empty_like(labels), [], []
        for members in strata.values():
            for g, donor in zip(members, rng.permutation(np.array(members, dtype=object)), strict=True):
                permuted[rows[g]] = labels[rows[donor]]
                if donor in failed:
                    new_failed.append(g)
                elif donor in normal:
                    new_normal.append(g)
        out.append((permuted, new_failed, new_normal))
    return out


def null_p_value(observed: float, null: np.ndarray) -> float:
    """Permutation p-value of a mean AUC: (1 + #(null >= observed)) / (1 + n), a NaN null value
    counted as reaching it (Phipson & Smyth 2010: never 0, exact for a permutation test)."""
    null = np.asarray(null, dtype=float)
    return float((1 + np.sum(~(null < observed))) / (1 + null.size))


# --------------------------------------------------------------------------------------------
# Procedure 2


@dataclass(frozen=True, eq=False)  # eq of DataFrame fields is ambiguous
class Comparison:
    """Outcome of :func:`compare_preprocessing` (thesis Procedure 2).

    Attributes
    ----------
    levene_statistic, levene_p : float
        Levene's test of equal AUC variance across the combinations.
    equal_variance : bool
        ``levene_p >= alpha`` (a NaN p-value, e.g. every sample constant, counts as equal).
    test : {"anova", "welch_anova"}
        The omnibus test used: one-way ANOVA if equal variances, else Welch's ANOVA.
    statistic, p_value : float
        Its F statistic and p-value (``p_unc`` of pingouin).
    significant : bool
        ``p_value < alpha``.
    posthoc : {"tukey", "games_howell"}
        The post-hoc test that goes with ``test``.
    pairwise : pandas.DataFrame
        pingouin's ``pairwise_tukey`` or ``pairwise_gameshowell`` table (columns ``A``, ``B``,
        ``mean_A``, ``mean_B``, ``diff``, ``T``, p-value ``p_tukey`` or ``pval``, ...), computed
        only when ``significant`` (Procedure 2), else empty.
    alpha : float
    n : dict of str to int
        AUCs per combination after dropping NaN.
    """

    levene_statistic: float
    levene_p: float
    equal_variance: bool
    test: str
    statistic: float
    p_value: float
    significant: bool
    posthoc: str
    pairwise: pd.DataFrame = field(repr=False)
    alpha: float = ALPHA
    n: dict = field(default_factory=dict)


def _p_column(table: pd.DataFrame) -> str:
    for name in ("p_unc", "p-unc"):  # pingouin >= 0.7 / older
        if name in table.columns:
            return name
    raise KeyError(f"no p-value column in pingouin output {list(table.columns)}")


def compare_preprocessing(aucs: Mapping[str, Iterable[float]], alpha: float = ALPHA,
                          center: str = "median") -> Comparison:
    """Does preprocessing change the AUC? Thesis Procedure 2 for one classifier.

    1. Levene's test (``scipy.stats.levene``) for equal variance of AUC across combinations.
    2. Variances differ (``p < alpha``): Welch's ANOVA (``pingouin.welch_anova``), and if it is
       significant the Games-Howell post-hoc test (``pingouin.pairwise_gameshowell``).
       Otherwise: one-way ANOVA (``pingouin.anova``) and Tukey's HSD (``pingouin.pairwise_tukey``).

    Parameters
    ----------
    aucs : mapping of str to array-like of float
        AUCs of each preprocessing combination, e.g. from :func:`leave_pair_out_auc`; NaN are
        dropped. At least two combinations, each with at least two AUCs.
    alpha : float, default=0.05
        Significance level (thesis ch. 5.3.4).
    center : {"median", "mean", "trimmed"}, default="median"
        Levene's centre; the median (Brown-Forsythe) is the default of R's ``lawstat::levene.test``
        the thesis used, and of scipy.

    Returns
    -------
    Comparison

    Raises
    ------
    ValueError
        For fewer than two combinations or one with fewer than two AUCs (named).
    """
    import pingouin as pg  # here, not at the top: it takes seconds to import (statsmodels, seaborn)
    from scipy.stats import levene

    samples = {str(k): np.asarray(list(v), dtype=float) for k, v in aucs.items()}
    samples = {k: v[~np.isnan(v)] for k, v in samples.items()}
    if len(samples) < 2:
        raise ValueError(f"need AUCs of at least two preprocessing combinations, got {len(samples)}")
    for k, v in samples.items():
        if v.size < 2:
            raise ValueError(f"preprocessing {k!r} has {v.size} AUC(s) that are not NaN; at least 2 needed")
    stat, p_levene = levene(*samples.values(), center=center)
    equal = not (p_levene < alpha)
    data = pd.DataFrame({"preprocessing": np.concatenate([[k] * v.size for k, v in samples.items()]),
                         "auc": np.concatenate(list(samples.values()))})
    if equal:
        test, posthoc = "anova", "tukey"
        omnibus = pg.anova(data=data, dv="auc", between="preprocessing")
    else:
        test, posthoc = "welch_anova", "games_howell"
        omnibus = pg.welch_anova(data=data, dv="auc", between="preprocessing")
    p = float(omnibus[_p_column(omnibus)].iloc[0])
    significant = bool(p < alpha)
    if significant:
        run = pg.pairwise_tukey if posthoc == "tukey" else pg.pairwise_gameshowell
        pairwise = run(data=data, dv="auc", between="preprocessing")
    else:
        pairwise = pd.DataFrame()
    return Comparison(levene_statistic=float(stat), levene_p=float(p_levene), equal_variance=equal, test=test,
                      statistic=float(omnibus["F"].iloc[0]), p_value=p, significant=significant,
                      posthoc=posthoc, pairwise=pairwise, alpha=alpha,
                      n={k: int(v.size) for k, v in samples.items()})


# --------------------------------------------------------------------------------------------
# Table 5.2


def evaluate(X, y, groups, failed_groups, normal_groups,
             classifiers: Iterable[str] | Mapping[str, object] = tuple(CLASSIFIERS),
             preprocessing: Iterable[str] | None = None, *, estimated=None, n_pairs: int | None = None,
             random_state: int | None = 0, label_rule=None, matched: bool = False, n_jobs: int | None = None,
             permutations: int = 0, return_aucs: bool = False, progress: bool = False):
    """Mean and standard deviation of leave-pair-out AUC per combination and classifier, Table 5.2.

    Every combination and classifier is scored by :func:`leave_pair_out_auc` on the same pairs.

    Parameters
    ----------
    X, y, groups, failed_groups, normal_groups
        As in :func:`leave_pair_out_auc`.
    classifiers : iterable of str or mapping of str to estimator, default=all of CLASSIFIERS
        Names in :data:`CLASSIFIERS`, or column name -> estimator (cloned per pair).
    preprocessing : iterable of str or None, default=None
        Combination names (:func:`preprocessing_steps`). None: every key of
        :data:`PREPROCESSING`, without the ``+estM`` ones when ``estimated`` is None.
    estimated : array-like of shape (n_samples, n_estimated) or None, default=None
        Estimated quantities (thesis ch. 5.3.2: torque and speed estimated from the indicators),
        appended as columns to ``X`` for the combinations starting with ``+estM``; required by
        them. faultgen has no such block of its own; pass e.g. model-based estimates.
    n_pairs, random_state, label_rule, matched, n_jobs
        As in :func:`leave_pair_out_auc`; ``random_state`` also seeds the classifiers and the
        permutations.
    permutations : int, default=0
        With ``K >= 1``, also the chance level of every cell: the mean AUC on each of ``K`` label
        sets with the runs' roles exchanged (:func:`permuted_roles`, the same sets for every
        cell), reported as their mean (column ``"null"``) and the permutation p-value of the
        observed mean (``"p"``, :func:`null_p_value`). Costs ``K`` times the table.
    return_aucs : bool, default=False
        Also return ``{(classifier, preprocessing): ndarray of AUCs}``, the input of
        :func:`compare_preprocessing`.
    progress : bool, default=False
        Show a progress bar over the (preprocessing, classifier) cells.

    Returns
    -------
    table : pandas.DataFrame
        Index ``preprocessing`` (in the order given), columns a MultiIndex ``(classifier,
        "mean" | "std")``: mean and sample standard deviation (ddof 1) of the AUCs, NaN pairs
        left out; with ``permutations`` also ``"null"`` and ``"p"`` per classifier, and
        ``attrs["null_values"]``: ``"<classifier> <preprocessing>"`` -> the K exchanged mean AUCs.
    aucs : dict
        Only with ``return_aucs=True``.

    Raises
    ------
    ValueError
        As :func:`leave_pair_out_auc`; for an unknown classifier or combination; for ``+estM``
        without ``estimated``, or ``estimated`` with other rows than ``X``; for ``permutations``
        not an integer >= 0.
    """
    X, y, groups, failed, normal = _check_inputs(X, y, groups, failed_groups, normal_groups)
    if not is_whole(permutations, 0):
        raise ValueError(f"permutations = {permutations!r}; expected an integer >= 0 (0: no chance level)")
    if estimated is not None:
        estimated = np.asarray(estimated, dtype=float)
        if estimated.ndim == 1:
            estimated = estimated[:, None]
        if estimated.ndim != 2 or estimated.shape[0] != X.shape[0]:
            raise ValueError(f"estimated must have shape ({X.shape[0]}, n_estimated), got {estimated.shape}")
    if preprocessing is None:
        names = [n for n in PREPROCESSING if estimated is not None or not n.startswith(ESTIMATED)]
    else:
        names = list(preprocessing)
    for name in names:
        preprocessing_steps(name)  # unknown tokens fail before any fitting
        if name.startswith(ESTIMATED) and estimated is None:
            raise ValueError(f"preprocessing {name!r} needs the estimated quantities (estimated=...)")
    if isinstance(classifiers, Mapping):
        models = dict(classifiers)
    else:
        models = {}
        for c in classifiers:
            if c not in CLASSIFIERS:
                raise ValueError(f"unknown classifier {c!r}; expected one of: {', '.join(CLASSIFIERS)}")
            models[c] = c
    labels = make_labels(y, groups, failed, label_rule)
    X_est = np.hstack([X, estimated]) if estimated is not None else None
    roles = permuted_roles(labels, groups, failed, normal, permutations, random_state) if permutations else []

    # one job per (label set, held-out pair): every cell of the pair, each preprocessing computed once
    label_sets = [(labels, failed, normal), *roles]
    jobs = [(k, pair) for k, (_, f, n) in enumerate(label_sets) for pair in select_pairs(f, n, n_pairs, random_state)]
    run = delayed(_pair_cells)
    tasks = (run(X, X_est, label_sets[k][0], groups, pair, names, models, random_state, matched) for k, pair in jobs)
    # these fits are small (hundreds of samples): a BLAS thread pool per process only contends for
    # the cores (quick.h5, a loaded 2-core machine: LR 0.5 s a fit with the pool, 0.02 s without);
    # joblib's workers limit theirs alike
    # loky's workers and trackers start in this folder: no joblib.py of it on their path (issue 61)
    with threadpool_limits(limits=1), children.safe_path():
        results = Parallel(n_jobs=n_jobs if n_jobs is not None else 1, return_as="generator")(tasks)
        per_job = np.array(list(tqdm(results, total=len(jobs), desc="classify", unit="pair", disable=not progress)))
    per_job = per_job.reshape(len(jobs), len(names) * len(models))
    set_of = np.array([k for k, _ in jobs])
    cells = [(name, column) for name in names for column in models]
    aucs: dict[tuple[str, str], np.ndarray] = {}
    null: dict[tuple[str, str], np.ndarray] = {}
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "Mean of empty slice", RuntimeWarning)  # a permutation without AUC
        for c, (name, column) in enumerate(cells):
            aucs[column, name] = per_job[set_of == 0, c]
            null[column, name] = np.array([np.nanmean(per_job[set_of == k, c]) for k in range(1, len(label_sets))])
    n_nan = {int(np.isnan(a).sum()) for a in aucs.values()}
    if n_nan - {0}:
        warnings.warn(f"up to {max(n_nan)} held-out pairs per cell have no AUC (one class only); they are "
                      "left out of mean and std", UndefinedAUCWarning, stacklevel=2)

    statistics = ["mean", "std", "null", "p"] if permutations else ["mean", "std"]
    columns = pd.MultiIndex.from_product([list(models), statistics], names=["classifier", "statistic"])
    table = pd.DataFrame(index=pd.Index(names, name="preprocessing"), columns=columns, dtype=float)
    for (column, name), a in aucs.items():
        valid = a[~np.isnan(a)]
        table.loc[name, (column, "mean")] = valid.mean() if valid.size else np.nan
        table.loc[name, (column, "std")] = valid.std(ddof=1) if valid.size > 1 else np.nan
        if permutations:
            table.loc[name, (column, "null")] = np.nanmean(null[column, name])
            table.loc[name, (column, "p")] = null_p_value(table.loc[name, (column, "mean")], null[column, name])
    if permutations:  # each cell's mean AUC per exchanged label set: what its p-value counts against
        table.attrs["null_values"] = {f"{column} {name}": [float(v) for v in values]
                                      for (column, name), values in null.items()}
    return (table, aucs) if return_aucs else table
