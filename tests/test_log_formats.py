"""A log format added in one file reaches `logs import`, `calibrate` and `monitor` (issue 57, item 2).

tests/log_format_example.py registers ``deg-ms`` (milliseconds, degrees, tab-separated) and nothing
else: each command given ``--format deg-ms`` reads the logs through it and gives the outputs it
gives on the same numbers in the measured format.
"""

import json

import fleetlog_folder
import h5py
import log_format_example
import numpy as np
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.data import adapters
from faultgen.model import robots

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


def test_the_format_is_one_registered_class():
    assert adapters.ADAPTERS["deg-ms"] is log_format_example.DegreesMilliseconds
    with pytest.raises(ValueError, match="deg-ms"):  # an unknown name lists the registered ones
        adapters.make("no-such-format")


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


def test_calibrate_reads_the_format(tmp_path, puma):
    """A log with a hidden Coulomb friction on some axes, in the example layout: the calibration
    finds what it finds on the same numbers in the measured format, step for step."""
    hidden = tmp_path / "hidden.csv"
    made = runner.invoke(app, ["hidden-log", "puma560", "--effect", "coulomb", "--cycles", "1", "-o", str(hidden)])
    assert made.exit_code == 0, made.output
    tsv = log_format_example.write(hidden, tmp_path / "hidden.tsv")
    plain = log_format_example.measured_copy(tsv, puma, tmp_path / "plain.csv")
    reports = {}
    for name, log, extra in (("example", tsv, ["--format", "deg-ms"]), ("plain", plain, [])):
        out = tmp_path / f"calib-{name}"
        result = runner.invoke(app, ["calibrate", "--robot", "puma560", "--measured", str(log), "-o", str(out),
                                     "--max-steps", "1", "--no-sysid", *extra])
        assert result.exit_code == 0, result.output
        reports[name] = json.loads((out / "report.json").read_text())
    for report in reports.values():
        report.pop("measured"), report.pop("model_out")
    assert reports["example"] == reports["plain"]
    assert [step["effect"] for step in reports["example"]["steps"]] == ["coulomb"]


def test_calibrate_refuses_an_unknown_format_and_torque_constants_of_another(tmp_path):
    result = runner.invoke(app, ["calibrate", "--robot", "puma560", "--measured", str(tmp_path / "x.csv"),
                                 "-o", str(tmp_path / "c"), "--format", "no-such-format"])
    assert result.exit_code == 2 and "no-such-format" in result.output and "ur-rtde" in result.output
    result = runner.invoke(app, ["calibrate", "--robot", "puma560", "--measured", str(tmp_path / "x.csv"),
                                 "-o", str(tmp_path / "c"), "--format", "voraus", "--torque-constants", "1,1,1,1,1,1"])
    assert result.exit_code == 2 and "--torque-constants" in result.output
    assert not (tmp_path / "c").exists()
