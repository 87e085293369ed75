"""A remaining life that does not run late (issue 75, item 4): the model average of
faultgen.monitor.prognosis (the line, the exponential, the changepoint trend and the power-law rise,
weighted by AICc) on synthetic accelerating wear whose crossing of the failure wear is known; the
"not yet predictable" verdict; the per-axis scale uncertainty; the PHM 2008 score
(faultgen.bench.rul_scores) against values computed by hand; the same seed, the same bytes.
The check against independent fleets is benchmarks/monitor_rul.py (docs/_r6_rul.md)."""

import datetime
import math
from statistics import NormalDist

import numpy as np
import pytest

from faultgen.bench import rul_scores
from faultgen.monitor import prognosis, tables, trends

ALPHA = 0.01
Z = NormalDist().inv_cdf(1 - ALPHA)
NOISE = 1.0  # % : each log's estimate's standard error
DRAWS = 20
SAMPLES = 200
F = prognosis.FAILURE_WEAR


def _rows(wear, n_axes: int = 1) -> list[dict]:
    day = datetime.date.fromisoformat("2026-01-05")
    rows = []
    for i, w in enumerate(wear):
        row = {"stamp": (day + datetime.timedelta(days=i)).isoformat(), "phase": "monitoring"}
        for a in range(1, n_axes + 1):
            row.update({f"wear{a}": float(w), f"wear{a}_log": float(w), f"wear{a}_log_lower": float(w - Z * NOISE)})
        rows.append(row)
    return rows


def _alarmed(rows, alarm: int, **options) -> prognosis.Remaining:
    """The open alarm's source axis (axis 1) at the last log: the model average over the whole block."""
    (row,) = prognosis.remaining_life("u", tables.log_rows(rows), 1, alpha=ALPHA, samples=SAMPLES, since=rows[alarm]["stamp"],
                                      source_axis=1, **options)
    return row


def _judge(series, crossing, alarm_at: float = 12.0):
    """Per seeded draw of ``series(rng)`` (wear at each day, the true crossing of F in days after the
    last log): whether the row gives a number, covers the true crossing, and is late by more than 20 %."""
    numbers = covered = late = 0
    for seed in range(DRAWS):
        rng = np.random.default_rng(seed)
        wear, truth = series(rng)
        noisy = wear + rng.normal(0, NOISE, len(wear))
        alarm = int(np.argmax(wear >= alarm_at))
        row = _alarmed(_rows(noisy), alarm)
        assert row.logs_fitted == len(wear), row
        if row.rul is None:
            assert row.verdict.startswith("not yet predictable"), row.verdict
            continue
        numbers += 1
        covered += rul_scores.covers(row.rul_5, row.rul_95, truth)
        late += rul_scores.late(row.rul, truth)
    return numbers, covered, late


def test_the_model_average_follows_a_power_law_rise_without_running_late():
    """Flat for 30 days, then ``c (t - 30)^p`` with p in 1.6-2.4 for 35 days (18-26 % at the last log,
    40 % 10-24 days later): the 5-95 % interval covers the true crossing on at least 80 % of the
    draws with a number, and the median is late by more than 20 % on at most 10 % of them."""
    def series(rng):
        p = rng.uniform(1.6, 2.4)
        c = 22.0 / 35.0**p
        t = np.arange(65.0)
        wear = c * np.maximum(t - 30.0, 0.0) ** p
        return wear, 30.0 + (F / c) ** (1 / p) - 64.0

    numbers, covered, late = _judge(series, None)
    assert numbers >= 0.8 * DRAWS, numbers
    assert covered >= 0.8 * numbers, (covered, numbers)
    assert late <= 0.1 * numbers, (late, numbers)


def test_the_model_average_follows_an_exponential_wear_without_running_late():
    """``2 (exp(k t) - 1)``, k in 0.045-0.055 a day, 60 days (26-52 %... cut where it is below F):
    the interval covers the true crossing on at least 80 % of the draws with a number, the median
    late by more than 20 % on at most 10 %."""
    def series(rng):
        k = rng.uniform(0.040, 0.046)
        t = np.arange(60.0)
        return 2.0 * np.expm1(k * t), np.log1p(F / 2.0) / k - 59.0

    numbers, covered, late = _judge(series, None)
    assert numbers >= 0.8 * DRAWS, numbers
    assert covered >= 0.8 * numbers, (covered, numbers)
    assert late <= 0.1 * numbers, (late, numbers)


def test_the_power_law_fit_recovers_its_parameters():
    rng = np.random.default_rng(3)
    t = np.arange(70.0) - 69.0
    wear = 0.02 * np.maximum(t + 35.0, 0.0) ** 2 + rng.normal(0, 0.5, 70)
    fit = trends.fit_power(t, wear, np.full(70, 0.5))
    w_now, b, age, p = fit.params
    errors = np.sqrt(np.diag(fit.cov))
    for value, truth, error in ((w_now, 0.02 * 35**2, errors[0]), (b, 0.04 * 35, errors[1]), (age, 35.0, errors[2]),
                                (p, 2.0, errors[3])):
        assert abs(value - truth) < 3.5 * error, (value, truth, error)
    assert fit.changepoint == -age and 1.0 <= p <= trends.POWER_MAX
    np.testing.assert_allclose(trends.power_curve(t, w_now, b, age, 1.0),
                               w_now + b * (np.maximum(t, -age) - 0.0), atol=1e-9)


def test_a_power_law_rise_begun_before_the_first_log_fitted_is_followed(monkeypatch):
    """A quadratic rise from 60 days before the last log, fitted on the last 50 (the unit learning before
    them): the start and the power recovered, the day the wear reaches 40 % (21.65 days on) not late
    (21.1 days on this draw); held to a start among the logs (trends.BEFORE_FIRST empty) the fit takes
    a later start and a flatter power (1.58) and reaches 40 % 2.8 days late."""
    rng = np.random.default_rng(5)
    t = np.arange(50.0) - 49.0
    wear = 0.006 * (t + 60.0) ** 2 + rng.normal(0, 0.3, 50)
    crossing = np.sqrt(40.0 / 0.006) - 60.0
    ahead = np.linspace(0.0, 40.0, 4001)

    def reaches(fit) -> float:
        return float(ahead[np.argmax(trends.power_curve(ahead, *fit.params) >= 40.0)])

    fit = trends.fit_power(t, wear, np.full(50, 0.3))
    _, _, age, p = fit.params
    errors = np.sqrt(np.diag(fit.cov))
    assert abs(age - 60.0) < 3.5 * errors[2] and abs(p - 2.0) < 3.5 * errors[3], (age, p, errors)
    assert crossing - 2.0 <= reaches(fit) <= crossing + 0.5, reaches(fit)  # early rather than late
    monkeypatch.setattr(trends, "BEFORE_FIRST", np.array([]))
    late = trends.fit_power(t, wear, np.full(50, 0.3))
    assert late.params[2] <= 47.0 and reaches(late) > crossing + 1.0, (late.params, reaches(late))


def test_the_fits_covariance_is_the_weighted_least_squares_one_where_the_logs_fix_every_parameter():
    """trends.gauss_newton_cov on a line's design (residuals over their errors) against statsmodels' WLS
    (its unscaled covariance, (X^T W X)^-1), and on a well-conditioned Jacobian against the plain inverse
    of J^T J it replaces."""
    import statsmodels.api as sm

    rng = np.random.default_rng(11)
    t = np.arange(40.0) - 39.0
    error = rng.uniform(0.5, 2.0, 40)
    x = np.column_stack([np.ones(40), t])
    reference = sm.WLS(rng.normal(size=40), x, weights=1.0 / error**2).fit().normalized_cov_params
    np.testing.assert_allclose(trends.gauss_newton_cov(x / error[:, None]), reference, rtol=1e-10)
    jacobian = rng.normal(size=(60, 4)) * np.array([1.0, 30.0, 0.1, 5.0])
    np.testing.assert_allclose(trends.gauss_newton_cov(jacobian), np.linalg.inv(jacobian.T @ jacobian), rtol=1e-9)


def test_a_power_law_whose_start_the_logs_do_not_fix_is_drawn_at_its_fitted_start():
    """An exact line over 60 logs: the power law fits it with its exponent at 1 and its start before the
    first log, where the start moves nothing. The plain inverse of J^T J put a standard deviation of
    about 10^8 days on the start and a negative eigenvalue (-0.24) beside it, so NumPy's draws warned
    "covariance is not symmetric positive-semidefinite" (it did in `faultgen monitor`'s console on the
    independent fleets); the pseudo-inverse gives the start no variance, the others theirs."""
    import warnings

    t = np.arange(60.0) - 59.0
    fit = trends.fit_power(t, 10.0 + 0.5 * (t + 59.0), np.ones(60))
    w_now, b, age, p = fit.params
    assert p == pytest.approx(1.0, abs=1e-9) and age > 59.0, fit.params  # the case: a line, begun before the logs
    eigenvalues = np.linalg.eigvalsh(fit.cov)
    assert np.allclose(fit.cov, fit.cov.T, rtol=1e-12, atol=0.0) and eigenvalues[0] >= -1e-12 * eigenvalues[-1], eigenvalues
    errors = np.sqrt(np.diag(fit.cov))
    assert errors[2] < 1e-6 and 0.1 < errors[0] < 1.0 and 0.005 < errors[1] < 0.05 and 0.01 < errors[3] < 0.2, errors
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        drawn = np.random.default_rng(0).multivariate_normal(fit.params, fit.cov, size=1000, method="eigh")
    assert np.ptp(drawn[:, 2]) < 1e-4 and np.std(drawn[:, 3]) == pytest.approx(errors[3], rel=0.1)


def test_a_rise_too_short_or_too_slow_is_not_yet_predictable_and_a_flat_one_has_no_end_of_life():
    t = np.arange(45.0)
    rng = np.random.default_rng(1)
    # a rise of 3 logs after 42 flat ones: fewer than MIN_RISE_LOGS since the rise
    short = np.r_[np.zeros(42), [6.0, 12.0, 18.0]] + rng.normal(0, NOISE, 45)
    row = _alarmed(_rows(short), 43)
    assert row.rul is None and row.rul_5 is None and row.rul_95 is None, row
    assert row.verdict.startswith("not yet predictable"), row.verdict
    assert not row.predictable and row.distribution is not None
    # a slow rise whose 95 % end lies beyond the horizon
    slow = 0.03 * t + rng.normal(0, NOISE, 45)
    (row,) = prognosis.remaining_life("u", tables.log_rows(_rows(slow)), 1, alpha=0.2, samples=SAMPLES)
    assert row.rul is None and ("not yet predictable" in row.verdict or "no end of life" in row.verdict), row.verdict
    # flat: the trend can tell, there is no end of life within the horizon
    (row,) = prognosis.remaining_life("u", tables.log_rows(_rows(rng.normal(0, NOISE, 45))), 1, alpha=ALPHA, samples=SAMPLES)
    assert row.rul is None and "no end of life within the horizon" in row.verdict, row.verdict


def test_a_life_whose_upper_end_alone_is_unbounded_gives_its_service_by_end():
    """Condition (b) alone (module docstring of prognosis, 7): a slow line, 0.12 % a day, 5.3 % at its
    last log (40 % about 289 days later): the median and the 95 % end are withheld, the 5 % end, the
    service-by end, is the draws' own 5 % quantile and comes before the line's crossing."""
    rng = np.random.default_rng(1)
    t = np.arange(45.0)
    (row,) = prognosis.remaining_life("u", tables.log_rows(_rows(0.12 * t + rng.normal(0, NOISE, 45))), 1,
                                      alpha=ALPHA, samples=SAMPLES)
    assert row.rul is None and row.rul_95 is None and not row.predictable, row
    assert row.verdict.startswith("not yet predictable: the 95 % end") and "service by its 5 % end" in row.verdict
    times = np.array([np.inf if v is None else float(v) for v in row.distribution.key("failure")])
    assert np.mean(np.isinf(times)) > 0.05  # more than 5 % of the draws beyond the horizon
    assert row.rul_5 == pytest.approx(np.quantile(times, 0.05, method="inverted_cdf"))
    assert 0 < row.rul_5 < (40.0 - 0.12 * 44) / 0.12


def test_the_rule_of_not_yet_predictable_on_hand_made_draws():
    """:func:`prognosis.unpredictable`: two models whose intervals do not overlap, a light model
    apart, an agreeing pair, a wide interval (predictable), one beyond the horizon, a short rise."""
    fits = [trends.Fit("linear", np.zeros(2), np.eye(2)), trends.Fit("power", np.zeros(4), np.eye(4))]
    labels = np.repeat([0, 1], 100)
    apart = np.r_[np.linspace(10, 12, 100), np.linspace(20, 22, 100)]
    assert "do not overlap" in prognosis.unpredictable(fits, [0.5, 0.5], labels, apart, 10.1, 15.0, 21.9, 20)
    assert prognosis.unpredictable(fits, [0.95, 0.05], labels, apart, 10.1, 15.0, 21.9, 20) == ""
    together = np.r_[np.linspace(10, 20, 100), np.linspace(12, 22, 100)]
    assert prognosis.unpredictable(fits, [0.5, 0.5], labels, together, 10.5, 15.0, 21.5, 20) == ""
    # a wide interval alone is an answer (its width says what the estimate's scale does not know)
    assert prognosis.unpredictable(fits, [0.5, 0.5], labels, together, 1.0, 5.0, 100.0, 20) == ""
    assert "beyond the horizon" in prognosis.unpredictable(fits, [0.5, 0.5], labels, together, 1.0, 5.0, np.inf, 20)
    assert "logs since the rise" in prognosis.unpredictable(fits, [0.5, 0.5], labels, together, 10.5, 15, 21.5, 3)


def test_the_scale_uncertainty_per_axis():
    rng = np.random.default_rng(4)
    rows = _rows(0.5 * np.arange(50.0) + rng.normal(0, NOISE, 50), n_axes=2)

    def rows_of(u):
        return prognosis.remaining_life("u", tables.log_rows(rows), 2, alpha=ALPHA, samples=SAMPLES, scale_uncertainty=u)

    one, two = rows_of({1: 0.0, 2: 0.3})
    assert one.rul_95 - one.rul_5 < 0.5 * (two.rul_95 - two.rul_5), (one, two)
    (zero, _) = rows_of(0.0)
    assert (one.rul, one.rul_5, one.rul_95) == (zero.rul, zero.rul_5, zero.rul_95)
    assert [(r.rul, r.rul_5, r.rul_95) for r in rows_of([0.0, 0.3])] == [(r.rul, r.rul_5, r.rul_95) for r in (one, two)]
    default = rows_of({1: 0.0})[1]  # an axis not named: the monitor's SCALE_UNCERTAINTY
    same = rows_of(prognosis.SCALE_UNCERTAINTY)[1]
    assert (default.rul, default.rul_5, default.rul_95) == (same.rul, same.rul_5, same.rul_95)
    for bad, match in (({3: 0.1}, "axis 3"), ([0.1], "expected 2 numbers"), (10.5, "10.5"), (float("nan"), "nan"), (-0.1, "-0.1"),
                       ({1: "x"}, "'x'")):
        with pytest.raises(ValueError, match=match):
            rows_of(bad)


def test_the_phm08_score_against_hand_computed_values():
    # d = predicted - true: exp(-d / 13) - 1 early, exp(d / 10) - 1 late (Saxena et al. 2008)
    predicted = np.array([10.0, 23.0, 0.0, 15.0, 20.0, 30.0])
    true = np.array([10.0, 10.0, 13.0, 20.0, 10.0, 40.0])
    expected = [0.0, 2.669297, 1.718282, 0.469049, 1.718282, 1.158106]
    np.testing.assert_allclose(rul_scores.phm08_score(predicted, true), expected, atol=1e-6)
    assert rul_scores.phm08_score(12.0, 10.0) > rul_scores.phm08_score(8.0, 10.0)  # late costs more
    assert math.isclose(float(rul_scores.phm08_score(10.0 + 10.0 * math.log(2.0), 10.0)), 1.0)
    with pytest.raises(ValueError, match="finite"):
        rul_scores.phm08_score(np.inf, 1.0)
    assert rul_scores.late(12.5, 10.0) and not rul_scores.late(12.0, 10.0) and not rul_scores.late(2.0, 10.0)
    assert rul_scores.covers(5.0, None, 400.0) and not rul_scores.covers(5.0, 9.0, 10.0)
    with pytest.raises(ValueError, match="true remaining life"):
        rul_scores.late(1.0, 0.0)


def test_the_same_seed_gives_the_same_bytes(tmp_path):
    rng = np.random.default_rng(9)
    wear = np.r_[np.zeros(25), 0.02 * np.arange(1.0, 36.0) ** 2] + rng.normal(0, NOISE, 60)
    rows = _rows(wear)
    paths = []
    for seed in (0, 0, 1):
        paths.append(prognosis.rul_table([_alarmed(rows, 40, seed=seed)]).write(tmp_path).read_bytes())
    assert paths[0] == paths[1]
    assert paths[0] != paths[2]
    assert b"models" in paths[0].splitlines()[0]


def test_sample_counts_follow_the_weights():
    assert list(prognosis.sample_counts([0.5, 0.3, 0.2], 10)) == [5, 3, 2]
    assert list(prognosis.sample_counts([0.335, 0.333, 0.332], 100)) == [34, 33, 33]
    assert prognosis.sample_counts([0.999, 0.001, 0.0], 1000).sum() == 1000
    np.testing.assert_allclose(trends.akaike_weights(
        [trends.Fit("linear", np.zeros(2), np.eye(2), aicc=a) for a in (10.0, 12.0, np.inf)]),
        [1 / (1 + math.exp(-1)), math.exp(-1) / (1 + math.exp(-1)), 0.0])


def test_the_fleets_wear_growth_is_linear_by_default_and_a_power_of_the_time_since_the_onset():
    from faultgen.bench import independent

    spec = independent.FleetSpec(units=3, worn=2, days=30, seed=4, onset=(5, 10))
    assert independent.truth_rows(spec) == independent.truth_rows(independent.FleetSpec(
        units=3, worn=2, days=30, seed=4, onset=(5, 10), wear_growth=1.0))
    grown = independent.FleetSpec(units=3, worn=2, days=30, seed=4, onset=(5, 10), wear_growth=2.0)
    for linear, square in zip(independent.truth_rows(spec), independent.truth_rows(grown)):
        assert linear[:3] == square[:3]
        assert math.isclose(float(square[3]), float(linear[3]) ** 2 / spec.final_wear, abs_tol=2e-4)
    with pytest.raises(ValueError, match="wear_growth = 0.5"):
        independent.FleetSpec(wear_growth=0.5)
