"""A continued ``faultgen monitor`` run reads ``events.csv`` again (issue 90, item 6): an event
added, changed or removed since the last run re-scores its unit from its first log, and every
output equals a fresh run's on the same folder, byte for byte (the tree compared as
benchmarks/golden_monitor.py compares it: all but ``.cache`` and ``.state``); a unit whose events
did not change keeps its state (its scored logs are not scored again)."""

import os
import shutil
from pathlib import Path

import independent_fleet
import pytest

from faultgen.monitor import console, feed, loop
from faultgen.monitor.run import resolve_run
from faultgen.monitor.scoring import Settings

# two units, 20 days, one worn from day 11-12 (small: the twin's cycles simulated once, then copied)
SPEC = independent_fleet.FleetSpec(units=2, worn=1, days=20, seed=7, onset=(11, 12))
SETTINGS = Settings(train=10, persistence=2)
FIRST, ALL, DAY = 15, 20, 12  # the first run's logs, the second's; the event's day (index)
SKIPPED = (".cache", ".state")  # as benchmarks/golden_monitor.py


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    root = tmp_path_factory.mktemp("fleet")
    robot, logs, _ = independent_fleet.write_fleet(root, SPEC)
    units = sorted(p.name for p in logs.iterdir() if p.is_dir())
    cycles = tmp_path_factory.mktemp("cycles") / "out"
    loop.monitor(resolve_run(robot, logs, cycles, calibrate=False, settings=SETTINGS, progress=False))
    return robot, logs, units, cycles


def _tree(out: Path) -> dict[str, bytes]:
    return {str(p.relative_to(out)): p.read_bytes() for p in sorted(out.rglob("*"))
            if p.is_file() and p.relative_to(out).parts[0] not in SKIPPED}


def _folder(logs: Path, root: Path, units: list[str], days: int, events: str | None) -> Path:
    """``root`` holding each unit's first ``days`` logs (hard links) and ``events`` as events.csv."""
    for unit in units:
        (root / unit).mkdir(parents=True, exist_ok=True)
        for log in sorted((logs / unit).iterdir())[:days]:
            if not (root / unit / log.name).exists():
                os.link(log, root / unit / log.name)
    if events is None:
        (root / "events.csv").unlink(missing_ok=True)
    else:
        (root / "events.csv").write_text(events)
    return root


def _run(fleet, logs: Path, out: Path, cycles_from: Path):
    robot = fleet[0]
    if not (out / ".cache").exists():
        shutil.copytree(cycles_from / ".cache" / "cycles", out / ".cache" / "cycles")
    return loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False))


def _stamps(logs: Path, unit: str) -> list[str]:
    return [p.name.split(".")[0] for p in sorted((logs / unit).iterdir())]


@pytest.mark.parametrize("case", ["removed", "added"])
def test_an_event_changed_since_the_last_run_gives_a_fresh_runs_outputs(fleet, tmp_path, case):
    robot, logs, units, cycles = fleet
    unit = units[-1]  # not the first unit: its twin replays the first unit's program in a fresh run
    stamps = _stamps(logs, unit)
    header = "unit,stamp,event,axis\n"
    wrong = f"{header}{unit},{stamps[DAY]},gearbox_change,2\n"
    first, then = {"removed": (wrong, header), "added": (None, wrong)}[case]
    folder = _folder(logs, tmp_path / "logs", units, FIRST, first)
    out = tmp_path / "continued"
    _run(fleet, folder, out, cycles)
    folder = _folder(logs, folder, units, ALL, then)  # the file corrected, and five days more
    outcome = _run(fleet, folder, out, cycles)
    assert outcome.rescored == [(unit, stamps[DAY])]
    lines, _ = console.summary(outcome, SETTINGS, out)
    assert lines[0] == (f"events.csv changed for {unit} since the last run: re-scored from its first log "
                        f"(the earliest event added, changed or removed: {stamps[DAY]})")
    fresh = tmp_path / "fresh"
    assert not _run(fleet, folder, fresh, cycles).rescored
    got, want = _tree(out), _tree(fresh)
    assert sorted(got) == sorted(want)
    assert [name for name in want if got[name] != want[name]] == []
    if case == "removed":  # the wrong gearbox change left no trace: no alarm closed by it, nothing relearned
        assert b"gearbox_change" not in got["alarms.csv"] and b"relearning" not in got["scores.csv"]


def test_an_unchanged_events_csv_keeps_the_state_and_scores_only_the_new_logs(fleet, tmp_path, monkeypatch):
    robot, logs, units, cycles = fleet
    unit = units[-1]
    events = f"unit,stamp,event,axis\n{unit},{_stamps(logs, unit)[DAY]},gearbox_change,2\n"
    folder = _folder(logs, tmp_path / "logs", units, FIRST, events)
    out = tmp_path / "continued"
    _run(fleet, folder, out, cycles)
    scored: list[str] = []
    score_log = feed.score_log

    def counted(unit, log, *args, **kwargs):
        scored.append(f"{unit.unit}/{log.stamp}")
        return score_log(unit, log, *args, **kwargs)

    monkeypatch.setattr(feed, "score_log", counted)
    folder = _folder(logs, folder, units, ALL, events)  # the same events, five days more
    outcome = _run(fleet, folder, out, cycles)
    assert outcome.rescored == []
    assert scored == [f"{u}/{s}" for u in units for s in _stamps(logs, u)[FIRST:ALL]]
    # an event added on a day already scored re-scores that unit alone, all its logs
    scored.clear()
    stamps = _stamps(logs, units[0])
    folder = _folder(logs, folder, units, ALL, events + f"{units[0]},{stamps[DAY + 1]},repair,1\n")
    assert _run(fleet, folder, out, cycles).rescored == [(units[0], stamps[DAY + 1])]
    assert scored == [f"{units[0]}/{s}" for s in stamps]
