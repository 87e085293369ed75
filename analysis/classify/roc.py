"""ROC AUC of one held-out pair's scores by scikit-learn's own arithmetic, without its input checks:
the classification table computes thousands of them on arrays it has already checked."""

from __future__ import annotations

import numpy as np


def binary_auc(truth: np.ndarray, scores: np.ndarray) -> float:
    """Area under the ROC curve of ``scores`` against ``truth``, the same float, bit for bit, as
    ``sklearn.metrics.roc_auc_score(truth, scores)``.

    The same steps as scikit-learn's (1.6-1.9: ``roc_curve`` with ``drop_intermediate=True``, then
    the trapezoidal rule): the scores sorted in descending order, the true and false positives
    counted at each distinct score (whole numbers, exact in float64 whatever the order within
    ties), the points collinear with their neighbours dropped, each count divided by its total,
    and ``sum(dx * (y[1:] + y[:-1]) / 2)`` over the same array; only the checks are left out
    (tests/test_classify_auc_exact.py compares it with scikit-learn on random scores with ties).

    Parameters
    ----------
    truth : ndarray of shape (n_samples,)
        Two distinct labels; the larger is the positive class (as ``roc_auc_score`` takes it).
    scores : ndarray of shape (n_samples,)
        Finite scores, larger meaning more likely positive.

    Returns
    -------
    float
        In [0, 1].

    Raises
    ------
    ValueError
        When ``truth`` has not exactly two labels, or the shapes differ (the caller checks the
        rest: finite scores).
    """
    truth, scores = np.asarray(truth), np.asarray(scores, dtype=float)
    classes = np.unique(truth)
    if classes.size != 2 or truth.shape != scores.shape or truth.ndim != 1:
        raise ValueError(f"binary_auc needs two labels and one score per label, got labels {classes.tolist()} "
                         f"of shape {truth.shape} and scores of shape {scores.shape}")
    order = np.argsort(scores, kind="stable")[::-1]
    ranked = scores[order]
    ends = np.r_[np.flatnonzero(np.diff(ranked)), ranked.size - 1]  # the last row of each distinct score
    tps = np.cumsum((truth[order] == classes[1]).astype(float))[ends]
    fps = 1 + ends.astype(float) - tps
    if fps.size > 2:  # roc_curve's drop_intermediate: keep the corners
        keep = np.r_[True, np.logical_or(np.diff(fps, 2), np.diff(tps, 2)), True]
        fps, tps = fps[keep], tps[keep]
    fpr, tpr = np.r_[0.0, fps] / fps[-1], np.r_[0.0, tps] / tps[-1]
    return float(np.sum((fpr[1:] - fpr[:-1]) * (tpr[1:] + tpr[:-1]) / 2.0))
