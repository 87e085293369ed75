"""The log reader's notes on a column reach life.csv's verdict as data, not as text (issue 84, "the
notes read back"): the reader makes a :class:`faultgen.logs.measured.ColumnNote` (its axis and kind
as fields), the monitor keeps it in the unit's record once per axis and kind
(:func:`faultgen.monitor.logs.log_notes`), the saved state and a worker's pickle carry its fields,
and the verdict of that axis, and of no other, ends with it (:func:`faultgen.monitor.life.of_unit`).
A note whose text reads like a column note is not taken. Two synthetic PUMA 560 logs
(tests/fleetlog_folder.py) and a planted record: no simulation, no monitor run."""

from __future__ import annotations

import pickle
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from faultgen.logs import measured
from faultgen.model import rating, robots
from faultgen.monitor import history, life
from faultgen.monitor import logs as fleet_logs

sys.path.insert(0, str(Path(__file__).parent))
import fleetlog_folder  # noqa: E402


@pytest.fixture(scope="module")
def puma():
    return robots.load("puma560")


def _log(path: Path, robot, speed_times: float, torque_times: float) -> Path:
    """A log whose axis-2 speed column is ``speed_times`` and its torque column ``torque_times`` the joint's."""
    fleetlog_folder.write_log(path, robot, 0, 0, np.zeros(robot.n_axes))
    frame = pd.read_csv(path)
    frame["qd2"] *= speed_times
    frame["tau2"] *= torque_times
    frame.to_csv(path, index=False)
    return path


def test_a_readers_column_note_reaches_its_axis_verdict_by_its_fields(tmp_path, puma):
    gear = puma.gear_ratio[1]
    first = measured.read(_log(tmp_path / "a.csv", puma, gear, 1.0), puma)  # axis 2's speed motor-side
    second = measured.read(_log(tmp_path / "b.csv", puma, gear, 1e3), puma)  # ... and its torque too high
    said = [n for n in first.notes if isinstance(n, measured.ColumnNote)]
    assert [(n.axis, n.kind) for n in said] == [(2, measured.MOTOR_SIDE_SPEED)], first.notes
    # a planted note of the old form "log STAMP: column qd1 ...": the regex that read notes back took it for axis 1
    kept = [history.Note("log 2026-02-28: column qd1 is motor-side: planted, not the reader's")]
    kept += fleet_logs.log_notes("2026-03-01", first.notes, kept)
    kept += fleet_logs.log_notes("2026-03-02", second.notes, kept)  # the speed's note said already: the torque's
    assert [(n.kind, n.log, n.column.axis, n.column.kind) for n in kept[1:]] == [
        (history.COLUMN, "2026-03-01", 2, measured.MOTOR_SIDE_SPEED),
        (history.COLUMN, "2026-03-02", 2, measured.TORQUE_ABOVE_LIMIT)]
    assert kept[2] == f"log 2026-03-02: {kept[2].column}" and kept[2].column in second.notes  # units.csv's text
    path = tmp_path / ".state" / "u.json"
    path.parent.mkdir()
    history.write_unit(path, history.UnitHistory("u", "none", first=("2026-02-28", ""), notes=kept), {})
    back = pickle.loads(pickle.dumps(history.read_unit(path, tmp_path, "u", {}, puma.n_axes, 6).notes))
    entries = [SimpleNamespace(stamp=f"2026-03-0{d}", load=np.ones((2, puma.n_axes)), duration=60.0) for d in (1, 2)]
    ratings = (rating.GearboxRating("strain-wave", 10.0, 2.0, 1000.0),) * puma.n_axes
    plain = life.of_unit("u", entries, [], ratings)
    rows = life.of_unit("u", entries, [], ratings, notes=back)
    assert rows[1].verdict == (
        f"{plain[1].verdict}; speeds joint side: column qd2 logged motor-side from log 2026-03-01 on, divided by "
        f"the gear ratio before its load was counted (the reader: {kept[1].column}); the reader of log 2026-03-02: "
        f"{kept[2].column}; the load counted as logged")
    assert kept[1].column.startswith("column qd2 is motor-side: ") and kept[2].column.startswith("column tau2 reaches")
    assert [r.verdict for r in rows[:1] + rows[2:]] == [r.verdict for r in plain[:1] + plain[2:]]  # axis 1 too
