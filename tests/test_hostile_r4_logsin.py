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
