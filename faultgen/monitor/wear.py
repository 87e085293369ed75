"""The wear stage (:class:`WearEstimator`): each axis's wear as a log reads it (the baseline's
estimate, :meth:`faultgen.monitor.baseline.Baseline.wear_estimate`) filtered over the unit's logs
(:class:`~faultgen.monitor.wear_trend.WearTrend`), put on the unit's friction tests' scale when it
has them (:mod:`faultgen.monitor.friction_tests`), with its interval and the lower bound the alarm
is judged on (:mod:`faultgen.monitor.scoring`'s docstring)."""

from __future__ import annotations

from statistics import NormalDist

import numpy as np

from faultgen.monitor import bounds, record
from faultgen.monitor.alarm import alarm_quantile
from faultgen.monitor.baseline import WEAR_INTERVAL_Z
from faultgen.monitor.wear_trend import WearTrend

#: Relative standard uncertainty of the wear signature's scale: how far the change of a unit's
#: features per % of its own dry friction may lie from its twin's, which the 90 % interval of each
#: wear estimate carries beside the noise (:meth:`WearEstimator.wear_interval`). What it rests on
#: (docs/analysis.md, "Wear in the robot's own scale"): the signature's scale moved by 0.89-1.08
#: between the friction states of the independent fleet's units (their joints at 20-40 deg C, no
#: part or 25 kg) against the twin at the model's own friction, noise-free; and a calibrated
#: model's dry friction of the worn axis was 0.90-0.97 of the unit's own on seed 0 of that fleet
#: (the calibration fits some axes' Coulomb friction; the others stay nominal, 15 % unit spread).
#: Chosen on seeds 0 and 1 of that fleet, checked on a held-out seed and a second friction law.
SCALE_UNCERTAINTY = 0.10


class WearEstimator:
    """A unit's wear under ``settings`` (``alpha``, ``wear_limit``) on its ``n_axes`` axes: the filter
    :attr:`trend` and the friction tests' scale :attr:`tests`."""

    def __init__(self, settings, n_axes: int):
        self.settings, self.n_axes = settings, n_axes
        #: Each axis's wear filtered over the logs (the wear reported and alarmed on).
        self.trend = WearTrend(n_axes)
        #: The unit's friction tests' scale (:class:`faultgen.monitor.friction_tests.Rescale`), or
        #: None: the wear in the twin's scale.
        self.tests = None

    def start(self, regressors: int, error: np.ndarray | None, gram_inv: np.ndarray) -> None:
        """The filter started on a learned baseline of ``regressors`` condition slopes, their error in
        its state (``error`` (n_axes,): an unworn axis's wear standard error, None without a twin;
        ``gram_inv``: the learning conditions' (X'X)^-1)."""
        self.trend = WearTrend(self.n_axes, regressors)
        if error is not None:
            self.trend.set_prior(error[:, None, None] ** 2 * gram_inv[None])

    @property
    def bound_quantile(self) -> float:
        """The standard normal's ``1 - alpha`` quantile: the lower bound of a log's own wear
        estimate (``wearI_log_lower``) is the estimate minus this many standard errors."""
        return float(NormalDist().inv_cdf(1.0 - self.settings.alpha))

    @staticmethod
    def wear_interval(estimate: np.ndarray, error: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The :data:`~faultgen.monitor.baseline.WEAR_INTERVAL` (90 %) interval of wear ``estimate`` %
        whose noise has standard ``error`` %, both (n_axes,): the estimate -+ the normal quantile times
        ``sqrt(error^2 + (SCALE_UNCERTAINTY estimate)^2)``, the twin's model uncertainty
        (:data:`SCALE_UNCERTAINTY`, a share of the estimate: a scale) beside the noise. Returns (lower, upper), %."""
        return bounds.interval(estimate, bounds.standard_error(error, estimate, SCALE_UNCERTAINTY), WEAR_INTERVAL_Z)

    def read(self, stamp: str, wear, observable: np.ndarray):
        """A log's ``wear`` (its own estimate (n_axes,), its error, the filter's measurement error and
        the log's centred conditions) filtered: returns the filtered wear and its bound's error (as
        the alarm reads it), whether the log alarms and alarms at once (an axis ``observable``
        whose lower bound reaches ``wear_limit``; by its own width), and the row's
        :class:`faultgen.monitor.record.AxisWear`."""
        log_estimate, log_error, trend_error, x = wear
        estimate, error = self.trend.update(log_estimate, trend_error, x)
        # the log's own estimate less the slope errors' part at its conditions, as learned up
        # to it: the season the learned slopes extrapolate, which the remaining life's trend
        # would otherwise take for wear (docs/analysis.md, "The log's own estimate without
        # the season")
        log_estimate = log_estimate - self.trend.condition_part(x)
        bound = bounds.lower_bound(estimate, error, SCALE_UNCERTAINTY, alarm_quantile())  # with the scale's doubt
        # the interval keeps the log's own error: the filter averages out the scatter from log
        # to log, not the errors that stay for weeks (the learned temperature slopes
        # extrapolated over a season, the calibration's friction), which the learning logs
        # cannot tell apart (docs/analysis.md, "Wear in the robot's own scale")
        low, high = self.wear_interval(estimate, np.maximum(log_error, error))  # the filter's lag widens it
        tested = None
        if self.tests is not None:  # on the unit's friction tests' scale
            estimate, low, high, bound, log_estimate, log_error, tested = self._on_tests(
                stamp, estimate, error, log_estimate, log_error)
        filtered = (estimate, (estimate - bound) / alarm_quantile())  # the bound's error, as the alarm reads it
        limit = self.settings.wear_limit
        alarm = bool(np.max(np.where(observable, bound, -np.inf)) >= limit)
        # the lower bound above the limit by its own width (the filtered wear less two of its
        # quantiles): alarmed at once, persistence cannot hide it
        at_once = bool(np.max(np.where(observable, 2 * bound - estimate, -np.inf)) >= limit)
        hidden = np.where(observable, 1.0, np.nan)  # an axis not observable has no wear (NOT_OBSERVABLE_LIMITS)
        estimate, bound, low, high = estimate * hidden, bound * hidden, low * hidden, high * hidden
        log_estimate, log_error = log_estimate * hidden, log_error * hidden
        row = record.AxisWear(*(np.asarray(v, dtype=float) for v in (
            estimate, bound, low, high, log_estimate, log_estimate - self.bound_quantile * log_error)), tested)
        return filtered, alarm, at_once, row

    def _on_tests(self, stamp, estimate, error, log_estimate, log_error):
        """The filtered wear, its interval, alarm bound and the log's own estimate (with its error)
        on the unit's friction tests' scale (:mod:`faultgen.monitor.friction_tests`), and the row's
        twin-scale values, factors and scales."""
        factor, factor_error, names = self.tests.at(stamp, estimate, error)
        wear, sd = self.tests.wear(estimate, error, factor, factor_error)  # the scale's doubt in it (module bounds)
        low, high = bounds.interval(wear, sd, WEAR_INTERVAL_Z)
        lower = log_estimate - self.bound_quantile * log_error
        row = record.TestsScale(*(np.asarray(v, dtype=float) for v in (log_estimate, lower, factor, factor_error)),
                                tuple(names))
        floor = self.tests.floored(wear - alarm_quantile() * sd)  # right after tests.wear, for the same log
        return wear, low, high, floor, factor * log_estimate, factor * log_error, row
