"""A remaining life that knows it does not know its scale (issue 75, production logs only): without
a friction test each draw's scale of the wear estimate is log-normal, median 1, log standard
deviation faultgen.monitor.prognosis.TWIN_SCALE_LOG_SD, the spread measured across the independent
fleets' friction laws. The prior's size against the measured scales computed by hand; the draws'
quantiles and a known line's crossing against scipy's log-normal; an estimate reading 1.5 times a
known truth: the interval covers the truth's crossing (the normal 10 % of the monitor before does
not); a test's factor still drawn normal; the same seed, the same bytes. The check against
independent fleets: docs/analysis.md, "A remaining life that knows it does not know its scale"."""

import datetime
import math
from statistics import NormalDist

import numpy as np
from scipy import stats

from faultgen.bench import rul_scores
from faultgen.monitor import prognosis, scoring, tables, trends

ALPHA = 0.01
Z = NormalDist().inv_cdf(1 - ALPHA)
F = prognosis.FAILURE_WEAR
SAMPLES = 200

#: The twin's scale (estimate per % of true wear) of each worn unit of the nine fleets without tests,
#: as benchmarks/monitor_wear_scale.py printed it (2026-11-26/27; docs/analysis.md): per friction law.
MEASURED_SCALES = {
    "first": [1.24, 1.12, 1.07, 1.30, 1.03, 0.98, 1.14, 0.94, 1.04, 1.20, 0.91, 1.03, 0.96, 1.12, 1.14, 0.94,
              1.11, 1.07, 1.15, 1.06, 0.96, 1.10, 0.93, 1.16, 1.11, 1.06, 1.05, 1.06, 1.13, 1.16, 0.94, 0.92,
              1.04, 1.03, 0.99, 0.97, 1.02, 1.01, 1.16, 0.97],
    "lorentzian hump": [1.22, 1.10, 1.06, 1.28, 1.02, 0.97, 1.12, 0.94, 1.03, 1.18, 0.90, 1.03, 0.95, 1.10, 1.13,
                        0.94, 1.06, 1.06, 0.93, 0.94, 1.42, 0.93, 0.98, 1.09],
    "exponential hump": [1.24, 1.66, 1.39, 1.32, 1.61, 1.62, 1.98, 1.52],
}


def test_the_prior_is_the_spread_of_the_twins_scale_on_the_widest_law():
    """RMS of ln(scale) about 1 per law, by hand: the exponential hump's (0.446) is the widest and
    gives TWIN_SCALE_LOG_SD to two digits; the others' are near the 10 % of the normal before."""
    rms = {law: math.sqrt(sum(math.log(s) ** 2 for s in scales) / len(scales))
           for law, scales in MEASURED_SCALES.items()}
    assert [len(s) for s in MEASURED_SCALES.values()] == [40, 24, 8]
    assert max(rms, key=rms.get) == "exponential hump"
    assert round(rms["exponential hump"], 2) == prognosis.TWIN_SCALE_LOG_SD == 0.45
    assert 0.09 < rms["first"] < 0.11 and 0.11 < rms["lorentzian hump"] < 0.13, rms
    assert scoring.SCALE_UNCERTAINTY == 0.10  # the wear's own interval (scoring) keeps its 10 %


def test_the_draws_are_log_normal_without_a_test_and_normal_with_one():
    z = np.random.default_rng(3).standard_normal(20000)
    drawn = prognosis.scale_draws(np.random.default_rng(3), 20000, None)
    np.testing.assert_allclose(drawn, np.exp(0.45 * z))
    reference = stats.lognorm(s=prognosis.TWIN_SCALE_LOG_SD)  # median 1 (scale = exp(0))
    for q in (0.05, 0.5, 0.95):
        assert abs(np.quantile(drawn, q) - reference.ppf(q)) < 0.02 * reference.ppf(q), q
    # a friction test's factor error: the normal of the monitor before, floor 0.05; 0 none
    np.testing.assert_allclose(prognosis.scale_draws(np.random.default_rng(3), 20000, 0.2),
                               np.maximum(1.0 + 0.2 * z, 0.05))
    np.testing.assert_array_equal(prognosis.scale_draws(np.random.default_rng(3), 5, 0.0), np.ones(5))


def test_a_known_lines_crossing_spreads_as_the_log_normal_and_keeps_its_median():
    """A line known exactly (w0, b): the crossing of F k, k log-normal, is (F k - w0) / b: its
    quantiles are scipy's log-normal's mapped through it; its median is the scale-1 crossing's."""
    w0, b = 10.0, 0.5
    fit = trends.Fit("linear", np.array([w0, b]), np.zeros((2, 2)), 0.0)
    toe = prognosis.time_of_event(fit, F, samples=4000, seed=1, scale_uncertainty=None)
    times = np.array(list(toe.key("failure")), dtype=float)
    times = np.where(np.isnan(times), 0.0, times)
    reference = stats.lognorm(s=prognosis.TWIN_SCALE_LOG_SD)
    for q in (0.5, 0.95):
        expected = (F * reference.ppf(q) - w0) / b
        assert abs(np.quantile(times, q) - expected) < 0.03 * expected, (q, np.quantile(times, q), expected)
    assert abs(np.median(times) - (F - w0) / b) < 0.03 * (F - w0) / b


def _rows(wear, noise: float) -> list[dict]:
    day = datetime.date.fromisoformat("2026-01-05")
    return [{"stamp": (day + datetime.timedelta(days=i)).isoformat(), "phase": "monitoring",
             "wear1": float(w), "wear1_log": float(w), "wear1_log_lower": float(w - Z * noise)} for i, w in enumerate(wear)]


def _reading_high(seed: int, scale_uncertainty):
    """A true wear 0.4 % a day from day 30, read 1.5 times (1 % noise): at day 94 the estimate is
    some 38 % (the truth 25.6 %, lambda-like), the truth's 40 % 36 days ahead; the source axis's row."""
    days, rate, onset = 95, 0.4, 30.0
    t = np.arange(float(days))
    truth = rate * np.maximum(t - onset, 0.0)
    estimate = 1.5 * truth + np.random.default_rng(seed).normal(0.0, 1.0, days)
    rows = _rows(estimate, 1.0)
    (row,) = prognosis.remaining_life("u", tables.log_rows(rows), 1, alpha=ALPHA, samples=SAMPLES, seed=seed, source_axis=1,
                                      since=rows[int(np.argmax(estimate >= 12.0))]["stamp"],
                                      scale_uncertainty=scale_uncertainty)
    return row, onset + F / rate - (days - 1)


def test_an_estimate_reading_high_gets_an_interval_that_covers_the_truths_crossing():
    """On 4 seeds: the default (no test) covers the truth's crossing each time, its median early
    (the estimate reaches 40 % first); the normal 10 % of the monitor before covers it on none."""
    for seed in range(4):
        row, truth = _reading_high(seed, None)
        assert row.rul is not None and rul_scores.covers(row.rul_5, row.rul_95, truth), (seed, row.verdict)
        assert row.rul < truth and not rul_scores.late(row.rul, truth)
        before, _ = _reading_high(seed, scoring.SCALE_UNCERTAINTY)
        assert before.rul is not None and not rul_scores.covers(before.rul_5, before.rul_95, truth), before.verdict


def test_the_same_seed_gives_the_same_bytes(tmp_path):
    """rul.csv of the high-reading rise under the default and under a test's 10 %: seed 2 twice the
    same bytes, seed 3 others."""
    def written(seed: int) -> bytes:
        return prognosis.rul_table([_reading_high(seed, None)[0], _reading_high(seed, 0.1)[0]]).write(tmp_path).read_bytes()

    first = written(2)
    assert written(2) == first != written(3)
