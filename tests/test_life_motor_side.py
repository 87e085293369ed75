"""Motor-side speed columns and the life consumed by load (issue 90, item 4): a log whose ``qd``
columns are the motors' speeds (the joint's times the gear ratio G, a controller's motor-side
export) is read at the joint side, divided by G with a note; its unit's life.csv consumes what the
same logs at the joint side consume (before: G times as much, silently), its verdict says the
columns were converted, and the reader's note reaches units.csv once per column. A small synthetic
PUMA 560 fleet (tests/fleetlog_folder.py), protocol own."""

from __future__ import annotations

import csv
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.logs import measured
from faultgen.model import robots

sys.path.insert(0, str(Path(__file__).parent))
import fleetlog_folder  # noqa: E402

runner = CliRunner()


@pytest.fixture(scope="module")
def puma():
    return robots.load("puma560")


def _motor_side(src: Path, dst: Path, robot, axes=None) -> Path:
    """The log ``src`` with the ``qd`` columns of ``axes`` (1-based; all by default) times the gear ratio."""
    frame = pd.read_csv(src)
    for k in axes or range(1, robot.n_axes + 1):
        frame[f"qd{k}"] *= robot.gear_ratio[k - 1]
    dst.parent.mkdir(parents=True, exist_ok=True)
    frame.to_csv(dst, index=False)
    return dst


def test_the_reader_divides_a_motor_side_speed_column_by_the_gear_ratio_and_says_so(tmp_path, puma):
    joint = fleetlog_folder.write_log(tmp_path / "joint.csv", puma, 0, 0, np.zeros(6))
    motor = _motor_side(joint, tmp_path / "motor.csv", puma, axes=(1, 3))
    a, b = measured.read(joint, puma), measured.read(motor, puma)
    np.testing.assert_allclose(b.qd, a.qd, rtol=1e-12, atol=1e-12)
    assert measured.motor_side_speeds(b.notes) == (1, 3) and measured.motor_side_speeds(a.notes) == ()
    note = next(n for n in b.notes if n.startswith("column qd1 "))
    assert note.startswith("column qd1 is motor-side: 62.6") and "axis 1's gear ratio 62.61" in note, note
    # before: PUMA's axis 1 (G = 62.6, within 40..80) was refused as deg/s; deg/s is still refused
    frame = pd.read_csv(joint)
    frame["qd4"] = np.rad2deg(frame["qd4"])
    frame.to_csv(tmp_path / "deg.csv", index=False)
    deg_per_s = r"column qd4 looks like deg/s \(it is 57\.\d+ times"
    with pytest.raises(measured.MeasuredDataError, match=deg_per_s):
        measured.read(tmp_path / "deg.csv", puma)


def test_a_ratio_that_is_deg_per_s_and_a_gear_ratio_alike_is_refused_and_a_slow_axis_not_judged():
    ratio = np.array([57.0, 57.0, 100.0])
    power, cross = np.array([1.0, 1.0, 1e-9]), np.array([57.3, 1.0, 100e-9])
    both = (r"x\.csv: column qd1 is 57\.3 times the derivative of q1: deg/s or the motor's speed "
            r"\(axis 1's gear ratio 57\)")
    with pytest.raises(measured.MeasuredDataError, match=both):
        measured.velocity_verdicts(Path("x.csv"), power, cross, 1, ratio)
    power[0], cross[0] = 1.0, 1.0
    assert measured.velocity_verdicts(Path("x.csv"), power, cross, 1, ratio) == []  # axis 3 too slow to judge
    np.testing.assert_array_equal(measured.speed_sides(power, cross * [1, 57, 1], 1, ratio), [1.0, 57.0, 1.0])


def _rows(path: Path) -> dict[str, list[dict]]:
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {unit: [r for r in rows if r["unit"] == unit] for unit in {r["unit"] for r in rows}}


def test_a_fleet_logged_motor_side_consumes_what_the_joint_side_fleet_does_and_says_so(tmp_path, puma):
    logs = fleetlog_folder.write_fleet(tmp_path / "LOGS", puma, units=1, days=4)
    for log in sorted((logs / "u1").iterdir()):
        _motor_side(log, logs / "m1" / log.name, puma)
    out = tmp_path / "out"
    result = runner.invoke(app, ["monitor", str(logs), "--robot", "puma560", "-o", str(out),
                                 "--protocol", "own", "--train", "10", "--persistence", "2"])
    assert result.exit_code == 0, result.output
    life = _rows(out / "life.csv")
    assert [r["axis"] for r in life["m1"]] == [str(k) for k in range(1, 7)]
    for joint, motor in zip(life["u1"], life["m1"]):
        assert float(joint["consumed_pct"]) > 0
        for column in ("consumed_pct", "duty_pct_per_day"):
            same = pytest.approx(float(joint[column]), rel=1e-6)
            assert float(motor[column]) == same, (column, joint["axis"])
        k = motor["axis"]
        said = (f"speeds joint side: column qd{k} logged motor-side from log 2026-03-01 on, divided by the "
                f"gear ratio before its load was counted (the reader: column qd{k} is motor-side: ")
        assert said in motor["verdict"], motor["verdict"]
        assert "motor-side" not in joint["verdict"] and "the reader" not in joint["verdict"]
    units = _rows(out / "units.csv")
    reason = units["m1"][0]["reason"]
    for k in range(1, 7):  # the reader's note reaches units.csv, once per column over the unit's 4 logs
        assert reason.count(f"column qd{k} is motor-side") == 1, reason
    assert "log 2026-03-01: column qd1 is motor-side: 62.6" in reason
    assert "motor-side" not in units["u1"][0]["reason"]


def test_a_long_log_read_in_blocks_converts_as_the_whole_reader_does(tmp_path, puma):
    from faultgen.logs import longlog

    joint = fleetlog_folder.write_log(tmp_path / "joint.csv", puma, 1, 2, np.zeros(6))
    motor = _motor_side(joint, tmp_path / "motor.csv", puma, axes=(2,))
    (a, moved_a), (b, moved_b) = (longlog.read(p, puma, 100, 0.01) for p in (joint, motor))
    assert len(b.t) <= 100 < len(pd.read_csv(joint))  # averaged down: the block reader's path
    np.testing.assert_allclose(b.qd, a.qd, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(moved_b.peak, moved_a.peak, rtol=1e-12)
    assert measured.motor_side_speeds(b.notes) == (2,) and measured.motor_side_speeds(a.notes) == ()
