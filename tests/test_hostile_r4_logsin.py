"""Hostile log folders, events and monitor OUT folders (issue 71, round 4, group logsin): an
events.csv of many repairs costs time linear in its rows; an import keys a log by its unit and
stamp, never its file name; a log that changed or vanished after it was scored is skipped and
named, never fatal to the fleet or its OUT; a unit whose name makes a file name too long is
monitored under a bounded name; every value read from a monitor state or its settings is one a run
writes. Small synthetic fleets (tests/fleetlog_folder.py), protocol own."""

from __future__ import annotations

import sys
import time
from datetime import datetime, timedelta, timezone
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.model import robots

sys.path.insert(0, str(Path(__file__).parent))
import fleetlog_folder

runner = CliRunner()
ROBOT = "puma560"


@pytest.fixture(scope="module")
def puma():
    return robots.load(ROBOT)


def _fleet(folder: Path, puma, units: int = 1, days: int = 4) -> Path:
    return fleetlog_folder.write_fleet(folder / "LOGS", puma, units=units, days=days)


def _monitor(logs: Path, out: Path, *extra: str):
    return runner.invoke(app, ["monitor", str(logs), "--robot", ROBOT, "-o", str(out), "--protocol", "own", *extra])


def _repairs(path: Path, n: int) -> None:
    """``n`` distinct repairs of u1 on the fleet's first day, one a second, axes in turn."""
    start = datetime(2026, 3, 1, tzinfo=timezone.utc)
    rows = [f"u1,{(start + timedelta(seconds=i)).strftime('%Y-%m-%dT%H:%M:%S')},repair,{1 + i % 6}" for i in range(n)]
    path.write_text("unit,stamp,event,axis\n" + "\n".join(rows) + "\n")


def test_many_repairs_in_events_csv_cost_time_linear_in_their_number(tmp_path, puma):
    logs = _fleet(tmp_path, puma)
    seconds = {}
    for n in (1000, 16000):
        _repairs(logs / "events.csv", n)
        out = tmp_path / f"out{n}"
        start = time.perf_counter()
        done = _monitor(logs, out)
        seconds[n] = time.perf_counter() - start
        assert done.exit_code in (0, 3), done.output
        assert (out / ".state" / "u1.json").read_text().count('"repair"') == n  # every repair given once
    # 16 times the rows: a cost linear in them (and the run's fixed cost) well within 20 times; one
    # growing with their square 256 times
    assert seconds[16000] < 20 * seconds[1000], seconds


def _gzip(path: Path) -> Path:
    """``path`` replaced by ``path.gz`` of the same content (``gzip FILE``)."""
    import gzip

    packed = path.with_name(path.name + ".gz")
    packed.write_bytes(gzip.compress(path.read_bytes()))
    path.unlink()
    return packed


def _stamps(dataset: Path, unit: str) -> list[str]:
    import h5py

    with h5py.File(dataset) as f:
        return [s.decode() for s in f["runs"][unit]["stamp"][()]]


def test_a_log_gzipped_after_its_import_is_the_same_log_not_a_second_record(tmp_path, puma):
    logs = _fleet(tmp_path, puma, days=3)
    out = tmp_path / "f.h5"
    assert runner.invoke(app, ["logs", "import", str(logs), "--robot", ROBOT, "-o", str(out), "--no-progress"]).exit_code == 0
    packed = _gzip(logs / "u1" / "2026-03-02.csv")
    again = runner.invoke(app, ["logs", "import", str(logs), "--robot", ROBOT, "-o", str(out), "--no-progress"])
    assert again.exit_code == 0 and "nothing new" in again.output, again.output
    assert _stamps(out, "u1") == ["2026-03-01", "2026-03-02", "2026-03-03"]
    assert runner.invoke(app, ["validate", str(out)]).exit_code == 0
    # another content under the gzipped name: changed, named with the name it was imported as
    fleetlog_folder.write_log(packed, puma, 1, 0, np.full(puma.n_axes, 0.5))
    changed = runner.invoke(app, ["logs", "import", str(logs), "--robot", ROBOT, "-o", str(out), "--no-progress"])
    assert changed.exit_code == 2 and f"{packed} changed since it was imported as u1/2026-03-02.csv" in changed.output, \
        changed.output
    redone = runner.invoke(app, ["logs", "import", str(logs), "--robot", ROBOT, "-o", str(out), "--no-progress",
                                 "--reimport-changed"])
    assert redone.exit_code == 0, redone.output
    assert _stamps(out, "u1") == ["2026-03-01", "2026-03-02", "2026-03-03"]
    assert runner.invoke(app, ["validate", str(out)]).exit_code == 0
    # the plain log back beside the gzipped one: two files of one stamp, refused by name
    fleetlog_folder.write_log(logs / "u1" / "2026-03-02.csv", puma, 1, 0, np.zeros(puma.n_axes))
    both = runner.invoke(app, ["logs", "import", str(logs), "--robot", ROBOT, "-o", str(out), "--no-progress"])
    assert both.exit_code == 2 and "u1/2026-03-02.csv and u1/2026-03-02.csv.gz have the same stamp" in both.output, \
        both.output


def _units_csv(out: Path) -> dict[str, dict]:
    import csv

    with open(out / "units.csv", newline="") as fh:
        return {row["unit"]: row for row in csv.DictReader(fh)}


def test_a_scored_log_gzipped_changed_or_gone_and_a_late_log_are_named_never_fatal(tmp_path, puma):
    logs = _fleet(tmp_path, puma, units=2, days=3)
    out = tmp_path / "OUT"
    assert _monitor(logs, out).exit_code == 0
    _gzip(logs / "u1" / "2026-03-02.csv")  # the same content: the same log
    fleetlog_folder.write_log(logs / "u1" / "2026-03-04.csv", puma, 3, 0, np.zeros(puma.n_axes))
    done = _monitor(logs, out)
    assert done.exit_code == 0, done.output
    assert _units_csv(out)["u1"]["logs_scored"] == "4" and "changed" not in _units_csv(out)["u1"]["reason"]
    # a scored log rewritten (caught mid-write), the last one gone, a late one: named, the rest scored
    fleetlog_folder.write_log(logs / "u1" / "2026-03-01.csv", puma, 0, 9, np.full(puma.n_axes, 0.5))
    (logs / "u1" / "2026-03-04.csv").unlink()
    fleetlog_folder.write_log(logs / "u1" / "2026-02-27.csv", puma, 0, 0, np.zeros(puma.n_axes))
    fleetlog_folder.write_log(logs / "u1" / "2026-03-05.csv", puma, 4, 0, np.zeros(puma.n_axes))
    fleetlog_folder.write_log(logs / "u2" / "2026-03-04.csv", puma, 3, 1, np.zeros(puma.n_axes))
    done = _monitor(logs, out)
    assert done.exit_code == 3 and "Traceback" not in done.output, done.output
    units = _units_csv(out)
    reason = units["u1"]["reason"]
    assert units["u1"]["status"] == "degraded" and units["u1"]["logs_scored"] == "5", units
    assert "changed since an earlier run scored or skipped them (its results kept): u1/2026-03-01.csv" in reason
    assert "now gone from the logs folder (its results kept): 2026-03-04" in reason
    assert "older than the last log scored, not scored (logs are scored in stamp order): u1/2026-02-27.csv" in reason
    assert units["u2"]["logs_scored"] == "4" and units["u2"]["status"] == "learning", units


def test_a_log_deleted_during_the_run_is_skipped_and_named_and_the_fleet_finishes(tmp_path, puma, monkeypatch):
    from faultgen.monitor import loop

    logs = _fleet(tmp_path, puma, units=2, days=3)
    listed = loop.fleet_logs.fleet

    def listed_then_deleted(*args, **kwargs):
        units = listed(*args, **kwargs)
        (logs / "u2" / "2026-03-02.csv").unlink()  # gone after the folder was listed
        return units

    monkeypatch.setattr(loop.fleet_logs, "fleet", listed_then_deleted)
    done = _monitor(logs, tmp_path / "OUT")
    assert done.exit_code == 3 and isinstance(done.exception, (SystemExit, type(None))), done.output
    units = _units_csv(tmp_path / "OUT")
    assert units["u1"]["logs_scored"] == "3" and units["u2"]["logs_scored"] == "2", units
    assert "1 logs skipped: 2026-03-02:" in units["u2"]["reason"] and "cannot be read" in units["u2"]["reason"], units


def test_a_unit_named_to_the_longest_file_name_is_monitored_under_a_bounded_name(tmp_path, puma):
    from faultgen.monitor import state

    logs = _fleet(tmp_path, puma, units=2, days=3)
    long = "w" * 251  # the folder may be named so (255 bytes at most); "<name>.json" may not
    (logs / "u2").rename(logs / long)
    out = tmp_path / "OUT"
    done = _monitor(logs, out)
    assert done.exit_code == 0 and "Traceback" not in done.output, done.output
    assert _units_csv(out)[long]["logs_scored"] == "3"
    name = state.unit_file(long, ".json")
    assert len(name.encode()) <= state.UNIT_FILE_MAX_BYTES + 32 and (out / ".state" / name).is_file()
    assert (out / state.unit_file(long, ".png")).is_file()
    fleetlog_folder.write_log(logs / long / "2026-03-04.csv", puma, 3, 1, np.zeros(puma.n_axes))
    again = _monitor(logs, out)  # the state found again under the same name
    assert again.exit_code == 0 and _units_csv(out)[long]["logs_scored"] == "4", again.output


@pytest.fixture(scope="module")
def monitored(tmp_path_factory, puma) -> Path:
    """A protocol-own monitor OUT of a small fleet (two units, three logs), for its files to be planted."""
    root = tmp_path_factory.mktemp("monitored")
    logs = _fleet(root, puma, units=2, days=3)
    assert _monitor(logs, root / "OUT").exit_code == 0
    return root / "OUT"


def _copy(out: Path, tmp_path: Path) -> Path:
    import shutil

    return Path(shutil.copytree(out, tmp_path / "OUT"))


@pytest.mark.parametrize(("key", "value", "said"), [
    ("train", -5, "train = -5; expected a whole number of logs 10..100000"),
    ("alpha", 1e999, "alpha = Infinity; expected a significance level in (0, 0.5)"),
    ("persistence", 10**30, "persistence = 1000000000000000000000000000000; expected a whole number of logs"),
    ("persistence", 5.5, "persistence = 5.5; expected a whole number"),
    ("wear_limit", 0, "wear_limit = 0; expected a wear in (0, 1000] %"),
    ("protocol", "=HYPERLINK(1)", 'protocol = "=HYPERLINK(1)"; expected one of twin, own'),
    ("twin_temperature", 1, "twin_temperature = 1; expected true or false"),
    ("verbose", True, "key 'verbose' is not a monitor setting"),
])
def test_a_planted_settings_value_is_refused_naming_the_file_and_key(monitored, tmp_path, key, value, said):
    import json

    out = _copy(monitored, tmp_path)
    settings = json.loads((out / "settings.json").read_text())
    settings[key] = value
    (out / "settings.json").write_text(json.dumps(settings))
    done = runner.invoke(app, ["report", str(out)])
    assert done.exit_code == 2 and f"settings.json: {said}" in done.output, done.output
    assert not isinstance(done.exception, (OverflowError, TypeError)), done.exception


def test_a_planted_settings_value_is_a_one_line_refusal_under_the_cap(monitored, tmp_path):
    import capped

    out = _copy(monitored, tmp_path)
    (out / "settings.json").write_text((out / "settings.json").read_text().replace('"persistence": 5',
                                                                                   '"persistence": 1e999'))
    capped.one_line_refusal(capped.run("report", out, cwd=tmp_path), "settings.json", "persistence")


def _plant(state: dict, where: str, value) -> None:
    """Set ``state``'s value at ``where`` (``logs.1.temperature_C``: keys and list positions)."""
    *path, last = where.split(".")
    node = state
    for part in path:
        node = node[int(part)] if isinstance(node, list) else node[part]
    node[int(last) if isinstance(node, list) else last] = value


@pytest.mark.parametrize(("where", "value", "said"), [
    ("logs.1.temperature_C", float("inf"), "logs[1].temperature_C is infinite; expected a finite number, or NaN"),
    ("maintenance", [{"stamp": "2026-03-02", "event": "repair", "axis": 10**18, "at": 1}],
     "maintenance[0].axis = 1000000000000000000; expected an axis 1..6"),
    ("maintenance", [{"stamp": "2026-03-02", "event": '=HYPERLINK("http://x")', "axis": 1, "at": 1}],
     "maintenance[0].event = '=HYPERLINK(\"http://x\")'; expected one of repair, gearbox_change"),
    ("maintenance", [{"stamp": "2026-03-02", "event": "repair", "axis": 1, "at": 99}],
     "maintenance[0].at = 99, after the 3 logs scored"),
    ("maintenance", [{"stamp": "yesterday", "event": "repair", "axis": 1, "at": 1}],
     "maintenance[0].stamp: stamp 'yesterday' is neither"),
    ("logs.1.stamp", "2026-02-30", "logs[1].stamp: stamp '2026-02-30' is neither"),
    ("logs.1.stamp", "2026-02-28", "logs[1].stamp '2026-02-28' is not after logs[0]'s"),
    ("logs.1.stamp", "2026-03-01", "logs[1] has the stamp of logs[0]"),
    ("logs.0.sha256", "=" * 64, "logs[0].sha256 is not a SHA-256"),
    ("skipped", [{"stamp": "2026-03-02", "sha256": "0" * 64, "reason": "planted"}],
     "logs[1] has the stamp of skipped[0]"),
    ("first.0", "=cmd|' /C calc'!A0", "first[0]: stamp"),
])
def test_a_planted_state_value_no_run_writes_is_refused_naming_the_file_and_value(monitored, tmp_path, where, value,
                                                                                   said):
    import json

    out = _copy(monitored, tmp_path)
    path = out / ".state" / "u1.json"
    state = json.loads(path.read_text())
    _plant(state, where, value)
    path.write_text(json.dumps(state))
    done = _monitor(monitored.parent / "LOGS", out)
    assert done.exit_code == 2 and f"u1.json: {said}" in done.output, done.output


def test_an_infinite_temperature_in_a_state_is_a_one_line_refusal_under_the_cap(monitored, tmp_path):
    import capped

    out = _copy(monitored, tmp_path)
    path = out / ".state" / "u2.json"
    path.write_text(path.read_text().replace('"temperature_C":NaN', '"temperature_C":Infinity', 1))
    done = capped.run("monitor", monitored.parent / "LOGS", "--robot", ROBOT, "-o", out, "--protocol", "own",
                      cwd=tmp_path)
    capped.one_line_refusal(done, "u2.json", "temperature_C")


def test_a_log_deleted_during_an_import_is_skipped_and_named(tmp_path, puma, monkeypatch):
    from faultgen.data import fleetlogs

    logs = _fleet(tmp_path, puma, units=2, days=3)
    listed = fleetlogs.logfolder.scan
    hashed = fleetlogs.sha256

    def listed_then_deleted(*args, **kwargs):
        units = listed(*args, **kwargs)
        (logs / "u1" / "2026-03-02.csv").unlink()  # gone after the folder was listed
        return units

    def hashed_then_deleted(path):
        digest = hashed(path)
        if path.name == "2026-03-03.csv" and path.parent.name == "u2":
            path.unlink()  # gone after it was hashed, before it was read
        return digest

    monkeypatch.setattr(fleetlogs.logfolder, "scan", listed_then_deleted)
    monkeypatch.setattr(fleetlogs, "sha256", hashed_then_deleted)
    done = runner.invoke(app, ["logs", "import", str(logs), "--robot", ROBOT, "-o", str(tmp_path / "f.h5"),
                               "--no-progress"])
    assert done.exit_code == 0, done.output
    assert "u1/2026-03-02.csv: removed from the folder while it was imported" in done.output
    assert "u2/2026-03-03.csv: removed from the folder while it was imported" in done.output
    assert _stamps(tmp_path / "f.h5", "u1") == ["2026-03-01", "2026-03-03"]
    assert _stamps(tmp_path / "f.h5", "u2") == ["2026-03-01", "2026-03-02"]
