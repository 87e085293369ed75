"""The least median wear error of a scale learned from friction tests (benchmarks/monitor_scale_bound.py;
docs/analysis.md, "The wear on the friction tests' scale"): the closed form against a Monte Carlo of the
monitor's own kind of fit
(statsmodels WLS with the prior as a pseudo-observation, as faultgen.monitor.friction_tests.Rescale
fits it), and bad input refused by name."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
import statsmodels.api as sm

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import monitor_scale_bound as bound  # noqa: E402


def test_no_test_leaves_the_prior():
    assert bound.factor_error([], [], 0.5) == pytest.approx(0.5)


def test_one_test_adds_its_information():
    # 1 / r^2 = 1 / 0.5^2 + (20 / 4)^2 = 4 + 25
    assert bound.factor_error([20.0], [4.0], 0.5) == pytest.approx(29 ** -0.5)


def test_closed_form_against_a_monte_carlo_of_the_monitors_fit():
    """Tests at true wear w_j with errors s_j read y_j = w_j + e_j; x_j = w_j / f the twin's exact wear.
    Fitting y = g x by WLS with the prior g ~ N(f, (p f)^2) as a pseudo-observation (mixed estimation,
    as the monitor does), the log at true wear W gets g x = W g / f: its median absolute error over
    draws must match 0.6745 W r of the closed form."""
    rng = np.random.default_rng(7)
    f, p, wears, errors, log_wear = 0.8, 0.5, np.array([0.0, 5.0, 15.0, 25.0]), np.array([3.3, 3.4, 3.6, 3.8]), 30.0
    x = wears / f
    design = np.r_[x, 1.0][:, None]
    weights = np.r_[1 / errors**2, 1 / (p * f) ** 2]
    draws = []
    for _ in range(4000):
        y = wears + rng.normal(0.0, errors)
        g = sm.WLS(np.r_[y, f], design, weights=weights).fit().params[0]
        draws.append(log_wear * g / f - log_wear)
    expected = bound.median_error_bound([(log_wear, list(zip(wears, errors)))], p)
    assert np.median(np.abs(draws)) == pytest.approx(expected, rel=0.05)


def test_the_filter_error_adds_in_quadrature():
    logs = [(20.0, [(10.0, 3.3)]), (30.0, [(10.0, 3.3), (25.0, 3.7)]), (12.0, [])]
    r = [bound.factor_error([w for w, _ in t], [s for _, s in t], 0.3) for _, t in logs]
    each = [bound.MEDIAN_ABS * np.hypot(w * ri, 1.6) for (w, _), ri in zip(logs, r)]
    assert bound.median_error_bound(logs, 0.3, 1.6) == pytest.approx(np.median(each))
    assert bound.median_error_bound(logs, 0.3, 1.6) > bound.median_error_bound(logs, 0.3, 0.0)


@pytest.mark.parametrize("args", [([10.0], [3.0], 0.0), ([10.0], [0.0], 0.5), ([10.0, 20.0], [3.0], 0.5),
                                  ([float("nan")], [3.0], 0.5)])
def test_bad_input_is_refused_by_name(args):
    with pytest.raises(ValueError, match="prior_sd"):
        bound.factor_error(*args)


def test_bad_logs_are_refused():
    with pytest.raises(ValueError, match="filter_sd"):
        bound.median_error_bound([], 0.5)
    with pytest.raises(ValueError, match="filter_sd -1"):
        bound.median_error_bound([(10.0, [])], 0.5, -1.0)
