"""Class labels of the samples (0 normal, 1 failed): given, by a wear threshold, or by a rule such as
the thesis's last samples before the failure (ch. 5.3.3); a normal run never has a failed sample."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from faultgen.checks import is_whole


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
