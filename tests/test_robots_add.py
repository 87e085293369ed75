"""`faultgen robots add`: a robot folder from a DH table, loadable, with checked tasks and the
provenance of every drivetrain number; bad input leaves nothing behind."""

from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.model import robots
from faultgen.operation import programs, tasks

UR5 = Path(__file__).resolve().parents[1] / "docs/examples/ur5_dh.toml"


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def test_robot_added_from_a_dh_table_loads_plans_and_says_where_numbers_came_from(tmp_path):
    drive = tmp_path / "drives.toml"
    drive.write_text("[axis.2]\ngear_ratio = 101.0\nmotor_inertia = 3e-5\n")
    out = tmp_path / "ur5"
    result = run("robots", "add", "ur5", "--from", UR5, "--drivetrain", drive, "-o", out)
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in out.iterdir()) == [
        "README.md",
        "drivetrain.toml",
        "scene.xml",
        "tasks.toml",
        "ur5.xml",
    ]
    robot = robots.load(out)
    assert robot.n_axes == 6 and robot.gear_ratio[1] == 1 / (1 / 101.0) and robot.motor_inertia[1] == 3e-5
    # the capacity the table gives (150 N m on axes 1-3, 28 N m on the wrist)
    np.testing.assert_allclose(robot.motor_torque_limit * robot.gear_ratio, [150, 150, 150, 28, 28, 28])
    readme = (out / "README.md").read_text()
    assert "gear_ratio, axis 2: given in --drivetrain" in readme
    assert (
        "gear_ratio, axis 1: sized: G = 470 rad/s / joint speed limit (3.142 rad/s from the source)" in readme
    )
    assert "sized: the source's effort limit 150 N m / G" in readme
    # the tasks plan, and stay within the motors' capacity
    for name in tasks.TASKS:
        path = programs.load(robot, name).trajectory(0.004)
        tau = robot.inverse_dynamics(path.q, path.qd, path.qdd)
        assert np.all(np.abs(tau) <= robot.motor_torque_limit * robot.gear_ratio)
    # the drivetrain.toml written is the model's, and rebuilding from it gives the same model
    again = tmp_path / "again"
    assert (
        run(
            "robots", "add", "ur5", "--from", UR5, "--drivetrain", out / "drivetrain.toml", "-o", again
        ).exit_code
        == 0
    )
    assert (again / "ur5.xml").read_text() == (out / "ur5.xml").read_text()


def test_bad_arm_is_refused_and_nothing_is_written(tmp_path):
    bad = tmp_path / "arm.toml"
    bad.write_text(UR5.read_text().replace("mass = 2.33", "mass = 0.0"))
    out = tmp_path / "out"
    result = run("robots", "add", "bad", "--from", bad, "-o", out)
    assert result.exit_code == 2 and "link 3: mass 0.0 kg" in result.output
    assert list(tmp_path.iterdir()) == [bad]


def test_bad_drivetrain_is_refused_and_nothing_is_written(tmp_path):
    drive = tmp_path / "drives.toml"
    drive.write_text("[axis.2]\ngear_ratio = -5\n")
    result = run("robots", "add", "ur5", "--from", UR5, "--drivetrain", drive, "-o", tmp_path / "out")
    assert result.exit_code == 2 and "axis 2: gear_ratio = -5" in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["drives.toml"]


def test_existing_folder_is_not_overwritten(tmp_path):
    (tmp_path / "keep.txt").write_text("mine")
    result = run("robots", "add", "ur5", "--from", UR5, "-o", tmp_path)
    assert result.exit_code == 2 and "not an empty folder" in result.output
    assert [p.name for p in tmp_path.iterdir()] == ["keep.txt"]


def test_fleet_parts_follow_the_rated_payload(tmp_path):
    from faultgen.model import sizing
    from faultgen.runs.fleet import PARTS

    # the shares reproduce the IRB-6700-like arm's part masses from its 200 kg
    (small, _), (big, _) = sizing.fleet_parts(200.0)
    assert small == PARTS["irb6700"][0][0] and big == PARTS["irb6700"][1][0]
    out = tmp_path / "ur5"
    assert run("robots", "add", "ur5", "--from", UR5, "-o", out).exit_code == 0
    assert robots.load(out).rated_payload == 5.0  # the DH table's rated_payload
    assert np.isnan(robots.load("puma560").rated_payload)


def test_a_built_in_robot_added_from_its_own_arm_and_drivetrain_has_its_dynamics(tmp_path):
    from faultgen.model import folder

    source = robots.robots_dir() / "irb6700"
    added = folder.add(
        "irb_copy",
        source / "arm.xml",
        tmp_path / "irb_copy",
        drivetrain=source / "drivetrain.toml",
        payload=200.0,
    )
    ours, reference = added.robot, robots.load("irb6700")
    rng = np.random.default_rng(3)
    q = rng.uniform(*reference.joint_range.T, (20, 6))
    qd, qdd = rng.normal(0, 1, q.shape), rng.normal(0, 2, q.shape)
    np.testing.assert_array_equal(ours.inverse_dynamics(q, qd, qdd), reference.inverse_dynamics(q, qd, qdd))
    for field in (
        "body_mass",
        "body_inertia",
        "jnt_stiffness",
        "tendon_stiffness",
        "tendon_damping",
        "wrap_prm",
        "actuator_ctrlrange",
        "dof_armature",
        "key_qpos",
    ):
        np.testing.assert_array_equal(
            getattr(ours.model, field), getattr(reference.model, field), err_msg=field
        )
    readme = (tmp_path / "irb_copy" / "README.md").read_text()
    assert "gear_ratio, all axes: given in --drivetrain" in readme
    assert "Rated payload: 200 kg (given with --payload)" in readme


def test_a_killed_add_leaves_a_hidden_staging_folder_that_the_next_add_removes(tmp_path):
    import os
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "ur5"
    import faultgen

    env = {**os.environ, "PYTHONPATH": str(Path(faultgen.__file__).resolve().parents[1])}  # this faultgen
    command = [sys.executable, "-m", "faultgen.cli", "robots", "add", "ur5", "--from", str(UR5), "-o", str(out)]
    process = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    staged = []
    while not staged and process.poll() is None and time.monotonic() < deadline:
        staged = [p for p in tmp_path.glob(".ur5.partial-*") if (p / "ur5.xml").exists()]
        time.sleep(0.02)
    process.send_signal(signal.SIGKILL)
    process.wait()
    assert staged and staged[0].exists() and not out.exists()  # killed while staging
    result = run("robots", "add", "ur5", "--from", UR5, "-o", out)
    assert result.exit_code == 0, result.output
    assert [p.name for p in tmp_path.iterdir()] == ["ur5"]
