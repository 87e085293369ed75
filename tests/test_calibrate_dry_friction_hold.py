"""Issue 72 item 3's remaining misses: a dry friction level the joint (dry + viscous) fit places
precisely but at a level no unit of the type has (a trade with something the model leaves) is held
at the nominal model's and named by the range it left; a level placed less tightly than the old
15 % interval but at least as well as the unit spread, inside that range, is fitted.

Independent references: the level, its standard error and its interval by numpy's least squares and
the textbook covariance ``s^2 (X^T X)^-1`` with scipy's t quantile (not statsmodels, which the
check uses); the unit spread's range from ``numpy.exp`` of the spread's standard deviation."""

from types import SimpleNamespace

import numpy as np
import pytest
from scipy.stats import t as student_t

from faultgen.calibrate import loop, separable
from faultgen.model import robots

NOMINAL = 0.05  # N m, motor side
G = 100.0


def _speeds(speeds, seconds=60.0, rate=250.0):
    """One axis moving at ``speeds`` (rad/s), a speed a 2 s segment, back and forth."""
    t = np.arange(0.0, seconds, 1 / rate)
    segment = (t // 2).astype(int)
    return t, np.array(speeds)[segment % len(speeds)] * np.where(segment % 2, -1.0, 1.0)


def _case(dry_over_nominal, noise, speeds=(0.2, 0.5, 1.0, 1.6), seed=0):
    """A residual of the nominal model: the dry level ``dry_over_nominal`` x nominal, a viscous
    change, Gaussian noise of ``noise`` N m. Returns design, residual, rows."""
    t, qd = _speeds(speeds)
    design = np.column_stack([G * np.sign(qd), G**2 * qd])
    rng = np.random.default_rng(seed)
    residual = design @ [(dry_over_nominal - 1) * NOMINAL, 2e-6] + rng.normal(0.0, noise, len(t))
    return design, residual, np.abs(qd) > 0


def _textbook(design, residual, rows, stride):
    """The dry level over nominal, its standard error over nominal and its 95 % interval: numpy's
    least squares and s^2 (X^T X)^-1 on the thinned samples, the level on every sample."""
    x, y = design[rows][::stride], residual[rows][::stride]
    theta = np.linalg.lstsq(x, y, rcond=None)[0]
    s2 = np.sum((y - x @ theta) ** 2) / (len(y) - 2)
    error = np.sqrt(s2 * np.linalg.inv(x.T @ x)[0, 0])
    level = 1 + np.linalg.lstsq(design[rows], residual[rows], rcond=None)[0][0] / NOMINAL
    half = student_t.ppf(0.975, len(y) - 2) * error / NOMINAL
    return level, error / NOMINAL, (level - half, level + half)


def test_the_range_is_the_unit_spreads_three_standard_deviations():
    assert separable.RANGE == pytest.approx((np.exp(-0.45), np.exp(0.45)))
    assert separable.RANGE[0] > 0.3  # issue 72's 0.18-0.30 x can never be written


@pytest.mark.parametrize("dry, noise, held_by", [
    (1.2, 0.3, None),           # placed and plausible: fitted
    (1.9, 0.3, "range"),        # placed to a few %, at a level no unit has: the trade the noise does not see
    (0.25, 0.3, "range"),       # issue 72's failure, placed tightly: still never written
    (1.2, 15.0, None),          # interval wider than the old 15 %, standard error within the spread: fitted
    (1.0, 30.0, "precision"),   # the log cannot place it
])
def test_the_check_against_the_textbook_least_squares(dry, noise, held_by):
    design, residual, rows = _case(dry, noise)
    found = separable.dry_and_viscous(design, residual, rows, 7, NOMINAL)
    level, error, interval = _textbook(design, residual, rows, 7)
    assert found["level"] == pytest.approx(level, rel=1e-9)
    assert found["standard_error"] == pytest.approx(error, rel=1e-9)
    assert found["interval"] == pytest.approx(list(interval), rel=1e-9)
    expected = ("precision" if error > 0.15 else
                "range" if interval[0] < np.exp(-0.45) or interval[1] > np.exp(0.45) else None)
    assert found["held_by"] == expected == held_by
    assert found["separable"] is (held_by is None)


def test_the_old_interval_rule_held_a_level_that_is_now_fitted():
    """The static-friction unit's miss: a level fitted right whose interval is wider than 15 % of
    nominal (the old rule held it at 1.00); its standard error is within the spread: fitted now."""
    design, residual, rows = _case(1.2, 15.0)
    found = separable.dry_and_viscous(design, residual, rows, 7, NOMINAL)
    assert found["share"] > 0.15 and found["standard_error"] <= separable.SHARE and found["separable"]
    assert found["interval"][0] <= 1.2 <= found["interval"][1]


def test_the_level_is_the_models_plus_the_fits_change():
    design, residual, rows = _case(1.2, 0.3)
    from_nominal = separable.dry_and_viscous(design, residual, rows, 7, NOMINAL)
    # the same residual left by a model whose dry level is 1.1 x nominal: the level is 0.2 x above it
    from_model = separable.dry_and_viscous(design, residual, rows, 7, NOMINAL, 1.1 * NOMINAL)
    assert from_model["level"] == pytest.approx(from_nominal["level"] + 0.1)
    assert from_model["held_by"] is None and from_model["fitted_dry_Nm"] == pytest.approx(1.3 * NOMINAL, rel=0.02)
    # ... and by one at 1.5 x: 1.7 x, outside the range, held
    assert separable.dry_and_viscous(design, residual, rows, 7, NOMINAL, 1.5 * NOMINAL)["held_by"] == "range"


@pytest.mark.parametrize("nominal, stride, named", [(0.0, 7, "nominal_dry 0.0"), (-1.0, 7, "nominal_dry -1.0"),
                                                     (0.05, 0, "stride 0")])
def test_bad_input_is_named(nominal, stride, named):
    design, residual, rows = _case(1.0, 0.3)
    with pytest.raises(ValueError, match=named):
        separable.dry_and_viscous(design, residual, rows, stride, nominal)


def test_the_words_name_the_part_that_failed():
    design, residual, rows = _case(1.9, 0.3)
    words = separable.words(separable.dry_and_viscous(design, residual, rows, 7, NOMINAL))
    assert words.startswith("fitted at 1.9") and "outside the levels a unit of the type has (0.64..1.57 x)" in words
    design, residual, rows = _case(1.0, 30.0)
    words = separable.words(separable.dry_and_viscous(design, residual, rows, 7, NOMINAL))
    assert words.startswith("not separable on this motion from the viscous level (its standard error")


def test_an_axis_placed_at_twice_its_nominal_dry_level_is_held_and_its_viscous_level_fitted():
    """faultgen's PUMA 560 axis 1 through the own-friction fit (loop._own_axis): a residual of a
    dry level twice nominal, placed tightly, is held at the nominal (both directions) and named by
    the range; the viscous level is fitted alone."""
    robot = robots.load("puma560")
    t, qd1 = _speeds([0.05, 0.3, 0.8, 1.5])
    qd = np.column_stack([qd1] + [np.zeros_like(qd1)] * 5)
    f, g = robot.friction, robot.gear_ratio[0]
    nominal = (f.coulomb_pos[0] + f.coulomb_neg[0]) / 2
    residual = np.zeros((len(t), 6))
    residual[:, 0] = g * nominal * np.sign(qd1) + g**2 * 0.3 * f.viscous[0] * qd1
    residual[:, 0] += np.random.default_rng(0).normal(0.0, 0.01 * np.std(residual[:, 0]), len(t))
    c, v, check = loop._own_axis(0, SimpleNamespace(robot=robot, qd=qd, t=t), residual, np.abs(qd1) > 0, robot, 5)
    assert check["held_by"] == "range" and check["level"] == pytest.approx(2.0, abs=0.02), check
    assert c["coulomb_pos"] == pytest.approx(f.coulomb_pos[0]) and c["coulomb_neg"] == pytest.approx(f.coulomb_neg[0])
    assert v is not None and v["viscous"] > f.viscous[0]


def test_the_checked_level_is_the_level_written():
    """The level the range is judged on is the one the own-friction fit writes (both directions'
    mean), also from a model whose two directions differ from the nominal's."""
    robot = robots.load("puma560")
    t, qd1 = _speeds([0.05, 0.3, 0.8, 1.5])
    qd = np.column_stack([qd1] + [np.zeros_like(qd1)] * 5)
    f, g = robot.friction, robot.gear_ratio[0]
    model = SimpleNamespace(gear_ratio=robot.gear_ratio, friction=SimpleNamespace(
        coulomb_pos=f.coulomb_pos * 1.3, coulomb_neg=f.coulomb_neg * 0.9, viscous=f.viscous, static=f.static))
    nominal = (f.coulomb_pos[0] + f.coulomb_neg[0]) / 2
    residual = np.zeros((len(t), 6))
    residual[:, 0] = g * 0.2 * nominal * np.sign(qd1) + g**2 * 0.3 * f.viscous[0] * qd1
    residual[:, 0] += np.random.default_rng(1).normal(0.0, 0.01 * np.std(residual[:, 0]), len(t))
    c, v, check = loop._own_axis(0, SimpleNamespace(robot=model, qd=qd, t=t), residual, np.abs(qd1) > 0, robot, 5)
    assert check["held_by"] is None, check
    assert check["fitted_dry_Nm"] == pytest.approx((c["coulomb_pos"] + c["coulomb_neg"]) / 2, rel=1e-9)
    assert check["level"] * nominal == pytest.approx((c["coulomb_pos"] + c["coulomb_neg"]) / 2, rel=1e-9)
