"""The wear stage (:class:`faultgen.monitor.wear.WearEstimator`) on its own: a log's wear read
filtered, its alarm bound with the scale's doubt, the at-once rule, an axis not observable."""

from statistics import NormalDist

import numpy as np

from faultgen.monitor.alarm import alarm_quantile
from faultgen.monitor.scoring import Settings
from faultgen.monitor.wear import SCALE_UNCERTAINTY, WearEstimator


def _first_read(log, observable):
    wear = WearEstimator(Settings(wear_limit=10.0, alpha=0.01), 2)
    error = np.array([2.0, 2.0])
    filtered, alarm, at_once, row = wear.read("001", (np.array(log), error, error, None), np.array(observable))
    return wear, filtered, alarm, at_once, row


def test_the_first_read_starts_the_filter_and_alarms_when_its_lower_bound_reaches_the_limit():
    for log, expected in (([20.0, 30.0], (True, True)), ([12.0, 30.0], (False, False))):
        wear, filtered, alarm, at_once, row = _first_read(log, [True, False])
        np.testing.assert_allclose(filtered[0][0], log[0])  # the first log starts the filter at its read
        sd = np.sqrt(wear.trend.covariance[0, 0, 0])
        lower = log[0] - alarm_quantile() * np.hypot(sd, SCALE_UNCERTAINTY * log[0])  # the scale's doubt in it
        assert abs(row.lower[0] - lower) < 1e-12
        assert (alarm, at_once) == expected == (lower >= 10.0, 2 * lower - log[0] >= 10.0)
        assert abs(row.log_lower[0] - (log[0] - NormalDist().inv_cdf(0.99) * 2.0)) < 1e-12
        # axis 2 is not observable: no numbers, and its 30 % does not alarm
        assert all(np.isnan(getattr(row, name)[1]) for name in ("estimate", "lower", "p5", "p95", "log", "log_lower"))


def test_an_axis_not_observable_cannot_alarm():
    _, _, alarm, at_once, row = _first_read([40.0, 40.0], [False, False])
    assert not alarm and not at_once and np.all(np.isnan(row.estimate)) and row.tests is None
