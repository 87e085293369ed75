"""Every classifier with every preprocessing combination on the same held-out pairs, Table 5.2's
layout, with the chance level of every cell on request."""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Mapping
from functools import partial

import numpy as np
import pandas as pd
from joblib import Parallel, delayed, effective_n_jobs
from sklearn.base import BaseEstimator
from threadpoolctl import threadpool_limits
from tqdm.auto import tqdm

from analysis.classify.chance import null_p_value, permuted_roles
from analysis.classify.classifiers import CLASSIFIERS
from analysis.classify.labels import make_labels
from analysis.classify.leave_pair_out import UndefinedAUCWarning, check_inputs, pair_cells
from analysis.classify.preprocessing import ESTIMATED, PREPROCESSING, preprocessing_steps
from analysis.evaluate import LeavePairOut
from faultgen import children, pools
from faultgen.checks import is_whole


def evaluate(X, y, groups, failed_groups, normal_groups,
             classifiers: Iterable[str] | Mapping[str, object] = tuple(CLASSIFIERS),
             preprocessing: Iterable[str] | None = None, *, estimated=None, n_pairs: int | None = None,
             random_state: int | None = 0, label_rule=None, matched: bool = False, n_jobs: int | None = None,
             permutations: int = 0, null_of: Iterable[str] | None = None, return_aucs: bool = False,
             progress: bool = False):
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
    null_of : iterable of str or None, default=None
        With ``permutations``, the classifiers (columns) whose cells get a chance level; the
        others' ``"null"`` and ``"p"`` are NaN and they have no ``null_values``. None: every one.
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
        not an integer >= 0; for a ``null_of`` name that is not a classifier column.
    """
    X, y, groups, failed, normal = check_inputs(X, y, groups, failed_groups, normal_groups)
    if not is_whole(permutations, 0):
        raise ValueError(f"permutations = {permutations!r}; expected an integer >= 0 (0: no chance level)")
    estimated = _estimated(estimated, X)
    names = _names(preprocessing, estimated)
    models = _models(classifiers)
    judged = _null_of(null_of, models)
    labels = make_labels(y, groups, failed, label_rule)
    roles = permuted_roles(labels, groups, failed, normal, permutations, random_state) if permutations else []
    label_sets = [(labels, failed, normal), *roles]
    jobs = [(k, pair) for k, (_, f, n) in enumerate(label_sets)
            for pair in LeavePairOut(f, n, n_pairs, random_state).pairs()]
    tasks = _tasks(X, estimated, groups, label_sets, jobs, names, models, judged, random_state, matched)
    per_job = np.full((len(jobs), len(names) * len(models)), np.nan)
    for (members, _), found in zip(tasks, _run(tasks, n_jobs, progress), strict=True):
        per_job[members] = found
    aucs, null = _cells(per_job, [k for k, _ in jobs], names, models, judged, len(label_sets))
    table = _table(aucs, null, names, models, permutations)
    return (table, aucs) if return_aucs else table


def _run(tasks: list, n_jobs: int | None, progress: bool) -> list[np.ndarray]:
    """:func:`pair_cells` of each of ``tasks`` (:func:`_tasks`), in their order, on ``n_jobs``
    processes (None: 1; -1: one per core): on Linux forked from this one
    (:func:`faultgen.pools.forked_pool`: they start with its imports, scikit-learn's, SciPy's and
    pandas', which a fresh interpreter takes 2-3 s of CPU to make again), elsewhere joblib's loky."""
    # these fits are small (hundreds of samples): a BLAS thread pool per process only contends for
    # the cores (quick.h5, a loaded 2-core machine: LR 0.5 s a fit with the pool, 0.02 s without);
    # forked workers inherit this limit, joblib's workers limit theirs alike
    # loky's workers and trackers start in this folder: no joblib.py of it on their path
    with threadpool_limits(limits=1), children.safe_path():
        workers = min(effective_n_jobs(n_jobs if n_jobs is not None else 1), len(tasks))
        bar = partial(tqdm, total=len(tasks), desc="classify", unit="pair", disable=not progress)
        if workers > 1 and pools.FORK:
            with pools.forked_pool(workers) as pool:
                return list(bar(pool.map(pair_cells, *zip(*(args for _, args in tasks), strict=True))))
        results = Parallel(n_jobs=n_jobs if n_jobs is not None else 1, return_as="generator")(
            delayed(pair_cells)(*args) for _, args in tasks)
        return list(bar(results))


def _null_of(null_of: Iterable[str] | None, models: dict) -> list[str]:
    """The columns whose cells get a chance level: ``null_of``, or every one of ``models``.

    Raises
    ------
    ValueError
        For a name that is not a column.
    """
    judged = list(models) if null_of is None else list(null_of)
    for column in judged:
        if column not in models:
            raise ValueError(f"null_of names {column!r}, not a classifier here; expected some of: {', '.join(models)}")
    return judged


def _tasks(X, estimated, groups, label_sets: list, jobs: list, names: list[str], models: dict, judged: list[str],
           random_state, matched: bool) -> list[tuple[list[int], tuple]]:
    """One task per held-out pair of runs, whatever the label set (the same training runs, so the
    same preprocessing): (the indices of its ``jobs``, the arguments of :func:`pair_cells`), in the
    order of each pair's first job. A task ships the features only once, and the estimated block
    only where a name needs it (:func:`pair_cells` appends it)."""
    by_pair: dict[frozenset, list[int]] = {}
    for j, (_, pair) in enumerate(jobs):
        by_pair.setdefault(frozenset(pair), []).append(j)
    columns = [list(models), *[judged] * (len(label_sets) - 1)]  # the true labels: every cell
    features = X if any(not n.startswith(ESTIMATED) for n in names) else None
    extra = estimated if any(n.startswith(ESTIMATED) for n in names) else None
    tasks = []
    for members in by_pair.values():
        sets = [(label_sets[jobs[j][0]][0], jobs[j][1], columns[jobs[j][0]]) for j in members]
        tasks.append((members, (features, extra, groups, jobs[members[0]][1], sets, names, models, random_state,
                                matched)))
    return tasks


def _estimated(estimated, X: np.ndarray) -> np.ndarray | None:
    """``estimated`` as an array of shape (n_samples, n_estimated), or None.

    Raises
    ------
    ValueError
        If it has other rows than ``X``.
    """
    if estimated is not None:
        estimated = np.asarray(estimated, dtype=float)
        if estimated.ndim == 1:
            estimated = estimated[:, None]
        if estimated.ndim != 2 or estimated.shape[0] != X.shape[0]:
            raise ValueError(f"estimated must have shape ({X.shape[0]}, n_estimated), got {estimated.shape}")
    return estimated


def _names(preprocessing: Iterable[str] | None, estimated: np.ndarray | None) -> list[str]:
    """The preprocessing combinations to score: ``preprocessing``, or every key of PREPROCESSING (without
    the ``+estM`` ones when ``estimated`` is None).

    Raises
    ------
    ValueError
        For an unknown combination, or one starting ``+estM`` without ``estimated``.
    """
    if preprocessing is None:
        names = [n for n in PREPROCESSING if estimated is not None or not n.startswith(ESTIMATED)]
    else:
        names = list(preprocessing)
    for name in names:
        preprocessing_steps(name)  # unknown tokens fail before any fitting
        if name.startswith(ESTIMATED) and estimated is None:
            raise ValueError(f"preprocessing {name!r} needs the estimated quantities (estimated=...)")
    return names


def _models(classifiers: Iterable[str] | Mapping[str, object]) -> dict[str, object]:
    """Column name -> estimator, or -> its name in CLASSIFIERS.

    Raises
    ------
    ValueError
        For a name not in CLASSIFIERS, or an estimator with a parameter scikit-learn rejects
        (:func:`check_parameters`).
    """
    if isinstance(classifiers, Mapping):
        models = dict(classifiers)
        for model in models.values():  # the workers skip scikit-learn's parameter checks per fit
            if not isinstance(model, str):
                check_parameters(model)
    else:
        models = {}
        for c in classifiers:
            if c not in CLASSIFIERS:
                raise ValueError(f"unknown classifier {c!r}; expected one of: {', '.join(CLASSIFIERS)}")
            models[c] = c
    return models


def _cells(per_job: np.ndarray, set_of: list[int], names: list[str], models: dict, judged: list[str],
           n_sets: int) -> tuple[dict, dict]:
    """(``(classifier, preprocessing)`` -> the AUCs of the true labels' pairs, -> the mean AUC on each
    exchanged label set, for the ``judged`` classifiers) from ``per_job`` (n_jobs, cells), each job's
    label set in ``set_of`` (0: the true labels); an UndefinedAUCWarning where pairs have no AUC."""
    set_of = np.array(set_of)
    cells = [(name, column) for name in names for column in models]
    aucs: dict[tuple[str, str], np.ndarray] = {}
    null: dict[tuple[str, str], np.ndarray] = {}
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "Mean of empty slice", RuntimeWarning)  # a permutation without AUC
        for c, (name, column) in enumerate(cells):
            aucs[column, name] = per_job[set_of == 0, c]
            if column in judged:
                null[column, name] = np.array([np.nanmean(per_job[set_of == k, c]) for k in range(1, n_sets)])
    n_nan = {int(np.isnan(a).sum()) for a in aucs.values()}
    if n_nan - {0}:
        warnings.warn(f"up to {max(n_nan)} held-out pairs per cell have no AUC (one class only); they are "
                      "left out of mean and std", UndefinedAUCWarning, stacklevel=3)
    return aucs, null


def _table(aucs: dict, null: dict, names: list[str], models: dict, permutations: int) -> pd.DataFrame:
    """Table 5.2 from the cells' AUCs (:func:`evaluate`'s Returns)."""
    statistics = ["mean", "std", "null", "p"] if permutations else ["mean", "std"]
    columns = pd.MultiIndex.from_product([list(models), statistics], names=["classifier", "statistic"])
    table = pd.DataFrame(index=pd.Index(names, name="preprocessing"), columns=columns, dtype=float)
    for (column, name), a in aucs.items():
        valid = a[~np.isnan(a)]
        table.loc[name, (column, "mean")] = valid.mean() if valid.size else np.nan
        table.loc[name, (column, "std")] = valid.std(ddof=1) if valid.size > 1 else np.nan
        if permutations and (column, name) in null:
            table.loc[name, (column, "null")] = np.nanmean(null[column, name])
            table.loc[name, (column, "p")] = null_p_value(table.loc[name, (column, "mean")], null[column, name])
    if permutations:  # each cell's mean AUC per exchanged label set: what its p-value counts against
        table.attrs["null_values"] = {f"{column} {name}": [float(v) for v in values]
                                      for (column, name), values in null.items()}
    return table


def check_parameters(estimator) -> None:
    """scikit-learn's check of the parameters of ``estimator`` and of every estimator in it (a
    Pipeline's steps, a stack's members), done once here: :func:`pair_cells` fits with
    ``skip_parameter_validation``.

    Raises
    ------
    ValueError
        scikit-learn's ``InvalidParameterError`` (a ValueError) naming the parameter, its value and
        what it accepts.
    """
    nested = [estimator, *estimator.get_params(deep=True).values()] if hasattr(estimator, "get_params") else []
    for part in nested:
        if isinstance(part, BaseEstimator) and hasattr(part, "_parameter_constraints"):
            part._validate_params()
