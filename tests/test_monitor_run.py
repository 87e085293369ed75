"""A monitor run resolved once (issue 84, item 3): :func:`faultgen.monitor.run.resolve_run` checks and
loads what the command names (the robot, the ``--calibrated`` model, the log format with its
torque constants, the settings' digest, the execution context) into one
:class:`~faultgen.monitor.run.MonitorRun`, which :func:`faultgen.monitor.loop.monitor` takes and
the workers' :class:`faultgen.monitor.feed.Context` is made from."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.logs import formats
from faultgen.model import robots
from faultgen.monitor import feed, loop
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import state as stored
from faultgen.monitor.run import MonitorRun, resolve_run
from faultgen.monitor.scoring import Settings
from faultgen.runs.context import ExecutionContext
from faultgen.simulation import backends


def _one_unit(tmp_path):
    """A fleet folder of one unit whose only log has no torque column: the run finishes at once,
    the unit not monitored (its reason names the missing columns)."""
    logs = tmp_path / "LOGS"
    (logs / "u1").mkdir(parents=True)
    (logs / "u1" / "2026-01-01.csv").write_text("timestamp\n")
    return logs


def test_the_command_with_torque_constants_loads_its_robot_once(tmp_path, loads):
    """``--format ur-rtde --torque-constants``: the constants are checked against the robot the run
    resolves (resolve_run); before, the command loaded the robot for them and the monitor loaded it
    again (['puma560', 'puma560'] on this fleet, main d4f08b2, 2026-11-28)."""
    result = CliRunner().invoke(app, ["monitor", str(_one_unit(tmp_path)), "--robot", "puma560", "-o",
                                      str(tmp_path / "out"), "--format", "ur-rtde", "--torque-constants",
                                      "1,1,1,1,1,1", "--no-calibrate", "--no-progress"])
    assert result.exit_code == loop.EXIT_SOME_UNITS_NOT_MONITORED, result.output
    assert "actual_current_0..5 (A) with the torque constants given" in (tmp_path / "out" / "units.csv").read_text()
    assert loads == ["puma560"]
    bad = CliRunner().invoke(app, ["monitor", str(_one_unit(tmp_path / "b")), "--robot", "puma560", "-o",
                                   str(tmp_path / "b" / "out"), "--format", "ur-rtde", "--torque-constants", "1,1"])
    assert bad.exit_code != 0 and "expected 6 numbers (the axes of puma560)" in bad.output, bad.output
    assert not (tmp_path / "b" / "out").exists()  # refused before any work


def test_a_resolved_run_holds_what_its_text_names_each_loaded_once(tmp_path, loads):
    logs, out = _one_unit(tmp_path), tmp_path / "out"
    stepper = backends.LoopStepper()
    made = []

    def ur(robot):  # a format made from the resolved robot, as the command's --torque-constants
        made.append(robot)
        return formats.make("ur-rtde", torque_constants=(2.0,) * robot.n_axes)

    mjcf = robots.load("puma560").path  # a model file given as the calibrated model
    loads.clear()
    run = resolve_run("puma560", logs, out, calibrated=mjcf, settings=Settings(train=12), log_format=ur,
                      context=ExecutionContext(stepper=stepper), failure_wear=30.0, hours_per_day=8.0)
    assert loads == ["puma560", str(mjcf)]
    assert isinstance(run, MonitorRun) and made == [run.robot] and run.robot.name == "puma560"
    assert (run.named, run.logs, run.out, run.calibrated) == ("puma560", logs, out, mjcf)
    assert run.given is robots.load(mjcf) and run.stepper is stepper
    assert run.n_features == 6 * len(fleet_logs.FEATURES)
    assert run.model_source == stored.sha256_file(mjcf) and run.own_model
    assert run.digest == stored.settings_digest(Settings(train=12), run.model_source, False,
                                                stored.sha256_file(run.robot.path), run.log_format.key)
    assert "torque_constants" in run.log_format.key
    # the workers' context, made from the run: paths (each worker resolves them once), its stepper
    context = feed.Context.of(run, {"u1": []}, {})
    assert (context.robot, context.calibrated, context.out, context.stepper) == (run.robot.path, mjcf, out, stepper)
    assert (context.settings, context.log_format, context.failure_wear) == (run.settings, run.log_format, 30.0)
    source = run.new_source()
    assert (source.robot, source.given) == (run.robot, run.given)
    # the model source as the state is keyed by: own protocol or no calibration: the nominal model
    own = resolve_run(run.robot, logs, out, calibrated=mjcf, settings=Settings(protocol="own"))
    assert (own.model_source, own.calibrated, own.given, own.named) == ("nominal", None, None, run.robot.path)
    assert resolve_run(run.robot, logs, out).model_source == "per-unit"
    assert resolve_run(run.robot, logs, out, calibrate=False).model_source == "nominal"
    assert loads == ["puma560", str(mjcf), str(mjcf)]  # the last this test's own: a Robot given is not loaded again


@pytest.mark.parametrize("change, message", [
    ({"hours_per_day": 25.0}, r"hours_per_day = 25.0; expected operating hours per calendar day in \(0, 24\]"),
    ({"context": 2}, r"context 2: expected an ExecutionContext"),
    ({"context": ExecutionContext(jobs=2, scheduler="tcp://127.0.0.1:1")}, r"--jobs 2 with --scheduler"),
    ({"robot": "no_such_arm"}, r"unknown robot 'no_such_arm'"),
    ({"calibrated": "CAL/arm.xml"}, r"--calibrated .*arm\.xml: the model does not load"),
    ({"out": "LOGS/out"}, r"out lies inside the logs folder .*LOGS"),
], ids=["hours", "context", "jobs-and-scheduler", "robot", "calibrated", "out-in-logs"])
def test_a_run_is_refused_before_any_work(tmp_path, change, message):
    logs = _one_unit(tmp_path)
    (tmp_path / "CAL").mkdir()
    (tmp_path / "CAL" / "arm.xml").write_text("<mujoco/>")
    args = {"robot": "puma560", "logs": logs, "out": tmp_path / "out", **change}
    for key in ("calibrated", "out"):
        if isinstance(args.get(key), str):
            args[key] = tmp_path / args[key]
    with pytest.raises(ValueError, match=message):
        resolve_run(args.pop("robot"), args.pop("logs"), args.pop("out"), **args)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["CAL", "LOGS"]  # nothing made


def test_the_monitor_takes_a_resolved_run_not_names(tmp_path):
    with pytest.raises(TypeError, match="expected a MonitorRun .*resolve_run.*, got str"):
        loop.monitor("puma560")
