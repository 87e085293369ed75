"""The friction test: the motion faultgen writes (a program like any task, inside the limits, at least
3 speeds each way per axis held 0.5 s), its reader on an independent simulator's log (roboticstoolbox,
a friction law unlike faultgen's, a motion faultgen did not write) and on faultgen's own simulation,
and what the reader refuses."""

from __future__ import annotations


import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import faultgen
import friction_test_log
from faultgen.calibrate import friction_report, friction_test
from faultgen.cli import app
from faultgen.logs import measured
from faultgen.data import logfiles
from faultgen.model import robots
from faultgen.operation import friction_test as motion
from faultgen.operation import programs

runner = CliRunner()


def _steady_runs(qd: np.ndarray, dt: float) -> list[tuple[float, float]]:
    """(speed, seconds) of each run of constant nonzero speed in the planned path's ``qd`` (n,)."""
    out, k = [], 0
    while k < len(qd):
        j = k
        while j + 1 < len(qd) and qd[j + 1] == qd[k]:
            j += 1
        if qd[k] != 0 and j > k:
            out.append((float(qd[k]), (j - k) * dt))
        k = j + 1
    return out


@pytest.mark.parametrize("name", ["puma560", "irb6700"])
def test_the_motion_is_a_checked_program_within_the_limits_with_three_speeds_each_way(name):
    robot = robots.load(name)
    program = programs.parse(motion.text(robot), robot, where="test")  # the project's program checks
    path = program.trajectory(0.004)  # plans: joint, speed, acceleration and torque limits checked
    low, high = robot.joint_range.T
    assert np.all(path.q >= low - 1e-9) and np.all(path.q <= high + 1e-9)
    for k in range(robot.n_axes):
        # other axes still while axis k moves at a constant speed
        alone = np.all(np.delete(path.qd, k, axis=1) == 0, axis=1)
        qd = np.round(np.where(alone, path.qd[:, k], 0.0), 9)
        runs = _steady_runs(qd, 0.004)
        for sign in (1, -1):
            speeds = {round(abs(v), 6) for v, seconds in runs if np.sign(v) == sign and seconds >= 0.5}
            assert len(speeds) >= 3, (name, k + 1, sign, runs)


def test_gravity_changes_less_in_the_chosen_posture_than_at_mid_range():
    robot = robots.load("puma560")
    k, length = 1, 0.8
    chosen = motion.posture(robot, k, length)
    offsets = np.linspace(-length / 2, length / 2, 9)

    def change(q0):
        q = np.repeat(q0[None], len(offsets), axis=0)
        q[:, k] += offsets
        g = robot.static_load(q)[:, k]
        return g.max() - g.min()

    middle = robot.joint_range.mean(axis=1)
    assert change(chosen) < 0.5 * change(middle)


@pytest.fixture(scope="module")
def independent_logs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("independent")
    return {temperature: friction_test_log.write_log(folder / f"test_{temperature:g}.csv", temperature)
            for temperature in (20.0, 45.0, 70.0)}


@pytest.mark.parametrize("temperature", [20.0, 45.0, 70.0])
def test_the_reader_recovers_an_independent_simulators_friction(independent_logs, temperature):
    """Dry level within 3 %, viscous within 10 % of the truth of another simulator's law (exponential
    hump, tanh sign, levels moving with temperature) on a motion faultgen did not write, every axis."""
    robot = robots.load("irb6700")
    reading = friction_report.read(measured.read(independent_logs[temperature], robot, accelerations=False), robot)
    dry, viscous = friction_test_log.truth(temperature)
    fits = reading.fits.sort_values("axis")
    assert list(fits["axis"]) == [1, 2, 3, 4, 5, 6] and not reading.notes
    assert np.all(np.abs(fits["coulomb_Nm"].to_numpy() / dry - 1) < 0.03), fits["coulomb_Nm"].to_numpy() / dry
    assert np.all(np.abs(fits["viscous_Nms_rad"].to_numpy() / viscous - 1) < 0.10)
    assert np.allclose(fits["temperature_degC"], temperature)
    assert set(reading.points["source"]) == {"differenced"}


def test_the_reader_finds_the_segments_without_being_told(independent_logs):
    """Every stroke at constant speed of the independent motion is found, with its speed, and nothing else."""
    robot = robots.load("irb6700")
    log = measured.read(independent_logs[20.0], robot, accelerations=False)
    found = friction_test.segments(log)
    for k in range(6):
        for sign in (1, -1):
            got = sorted(abs(s.speed) for s in found if s.axis == k and np.sign(s.speed) == sign)
            assert np.allclose(got, friction_test_log.SPEEDS[k], rtol=0.01), (k, sign, got)
    assert all(s.duration >= friction_test.MIN_STEADY for s in found)


def test_a_log_missing_one_direction_is_read_through_the_model_and_says_so(tmp_path):
    robot = robots.load("irb6700")
    path = friction_test_log.write_log(tmp_path / "one_way.csv", 20.0, axes=[0, 1], one_way=0)
    reading = friction_report.read(measured.read(path, robot, accelerations=False), robot)
    axis1 = reading.points[reading.points["axis"] == 1]
    assert set(axis1["source"]) == {"model"} and set(reading.points[reading.points["axis"] == 2]["source"]) == {
        "differenced"}
    assert sum("axis 1" in note and "through the model" in note for note in reading.notes) == 6


def test_a_log_without_a_test_is_refused_naming_the_minimum(tmp_path):
    robot = robots.load("irb6700")
    path = friction_test_log.write_log(tmp_path / "short.csv", 20.0, axes=[0])
    log = measured.read(path, robot, accelerations=False)
    keep = log.t < 9.0  # the first two speeds only
    cut = measured.from_arrays(log.t[keep], log.q[keep], log.tau[keep], robot, source="cut")
    with pytest.raises(ValueError, match="at least 3 speeds each way, each steady at least 0.5 s"):
        friction_report.read(cut, robot)


def test_faultgens_own_test_simulated_and_read_end_to_end(tmp_path):
    """`tasks friction-test` writes a short test, `simulate --task` runs it, `friction-test` reads the
    log (arm angle, motor torque x G) and writes its files; the dry and viscous levels agree with the
    drivetrain's (not independent: the same model simulated and read, a check of the plumbing). The
    commands run through the in-process CLI runner, as the refusals below (a child process each only
    started Python again; tests/capped.py's one_line_refusal checks refusals of `python -m faultgen.cli`)."""
    program, data, log, out = (tmp_path / name for name in ("t.toml", "t.h5", "t.csv", "out"))
    made = runner.invoke(app, ["tasks", "friction-test", "puma560", "--axes", "2", "--speeds", "4", "-o", str(program)])
    assert made.exit_code == 0 and "friction test of puma560" in made.stdout and " s (" in made.stdout, made.output
    run = runner.invoke(app, ["simulate", "--robot", "puma560", "--task", str(program), "--cycles", "1", "-o", str(data)])
    assert run.exit_code == 0, run.output
    robot = robots.load("puma560")
    recorded = faultgen.open(data).runs[0]
    q, tau = recorded.signal("q_a")[0], recorded.signal("tau_m")[0] * robot.gear_ratio
    logfiles.write_csv(log, np.arange(len(q)) / 250.0, q, tau)
    read = runner.invoke(app, ["friction-test", str(log), "--robot", "puma560", "-o", str(out)])
    assert read.exit_code == 0, read.output
    assert "axis 2 (" in read.stdout and "(95 %, arm side)" in read.stdout
    assert sorted(p.name for p in out.iterdir()) == ["friction_axis2.png", "friction_curve.csv", "friction_fit.csv"]
    fit = pd.read_csv(out / "friction_fit.csv").iloc[0]
    G, f = robot.gear_ratio[1], robot.friction
    assert fit["coulomb_Nm"] == pytest.approx(G * (f.coulomb_pos[1] + f.coulomb_neg[1]) / 2, rel=0.02)
    assert fit["viscous_Nms_rad"] == pytest.approx(G**2 * f.viscous[1], rel=0.05)
    again = runner.invoke(app, ["friction-test", str(log), "--robot", "puma560", "-o", str(tmp_path / "again"),
                                "--reference", str(out)])
    assert again.exit_code == 0, again.output


@pytest.mark.parametrize(("args", "message"), [
    (["tasks", "friction-test", "puma560", "--axes", "7"], "error: axes [7]: expected axis numbers in 1..6"),
    (["tasks", "friction-test", "puma560", "--axes", "one"], "error: --axes 'one': expected axis numbers"),
    (["tasks", "friction-test", "puma560", "--speeds", "2"], "error: speeds = 2: expected a whole number"),
])
def test_bad_input_is_refused_in_one_line(args, message):
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.output
    assert result.stderr.strip().splitlines() == [result.stderr.strip()] and result.stderr.startswith(message)


def test_a_reference_that_is_no_output_folder_is_refused(tmp_path, independent_logs):
    result = runner.invoke(app, ["friction-test", str(independent_logs[20.0]), "--robot", "irb6700", "-o",
                                 str(tmp_path / "o"), "--reference", str(tmp_path)])
    assert result.exit_code == 2 and "a folder without friction_fit.csv" in result.stderr, result.output
