"""Accelerating wear without running late (issue 75, item 4): the model average's weights
(faultgen.monitor.trends.model_weights: the changepoint trend and the line, which the power-law rise
nests, out of the average where the power law is fitted; the others' Akaike weights at learning
rate 1/2) against values computed by hand, and the remaining life of synthetic rises whose crossing
of the failure wear is known: an exact quadratic rise's crossing within its interval, noisy
quadratic rises late less often than under the Akaike weights of every model (the rule before), a
linear rise not made early by more than a measured factor; the same seed, the same bytes. The check
against independent fleets is benchmarks/monitor_rul.py (docs/analysis.md, "Accelerating wear without running late")."""

import datetime
import math
from statistics import NormalDist

import numpy as np
import pytest

from faultgen.bench import rul_scores
from faultgen.monitor import prognosis, tables, trends

ALPHA = 0.01
Z = NormalDist().inv_cdf(1 - ALPHA)
F = prognosis.FAILURE_WEAR
SAMPLES = 200
DAYS = 65  # logs, one a day; the rise starts on day 30, the alarm where the wear reaches 12 %
QUADRATIC = 0.02  # % per day^2: 23 % at the last log, 40 % 10.7 days later
SLOPE = 0.6  # % per day: 20 % at the last log, 40 % 32.7 days later


def _rows(wear, noise: float) -> list[dict]:
    day = datetime.date.fromisoformat("2026-01-05")
    return [{"stamp": (day + datetime.timedelta(days=i)).isoformat(), "phase": "monitoring",
             "wear1": float(w), "wear1_log": float(w), "wear1_log_lower": float(w - Z * noise)} for i, w in enumerate(wear)]


def _predict(shape: str, noise: float, seed: int) -> tuple[prognosis.Remaining, float]:
    """The source axis's row at the last log of a rise from day 30 (``shape`` "quadratic": 0.02 (t -
    30)^2; "linear": 0.6 (t - 30)) plus normal noise of ``noise`` % (its stated error), and the true
    remaining life (days after the last log)."""
    t = np.arange(float(DAYS))
    if shape == "quadratic":
        wear, truth = QUADRATIC * np.maximum(t - 30.0, 0.0) ** 2, 30.0 + math.sqrt(F / QUADRATIC) - (DAYS - 1)
    else:
        wear, truth = SLOPE * np.maximum(t - 30.0, 0.0), 30.0 + F / SLOPE - (DAYS - 1)
    noisy = wear + np.random.default_rng(seed).normal(0.0, noise, DAYS)
    rows = _rows(noisy, noise)
    # the scale drawn as when these figures were measured (normal, 10 %): the trend's rule is tested
    # here; the no-test prior since (log-normal, prognosis.TWIN_SCALE_LOG_SD) in tests/test_life_unknown_scale.py
    (row,) = prognosis.remaining_life("u", tables.log_rows(rows), 1, alpha=ALPHA, samples=SAMPLES, seed=seed, source_axis=1,
                                      since=rows[int(np.argmax(wear >= 12.0))]["stamp"],
                                      scale_uncertainty=prognosis.SCALE_UNCERTAINTY)
    return row, truth


def _judge(shape: str, noise: float, seeds) -> tuple[int, int, int, list[float]]:
    """Over the ``seeds``: the rows with a number, covering the truth, late by more than 20 %, and
    each number's median over the true remaining life (a row without one is "not yet predictable")."""
    found = [_predict(shape, noise, seed) for seed in seeds]
    assert all(r.verdict.startswith("not yet predictable") for r, _ in found if r.rul is None), found
    found = [(r, truth) for r, truth in found if r.rul is not None]
    return (len(found), sum(rul_scores.covers(r.rul_5, r.rul_95, truth) for r, truth in found),
            sum(rul_scores.late(r.rul, truth) for r, truth in found), [r.rul / truth for r, truth in found])


def _fit(model: str, aicc: float) -> trends.Fit:
    return trends.Fit(model, np.zeros(2), np.eye(2), aicc=aicc)


def test_model_weights_leave_the_power_laws_nested_models_out_and_temper_the_rest():
    fits = [_fit("linear", 10.0), _fit("exponential", 12.0), _fit("changepoint", 9.0), _fit("power", 14.0)]
    # exponential and power only, exp(-0.5 * 0.5 * dAICc) normalised: dAICc 0 and 2
    expected = [0.0, 1 / (1 + math.exp(-0.5)), 0.0, math.exp(-0.5) / (1 + math.exp(-0.5))]
    np.testing.assert_allclose(trends.model_weights(fits), expected)
    assert trends.WEIGHT_RATE == 0.5
    # at rate 1: the Akaike weights of the exponential and the power law (dAICc 2)
    np.testing.assert_allclose(trends.model_weights(fits, rate=1.0), [0.0, 1 / (1 + math.exp(-1)), 0.0,
                                                                      math.exp(-1) / (1 + math.exp(-1))])
    # without a power law (every axis but an alarm's source): the Akaike weights of all, as before
    np.testing.assert_allclose(trends.model_weights(fits[:3]), trends.akaike_weights(fits[:3]))
    np.testing.assert_allclose(trends.model_weights(fits[:2]), [1 / (1 + math.exp(-1)), math.exp(-1) / (1 + math.exp(-1))])
    np.testing.assert_allclose(trends.model_weights([_fit("linear", np.inf), _fit("power", np.inf)]), [0.0, 1.0])


@pytest.mark.parametrize("rate", [0.0, -0.5, 1.5, float("nan")])
def test_a_rate_outside_0_1_is_refused_by_name(rate):
    with pytest.raises(ValueError, match="rate"):
        trends.akaike_weights([_fit("linear", 1.0)], rate)


def test_an_exact_quadratic_rises_crossing_lies_within_its_interval():
    """Stated errors of 0.5 %, noise the same: every draw a number covering the true crossing (10.7
    days after the last log), its median within 15 % of it."""
    numbers, covered, late, ratios = _judge("quadratic", 0.5, range(4))
    assert numbers == covered == 4 and late == 0
    assert all(abs(r - 1.0) < 0.15 for r in ratios), ratios


def test_noisy_quadratic_rises_run_late_less_often_than_under_the_akaike_weights(monkeypatch):
    """Each log's estimate scattering by 3.5 % as on the independent fleets: a number on at least 10
    of 12 draws, covering the truth on every one, late by more than 20 % on at most 2 of 12 (the
    criterion's 20 %); the Akaike weights of all four models (the rule before) on the same draws
    are late on more (measured 2026-11-27: 5 of 8 numbers, 4 not yet predictable; now 2 of 11)."""
    numbers, covered, late, _ = _judge("quadratic", 3.5, range(12))
    assert numbers >= 10 and covered == numbers and late <= 2, (numbers, covered, late)
    monkeypatch.setattr(prognosis, "model_weights", trends.akaike_weights)
    _, _, late_before, _ = _judge("quadratic", 3.5, range(12))
    assert late < late_before, (late, late_before)


def test_a_noisy_linear_rise_is_not_made_much_earlier():
    """What the change costs on a linear rise (3.5 % scatter, 32.7 days left): the interval covers
    the truth on at least 10 of 12 draws, late on at most 1, and the medians are 0.8 of the truth
    at their median (0.97 before), none below 0.3 of it (measured: 0.81, the least 0.37)."""
    numbers, covered, late, ratios = _judge("linear", 3.5, range(12))
    assert numbers == 12 and covered >= 10 and late <= 1, (numbers, covered, late)
    assert np.median(ratios) >= 0.7 and min(ratios) >= 0.3, ratios


def test_the_same_seed_gives_the_same_bytes(tmp_path):
    written = []
    for seed in (4, 4, 5):
        row, _ = _predict("quadratic", 3.5, 4)
        (again,) = prognosis.remaining_life("u", tables.log_rows(_rows([0.0] * 30 + [0.02 * i**2 for i in range(35)], 3.5)), 1,
                                            alpha=ALPHA, samples=SAMPLES, seed=seed, source_axis=1,
                                            since="2026-02-28")
        written.append(prognosis.rul_table([row, again]).write(tmp_path).read_bytes())
    assert written[0] == written[1]
    assert written[0] != written[2]


def test_an_exponential_faster_than_the_logs_spacing_is_not_fitted():
    """A flat series with a step at its last log (as after a gearbox change): an exponential with a time
    constant of 1/18 day under daily logs is a step, not a trend (its b and k trade off: variance 1e15),
    and took the whole model average from the line by its AICc before; it is left out, the line stays
    (a slower exponential, the rise of a quadratic, is still fitted)."""
    rng = np.random.default_rng(0)
    t = np.arange(-19.0, 1.0)
    wear = 2.0 + 0.3 * rng.standard_normal(t.size)
    wear[-1] = -4.0
    fits = trends.fit_models(t, wear, np.full(t.size, 0.5))
    assert [f.model for f in fits] == ["linear"]
    assert trends.model_weights(fits) == pytest.approx([1.0])
    rise = 0.02 * np.clip(t + 19.0 - 5.0, 0.0, None) ** 2
    slow = trends.fit_models(t, rise + 0.05 * rng.standard_normal(t.size), np.full(t.size, 0.05))
    exponential = next(f for f in slow if f.model == "exponential")
    assert 0.0 < exponential.params[2] < 1.0 and np.all(np.linalg.eigvalsh(exponential.cov) < 1e6)
