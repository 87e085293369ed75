"""What a monitor of faultgen's form could reach at best on a real-cell fleet
(benchmarks/real_cell_ceiling.py, issue 90): the factor's posterior against statsmodels' WLS with the
prior as a pseudo-observation and against monitor_scale_bound's closed form, the first alarm at the
prior's threshold, the bound below or above the truth and the interval's coverage (known values), an exact scale giving the
remaining life exactly, the same seed the same chances, the tests' measured scatter and actual errors,
and bad input refused by name."""

from __future__ import annotations

import csv
import sys
from pathlib import Path

import numpy as np
import pytest
import statsmodels.api as sm

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import monitor_scale_bound
import real_cell_ceiling as ceiling

from faultgen.monitor.alarm import alarm_quantile

RAMP = np.r_[np.zeros(20), np.arange(1.0, 81.0)]  # 20 healthy days, then 1 point a day to 80 %


def test_the_factor_is_the_weighted_least_squares_with_the_prior_as_an_observation():
    x = RAMP / 1.25
    tests = [(19, 0.0, 3.0), (33, 14.0, 3.3), (47, 28.0, 3.6)]  # (log, RAMP[log], error)
    errors = np.array([[1.1, -2.0, 0.7]])
    factor, sd = ceiling.factor_draws(x, tests, errors, 0.3)
    design = np.r_[[x[i] for i, _, _ in tests], 1.0][:, None]
    target = np.r_[[w + e for (_, w, _), e in zip(tests, errors[0])], 1.0]
    weights = np.r_[[s**-2 for _, _, s in tests], 0.3**-2]
    fit = sm.WLS(target, design, weights=weights).fit(cov_type="fixed scale")
    assert factor[0, 60] == pytest.approx(fit.params[0], rel=1e-12)
    assert sd[0, 60] == pytest.approx(fit.bse[0], rel=1e-12)
    assert (factor[0, 25], sd[0, 25]) == (1.0, 0.3)  # a test at no wear tells nothing: the prior
    # with a twin reading the truth, the factor's error is the closed form of monitor_scale_bound
    _, sd = ceiling.factor_draws(RAMP, tests, errors, 0.3)
    closed_form = monitor_scale_bound.factor_error([0.0, 14.0, 28.0], [3.0, 3.3, 3.6], 0.3)
    assert sd[0, 60] == pytest.approx(closed_form)


def test_without_a_test_that_sees_the_wear_the_alarm_waits_for_the_priors_threshold():
    # x (1 - z p) >= 8: x >= 8 / (1 - 1.2816 * 0.3) = 13.0 %; a twin reading 1 / 1.3 of the truth: 16.9 %
    threshold = 8.0 / (1.0 - alarm_quantile() * 0.3)
    assert threshold == pytest.approx(13.0, abs=0.01)
    tests = [(5, 0.0, 3.0), (19, 0.0, 3.0)]
    for c, expected in ((1.0, 13.0), (1.3, 17.0)):  # the first whole point past threshold * c on the ramp
        errors = np.random.default_rng(1).normal(0.0, 3.0, (50, 2))
        draws = ceiling.unit_chances(RAMP, tests, c, errors, 8.0, 0.3)
        assert np.all(draws["alarm"] == expected)
        assert draws["in_window"].all() == (expected <= 15.0)


def test_a_fleets_prior_about_the_twins_factor_moves_the_threshold_to_the_limit():
    """With the prior centred on the twin's factor c (``faultgen monitor --scale-prior``) the bound
    x (c - z p) passes 8 % at a true wear of 8 c / (c - z p): 9.53 % at c 1.2, p 0.15 (the ramp's first
    whole point past it: 10 %), where the default prior N(1, 0.3^2) waits for 13.0 c (15.6: 16 %)."""
    threshold = 8.0 * 1.2 / (1.2 - alarm_quantile() * 0.15)
    assert threshold == pytest.approx(9.53, abs=0.01)
    errors = np.random.default_rng(3).normal(0.0, 3.0, (50, 2))
    tests = [(5, 0.0, 3.0), (19, 0.0, 3.0)]
    fleet = ceiling.unit_chances(RAMP, tests, 1.2, errors, 8.0, 0.15, prior_mean=1.2)
    default = ceiling.unit_chances(RAMP, tests, 1.2, errors, 8.0, 0.3)
    assert np.all(fleet["alarm"] == np.ceil(threshold)) and np.all(default["alarm"] == 16.0)
    factor, sd = ceiling.factor_draws(RAMP / 1.2, tests, errors, 0.15, 1.2)
    assert (factor[0, 30], sd[0, 30]) == (1.2, 0.15)  # tests at no wear tell nothing: the prior


def test_an_exact_scale_alarms_at_the_limit_and_gives_the_remaining_life_exactly():
    tests = [(24, 5.0, 1e-4), (26, 7.0, 1e-4)]  # tests without error tell the factor 1.25 before the alarm
    errors = np.random.default_rng(2).normal(0.0, 1e-4, (20, 2))
    draws = ceiling.unit_chances(RAMP, tests, 1.25, errors, 7.5, 0.3)
    assert np.all(draws["alarm"] == 8.0)  # the first log past the limit
    assert draws["within"].all() and not draws["late"].any()


@pytest.mark.parametrize(("c", "z", "below"), [
    (1.0, None, True),  # bound x (1 - 1.28 x 0.3) = 0.62 w: below the truth on every alarming log
    (0.5, None, False),  # a twin reading twice the truth: 2 w x 0.62 = 1.23 w, above on every one
    (0.7, None, True),  # w / 0.7 x 0.62 = 0.88 w
    (0.7, 0.5, False),  # a 69 % bound: w / 0.7 x (1 - 0.5 x 0.3) = 1.21 w
    (0.7, 1.96, True),  # a 97.5 % bound: 0.59 w
])
def test_the_bound_below_the_truth_on_known_values(c, z, below):
    """Without a test that sees the wear the factor is the prior's 1 +- 0.3 on every log, so the bound is
    x (1 - z 0.3) = w (1 - z 0.3) / c: below the truth on every alarming log or on none."""
    tests = [(5, 0.0, 3.0), (19, 0.0, 3.0)]
    errors = np.random.default_rng(4).normal(0.0, 3.0, (30, 2))
    draws = ceiling.unit_chances(RAMP, tests, c, errors, 8.0, 0.3, z=z)
    assert np.all(draws["alarming"] > 0)
    assert np.all(draws["below"] == (draws["alarming"] if below else 0))
    assert np.all(draws["first_below"] == below)


def _fleet(root: Path) -> Path:
    fleet, out = root / "scatter-0.03", root / "out"
    fleet.mkdir()
    out.mkdir()
    exponential = np.r_[np.zeros(40), 0.05 * np.exp(0.11 * np.arange(60.0))]
    wear = {"u1": (2, RAMP), "u2": (3, exponential), "u3": (0, 0 * RAMP)}
    stamps = [f"2026-{1 + d // 28:02d}-{1 + d % 28:02d}" for d in range(len(RAMP))]
    with open(fleet / "truth.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["unit", "stamp", "worn_axis", "wear_percent"])
        for unit, (axis, series) in wear.items():
            w.writerows([unit, s, axis, f"{v:.4f}"] for s, v in zip(stamps, series))
    with open(out / "tests.csv", "w", newline="") as f:
        w = csv.DictWriter(f, ["unit", "stamp", "axis", "wear", "wear_lower", "wear_upper", "verdict"])
        w.writeheader()
        for unit, (axis, series) in wear.items():
            for day in range(0, len(RAMP), 14):
                half = 5.0 if day else 4.0  # points: an own error of about 1.8 % in ln after the reference's
                w.writerow({"unit": unit, "stamp": stamps[day], "axis": axis or 1, "wear": series[day],
                            "wear_lower": series[day] - half, "wear_upper": series[day] + half,
                            "verdict": "reference: the first test" if day == 0 else "read"})
    return fleet


@pytest.mark.parametrize(("c", "covered"), [(1.0, True), (1.45, True), (1.55, False), (0.55, True), (0.45, False)])
def test_the_interval_covers_the_truth_on_known_values(c, covered):
    """Without a test that sees the wear the factor is its prior, 1 -+ 0.3, and the 90 % interval
    ``(w / c) (1 -+ 1.6449 x 0.3)`` = ``(w / c) [0.5065, 1.4935]`` holds the true wear ``w`` on every log
    at 10-40 % when ``c`` lies in [0.5065, 1.4935] and on none outside: a unit's coverage is 100 % or
    nothing, never in 80-97 %, however honest the interval (its error is one number for all its logs)."""
    tests = [(19, 0.0, 3.0)]
    draws = ceiling.unit_chances(RAMP, tests, c, np.zeros((3, 1)), 8.0, 0.3)
    assert draws["spanned"] == 31  # the logs at 10, 11, .. 40 %
    np.testing.assert_array_equal(draws["covered"], 31 if covered else 0)
    assert ceiling.coverage_chance(draws) == 0.0  # 100 % or none: never in 80-97 %


def test_the_same_seed_gives_the_same_chances_and_a_table(tmp_path):
    fleet = _fleet(tmp_path)
    truth = ceiling.independent.read_truth(fleet / "truth.csv")
    errors = monitor_scale_bound.own_test_errors(truth, tmp_path / "out")
    assert sorted(errors) == ["u1", "u2"] and len(errors["u1"]) == 7  # the healthy unit and references out
    first = ceiling.fleet_chances(fleet, tmp_path / "out", 1.2, 8.0, 0.3, draws=300, seed=5)
    again = ceiling.fleet_chances(fleet, tmp_path / "out", 1.2, 8.0, 0.3, draws=300, seed=5)
    assert sorted(first) == ["u1", "u2"]
    for unit in first:
        for key in first[unit]:
            np.testing.assert_array_equal(first[unit][key], again[unit][key])
    lines = ceiling.table(fleet.name, first, 1.2)
    assert lines[0] == "**scatter-0.03**, twin factor 1.2"
    assert any(line.startswith("- every worn unit's first alarm in the window: chance ") for line in lines)
    half = "- the median within 20 % at lambda on at least 1 of 2: chance "
    assert any(line.startswith(half) for line in lines)
    honest = "- the bound below the truth on >= 95 % of alarming log-axes: chance "
    assert any(line.startswith(honest) for line in lines)
    cover = "- the 90 % interval covering 80-97 % of the worn axes' "
    assert any(line.startswith(cover) for line in lines)


def test_the_actual_errors_take_off_the_reference_as_a_factor():
    offset = np.mean(np.log1p([0.02, 0.04]))  # two tests at no true wear read 2 and 4 %
    exact = 100 * (1.10 * np.exp(offset) - 1)  # a test at 10 % true wear read through that reference exactly
    errors = ceiling.actual_errors([(0.0, 2.0), (0.0, 4.0), (10.0, exact), (20.0, 25.0)])
    assert errors[2] == pytest.approx(0.0, abs=1e-12)
    assert errors[0] == pytest.approx(-errors[1], rel=0.02)  # about the healthy tests' mean
    assert errors[3] == pytest.approx(100 * (1.25 / np.exp(offset) - 1) - 20.0)
    np.testing.assert_allclose(ceiling.actual_errors([(5.0, 7.0), (9.0, 8.0)]), [2.0, -1.0])  # no healthy test


def test_the_fleets_own_test_errors_are_one_draw(tmp_path):
    fleet = _fleet(tmp_path)  # its tests read the true wear exactly: no error
    actual = ceiling.fleet_chances(fleet, tmp_path / "out", 1.0, 8.0, 0.3, actual=True)
    truth = ceiling.independent.read_truth(fleet / "truth.csv")
    for unit, outcome in actual.items():
        assert len(outcome["alarm"]) == 1
        log = {s: i for i, s in enumerate(truth[unit]["stamps"])}
        tests = [(log[s], float(truth[unit]["wear"][log[s]]), 100 * (1 + truth[unit]["wear"][log[s]] / 100) * e)
                 for s, e, _ in monitor_scale_bound.own_test_errors(truth, tmp_path / "out")[unit]]
        exact = ceiling.unit_chances(truth[unit]["wear"], tests, 1.0, np.zeros((1, len(tests))), 8.0, 0.3)
        assert outcome["alarm"][0] == exact["alarm"][0]
        assert outcome["covered"][0] == outcome["spanned"]  # tests without error, a twin reading the truth
    lines = ceiling.actual_table(fleet.name, actual, 1.0)
    assert lines[-1].startswith("- first alarms in the window: ")


@pytest.mark.parametrize(("call", "message"), [
    (lambda: ceiling.unit_chances(RAMP, [], 0.0, np.zeros((5, 0)), 8.0, 0.3), "twin_factor 0.0"),
    (lambda: ceiling.factor_draws(RAMP, [], np.zeros((5, 0)), 0.0), "prior_sd 0.0"),
    (lambda: ceiling.fleet_chances(Path("."), Path("."), 1.0, 8.0, 0.3, draws=0), "draws 0"),
])
def test_bad_input_is_refused_by_name(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_the_measured_error_ratio_is_one_for_tests_that_scatter_as_they_say(tmp_path):
    fleet, out = _fleet(tmp_path), tmp_path / "out"
    truth = ceiling.independent.read_truth(fleet / "truth.csv")
    own = monitor_scale_bound.own_test_errors(truth, out)
    reads, sign = {}, 1.0
    for unit, tests in own.items():  # each worn test one error off, up and down in turn, on an offset of 2 %
        true = dict(zip(truth[unit]["stamps"], truth[unit]["wear"]))
        healthy = [e for stamp, e, _ in tests if true[stamp] == 0]  # the offset's error: their mean's
        offset_var = sum(e**2 for e in healthy) / len(healthy) ** 2
        for stamp, e, _ in tests:
            w = true[stamp]
            off = sign * np.sqrt(e**2 + offset_var)
            reads[unit, stamp] = 2.0 if w == 0 else 100 * ((1 + w / 100) * 1.02 * np.exp(off) - 1)
            sign = -sign if w else sign
    with open(out / "tests.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        if int(r["axis"]) == truth[r["unit"]]["axis"]:
            r["wear"] = reads.get((r["unit"], r["stamp"]), r["wear"])
    with open(out / "tests.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    ratio, n = ceiling.measured_error_ratio(fleet, out)
    assert n == sum(1 for (unit, stamp), y in reads.items() if y != 2.0)
    assert ratio == pytest.approx(1.0, rel=1e-9)
