"""Issue 72, items 1 and 2: a new user's UR fleet reaches the calibrated twin, and the torque source
is stated.

The scenario, small: a UR5 added from the shipped DH table (docs/examples/ur5_dh.toml), three units
logging one pick and place a day in the RTDE recorder's layout (space-separated, the recorder's
column names, joint temperatures, the measured ``actual_current_i`` beside the commanded
``target_moment_i``), one unit whose axis 2 wears until its gearbox is changed (events.csv), one
healthy unit whose program changes (pick and place to spot weld) on a day nobody logs. The
logs are faultgen's own simulation (the conditions on: the season's joint temperature, the unit
spread, encoder noise), the currents the arm torque over test torque constants (``TORQUE_CONSTANTS``:
the test's, not Universal Robots' numbers), the commanded moment the same array every day (the
controller's command of a fixed program).

- With the torque constants every unit is on its calibrated twin (on 6e0facf each fell back to the
  nominal model, "qdd holds a non-finite value", exit 0, wear.csv saying "own"), the worn unit
  alarms on axis 2 within 10-15 % true wear with its alarm closed by the gearbox change, the healthy
  units are quiet, the program change is found on its day (and its logs are relearning), the page
  lists the units by urgency, and units.csv, the console and the page say the torque is the measured
  current.
- Without them the fleet finishes: each unit "not monitored" with why, exit status 3 (on 6e0facf:
  "feature 0 is constant in the training data ... drop it", exit 2, no output).
"""

from __future__ import annotations

import csv
import datetime
import os
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.logs import formats
from faultgen.model import robots
from faultgen.monitor import feed, lights, loop, page, report, scoring, steps, tables
from faultgen.monitor import logs as fleet_logs
from faultgen.operation import conditions, wear
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim
from resolved_runs import run_config
from ur_rtde_logs import add_ur5, write_ur_log

#: N m/A at the joint, the test's (the log's current is its arm torque over them).
TORQUE_CONSTANTS = (12.0, 12.0, 12.0, 9.0, 9.0, 9.0)
#: Logs a unit learns from (the monitor's fewest).
TRAIN = 10
#: The worn unit: days unworn, days of a linear wear of axis 2 up to FINAL_WEAR %, days after its
#: gearbox change (unworn again); each healthy unit's days.
UNWORN, WEARING, AFTER, HEALTHY_DAYS = 11, 14, 6, 15
WORN_AXIS, FINAL_WEAR = 2, 21.0
START = datetime.date(2026, 4, 1)
#: The healthy unit ur-03's program changes, unlogged, after this many days (to this task).
PROGRAM_DAY, OTHER_TASK = 12, "spot_weld"
runner = CliRunner()


def _simulate(robot_dir: Path, seed: int, cycles: int, start_day: float, plan, task: str = "pick_place"):
    held = conditions.Conditions(thermal=conditions.Temperature(), spread=conditions.UnitSpread(),
                                 cycles_per_day=1, start_day=start_day)
    config = run_config(robot=str(robot_dir), task=task, friction="stribeck", wear=plan, cycles=cycles,
                           seed=seed, noise=sensors.NoiseConfig(), nthread=1, conditions=held, signals=True)
    result = sim.simulate(config, progress=False)
    assert result.saturated.size == 0
    return result


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    """(robot folder, logs folder, true wear % of the worn unit's axis 2 per stamp)."""
    root = tmp_path_factory.mktemp("urfleet")
    robot_dir, logs = add_ur5(root), root / "logs"
    gear = robots.load(robot_dir).gear_ratio
    commanded = {}
    parts = {"ur-01": [(UNWORN, wear.WearPlan({})), (WEARING, wear.WearPlan.from_specs(
                 [f"{WORN_AXIS}:linear:{FINAL_WEAR:g}"], last_cycle=WEARING)), (AFTER, wear.WearPlan({}))],
             "ur-02": [(HEALTHY_DAYS, wear.WearPlan({}))],
             "ur-03": [(PROGRAM_DAY, wear.WearPlan({})), (HEALTHY_DAYS - PROGRAM_DAY, wear.WearPlan({}), OTHER_TASK)]}
    truth, change = {}, None
    for seed, (unit, runs) in enumerate(parts.items(), start=1):
        day = 0
        for index, (cycles, plan, *task) in enumerate(runs):
            run = _simulate(robot_dir, seed, cycles, 91.0 + day, plan, *task)
            # the controller's command of the program: the same every day
            command = commanded.setdefault(tuple(task), run.tau_m[0] * gear)
            for c in range(cycles):
                stamp = str(START + datetime.timedelta(days=day + c))
                write_ur_log(logs / unit / f"{stamp}.csv", run.t, run.q_a[c], run.tau_m[c] * gear,
                             run.conditions.joint_temperature[c], command, TORQUE_CONSTANTS)
                truth[(unit, stamp)] = 100.0 * (float(run.friction_multiplier[c, WORN_AXIS - 1]) - 1.0)
            if unit == "ur-01" and index == 2:
                change = str(START + datetime.timedelta(days=day))
            if task:  # the unlogged program change: in the truth, not in events.csv
                truth[(unit, "program change")] = str(START + datetime.timedelta(days=day))
            day += cycles
    (logs / "events.csv").write_text(f"unit,stamp,event,axis\nur-01,{change},gearbox_change,{WORN_AXIS}\n")
    return robot_dir, logs, truth


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def _monitor(robot_dir, logs, out, *extra):
    return runner.invoke(app, ["monitor", str(logs), "--robot", str(robot_dir), "-o", str(out), "--format", "ur-rtde",
                               "--train", str(TRAIN), "--no-progress", *extra])


def test_every_ur_unit_is_on_its_calibrated_twin_and_the_worn_one_alarms_on_its_axis(fleet, tmp_path):
    robot_dir, logs, truth = fleet
    constants = ",".join(f"{k:g}" for k in TORQUE_CONSTANTS)
    result = _monitor(robot_dir, logs, tmp_path / "out", "--torque-constants", constants)
    assert result.exit_code == 0, result.output
    units = {r["unit"]: r for r in _rows(tmp_path / "out" / "units.csv")}
    assert set(units) == {"ur-01", "ur-02", "ur-03"}
    changed = truth[("ur-03", "program change")]
    for unit, row in units.items():  # no fallback: every twin is the unit's calibrated model
        status = "learning" if unit == "ur-03" else "monitored"  # ur-03 relearning its new program
        assert (row["status"], row["model"]) == (status, "calibrated"), row
        assert "failed" not in row["reason"] and "wear_scale" not in row
        assert row["torque_source"] == formats.MEASURED_CURRENT
        assert f"{unit}: {status} (twin, calibrated model; torque: {formats.MEASURED_CURRENT})" in result.output
        # the unlogged program change found on its day, and nowhere else
        assert row["reason"].count("program changed at ") == (unit == "ur-03"), row
    assert f"program changed at {changed} (not logged" in units["ur-03"]["reason"]
    phases = {r["stamp"]: r["phase"] for r in _rows(tmp_path / "out" / "scores.csv") if r["unit"] == "ur-03"}
    assert {p for s, p in phases.items() if s >= changed} == {"relearning"} and phases[min(phases)] == "training"
    alarms = _rows(tmp_path / "out" / "alarms.csv")
    raised = [r for r in alarms if r["first_alarm"]]
    assert [r["unit"] for r in raised] == ["ur-01"]  # the healthy units quiet
    worn = raised[0]  # the axis, and closed by the gearbox change
    assert worn["source_axis"] == str(WORN_AXIS) and worn["closed_by"] == f"gearbox_change of axis {WORN_AXIS}"
    assert 10.0 <= truth[("ur-01", worn["first_alarm"])] <= 15.0, (worn, truth)
    assert 10.0 <= truth[("ur-01", worn["known"])] <= 15.0, (worn, truth)  # when a daily run saw it (item 4)
    html = (tmp_path / "out" / page.PAGE).read_text()
    assert f"<b>Torque</b>: {formats.MEASURED_CURRENT}." in html and "Twin fallback" not in html
    # the page's order by urgency: its units by the "service by" date it shows, the soonest first
    listed = re.findall(r'href="#unit-\d+">([^<]+)</a></td><td data-column="service by \(5-95 %\)">([^<]*)<', html)
    assert sorted(u for u, _ in listed) == sorted(units), listed
    dates = [datetime.date.fromisoformat(d.split()[0]) for _, d in listed]
    assert dates == sorted(dates), listed


def test_without_torque_constants_the_fleet_finishes_and_says_why_no_unit_is_monitored(fleet, tmp_path):
    robot_dir, logs, _ = fleet
    few = tmp_path / "logs"
    # the learning logs of one unit: enough to tell (each unit is judged on its own logs; a unit taken
    # off the monitor and the run going on to the next: tests/test_monitor.py's planted units)
    for unit in ("ur-02",):
        (few / unit).mkdir(parents=True)
        for log in sorted((logs / unit).iterdir())[:TRAIN + 1]:
            os.link(log, few / unit / log.name)
    result = _monitor(robot_dir, few, tmp_path / "out")
    assert result.exit_code == loop.EXIT_SOME_UNITS_NOT_MONITORED, result.output
    units = _rows(tmp_path / "out" / "units.csv")
    assert [r["unit"] for r in units] == ["ur-02"]
    for row in units:
        assert row["status"] == "not monitored" and row["torque_source"] == formats.COMMANDED_MOMENT
        assert feed.CONSTANT_TORQUE in row["reason"] and "can show no wear" in row["reason"]
        assert row["logs_scored"] == "0" and "learning: " not in row["reason"]
    assert f"ur-02: not monitored (twin, calibrated model; torque: {formats.COMMANDED_MOMENT})" in result.output
    assert "exit status 3" in result.output
    html = (tmp_path / "out" / page.PAGE).read_text()
    assert f'<p class="evidence"><b>Torque</b>: {formats.COMMANDED_MOMENT}.</p>' in html
    # a rerun after a new log: the unit stays off the monitor, its new log skipped with the reason
    os.link(sorted((logs / "ur-02").iterdir())[TRAIN + 1], few / "ur-02" / sorted((logs / "ur-02").iterdir())[TRAIN + 1].name)
    again = _monitor(robot_dir, few, tmp_path / "out")
    assert again.exit_code == loop.EXIT_SOME_UNITS_NOT_MONITORED, again.output
    row = _rows(tmp_path / "out" / "units.csv")[0]
    assert row["status"] == "not monitored" and f"{TRAIN + 2} logs skipped" in row["reason"]
    assert row["torque_source"] == formats.COMMANDED_MOMENT  # kept in the unit's state, not read from its notes


def test_the_import_summary_states_the_torque_source(fleet, tmp_path):
    robot_dir, logs, _ = fleet
    few = tmp_path / "logs"
    (few / "ur-02").mkdir(parents=True)
    for log in sorted((logs / "ur-02").iterdir())[:2]:
        os.link(log, few / "ur-02" / log.name)
    command = ["logs", "import", str(few), "--robot", str(robot_dir), "--format", "ur-rtde", "--no-progress"]
    measured = runner.invoke(app, [*command, "-o", str(tmp_path / "a.h5"), "--torque-constants",
                                   ",".join(map(str, TORQUE_CONSTANTS))])
    assert measured.exit_code == 0, measured.output
    assert f"torque:        {formats.MEASURED_CURRENT} (2 log(s) read now)" in measured.output
    commanded = runner.invoke(app, [*command, "-o", str(tmp_path / "b.h5")])
    assert commanded.exit_code == 0, commanded.output
    assert f"torque:        {formats.COMMANDED_MOMENT} (2 log(s) read now)" in commanded.output


def test_an_adapter_log_is_read_once_with_the_accelerations_the_calibration_needs(fleet):
    """The monitor's reader of a format is the adapter's whole reader, accelerations estimated as
    the measured format's reader estimates them (on 6e0facf: NaN, and every calibrated twin failed)."""
    robot_dir, logs, _ = fleet
    robot = robots.load(robot_dir)
    read, suffixes = fleet_logs.reader_of(formats.make("ur-rtde", torque_constants=TORQUE_CONSTANTS))
    data = read(sorted((logs / "ur-01").iterdir())[0], robot)
    assert suffixes == (".csv", ".csv.gz") and np.all(np.isfinite(data.qdd))
    assert formats.torque_source(data.notes) == formats.MEASURED_CURRENT


def test_a_twin_fallen_back_to_the_nominal_model_labels_its_wear_so(tmp_path):
    """units.csv's and wear.csv's ``wear_scale`` say "nominal model" for a unit whose twin fell back
    to it (the page's panel and table say it too); a run that asked for the nominal model, and a
    unit on its own model, keep the twin's scale and no column."""
    settings = loop.Settings()

    class Kept:
        def __init__(self, model):
            self.model = model

    state = {"a": Kept("calibrated"), "b": Kept("nominal"), "c": Kept("friction")}
    assert loop._nominal_scale(state, settings, True) == {"b"}
    assert loop._nominal_scale(state, settings, False) == set()
    assert loop._nominal_scale(state, loop.Settings(protocol="own"), True) == set()
    statuses = [loop.UnitStatus("a", "monitored", "twin", "calibrated", "", 3, "x"),
                loop.UnitStatus("b", "monitored", "twin", "nominal", "the twin of the calibrated model failed (qdd); "
                                "nominal model used", 3, "x", "", "the twin of the calibrated model failed (qdd)")]
    report.units_table(statuses, scales={"a": "twin", "b": "nominal model"}).write(tmp_path)
    rows = _rows(tmp_path / "units.csv")
    assert [r["wear_scale"] for r in rows] == ["twin", "nominal model"] and "torque_source" not in rows[0]
    assert statuses[1].basis() == "; twin fallback: the twin of the calibrated model failed (qdd)"
    def Monitor(name):  # a unit's record of one scored log of two axes (its rows)
        unit = steps.start(name, scoring.Settings(), 2)
        unit.rows = tables.log_rows([{"unit": name, "stamp": "2026-04-01", "phase": "monitoring",
                                      **{f"wear{k}{end}": 1.0 for k in (1, 2)
                                         for end in ("", "_5", "_95", "_lower", "_log")}}])
        return unit

    report.wear_table([Monitor("a"), Monitor("b")], scales=True, nominal={"b"}).write(tmp_path)
    assert [r["wear_scale"] for r in _rows(tmp_path / "wear.csv")] == ["twin"] * 2 + ["nominal model"] * 2
    assert "wear_scale" not in report.wear_table([Monitor("a")]).columns
    notes = page._source_notes(rows[1])
    assert len(notes) == 1 and "Twin fallback" in notes[0] and not page._source_notes(rows[0])
    assert "nominal model's" in lights.SCALES["nominal model"]
