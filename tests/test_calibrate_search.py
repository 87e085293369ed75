"""Model selection on residuals made from the effects' own regressors: known values come back.

These use the inverse dynamics only (no stepping), so they are fast; the closed-loop checks are
in tests/test_calibrate_hidden.py.
"""

import numpy as np
import pytest

from faultgen import effects
from faultgen.calibrate import search, synth
from faultgen.model import robots


@pytest.fixture(scope="module")
def puma():
    robot = robots.load("puma560")
    motion, tau = synth.nominal_motion(robot, "pick_place", 3)
    return robot, motion, tau


def test_gap_against_hand_computation():
    column_tau = np.array([[1.0, 2.0], [3.0, -2.0], [-1.0, 2.0], [1.0, 0.0]])
    column_error = np.array([[0.5, 0.0], [-0.5, 1.0], [0.0, 0.0], [9.0, 9.0]])
    tau = np.tile(column_tau, 3)
    predicted = tau - np.tile(column_error, 3)
    mask = np.ones_like(tau, dtype=bool)
    mask[3] = False  # the last sample is left out
    gap = search.gap(tau, predicted, mask)
    rmse0, rms0 = np.sqrt((0.25 + 0.25 + 0) / 3), np.sqrt((1 + 9 + 1) / 3)
    rmse1, rms1 = np.sqrt((0 + 1 + 0) / 3), np.sqrt((4 + 4 + 4) / 3)
    assert gap["rmse_Nm"] == pytest.approx([rmse0, rmse1] * 3)
    assert gap["nrmse"] == pytest.approx([rmse0 / rms0, rmse1 / rms1] * 3)
    assert gap["total_nrmse"] == pytest.approx((rmse0 / rms0 + rmse1 / rms1) / 2)


def test_split_is_in_time_and_leaves_out_rest_and_edges():
    t = np.arange(0, 10, 0.004)
    qd = np.ones((len(t), 6))
    qd[1000:1100, 2] = 0.0  # axis 3 at rest for 0.4 s
    split = search.Split.of(t + 5.0, qd)
    assert not np.any(split.fit & split.held_out)
    fit_times = t[split.fit[:, 0]]
    held_times = t[split.held_out[:, 0]]
    assert fit_times.max() < held_times.min()
    assert held_times.min() == pytest.approx(search.FIT_FRACTION * t[-1], abs=0.005)
    assert fit_times.min() >= search.Split.EDGE and held_times.max() <= t[-1] - search.Split.EDGE
    assert not split.fit[1000:1100, 2].any() and split.fit[1000:1100, 1].all()


def test_coulomb_comes_back_from_its_own_regressor(puma):
    _, motion, tau = puma
    effect = effects.get("coulomb")
    phi, _ = effect.columns(motion, 2, None)
    rng = np.random.default_rng(3)
    residual = rng.normal(scale=0.01 * np.sqrt(np.mean(tau**2, axis=0)), size=tau.shape)
    residual[:, 2] += phi[:, 0] * 0.07
    split = search.Split.of(motion.t, motion.qd)
    ranked = search.rank(motion, residual, tau, split)
    best = ranked[0]
    assert best.effect.id == "coulomb" and best.axes == [2]
    # parameters are absolute: the nominal levels plus the change, in both directions
    friction = motion.robot.friction
    assert best.effect.coulomb_pos[2] - friction.coulomb_pos[2] == pytest.approx(0.07, rel=0.02)
    assert best.effect.coulomb_neg[2] - friction.coulomb_neg[2] == pytest.approx(0.07, rel=0.02)
    # report.json numbers the axis as a user does and gives only the significant one
    assert best.effect.report(best.axes) == {"3": {"coulomb_pos": best.effect.coulomb_pos[2],
                                                   "coulomb_neg": best.effect.coulomb_neg[2]}}


def test_payload_mass_comes_back(puma):
    _, motion, tau = puma
    effect = effects.get("payload")
    phi, _ = effect.columns(motion, None, None)
    rng = np.random.default_rng(4)
    residual = phi[:, :, 0] * 1.7 + rng.normal(scale=0.01 * np.sqrt(np.mean(tau**2, axis=0)), size=tau.shape)
    split = search.Split.of(motion.t, motion.qd)
    best = search.rank(motion, residual, tau, split)[0]
    assert best.effect.id == "payload" and best.axes == list(range(6))
    assert best.effect.mass == pytest.approx(1.7, rel=0.02)
    assert best.effect.report(best.axes) == {"robot": best.effect.values()}
    # a residual a point mass at the flange explains is fitted at the first level: mass only
    assert best.effect.values()["com_z"] == 0.0 and best.effect.values()["ixx"] == 0.0


def test_stribeck_velocity_and_exponent_are_refined_off_the_grid(puma):
    """A hump of exponent 1.15 (between the tried 1 and 1.25) at a velocity between two grid points:
    both come back, and the static level."""
    _, motion, tau = puma
    effect = effects.get("stribeck")
    axis = 5
    grid = effect.grid(motion, axis)
    v_s = float(np.sqrt(grid[4] * grid[5]))  # between two grid points
    phi, offset = effect.columns(motion, axis, (v_s, 1.15))
    residual = np.zeros_like(tau)
    residual[:, axis] = phi[:, 0] * 0.02 + offset
    split = search.Split.of(motion.t, motion.qd)
    candidate = search.fit_effect(effect, motion, residual, tau, split)
    params = candidate.effect.values(axis)
    assert params["stribeck_velocity"] == pytest.approx(v_s, rel=0.01)
    assert params["stribeck_exponent"] == pytest.approx(1.15, rel=0.01)
    assert params["static"] == pytest.approx(0.02, rel=0.01)


def test_noise_alone_names_nothing(puma):
    _, motion, tau = puma
    rng = np.random.default_rng(5)
    residual = rng.normal(scale=0.02 * np.sqrt(np.mean(tau**2, axis=0)), size=tau.shape)
    split = search.Split.of(motion.t, motion.qd)
    ranked = search.rank(motion, residual, tau, split)
    assert all(not c.axes for c in ranked)


def test_unphysical_fit_is_never_selected(puma):
    """A residual that only a negative mass would explain is not a payload."""
    _, motion, tau = puma
    phi, _ = effects.get("payload").columns(motion, None, None)
    residual = -2.0 * phi[:, :, 0]
    split = search.Split.of(motion.t, motion.qd)
    candidate = search.fit_effect(effects.get("payload"), motion, residual, tau, split)
    assert candidate.effect.mass == pytest.approx(-2.0, rel=1e-6)
    assert candidate.axes == []


def _least_squares_error(phi, noise, rows):
    """The textbook standard error of a one-column least-squares fit with noise of std ``noise``."""
    return noise * np.sqrt(1.0 / np.sum(phi[rows] ** 2))


def test_jackknife_standard_error_matches_least_squares_on_white_noise(puma):
    _, motion, tau = puma
    effect = effects.get("viscous")
    phi, _ = effect.columns(motion, 2, None)
    noise = 0.02 * np.sqrt(np.mean(tau[:, 2] ** 2))
    residual = np.zeros_like(tau)
    residual[:, 2] = phi[:, 0] * 2e-3 + np.random.default_rng(8).normal(scale=noise, size=len(tau))
    split = search.Split.of(motion.t, motion.qd)
    error = search.standard_errors(effect, motion, residual, tau, split, [2])[2]["viscous"]
    expected = _least_squares_error(phi[:, 0], noise, split.fit[:, 2])
    assert 0.5 < error / expected < 1.5
    fitted = search.fit_effect(effect, motion, residual, tau, split).effect.viscous[2]
    assert abs(fitted - motion.robot.friction.viscous[2] - 2e-3) < 3 * error


def test_jackknife_standard_error_sees_noise_correlated_in_time(puma):
    """A slow drift in the residual makes neighbouring samples agree; the least-squares formula
    takes them as independent and is too small, the blocks of time are not fooled."""
    _, motion, tau = puma
    effect = effects.get("viscous")
    phi, _ = effect.columns(motion, 2, None)
    noise = 0.02 * np.sqrt(np.mean(tau[:, 2] ** 2))
    white = np.random.default_rng(9).normal(size=len(tau))
    drift = np.convolve(white, np.ones(250) / np.sqrt(250), mode="same")  # 1 s moving sum, same std
    residual = np.zeros_like(tau)
    residual[:, 2] = phi[:, 0] * 2e-3 + noise * drift
    split = search.Split.of(motion.t, motion.qd)
    error = search.standard_errors(effect, motion, residual, tau, split, [2])[2]["viscous"]
    assert error > 3 * _least_squares_error(phi[:, 0], noise, split.fit[:, 2])


def test_warm_up_hidden_by_a_coulomb_level_is_found_jointly_with_it(puma):
    """A warm-up on axis 2 whose early excess a Coulomb level fitted before it took up: the warm-up
    alone then fits the held-out part worse than nothing; fitted together with a change of that
    level it comes back, and the level returns to where it was."""
    _, motion, tau = puma
    axis, amplitude, time_constant = 1, 0.5, 25.0
    temperature, coulomb = effects.get("temperature"), effects.get("coulomb")
    warm_up = temperature.columns(motion, axis, time_constant)[0][:, 0] * amplitude
    split = search.Split.of(motion.t, motion.qd)
    rng = np.random.default_rng(5)
    residual = rng.normal(scale=0.01 * np.sqrt(np.mean(tau**2, axis=0)), size=tau.shape)
    residual[:, axis] += warm_up
    # the level a Coulomb fit made of it on the fitting part, taken out as the model would have it
    level = coulomb.columns(motion, axis, None)[0][:, :1]
    taken = np.linalg.lstsq(level[split.fit[:, axis]], residual[split.fit[:, axis], axis], rcond=None)[0]
    residual[:, axis] -= level @ taken
    alone = search.fit_effect(temperature, motion, residual, tau, split)
    assert axis not in alone.axes and alone.gain[axis] < search.MIN_GAIN

    found = search.fit_jointly(temperature, [coulomb], motion, residual, tau, split, axis)
    assert found is not None and found.gain >= search.MIN_GAIN
    assert found.params["amplitude"] == pytest.approx(amplitude, rel=0.1)
    assert found.params["time_constant"] == pytest.approx(time_constant, rel=0.3)  # on the search grid
    nominal = motion.robot.friction.coulomb_neg[axis]
    assert found.others[0]["coulomb_neg"] - nominal == pytest.approx(-taken[0], rel=0.1)
    assert set(found.standard_errors[0]) == {"amplitude", "time_constant"}
    # noise alone on that axis gives nothing
    quiet = rng.normal(scale=0.01 * np.sqrt(np.mean(tau**2, axis=0)), size=tau.shape)
    assert search.fit_jointly(temperature, [coulomb], motion, quiet, tau, split, axis) is None
