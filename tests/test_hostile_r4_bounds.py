"""Hostile inputs, round 4: memory and size bounds on every reader. Each reader's memory is bounded
from the file's declared sizes before it reads; a file beyond a bound is refused with exit 2 and one
``error:`` line naming the file (and the row, column or value at fault), no traceback, under the 4 GB
address-space cap the findings were judged by (:mod:`capped`) where the finding is about memory."""

from __future__ import annotations

import csv
import os
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.monitor import page, report, tables
from faultgen.monitor.loop import UnitStatus

sys.path.insert(0, str(Path(__file__).parent))
import capped  # noqa: E402

runner = CliRunner()
#: A child's environment in which this folder's helper modules (the bench plug-ins) import.
WITH_TESTS = {"PYTHONPATH": os.pathsep.join(filter(None, (os.environ.get("PYTHONPATH"),
                                                          str(Path(__file__).parent))))}


def _refused(result, *names: str) -> str:
    """The error line of a refused in-process run: exit 2, no traceback, one ``error:`` line (the
    last: a command may say what it reads first) naming ``names``."""
    text = result.output
    assert result.exit_code == 2, text
    line = text.strip().splitlines()[-1]
    assert "Traceback" not in text and text.count("error: ") == 1 and line.startswith("error: "), text
    for name in names:
        assert str(name) in line, (name, text)
    return line


# -- the fleet report reads its tables through one bounded reader ----------------------------------

def _monitor_output(out: Path, reason: str = "", n_axes: int = 6) -> Path:
    """A small monitor output folder (one unit, three scored logs), written by the monitor's writers
    except scores.csv, whose ``n_axes`` score columns are written directly."""
    out.mkdir(parents=True, exist_ok=True)
    report.units_table([UnitStatus("weld-01", "monitored", "own", "", reason, 3, "2026-03-03")]).write(out)
    report.alarms_table([]).write(out)
    with open(out / "scores.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow([*report.SCORE_COLUMNS, *(f"score{i}" for i in range(1, n_axes + 1))])
        for day in (1, 2, 3):
            writer.writerow(["weld-01", f"2026-03-0{day}", "monitoring", 1.0, 2.0, 1.5, 3.0, 0, 1] + [0.1] * n_axes)
    return out


def test_the_report_reads_a_monitor_output_it_wrote_with_a_reason_longer_than_a_csv_field(tmp_path):
    """A unit's reason gathers a note per program change: one over 131 072 characters stopped the
    page at the end of ``monitor`` with ``_csv.Error``. The writer cuts it, saying so; the page reads it."""
    out = _monitor_output(tmp_path / "out", reason="program changed at 2026-03-01; " * 6000)
    fleet = page.read(out)
    reason = fleet.units[0].row["reason"]
    assert len(reason) <= report.CELL_MAX_CHARS and reason.endswith("more characters)"), reason[-80:]
    assert runner.invoke(app, ["report", str(out)]).exit_code == 0
    # the tables a monitor run has just written are read whatever their size (it holds their rows)
    with pytest.raises(ValueError, match=r"units\.csv: \d+ bytes; a monitor output table is read up to 200 bytes"):
        page.write(out, table_max_bytes=200)
    assert page.write(out, table_max_bytes=None).is_file()


@pytest.mark.parametrize("plant", ["long cell", "not utf-8", "too large", "eight axes"])
def test_a_planted_table_is_refused_by_the_report_naming_the_file(tmp_path, plant):
    """Every table the report reads goes through one bounded, checked reader: a cell over the CSV
    module's 131 072 characters (was ``_csv.Error``), a units.csv that is not UTF-8 (was
    ``UnicodeDecodeError``), a table over its size bound or with more
    score columns than a robot has axes (was read: 9 MB built a 299 MB page in 1.7 GB) is refused."""
    out = _monitor_output(tmp_path / "out", n_axes=8 if plant == "eight axes" else 6)
    name = "scores.csv" if plant in ("too large", "eight axes") else "units.csv"
    path = out / name
    if plant == "long cell":
        path.write_text(path.read_text() + "weld-02,monitored,own,," + "x" * 140_000 + ",3,2026-03-03\n")
    elif plant == "not utf-8":
        path.write_bytes(path.read_bytes().replace(b"weld-01", b"weld-\xff1"))
    elif plant == "too large":
        with open(path, "ab") as f:  # sparse: no time spent writing it
            f.truncate(tables.CSV_MAX_BYTES + 1)
    _refused(runner.invoke(app, ["report", str(out)]), path)


# -- a monitor's state: bounded by what a run writes -----------------------------------------------

def test_a_state_file_above_what_a_run_writes_is_refused_before_it_is_parsed(tmp_path, monkeypatch):
    """A state at the former 64 MiB bound cost 1.9 GB to parse (a file of empty lists); the bound is
    now what a run writes (:data:`~faultgen.monitor.state.STATE_MAX_BYTES`, 16 MiB: 0.44 GB at worst),
    checked on the file's size before ``json`` sees it, and no run writes a state it would refuse."""
    from faultgen.monitor import history, state

    path = tmp_path / ".state" / "weld-01.json"
    path.parent.mkdir()
    path.write_text('{"logs":[' + "[]," * (6 * 2**20) + "[]]}")  # 18 MiB
    monkeypatch.setattr(state.json, "loads", lambda text: pytest.fail("the state was parsed"))
    bound = state.STATE_MAX_BYTES
    with pytest.raises(state.StateError, match=rf"{path}: \d+ bytes; a monitor state is read up to {bound}"):
        history.read_unit(path, tmp_path, "weld-01", {}, 6, 18)
    big = history.UnitHistory("weld-01", notes=[history.Note("x" * state.STATE_MAX_BYTES)])
    with pytest.raises(state.StateError, match=r"weld-01\.json: the state of weld-01 would be \d+ bytes"):
        history.write_unit(tmp_path / ".state" / "weld-01.json", big, {})
    assert path.stat().st_size > state.STATE_MAX_BYTES  # the file there was left as it was


# -- planning: a cycle longer than MAX_CYCLE_DURATION refused before it is sampled -----------------

SLOW_PROGRAM = """name = "slow"
start = [0, 20, 15, 0, 80, 0]
[limits]
velocity = [0.05, 0.05, 0.05, 0.05, 0.05, 0.05]
acceleration = [100, 100, 100, 100, 100, 100]
jerk = [1000, 1000, 1000, 1000, 1000, 1000]
[[segment]]
type = "move"
to = [-10, 20, 15, 0, 80, 0]
[[segment]]
type = "move"
to = [169, 20, 15, 0, 80, 0]
"""


def test_moves_adding_up_past_an_hour_are_refused_before_the_move_is_sampled(tmp_path):
    """Each move was checked on its own duration: at the documented minimum velocity (0.05 deg/s) a
    move of 200 s and one of 3580 s sampled the second (a list of ruckig's samples: 3.8 GB, then
    ``MemoryError`` under the cap, 44 s). The cycle so far and the move's planned duration are now
    checked together before it is sampled (0.3 GB, 3 s)."""
    program = tmp_path / "slow.toml"
    program.write_text(SLOW_PROGRAM)
    done = capped.run("simulate", "--robot", "irb6700", "--task", program, "--cycles", "1", "--no-progress",
                      "-o", tmp_path / "run.h5", cwd=tmp_path)
    text = capped.one_line_refusal(done, program, "segment 2 (move)", "the cycle would last 3780.03 s",
                                   "MAX_CYCLE_DURATION")
    assert len(text.strip().splitlines()) == 1, text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["slow.toml"]


# -- bench score: a benchmark file's arrays bounded in bytes from their declared shapes --------------

def test_a_small_test_file_declaring_gigabytes_in_unwritten_chunks_is_refused_before_any_read(tmp_path):
    """A test.h5 of some kB within every former bound (10^7 records, below 2^30 elements) declaring
    cycles, four features and the angle histogram in chunks never written: 7.8 GB asked for on read
    (``MemoryError`` under the cap). The declared bytes of all units are now bounded
    (:data:`faultgen.bench.files.MAX_BYTES`, 512 MiB as float64) before any array is read."""
    import h5py
    from test_bench_hostile import AXES, _folder

    from faultgen.bench import files

    folder, n = _folder(tmp_path), 10**7
    with h5py.File(folder / "test.h5", "r+") as f:
        group = f["units/test-000"]
        for name in list(group):
            del group[name]
        group.create_dataset("cycles", shape=(n,), chunks=(2**16,), dtype="i8")
        for name in files.FEATURES:
            group.create_dataset(name, shape=(n, AXES), chunks=(2**14, AXES), dtype="f8")
        group.create_dataset("angle_hist", shape=(n, AXES, 12), chunks=(2**10, AXES, 12), dtype="f8")
    assert (folder / "test.h5").stat().st_size < 2**20
    done = capped.run("bench", "score", "thesis", "--data", folder, "--isolator", "bench_plugins:AlwaysBacklash",
                      "-o", tmp_path / "out", cwd=tmp_path, env=WITH_TESTS)
    capped.one_line_refusal(done, folder / "test.h5", "unit 'test-000'", f"more than {files.MAX_BYTES} bytes")
    assert not list(tmp_path.glob("out*"))


# -- voraus Parquet and HDF5 logs: one bounded reader for every command ----------------------------

VORAUS = ["time", *(f"{c}_{k}" for c in ("joint_position", "joint_velocity", "motor_torque") for k in range(1, 7)),
          "sample"]


def _voraus_rows(path: Path, rows: int) -> Path:
    """A voraus-AD Parquet table of ``rows`` rows (times in ms, everything else zero), written a
    million rows a row group: a few MB."""
    import numpy as np
    import pyarrow as pa
    import pyarrow.parquet as pq

    chunk = 10**6
    zeros = pa.array(np.zeros(chunk))
    with pq.ParquetWriter(path, pa.schema([(name, pa.float64()) for name in VORAUS])) as writer:
        for start in range(0, rows, chunk):
            n = min(chunk, rows - start)
            columns = {name: zeros.slice(0, n) for name in VORAUS}
            columns["time"] = pa.array(np.arange(start, start + n) * 1e-3)
            writer.write_table(pa.table(columns), row_group_size=chunk)
    return path


def test_calibrate_refuses_a_voraus_table_above_the_whole_read_bound_from_its_metadata(tmp_path):
    """``logs import`` refused a voraus table of more rows than a log read whole may have from the
    Parquet metadata; ``calibrate`` streamed it (pyarrow decodes a row group whole: a 14.5 MB file
    took 3.6 GB). Every path that reads a voraus log now checks it in one place."""
    from faultgen.logs import jointlog

    most = jointlog.whole_rows(len(VORAUS))
    log = _voraus_rows(tmp_path / "long.parquet", most + 1)
    done = capped.run("calibrate", "--robot", "puma560", "--measured", log, "--format", "voraus",
                      "-o", tmp_path / "cal", cwd=tmp_path)
    capped.one_line_refusal(done, f"{log}: {most + 1} rows of 20 columns", f"at most {most}", "WHOLE_MAX_BYTES")
    assert not (tmp_path / "cal").exists()


@pytest.mark.parametrize("command", ["calibrate", "import"])
def test_a_truncated_voraus_table_is_refused_naming_the_file(tmp_path, command):
    """A voraus Parquet cut short (no footer): pyarrow's error named no file."""
    folder = tmp_path / "logs" / "u1"
    folder.mkdir(parents=True)
    log = _voraus_rows(folder / "2026-03-01.parquet", 1000)
    log.write_bytes(log.read_bytes()[: log.stat().st_size // 2])
    args = (["calibrate", "--robot", "puma560", "--measured", str(log), "-o", str(tmp_path / "cal")]
            if command == "calibrate" else
            ["logs", "import", str(tmp_path / "logs"), "--robot", "puma560", "-o", str(tmp_path / "f.h5"),
             "--no-progress"])
    line = _refused(runner.invoke(app, [*args, "--format", "voraus"]), log, "not a readable Parquet file")
    assert "voraus-AD" in line
    assert not (tmp_path / "cal").exists() and not (tmp_path / "f.h5").exists()


def test_an_hdf5_log_whose_time_is_text_is_refused_naming_the_file_by_calibrate(tmp_path):
    """The calibration's block reader (a log longer than calibrate.MAX_ROWS) converted the datasets to
    float as it read them: a ``t`` of text gave ``could not convert string to float`` without the
    file's name (and text that reads as numbers was taken). Its datasets are now
    checked from their metadata as the whole read's are (one function)."""
    import h5py
    import numpy as np

    log = tmp_path / "log.h5"
    columns = ["t", *(f"q{i}" for i in range(1, 7)), *(f"tau{i}" for i in range(1, 7))]
    rows = 30_000  # above calibrate.MAX_ROWS: the log is streamed in blocks
    with h5py.File(log, "w") as f:
        for name in columns[1:]:
            f[name] = np.zeros(rows)
        f["t"] = np.array([f"t={k}ms" for k in range(rows)], dtype="S10")
    args = ["calibrate", "--robot", "puma560", "--measured", str(log), "-o", str(tmp_path / "cal")]
    _refused(runner.invoke(app, args), log, "dataset t has dtype |S10; expected numbers")
    assert not (tmp_path / "cal").exists()


# -- holding a log's bytes reserves what the file holds, not the bound -----------------------------

_ADDRESS_SPACE_GROWTH = """
import sys
from faultgen import inputs

def peak():
    with open("/proc/self/status") as fh:
        return next(int(line.split()[1]) * 1024 for line in fh if line.startswith("VmPeak"))

before = peak()
held = inputs.hold(sys.argv[1], "joint log", int(sys.argv[2]))
assert held.data.startswith(b"t,q1"), held.data[:20]
print(peak() - before)
"""


def test_holding_a_small_log_reserves_its_size_not_the_bound(tmp_path):
    """Every log the monitor reads is held once (``inputs.hold``, bounded at
    :data:`faultgen.monitor.logs.HOLD_MAX_BYTES`, 512 MiB); ``read(bound + 1)`` allocated the bound
    before the file was read, so each read of a 0.1 MB log reserved 512 MiB of address space (an
    8-unit run 4.9 GB: ``MemoryError`` under a 4 GB cap). The peak address space a read adds is now
    about the file's size."""
    import subprocess

    from faultgen import children
    from faultgen.monitor import logs

    log = tmp_path / "2026-03-01.csv"
    log.write_text("t,q1\n" + "0.001,0.5\n" * 10_000)
    done = subprocess.run(children.command("-c", _ADDRESS_SPACE_GROWTH, str(log), str(logs.HOLD_MAX_BYTES)),
                          env=children.environment(), capture_output=True, text=True, timeout=120, check=True)
    assert int(done.stdout) < 16 * 2**20, done.stdout  # was 512 MiB


def test_a_linear_segment_past_an_hour_is_refused_before_its_path_is_solved(monkeypatch):
    """A Cartesian segment's duration (its length over its speed) is known before any knot is
    solved: 0.5 m at 0.1 mm/s was solved and sampled first (42 s, 0.57 GB) and then refused."""
    from test_programs import line_segments

    from faultgen.model import robots
    from faultgen.operation import planner, programs
    from faultgen.operation.tasks import ProgramError

    text = SLOW_PROGRAM.split("[limits]")[0] + """[tool]
z = [-0.5, 0.0, -0.866]
x = [-1.0, 0.0, 0.0]
""" + line_segments(0.0001, 0.1)
    monkeypatch.setattr(planner.FlangeIK, "follow", lambda *a, **k: pytest.fail("the path was solved"))
    with pytest.raises(ProgramError, match=r"segment 2 \(linear\): the cycle would last 5000\.77 s; a cycle lasts at "
                                           r"most 3600 s \(MAX_CYCLE_DURATION\)"):
        programs.parse(text, robots.load("irb6700")).trajectory(0.004)


def test_a_unit_of_many_logs_and_closed_alarms_is_charted_in_linear_time():
    """Within the tables' bounds, a planted alarms.csv can close an alarm at every log of a unit: each
    closed alarm's log was looked up in a list of the unit's stamps (rows x alarms: 40 000 of each,
    11 s, a 32 MiB pair of tables hours). One look-up table per chart (0.5 s)."""
    import time

    rows = [{"unit": "u", "stamp": f"2026-{k:06d}", "phase": "monitoring", "Q": "1", "Q_limit": "2", "T2": "1",
             "T2_limit": "2", "score1": "0.1"} for k in range(40_000)]
    closed = [{"first_alarm": r["stamp"], "source_axis": "1", "closed_by": "repair", "closed": r["stamp"]}
              for r in rows]
    unit = page.Unit({"unit": "u", "status": "monitored", "last_log": rows[-1]["stamp"]}, scores=tables.log_rows(rows), closed=closed)
    start = time.perf_counter()
    chart = page.figure(unit, {})
    assert time.perf_counter() - start < 5.0
    assert len(chart["layout"]["shapes"]) == len(closed)
    assert chart["layout"]["shapes"][-1]["x0"] == len(rows) - 1
