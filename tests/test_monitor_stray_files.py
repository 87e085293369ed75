"""One stray file or one bad row of events.csv stops no fleet (issue 88, item 2): a file in a unit
folder that is not a log (``notes.txt``, ``backup copy.csv``) is passed over and named, a bad row of
events.csv (a typo'd event) stops its unit only, naming the row, and every other output is byte for
byte that of the run without them. A small synthetic fleet (tests/fleetlog_folder.py), protocol own."""

from __future__ import annotations

import csv
import os
import sys
from pathlib import Path

from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.model import robots
from faultgen.monitor import loop

sys.path.insert(0, str(Path(__file__).parent))
import fleetlog_folder  # noqa: E402

runner = CliRunner()
GOOD_EVENTS = "unit,stamp,event,axis\nu3,2026-03-09,repair,2\n"
OUTPUTS = ("alarms.csv", "scores.csv", "wear.csv", "rul.csv", "life.csv", "units.csv")


def _monitor(logs: Path, out: Path):
    return runner.invoke(app, ["monitor", str(logs), "--robot", "puma560", "-o", str(out), "--protocol", "own",
                               "--train", "10", "--persistence", "2"])


def _rows(path: Path) -> dict[str, list[dict]]:
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {unit: [r for r in rows if r["unit"] == unit] for unit in {r["unit"] for r in rows}}


def _linked(logs: Path, copy: Path) -> Path:
    for unit in sorted(p for p in logs.iterdir() if p.is_dir()):
        (copy / unit.name).mkdir(parents=True)
        for log in unit.iterdir():
            os.link(log, copy / unit.name / log.name)
    return copy


def test_a_stray_file_and_a_bad_events_row_stop_nothing_else_and_are_named(tmp_path):
    logs = fleetlog_folder.write_fleet(tmp_path / "clean" / "LOGS", robots.load("puma560"), units=3, days=12,
                                       worn={0: (2, 4, 0.05)})
    (logs / "events.csv").write_text(GOOD_EVENTS)
    clean = tmp_path / "clean" / "out"
    result = _monitor(logs, clean)
    assert result.exit_code == 0, result.output

    stray = _linked(logs, tmp_path / "stray" / "LOGS")
    (stray / "u1" / "notes.txt").write_text("the operator's notes\n")
    os.link(logs / "u1" / "2026-03-05.csv", stray / "u1" / "backup copy.csv")  # a log's bytes under no stamp
    (stray / "u3" / "friction-test").mkdir()
    (stray / "u3" / "friction-test" / "readme.md").write_text("tests go here\n")  # no test yet: as no folder
    (stray / "events.csv").write_text(GOOD_EVENTS + "u2,2026-03-04,replaced,1\nu9,2026-03-04,repair,1\n")
    out = tmp_path / "stray" / "out"
    result = _monitor(stray, out)
    assert result.exit_code == loop.EXIT_SOME_UNITS_NOT_MONITORED, result.output
    units = {u: rows[0] for u, rows in _rows(out / "units.csv").items()}
    # the bad row stops its unit only, named by its line
    assert units["u2"]["status"] == "not monitored" and units["u2"]["logs_scored"] == "0", units["u2"]
    assert units["u2"]["reason"].startswith("not monitored: events.csv: line 3: event 'replaced'; expected one of "
                                            "onset, failure, repair, gearbox_change, healthy"), units["u2"]
    # the stray files are passed over and named in their unit's reason, its status as without them
    before = {u: rows[0] for u, rows in _rows(clean / "units.csv").items()}
    named = ("2 files passed over, not logs: u1/backup copy.csv: stamp 'backup copy' is neither an ISO date "
             "(2026-03-01), an ISO date and time (2026-03-01T08:30:00 or 2026-03-01T08-30-00) nor a sequence "
             "number (17) (and 1 more)")
    assert units["u1"] == {**before["u1"], "reason": "; ".join(filter(None, (before["u1"]["reason"], named)))}
    assert before["u1"]["status"] == "monitored"
    assert units["u3"] == {**before["u3"], "reason": "; ".join(filter(None, (
        before["u3"]["reason"], "1 files passed over, not logs: u3/friction-test/readme.md: not a friction test: "
                                "expected <stamp>.csv or <stamp>.csv.gz or <stamp>.h5 or <stamp>.hdf5")))}, units["u3"]
    # and on the console, with the events row that names no unit
    assert "passed over 4 entries of the logs folder: u1/backup copy.csv: stamp 'backup copy'" in result.output
    assert "(and 3 more)" in result.output
    assert "u2: not monitored (own): events.csv: line 3: event 'replaced'" in result.output
    # every other unit's outputs: byte for byte those of the run without the stray file and the bad row
    for name in OUTPUTS[:-1]:
        a, b = _rows(clean / name), _rows(out / name)
        assert a.keys() - {"u2"} == b.keys() - {"u2"} and ("u1" in a or name == "wear.csv"), name
        for unit in ("u1", "u3"):
            assert b.get(unit) == a.get(unit), (name, unit)
        assert "u2" not in b or all(not r.get("stamp") and not r.get("first_alarm") for r in b["u2"]), (name, b["u2"])
    for unit in ("u1", "u3"):
        assert (out / f"{unit}.png").read_bytes() == (clean / f"{unit}.png").read_bytes(), unit

    # the row corrected: the stopped unit is scored as in the clean run, the others kept
    (stray / "events.csv").write_text(GOOD_EVENTS)
    for path in ("u1/notes.txt", "u1/backup copy.csv", "u3/friction-test/readme.md"):
        (stray / path).unlink()
    result = _monitor(stray, out)
    assert result.exit_code == 0, result.output
    for name in OUTPUTS:
        assert (out / name).read_bytes() == (clean / name).read_bytes(), name


def test_a_stray_file_at_the_top_of_the_logs_folder_is_passed_over_and_named(tmp_path):
    logs = fleetlog_folder.write_fleet(tmp_path / "clean" / "LOGS", robots.load("puma560"), units=2, days=4)
    clean = tmp_path / "clean" / "out"
    assert _monitor(logs, clean).exit_code == 0
    stray = _linked(logs, tmp_path / "stray" / "LOGS")
    (stray / "notes.txt").write_text("the operator's notes\n")
    out = tmp_path / "stray" / "out"
    result = _monitor(stray, out)
    assert result.exit_code == 0, result.output
    assert ("passed over 1 entries of the logs folder: notes.txt: not a log: a file at the top of the logs folder; "
            "expected one folder per unit") in result.output
    for name in OUTPUTS:  # every unit as without it
        assert (out / name).read_bytes() == (clean / name).read_bytes(), name
    # `logs import` lists it with the other bad files: refused naming it, or passed over with --skip-bad
    result = runner.invoke(app, ["logs", "import", str(stray), "--robot", "puma560", "-o", str(tmp_path / "f.h5")])
    assert result.exit_code == 2 and f"{stray / 'notes.txt'}: not a log: a file at the top" in result.output, \
        result.output
