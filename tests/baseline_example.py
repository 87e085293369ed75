"""Baselines added in one file (issue 57: "adding a detector baseline touches 1 file"), one of each
role: a detector (``zmean``, the z-score of a record's mean standardised feature against the healthy
records'), an isolator (``rise``, the axis whose signal rose most) and a prognoser (``doubling``, the
end of life at twice the time so far).

Importing this module registers them (:func:`faultgen.bench.baselines.register`); from then on
``zmean`` is a name of ``faultgen bench score --baseline``, ``faultgen detect --baseline``,
``faultgen bench baselines`` and the leaderboard's list (``benchmarks/bench_all.py``), ``rise`` is
one of the isolators ``faultgen bench-isolators`` runs, and ``doubling`` a name of ``faultgen bench
score prognostics --prognoser``. A baseline shipped with faultgen is the same decorated function in
``faultgen/bench/baselines.py``. tests/test_baseline_registry.py uses it.
"""

from __future__ import annotations

import numpy as np
from sklearn.base import BaseEstimator

from faultgen.bench import baselines


class ZScoreOfMean(BaseEstimator):
    """Alarm where a record's mean standardised feature lies more than ``limit`` standard deviations
    from the healthy records' mean.

    Parameters
    ----------
    limit : float, default=3.0
        The alarm threshold, in standard deviations of the healthy records' mean feature.
    """

    def __init__(self, limit: float = 3.0):
        self.limit = limit

    def _means(self, X) -> np.ndarray:
        return ((np.asarray(X, dtype=float) - self.center_) / self.scale_).mean(axis=1)

    def fit(self, X, y=None) -> ZScoreOfMean:
        """Learn healthy records ``X`` of shape (n_records, n_features)."""
        X = np.asarray(X, dtype=float)
        spread = X.std(axis=0)
        self.center_, self.scale_ = X.mean(axis=0), np.where(spread > 0, spread, 1.0)
        means = self._means(X)
        self.mean_, self.std_ = means.mean(), max(means.std(), 1e-12)
        return self

    def decision_function(self, X) -> np.ndarray:
        """The score per record, shape (n_records,): larger, more likely faulty."""
        return np.abs(self._means(X) - self.mean_) / self.std_

    def predict(self, X) -> np.ndarray:
        """One alarm per record, shape (n_records,)."""
        return self.decision_function(X) > self.limit


@baselines.register("zmean", "detector", "z-score of the mean standardised feature (a test-only example)")
def zmean() -> ZScoreOfMean:
    return ZScoreOfMean()


class LargestRise(BaseEstimator):
    """The isolator contract (analysis.isolation): ``fit(X)``, X of shape (n_cycles, N), sets
    ``source_axis_`` to the 1-based axis whose signal rose most from the first cycle to the last."""

    def fit(self, X, y=None) -> LargestRise:
        X = np.asarray(X, dtype=float)
        self.source_axis_ = int(np.argmax(X[-1] - X[0])) + 1
        return self


@baselines.register("rise", "isolator", "the axis whose signal rose most (a test-only example)")
def rise() -> LargestRise:
    return LargestRise()


class Doubling:
    """The prognoser contract (faultgen.bench.prognosers): the end of life at twice the time of the
    unit's last record so far, whatever it shows."""

    def fit(self, units, failure_wear: float) -> Doubling:
        return self

    def predict(self, unit) -> np.ndarray:
        return np.array([2.0 * float(unit.arrays["cycles"][-1])])


@baselines.register("doubling", "prognoser", "the end of life at twice the time so far (a test-only example)")
def doubling() -> Doubling:
    return Doubling()
