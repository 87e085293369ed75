"""The shipped log formats read in blocks (issue 57 item 2): each registered adapter's block reader
(:meth:`faultgen.logs.formats.LogFormat.source`) gives its whole read's columns, row for row, and a
long log calibrated through it (:func:`faultgen.logs.longlog.read`) gives, bit for bit, what its
whole read averaged down gives, as a long measured log does (tests/test_longlog.py)."""

import numpy as np
import pandas as pd
import pytest
from test_longlog import _log as long_log

from faultgen.calibrate import decimate, search
from faultgen.logs import formats, longlog
from faultgen.model import robots
from faultgen.logs import jointlog

ROWS = 1000


@pytest.fixture(scope="module")
def robot():
    return robots.load("puma560")


def _signals(n=23_456, seed=0):
    """tests/test_longlog.py's long log, with joint speeds 1 % off the angles' gradient."""
    t, q, tau = long_log(n, seed)
    return t, q, 1.01 * np.gradient(q, t, axis=0), tau


def _ur_rtde(path, robot):
    t, q, qd, tau = _signals()
    constants = np.array([2.0, 2.5, 3.0, 1.5, 1.0, 0.5])
    columns = {"timestamp": t, **{f"actual_q_{k}": q[:, k] for k in range(6)},
               **{f"actual_qd_{k}": qd[:, k] for k in range(6)}, "robot_mode": np.full(len(t), 7),
               **{f"actual_current_{k}": tau[:, k] / constants[k] for k in range(6)},
               **{f"joint_temperatures_{k}": 30 + t / 100 for k in range(6)}}
    pd.DataFrame(columns).to_csv(path, sep=" ", index=False, float_format="%.17g")
    return path, formats.make("ur-rtde", torque_constants=tuple(constants))


def _voraus(path, robot):
    t, q, qd, tau = _signals()
    table = {"time": t, "sample": (t // 2).astype(int), "anomaly": np.zeros(len(t), bool),
             **{f"joint_position_{k + 1}": q[:, k] for k in range(6)},
             **{f"joint_velocity_{k + 1}": qd[:, k] for k in range(6)},
             **{f"motor_torque_{k + 1}": tau[:, k] / robot.gear_ratio[k] for k in range(6)}}
    pd.DataFrame(table).to_parquet(path, row_group_size=1234)  # batches cut at row groups: blocks re-cut
    return path, formats.make("voraus")


MAKERS = {"ur-rtde": (_ur_rtde, "log.csv"), "voraus": (_voraus, "log.parquet")}


@pytest.mark.parametrize("name", list(MAKERS))
def test_the_blocks_are_the_whole_read_cut(tmp_path, robot, name):
    make, file = MAKERS[name]
    path, adapter = make(tmp_path / file, robot)
    src = adapter.source(path, robot)
    columns, label, *notes = adapter.columns(path, robot)
    assert src.rows == 23_456 and src.label(5) == label(5) and src.notes == (notes[0] if notes else ())
    blocks = list(src.blocks(3000))
    assert [start for start, _ in blocks] == list(range(0, 23_456, 3000))
    assert all(len(block) == 3000 for _, block in blocks[:-1])
    np.testing.assert_array_equal(np.concatenate([b for _, b in blocks]),
                                  np.column_stack([columns[c] for c in src.wanted]))


@pytest.mark.parametrize("name", list(MAKERS))
def test_a_long_log_of_the_format_read_in_blocks_equals_its_whole_read_then_averaged(tmp_path, robot, monkeypatch,
                                                                                      name):
    monkeypatch.setattr(longlog, "BLOCK_ROWS", 3000)  # eight blocks, the last one short
    make, file = MAKERS[name]
    path, adapter = make(tmp_path / file, robot)
    full = adapter.read(path, robot)
    whole = decimate(full, ROWS)
    part, motion = longlog.read(path, robot, ROWS, search.REST_SPEED, adapter)
    assert len(part) == len(whole) == 977
    for field in ("t", "q", "qd", "qdd", "tau"):
        np.testing.assert_array_equal(getattr(part, field), getattr(whole, field), err_msg=field)
    assert part.notes[:-1] == whole.notes[:-1] and part.notes[-1].startswith("decimated: 23456 rows")
    assert part.notes[0].startswith("torque from") or name == "voraus"
    np.testing.assert_array_equal(motion.peak, np.max(np.abs(full.qd), axis=0))


@pytest.mark.parametrize("name", list(MAKERS))
def test_a_bad_cell_deep_in_a_long_log_of_the_format_is_named_as_its_whole_read_names_it(tmp_path, robot,
                                                                                        monkeypatch, name):
    monkeypatch.setattr(longlog, "BLOCK_ROWS", 3000)
    make, file = MAKERS[name]
    path, adapter = make(tmp_path / file, robot)
    if name == "ur-rtde":
        lines = path.read_text().splitlines()
        cells = lines[17_001].split(" ")
        cells[lines[0].split(" ").index("actual_q_3")] = "abc"
        lines[17_001] = " ".join(cells)
        path.write_text("\n".join(lines) + "\n")
        message = r"data row 17001 \(line 17002\), column actual_q_3: value 'abc'; expected a finite number"
    else:
        table = pd.read_parquet(path)
        table.loc[17_000, "joint_position_4"] = np.inf
        table.to_parquet(path, row_group_size=1234)
        message = r"data row 17001 \(index 17000\), column joint_position_4: value inf; expected a finite number"
    with pytest.raises(jointlog.LogError, match=message) as whole:
        adapter.read(path, robot)
    with pytest.raises(jointlog.LogError) as part:
        longlog.read(path, robot, ROWS, search.REST_SPEED, adapter)
    assert str(part.value) == str(whole.value)
