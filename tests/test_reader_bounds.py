"""Bounded work in the log readers (issue 61, item 5): a CSV header of thousands of columns, an HDF5
log declaring 10^8 rows, a voraus-AD Parquet table of more rows than a log read whole may have, an
RTDE recording read as text, an oversized ``events.csv`` and a program of 10^4 moves are refused
(or read in memory proportional to the numbers kept) before the work that made them cost gigabytes
or minutes. Each refusal is a :class:`faultgen.inputs.InputError` whose message starts with the
file and names the count and the bound; the CLI prints one ``error:`` line and exits 2.
(Figures before and after: docs/reliability.md, ``benchmarks/input_bounds.py``.)"""

import re
import subprocess
import sys
import time
import tracemalloc

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

from faultgen import inputs
from faultgen.cli import app
from faultgen.data import logfolder
from faultgen.logs import formats, longlog, measured
from faultgen.data import logfiles
from faultgen.model import robots
from faultgen.operation import programs
from faultgen.logs import jointlog

runner = CliRunner()
COLUMNS = ["t", *(f"q{i}" for i in range(1, 7)), *(f"tau{i}" for i in range(1, 7))]


def _refused_by_cli(args, message):
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output, result.output
    line = result.output.strip().splitlines()[-1]
    assert line.startswith("error: ") and result.output.count("error: ") == 1, result.output
    assert re.search(message, line), line


def _wide_log(path, extra):
    names = COLUMNS + [f"x{i}" for i in range(extra)]
    rows = [",".join([f"{k * 0.001:.3f}"] + ["0"] * (len(names) - 1)) for k in range(3)]
    path.write_text(",".join(names) + "\n" + "\n".join(rows) + "\n")
    return path


def test_a_csv_header_of_thousands_of_columns_is_refused_before_its_rows_are_parsed(tmp_path):
    log = _wide_log(tmp_path / "wide.csv", 2000)  # 32 000 took 25 s and 0.6-2.6 GB before
    start = time.perf_counter()
    with pytest.raises(inputs.InputError) as err:
        measured.read(log, robots.load("puma560"))
    assert time.perf_counter() - start < 5.0
    assert str(err.value).startswith(f"{log}: the header names 2013 columns; a joint log has at most "
                                     f"{inputs.CSV_MAX_COLUMNS}")
    assert isinstance(err.value, measured.MeasuredDataError)
    _refused_by_cli(["calibrate", "--robot", "puma560", "--measured", str(log), "--out", str(tmp_path / "out")],
                    r"wide\.csv: the header names 2013 columns; .* at most 1024")


def test_a_csv_header_line_longer_than_the_bound_is_refused(tmp_path):
    log = tmp_path / "long.csv"
    log.write_text(",".join(COLUMNS) + ",x" + "y" * inputs.CSV_HEADER_MAX_BYTES + "\n0" + ",0" * 13 + "\n")
    with pytest.raises(inputs.InputError, match=rf"^{re.escape(str(log))}: the header line is longer than "
                                                 rf"{inputs.CSV_HEADER_MAX_BYTES} bytes"):
        measured.read(log, robots.load("puma560"))


def test_a_log_with_extra_columns_reads_only_the_wanted_ones_the_same(tmp_path):
    """Plain (pyarrow) and gzip-compressed (pandas, in chunks) logs with extra text columns read the
    same numbers as the log without them; a row with one field too many is still refused by line."""
    t = np.arange(3000) * 0.002
    q = 0.1 * np.sin(np.outer(t, np.arange(1, 7)))
    tau = np.cos(np.outer(t, np.arange(1, 7)))
    plain = logfiles.write_csv(tmp_path / "plain.csv", t, q, tau)
    text = plain.read_text().splitlines()
    wide = [text[0] + ",note,x"] + [line + ",abc,1" for line in text[1:]]
    (tmp_path / "wide.csv").write_text("\n".join(wide) + "\n")
    import gzip

    with gzip.open(tmp_path / "wide.csv.gz", "wt") as fh:
        fh.write("\n".join(wide) + "\n\n\n")  # trailing blank lines: dropped, as before
    base = jointlog.read_columns(plain, 6)[0]
    for name in ("wide.csv", "wide.csv.gz"):
        columns, extra, _ = jointlog.read_columns(tmp_path / name, 6)
        assert extra == ["note", "x"]
        for column in COLUMNS:
            np.testing.assert_array_equal(columns[column], base[column])
    ragged = wide[:100] + [wide[100] + ",9"] + wide[101:]
    with gzip.open(tmp_path / "ragged.csv.gz", "wt") as fh:
        fh.write("\n".join(ragged) + "\n")
    with pytest.raises(measured.MeasuredDataError, match=r"ragged\.csv\.gz: cannot read the file as CSV: .*line 101"):
        jointlog.read_columns(tmp_path / "ragged.csv.gz", 6)
    bad = wide[:2000] + [wide[2000].replace(",abc", "").replace(text[2000].split(",")[3], "x") + ",abc"] + wide[2001:]
    with gzip.open(tmp_path / "bad.csv.gz", "wt") as fh:
        fh.write("\n".join(bad) + "\n")
    with pytest.raises(measured.MeasuredDataError, match=r"bad\.csv\.gz: data row 2000 \(line 2001\), column q3: "
                                                         r"value 'x' is not a number"):
        jointlog.read_columns(tmp_path / "bad.csv.gz", 6)


def _declared(path, rows):
    path.parent.mkdir(parents=True, exist_ok=True)
    with h5py.File(path, "w") as f:
        for name in COLUMNS:
            f.create_dataset(name, shape=(rows,), dtype="f8", chunks=(4096,))
    return path


def test_an_hdf5_log_declaring_1e8_rows_is_refused_by_memory_before_a_whole_read(tmp_path):
    log = _declared(tmp_path / "logs" / "unit1" / "1.h5", 10**8)  # 8 kB; a MemoryError before
    most = jointlog.WHOLE_MAX_BYTES // (8 * 13)
    start = time.perf_counter()
    with pytest.raises(inputs.InputError) as err:
        measured.read(log, robots.load("puma560"))
    assert time.perf_counter() - start < 5.0
    assert str(err.value).startswith(f"{log}: 100000000 rows of 13 columns; a log read whole has at most {most}")
    _refused_by_cli(["logs", "import", str(tmp_path / "logs"), "--robot", "puma560", "-o", str(tmp_path / "f.h5"),
                     "--no-progress"], rf"1\.h5: 100000000 rows of 13 columns; .* at most {most}")
    assert not (tmp_path / "f.h5").exists()


def test_calibrate_refuses_an_hdf5_log_declaring_1e8_rows_at_its_first_block(tmp_path):
    """The calibration streams a long log and keeps its times (8 bytes a row): a declared 10^8 rows
    of fill values are refused at the first block (their times repeat), not after reading them all
    (71 s and 2.7 GB before)."""
    log = _declared(tmp_path / "log.h5", 10**8)
    start = time.perf_counter()
    with pytest.raises(measured.MeasuredDataError, match=r"log\.h5: column t repeats at data row 2"):
        longlog.read(log, robots.load("puma560"), 25_000, 0.01)
    assert time.perf_counter() - start < 5.0


def test_a_voraus_table_of_more_rows_than_a_whole_read_may_have_is_refused_from_its_metadata(tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    names = ["time", *(f"{c}_{k}" for c in ("joint_position", "joint_velocity", "motor_torque") for k in range(1, 7)),
             "sample"]
    rows = 10**6
    zeros = pa.array(np.zeros(rows))
    table = pa.table({name: zeros for name in names})
    path = tmp_path / "voraus.parquet"
    groups = jointlog.whole_rows(len(names)) // rows + 1  # 4 row groups: 4x10^6 rows, 0.3 MB
    with pq.ParquetWriter(path, table.schema) as writer:
        for _ in range(groups):
            writer.write_table(table, row_group_size=rows)
    start = time.perf_counter()
    with pytest.raises(inputs.InputError) as err:
        formats.make("voraus").read(path, robots.load("puma560"))
    assert time.perf_counter() - start < 2.0
    assert str(err.value).startswith(f"{path}: {groups * rows} rows of 20 columns; a voraus-AD log read whole has at "
                                     f"most {jointlog.whole_rows(20)}")


def _rtde(path, rows, outputs=80):
    """An RTDE recording of ``rows`` rows at 500 Hz (the cells of 1000 rows repeated: fast to write)."""
    names = ["timestamp", *(f"{c}_{k}" for c in ("actual_q", "actual_qd", "target_moment", "actual_current")
                            for k in range(6))]
    names += [f"output_{i}" for i in range(outputs)]
    cells = np.char.mod("%.4f", np.random.default_rng(0).uniform(-0.5, 0.5, (min(rows, 1000), len(names) - 1)))
    tails = [" ".join(row) for row in cells.tolist()]
    body = "".join(f"{k * 0.002:.3f} {tails[k % len(tails)]}\n" for k in range(rows))
    path.write_text(" ".join(names) + "\n" + body)
    return path


#: Run in a fresh interpreter: the peak resident memory (bytes) reading argv[2] adds, argv[1] read first
#: (the modules the reader imports on first use and the allocator's arenas not counted as the log's).
_PEAK_GROWTH = """
import pathlib, sys
from faultgen.logs import formats
from faultgen.model import robots

def status(key):
    with open("/proc/self/status") as fh:
        return next(int(line.split()[1]) * 1024 for line in fh if line.startswith(key))

adapter, puma = formats.make("ur-rtde"), robots.load("puma560")
adapter.columns(pathlib.Path(sys.argv[1]), puma)
with open("/proc/self/clear_refs", "w") as fh:
    fh.write("5")  # reset VmHWM to the current resident size
before = status("VmRSS:")
adapter.columns(pathlib.Path(sys.argv[2]), puma)
print(status("VmHWM:") - before)
"""


def _peak_growth(warm, path):
    done = subprocess.run([sys.executable, "-c", _PEAK_GROWTH, str(warm), str(path)], capture_output=True,
                          text=True, check=True)
    return int(done.stdout.split()[-1])


def test_an_rtde_log_is_read_as_numbers_in_memory_proportional_to_the_numbers_kept(tmp_path):
    """Every cell read as text took 7 times the file; now only the 19 wanted columns are parsed, as
    numbers, a chunk of rows at a time. Judged by what a log 3 times longer adds to the peak resident
    memory of a fresh interpreter (a fixed 25-30 MB of parser buffers and arenas cancels out): its
    31 MB more text hold 6 MB more numbers, and must cost less than that text (was 7 times it).
    Measured 7-10 MB (90 MB with every cell read as text), 2026-11-25; an in-process figure depended on which tests had run before."""
    path = _rtde(tmp_path / "rtde.csv", 20_000)
    columns, _, _ = formats.make("ur-rtde").columns(path, robots.load("puma560"))
    assert set(columns) == {*COLUMNS, *(f"qd{i}" for i in range(1, 7))}
    np.testing.assert_array_equal(columns["t"], np.round(np.arange(20_000) * 0.002, 3))
    longer = _rtde(tmp_path / "longer.csv", 60_000)
    warm = _rtde(tmp_path / "warm.csv", 200)
    extra_text = longer.stat().st_size - path.stat().st_size
    extra_memory = _peak_growth(warm, longer) - _peak_growth(warm, path)
    assert extra_memory < extra_text, (extra_memory, extra_text)


def test_an_rtde_log_with_a_bad_cell_is_refused_by_row(tmp_path):
    path = _rtde(tmp_path / "rtde.csv", 3000, outputs=3)
    lines = path.read_text().splitlines()
    cells = lines[2500].split(" ")
    cells[1] = "oops"  # actual_q_0 of data row 2500
    lines[2500] = " ".join(cells)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(measured.MeasuredDataError, match=r"rtde\.csv: data row 2500 \(line 2501\), column "
                                                         r"actual_q_0: value 'oops'"):
        formats.make("ur-rtde").columns(path, robots.load("puma560"))


def _units():
    return {"u": [logfolder.LogFile("u", "1", 1.0, "sequence", None, "u/1.csv")]}


def test_an_events_file_above_its_bound_is_refused_before_it_is_read(tmp_path):
    events = tmp_path / "events.csv"
    header, row = b"unit,stamp,event,axis\n", b"u,1,onset,1\n"
    events.write_bytes(header + row * (logfolder.EVENTS_MAX_BYTES // len(row) + 1))  # 64 MiB took 1.9 GB
    start = time.perf_counter()
    with pytest.raises(inputs.InputError, match=rf"^{re.escape(str(events))}: {events.stat().st_size} bytes; a events "
                                                 rf"file is read up to {logfolder.EVENTS_MAX_BYTES} bytes"):
        logfolder.read_events(events, _units(), 6)
    assert time.perf_counter() - start < 2.0
    assert logfolder.EVENTS_MAX_BYTES <= 16 * 2**20


@pytest.mark.parametrize("row", [b"u,1,onset,1\n", b",,,\n"], ids=["events", "blank rows"])
def test_events_are_read_row_by_row_without_a_blow_up(tmp_path, row):
    events = tmp_path / "events.csv"
    events.write_bytes(b"unit,stamp,event,axis\n" + row * (2**18 // len(row)))
    tracemalloc.start()
    try:
        found = logfolder.read_events(events, _units(), 6)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert len(found) == (2**18 // len(row) if row.strip(b",\n") else 0)
    # was 30 (events) and 25 (blank rows) times the file
    assert peak < (16 if found else 3) * events.stat().st_size, peak / events.stat().st_size


def test_a_program_of_1e4_moves_is_refused_before_any_move_is_checked(tmp_path):
    moves = ["[[segment]]\ntype = \"move\"\nto = [" + ("10, 80, -110, 20, 10, 10" if k % 2 else "0, 92, -122, 30, 0, 0")
             + "]\n" for k in range(10_000)]
    path = tmp_path / "many.toml"
    path.write_text('name = "many"\nstart = [0, 92, -122, 30, 0, 0]\n\n' + "\n".join(moves))
    start = time.perf_counter()
    with pytest.raises(inputs.InputError) as err:  # 46 s and 1.4 GB before, refused by the cycle's duration
        programs.read(path, robots.load("puma560"))
    assert time.perf_counter() - start < 5.0
    assert str(err.value).startswith(f"{path}: 10000 [[segment]] tables; a program has at most "
                                     f"{programs.MAX_SEGMENTS}")
    assert isinstance(err.value, programs.ProgramError)
    _refused_by_cli(["simulate", "--robot", "puma560", "--task", str(path), "--cycles", "1", "--no-progress", "-o",
                     str(tmp_path / "run.h5")], r"many\.toml: 10000 \[\[segment\]\] tables; .* at most 1000")
