"""A unit the monitor cannot read is never shown healthy (issue 88, item 1 and the monitor's parts
of item 6): a unit whose torque is logged motor-side is refused as ``faultgen calibrate`` refuses
it, not monitored against a fallback model (grey light, exit 3, every other unit as without it); one
empty first log does not take a unit's twin away; a twin shared by units names no other unit's log;
the same replay failure through a fallback chain is said once.

A small fleet of faultgen's own PUMA 560 (three pick-and-place cycles, one a day, with faultgen's
default sensor noise): ``h1`` healthy, ``m2`` the same logs with the torque divided by the gear
ratios (a controller's motor-side export), ``e3`` an empty first log, then h1's logs and a last
one declaring a 30 kg part the arm cannot carry."""

from __future__ import annotations

import csv
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.logs import formats
from faultgen.model import robots
from faultgen.monitor import feed, loop, prognosis
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import unit as units_module
from faultgen.monitor.run import resolve_run
from faultgen.monitor.scoring import Settings
from resolved_runs import run_config

runner = CliRunner()
OUTPUTS = ("alarms.csv", "scores.csv", "wear.csv", "rul.csv", "life.csv", "units.csv")
NAMES = ["t", *(f"q{k}" for k in range(1, 7)), *(f"tau{k}" for k in range(1, 7))]


def _write(path: Path, t, q, tau, payload: float | None = None) -> Path:
    columns, names = [t, q, tau], list(NAMES)
    if payload is not None:
        columns.append(np.full(len(t), payload))
        names.append("payload")
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savetxt(path, np.column_stack(columns), delimiter=",", header=",".join(names), comments="", fmt="%.9g")
    return path


@pytest.fixture(scope="module")
def fleet(tmp_path_factory) -> Path:
    from faultgen.operation import wear
    from faultgen.simulation import sensors
    from faultgen.simulation import stepping as sim

    robot = robots.load("puma560")
    run = sim.simulate(run_config(robot="puma560", task="pick_place", friction="stribeck", wear=wear.WearPlan({}),
                                     cycles=3, seed=1, noise=sensors.NoiseConfig(), nthread=1, signals=True),
                       progress=False)
    logs = tmp_path_factory.mktemp("refused") / "LOGS"
    (logs / "e3").mkdir(parents=True)
    for c in range(3):
        tau = run.tau_m[c] * robot.gear_ratio  # arm side
        _write(logs / "h1" / f"2026-03-0{c + 1}.csv", run.t, run.q_a[c], tau)
        _write(logs / "m2" / f"2026-03-0{c + 1}.csv", run.t, run.q_a[c], tau / robot.gear_ratio)  # motor side
        os.link(logs / "h1" / f"2026-03-0{c + 1}.csv", logs / "e3" / f"2026-03-0{c + 2}.csv")
    (logs / "e3" / "2026-03-01.csv").write_text(",".join(NAMES) + "\n")  # empty: a header, no sample
    _write(logs / "e3" / "2026-03-05.csv", run.t, run.q_a[2], run.tau_m[2] * robot.gear_ratio, payload=30.0)
    return logs


def _rows(path: Path) -> dict[str, list[dict]]:
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {unit: [r for r in rows if r["unit"] == unit] for unit in dict.fromkeys(r["unit"] for r in rows)}


def _monitor(logs: Path, out: Path):
    return runner.invoke(app, ["monitor", str(logs), "--robot", "puma560", "-o", str(out), "--train", "10",
                               "--persistence", "3"])


def test_a_unit_logged_motor_side_is_not_monitored_with_the_calibrations_message_and_the_others_unchanged(
        fleet, tmp_path):
    from faultgen.calibrate import ImplausibleLogError, calibrate

    with pytest.raises(ImplausibleLogError) as refused:  # what `faultgen calibrate` says of m2's log
        calibrate("puma560", fleet / "m2" / "2026-03-01.csv", tmp_path / "c")
    message = " ".join(str(refused.value).split())
    assert "the torque looks like motor-side torque" in message

    out = tmp_path / "out"
    result = _monitor(fleet, out)
    assert result.exit_code == loop.EXIT_SOME_UNITS_NOT_MONITORED, result.output
    units = {u: rows[0] for u, rows in _rows(out / "units.csv").items()}
    m2 = units["m2"]
    assert (m2["status"], m2["logs_scored"], m2["model"]) == ("not monitored", "0", ""), m2
    assert f"not monitored: its first log is refused (2026-03-01): {message}" in m2["reason"], m2["reason"]
    assert "fall" not in m2["reason"] and "nominal model" not in m2["reason"], m2["reason"]
    assert f"m2: not monitored (twin): its first log is refused (2026-03-01): {message}" in \
        " ".join(result.output.split())
    # no wear, no life, no "service by" for it: a grey light, never green
    assert _rows(out / "rul.csv")["m2"][0]["verdict"] == "no log scored: no wear estimate"
    assert "m2" not in _rows(out / "life.csv")
    page = (out / "report.html").read_text()
    row = re.search(r'<tr><td data-column="state">(.*?)</td><td data-column="unit"><a [^>]*>m2</a>', page)
    assert row and 'class="light l-unknown"' in row.group(1) and ">unknown</span>" in row.group(1), row
    assert "title=\"unknown: not monitored (not monitored: its first log is refused" in row.group(1)
    assert units["h1"]["status"] == "learning" and units["h1"]["model"] == "calibrated", units["h1"]

    # h1 without m2 and e3 (its calibration and twin from the cache): the same outputs, byte for byte
    alone = tmp_path / "alone" / "LOGS"
    (alone / "h1").mkdir(parents=True)
    for log in (fleet / "h1").iterdir():
        os.link(log, alone / "h1" / log.name)
    again = tmp_path / "alone" / "out"
    shutil.copytree(out / ".cache", again / ".cache")
    assert _monitor(alone, again).exit_code == 0
    for name in OUTPUTS:  # (learning: no row in scores.csv and wear.csv yet)
        assert _rows(again / name).get("h1") == _rows(out / name).get("h1"), name
        assert name in ("scores.csv", "wear.csv") or _rows(again / name)["h1"], name
    assert (again / "h1.png").read_bytes() == (out / "h1.png").read_bytes()

    # one empty first log: the twin is built on the next log (not protocol own for good); the shared
    # twin's refusal of a part names e3's own log, not h1's program log it replays
    e3 = units["e3"]
    assert (e3["status"], e3["protocol"], e3["model"], e3["logs_scored"]) == ("degraded", "twin", "calibrated", "3"), e3
    assert "protocol own" not in e3["reason"], e3["reason"]
    assert re.search(r"^2 logs skipped: 2026-03-01: \S*e3/2026-03-01\.csv: .*; 2026-03-05: the twin with a 30 kg part "
                     r"\(aluminium cube at the flange\) saturates the drive of axis", e3["reason"]), e3["reason"]
    assert "h1" not in e3["reason"] and "2026-03-01.csv with" not in e3["reason"], e3["reason"]


def test_a_replay_failure_of_every_fallback_is_said_once_with_its_count(tmp_path, monkeypatch):
    """A unit whose twin fails alike for each kind of model (a motion no model's drives follow)
    names the failure once, with the count, where it named it three times (and the console once more
    beside its status: twice six times)."""
    from faultgen.monitor import console

    logs = tmp_path / "LOGS"
    robot = robots.load("puma560")
    t = np.arange(750) / 250.0
    q = np.zeros((750, 6)) + 0.1 * np.sin(2 * np.pi * t)[:, None]
    _write(logs / "u1" / "2026-03-01.csv", t, q, np.ones((750, 6)))
    units = fleet_logs.fleet(logs)
    source = fleet_logs.Source(robot)
    error = "/x/u1/2026-03-01.csv (replay): the log ends moving with an acceleration of 39.17 rad/s^2 on axis 1"

    def failing(source, kind, *args):
        raise ValueError(error)

    monkeypatch.setattr(units_module, "model_of", failing)
    monkeypatch.setattr(units_module, "plausible", lambda nominal, data: None, raising=False)
    unit = units_module.new_unit("u1", units, robot, Settings(), None, True, [], source)
    context = feed.Context(robot.path, Settings(), None, tmp_path, False, formats.MEASURED, units, {},
                           prognosis.FAILURE_WEAR)  # the fleet's logs, the cache's folder, the default stepper
    assert units_module.twin_of(unit, context, {}, False, source) is None
    assert unit.notes == [f"the twins of the calibrated model, the nominal model with the unit's own friction and the "
                          f"nominal model failed (3 times, each on the same: {error}); protocol own used"]
    assert units_module.fallback_notes(unit) == unit.notes
    status = loop._status("u1", unit, Settings())
    lines, _ = console.summary(loop.Outcome([], [status]), Settings(), tmp_path)
    assert lines[0].count(error) == 1, lines[0]


def test_the_same_angles_at_another_pace_are_another_program(tmp_path):
    """Two units whose first logs trace the same angles, one three times faster, do not share a
    program (the faster asks nine times the torque of inertia; it replayed the other's log)."""
    robot = robots.load("puma560")
    t = np.arange(1800) / 250.0
    q = 0.2 * np.sin(2 * np.pi * t / 7.2)[:, None] * np.ones((1, 6))
    slow = _write(tmp_path / "LOGS" / "a" / "1.csv", t, q, np.ones((1800, 6)))
    fast = _write(tmp_path / "LOGS" / "b" / "1.csv", t / 3, q, np.ones((1800, 6)))
    same = _write(tmp_path / "LOGS" / "c" / "1.csv", t, q + 1e-4, np.ones((1800, 6)))
    source, programs = fleet_logs.Source(robot), []
    log = {p.parent.name: fleet_logs.Log(p.parent.name, "1", 1.0, "sequence", p, f"{p.parent.name}/1.csv")
           for p in (slow, fast, same)}
    assert units_module.program_of(log["a"], "a", programs, source) == ("a", "1")
    assert units_module.program_of(log["b"], "b", programs, source) == ("b", "1")
    assert units_module.program_of(log["c"], "c", programs, source) == ("a", "1")


def test_a_given_model_that_does_not_load_is_refused_not_replaced_by_the_nominal_model(fleet, tmp_path):
    bad = tmp_path / "puma560_calibrated.xml"
    bad.write_text("<mujoco><worldbody><body name='x'><joint/></body></worldbody>")  # not closed
    out = tmp_path / "out"
    with pytest.raises(ValueError, match=r"^--calibrated .*puma560_calibrated\.xml: the model does not load \("):
        loop.monitor(resolve_run("puma560", fleet, out, calibrated=bad, settings=Settings(train=10, persistence=3),
                                 progress=False))
    assert not out.exists()
