"""faultgen.logs.longlog: a long measured log read in blocks and averaged down while it is read
(issue 50 item 4) gives, bit for bit, what reading it whole and averaging it after gives, and
refuses a bad cell or angle anywhere in it with the whole-log reader's own message."""

import numpy as np
import pytest

from faultgen.calibrate import decimate, search
from faultgen.logs import longlog, measured
from faultgen.data import logfiles
from faultgen.model import robots

ROWS = 1000


@pytest.fixture(scope="module")
def robot():
    return robots.load("puma560")


def _log(n=23_456, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 1e-3
    q = 0.3 * np.sin(2 * np.pi * 0.5 * t[:, None] + np.arange(6))
    tau = 5 * np.cos(2 * np.pi * 0.5 * t[:, None]) + rng.normal(0, 0.1, (n, 6))
    return t, q, tau


@pytest.mark.parametrize("name", ["log.csv", "log.csv.gz", "log.h5", "qd.csv", "qd.h5"])
def test_read_in_blocks_equals_read_whole_then_averaged(tmp_path, robot, monkeypatch, name):
    monkeypatch.setattr(longlog, "BLOCK_ROWS", 3000)  # eight blocks, the last one short
    t, q, tau = _log()
    qd = 1.01 * np.gradient(q, t, axis=0) if name.startswith("qd") else None
    path = tmp_path / name
    (logfiles.write_hdf5 if name.endswith(".h5") else logfiles.write_csv)(path, t, q, tau, qd)
    full = measured.read(path, robot)
    whole = decimate(full, ROWS)
    part, motion = longlog.read(path, robot, ROWS, search.REST_SPEED)
    assert len(part) == len(whole) == 977
    for field in ("t", "q", "qd", "qdd", "tau"):
        np.testing.assert_array_equal(getattr(part, field), getattr(whole, field), err_msg=field)
    assert part.notes[:-1] == whole.notes[:-1] and part.notes[-1].startswith("decimated: 23456 rows")
    np.testing.assert_array_equal(motion.moving, np.sum(np.abs(full.qd) >= search.REST_SPEED, axis=0))
    np.testing.assert_array_equal(motion.peak, np.max(np.abs(full.qd), axis=0))
    assert motion.rows == len(full)


def test_a_short_log_is_read_whole(tmp_path, robot):
    t, q, tau = _log(n=2500)
    path = logfiles.write_csv(tmp_path / "short.csv", t, q, tau)
    data, motion = longlog.read(path, robot, 3000, search.REST_SPEED)
    np.testing.assert_array_equal(data.qdd, measured.read(path, robot).qdd)
    assert motion.rows == 2500 and not any("decimated" in note for note in data.notes)


@pytest.mark.parametrize(("row", "column", "cell", "message"), [
    (17_000, 4, "abc", r"data row 17001 \(line 17002\), column q4: value 'abc' is not a number"),
    (9_999, 9, "nan", r"data row 10000 \(line 10001\), column tau3: value 'nan' \(NaN\); expected a number"),
    (20_500, 1, "3.5", r"column q1 at data row 20501 \(line 20502\) is 3\.5 rad, outside the joint range"),
])
def test_a_bad_cell_deep_in_a_long_log_is_named_as_the_whole_reader_names_it(tmp_path, robot, monkeypatch, row,
                                                                               column, cell, message):
    monkeypatch.setattr(longlog, "BLOCK_ROWS", 3000)
    t, q, tau = _log()
    path = logfiles.write_csv(tmp_path / "bad.csv", t, q, tau)
    lines = path.read_text().splitlines()
    cells = lines[row + 1].split(",")
    cells[column] = cell
    lines[row + 1] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(measured.MeasuredDataError, match=message) as whole:
        measured.read(path, robot)
    with pytest.raises(measured.MeasuredDataError) as part:
        longlog.read(path, robot, ROWS, search.REST_SPEED)
    assert str(part.value) == str(whole.value)
