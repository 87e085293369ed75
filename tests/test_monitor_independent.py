"""``faultgen monitor`` on a small 7-axis fleet made by a simulator that is not faultgen, with the
generator's own maintenance and program changes (tests/independent_fleet.py, issue 60 part 4): rtb-data's
LBR iiwa 14 R820 added with ``--payload 14``, parts up to 14 kg, one worn unit whose gearbox is
changed (``events.csv``, the axis's friction back to nominal in the generator) and one healthy unit
whose program changes on a day nobody logged (other pick and place poses). The full check, 10
units x 100 days, is ``benchmarks/monitor_loop.py --arm iiwa14 ...`` (docs/analysis.md).

The loop's handling of these events on hand-made changes is tests/test_monitor.py's; here the
changes come from the independent generator, on an arm of 7 axes."""

import csv

import independent_fleet
import numpy as np
import pytest

from faultgen.monitor import loop
from faultgen.monitor.run import resolve_run
from faultgen.monitor.scoring import Settings

# two units, 40 days: unit01 or unit02 worn from day 11 (20 % passed on day 14, gearbox change on
# day 24, 83 % wear the day before), the other healthy with a program change drawn in days 16-24
SPEC = independent_fleet.FleetSpec(units=2, worn=1, days=40, seed=3, onset=(11, 11), final_wear=200.0,
                                   wearable=(1, 2, 3, 4, 5, 6, 7), max_part=14.0, rated_part=True,
                                   gearbox_changes=1,
                                   program_changes=1)
SETTINGS = Settings(train=10, persistence=3)


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    root = tmp_path_factory.mktemp("iiwa-fleet")
    robot = independent_fleet.add_robot(root / "iiwa14", "iiwa14", payload=14.0)
    _, logs, truth = independent_fleet.write_fleet(root, SPEC, robot=robot)
    return robot, logs, truth, independent_fleet.read_changes(root)


@pytest.fixture(scope="module")
def monitored(fleet, tmp_path_factory):
    robot, logs, _, _ = fleet
    out = tmp_path_factory.mktemp("monitor") / "out"
    outcome = loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False))
    return out, outcome


def rows_of(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def angles_and_payload(path):
    """A generated log's angles (n, 7), rad, and its payload column (n,), kg."""
    table = np.loadtxt(path, delimiter=",", skiprows=1)
    return table[:, 1:8], table[:, -1]


def test_the_generator_writes_the_gearbox_change_and_the_program_change(fleet):
    _, logs, truth_path, changes = fleet
    truth = independent_fleet.read_truth(truth_path)
    worn = next(u for u, t in truth.items() if t["axis"])
    healthy = next(u for u, t in truth.items() if not t["axis"])
    (gearbox,), (program,) = changes[worn], changes[healthy]
    assert gearbox["change"] == "gearbox_change" and gearbox["axis"] == truth[worn]["axis"]
    assert program["change"] == "program_change" and program["axis"] == 0
    # the gearbox change is logged for the monitor, the program change is not
    assert rows_of(logs / "events.csv") == [{"unit": worn, "stamp": gearbox["stamp"], "event": "gearbox_change",
                                             "axis": str(gearbox["axis"])}]
    # true wear: 20 % passed CHANGE_DELAY days before the change, 0 from the change on (a new gearbox)
    day = truth[worn]["stamps"].index(gearbox["stamp"])
    wear = truth[worn]["wear"]
    passed = int(np.argmax(wear >= independent_fleet.independent.CHANGE_WEAR))
    assert day - passed == independent_fleet.independent.CHANGE_DELAY
    assert wear[day - 1] > 20.0 and np.all(wear[day:] == 0.0)
    # the program: another motion from its day on, the same one before
    stamps = truth[healthy]["stamps"]
    day = stamps.index(program["stamp"])
    (first, _), (before, _), (after, _) = (angles_and_payload(logs / healthy / f"{s}.csv")
                                           for s in (stamps[0], stamps[day - 1], stamps[day]))
    assert first.shape[1] == 7 and len(before) == len(first)
    assert np.max(np.abs(before - first)) < 1e-3  # the same motion: angle noise 1e-5 rad
    n = min(len(after), len(first))
    assert np.max(np.abs(after[:n] - first[:n])) > loop.PROGRAM_CHANGE
    parts = {float(angles_and_payload(p)[1][0]) for u in truth for p in (logs / u).glob("*.csv")}
    assert 0.0 < min(parts) and max(parts) == 14.0, parts  # the rated payload carried, nothing heavier


def test_same_seed_gives_identical_files_with_the_changes(fleet, tmp_path):
    robot, logs, _, _ = fleet
    _, again, _ = independent_fleet.write_fleet(tmp_path, SPEC, robot=robot)
    names = sorted(p.relative_to(logs).as_posix() for p in logs.rglob("*.csv"))
    assert names == sorted(p.relative_to(again).as_posix() for p in again.rglob("*.csv")) and "events.csv" in names
    for name in names:
        assert (logs / name).read_bytes() == (again / name).read_bytes(), name
    for name in ("truth.csv", "changes.csv"):
        assert (logs.parent / name).read_bytes() == (again.parent / name).read_bytes(), name


def test_the_gearbox_change_closes_the_alarm_and_the_program_change_is_not_raised_as_wear(fleet, monitored):
    _, _, truth_path, changes = fleet
    out, outcome = monitored
    truth = independent_fleet.read_truth(truth_path)
    worn = next(u for u, t in truth.items() if t["axis"])
    healthy = next(u for u, t in truth.items() if not t["axis"])
    (gearbox,), (program,) = changes[worn], changes[healthy]
    assert outcome.exit_status == 0
    status = {r["unit"]: r for r in rows_of(out / "units.csv")}
    assert {u: r["status"] for u, r in status.items()} == {worn: "monitored", healthy: "monitored"}
    alarms = [r for r in rows_of(out / "alarms.csv") if r["first_alarm"]]
    # the worn unit: alarmed on its worn axis before the change, closed by it, quiet after it
    assert [r["unit"] for r in alarms] == [worn], alarms
    (alarm,) = alarms
    assert alarm["first_alarm"] < gearbox["stamp"] and int(alarm["source_axis"]) == truth[worn]["axis"], alarm
    assert alarm["closed"] == gearbox["stamp"] and alarm["closed_by"] == f"gearbox_change of axis {gearbox['axis']}"
    scores = rows_of(out / "scores.csv")
    after = [r for r in scores if r["unit"] == worn and r["stamp"] >= gearbox["stamp"]]
    relearn = max(5, SETTINGS.train // 4)
    assert [r["phase"] for r in after[:relearn + 1]] == ["relearning"] * relearn + ["monitoring"], after
    # the healthy unit: its program change found on its day, learned again, no alarm (not wear)
    assert f"program changed at {program['stamp']}" in status[healthy]["reason"], status[healthy]
    after = [r for r in scores if r["unit"] == healthy and r["stamp"] >= program["stamp"]]
    # its new program's learning logs are relearning (issue 72): its offset alone, on relearn_logs (issue 90)
    assert [r["phase"] for r in after[:relearn + 1]] == ["relearning"] * relearn + ["monitoring"]
    assert all(r["alarm"] == "0" for r in scores if r["unit"] == healthy), "a healthy unit's log alarmed"


@pytest.mark.parametrize(("field", "value", "message"), [
    ("wearable", (0, 1), "fleet wearable = (0, 1): expected axes as whole numbers >= 1"),
    ("max_part", -1.0, "fleet max_part = -1.0 kg: expected a mass in (0, 10000]"),
    ("max_part", True, "fleet max_part = True kg: expected a mass in (0, 10000]"),
    ("gearbox_changes", 2, "fleet gearbox_changes = 2: more than its 1 worn units"),
    ("program_changes", 2, "fleet program_changes = 2: more than its 1 healthy units"),
])
def test_a_fleet_spec_out_of_range_is_refused_by_name(field, value, message):
    with pytest.raises(ValueError) as err:
        independent_fleet.FleetSpec(**{"units": 2, "worn": 1, field: value})
    assert str(err.value) == message


def test_rated_part_must_be_a_bool_and_an_axis_beyond_the_robot_is_refused(fleet, tmp_path):
    with pytest.raises(TypeError, match=r"^fleet rated_part = 1: expected True or False$"):
        independent_fleet.FleetSpec(rated_part=1)
    robot = fleet[0]
    with pytest.raises(ValueError, match=r"^fleet wearable = \(1, 8\): the robot has axes 1\.\.7$"):
        independent_fleet.write_fleet(tmp_path, independent_fleet.FleetSpec(units=1, worn=1, wearable=(1, 8)),
                                      robot=robot)


def test_own_friction_is_each_units_dry_friction_as_the_generator_applies_it(fleet, tmp_path, monkeypatch):
    """``independent.own_friction`` (the truth a unit's wear is a percentage of, for
    benchmarks/wear_scale_sources.py) against the levels the generator hands its friction law on
    every log of two healthy units: the Coulomb and static levels are it times each log's jitter
    (log-normal, sd JITTER: within 4 sd), and a draw of another component or unit would not be."""
    from faultgen.bench import independent
    from faultgen.model import robots

    robot = fleet[0]
    spec = independent_fleet.FleetSpec(units=2, worn=0, days=2, seed=5, onset=(1, 2), max_part=14.0,
                                       wearable=SPEC.wearable)
    handed = []
    law = independent.motor_friction

    def recorded(w, coulomb, static, viscous):
        handed.append(np.array([coulomb, static]))
        return law(w, coulomb, static, viscous)

    monkeypatch.setattr(independent, "motor_friction", recorded)
    independent.write_fleet(tmp_path, spec, robot)
    own = independent.own_friction(spec, robots.load(robot))
    assert sorted(own) == ["unit01", "unit02"] and own["unit01"].shape == (3, 7)
    levels = {"unit01": np.array(handed[:2]), "unit02": np.array(handed[2:])}  # units in order, a log a day
    assert len(handed) == 4
    bound = 4 * independent.JITTER
    for unit, logged in levels.items():
        assert np.all(np.abs(np.log(logged / own[unit][:2])) < bound), unit
    # the bound tells the draws apart: the other unit's levels, or this unit's viscous draw applied to
    # its Coulomb level, are off by more
    assert np.any(np.abs(np.log(levels["unit01"] / own["unit02"][:2])) > bound)
    nominal = robots.load(robot).friction
    viscous_draw = own["unit01"][2] / np.asarray(nominal.viscous)
    assert np.any(np.abs(np.log(levels["unit01"][:, 0] / (np.asarray(nominal.coulomb_pos) * viscous_draw))) > bound)
