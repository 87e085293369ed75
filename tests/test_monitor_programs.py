"""Several programs a unit and logs cut anywhere, in the monitor (issue 90 items 1-2:
faultgen.monitor.programs, faultgen.monitor.feed.place): a unit alternating two programs is
monitored, reports one program change (on the day it first meets the second program), simulates
each program's twin once (not once a log), scores its logs cut at a random phase on their whole
cycles, skips a log with no whole cycle with its reason, and does not take a ``cycle`` column's
0.072 s first run for a cycle. The cell is made by the independent generator
(faultgen.bench.independent: Pinocchio's dynamics, its own friction law), one unit of 26 days."""

import csv
import json
import re

import numpy as np
import pinocchio_log
import pytest

from faultgen.bench import independent
from faultgen.logs import align
from faultgen.monitor import feed, loop, programs
from faultgen.monitor import state as stored
from faultgen.monitor import unit as unit_module
from faultgen.monitor.run import resolve_run
from faultgen.monitor.scoring import Settings

RATE = 125.0
#: One unit running the cell's two programs in turn, logs of 1.5-3 cycles from a random phase.
CELL = independent.FleetSpec(units=1, worn=0, days=26, onset=(2, 3), rate=RATE, seed=5, programs=2,
                             unit_programs=(2,), span=(1.5, 3.0))
SETTINGS = Settings(train=10, persistence=3)
#: A ``cycle`` column's first run, s (the issue's log whose column starts with a fragment).
FRAGMENT = 0.072


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def _with_cycle_column(path, period: float) -> None:
    """Add a ``cycle`` column to the log at ``path``: a first run of :data:`FRAGMENT` s, then runs of
    ``period`` s (the column's runs do not start where the program's cycles do)."""
    lines = path.read_text().splitlines()
    t = np.array([float(line.split(",", 1)[0]) for line in lines[1:]])
    cycle = np.where(t - t[0] < FRAGMENT - 0.5 / RATE, 0, 1 + np.floor((t - t[0] - FRAGMENT) / period + 1e-9))
    path.write_text("\n".join([lines[0] + ",cycle", *(f"{line},{int(c)}" for line, c in zip(lines[1:], cycle))]) + "\n")


@pytest.fixture(scope="module")
def cell(tmp_path_factory):
    """The cell's logs (the first log with a cycle column whose first run is 0.072 s, a late log cut to
    0.6 of a cycle), the truth and the monitor's outcome, with the twins it made."""
    root = tmp_path_factory.mktemp("programs")
    robot = pinocchio_log.add_kr210(root / "kr210")
    logs, _ = independent.write_fleet(root / "fleet", CELL, robot)
    truth = _rows(root / "fleet" / "truth_programs.csv")
    paths = sorted((logs / "unit01").glob("*.csv"))
    first = np.loadtxt(paths[0], delimiter=",", skiprows=1)
    period = float(programs.reference_of(first[:, 0], first[:, 1:7]).period)
    _with_cycle_column(paths[0], period)
    short = np.loadtxt(paths[-2], delimiter=",", skiprows=1)
    header = paths[-2].read_text().splitlines()[0]
    keep = short[short[:, 0] - short[0, 0] < 0.6 * period]
    np.savetxt(paths[-2], keep, delimiter=",", header=header, comments="", fmt="%.6f")
    made = []
    real = feed.Twin

    class Counted(real):
        def __init__(self, *args, **kwargs):
            made.append(args[1])
            super().__init__(*args, **kwargs)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(feed, "Twin", Counted)
        patch.setattr(unit_module, "Twin", Counted)
        outcome = loop.monitor(resolve_run(robot, logs, root / "out", calibrate=False, settings=SETTINGS,
                                           progress=False))
    return {"root": root, "logs": logs, "truth": truth, "out": root / "out", "outcome": outcome, "made": made,
            "period": period, "short": paths[-2].stem}


def test_the_cell_alternates_two_programs(cell):
    programs_run = [r["program"] for r in cell["truth"]]
    assert len(set(programs_run)) == 2 and programs_run.count(programs_run[0]) < len(programs_run) - 3


def test_a_unit_alternating_two_programs_is_monitored_with_one_program_change(cell):
    (row,) = _rows(cell["out"] / "units.csv")
    assert row["status"] == "degraded"  # its one log cut to 0.6 of a cycle is skipped, named
    truth = cell["truth"]
    second = next(r["stamp"] for r in truth if r["program"] != truth[0]["program"])
    assert re.findall(r"program changed at (\S+) ", row["reason"]) == [second]
    logs = len(truth) - 1  # all but the log cut short
    assert int(row["logs_scored"]) == logs
    counts = [int(n) for n in re.findall(r"program \d: (\d+) logs", row["reason"])]
    first = sum(r["program"] == truth[0]["program"] for r in truth if r["stamp"] != cell["short"])
    assert counts == [first, logs - first]
    scores = _rows(cell["out"] / "scores.csv")
    assert [r["stamp"] for r in scores] == sorted(r["stamp"] for r in scores)
    assert {r["phase"] for r in scores} >= {"training", "monitoring"}
    monitoring = [r for r in scores if r["phase"] == "monitoring"]
    assert len(monitoring) == logs - 2 * SETTINGS.train  # both programs learned, every later log scored


def test_each_programs_twin_is_made_once_not_once_a_log(cell):
    assert len(cell["made"]) == 2


def test_a_log_with_no_whole_cycle_is_skipped_with_its_reason(cell):
    (row,) = _rows(cell["out"] / "units.csv")
    assert f"{cell['short']}: no whole cycle of program " in row["reason"]
    assert align.Why.SHORTER_THAN_A_CYCLE.value in row["reason"]
    state = json.loads((cell["out"] / ".state" / stored.unit_file("unit01", ".json")).read_text())
    assert [k["stamp"] for k in state["skipped"]] == [cell["short"]]
    # each log's program in the state: the second program's logs marked 1, the first's unmarked
    truth = {r["stamp"]: r["program"] for r in cell["truth"]}
    first = cell["truth"][0]["program"]
    assert all((log.get("program", 0) == 1) == (truth[log["stamp"]] != first) for log in state["logs"])
    assert [c["stamp"] for c in state["program_changes"]] == [next(s for s, p in truth.items() if p != first)]


def test_a_cycle_column_starting_with_a_0072_s_fragment_is_not_the_cycle(cell):
    first = sorted((cell["logs"] / "unit01").glob("*.csv"))[0]
    data = np.genfromtxt(first, delimiter=",", names=True)
    cycle = data["cycle"].astype(int)
    assert (data["t"][cycle == 0][-1] - data["t"][0]) == pytest.approx(FRAGMENT - 1 / RATE, abs=1e-9)
    t, q = data["t"], np.column_stack([data[f"q{k}"] for k in range(1, 7)])
    reference = programs.reference_of(t, q, cycle)
    assert reference.period == pytest.approx(cell["period"], rel=1e-3) and reference.period > 1.0
    replayed, _, which = programs.first_cycle(t, q, cycle)
    assert replayed[-1] == pytest.approx(cell["period"], abs=2 / RATE)  # one cycle, not 0.072 s
    assert which  # one cycle of a log cut anywhere (its samples, or the reference), not the whole log


def test_a_log_cut_at_a_random_phase_is_scored_on_its_whole_cycles(cell):
    truth = {r["stamp"]: r for r in cell["truth"]}
    first = sorted((cell["logs"] / "unit01").glob("*.csv"))[0]
    data = np.genfromtxt(first, delimiter=",", names=True)
    reference = programs.reference_of(data["t"], np.column_stack([data[f"q{k}"] for k in range(1, 7)]))
    checked = 0
    for path in sorted((cell["logs"] / "unit01").glob("*.csv"))[1:-2]:
        if truth[path.stem]["program"] != truth[first.stem]["program"]:
            continue
        log = np.loadtxt(path, delimiter=",", skiprows=1)
        t, q = log[:, 0], log[:, 1:7]
        cut = align.whole_cycles(t, q, reference)
        start, stop = programs.span_of(t, cut, reference.period)
        span = t[stop - 1] - t[start] + 1 / RATE
        cycles = float(truth[path.stem]["span_cycles"])
        assert span / reference.period == pytest.approx(np.floor(cycles), abs=0.02), path.stem
        checked += 1
    assert checked >= 5
