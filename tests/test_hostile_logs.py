"""Hostile logs, programs and tables (issue 50, items 2, 4 and 5): `calibrate --measured` and a
replayed log (`simulate --task LOG`) refuse HDF5 links and virtual datasets to other files, a log
whose `t` is a group, a header-only log, a gzip bomb and a declared length of 10^10; a program
asking for a 10^9 s dwell and a device given as a TOML table are refused before anything is
allocated. Each: exit 2, one line naming the file and the item, nothing written."""

import gzip
import re
import time

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

from faultgen.cli import app

runner = CliRunner()
COLUMNS = ["t", *(f"q{i}" for i in range(1, 7)), *(f"tau{i}" for i in range(1, 7))]


def _refused(result, message, folder, kept):
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output, result.output
    line = result.output.strip().splitlines()[-1]  # calibrate says "reading FILE" first
    assert line.startswith("error: ") and result.output.count("error: ") == 1, result.output
    assert re.search(message, line), line
    assert sorted(p.name for p in folder.iterdir()) == sorted(kept)  # nothing written


def _log_h5(path, build=None, rows=3000):
    t = np.arange(rows) * 0.004
    with h5py.File(path, "w") as f:
        for name in COLUMNS:
            f[name] = t if name == "t" else np.zeros(rows)
        if build is not None:
            build(f)
    return path


def _external_t(f):
    del f["t"]
    f["t"] = h5py.ExternalLink("elsewhere.h5", "/t")


def _virtual_q1(f):
    del f["q1"]
    layout = h5py.VirtualLayout(shape=(3000,), dtype="f8")
    layout[:] = h5py.VirtualSource("elsewhere.h5", "q1", shape=(3000,))
    f.create_virtual_dataset("q1", layout)


def _group_t(f):
    del f["t"]
    f.create_group("t")


def _declared_1e10(f):
    for name in COLUMNS:
        del f[name]
        f.create_dataset(name, shape=(10**10,), dtype="f8", chunks=(4096,))


HDF5_LOGS = {
    "external link": (_external_t, r"log\.h5: /t is an external link to elsewhere\.h5:/t"),
    "virtual dataset": (_virtual_q1, r"log\.h5: /q1 is a virtual dataset reading elsewhere\.h5"),
    "t is a group": (_group_t, r"log\.h5: .*\bt\b.*group"),
    "declared 1e10 rows": (_declared_1e10, r"log\.h5: .*10000000000"),
}


@pytest.fixture(params=sorted(HDF5_LOGS))
def hostile_log(request, tmp_path):
    build, message = HDF5_LOGS[request.param]
    _log_h5(tmp_path / "elsewhere.h5")
    return _log_h5(tmp_path / "log.h5", build), message


def test_calibrate_refuses_a_hostile_hdf5_log(hostile_log):
    log, message = hostile_log
    result = runner.invoke(app, ["calibrate", "--robot", "puma560", "--measured", str(log), "--out",
                                 str(log.parent / "out")])
    _refused(result, message, log.parent, ["elsewhere.h5", "log.h5"])


def test_a_replay_refuses_a_hostile_hdf5_log(hostile_log):
    log, message = hostile_log
    result = runner.invoke(app, ["simulate", "--robot", "puma560", "--task", str(log), "--cycles", "1",
                                 "--no-progress", "-o", str(log.parent / "run.h5")])
    _refused(result, message, log.parent, ["elsewhere.h5", "log.h5"])


@pytest.mark.parametrize("command", ["calibrate", "simulate"])
def test_a_header_only_log_is_refused_by_name(tmp_path, command):
    log = tmp_path / "header.csv"
    log.write_text(",".join(COLUMNS) + "\n")
    args = (["calibrate", "--robot", "puma560", "--measured", str(log), "--out", str(tmp_path / "out")]
            if command == "calibrate" else
            ["simulate", "--robot", "puma560", "--task", str(log), "--cycles", "1", "--no-progress", "-o",
             str(tmp_path / "run.h5")])
    _refused(runner.invoke(app, args), r"header\.csv: .*(0 data row|no data rows)", tmp_path, ["header.csv"])


@pytest.mark.parametrize("command", ["calibrate", "simulate"])
def test_a_gzip_bomb_log_is_refused_within_seconds(tmp_path, command):
    log = tmp_path / "bomb.csv.gz"
    with gzip.open(log, "wb", compresslevel=9) as g:
        g.write((",".join(COLUMNS) + "\n").encode())
        for _ in range(40):
            g.write(b"0,0,0,0,0,0,0,0,0,0,0,0,0\n" * 1_000_000)  # 1 GB inflated, 1 MB compressed
    args = (["calibrate", "--robot", "puma560", "--measured", str(log), "--out", str(tmp_path / "out")]
            if command == "calibrate" else
            ["simulate", "--robot", "puma560", "--task", str(log), "--cycles", "1", "--no-progress", "-o",
             str(tmp_path / "run.h5")])
    start = time.perf_counter()
    result = runner.invoke(app, args)
    assert time.perf_counter() - start < 5.0
    _refused(result, r"bomb\.csv\.gz: inflates more than 100 times its compressed size", tmp_path, ["bomb.csv.gz"])


def test_a_billion_second_dwell_is_refused_before_it_is_sampled(tmp_path):
    program = tmp_path / "p.toml"
    program.write_text('name = "long"\nstart = [0, 20, 15, 0, 80, 0]\n[[segment]]\ntype = "dwell"\ntime = 1e9\n')
    start = time.perf_counter()
    result = runner.invoke(app, ["simulate", "--robot", "irb6700", "--task", str(program), "--cycles", "1",
                                 "--no-progress", "-o", str(tmp_path / "run.h5")])
    assert time.perf_counter() - start < 5.0
    _refused(result, r"p\.toml \(long\), segment 1 \(dwell\): the cycle would last 1e\+09 s; a cycle lasts at most "
             r"3600 s \(MAX_CYCLE_DURATION\)", tmp_path, ["p.toml"])


def test_dwells_adding_up_past_an_hour_are_refused_at_the_segment_that_crosses_it(tmp_path):
    program = tmp_path / "p.toml"
    program.write_text('name = "long"\nstart = [0, 20, 15, 0, 80, 0]\n'
                       + '[[segment]]\ntype = "dwell"\ntime = 1000.0\n' * 4)
    result = runner.invoke(app, ["simulate", "--robot", "irb6700", "--task", str(program), "--cycles", "1",
                                 "--no-progress", "-o", str(tmp_path / "run.h5")])
    _refused(result, r"segment 4 \(dwell\): the cycle would last 4000 s", tmp_path, ["p.toml"])


def test_a_device_as_a_drivetrain_table_is_not_a_regular_file(tmp_path):
    from faultgen.model import drivetrain

    (tmp_path / "drives.toml").symlink_to("/dev/zero")
    with pytest.raises(drivetrain.DrivetrainError,
                       match=r"drives\.toml: not a regular file \(a symlink to /dev/zero, a character device\)"):
        drivetrain.read(tmp_path / "drives.toml", 6)
