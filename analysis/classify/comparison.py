"""Thesis Procedure 2 (ch. 5.3.4): does preprocessing change the AUC? Levene, then ANOVA + Tukey HSD or
Welch ANOVA + Games-Howell (pingouin)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

#: Significance level of Procedure 2 (thesis ch. 5.3.4).
ALPHA = 0.05


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
