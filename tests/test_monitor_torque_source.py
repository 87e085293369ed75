"""Issue 90, item 5: a UR unit whose RTDE logs switch torque source partway.

The scenario, small: one UR5 unit (faultgen's own simulation, one pick and place a day) whose axis 2
wears linearly from day :data:`UNWORN` on. Its RTDE logs carry the measured ``actual_current_i``
(read with the test's torque constants: "measured current x torque constant") until
:data:`SWITCH`; from then on the recorder also writes ``actual_current_as_torque_i`` (a PolyScope
upgrade: the reader takes it first), the current turned into torque by the controller's own
constants, a few % off the test's on each axis (:data:`CONTROLLER`). Before issue 90 those logs
were scored against the first source's baseline and units.csv named only the first.

- The switch is reported on its day (the unit's reason, on the console and the page); the logs
  from it on learn their own baseline (scores.csv's "relearning", the state's baseline index) and
  are never scored against the first source's; the worn unit still alarms on axis 2, within
  8-15 % true wear; units.csv's ``torque_source`` names both sources and the day of the switch.
- The same unit's logs switched to the commanded moment only (``target_moment_i``, the controller's
  command of its fixed program, the same every day), scored in two runs: the switch reported, the
  commanded logs not scored against the measured baseline, and, as their own baseline can show no
  wear, skipped with why (the unit degraded, exit status 3; before issue 90: monitored, no alarm,
  exit 0); units.csv names both sources.
"""

from __future__ import annotations

import csv
import datetime
import json
import os
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.logs import formats
from faultgen.model import robots
from faultgen.monitor import feed, loop, page, sources
from faultgen.operation import wear
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim
from resolved_runs import run_config
from ur_rtde_logs import add_ur5, write_rtde

#: N m/A at the joint given on the command line (the log's current is its arm torque over them).
TORQUE_CONSTANTS = (12.0, 12.0, 12.0, 9.0, 9.0, 9.0)
#: The controller's own constants over the given ones: its current as torque is the arm torque times these.
CONTROLLER = (1.04, 0.97, 1.05, 1.03, 0.96, 1.04)
#: Logs a baseline learns from (the monitor's fewest).
TRAIN = 10
#: The logs a baseline met after the unit learned learns its offset on (Baseline.relearn_logs).
RELEARN = max(5, TRAIN // 4)
#: Days unworn, then days of axis 2's linear wear to FINAL_WEAR %; the source switches on day SWITCH.
UNWORN, WEARING, WORN_AXIS, FINAL_WEAR = 2 * TRAIN + 1, 10, 2, 20.0
SWITCH = TRAIN + 1
#: The unit's program, short (a third of the shipped pick and place's cycle: the test's CPU).
PROGRAM = """name = "short_pick_place"
robot = "ur5"
process = "point-to-point"
start = [0, 0, 0, 0, 0, 0]
velocity_scale = 1
acceleration_scale = 1
""" + "".join(f"\n[[segment]]\n{segment}\n" for segment in (
    'type = "move"\nto = [-60, 60, -60, 60, -60, 60]', 'type = "dwell"\ntime = 0.2',
    'type = "move"\nto = [60, -60, 60, -60, 60, -60]', 'type = "dwell"\ntime = 0.2', 'type = "move"\nto = [0, 0, 0, 0, 0, 0]'))
START = datetime.date(2026, 3, 1)
runner = CliRunner()


def _simulate(robot_dir: Path, cycles: int, plan):
    config = run_config(robot=str(robot_dir), task=str(robot_dir.parent / "short.toml"), friction="stribeck", wear=plan, cycles=cycles,
                        seed=3, noise=sensors.NoiseConfig(), nthread=1)
    result = sim.simulate(config, progress=False)
    assert result.saturated.size == 0
    return result


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    """(robot folder, days: [(stamp, t, q, arm torque (n, 6) N m)], true wear % of axis 2 per stamp)."""
    root = tmp_path_factory.mktemp("sourcefleet")
    robot_dir = add_ur5(root)
    (root / "short.toml").write_text(PROGRAM)
    gear = robots.load(robot_dir).gear_ratio
    days, truth = [], {}
    for cycles, plan in ((UNWORN, wear.WearPlan({})),
                         (WEARING, wear.WearPlan.from_specs([f"{WORN_AXIS}:linear:{FINAL_WEAR:g}"], last_cycle=WEARING))):
        run = _simulate(robot_dir, cycles, plan)
        for c in range(cycles):
            stamp = str(START + datetime.timedelta(days=len(days)))
            days.append((stamp, run.t, run.q_a[c], run.tau_m[c] * gear))
            truth[stamp] = 100.0 * (float(run.friction_multiplier[c, WORN_AXIS - 1]) - 1.0)
    return robot_dir, days, truth


def _logs(days, folder: Path, after: str) -> Path:
    """The unit's logs: the measured current until day SWITCH, then ``after``'s columns ("as torque":
    the current as torque beside the current; "commanded": the commanded moment only)."""
    command = days[0][3]  # the controller's command of the fixed program: the same every day
    for day, (stamp, t, q, tau) in enumerate(days):
        if day < SWITCH:
            columns = {"actual_current": tau / np.asarray(TORQUE_CONSTANTS)}
        elif after == "as torque":
            columns = {"actual_current": tau / np.asarray(TORQUE_CONSTANTS),
                       "actual_current_as_torque": tau * np.asarray(CONTROLLER)}
        else:
            columns = {"target_moment": command}
        write_rtde(folder / "ur-01" / f"{stamp}.csv", t, {"actual_q": q, **columns})
    return folder


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def _monitor(robot_dir, logs, out):
    return runner.invoke(app, ["monitor", str(logs), "--robot", str(robot_dir), "-o", str(out), "--format", "ur-rtde",
                               "--train", str(TRAIN), "--no-calibrate", "--no-progress", "--torque-constants",
                               ",".join(f"{k:g}" for k in TORQUE_CONSTANTS)])


def test_a_switch_to_the_controllers_current_as_torque_learns_its_own_baseline_and_the_unit_alarms(fleet, tmp_path):
    robot_dir, days, truth = fleet
    out = tmp_path / "out"
    result = _monitor(robot_dir, _logs(days, tmp_path / "logs", "as torque"), out)
    assert result.exit_code == 0, result.output
    switch = days[SWITCH][0]
    note = (f"torque source changed at {switch}: {formats.CURRENT_AS_TORQUE} (before: {formats.MEASURED_CURRENT}); "
            "program 1's logs of this source learn their own baseline")
    (row,) = _rows(out / "units.csv")
    assert note in row["reason"] and row["reason"].count("torque source changed") == 1
    assert f"ur-01: monitored (twin, nominal model; torque: {row['torque_source']})" in result.output  # the console
    assert note in (out / page.PAGE).read_text().replace("&#x27;", "'")
    assert row["torque_source"] == f"{formats.MEASURED_CURRENT}, {formats.CURRENT_AS_TORQUE} from {switch}"
    assert row["status"] == "monitored" and "program changed" not in row["reason"]
    assert row["programs"] == f"program 1 ({formats.MEASURED_CURRENT}): {SWITCH} logs, " \
                              f"program 1 ({formats.CURRENT_AS_TORQUE}): {len(days) - SWITCH} logs"
    # the logs from the switch on: their own baseline (1), its offset learned on their own first logs (a
    # quarter of TRAIN, at least 5: as a program met after the unit learned), the rest borrowed
    state = json.loads((out / ".state" / "ur-01.json").read_text())
    assert [log.get("program", 0) for log in state["logs"]] == [0] * SWITCH + [1] * (len(days) - SWITCH)
    assert [(c["stamp"], c["source"]) for c in state["program_changes"]] == [(switch, formats.CURRENT_AS_TORQUE)]
    assert state["program_changes"][0]["program"] == state["program"]  # the same program, the same twin
    phases = [r["phase"] for r in _rows(out / "scores.csv")]
    assert phases == ["training"] * TRAIN + ["monitoring"] + ["relearning"] * RELEARN + ["monitoring"] * (WEARING + TRAIN - RELEARN)
    # the worn unit alarms on its worn axis, in time
    (alarm,) = [r for r in _rows(out / "alarms.csv") if r["first_alarm"]]
    assert alarm["source_axis"] == str(WORN_AXIS)
    assert 8.0 <= truth[alarm["first_alarm"]] <= 15.0, (alarm, truth)


def test_a_switch_to_the_commanded_moment_is_never_scored_against_the_measured_baseline(fleet, tmp_path):
    """Scored in two runs (the second continuing from the first's state, the switch in the first): the
    source of each baseline is kept in the unit's state."""
    robot_dir, days, _ = fleet
    out, every, logs = tmp_path / "out", _logs(days, tmp_path / "all", "commanded") / "ur-01", tmp_path / "logs" / "ur-01"
    logs.mkdir(parents=True)
    for k, (stamp, *_) in enumerate(days):
        if k == SWITCH + 3:
            first = _monitor(robot_dir, logs.parent, out)
            assert first.exit_code == 0, first.output  # learning its new baseline
        os.link(every / f"{stamp}.csv", logs / f"{stamp}.csv")
    result = _monitor(robot_dir, logs.parent, out)
    switch = days[SWITCH][0]
    (row,) = _rows(out / "units.csv")
    assert row["reason"].count("torque source changed") == 1
    assert f"torque source changed at {switch}: {formats.COMMANDED_MOMENT} (before: {formats.MEASURED_CURRENT})" \
        in row["reason"]
    assert row["torque_source"] == f"{formats.MEASURED_CURRENT}, {formats.COMMANDED_MOMENT} from {switch}"
    # its own baseline cannot be learned (the command is the same every day): every later log skipped with why
    skipped = len(days) - SWITCH - (RELEARN - 1)
    assert f"{skipped} logs skipped: {days[SWITCH + RELEARN - 1][0]}: the baseline begun at {switch} cannot be learned: " \
           f"{feed.CONSTANT_TORQUE.removeprefix('not monitored: ')}" in row["reason"], row["reason"]
    # degraded, and said so by the exit status (before issue 90: "monitored", exit 0, no alarm)
    assert row["status"] == "degraded" and result.exit_code == loop.EXIT_SOME_UNITS_NOT_MONITORED, result.output
    assert row["programs"] == f"program 1 ({formats.MEASURED_CURRENT}): {SWITCH} logs, " \
                              f"program 1 ({formats.COMMANDED_MOMENT}): {RELEARN - 1} logs"
    state = json.loads((out / ".state" / "ur-01.json").read_text())
    assert [log.get("program", 0) for log in state["logs"]] == [0] * SWITCH + [1] * (RELEARN - 1)
    # no log of the commanded moment scored against the measured baseline: no alarm, no monitoring row after it
    scores = _rows(out / "scores.csv")
    assert all(r["phase"] != "monitoring" for r in scores if r["stamp"] >= switch)
    assert not any(r["first_alarm"] for r in _rows(out / "alarms.csv"))


def test_units_csv_names_the_sources_seen_in_order():
    """:func:`faultgen.monitor.sources.seen` on planted units: one source, a few changes, a mix."""
    from faultgen.monitor.history import Entry, ProgramChange

    class Planted:
        def __init__(self, sources_of_logs):
            self.torque_source, self.program = "A", ("u", "2026-01-01")
            self.program_changes = [ProgramChange("2026-01-02", self.program, 1, np.zeros((1, 1)), "B")]
            self.entries = [Entry(f"2026-01-{d + 1:02d}", "", np.zeros(1), 20.0, 0.0, None, program=int(s == "B"))
                            for d, s in enumerate(sources_of_logs)]

    assert sources.seen(Planted("AAA")) == "A"
    assert sources.seen(Planted("AABBA")) == "A, B from 2026-01-03, A from 2026-01-05"
    assert sources.seen(Planted("ABABAB")) == "a mix of A: 3 logs, B: 3 logs (5 changes from 2026-01-02)"
    assert sources.seen(Planted("")) == "A"
