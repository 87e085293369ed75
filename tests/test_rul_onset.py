"""Service-by dates that are not late (issue 90): the remaining life's exponential rise after a flat
stretch and its credible end (faultgen.monitor.rul_forecast). Before them, on a wear flat for 48
days and then exponential (the clean fleet's unit04, docs/analysis.md "Issue 90: service-by dates
that are not late"), the power law took every weight and the service-by end fell 0.7-0.9 days after
the true crossing (median 12.6 days for a true 9.9)."""

import datetime
from statistics import NormalDist

import numpy as np

from faultgen.monitor import prognosis, rul_forecast, tables

ALPHA = 0.01
Z = NormalDist().inv_cdf(1 - ALPHA)
A, K, ONSET, LAST, NOISE, SCALE = 1.2, 0.0553, 48, 102, 0.1, 0.05
F = prognosis.FAILURE_WEAR


def _rows(wear) -> list[dict]:
    day = datetime.date.fromisoformat("2026-01-05")
    return [{"stamp": (day + datetime.timedelta(days=i)).isoformat(), "phase": "monitoring", "wear1": float(w),
             "wear1_log": float(w), "wear1_log_lower": float(w - Z * NOISE)} for i, w in enumerate(wear)]


def test_an_exponential_rise_after_a_flat_stretch_is_dated_early_not_late():
    """``A (exp(K (t - 48))_+ - 1)`` with noise 0.1 %: the onset fit recovers the rate and the start,
    the service-by end (``rul_5``) is not after the true crossing and equals, within 5 %, the 5 %
    quantile of an independent Monte Carlo of the onset fit's paths (numpy draws of its parameters and
    of the scale, each crossing solved in closed form), and the median is within 20 %."""
    rng = np.random.default_rng(0)
    t = np.arange(LAST + 1.0)
    wear = A * np.expm1(K * np.maximum(t - ONSET, 0.0)) + rng.normal(0, NOISE, t.size)
    truth = ONSET + np.log1p(F / A) / K - LAST
    rows = _rows(wear)
    alarm = int(np.argmax(wear >= 12.0))
    (row,) = prognosis.remaining_life("u", tables.log_rows(rows), 1, alpha=ALPHA, since=rows[alarm]["stamp"],
                                      source_axis=1, scale_uncertainty=SCALE)
    assert row.rul is not None, row.verdict
    assert row.rul_5 <= truth, (row.rul_5, truth, row.verdict)
    assert abs(row.rul - truth) <= 0.2 * truth, (row.rul, truth)
    fit = rul_forecast.fit_onset_exponential(t - LAST, wear, np.full(t.size, NOISE), np.array([30.0, 60.0]))
    assert fit.model == rul_forecast.ONSET and abs(fit.params[2] - K) < 0.003, fit
    assert abs(fit.changepoint - (ONSET - LAST)) < 2.0, fit
    draws = np.random.default_rng(1).multivariate_normal(fit.params, fit.cov, size=20000)
    scale = np.maximum(1.0 + SCALE * np.random.default_rng(2).standard_normal(20000), 0.05)
    w, b, k = draws.T
    crossing = np.log1p(np.maximum(k, 0.0) * (F * scale - w) / b) / np.maximum(k, 1e-12)
    assert abs(row.rul_5 - np.quantile(crossing, 0.05)) <= 0.05 * truth, (row.rul_5, np.quantile(crossing, 0.05))


def test_the_credible_end_is_the_earliest_5_percent_end_of_a_model_of_weight_1_percent_or_more():
    """Hand-made draws: a model of weight 0.02 whose own draws (made by ``own``, the average gave it
    too few) end earlier sets the end; one of weight 0.005 does not; none credible: infinity."""
    fits = [prognosis.Fit(m, np.zeros(2), np.eye(2)) for m in ("power", "exponential", "linear")]
    values = np.r_[np.linspace(10.0, 20.0, 980), np.full(15, 4.0), np.full(5, 1.0)]
    labels = np.r_[np.zeros(980, int), np.ones(15, int), np.full(5, 2)]
    asked = []

    def own(i):
        asked.append(i)
        return np.linspace(5.0, 9.0, rul_forecast.CREDIBLE_SAMPLES)

    low, model, weight = rul_forecast.credible_low(values, labels, fits, [0.975, 0.02, 0.005], own)
    assert asked == [1] and model == "exponential" and weight == 0.02
    assert low == np.quantile(np.linspace(5.0, 9.0, 200), 0.05, method="inverted_cdf")
    low, model, _ = rul_forecast.credible_low(values, labels, fits, [0.995, 0.0, 0.005], own)
    assert model == "power" and low == np.quantile(values[:980], 0.05, method="inverted_cdf")
    assert rul_forecast.credible_low(values, labels, fits, [0.0, 0.0, 0.0], own) == (np.inf, "", 0.0)
