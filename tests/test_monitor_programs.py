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
from faultgen.monitor import feed, loop, programs, steps
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
    # the unit learned on its first `train` logs in all, both programs' (each its own offset, issue 90):
    # every later log scored (not `train` of each program)
    learned = sorted(r["stamp"] for r in truth if r["stamp"] != cell["short"])[:SETTINGS.train]
    second = sum(dict((r["stamp"], r["program"]) for r in truth)[s] != truth[0]["program"] for s in learned)
    assert min(second, SETTINGS.train - second) >= max(5, SETTINGS.train // 4)  # both pooled (relearn_logs each)
    assert [r["stamp"] for r in scores if r["phase"] == "training"] == learned
    assert [r["phase"] for r in scores][SETTINGS.train:] == ["monitoring"] * (logs - SETTINGS.train)


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


# -- learning on the logs of all the unit's programs (issue 90 item 3: every unit monitored by day 40) --------
#: A synthetic unit of 2 axes (6 features): each program's residual its own offset, one temperature slope shared.
SLOPE = np.array([0.02, -0.01, 0.03, 0.01, 0.05, -0.04])


def _signatures(k: int) -> np.ndarray:
    """Program ``k``'s wear signatures (2 axes x 6 features, per %): its friction torques move per % of wear."""
    signatures = np.zeros((2, 6))
    signatures[0, [0, 2, 4]] = 0.02 * (k + 1)
    signatures[1, [1, 3, 5]] = 0.03 * (k + 1)
    return signatures


def _feed(days, seed=0, train=15):
    """A synthetic unit fed the program of each day of ``days`` (0, 1, 2: met in that order), a log a day:
    each program's own offset (far apart: what the twin's residual keeps of its model's error on that
    motion), the shared temperature slope and noise. Returns the monitor, its baselines and the logs."""
    rng = np.random.default_rng(seed)
    offsets = rng.normal(0.0, 5.0, (3, 6))
    monitor = steps.start("u", Settings(train=train, persistence=3), 2, _signatures(0))
    baselines = monitor.stages.programs
    logs = []
    for day, k in enumerate(days):
        if k == len(baselines.saved) + 1:
            baselines.new(monitor.stages, _signatures(k))
        temperature = 25.0 + 8.0 * np.sin(day / 5.0)
        residual = offsets[k] + SLOPE * (temperature - 25.0) + rng.normal(0.0, 0.01, 6)
        stamp = f"2026-01-{day + 1:02d}" if day < 31 else f"2026-02-{day - 30:02d}"
        steps.run(monitor, k, lambda: steps.add(monitor, stamp, residual, temperature, 10.0))
        logs.append((stamp, k, residual, temperature))
    return monitor, baselines, logs


def test_a_unit_alternating_three_programs_is_monitored_after_train_logs_in_all():
    days = [0, 1, 2] * 8  # a program a day in turn
    monitor, baselines, logs = _feed(days)
    assert monitor.stages.baseline.pca is not None and all(b.pca is not None for b in baselines.saved)
    phases = [(row.stamp, row.phase) for row in monitor.rows]
    assert phases == [(s, "training") for s, _, _, _ in logs[:15]] + [(s, "monitoring") for s, _, _, _ in logs[15:]]
    # the offsets and the shared slope: the dummy-variable least squares of the 15 learning logs (fixed effects)
    k = np.array([p for _, p, _, _ in logs[:15]])
    T = np.array([t for _, _, _, t in logs[:15]])
    design = np.column_stack([np.eye(3)[k], T - T.mean()])
    solution = np.linalg.lstsq(design, np.stack([e for _, _, e, _ in logs[:15]]), rcond=None)[0]
    learned = [monitor.stages.baseline.mean_] + [b.mean_ for b in baselines.saved]
    np.testing.assert_allclose(np.stack(learned), solution[:3], atol=1e-9)
    np.testing.assert_allclose(monitor.stages.baseline.slope_[0], solution[3], atol=1e-9)
    assert all(b.pca is monitor.stages.baseline.pca and b.learned_ == 5 for b in baselines.saved)
    wear = np.stack([row.wear.log for row in monitor.rows if row.phase == "monitoring"])
    assert np.all(np.abs(wear) < 5.0) and monitor.stages.alarm.first_alarm is None  # each program read on its own offset


def test_a_program_met_after_learning_is_scored_after_its_short_relearning():
    days = [0] * 15 + [1, 0] * 7  # program 2 from day 16, every other day
    monitor, baselines, logs = _feed(days, seed=1)
    (saved,) = baselines.saved
    relearn = monitor.stages.baseline.relearn_logs
    assert relearn == 5 and saved.pca is monitor.stages.baseline.pca and saved.slope_ is monitor.stages.baseline.slope_
    second = [(s, e, t) for s, k, e, t in logs if k == 1]
    phases = {row.stamp: row.phase for row in monitor.rows}
    assert [phases[s] for s, _, _ in second] == ["relearning"] * relearn + ["monitoring"] * (len(second) - relearn)
    assert [phases[s] for s, k, _, _ in logs[15:] if k == 0] == ["monitoring"] * 7  # program 1 scored throughout
    own = np.stack([e - (t - monitor.stages.baseline.condition_mean_[0]) * monitor.stages.baseline.slope_[0] for _, e, t in second[:relearn]])
    np.testing.assert_allclose(saved.mean_, own.mean(axis=0), atol=1e-12)
    assert [row.stamp for row in monitor.rows] == sorted(row.stamp for row in monitor.rows)
    # learned: no longer listed as learning
    assert "learning" not in programs.mix_note(monitor.stages, [], ["program 1", "program 2"])


def test_a_program_with_too_few_logs_in_the_pooled_learning_learns_its_offset_after():
    days = [0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 0]  # program 2: 1 of the first 15 logs
    monitor, baselines, logs = _feed(days, seed=2)
    (saved,) = baselines.saved
    phases = [row.phase for row in monitor.rows if row.stamp in {s for s, k, _, _ in logs if k == 1}]
    assert phases == ["relearning"] * 5 and saved.pca is monitor.stages.baseline.pca
    assert [row.phase for row in monitor.rows if row.stamp == logs[-1][0]] == ["monitoring"]
