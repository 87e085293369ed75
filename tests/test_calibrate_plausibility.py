"""The calibration refuses a log its robot cannot explain, and never writes an unphysical fit.

The wrong-robot log is made by another library (roboticstoolbox-python's PUMA 560 ``rne``) along
an excitation that lies inside both robots' joint ranges, so only the torque can give it away;
the unit and side errors are a right log with one thing changed.
"""

import numpy as np
import pytest
import roboticstoolbox as rtb  # test dependency, declared in pyproject.toml [test]
from typer.testing import CliRunner

from faultgen.calibrate import ImplausibleLogError, calibrate, plausibility, predict, search, synth
from faultgen.cli import app
from faultgen.logs import measured
from faultgen.data import logfiles
from faultgen.effects import get
from faultgen.model import robots


@pytest.fixture(scope="module")
def excitation():
    """20 s at 250 Hz inside the joint ranges of both robots."""
    return synth.excitation([robots.load("puma560"), robots.load("irb6700")], 20.0, 0.004)


def puma_log(excitation):
    t, q, qd, qdd = excitation
    tau = np.asarray(rtb.models.DH.Puma560().rne(q, qd, qdd))
    return t, q, tau + np.random.default_rng(0).normal(size=tau.shape) * 0.01 * np.sqrt(np.mean(tau**2, axis=0))


def test_the_right_robot_is_accepted_and_judged_on_every_axis(excitation):
    t, q, tau = puma_log(excitation)
    robot = robots.load("puma560")
    data = measured.from_arrays(t, q, tau, robot=robot)
    predicted = predict(robot, data)
    slopes = plausibility.slopes(data.tau, predicted, np.abs(data.qd) >= search.REST_SPEED)
    assert np.all(np.isfinite(slopes)) and slopes == pytest.approx(1.0, abs=0.05)
    plausibility.check(robot, data.tau, predicted, np.abs(data.qd) >= search.REST_SPEED)


def test_a_puma_log_given_as_the_irb_is_refused_from_the_command_line_and_nothing_is_written(tmp_path, excitation):
    """The first round wrote a "calibrated" IRB model with torque offsets of 1208 and 1081 N m here."""
    t, q, tau = puma_log(excitation)
    log = logfiles.write_csv(tmp_path / "puma.csv", t, q, tau)
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["calibrate", "--robot", "irb6700", "--measured", str(log), "--out", str(out)])
    assert result.exit_code == 2, result.output
    message = " ".join(result.output.split())
    assert "not what irb6700 could produce" in message and "--robot" in message and "arm side" in message
    assert not out.exists(), "a refused log writes nothing"


@pytest.mark.parametrize(("change", "expected"), [
    ("motor side", "looks like motor-side torque"),
    ("tau3 in kN m", "tau3 is 0.001 x"),
    ("tau5 sign", "tau5 run against"),
])
def test_unit_side_and_sign_errors_are_refused_naming_what_to_check(tmp_path, excitation, change, expected):
    robot = robots.load("puma560")
    t, q, tau = puma_log(excitation)
    if change == "motor side":
        tau = tau / robot.gear_ratio
    elif change == "tau3 in kN m":
        tau[:, 2] /= 1000.0
    else:
        tau[:, 4] *= -1.0
    with pytest.raises(ImplausibleLogError, match=expected):
        calibrate("puma560", measured.from_arrays(t, q, tau, robot=robot), tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_an_offset_above_the_rated_torque_is_never_selected():
    robot = robots.load("puma560")
    motion, tau = synth.nominal_motion(robot, "pick_place", 2)
    split = search.Split.of(motion.t, motion.qd)
    rated = robot.gear_ratio[1] * robot.motor_torque_limit[1]  # arm side, N m
    effect = get("torque_offset")
    residual = np.zeros_like(tau)
    residual[:, 1] = 0.5 * rated
    assert search.fit_effect(effect, motion, residual, tau, split).axes == [1]
    residual[:, 1] = 1.5 * rated
    candidate = search.fit_effect(effect, motion, residual, tau, split)
    assert candidate.effect.offset[1] == pytest.approx(1.5 * rated)  # fitted, but not physical
    assert candidate.axes == []


def test_a_payload_the_drives_cannot_carry_is_never_selected():
    robot = robots.load("puma560")
    motion, tau = synth.nominal_motion(robot, "pick_place", 2)
    split = search.Split.of(motion.t, motion.qd)
    effect = get("payload")
    phi, _ = effect.columns(motion, None, None)
    heaviest = float(np.min(robot.motor_torque_limit * robot.gear_ratio / np.max(np.abs(phi[:, :, 0]), axis=0)))
    assert search.fit_effect(effect, motion, 0.5 * heaviest * phi[:, :, 0], tau, split).axes == list(range(6))
    assert search.fit_effect(effect, motion, 2.0 * heaviest * phi[:, :, 0], tau, split).axes == []
