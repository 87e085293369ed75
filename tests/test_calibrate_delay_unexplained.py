"""Issue 73 (a channel delay named unexplained on every axis it shifts) and issue 72 item 3 (a dry
friction level the log cannot place is held at the nominal model's and named not separable).

Independent references: the delayed torque is made by ``np.interp`` / pandas row shifts, not by
faultgen's ``delay.shift``; the dry level's interval is checked against statsmodels' OLS standard
error on the same thinned samples. The calibration of a late roboticstoolbox log is checked in
tests/test_calibrate_delay.py (one calibration for both)."""

from types import SimpleNamespace

import numpy as np
import pytest
import statsmodels.api as sm
from scipy.stats import t as student_t

from faultgen.calibrate import delay, loop, remainder, separable
from faultgen.model import robots

RATE = 500.0


def _motion(seconds=30.0, seed=0):
    """Six axes of a smooth multi-sine motion at :data:`RATE` and a model torque along it (the
    speeds and accelerations mixed, as inverse dynamics mixes them)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, seconds, 1 / RATE)
    w = 2 * np.pi * np.array([0.11, 0.23, 0.37])
    a = rng.normal(size=(3, 6))
    q = np.sin(np.outer(t, w)) @ a
    qd = (np.cos(np.outer(t, w)) * w) @ a
    qdd = -(np.sin(np.outer(t, w)) * w**2) @ a
    model = 10 * qdd + 5 * qd + 3 * np.sign(qd) + 20 * np.cos(q)
    return t, q, qd, qdd, model


def _late(t, model, seconds, noise, seed=1):
    rng = np.random.default_rng(seed)
    late = np.column_stack([np.interp(t - seconds, t, model[:, a]) for a in range(model.shape[1])])
    return late + noise * rng.standard_normal(model.shape) * np.sqrt(np.mean(model**2, axis=0))


def test_a_channel_delay_shows_on_every_moving_axis_and_not_on_a_still_one():
    t, q, qd, qdd, model = _motion()
    tau = _late(t, model, 0.012, 0.01)
    moving = np.abs(qd) > 0.01
    moving[:, 5] = False  # axis 6 held still: not named
    found = delay.shown(t, tau, model, moving)
    assert found is not None and found["channel"] and found["level"] == delay.SHOWN_LEVEL
    assert found["seconds"] == pytest.approx(0.012, abs=0.001)
    assert found["interval_s"][0] <= 0.012 <= found["interval_s"][1]
    assert found["axes"] == [1, 2, 3, 4, 5] and 6 not in found["per_axis"]
    assert found["error_after"] < found["error_before"]
    assert "channel delay" not in loop.shown_words(found) and "axes 1, 2, 3, 4, 5" in loop.shown_words(found)


def test_no_delay_shows_on_a_log_without_one():
    t, q, qd, qdd, model = _motion(seed=3)
    for seed in range(3):
        assert delay.shown(t, _late(t, model, 0.0, 0.01, seed), model, np.abs(qd) > 0.01) is None


def test_a_peak_that_moving_the_torque_does_not_explain_is_not_a_channel_delay():
    """The peak says 12 ms (the torque late on the last seven eighths), but on the samples the
    model's error is judged on (the first eighth, where it is not late) moving the torque makes the
    error larger: not taken for a channel delay, no axis named, and the words say why."""
    t, q, qd, qdd, model = _motion(seed=4)
    first = t < t[-1] / 8
    tau = np.where(first[:, None], _late(t, model, 0.0, 0.01, 2), _late(t, model, 0.012, 0.01))
    found = delay.shown(t, tau, model, (np.abs(qd) > 0.01) & first[:, None])
    assert found["seconds"] == pytest.approx(0.012, abs=0.001) and found["interval_s"][0] > 0
    assert not found["channel"] and found["axes"] == [] and found["error_after"] > found["error_before"]
    assert loop.shown_words(found).startswith("not a channel delay")


def test_the_log_delay_is_the_first_term_of_an_axis_with_its_value_and_interval():
    t, q, qd, qdd, model = _motion(seed=5)
    tau = _late(t, model, 0.008, 0.005)
    n = len(t)
    fit = np.zeros((n, 6), dtype=bool)
    fit[: int(0.7 * n)] = True
    held = ~fit
    found = remainder.explain(t, q, qd, qdd, tau, model, np.full(6, 100.0), fit, held, 2,
                              log_delay=(0.008, [0.0077, 0.0083]))
    first = found["terms"][0]
    assert first["form"] == "channel_delay" and first["value"] == 0.008 and first["interval"] == [0.0077, 0.0083]
    assert "lags the motion by 8.0 ms (+7.7 .. +8.3 ms)" in first["words"]
    assert first["share"] > 0.5  # the shift is most of what this axis's remainder is


def _axis_motion(speeds, seconds=60.0):
    """A motion of one axis at the given speeds, a speed a segment, back and forth (rad/s)."""
    t = np.arange(0.0, seconds, 1 / 250.0)
    segment = (t // 2).astype(int)
    qd = np.array(speeds)[segment % len(speeds)] * np.where(segment % 2, -1.0, 1.0)
    qd = np.column_stack([qd] + [np.zeros_like(qd)] * 5)
    return t, qd


def test_the_dry_level_interval_is_ordinary_least_squares_on_the_thinned_samples():
    t, qd = _axis_motion([0.2, 0.5, 1.0, 1.6])
    g = 100.0
    design = g * np.column_stack([np.sign(qd[:, 0]), qd[:, 0]])
    rng = np.random.default_rng(0)
    residual = design @ [0.01, 0.002] + rng.normal(0.0, 0.5, len(t))
    rows = np.abs(qd[:, 0]) > 0
    found = separable.dry_and_viscous(design, residual, rows, 7, 0.05)
    x, y = design[rows][::7], residual[rows][::7]
    ols = sm.OLS(y, x).fit()
    half = student_t.ppf(0.975, ols.df_resid) * ols.bse[0]
    assert found["dry_half_width_Nm"] == pytest.approx(half, rel=1e-9)
    assert found["share"] == pytest.approx(half / 0.05) and found["samples"] == len(y)


def _own_axis(speeds, seed=0):
    """faultgen's PUMA 560 axis 1 moving at ``speeds``; its residual: its dry level 20 % above
    nominal and its viscous level 50 % above, with 2 % torque noise. Returns (Coulomb, viscous, check)."""
    robot = robots.load("puma560")
    t, qd = _axis_motion(speeds)
    motion = SimpleNamespace(robot=robot, qd=qd, t=t)
    f, g = robot.friction, robot.gear_ratio[0]
    dry, wet = 0.2 * (f.coulomb_pos[0] + f.coulomb_neg[0]) / 2, 0.5 * f.viscous[0]
    clean = g * dry * np.sign(qd[:, 0]) + g**2 * wet * qd[:, 0]  # the effects' columns
    rng = np.random.default_rng(seed)
    residual = np.zeros((len(t), 6))
    residual[:, 0] = clean + 0.02 * np.sqrt(np.mean(clean**2)) * rng.standard_normal(len(t)) * 10
    return loop._own_axis(0, motion, residual, np.abs(qd[:, 0]) > 0, robot, 5), robot


def test_a_dry_level_the_motion_can_place_is_fitted():
    (c, v, check), robot = _own_axis([0.05, 0.3, 0.8, 1.5])
    f = robot.friction
    nominal = (f.coulomb_pos[0] + f.coulomb_neg[0]) / 2
    assert check["separable"], check
    assert (c["coulomb_pos"] + c["coulomb_neg"]) / 2 == pytest.approx(1.2 * nominal, rel=0.05)
    assert v["viscous"] == pytest.approx(1.5 * f.viscous[0], rel=0.1)


def test_a_dry_level_at_one_steady_speed_is_held_at_nominal_and_named_not_separable():
    (c, v, check), robot = _own_axis([1.0])
    f = robot.friction
    assert not check["separable"] and check["cosine"] > 0.999, check
    assert c["coulomb_pos"] == pytest.approx(f.coulomb_pos[0]) and c["coulomb_neg"] == pytest.approx(f.coulomb_neg[0])
    assert v is not None and v["viscous"] > f.viscous[0]  # the viscous level takes what the dry one would
