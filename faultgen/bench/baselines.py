"""The named baselines of ``faultgen bench score --baseline NAME``: the thesis's methods and two
maintained library detectors outside it.

Detectors (scored like a ``--detector`` plug-in, :mod:`faultgen.bench.score`):

- ``pca``: the PCA monitor of thesis ch. 2.3 (:class:`analysis.monitoring.PCAMonitor`, 75 % of the
  variance as in ch. 3.2.2, alarm on T2 or Q above its 95 % limit), its score the larger of T2 and
  Q as a multiple of its limit; learns the healthy train units of the test unit's robot and task;
- ``lr``, ``svm``, ``rf``, ``stacking``: the classifiers of thesis ch. 5.2
  (:data:`analysis.classify.CLASSIFIERS`), trained on every train record labelled worn at
  >= 10 % (Table 5.2's rule);
- ``iforest``, ``ecod``: pyod's isolation forest (Liu, Ting & Zhou 2008) and ECOD (Li et al. 2022),
  outside the thesis, from the optional ``bench`` extra (``pip install faultgen-robots[bench]``).

Isolators (scored like an ``--isolator`` plug-in): ``transfer_entropy``, ``cross_correlation``,
``granger``, ``trend``, ``pca_contribution`` (:data:`analysis.isolation.ISOLATORS`, thesis ch. 3.3 and 6.3).
"""

from __future__ import annotations

import numpy as np
from sklearn.base import BaseEstimator

DETECTORS = ("pca", "lr", "svm", "rf", "stacking", "iforest", "ecod")
ISOLATORS = ("transfer_entropy", "cross_correlation", "granger", "trend", "pca_contribution")


class PCADetector(BaseEstimator):
    """The PCA T2/Q monitor as a benchmark detector: ``decision_function`` is ``max(T2 / T2_limit,
    Q / Q_limit)`` (> 1: an alarm), features that do not vary in training left out.

    Parameters
    ----------
    variance : float, default=0.75
        Share of the variance kept (thesis ch. 3.2.2).
    alpha : float, default=0.05
    """

    def __init__(self, variance: float = 0.75, alpha: float = 0.05):
        self.variance = variance
        self.alpha = alpha

    def fit(self, X, y=None) -> PCADetector:
        from analysis.monitoring import PCAMonitor, varying_columns

        X = np.asarray(X, dtype=float)
        self.columns_ = varying_columns(X)
        self.monitor_ = PCAMonitor(variance=self.variance, alpha=self.alpha).fit(X[:, self.columns_])
        return self

    def decision_function(self, X) -> np.ndarray:
        t2, q = self.monitor_.score_samples(np.asarray(X, dtype=float)[:, self.columns_])
        return np.maximum(t2 / self.monitor_.t2_limit_, q / self.monitor_.q_limit_)

    def predict(self, X) -> np.ndarray:
        return self.decision_function(X) > 1.0


def make(name: str) -> tuple[str, BaseEstimator]:
    """(role, a new unfitted estimator) of the baseline ``name``.

    Raises
    ------
    ValueError
        For an unknown name (listing them), or a pyod baseline without pyod installed (saying how).
    """
    if name == "pca":
        return "detector", PCADetector()
    if name in ("lr", "svm", "rf", "stacking"):
        from analysis.classify import CLASSIFIERS

        if name == "stacking":  # folds by sample: the benchmark's fit sees records, not their units
            return "detector", CLASSIFIERS[name](random_state=0, inner_cv="sample")
        return "detector", CLASSIFIERS[name](random_state=0)
    if name in ("iforest", "ecod"):
        try:
            if name == "iforest":
                from pyod.models.iforest import IForest

                return "detector", IForest(random_state=0)
            from pyod.models.ecod import ECOD

            return "detector", ECOD()
        except ImportError:
            raise ValueError(f"baseline {name!r} needs pyod: pip install 'faultgen-robots[bench]' (or pyod)") from None
    if name in ISOLATORS:
        from analysis import isolation

        return "isolator", isolation.make(name)
    raise ValueError(f"unknown baseline {name!r}; expected one of: {', '.join(DETECTORS + ISOLATORS)}")
