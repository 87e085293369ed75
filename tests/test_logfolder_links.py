"""Symbolic links in a fleet's log folder (issue 61, item 4): a unit folder, a log or events.csv
whose link leads out of LOGS is refused, named by its place inside LOGS, before anything behind it
is listed or read, and no line of a file outside LOGS is echoed; links that stay inside LOGS still
work; an imported dataset keeps no absolute path of LOGS."""

from __future__ import annotations

import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.data import fleetlogs, logfolder, reader
from faultgen.monitor import logs as fleet_logs

sys.path.insert(0, str(Path(__file__).parent))
import fleetlog_folder

runner = CliRunner()
MARKER = "MARKER-4f1c9e-not-for-your-eyes"
LINKS_RULE = "links must stay inside the folder"


@pytest.fixture
def logs(tmp_path, puma):
    return fleetlog_folder.write_fleet(tmp_path / "LOGS", puma, units=2, days=3)


@pytest.fixture
def outside(tmp_path, puma):
    """A folder beside LOGS: a valid log and a file whose first line is the marker."""
    folder = tmp_path / "outside"
    folder.mkdir()
    fleetlog_folder.write_log(folder / "2026-04-01.csv", puma, 0, 9, np.zeros(puma.n_axes))
    (folder / f"{MARKER}.csv").write_text(f"{MARKER},q1,tau1\n1,2,3\n")
    (folder / "secret.csv").write_text(f"{MARKER}\n1,2,3\n")
    return folder


def _import(logs: Path, out: Path, *extra: str):
    return runner.invoke(app, ["logs", "import", str(logs), "--robot", "puma560", "-o", str(out), "--no-progress",
                               *extra])


def _refused(result, link: Path, outside: Path):
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output, result.output
    line = result.output.strip().splitlines()[-1]
    assert line.startswith(f"error: {link}: ") and LINKS_RULE in line, result.output
    assert MARKER not in result.output and str(outside) not in result.output, result.output


def test_a_unit_folder_linked_outside_is_refused_naming_it(logs, outside, tmp_path):
    (logs / "u3").symlink_to(outside, target_is_directory=True)
    with pytest.raises(ValueError, match=LINKS_RULE) as err:
        logfolder.scan(logs, fleetlogs.SUFFIXES)
    message = str(err.value)
    assert message.startswith(f"{logs / 'u3'}: ") and MARKER not in message and "2026-04-01" not in message
    with pytest.raises(ValueError, match=LINKS_RULE):
        fleet_logs.fleet(logs)
    _refused(_import(logs, tmp_path / "f.h5"), logs / "u3", outside)
    _refused(_import(logs, tmp_path / "f.h5", "--skip-bad"), logs / "u3", outside)
    assert not (tmp_path / "f.h5").exists()
    result = runner.invoke(app, ["monitor", str(logs), "--robot", "puma560", "-o", str(tmp_path / "mon"),
                                 "--protocol", "own"])
    _refused(result, logs / "u3", outside)
    assert not (tmp_path / "mon").exists()


def test_a_log_linked_outside_is_refused_and_its_first_line_never_echoed(logs, outside, tmp_path):
    link = logs / "u1" / "2026-03-09.csv"
    link.symlink_to(outside / "secret.csv")
    units, bad = logfolder.scan(logs, fleetlogs.SUFFIXES)
    assert [g.name for g in units["u1"]] == ["u1/2026-03-01.csv", "u1/2026-03-02.csv", "u1/2026-03-03.csv"]
    assert [name for name, _ in bad] == ["u1/2026-03-09.csv"] and LINKS_RULE in bad[0][1]
    with pytest.raises(ValueError, match=LINKS_RULE) as err:
        fleetlogs.import_logs(logs, tmp_path / "f.h5", robot="puma560", progress=False)
    assert str(err.value).startswith(f"{link}: ") and MARKER not in str(err.value)
    with pytest.raises(ValueError, match=LINKS_RULE) as err:
        fleet_logs.fleet(logs)
    assert str(err.value).startswith(f"{link}: ") and MARKER not in str(err.value)
    _refused(_import(logs, tmp_path / "f.h5"), link, outside)
    assert not (tmp_path / "f.h5").exists()
    # --skip-bad passes over it, listed, never read
    result = _import(logs, tmp_path / "f.h5", "--skip-bad")
    assert result.exit_code == 0, result.output
    assert "u1/2026-03-09.csv: " in result.output and LINKS_RULE in result.output and "imported now:  6" in result.output
    assert MARKER not in result.output and str(outside) not in result.output
    # a link to a log named like the marker: not even its name is echoed
    link.unlink()
    link.symlink_to(outside / f"{MARKER}.csv")
    _refused(_import(logs, tmp_path / "g.h5"), link, outside)


def test_events_linked_outside_are_refused_and_never_echoed(logs, outside, tmp_path):
    (logs / "events.csv").symlink_to(outside / "secret.csv")
    with pytest.raises(ValueError, match=LINKS_RULE) as err:
        logfolder.scan(logs, fleetlogs.SUFFIXES)
    assert str(err.value).startswith(f"{logs / 'events.csv'}: ") and MARKER not in str(err.value)
    # the events reader refuses it on its own too (before reading the header it would quote)
    units = {"u1": [], "u2": []}
    with pytest.raises(ValueError, match=LINKS_RULE) as err:
        logfolder.read_events(logs / "events.csv", units, 6)
    assert MARKER not in str(err.value)
    with pytest.raises(ValueError, match=LINKS_RULE) as err:
        fleetlogs.import_logs(logs, tmp_path / "f.h5", robot="puma560", progress=False, skip_bad=True)
    assert MARKER not in str(err.value)
    _refused(_import(logs, tmp_path / "f.h5"), logs / "events.csv", outside)
    assert not (tmp_path / "f.h5").exists()


def test_links_that_stay_inside_the_folder_still_work(logs, tmp_path):
    (logs / "u3").symlink_to("u1", target_is_directory=True)  # a unit folder linked to another
    (logs / "u2" / "2026-03-09.csv").symlink_to(Path("..") / "u1" / "2026-03-01.csv")  # a log linked to another
    (logs / ".meta").mkdir()  # hidden: not a unit
    (logs / ".meta" / "events.csv").write_text("unit,stamp,event,axis\nu2,2026-03-09,onset,3\n")
    (logs / "events.csv").symlink_to(Path(".meta") / "events.csv")
    units, bad = logfolder.scan(logs, fleetlogs.SUFFIXES)
    assert bad == [] and sorted(units) == ["u1", "u2", "u3"]
    assert [g.stamp for g in units["u3"]] == [g.stamp for g in units["u1"]]
    assert [g.stamp for g in units["u2"]] == ["2026-03-01", "2026-03-02", "2026-03-03", "2026-03-09"]
    assert sorted(fleet_logs.fleet(logs)) == ["u1", "u2", "u3"]
    result = _import(logs, tmp_path / "f.h5")
    assert result.exit_code == 0, result.output
    assert "3 unit(s), 10 log record(s)" in result.output and "1 worn" in result.output
    with reader.open(tmp_path / "f.h5") as data:
        np.testing.assert_array_equal(data["u3"].array("rms_torque"), data["u1"].array("rms_torque"))
        np.testing.assert_array_equal(data["u2"].array("rms_torque")[3], data["u1"].array("rms_torque")[0])
        assert data["u2"].worn_axes == (3,)


def _strings(path: Path) -> list[str]:
    """Every attribute value and every string dataset of an HDF5 file, as text."""
    found = []

    def text(value) -> list[str]:
        values = np.ravel(np.asarray(value, dtype=object))
        return [v.decode(errors="replace") if isinstance(v, bytes) else str(v) for v in values]

    def visit(name, obj):
        found.append(name)
        for key, value in obj.attrs.items():
            found.extend([key, *text(value)])
        if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "OSU":
            found.extend(text(obj[()]))

    with h5py.File(path, "r") as f:
        visit("/", f)
        f.visititems(visit)
    return found


def test_an_imported_dataset_holds_no_absolute_path_of_the_logs_folder(logs, tmp_path, monkeypatch):
    absolute = [str(tmp_path), str(tmp_path.resolve())]
    out = tmp_path / "lib.h5"
    fleetlogs.import_logs(logs, out, robot="puma560", progress=False)
    strings = _strings(out)
    assert "u1/2026-03-01.csv" in strings  # the manifest names the logs relative to LOGS
    assert not [s for s in strings if any(a in s for a in absolute)]
    with h5py.File(out, "r") as f:
        assert f["import"].attrs["logs"] == "LOGS"
    # by the command line, LOGS given as an absolute path (the stored command included)
    monkeypatch.chdir(tmp_path)
    argv = ["logs", "import", str(logs.resolve()), "--robot", "puma560", "-o", "cli.h5", "--no-progress"]
    monkeypatch.setattr(sys, "argv", ["faultgen", *argv])
    result = runner.invoke(app, argv)
    assert result.exit_code == 0, result.output
    strings = _strings(tmp_path / "cli.h5")
    assert not [s for s in strings if any(a in s for a in absolute)], [s for s in strings if str(tmp_path) in s]
    with h5py.File(tmp_path / "cli.h5", "r") as f:
        assert "logs import LOGS --robot puma560" in f.attrs["command"]
    result = runner.invoke(app, ["info", str(tmp_path / "cli.h5")])
    assert result.exit_code == 0 and "measured" in result.output, result.output
