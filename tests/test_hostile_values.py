"""Issue 61, items 7 and 8: hostile values at the boundary. Each case was a traceback, an unclear
error or a value taken (exit 0); each is now refused with exit 2 and one ``error:`` line naming the
value, file or row and what was expected: sequence stamps, ``--torque-constants``, log values
(torque, temperature, payload, cycle), folder entries (a non-UTF-8 name, ``events.csv`` a folder, a
FIFO), RTDE parser errors, ``monitor`` options and ``-o FILE``, a robot's ``[limits]``, a dataset's
``n_axes``, and text cells a spreadsheet would run as formulas (escaped, as the monitor's).

Each input is a copy of one tiny fleet (one unit, two logs of 3 s at 250 Hz, puma560)."""

from __future__ import annotations

import os
import re
import shutil
import sys
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.data import cells, fleetlogs, logfolder
from faultgen.model import robots

sys.path.insert(0, str(Path(__file__).parent))
import fleetlog_folder  # noqa: E402

runner = CliRunner()
MISSING = "/nonexistent-faultgen-folder"
ROBOTS = Path(__file__).resolve().parent.parent / "robots"


@pytest.fixture(scope="module")
def puma():
    return robots.load("puma560")


@pytest.fixture(scope="module")
def template(tmp_path_factory, puma):
    return fleetlog_folder.write_fleet(tmp_path_factory.mktemp("fleet") / "LOGS", puma, units=1, days=2)


@pytest.fixture
def logs(template, tmp_path):
    return Path(shutil.copytree(template, tmp_path / "LOGS"))


def _refused(result, pattern: str, code: int = 2) -> str:
    """Exit ``code``, one ``error:`` line matching ``pattern``, no traceback."""
    assert result.exit_code == code, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(result.exception)
    errors = [line for line in result.output.splitlines() if line.startswith("error: ")]
    assert len(errors) == 1 and "Traceback" not in result.output, result.output
    assert re.search(pattern, errors[0]), errors[0]
    return errors[0]


def _import(logs: Path, *extra: str):
    return runner.invoke(app, ["logs", "import", str(logs), "--robot", "puma560", "-o", str(logs.parent / "f.h5"),
                               "--no-progress", *extra])


def _edit_first_log(logs: Path, edit) -> None:
    path = sorted((logs / "u1").iterdir())[0]
    frame = pd.read_csv(path)
    edit(frame)
    frame.to_csv(path, index=False)


# -- item 7: tracebacks and unclear errors ---------------------------------------------------------------------


@pytest.mark.parametrize("stamp", ["1" * 400, "\u00b2", "9" * 5000])
def test_a_sequence_stamp_of_400_or_5000_digits_or_a_superscript_is_named(logs, stamp):
    """Before: OverflowError (400 digits, a traceback), Python's "invalid literal for int()" ("²") and
    "Exceeds the limit (4300 digits)" (5000), none naming the file or line."""
    for k, path in enumerate(sorted((logs / "u1").iterdir()), start=1):
        path.rename(path.with_name(f"{k}.csv"))
    (logs / "events.csv").write_text(f"unit,stamp,event,axis\nu1,{stamp},onset,1\n", encoding="utf-8")
    line = _refused(_import(logs), r"events\.csv: line 2: stamp .* expected a sequence number of at most 15 digits")
    assert len(line) < 400
    with pytest.raises(ValueError, match="at most 15 digits"):
        logfolder.parse_stamp(stamp, "here")


def test_torque_constants_with_the_voraus_format_are_refused(logs):
    """Before: TypeError (Voraus() takes no torque_constants), a traceback."""
    _refused(_import(logs, "--format", "voraus", "--torque-constants", "1,1,1,1,1,1"),
             r"--torque-constants .* give it with --format ur-rtde, not --format voraus")


def test_a_unit_folder_whose_name_is_not_utf8_is_named(logs):
    """Before: "'utf-8' codec can't encode character '\\udcff'", no file named."""
    os.rename(os.fsencode(logs / "u1"), os.fsencode(logs) + b"/u\xff1")
    _refused(_import(logs), r"LOGS/u\\xff1: the name is not UTF-8 text")


@pytest.mark.parametrize("damage, message", [
    (lambda text: text.replace("actual_q_1", "actual_q_0", 1), r"column\(s\) actual_q_0 appear more than once"),
    (lambda text: text.replace("\n", '\n"', 3), r"cannot read the file as an RTDE recorder CSV: .*EOF inside string"),
])
def test_ur_rtde_parser_errors_name_the_file(tmp_path, puma, damage, message):
    """Before: "Duplicate names are not allowed." and "Error tokenizing data...", no file named."""
    t, q, _, tau, _ = fleetlog_folder.log_signals(puma, 1, 0, np.zeros(6))
    frame = pd.DataFrame({"timestamp": t, **{f"actual_q_{k}": q[:, k] for k in range(6)},
                          **{f"target_moment_{k}": tau[:, k] for k in range(6)}})
    (tmp_path / "UR" / "cell").mkdir(parents=True)
    (tmp_path / "UR" / "cell" / "2026-03-01.csv").write_text(damage(frame.to_csv(sep=" ", index=False)))
    _refused(_import(tmp_path / "UR", "--format", "ur-rtde"), r"UR/cell/2026-03-01\.csv: " + message)


def test_monitor_out_an_existing_file_is_refused_before_any_log_is_read(logs, tmp_path):
    """Before: "error: OUT/.cache: Not a directory", exit 1."""
    (tmp_path / "out.txt").write_text("mine\n")
    result = runner.invoke(app, ["monitor", str(logs), "--robot", "puma560", "-o", str(tmp_path / "out.txt")])
    _refused(result, r"out\.txt exists and is not a folder")
    assert (tmp_path / "out.txt").read_text() == "mine\n"


@pytest.mark.parametrize("velocity", ["1e-6", "1e300"])
def test_robot_limits_outside_their_bounds_are_refused_naming_the_axis(tmp_path, velocity):
    """Before: 1e-6 deg/s gave "error: -101 is not a valid Result." (ruckig); 1e300 simulated, exit 0."""
    robot = Path(shutil.copytree(ROBOTS / "puma560", tmp_path / "puma560"))
    toml = robot / "tasks.toml"
    toml.write_text(toml.read_text().replace("velocity = [100, 95,", f"velocity = [{velocity}, 95,", 1))
    result = runner.invoke(app, ["simulate", "--robot", str(robot), "--task", "pick_place", "--cycles", "1",
                                 "-o", str(tmp_path / "s.h5"), "--no-progress"])
    _refused(result, r"tasks\.toml .*\[limits\] velocity: axis 1: 1e[-+]\d+ deg/s; expected 0\.05 \.\. 6000 deg/s")
    assert not (tmp_path / "s.h5").exists()


# -- items 7 and 8: values a log may hold -----------------------------------------------------------------------


def _set(column, value, row=5):
    def edit(frame):
        frame[column] = frame[column].astype(float)
        frame.loc[row, column] = value
    return edit


def _with(column, fill, row, value):
    def edit(frame):
        names = [f"{column}{k}" for k in range(1, 7)] if column == "temperature" else [column]
        for name in names:
            frame[name] = fill
        frame.loc[row, names[-1]] = value
    return edit


def _every_sample(frame):
    frame["cycle"] = np.arange(len(frame)) + 1


LOG_VALUES = {
    "torque 1e300": (_set("tau1", 1e300), r"data row 6 \(line 7\), column tau1: value 1e\+300 N m; expected "
                                          r"-1e\+07 \.\. 1e\+07 N m"),
    "temperature 1e300": (_with("temperature", 25.0, 7, 1e300), r"data row 8 \(line 9\), column temperature6: value "
                                                                r"1e\+300 degC; expected -60 \.\. 250 degC"),
    "payload -1e6": (_with("payload", 10.0, 3, -1e6), r"data row 4 \(line 5\), column payload: value -1e\+06 kg; "
                                                      r"expected 0 \.\. 10000 kg"),
    "payload 1e300": (_with("payload", 10.0, 3, 1e300), r"data row 4 \(line 5\), column payload: value 1e\+300 kg"),
    "cycle 1e15": (_set("cycle", 1e15, 0), r"data row 1 \(line 2\), column cycle: value 1e\+15; expected a whole cycle "
                                           r"number 0 \.\. 1e\+09"),
    "cycle -5": (_set("cycle", -5, 0), r"data row 1 \(line 2\), column cycle: value -5; expected"),
    "a cycle every sample": (_every_sample, r"column cycle: cycle 2 from data row 2 \(line 3\) spans 0 s; expected "
                                            r"cycles of at least 0\.1 s"),
}


@pytest.mark.parametrize("case", sorted(LOG_VALUES))
def test_a_log_value_out_of_bounds_is_refused_naming_the_file_row_and_bound(logs, case):
    """Before: stored with exit 0 (temperature, payload, cycle -5, a cycle every sample), or a
    numpy overflow warning and a slope of -1e295 (torque 1e300)."""
    edit, message = LOG_VALUES[case]
    _edit_first_log(logs, edit)
    _refused(_import(logs), r"u1/2026-03-01\.csv: " + message)
    assert not (logs.parent / "f.h5").exists()


# -- item 8: bad values accepted --------------------------------------------------------------------------------


@pytest.mark.parametrize("option, value", [("--train", "1000000000"), ("--persistence", str(10**12)),
                                           ("--alpha", "nan"), ("--alpha", "0.5")])
def test_monitor_counts_and_significance_have_ranges(option, value):
    """Before: --train 10^9 and --persistence 10^12 taken; --alpha nan refused only after the logs
    were read, without the option named."""
    result = runner.invoke(app, ["monitor", f"{MISSING}/LOGS", "--robot", "puma560", "-o", f"{MISSING}/m",
                                 option, value])
    _refused(result, rf"{option} '{re.escape(value)}': expected")


@pytest.mark.parametrize("constants", ["1e308,1,1,1,1,1", "1e-300,1,1,1,1,1", "1,1"])
def test_torque_constants_are_bounded_and_one_per_axis(logs, constants):
    """Before: taken (1e308, 1e-300), or refused only at a log with current columns (2 values)."""
    _refused(_import(logs, "--format", "ur-rtde", "--torque-constants", constants),
             r"--torque-constants .*: expected 6 numbers \(the axes of puma560\), comma-separated, each "
             r"0\.001 \.\. 10000 N m/A")


@pytest.fixture(scope="module")
def imported(template, tmp_path_factory):
    """The tiny fleet imported, its unit named as a formula."""
    folder = Path(shutil.copytree(template, tmp_path_factory.mktemp("formula") / "LOGS"))
    (folder / "u1").rename(folder / "=HYPERLINK(1)")
    fleetlogs.import_logs(folder, folder.parent / "f.h5", robot="puma560", progress=False)
    return folder.parent / "f.h5"


@pytest.mark.parametrize("command", [["export", "-o", "{tmp}/x.csv"], ["plot", "-o", "{tmp}/x.png"]])
def test_a_dataset_with_a_billion_axes_is_refused_by_every_reader(imported, tmp_path, command):
    """Before: `validate` refused n_axes = 1e9, `export` and `plot` wrote with exit 0. Now every
    reader refuses it at opening, as a broken dataset (exit 1, as `validate`'s verdict)."""
    broken = tmp_path / "broken.h5"
    shutil.copy(imported, broken)
    with h5py.File(broken, "a") as f:
        f["runs"][next(iter(f["runs"]))].attrs["n_axes"] = 10**9
    args = [a.format(tmp=tmp_path) for a in command]
    _refused(runner.invoke(app, [args[0], str(broken), *args[1:]]),
             r"broken\.h5: run '=HYPERLINK\(1\)': n_axes attribute 1000000000, expected a whole number 5\.\.7", code=1)
    assert not list(tmp_path.glob("x.*"))


def test_a_unit_named_as_a_formula_is_escaped_in_the_exported_csv(imported, tmp_path):
    """Before: `=HYPERLINK(1)` written as it is (formula injection); now with a leading ', as the
    monitor's CSVs (faultgen.data.cells)."""
    result = runner.invoke(app, ["export", str(imported), "-o", str(tmp_path / "x.csv")])
    assert result.exit_code == 0, result.output
    lines = (tmp_path / "x.csv").read_text().splitlines()
    assert all(line.startswith("'=HYPERLINK(1),") for line in lines[1:]), lines[:2]
    assert cells.text("-2") == "-2" and cells.text("-x") == "'-x" and cells.text("ok") == "ok"  # numbers stay numbers
    assert pd.read_csv(tmp_path / "x.csv")["run"].iloc[0] == "'=HYPERLINK(1)"


def test_events_csv_a_folder_and_a_fifo_at_the_top_are_named(logs):
    """Before: events.csv as a folder was taken as a unit without logs (exit 0); a FIFO gave
    "Not a directory" (now: named as a FIFO)."""
    (logs / "events.csv").mkdir()
    _refused(_import(logs), r"LOGS/events\.csv: a folder; the events file must be a regular file")
    (logs / "events.csv").rmdir()
    os.mkfifo(logs / "pipe")
    _refused(_import(logs), r"LOGS/pipe: neither a unit folder nor events\.csv \(a FIFO \(named pipe\)\)")
