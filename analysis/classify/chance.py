"""The chance level of Procedure 1 on a dataset's robots: label sets with the runs' roles exchanged (a
group-level permutation test, Ojala & Garriga 2010) and the permutation p-value of a mean AUC
(Phipson & Smyth 2010)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from faultgen.checks import is_whole


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
