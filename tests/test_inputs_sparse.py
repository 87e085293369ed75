"""A file's apparent size is no promise (issue 86, items 1, 2, 3, 6 and 12): a sparse file made by
``truncate`` (terabytes apparent, nothing on disk) is refused on its size before anything reads,
hashes or copies it, and every file faultgen reads goes through :mod:`faultgen.inputs`.

Each test measures what the process read and wrote (``/proc/self/io``: ``rchar`` and ``wchar``
count every byte through read and write calls, a hole's zeros included), so none of them reads an
apparent size to pass: a reader that hashed or copied the file first reads (and wrote) its whole
length. Where the fault would read the whole file on the code before the fix, the size bound is
lowered (``monkeypatch``) and the file made just above it, so the test stays short either way; the
real bound is checked on a file of 1 TiB apparent where nothing could read it. Refusals that read a
file whole into memory on the old code run with the address space capped (:func:`address_space`),
so that the old code's read fails at once with a MemoryError.
"""

from __future__ import annotations

import contextlib
import os
import resource
import shutil
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from faultgen import inputs
from faultgen.cli import app
from faultgen.logs import columns, formats
from faultgen.model import robots

sys.path.insert(0, str(Path(__file__).parent))
import fleetlog_folder  # noqa: E402

runner = CliRunner()
TIB = 2**40
MIB = 2**20


def io_bytes() -> tuple[int, int]:
    """Bytes this process has read and written so far (``/proc/self/io``: rchar, wchar)."""
    fields = dict(line.split(": ") for line in Path("/proc/self/io").read_text().splitlines())
    return int(fields["rchar"]), int(fields["wchar"])


def sparse(path: Path, size: int, head: bytes = b"") -> Path:
    """``path`` of ``size`` bytes apparent: ``head``, then a hole (nothing on disk)."""
    path.write_bytes(head)
    os.truncate(path, size)
    return path


@pytest.fixture
def logs(tmp_path, puma):
    return fleetlog_folder.write_fleet(tmp_path / "LOGS", puma, units=1, days=3)


def header_of(logs: Path) -> bytes:
    return (logs / "u1" / "2026-03-01.csv").read_bytes().split(b"\n", 1)[0] + b"\n"


# -- faultgen.inputs ------------------------------------------------------------------------------


def test_a_bounded_hash_refuses_a_sparse_terabyte_on_its_size_without_reading_it(tmp_path):
    big = sparse(tmp_path / "big.csv", TIB)
    before = io_bytes()
    with pytest.raises(inputs.InputError, match=rf"big\.csv: {TIB} bytes; a log is read up to {columns.LOG_MAX_BYTES}"):
        inputs.sha256_of(big, "log", columns.LOG_MAX_BYTES)
    assert io_bytes()[0] - before[0] < MIB
    small = tmp_path / "small.csv"
    small.write_bytes(b"t,q1\n0,1\n")
    import hashlib

    assert inputs.sha256_of(small, "log", 100) == hashlib.sha256(b"t,q1\n0,1\n").hexdigest()
    with pytest.raises(inputs.InputError, match="9 bytes; a log is read up to 8 bytes"):
        inputs.sha256_of(small, "log", 8)


def test_a_line_longer_than_the_row_bound_is_refused_as_the_lines_are_counted(tmp_path):
    """A hole after a header reads as one line of zeros: refused at the first block (4 MiB), named."""
    log = sparse(tmp_path / "log.csv", 64 * MIB, b"t,q1\n0,1\n")
    before = io_bytes()
    with pytest.raises(inputs.InputError, match=rf"log\.csv: line 3 is longer than {inputs.CSV_ROW_MAX_BYTES} bytes"):
        inputs.count_lines(log, "joint log", inputs.CSV_ROW_MAX_BYTES)
    assert io_bytes()[0] - before[0] <= 5 * MIB
    assert inputs.count_lines(log, "joint log") == 3  # without the bound: counted, as before
    lines = tmp_path / "lines.csv"
    lines.write_bytes(b"ab\n" + b"x" * 10 + b"\nabc")
    assert inputs.count_lines(lines, "t", 10) == 3
    with pytest.raises(inputs.InputError, match="line 2 is longer than 9 bytes"):
        inputs.count_lines(lines, "t", 9)


# -- item 1: logs import --------------------------------------------------------------------------


def test_the_import_refuses_a_sparse_log_above_the_bound_before_any_copy(logs, tmp_path, puma, monkeypatch):
    """The bound lowered to 1 MiB, a log of 64 MiB apparent: refused by its size, named, with nothing
    written to TMPDIR and next to nothing read (the import copied it whole into TMPDIR first)."""
    monkeypatch.setattr(columns, "LOG_MAX_BYTES", MIB, raising=False)
    from faultgen.data import fleetlogs

    bad = sparse(logs / "u1" / "2026-03-04.csv", 64 * MIB)
    before = io_bytes()
    summary = fleetlogs.import_logs(logs, tmp_path / "f.h5", robot=puma, skip_bad=True, progress=False)
    read, written = (after - was for after, was in zip(io_bytes(), before))
    assert summary.skipped == [("u1/2026-03-04.csv", f"{64 * MIB} bytes; a log is read up to {MIB} bytes")]
    assert len(summary.imported) == 3 and bad.stat().st_blocks == 0
    assert read < 8 * MIB and written < 4 * MIB, (read, written)


def test_the_import_writes_nothing_to_measure_a_sparse_log_within_the_bound(logs, tmp_path, puma, monkeypatch):
    """A header, then a hole of 16 MiB (the real bound, 4 GiB, above it): held in memory, never
    copied into TMPDIR, and its hole refused as a row too long, before pandas parses it."""
    from faultgen.data import fleetlogs

    folder = tmp_path / "tmpdir"
    folder.mkdir()
    monkeypatch.setenv("TMPDIR", str(folder))
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", str(folder))
    sparse(logs / "u1" / "2026-03-04.csv", 16 * MIB, header_of(logs))
    before = io_bytes()
    summary = fleetlogs.import_logs(logs, tmp_path / "f.h5", robot=puma, skip_bad=True, progress=False)
    written = io_bytes()[1] - before[1]
    [(name, reason)] = summary.skipped
    assert name == "u1/2026-03-04.csv" and reason.startswith("line 2 is longer than 65536 bytes"), reason
    assert written < 4 * MIB and not any(folder.iterdir()), written


def test_a_log_imported_before_and_now_above_the_bound_is_named_as_changed_unread(logs, tmp_path, puma, monkeypatch):
    from faultgen.data import fleetlogs

    out = tmp_path / "f.h5"
    fleetlogs.import_logs(logs, out, robot=puma, progress=False)
    monkeypatch.setattr(columns, "LOG_MAX_BYTES", MIB, raising=False)
    victim = sparse(logs / "u1" / "2026-03-02.csv", 64 * MIB)
    before = io_bytes()
    with pytest.raises(ValueError, match=rf"{victim} changed since it was imported .*now {64 * MIB} bytes; a log is "
                                         rf"read up to {MIB} bytes"):
        fleetlogs.import_logs(logs, out, robot=puma, progress=False)
    assert io_bytes()[0] - before[0] < 8 * MIB


# -- item 2: the monitor's hashes -----------------------------------------------------------------


def test_the_monitor_refuses_a_sparse_log_on_its_size_before_hashing_it(tmp_path, puma, monkeypatch):
    from faultgen.monitor import logs as fleet_logs
    from faultgen.monitor import loop

    monkeypatch.setattr(columns, "LOG_MAX_BYTES", MIB, raising=False)
    log = sparse(tmp_path / "2026-01-20.csv", 64 * MIB)
    before = io_bytes()
    parsed = fleet_logs.parse(log, puma, formats.MEASURED.read)
    assert parsed.data is None and parsed.sha256 == ""
    assert str(parsed.error) == f"{log}: {64 * MIB} bytes; a joint log is read up to {MIB} bytes (LOG_MAX_BYTES)"
    # a later run asks whether the log it skipped changed: not read either, the same while too large
    assert loop._same_log(log, "") and not loop._same_log(log, "0" * 64)
    assert io_bytes()[0] - before[0] < MIB


def test_the_monitor_refuses_a_sparse_friction_test_on_its_size_before_hashing_it(tmp_path, puma, monkeypatch):
    from faultgen.data import logfolder
    from faultgen.monitor import friction_tests

    monkeypatch.setattr(columns, "LOG_MAX_BYTES", MIB, raising=False)
    folder = tmp_path / "LOGS" / "u1" / logfolder.TESTS
    folder.mkdir(parents=True)
    test = sparse(folder / "2026-01-20.csv", 64 * MIB)
    found = {"u1": [logfolder.LogFile("u1", "2026-01-20", 0.0, "time", test, "u1/friction-test/2026-01-20.csv")]}
    before = io_bytes()
    [reading] = friction_tests.read_tests(found, puma, tmp_path / "OUT")["u1"]
    assert reading.error == f"{test}: {64 * MIB} bytes; a joint log is read up to {MIB} bytes" and not reading.fits
    assert io_bytes()[0] - before[0] < MIB


# -- item 3: whole-file reads before the bounds ---------------------------------------------------


@contextlib.contextmanager
def address_space(extra: int = 2**30):
    """This process's address space capped (``RLIMIT_AS``, soft) at its current size plus ``extra``
    while the block runs: a whole-file read of a sparse file's apparent size fails at once with a
    MemoryError instead of filling the machine's memory (the attacker's runs used a 4 GB cap)."""
    status = dict(line.split(":", 1) for line in Path("/proc/self/status").read_text().splitlines() if ":" in line)
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    resource.setrlimit(resource.RLIMIT_AS, (int(status["VmSize"].split()[0]) * 1024 + extra, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


def robot_copy(folder: Path, name: str = "puma560.xml") -> Path:
    """The puma560's robot folder copied to ``folder``, its MJCF named ``name``."""
    shutil.copytree(Path(robots.load("puma560").path).parent, folder)
    if name != "puma560.xml":
        (folder / "puma560.xml").rename(folder / name)
    return folder


@pytest.mark.parametrize(("planted", "what", "bound"), [("puma560.xml", "robot MJCF", 10_000_000),
                                                        ("tasks.toml", "tasks file", inputs.TOML_MAX_BYTES)])
def test_a_robot_folders_sparse_model_or_tasks_file_is_refused_in_one_line(tmp_path, planted, what, bound):
    """A 20 GiB sparse MJCF or tasks.toml in a --robot folder: a MemoryError traceback under a cap (the
    MJCF hashed whole, the tasks file hashed whole to key the preparation); refused on its size."""
    robot = robot_copy(tmp_path / "puma560")
    sparse(robot / planted, 20 * 2**30)
    with address_space():
        result = runner.invoke(app, ["simulate", "--robot", str(robot), "--task", "pick_place", "--cycles", "1",
                                     "-o", str(tmp_path / "o.h5")])
    assert result.exit_code == 2, (result.output, result.exception)
    assert f"{robot / planted}: {20 * 2**30} bytes; a {what} is read up to {bound} bytes" in result.output


@pytest.mark.parametrize("name", ["program.toml", "log.csv"])
def test_a_sparse_task_file_is_refused_in_one_line(tmp_path, name):
    task = sparse(tmp_path / name, 20 * 2**30)
    bound = f"a program file is read up to {inputs.TOML_MAX_BYTES}" if name.endswith(".toml") else \
        f"a joint log is read up to {columns.LOG_MAX_BYTES}"
    with address_space():
        result = runner.invoke(app, ["simulate", "--robot", "puma560", "--task", str(task), "--cycles", "1",
                                     "-o", str(tmp_path / "o.h5")])
    assert result.exit_code == 2 and f"{task}: {20 * 2**30} bytes; {bound} bytes" in result.output, \
        (result.output, result.exception)


def test_a_planted_tasks_file_in_outs_calibration_cache_is_refused_before_it_is_read(tmp_path):
    """The monitor's twin of a cached calibration keys its preparation on the model folder's
    tasks.toml: a sparse one planted there is refused by its size (was a MemoryError)."""
    import numpy as np

    from faultgen.monitor import unit
    from faultgen.operation import tasks
    from faultgen.simulation import prepare

    model = robot_copy(tmp_path / "OUT" / ".cache" / "calibrated" / ("d" * 24) / "model", "puma560_calibrated.xml")
    sparse(model / "tasks.toml", 20 * 2**30)
    robot = unit.cached_model(model / "puma560_calibrated.xml")
    motion = tasks.Motion("m", np.arange(3) * 0.004, np.zeros((3, robot.n_axes)))
    with address_space(), pytest.raises(inputs.InputError) as refused:
        prepare.digests(robot, motion)
    assert str(refused.value) == f"{model / 'tasks.toml'}: {20 * 2**30} bytes; a tasks file is read up to " \
                                 f"{inputs.TOML_MAX_BYTES} bytes"


# -- item 6: friction-test --reference ------------------------------------------------------------

FIT = ("axis,model,coulomb_Nm,static_excess_Nm,stribeck_velocity_rad_s,viscous_Nms_rad\n"
       "2,coulomb+viscous,12.5,0.0,,3.25\n")


def test_a_reference_fit_table_is_read_back_with_its_numbers(tmp_path, puma):
    from faultgen.calibrate import friction_report

    (tmp_path / "friction_fit.csv").write_text(FIT)
    table = friction_report.reference_fits(tmp_path, puma)
    assert list(table["axis"]) == [2] and table["coulomb_Nm"].iloc[0] == 12.5 and table["viscous_Nms_rad"].iloc[0] == 3.25
    assert table["stribeck_velocity_rad_s"].isna().all()  # not fitted: empty, read as NaN


@pytest.mark.parametrize(("content", "message"), [
    (FIT.replace("12.5", "twelve"), r"row 1 \(line 2\), column coulomb_Nm: 'twelve'; expected a finite number"),
    (FIT.replace("2,coulomb", "0.5,coulomb"), r"row 1 \(line 2\), column axis: '0.5'; expected a whole axis number"),
    (FIT.replace("3.25", "inf"), r"row 1 \(line 2\), column viscous_Nms_rad: 'inf'; expected a finite number"),
    ("axis,coulomb_Nm\n1,2\n", r"not a friction_fit.csv \(no columns static_excess_Nm"),
])
def test_a_reference_fit_table_with_a_bad_cell_is_refused_naming_its_row_and_column(tmp_path, puma, content, message):
    from faultgen.calibrate import friction_report

    (tmp_path / "friction_fit.csv").write_text(content)
    with pytest.raises(ValueError, match=rf"{tmp_path / 'friction_fit.csv'}: {message}"):
        friction_report.reference_fits(tmp_path, puma)


def test_a_reference_fit_table_linked_out_of_its_folder_or_too_large_is_refused_unread(tmp_path, puma):
    from faultgen.calibrate import friction_fit, friction_report

    folder, outside = tmp_path / "ref", tmp_path / "secret.csv"
    folder.mkdir()
    outside.write_text(FIT)
    (folder / "friction_fit.csv").symlink_to(outside)
    with pytest.raises(ValueError, match="friction_fit.csv: a symbolic link out of the reference folder"):
        friction_report.reference_fits(folder, puma)
    (folder / "friction_fit.csv").unlink()
    sparse(folder / "friction_fit.csv", 2 * friction_fit.FITS_MAX_BYTES, FIT.encode())
    before = io_bytes()
    with pytest.raises(ValueError, match=f"{2 * friction_fit.FITS_MAX_BYTES} bytes; a friction_fit.csv is read up to"):
        friction_report.reference_fits(folder, puma)
    assert io_bytes()[0] - before[0] < friction_fit.FITS_MAX_BYTES


# -- item 12: --task on what is no file -----------------------------------------------------------


@pytest.mark.parametrize(("make", "kind"), [
    (lambda p: os.mkfifo(p), "not a regular file (a FIFO (named pipe))"),
    (lambda p: p.symlink_to("/dev/zero"), "not a regular file (a symlink to /dev/zero, a character device)"),
    (lambda p: p.mkdir(), "not a regular file (a folder)"),
])
def test_a_task_that_is_no_regular_file_is_named_for_what_it_is(tmp_path, make, kind):
    task = tmp_path / "task.toml"
    make(task)
    result = runner.invoke(app, ["simulate", "--robot", "puma560", "--task", str(task), "--cycles", "1",
                                 "-o", str(tmp_path / "o.h5")])
    assert result.exit_code == 2 and f"{task}: {kind}; the task file must be a regular file" in result.output, \
        result.output
    missing = runner.invoke(app, ["simulate", "--robot", "puma560", "--task", str(tmp_path / "gone.toml"),
                                  "--cycles", "1", "-o", str(tmp_path / "o.h5")])
    assert missing.exit_code == 2 and "does not exist" in missing.output, missing.output


def test_a_sparse_model_planted_in_outs_calibration_cache_is_refused_unread(tmp_path):
    """A cached calibration's model is hashed to check it against its record: a sparse one above the
    bound is refused by its size, never read (it was hashed whole, 5 GiB of zeros here)."""
    import json

    from faultgen.monitor import state as stored

    root = tmp_path / "OUT"
    model = robot_copy(root / ".cache" / "calibrated" / ("d" * 24) / "model", "puma560_calibrated.xml")
    record = root / ".cache" / "calibrated" / f"{'d' * 24}.json"
    key = {"nominal": "n", "log": "l"}
    record.write_text(json.dumps({"format": stored.CALIBRATION_FORMAT, "key": key, "model": "0" * 64}))
    planted = sparse(model / "puma560_calibrated.xml", columns.LOG_MAX_BYTES + 2**30)
    before = io_bytes()
    with pytest.raises(inputs.InputError, match=rf"puma560_calibrated\.xml: {columns.LOG_MAX_BYTES + 2**30} bytes; a "
                                                rf"file is read up to {columns.LOG_MAX_BYTES} bytes"):
        stored.read_calibration(record, root, key, planted)
    assert io_bytes()[0] - before[0] < MIB
