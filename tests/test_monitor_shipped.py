"""The README's monitor example on fleets of faultgen's own shipped robots (issue 60): daily logs of
an irb6700 and a PUMA 560 doing pick and place with the joint temperature over a spring, the
unit-to-unit spread, faultgen's default encoder noise (1e-4 rad), a part on some days and one unit
without a payload column (tests/shipped_fleet.py). On 997c8e5 the irb6700's stopped the whole run
(`the twin ... saturates the drive of axis 1`: the twin simulated 0 deg C, and replayed the
encoder's noise). Faultgen's own simulator made these logs, so this checks that the monitor runs on
the robots faultgen ships, not the method against an independent reference (tests/test_monitor.py
does that on a Pinocchio fleet)."""

import csv

import numpy as np
import pytest
import shipped_fleet
from typer.testing import CliRunner

from faultgen.cli import app

FLEETS = {
    # three units, 36 days: its two healthy units are the regression check of the trend's innovation
    # gate (docs/analysis.md: one log of a healthy unit of this fleet carried the filtered wear over
    # the limit without it)
    "irb6700": shipped_fleet.ShippedFleet(robot="irb6700", parts=(15.0, 35.0)),
    # two units, 28 days (the suite's time, docs/performance.md): the healthy unit 01 logs no payload
    # column, the worn unit 02 wears from day 14 (after the 14 learning logs) to 60 % on day 28
    "puma560": shipped_fleet.ShippedFleet(robot="puma560", parts=(1.0, 2.5), units=2, days=28,  # rated 2.5 kg
                                          no_payload=1),
}


@pytest.mark.parametrize("robot", sorted(FLEETS))
def test_the_readmes_monitor_example_on_a_fleet_of_a_shipped_robot(robot, tmp_path):
    spec = FLEETS[robot]
    logs, truth = shipped_fleet.write_fleet(tmp_path, spec)
    assert "payload" not in (logs / shipped_fleet.unit_name(spec.no_payload)).glob("*.csv").__next__().read_text()[:300]
    out = tmp_path / "monitor"
    # the README's command (on the irb6700; the PUMA 560's twins on the nominal model, to keep the
    # suite short); 36 days of logs (28 for the PUMA), so 14 learning logs and 3 in a row instead of 28 and 5
    result = CliRunner().invoke(app, ["monitor", str(logs), "--robot", robot, "-o", str(out), "--train", "14",
                                      "--persistence", "3", "--no-progress",
                                      *(["--no-calibrate"] if robot == "puma560" else [])])
    assert result.exit_code == 0, result.output
    with open(out / "units.csv", newline="") as f:
        units = {row["unit"]: row for row in csv.DictReader(f)}
    assert set(units) == set(truth)
    for unit, row in units.items():
        assert (row["status"], row["protocol"]) == ("monitored", "twin"), row
        assert row["logs_scored"] == str(spec.days), row
    with open(out / "alarms.csv", newline="") as f:
        alarms = {row["unit"]: row for row in csv.DictReader(f)}
    stamps = sorted(p.stem for p in (logs / shipped_fleet.unit_name(1)).iterdir())
    for unit, t in truth.items():
        if t["axis"]:  # flagged with its axis, after 5 % and before 40 % of wear
            assert alarms[unit]["source_axis"] == str(t["axis"]), alarms[unit]
            wear = t["wear"][stamps.index(alarms[unit]["first_alarm"])]
            assert 5.0 <= wear < 40.0, (unit, wear)
        else:
            assert alarms[unit]["first_alarm"] == "", alarms[unit]
    assert np.max(truth[shipped_fleet.unit_name(2)]["wear"]) > 40.0
