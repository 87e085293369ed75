"""A log holding several cycles of the unit's program is the same program (issue 72 item 8, now
faultgen.monitor.programs over faultgen.logs.align): the program recognised from the motion, its
whole cycles scored, a program change declared only when a log's motion matches none of the unit's
programs, in time rather than samples (250 and 500 Hz logs of one program). Checked on motions
made here (a reference cycle tiled and resampled by hand) and on the independent generator's mixed
fleet (faultgen.bench.independent's ``cycles`` and ``rates``: Pinocchio's dynamics, one unlogged
program change on a known day), whose default fleets stay the same file for file."""

import independent_fleet
import numpy as np
import pytest

from faultgen.bench import layouts
from faultgen.data import logfolder
from faultgen.logs import measured
from faultgen.model import robots
from faultgen.logs import align
from faultgen.monitor import programs
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import unit as unit_module
from faultgen.monitor.twin import Twin


def motion(t: np.ndarray, reach: float = 1.0) -> np.ndarray:
    """A rest-to-rest cycle of 3 axes over 4 s, rad: out to ``reach`` times its targets and back."""
    phase = np.clip(t / 4.0, 0.0, 1.0)
    shape = np.sin(np.pi * phase) ** 2  # 0 at both ends, at rest
    return reach * np.column_stack([0.8 * shape, -0.5 * shape, 1.2 * np.sin(np.pi * phase) ** 4])


def log(rate: float, k: int, reach: float = 1.0, noise: float = 1e-4, seed: int = 0):
    """``k`` back-to-back 4 s cycles sampled at ``rate`` Hz (each ``4 * rate`` samples, the next
    starting a sample after the last ends) with angle noise; returns (t, q, cycle column)."""
    n = int(round(4.0 * rate))
    one = motion(np.arange(n) / rate, reach)
    q = np.tile(one, (k, 1)) + np.random.default_rng(seed).normal(0.0, noise, (k * n, 3))
    return np.arange(k * n) / rate, q, np.repeat(np.arange(k), n)


def _scored(t, q, reference, cycle=None):
    """The samples of a log the monitor scores: (start, stop) or None (faultgen.monitor.programs.span_of)."""
    return programs.span_of(t, align.whole_cycles(t, q, reference, cycle), reference.period)


@pytest.mark.parametrize("program_rate, program_cycles", [(250.0, 1), (500.0, 1), (250.0, 2), (500.0, 3)])
def test_a_log_of_whole_cycles_at_any_rate_is_the_program(program_rate, program_cycles):
    t, q, _ = log(program_rate, program_cycles)
    program = programs.reference_of(t, q)
    assert program.period == pytest.approx(4.0, rel=1e-3)
    assert programs.first_cycle(t, q)[2] == ("" if program_cycles == 1 else f"1 of {program_cycles}")
    for rate in (250.0, 500.0, 125.0):
        for k in (1, 2, 3):
            t, q, cycle = log(rate, k, seed=k)
            assert align.recognise(t, q, [program]).status is align.Status.KNOWN, (rate, k)
            assert _scored(t, q, program) == (0, len(t)), (rate, k)  # every sample scored
            assert _scored(t, q, program, cycle) == (0, len(t)), (rate, k)


def test_another_motion_is_another_program_and_a_part_of_a_cycle_is_not_scored():
    program = programs.reference_of(*log(250.0, 1)[:2])
    # other targets (70 % of the way: the generator's program change), one cycle or two
    for k in (1, 2):
        t, q, cycle = log(250.0, k, reach=0.7)
        assert align.recognise(t, q, [program]).status is align.Status.NEW
    # a cycle stretched by 10 % (a slower program): another program
    t, q, _ = log(250.0, 1)
    assert align.recognise(t * 1.1, q, [program]).status is align.Status.NEW
    # a cycle and a half: the program, one cycle of it scored
    t, q, _ = log(500.0, 3)
    half = len(t) // 2
    start, stop = _scored(t[:half], q[:half], program)
    assert (stop - start) / 500.0 == pytest.approx(4.0, abs=0.01)
    # the second of two cycles off the program: only the first is scored
    t, q, cycle = log(250.0, 2)
    q[cycle == 1] = log(250.0, 1, reach=0.7)[1]
    assert _scored(t, q, program) == (0, 1000)


def test_a_one_cycle_program_is_not_taken_for_several():
    t, q, _ = log(250.0, 1)
    program = programs.reference_of(t, q)
    assert program.period == pytest.approx(4.0) and len(program.q) == len(t)
    assert programs.first_cycle(t, q)[2] == ""


# a 2-unit iiwa 14 fleet of 12 days, logs of 1 or 2 cycles at 250 or 500 Hz, the healthy unit's
# program changed on a day drawn in 5..7 (nobody logs it)
SPEC = independent_fleet.FleetSpec(units=2, worn=1, days=12, seed=5, onset=(3, 3), final_wear=100.0,
                                   wearable=(1, 2, 3, 4, 5, 6, 7), max_part=14.0, rated_part=True,
                                   program_changes=1, rate=250.0, cycles=(1, 2), rates=(250.0, 500.0))


@pytest.fixture(scope="module")
def robot(tmp_path_factory):
    return independent_fleet.add_robot(tmp_path_factory.mktemp("iiwa") / "iiwa14", "iiwa14", payload=14.0)


@pytest.fixture(scope="module")
def mixed(robot, tmp_path_factory):
    root = tmp_path_factory.mktemp("mixed")
    logs, _ = independent_fleet.independent.write_fleet(root, SPEC, robot)
    return root, logs


def test_the_generator_mixes_layouts_and_leaves_every_other_draw_as_it_was(robot, mixed, tmp_path):
    root, logs = mixed
    plain = independent_fleet.FleetSpec(**{**SPEC.__dict__, "cycles": (1,), "rates": (), "rate": 250.0})
    logs_plain, _ = independent_fleet.independent.write_fleet(tmp_path, plain, robot)
    seen, same = set(), 0
    for unit in independent_fleet.unit_names(SPEC):
        for stamp in independent_fleet.stamps(SPEC):
            one = len(np.loadtxt(logs_plain / unit / f"{stamp}.csv", delimiter=",", skiprows=1))  # a cycle at 250 Hz
            data = np.loadtxt(logs / unit / f"{stamp}.csv", delimiter=",", skiprows=1)
            rate = round(1.0 / np.median(np.diff(data[:, 0])))
            k = len(data) / (one if rate == 250 else 2 * one - 1)
            assert k in (1.0, 2.0), (unit, stamp, len(data), rate)
            seen.add((int(k), rate))
            if (k, rate) == (1.0, 250):  # the default layout: the file the plain fleet wrote
                plain_bytes = (logs_plain / unit / f"{stamp}.csv").read_bytes()
                assert (logs / unit / f"{stamp}.csv").read_bytes() == plain_bytes
                same += 1
    assert seen == {(1, 250), (2, 250), (1, 500), (2, 500)} and same > 0
    assert (root / "truth.csv").read_bytes() == (tmp_path / "truth.csv").read_bytes()
    assert (root / "changes.csv").read_bytes() == (tmp_path / "changes.csv").read_bytes()


def test_the_generator_refuses_a_bad_layout():
    with pytest.raises(ValueError, match="cycles = \\(0,\\)"):
        independent_fleet.FleetSpec(cycles=(0,))
    with pytest.raises(ValueError, match="rate = 300.0 Hz"):
        independent_fleet.FleetSpec(rates=(250.0, 300.0))
    assert layouts.plan(500.0, 250.0) == (1 / 500.0, 1) and layouts.plan(125.0, 250.0) == (1 / 250.0, 2)


def test_only_the_real_program_change_is_one_on_the_mixed_fleet(robot, mixed):
    root, logs = mixed
    model = robots.load(robot)
    ((unit_changed, (change,)),) = independent_fleet.read_changes(root).items()
    for unit in independent_fleet.unit_names(SPEC):
        stamps = independent_fleet.stamps(SPEC)
        first = measured.read(logs / unit / f"{stamps[0]}.csv", model, accelerations=False)
        known = [programs.reference_of(first.t, first.q, first.cycle)]
        changed = []
        for stamp in stamps[1:]:
            data = measured.read(logs / unit / f"{stamp}.csv", model, accelerations=False)
            if align.recognise(data.t, data.q, known).status is align.Status.NEW:
                changed.append(stamp)
                known.append(programs.reference_of(data.t, data.q, data.cycle, f"program {len(known) + 1}"))
        assert changed == ([change["stamp"]] if unit == unit_changed else []), unit



def test_units_whose_first_logs_hold_other_layouts_of_one_program_share_its_twin(robot, mixed):
    root, logs = mixed
    model = robots.load(robot)
    source = fleet_logs.Source(model)
    ((unit_changed, (change,)),) = independent_fleet.read_changes(root).items()
    before = [(u, s) for u in independent_fleet.unit_names(SPEC) for s in independent_fleet.stamps(SPEC)
              if u != unit_changed or s < change["stamp"]]
    layouts_seen, programs = {}, []
    for unit, stamp in before:
        data = measured.read(logs / unit / f"{stamp}.csv", model, accelerations=False)
        layouts_seen.setdefault((len(data.t), round(1 / np.median(np.diff(data.t)))), (unit, stamp))
    assert len(layouts_seen) == 4  # 1 or 2 cycles at 250 or 500 Hz
    first = None
    for k, (unit, stamp) in enumerate(layouts_seen.values()):
        entry = logfolder.LogFile(unit, stamp, 0.0, "time", logs / unit / f"{stamp}.csv", f"{unit}/{stamp}.csv")
        program = unit_module.program_of(entry, f"u{k}", programs, source)
        first = first or program
        assert program == first == ("u0", list(layouts_seen.values())[0][1])  # the first one's program, shared
    changed = logfolder.LogFile(unit_changed, change["stamp"], 0.0, "time", logs / unit_changed / f"{change['stamp']}.csv",
                                f"{unit_changed}/{change['stamp']}.csv")
    assert unit_module.program_of(changed, "other", programs, source) == ("other", change["stamp"])
    assert len(programs) == 2


def test_the_twin_of_a_log_of_two_cycles_replays_one_and_expects_what_a_one_cycle_programs_twin_does(robot, mixed,
                                                                                                     tmp_path):
    root, logs = mixed
    model = robots.load(robot)
    ((unit_changed, (change,)),) = independent_fleet.read_changes(root).items()
    by_rows = {}
    for stamp in independent_fleet.stamps(SPEC):
        if stamp < change["stamp"]:
            path = logs / unit_changed / f"{stamp}.csv"
            data = measured.read(path, model, accelerations=False)
            if round(1 / np.median(np.diff(data.t))) == 250:
                by_rows.setdefault(len(data.t), path)
    one, two = (by_rows[n] for n in sorted(by_rows))  # a cycle and two cycles at 250 Hz
    twins = [Twin(model, path, tmp_path / "cache" / "cycles", cycles=False) for path in (one, two)]
    replayed = [twin._reference.t for twin in twins]  # the smoothed program cycle, in memory (a Motion)
    assert len(replayed[1]) == len(replayed[0]) == len(np.loadtxt(one, delimiter=",", skiprows=1))
    healthy = [twin.cycle(float("nan"), 0.0) for twin in twins]
    # the two logs' motions differ by their angle noise only (1e-5 rad), which the replay tracks: the
    # twins of two one-cycle logs of a unit differed by up to 0.35 % per feature (2026-11-27)
    np.testing.assert_allclose(healthy[1], healthy[0], rtol=1e-2)


@pytest.mark.parametrize("short", [1, 2, 10, 15])
def test_a_log_a_part_of_a_period_short_of_three_cycles_is_scored_on_whole_cycles(short):
    """A log cut at a phase 0.3 of the cycle and ``short`` samples (of 1000 a period) short of three
    cycles: one or two samples short (a period's rounding to a sample) it counts as three periods and
    is scored whole; 10 or 15 short (1 and 1.5 % of a period, which the 2 % tolerance once counted) it
    is scored on its two whole cycles, over which a per-sample mean (here the mean |qd|, the viscous
    friction's weight) is the cycle's, where over the whole log it is not (main before: all of it)."""
    program = programs.reference_of(*log(250.0, 1)[:2])
    n = 1000
    t1, q1, _ = log(250.0, 1, noise=0.0)
    cycle_mean = np.mean(np.abs(np.gradient(q1, t1, axis=0)), axis=0)
    t, q, _ = log(250.0, 4, noise=0.0)
    qd = np.gradient(q, t, axis=0)
    first, last = int(0.3 * n), int(0.3 * n) + 3 * n - short
    start, stop = _scored(t[first:last] - t[first], q[first:last], program)
    if short <= programs.EDGE_SAMPLES:
        assert (start, stop) == (0, last - first)
        return
    assert (start, stop) == (n - first % n, 3 * n - first % n)  # the two whole cycles inside
    relative = lambda s: np.max(np.abs(np.mean(np.abs(qd[first:last][s]), axis=0) / cycle_mean - 1.0))
    assert relative(slice(start, stop)) < 1e-4
    assert relative(slice(None)) > 2e-3
