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
