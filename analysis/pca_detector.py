"""The PCA T2/Q monitor of thesis ch. 2.3 as a benchmark detector (the ``pca`` baseline of the
registry, :mod:`analysis.registry`), apart from the registry so that listing the baselines imports
no scikit-learn. It fits :class:`analysis.monitoring.PCAMonitor` itself: it is a registry entry, and
the registry imports it (asking the registry back would make the two modules import each other)."""

from __future__ import annotations

import numpy as np
from sklearn.base import BaseEstimator


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
        """Learn healthy records ``X`` of shape (n_records, n_features); returns itself.

        Raises
        ------
        ValueError
            As :meth:`analysis.monitoring.PCAMonitor.fit` (too few records, a variance that leaves no
            residual space).
        """
        from analysis.monitoring import PCAMonitor, varying_columns

        X = np.asarray(X, dtype=float)
        self.columns_ = varying_columns(X)
        # the same PCAMonitor as the registry's pca_monitor (analysis.registry), with its parameters
        self.monitor_ = PCAMonitor(variance=self.variance, alpha=self.alpha).fit(X[:, self.columns_])
        return self

    def decision_function(self, X) -> np.ndarray:
        t2, q = self.monitor_.score_samples(np.asarray(X, dtype=float)[:, self.columns_])
        return np.maximum(t2 / self.monitor_.t2_limit_, q / self.monitor_.q_limit_)

    def predict(self, X) -> np.ndarray:
        return self.decision_function(X) > 1.0
