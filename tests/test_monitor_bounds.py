"""The wear's doubts put together (issue 90, "Daily scatter, honest bounds": :mod:`faultgen.monitor.bounds`)
and the wear filter adapted to a fast wear (:class:`faultgen.monitor.wear_trend.WearTrend`)."""

import numpy as np
import pytest

from faultgen.monitor import bounds
from faultgen.monitor.friction_tests import SCALE_PRIOR, Rescale
from faultgen.monitor.wear_trend import WEAR_RATE_CHANGE, WearTrend

Z90, Z90_ONE_SIDED = 1.6449, 1.2816


def test_the_arithmetic_at_known_values():
    np.testing.assert_allclose(bounds.standard_error(np.array([3.0, 0.0]), np.array([40.0, 10.0]), 0.1), [5.0, 1.0])
    low, high = bounds.interval(np.array([12.0]), np.array([2.0]), 1.5)
    assert (low[0], high[0]) == (9.0, 15.0)
    # the alarm: 12.2 % read, the filter's error 0.3: 11.8 without the scale, below 8.0 with it
    assert 12.2 - Z90_ONE_SIDED * 0.3 == pytest.approx(11.8, abs=0.05)
    assert bounds.lower_bound(np.array([12.2]), np.array([0.3]), SCALE_PRIOR, Z90_ONE_SIDED)[0] < 8.0
    np.testing.assert_allclose(bounds.day_scatter(np.array([[1.0, 0.0], [3.0, 0.0], [5.0, 0.0]])), [2.0, 0.0])
    assert np.isnan(bounds.day_scatter(np.ones((1, 3)))).all()


def test_the_scale_doubt_against_a_monte_carlo():
    """A read is the wear times a scale drawn about 1 (relative standard error 0.1, the twin's) plus a
    noise: the 90 % interval with the scale's doubt covers the truth on 88-92 % of 200 000 draws (89.7
    and 90.1 % measured at noises of 0.5 and 2 points), the lower one-sided 90 % bound lies below the
    truth on at least 90 % (92.1-92.8 %); without the scale's doubt, on 63 and 80 %."""
    rng = np.random.default_rng(0)
    for noise in (0.5, 2.0):
        wear = rng.uniform(5.0, 40.0, 200_000)
        read = rng.normal(1.0, 0.1, wear.size) * wear + rng.normal(0.0, noise, wear.size)
        low, high = bounds.interval(read, bounds.standard_error(noise, read, 0.1), Z90)
        assert 0.88 <= np.mean((low <= wear) & (wear <= high)) <= 0.92
        assert np.mean(bounds.lower_bound(read, noise, 0.1, Z90_ONE_SIDED) <= wear) >= 0.90
        assert np.mean(read - Z90_ONE_SIDED * noise <= wear) < 0.85


def test_the_adaptation_at_known_values():
    # covariance matching: the rate's gain squared times the mean squared innovation, NaN left out
    innovations = np.array([[2.0, np.nan, 0.1], [4.0, np.nan, 0.1]])
    np.testing.assert_allclose(bounds.adapted_rate_variance(0.01, np.array([0.5, 0.5, 0.5]), innovations),
                               [0.25 * 10.0, 0.01, 0.01])
    normalised = np.array([[9.0, 1.0, np.nan], [3.0, 1.0, np.nan], [6.0, 1.0, np.nan]])
    np.testing.assert_allclose(bounds.fading_factor(normalised), [6.0, 1.0, 1.0])
    assert bounds.FADING_THRESHOLD == pytest.approx(11.345 / 3)


def _ramp(rate: float, noise: float, adaptive: bool, seed: int = 1, runs: int = 30):
    """The filtered wear's errors, and whether its 90 % interval held the truth, at 10-40 % true
    wear, on ``runs`` axes wearing ``rate`` points a log from log 30, each log read to ``noise``."""
    rng = np.random.default_rng(seed)
    errors, covered = [], []
    for _ in range(runs):
        truth = np.maximum(np.arange(80) - 30, 0) * rate
        trend = WearTrend(1, adaptive=adaptive)
        for k in range(80):
            wear, sd = trend.update(np.array([truth[k] + rng.normal(0.0, noise)]), np.array([noise]))
            if 10 <= truth[k] <= 40:
                errors.append(wear[0] - truth[k])
                covered.append(abs(wear[0] - truth[k]) <= Z90 * sd[0])
    return np.array(errors), np.mean(covered)


def test_the_filter_follows_a_wear_of_3_points_a_log():
    """Issue 90: a wear of 3 points a day outran the filter (4-9 points behind, the interval covering
    67 %). On 30 synthetic axes read to 1.5 points the adapted filter lags by 0.3 point on the mean
    and its 90 % interval covers 85 % of the logs at 10-40 % true wear (measured 2026-11-27); the fixed
    trend lags by 3.1 and covers 17 %."""
    errors, covered = _ramp(3.0, 1.5, adaptive=True)
    assert abs(np.mean(errors)) < 0.5 and 0.80 <= covered <= 0.97, (np.mean(errors), covered)
    errors, covered = _ramp(3.0, 1.5, adaptive=False)
    assert np.mean(errors) < -2.0 and covered < 0.5


def test_the_adaptation_leaves_a_trend_that_describes_its_logs_alone():
    """An unworn axis's logs (innovations of their stated spread) adapt the trend on few logs: the
    rate's process noise stays at its floor on at least 95 % of them."""
    rng = np.random.default_rng(2)
    trend, floors = WearTrend(4), []
    for _ in range(300):
        trend.update(rng.normal(0.0, 2.0, 4), np.full(4, 2.0))
        floors.append(trend.rate_variance == WEAR_RATE_CHANGE**2)
    assert np.mean(floors) >= 0.95


def test_an_axis_no_test_has_told_keeps_the_scale_prior():
    """Before a friction test pairs an axis, its factor is the twin's scale (1) with the prior's doubt
    (:data:`faultgen.monitor.friction_tests.SCALE_PRIOR`), not none: the bound an alarm is judged on
    carries it (issue 90: a bound of 11.8 % at 8.0 % true wear)."""
    factor, error, names = Rescale("u", 3, []).at("2026-01-05", np.array([12.2, 0.0, 1.0]), np.full(3, 0.3))
    np.testing.assert_allclose(factor, 1.0)
    np.testing.assert_allclose(error, SCALE_PRIOR)
    assert names == ["twin"] * 3


def test_each_axis_states_its_tests_scatter_about_the_temperature_law():
    """tests.csv's ``scatter_percent``: each axis's scatter of ``ln c`` about its own line in the
    temperature (the residuals' standard deviation, 2 parameters fitted), against numpy's polyfit."""
    from faultgen.monitor.temperature_law import learn_law

    rng = np.random.default_rng(4)
    t = rng.uniform(15.0, 35.0, 9)
    series = {k: (t, np.log(10.0 * k) - 0.004 * t + rng.normal(0.0, 0.01 * k, t.size)) for k in (1, 2, 3)}
    law = learn_law(series)
    for k, (x, y) in series.items():
        residual = y - np.polyval(np.polyfit(x, y, 1), x)
        assert law.scatter[k] == pytest.approx(np.sqrt(np.sum(residual**2) / (x.size - 2)), rel=1e-9)
    assert law.scatter[1] < law.scatter[3]


def test_a_worn_axis_states_the_scatter_of_its_tests_before_its_wear():
    """The scatter stated per axis, and the repeatability every test's error carries, are the plant's,
    not the wear (issue 90, item 3: "estimated from the unit's own healthy days and tests"): a unit of
    six axes, nine tests 14 days apart, the dry level falling 0.4 %/K with a 1.5 % scatter from test to
    test; axis 3 worn from the fifth test (0, 7, 14, .. 35 %), axis 1's reference test 3 % low (every
    later test reads it 3 % high: no wear, its tests all kept). On main 15a11aa axis 3 stated its wear
    as the plant's scatter, 8.9 %. Each axis's scatter against numpy's polyfit on the tests kept (axis
    3's first four: the fifth, at 7 % wear, is 5.4 repeatabilities above them; every test of the
    others), the repeatability against statsmodels' OLS of every kept test with a line per axis (ISO
    5725-2's pooled repeatability: the regression's residual standard deviation)."""
    import statsmodels.api as sm

    from faultgen.monitor.temperature_law import HEALTHY_Z, healthy_tests, learn_law

    rng = np.random.default_rng(7)
    t = 22.0 + 8.0 * np.sin(np.arange(9) / 2.0)
    wear = np.clip(7.0 * (np.arange(9) - 3), 0.0, None)
    series = {}
    for k in range(1, 7):
        y = np.log(100.0 * k) - 0.004 * t + rng.normal(0.0, 0.015, 9)
        if k == 1:
            y[0] -= 0.03
        if k == 3:
            y += np.log1p(wear / 100)
        series[k] = (t, y)
    law = learn_law(series)
    assert law.beta == pytest.approx(-0.004, abs=0.002)
    median = float(np.median([np.sqrt(np.sum((y - np.polyval(np.polyfit(t, y, 1), t)) ** 2) / 7)
                              for _, y in series.values()]))
    kept = {k: healthy_tests(x, y, law.beta, median) for k, (x, y) in series.items()}
    assert kept == {1: 9, 2: 9, 3: 4, 4: 9, 5: 9, 6: 9}
    for k, (x, y) in series.items():
        n = kept[k]
        residual = y[:n] - np.polyval(np.polyfit(x[:n], y[:n], 1), x[:n])
        assert law.scatter[k] == pytest.approx(np.sqrt(np.sum(residual**2) / (n - 2)), rel=1e-9)
    rows = [(k, x[j], y[j]) for k, (x, y) in series.items() for j in range(kept[k])]
    design = np.array([[float(a == k) * v for k in series for v in (1.0, x)] for a, x, _ in rows])
    ols = sm.OLS(np.array([r[2] for r in rows]), design).fit()
    assert law.repeatability == pytest.approx(np.sqrt(ols.scale), rel=1e-9)
    assert law.repeatability == pytest.approx(0.015, rel=0.3) and max(law.scatter.values()) < 0.03
    # the fifth test of axis 3 against the four before it, in the axes' median scatter (the cut: HEALTHY_Z)
    level = series[3][1] - law.beta * t
    assert (level[4] - level[:4].mean()) / (median * np.sqrt(1.25)) > HEALTHY_Z
    # every test counted, as main did: the wear is stated as the plant's scatter
    residual = series[3][1] - np.polyval(np.polyfit(t, series[3][1], 1), t)
    assert np.sqrt(np.sum(residual**2) / 7) > 0.08


def _test_wears(true, offset, reference_error=0.02, own_error=0.014):
    """One axis's tests (friction_tests.AxisWear) every other day: the reference reads 0, each later
    test's dry level ``1 + offset/100`` times the truth's (the reference read that much low, which every
    later test shares): its wear ``w + offset (1 + w/100)``, % of the reference's level."""
    from faultgen.data import logfolder
    from faultgen.monitor import friction_tests

    stamps = [f"2026-01-{2 * j + 1:02d}" for j in range(len(true))]
    wears = []
    for j, (stamp, w) in enumerate(zip(stamps, true)):
        y = w + offset * (1 + w / 100) if j else 0.0
        wears.append(friction_tests.AxisWear(stamp, logfolder.parse_stamp(stamp, "u")[0], 1, {}, y, y - 2, y + 2,
                                             own_error, reference_error, "", j == 0, own_error))
    return stamps, wears


def test_a_reference_tests_offset_told_before_the_wear_is_not_read_as_wear():
    """Issue 90 (the small 1.5 % fleet of seed 0: its reference test read 2.8 % low, every later test
    of the worn axis 3-4 points high, the alarm's bound above the truth): the pairs before the wear
    alone tell the offset ``b``; the factor's drift (``SCALE_DRIFT``) weighs a pair down by its ``x``,
    so they are not forgotten and the offset does not go into the factor. Twin scale = truth, 5 tests
    before the wear, then 8 to 48 %, each later test's level 3 % high: the logs on the tests' scale read
    within 1.5 points of 48 % (each earlier pair's weight times 0.6 a test, as before: 2.4 points)."""
    true = np.array([0.0] * 5 + [6.0 * k for k in range(1, 9)])
    stamps, wears = _test_wears(true, 3.0)
    scale = Rescale("u", 1, wears)
    for stamp, w in zip(stamps, true):
        factor, error, _ = scale.at(stamp, np.array([w]), np.array([0.5]))
    assert abs(factor[0] * 48.0 - 48.0) < 1.5 and abs(factor[0] - 1.0) < 1.5 * error[0], (factor, error)


def _blue(a, b, va, vb, c):
    """The generalised least squares estimate of one value read twice, ``[a, b]`` with covariance
    ``[[va, c], [c, vb]]``, and its variance (an independent reference for bounds.test_read)."""
    cov_inv = np.linalg.inv(np.array([[va, c], [c, vb]]))
    ones = np.ones(2)
    variance = 1.0 / (ones @ cov_inv @ ones)
    return variance * (ones @ cov_inv @ np.array([a, b])), variance


def test_a_test_read_at_once_against_generalised_least_squares():
    """bounds.test_read: on the test's own log, the test's read and the logs' ``f x`` (the factor's
    doubt 0.3 before any informative test) combined; on a later log, the test carried by the logs'
    growth, the factor's error common to both: the same as numpy's GLS on the stated covariance."""
    f, sf, x, e, y, sy, xt, et = 1.0, 0.3, 20.0, 1.0, 14.0, 1.5, 20.0, 1.0
    fused, sd = bounds.test_read((f, sf), (x, e), (y, sy, xt, et), True)
    want, variance = _blue(f * x, y, (sf * x) ** 2 + (f * e) ** 2, sy**2, 0.0)
    assert float(fused) == pytest.approx(want, rel=1e-12) and float(sd) == pytest.approx(np.sqrt(variance), rel=1e-12)
    assert abs(float(fused) - y) < 0.5 and float(sd) < sy  # the test's read, not the logs' read to 30 %
    x, e = 26.0, 1.2  # six points later: the filter's errors then and now independent, the factor's common
    fused, sd = bounds.test_read((f, sf), (x, e), (y, sy, xt, et), False)
    va, vb = (sf * x) ** 2 + (f * e) ** 2, sy**2 + (sf * (x - xt)) ** 2 + f**2 * (e**2 + et**2)
    want, variance = _blue(f * x, y + f * (x - xt), va, vb, sf**2 * x * (x - xt) + f**2 * e**2)
    assert float(fused) == pytest.approx(want, rel=1e-12) and float(sd) == pytest.approx(np.sqrt(variance), rel=1e-12)
    # no test (NaN): the logs' read and its error alone
    fused, sd = bounds.test_read((f, sf), (x, e), (np.nan, sy, xt, et), True)
    assert float(fused) == f * x and float(sd) == pytest.approx(np.hypot(sf * x, f * e))


def test_a_test_read_at_once_covers_the_truth_on_a_monte_carlo():
    """The wear on the test's own log drawn as the model states it (the factor f ~ N(1, 0.3), the
    filter's error 1 point, the test's 1.5): the combined read's 90 % interval covers the truth on
    88-92 % of 100 000 draws, and its error is below the test's."""
    rng = np.random.default_rng(7)
    n, f, sf, e, sy = 100_000, 1.0, 0.3, 1.0, 1.5
    wear = rng.uniform(5.0, 40.0, n)
    factor = rng.normal(1.0, sf, n)  # the twin's scale over the truth's: x = wear / factor
    x = wear / factor + rng.normal(0.0, e, n)
    y = wear + rng.normal(0.0, sy, n)
    fused, sd = bounds.test_read((f, sf), (x, e), (y, sy, x, e), True)
    assert 0.88 <= np.mean(np.abs(fused - wear) <= Z90 * sd) <= 0.92
    assert np.all(sd < sy)


def test_a_fast_wear_is_read_at_its_test_and_the_test_stays_in_the_factor():
    """A unit wearing fast whose filter lags (twin scale 14 % where the test reads 24 %, the tests
    before it unworn): on the test's log the wear on the tests' scale is the test's (to within its
    error, not 14 -+ 30 %), so its lower 90 % bound passes a 10 % limit at once; the next log is read
    by the factor the test gave."""
    true = np.array([0.0, 0.0, 24.0])
    stamps, wears = _test_wears(true, 0.0)
    scale = Rescale("u", 1, wears)
    for stamp, x in zip(stamps, (0.0, 0.0, 14.0)):
        factor, error, _ = scale.at(stamp, np.array([x]), np.array([1.0]))
    wear, sd = scale.wear(np.array([14.0]), np.array([1.0]), factor, error)
    assert abs(wear[0] - 24.0) < 2 * sd[0] and sd[0] < 2.5 and wear[0] - Z90_ONE_SIDED * sd[0] > 10.0
    factor, error, _ = scale.at("2026-01-06", np.array([17.0]), np.array([1.0]))
    wear, sd = scale.wear(np.array([17.0]), np.array([1.0]), factor, error)
    assert wear[0] == pytest.approx(factor[0] * 17.0) and factor[0] > 1.2


def test_a_tests_read_is_taken_less_its_offset_and_its_bound_floors_the_later_logs():
    """Issue 90 (the first alarm before 15 %): a test read into its log at once is taken less the
    offset ``b`` the tests before the wear tell (4 tests at no wear reading 3 points high, then 12 %
    read as 15.4: its log reads 12.5, 12.9 with the offset additive, 14.6 before the offset was taken); and its log's lower 90 % bound stays a floor of the
    later logs' until the next test (a wear does not fall): two logs after a test at 16 % the bound
    stays 13.7 where the factor alone gives 12.6-13.0, so the alarm persists from the test's log."""
    true = np.array([0.0, 0.0, 0.0, 0.0, 12.0])
    stamps, wears = _test_wears(true, 3.0)
    scale = Rescale("u", 1, wears)
    for stamp, x in zip(stamps, true):
        factor, error, _ = scale.at(stamp, np.array([x]), np.array([0.7]))
    wear, sd = scale.wear(np.array([12.0]), np.array([0.7]), factor, error)
    assert abs(wear[0] - 12.0) < 1.0 and abs(wear[0] - 12.0) < Z90 * sd[0]
    stamps, wears = _test_wears(np.array([0.0, 0.0, 16.0]), 0.0)
    scale = Rescale("u", 1, wears)
    for stamp, x in zip(stamps, (0.0, 0.0, 16.0)):
        factor, error, _ = scale.at(stamp, np.array([x]), np.array([0.7]))
    wear, sd = scale.wear(np.array([16.0]), np.array([0.7]), factor, error)
    floor = scale.floored(wear - Z90_ONE_SIDED * sd)[0]
    assert floor == pytest.approx(wear[0] - Z90_ONE_SIDED * sd[0]) and floor > 13.0
    for stamp, x in (("2026-01-06", 15.0), ("2026-01-07", 15.5), ("2026-01-08", 19.0)):
        factor, error, _ = scale.at(stamp, np.array([x]), np.array([0.7]))
        wear, sd = scale.wear(np.array([x]), np.array([0.7]), factor, error)
        own = wear[0] - Z90_ONE_SIDED * sd[0]
        assert wear[0] == pytest.approx(factor[0] * x)  # the test is in the factor alone
        assert scale.floored(np.array([own]))[0] == pytest.approx(max(own, floor))
    assert own > floor  # the logs' own bound takes over as the wear grows
    scale.reset(1)  # a repair: no floor
    assert scale.floored(np.array([1.0]))[0] == 1.0
