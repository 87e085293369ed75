"""A log format added in one file reaches `logs import`, `calibrate`, `monitor` and the replay of
`simulate --task LOG` (issue 57, item 2).

tests/log_format_example.py registers ``deg-ms`` (milliseconds, degrees, tab-separated) and nothing
else: each command given ``--format deg-ms`` reads the logs through it and gives the outputs it
gives on the same numbers in the measured format.
"""

import dataclasses
import json

import fleetlog_folder
import h5py
import log_format_example
import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import faultgen.calibrate
from faultgen.calibrate import search
from faultgen.cli import app
from faultgen.logs import formats, longlog
from faultgen.model import robots
from faultgen.operation import programs, replay
from faultgen.logs import jointlog

runner = CliRunner()


@pytest.fixture(scope="module")
def puma():
    return robots.load("puma560")


@pytest.fixture(scope="module")
def fleets(tmp_path_factory, puma):
    """The same fleet twice: ``deg-ms`` logs, and the numbers the adapter reads from them in the
    measured format."""
    root = tmp_path_factory.mktemp("formats")
    source = fleetlog_folder.write_fleet(root / "source", puma, units=2, days=16, worn={0: (2, 11, 0.3)})
    example, plain = root / "deg-ms", root / "plain"
    for log in sorted(source.rglob("*.csv")):
        for folder in (example, plain):
            (folder / log.parent.name).mkdir(parents=True, exist_ok=True)
        tsv = log_format_example.write(log, example / log.parent.name / (log.name[:-4] + ".tsv"))
        log_format_example.measured_copy(tsv, puma, plain / log.parent.name / log.name)
    return example, plain


@pytest.fixture(scope="module")
def hidden(tmp_path_factory, puma):
    """A 1-cycle log with a hidden Coulomb friction on some axes (1964 rows at 250 Hz) as ``deg-ms``,
    and the same numbers in the measured format."""
    root = tmp_path_factory.mktemp("hidden")
    log = root / "hidden.csv"
    made = runner.invoke(app, ["hidden-log", "puma560", "--effect", "coulomb", "--cycles", "1", "-o", str(log)])
    assert made.exit_code == 0, made.output
    tsv = log_format_example.write(log, root / "hidden.tsv")
    return tsv, log_format_example.measured_copy(tsv, puma, root / "plain.csv")


def test_the_format_is_one_registered_class():
    assert formats.FORMATS["deg-ms"] is log_format_example.DegreesMilliseconds
    with pytest.raises(ValueError, match="deg-ms"):  # an unknown name lists the registered ones
        formats.make("no-such-format")


def test_logs_import_reads_the_format(fleets, tmp_path):
    example, plain = fleets
    stores = {}
    for name, folder, extra in (("example", example, ["--format", "deg-ms"]), ("plain", plain, [])):
        out = tmp_path / f"{name}.h5"
        result = runner.invoke(app, ["logs", "import", str(folder), "--robot", "puma560", "-o", str(out),
                                     "--no-progress", *extra])
        assert result.exit_code == 0, result.output
        stores[name] = out
    with h5py.File(stores["example"]) as a, h5py.File(stores["plain"]) as b:
        runs = sorted(a["runs"])
        assert runs == sorted(b["runs"]) and len(runs) == 2
        for run in runs:
            # the numbers: every numeric array (the log's file name and digest differ, as they should)
            features = [k for k, v in a["runs"][run].items() if isinstance(v, h5py.Dataset) and v.dtype.kind in "fiu"]
            assert "torque_features" in features or len(features) > 3, features
            for k in features:
                np.testing.assert_array_equal(a["runs"][run][k][()], b["runs"][run][k][()], err_msg=f"{run}/{k}")


def test_monitor_reads_the_format(fleets, tmp_path):
    example, plain = fleets
    outs = {}
    for name, folder, extra in (("example", example, ["--format", "deg-ms"]), ("plain", plain, [])):
        out = tmp_path / name
        result = runner.invoke(app, ["monitor", str(folder), "--robot", "puma560", "-o", str(out), "--protocol", "own",
                                     "--train", "10", "--persistence", "2", "--no-progress", *extra])
        assert result.exit_code == 0, result.output
        outs[name] = out
    for name in ("alarms.csv", "scores.csv", "units.csv"):
        assert (outs["example"] / name).read_text() == (outs["plain"] / name).read_text(), name
    assert len((outs["example"] / "scores.csv").read_text().splitlines()) > 10


def test_calibrate_reads_the_format(tmp_path, hidden):
    """A log with a hidden Coulomb friction on some axes, in the example layout: the calibration
    finds what it finds on the same numbers in the measured format, step for step."""
    reports = _calibrated(tmp_path, *hidden)
    assert reports["example"] == reports["plain"]
    assert [step["effect"] for step in reports["example"]["steps"]] == ["coulomb"]


def _calibrated(tmp_path, tsv, plain, printed=""):
    """The reports of ``calibrate --format deg-ms`` on ``tsv`` and of ``calibrate`` on ``plain``
    (the log's file and model path left out), each run printing ``printed``."""
    reports = {}
    for name, log, extra in (("example", tsv, ["--format", "deg-ms"]), ("plain", plain, [])):
        out = tmp_path / f"calib-{name}"
        result = runner.invoke(app, ["calibrate", "--robot", "puma560", "--measured", str(log), "-o", str(out),
                                     "--max-steps", "1", "--no-sysid", *extra])
        assert result.exit_code == 0 and printed in result.output, result.output
        reports[name] = json.loads((out / "report.json").read_text())
    for report in reports.values():
        report.pop("measured"), report.pop("model_out")
    return reports


def _no_whole_read(monkeypatch):
    """The ``deg-ms`` adapter's whole read refused: what still works reads the log in blocks."""
    def whole(self, path, robot):
        raise AssertionError(f"{path} read whole")
    monkeypatch.setattr(log_format_example.DegreesMilliseconds, "columns", whole)


def test_calibrate_reads_a_long_log_of_the_format_in_blocks(tmp_path, puma, hidden, monkeypatch):
    """A log longer than the calibration's MAX_ROWS (here 700: 1964 rows averaged over blocks of 3),
    read in blocks of 300 rows: through the ``deg-ms`` adapter's block reader (its whole read
    refused) ``longlog.read`` gives, array for array and note for note, what it gives on the same
    numbers in the measured format, and ``calibrate --format deg-ms`` the same report."""
    tsv, plain = hidden
    monkeypatch.setattr(longlog, "BLOCK_ROWS", 300)
    monkeypatch.setattr(faultgen.calibrate, "MAX_ROWS", 700)
    _no_whole_read(monkeypatch)
    example, moves = longlog.read(tsv, puma, 700, search.REST_SPEED, formats.make("deg-ms"))
    measured, plain_moves = longlog.read(plain, puma, 700, search.REST_SPEED)
    assert len(example) == len(measured) == 654 and example.notes[-1].startswith("decimated: 1964 rows")
    for name in ("t", "q", "qd", "qdd", "tau"):
        np.testing.assert_array_equal(getattr(example, name), getattr(measured, name), err_msg=name)
    assert example.notes == measured.notes
    for name in ("moving", "peak", "rows"):
        np.testing.assert_array_equal(getattr(moves, name), getattr(plain_moves, name), err_msg=name)
    reports = _calibrated(tmp_path, tsv, plain, "decimated: 1964 rows averaged over blocks of 3 to 654")
    assert reports["example"] == reports["plain"]


@pytest.mark.parametrize(("row", "column", "cell", "message"), [
    (1500, "angle_deg_4", "abc", r"data row 1501 \(index 1500\), column angle_deg_4: value 'abc'; expected a finite"),
    (1700, "time_ms", "inf", r"data row 1701 \(index 1700\), column time_ms: value 'inf'; expected a finite"),
    (900, "angle_deg_1", "170", r"column q1 at data row 901 \(index 900\) is 2\.96706 rad, outside the joint range"),
])
def test_a_bad_cell_deep_in_a_long_log_of_the_format_is_refused_as_its_whole_read_refuses_it(
        tmp_path, puma, hidden, monkeypatch, row, column, cell, message):
    tsv = tmp_path / "bad.tsv"
    lines = hidden[0].read_text().splitlines()
    cells = lines[row + 1].split("\t")
    cells[lines[0].split("\t").index(column)] = cell
    lines[row + 1] = "\t".join(cells)
    tsv.write_text("\n".join(lines) + "\n")
    monkeypatch.setattr(longlog, "BLOCK_ROWS", 300)
    adapter = formats.make("deg-ms")
    with pytest.raises(jointlog.LogError, match=message) as whole:
        adapter.read(tsv, puma)
    with pytest.raises(jointlog.LogError) as part:
        longlog.read(tsv, puma, 700, search.REST_SPEED, adapter)
    assert str(part.value) == str(whole.value)


def test_a_format_of_a_whole_reader_alone_gets_blocks_of_it(puma, hidden):
    """A plug-in that defines ``columns`` alone (no ``convert``): its blocks are its whole read,
    sliced, of exactly the rows asked for, with its label and notes."""
    tsv = hidden[0]

    @dataclasses.dataclass(frozen=True)
    class Whole(formats.LogFormat):  # not registered: the registry stays the example's
        name = "whole"

        def columns(self, path, robot):
            columns = log_format_example.DegreesMilliseconds().columns(path, robot)[0]
            return columns, jointlog.csv_label, ("read whole",)

    src = Whole().source(tsv, puma)
    whole = log_format_example.DegreesMilliseconds().columns(tsv, puma)[0]
    assert src.rows == 1964 and src.notes == ("read whole",) and src.label(0) == "data row 1 (line 2)"
    blocks = list(src.blocks(500))
    assert [(start, len(block)) for start, block in blocks] == [(0, 500), (500, 500), (1000, 500), (1500, 464)]
    np.testing.assert_array_equal(np.concatenate([b for _, b in blocks]),
                                  np.column_stack([whole[name] for name in src.wanted]))


def test_calibrate_refuses_an_unknown_format_and_torque_constants_of_another(tmp_path):
    result = runner.invoke(app, ["calibrate", "--robot", "puma560", "--measured", str(tmp_path / "x.csv"),
                                 "-o", str(tmp_path / "c"), "--format", "no-such-format"])
    assert result.exit_code == 2 and "no-such-format" in result.output and "ur-rtde" in result.output
    result = runner.invoke(app, ["calibrate", "--robot", "puma560", "--measured", str(tmp_path / "x.csv"),
                                 "-o", str(tmp_path / "c"), "--format", "voraus", "--torque-constants", "1,1,1,1,1,1"])
    assert result.exit_code == 2 and "--torque-constants" in result.output
    assert not (tmp_path / "c").exists()


def motion_log(path, robot, t, q):
    """A measured-format log of the motion ``t`` (s), ``q`` (rad) with no torque (a replay reads none)."""
    names = ["t", *(f"q{k}" for k in range(1, 7)), *(f"tau{k}" for k in range(1, 7))]
    np.savetxt(path, np.column_stack([t, q, np.zeros_like(q)]), delimiter=",", header=",".join(names), comments="",
               fmt="%.17g")
    return path


def test_simulate_replays_the_format(tmp_path, puma):
    """A 2 s piece of the PUMA 560's pick and place (ending mid-move) at 250 Hz, as a ``deg-ms``
    log: ``simulate --task LOG --format deg-ms`` gives the dataset of the same numbers in the measured
    format, array for array; the dataset says which format the log was read by."""
    thesis = programs.load(puma, "pick_place").trajectory(0.004)
    piece = slice(200, 701)
    source = motion_log(tmp_path / "source.csv", puma, 3.0 + thesis.t[piece], thesis.q[piece])
    tsv = log_format_example.write(source, tmp_path / "piece.tsv")
    plain = log_format_example.measured_copy(tsv, puma, tmp_path / "plain.csv")
    stores = {}
    for name, log, extra in (("example", tsv, ["--format", "deg-ms"]), ("plain", plain, [])):
        out = tmp_path / f"{name}.h5"
        result = runner.invoke(app, ["simulate", "--robot", "puma560", "--task", str(log), "--cycles", "1",
                                     "--no-progress", "-o", str(out), *extra])
        assert result.exit_code == 0, result.output
        stores[name] = out
    with h5py.File(stores["example"]) as a, h5py.File(stores["plain"]) as b:
        run_a, run_b = a["runs/run"], b["runs/run"]
        arrays = sorted(k for k, v in run_b.items() if isinstance(v, h5py.Dataset))
        assert sorted(k for k, v in run_a.items() if isinstance(v, h5py.Dataset)) == arrays
        assert {"q_ref", "q_m", "tau_m", "mean_abs_torque"} <= set(arrays)
        for k in arrays:
            np.testing.assert_array_equal(run_a[k][()], run_b[k][()], err_msg=k)
        assert run_a.attrs["task"] == "piece" and run_b.attrs["task"] == "plain"
        assert json.loads(run_a.attrs["program"])["format"] == {"name": "deg-ms"}
        assert "format" not in json.loads(run_b.attrs["program"])
        assert json.loads(run_a.attrs["config"])["log_format"] == {"name": "deg-ms"}


def test_a_dense_log_in_the_format_replays_as_in_the_measured_format_and_is_refused_alike(tmp_path, puma,
                                                                                          monkeypatch):
    """A 1 s piece at 4 kHz (two rows per physics step of the PUMA 560): streamed in blocks through
    the adapter's block reader (its whole read refused), the replay keeps every second row as the
    measured reader does, bit for bit; a gap in the log is refused with the measured format's
    message."""
    thesis = programs.load(puma, "pick_place").trajectory(0.00025)
    piece = slice(1200, 5201)
    source = motion_log(tmp_path / "source.csv", puma, thesis.t[piece], thesis.q[piece])
    tsv = log_format_example.write(source, tmp_path / "dense.tsv")
    plain = log_format_example.measured_copy(tsv, puma, tmp_path / "plain.csv")
    monkeypatch.setattr(replay, "BLOCK_ROWS", 1000)  # streamed in blocks of 1000 rows
    measured = programs.load(puma, str(plain))
    _no_whole_read(monkeypatch)  # the adapter's log streamed through its block reader, never read whole
    example = programs.load(puma, programs.log_task(str(tsv), formats.make("deg-ms")))
    assert example.name == "dense" and len(example.t) == len(measured.t) == 2001
    for name in ("t", "q", "qd", "qdd"):
        np.testing.assert_array_equal(getattr(example, name), getattr(measured, name), err_msg=name)
    t = thesis.t[piece].copy()
    t[3000:] += 0.06  # a gap longer than the derivative filter's window
    gap = log_format_example.write(motion_log(tmp_path / "gap.csv", puma, t, thesis.q[piece]), tmp_path / "gap.tsv")
    with pytest.raises(jointlog.LogError, match=r"gap.tsv: column t jumps by 0.06025 s from data row 3000 \(index "
                                                 r"2999\) to data row 3001 \(index 3000\); expected no interval"):
        programs.load(puma, programs.log_task(str(gap), formats.make("deg-ms")))


def test_simulate_refuses_a_format_for_a_task_that_is_no_log_and_torque_constants_of_another(tmp_path):
    for task in ("pick_place", str(tmp_path / "mine.toml")):
        result = runner.invoke(app, ["simulate", "--robot", "puma560", "--task", task, "--format", "deg-ms",
                                     "-o", str(tmp_path / "x.h5")])
        assert result.exit_code == 2 and "log format deg-ms reads a joint log" in result.output, result.output
    result = runner.invoke(app, ["simulate", "--robot", "puma560", "--task", str(tmp_path / "x.tsv"), "--format",
                                 "no-such-format", "-o", str(tmp_path / "x.h5")])
    assert result.exit_code == 2 and "no-such-format" in result.output and "deg-ms" in result.output
    result = runner.invoke(app, ["simulate", "--robot", "puma560", "--task", str(tmp_path / "x.tsv"), "--format",
                                 "deg-ms", "--torque-constants", "1,1,1,1,1,1", "-o", str(tmp_path / "x.h5")])
    assert result.exit_code == 2 and "--torque-constants" in result.output
    assert not (tmp_path / "x.h5").exists()


def test_a_log_of_the_format_missing_a_column_is_refused_naming_it_whole_and_in_blocks(tmp_path, puma, hidden):
    """The base class's reading of a column-mapping format: a column ``convert`` names that the file
    lacks is refused with the file's columns, by the whole read, the calibration's and the replay's."""
    frame = pd.read_csv(hidden[0], sep="\t").drop(columns=["angle_deg_3"])
    frame.to_csv(tmp_path / "missing.tsv", sep="\t", index=False)
    adapter, log = formats.make("deg-ms"), tmp_path / "missing.tsv"
    message = r"missing\.tsv: missing column 'angle_deg_3' of the deg-ms layout; found time_ms, angle_deg_1, angle_deg_2, "
    for read in (lambda: adapter.read(log, puma), lambda: longlog.read(log, puma, 700, search.REST_SPEED, adapter),
                 lambda: programs.load(puma, programs.log_task(str(log), adapter))):
        with pytest.raises(jointlog.LogError, match=message):
            read()
