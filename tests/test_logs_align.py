"""A unit's programs recognised from the motion and the whole cycles of a log cut anywhere
(faultgen.logs.align; issue 90, items 1 and 2), on logs of the independent simulator
(faultgen.bench.independent: Pinocchio's dynamics, its own friction law; a KR210 cell of 3 programs,
units running 3, 2 and 1 of them, logs of 1.5-3 cycles from a random phase) checked against its truth
(truth_programs.csv: each log's program, span and phase; a program's cycle length from
faultgen.bench.plant.motion), never read by the code under test."""

import csv
import dataclasses

import numpy as np
import pinocchio_log
import pytest

from faultgen.bench import cell, independent, plant
from faultgen.logs import align
from faultgen.model import robots

RATE = 125.0
#: 3 programs; 3 units running 3, 2 and 1 of them; logs of 1.5-3 cycles at a random phase.
FLEET = independent.FleetSpec(units=3, worn=1, days=9, onset=(1, 2), rate=RATE, seed=11, programs=3,
                              unit_programs=(3, 2, 1), span=(1.5, 3.0), log_jitter=0.015)


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    """The fleet's logs, in order per unit: dicts of t, q, program, phase, span (truth) and the
    programs' cycle lengths in samples (truth)."""
    root = tmp_path_factory.mktemp("align")
    robot = pinocchio_log.add_kr210(root / "kr210")
    independent.write_fleet(root / "fleet", FLEET, robot)
    model = robots.load(robot)
    lengths = [len(plant.motion(model, RATE, False, s)[1]) for s in cell.VARIANT_SHRINK]
    logs = {}
    with open(root / "fleet" / "truth_programs.csv", newline="") as f:
        for row in csv.DictReader(f):
            data = np.loadtxt(root / "fleet" / "logs" / row["unit"] / f"{row['stamp']}.csv", delimiter=",", skiprows=1)
            program = int(row["program"])
            logs.setdefault(row["unit"], []).append({
                "t": data[:, 0], "q": data[:, 1:7], "program": program,
                "first": int(float(row["phase"]) * lengths[program])})
    return logs, lengths


@pytest.fixture(scope="module")
def placed(fleet):
    """Every log placed in turn among its unit's programs (align.place), with the truth program each
    learned reference stands for."""
    logs, _ = fleet
    out = {}
    for unit, unit_logs in logs.items():
        known, truth_of = [], {}
        for log in unit_logs:
            p = align.place(log["t"], log["q"], known)
            if p.learned is not None:
                known.append(p.learned)
                truth_of[p.learned.name] = log["program"]
            out.setdefault(unit, []).append((log, p, dict(truth_of), list(known)))
    return out


def test_the_fleet_has_what_the_tests_need(fleet):
    logs, _ = fleet
    assert [len({log["program"] for log in unit}) for unit in logs.values()] == [3, 2, 1]


def test_every_log_runs_the_program_its_truth_says_and_a_new_one_is_reported_only_when_new(placed):
    for unit, rows in placed.items():
        seen = set()
        for log, p, truth_of, _ in rows:
            new = log["program"] not in seen
            seen.add(log["program"])
            assert p.recognition.status is (align.Status.NEW if new else align.Status.KNOWN), (unit, log["program"])
            name = p.learned.name if new else p.recognition.program
            assert truth_of[name] == log["program"]
            if not new:  # the others lie far outside the tolerance: the programs are told apart with margin
                assert p.recognition.fits[0].rms < align.TOLERANCE / 20
                assert all(f.window > 5 * align.TOLERANCE for f in p.recognition.fits[1:])


def test_a_new_programs_period_is_found_from_its_first_log_within_a_sample(placed, fleet):
    _, lengths = fleet
    learned = [(log, p.learned) for rows in placed.values() for log, p, _, _ in rows if p.learned]
    assert len(learned) == 6
    for log, reference in learned:
        assert abs(reference.period - lengths[log["program"]] / RATE) < 0.5 / RATE
        assert len(reference.q) == lengths[log["program"]]


def _whole_cycle_expected(log, boundary, length):
    """Whether a log holds a whole cycle starting at ``boundary`` (a sample of the program's cycle)."""
    return (boundary - log["first"]) % length + length <= len(log["t"])


def test_the_whole_cycles_are_one_period_each_at_one_phase_and_every_one_the_log_holds(placed, fleet):
    """Each whole cycle spans the program's cycle length (1 sample), starts at the same sample of
    the true cycle on every log of a unit's program, follows the last one without a gap; the
    fragments are shorter than a cycle; a log is refused exactly when no whole cycle lies inside it."""
    _, lengths = fleet
    for rows in placed.values():
        boundary = {}
        for log, p, truth_of, known in rows:
            length = lengths[log["program"]]
            if p.cycles is None:
                assert p.refusal.why in (align.Why.CUT_INSIDE, align.Why.SHORTER_THAN_A_CYCLE)
                continue
            spans, n = p.cycles.spans, len(log["t"])
            assert all(abs(b - a - length) <= 1 for a, b in spans)
            assert all(b == a2 for (_, b), (a2, _) in zip(spans, spans[1:]))
            assert spans[0][0] < length and n - spans[-1][1] < length
            at = {(log["first"] + a) % length for a, _ in spans}
            boundary.setdefault(log["program"], at.pop())
            assert all(abs(x - boundary[log["program"]]) <= 1 for x in at | {boundary[log["program"]]})
            assert p.cycles.off == ()
        for log, p, _, _ in rows:
            if log["program"] in boundary:
                length = lengths[log["program"]]
                assert (p.cycles is not None) == _whole_cycle_expected(log, boundary[log["program"]], length)


def test_the_fragments_are_used_when_long_enough_and_dropped_when_short(placed):
    fragments = [f for rows in placed.values() for _, p, _, _ in rows if p.cycles
                 for f in (p.cycles.lead, p.cycles.trail) if f is not None]
    assert {f.use for f in fragments} == {align.Use.USED, align.Use.SHORT}
    for f in fragments:
        assert f.rms < align.TOLERANCE and 0.0 <= f.phase < 1.0


def _cut_before_boundary(log, length, lead):
    """The log's rows from ``lead`` samples before its first start of the true cycle."""
    start = (length - log["first"]) % length - lead
    assert start >= 0
    return log["t"][start:] - log["t"][start], log["q"][start:]


@pytest.fixture(scope="module")
def long_log(fleet):
    """A log of program 0 of 2.5 cycles or more, and its program's length."""
    logs, lengths = fleet
    log = next(x for unit in logs.values() for x in unit if len(x["t"]) >= 2.5 * lengths[x["program"]])
    return log, lengths[log["program"]]


def test_a_cycle_column_that_starts_with_a_0072_s_fragment_is_not_taken_as_the_cycle(long_log):
    """The issue's case: a log whose cycle column's first run is 0.072 s (9 samples at 125 Hz). The
    reference learned from it is a whole cycle of the motion's period, started where the column's
    (checked) cycles start; the fragment is the log's lead, dropped; and a column of only the fragment
    and one long run disagrees with the motion and is not used."""
    log, length = long_log
    t, q = _cut_before_boundary(log, length, 9)
    counter = np.concatenate([[0] * 9, np.repeat(np.arange(1, 5), length)])[: len(t)]
    reference = align.learn("p", t, q, cycle=counter)
    assert abs(reference.period - length / RATE) < 0.5 / RATE and reference.period > 10 * 0.072
    assert np.max(np.abs(reference.q[0] - q[9])) < 1e-3  # starts at the column's boundary
    cut = align.whole_cycles(t, q, reference, cycle=counter)
    assert cut.hint.verdict is align.HintVerdict.AGREES
    assert cut.spans[0] == (9, 9 + length)
    assert cut.lead == align.Fragment(0, 9, cut.lead.phase, cut.lead.rms, align.Use.SHORT)
    two_runs = np.concatenate([[0] * 9, [1] * (len(t) - 9)])
    again = align.whole_cycles(t, q, reference, cycle=two_runs)
    assert again.hint.verdict is align.HintVerdict.DISAGREES and "spans" in again.hint.detail
    assert again.spans == cut.spans
    assert align.learn("p", t, q, cycle=two_runs).period == pytest.approx(reference.period)


def test_a_cycle_column_whose_runs_are_off_the_period_is_refused_and_the_motion_kept(long_log):
    log, length = long_log
    t, q = _cut_before_boundary(log, length, 50)
    reference = align.learn("p", t, q)
    wrong = np.arange(len(t)) // (length // 2)  # a cycle every half period
    cut = align.whole_cycles(t, q, reference, cycle=wrong)
    assert cut.hint.verdict is align.HintVerdict.DISAGREES
    assert cut.spans == align.whole_cycles(t, q, reference).spans


def test_a_log_under_one_cycle_is_refused_with_its_reason(long_log):
    log, length = long_log
    t, q = log["t"], log["q"]
    reference = align.learn("p", t, q)
    part = slice(0, int(0.8 * length))
    short = align.place(t[part], q[part], [reference])
    assert short.recognition.status is align.Status.KNOWN and short.cycles is None
    assert short.refusal.why is align.Why.SHORTER_THAN_A_CYCLE and "no whole cycle inside" in short.refusal.detail
    new = align.place(t[: int(1.2 * length)], q[: int(1.2 * length)], [])
    assert new.recognition.status is align.Status.NEW and new.learned is None
    assert new.refusal.why is align.Why.NO_PERIOD and "1.3 of its cycles" in new.refusal.detail


def test_a_log_at_another_rate_is_the_same_program_and_cut_at_the_same_times(long_log):
    log, length = long_log
    reference = align.learn("p", log["t"], log["q"])
    half = align.place(log["t"][::2], log["q"][::2], [reference])
    full = align.whole_cycles(log["t"], log["q"], reference)
    assert half.recognition.program == "p" and half.learned is None
    for (a, b), (a2, b2) in zip(half.cycles.spans, full.spans):
        assert abs(2 * a - a2) <= 2 and abs(2 * b - b2) <= 2


def test_a_log_that_barely_moves_and_one_that_matches_two_programs_are_not_scored(long_log):
    log, _ = long_log
    reference = align.learn("p", log["t"], log["q"])
    still = np.tile(log["q"][0], (len(log["t"]), 1))
    assert align.place(log["t"], still, [reference]).refusal.why is align.Why.STILL
    twice = align.place(log["t"], log["q"], [reference, dataclasses.replace(reference, name="p again")])
    assert twice.recognition.status is align.Status.AMBIGUOUS and twice.refusal.why is align.Why.AMBIGUOUS


def test_the_shift_distances_are_the_direct_sums():
    rng = np.random.default_rng(0)
    for n, m in ((50, 13), (9, 13), (40, 40)):
        x, r = rng.normal(size=(n, 3)), rng.normal(size=(m, 3))
        direct = [np.mean((x - r[(np.arange(n) + s) % m]) ** 2) for s in range(m)]
        assert np.allclose(align._shift_distances(x, align.Reference("r", r, float(m))), direct, rtol=1e-10, atol=1e-12)
    x = rng.normal(size=(60, 2))
    direct = [np.mean((x[: 60 - k] - x[k:]) ** 2) for k in range(60)]
    assert np.allclose(align._lag_distances(x), direct, rtol=1e-9, atol=1e-12)


def test_a_periodic_path_at_a_fractional_shift_is_fitted_to_a_fraction_of_a_sample():
    m, step = 200, 0.01
    phases = 2 * np.pi * np.arange(m) / m
    reference = align.Reference("sine", np.column_stack([np.sin(phases), np.cos(2 * phases)]), m * step)
    t = np.arange(450) * step
    shift = 37.4  # reference samples at the log's first sample
    w = 2 * np.pi * (t / step + shift) / m
    found = align.fit(t, np.column_stack([np.sin(w), np.cos(2 * w)]), reference)
    assert found.shift == pytest.approx(shift, abs=0.05) and found.rms < 1e-3


@pytest.mark.parametrize("t, q, message", [
    ([0.0, 0.1, 0.1, 0.2], np.zeros((4, 2)), r"time at sample 2 \(0\.1 s\) does not follow 0\.1 s"),
    ([0.0, 0.1, 0.2], np.zeros((4, 2)), r"t \(3,\) and q \(4, 2\): expected t \(n >= 3,\) s and q \(n, N\) rad"),
    ([0.0, 0.1, np.nan], np.zeros((3, 2)), r"non-finite time or angle"),
])
def test_a_malformed_log_is_refused_by_name(t, q, message):
    reference = align.Reference("p", np.zeros((5, 2)), 1.0)
    with pytest.raises(ValueError, match=message):
        align.recognise(t, q, [reference])


def test_a_bad_tolerance_axes_or_reference_is_refused_by_name():
    reference = align.Reference("p", np.zeros((5, 2)), 1.0)
    t = np.arange(10) * 0.1
    with pytest.raises(ValueError, match=r"tolerance -1 rad: expected a positive angle"):
        align.recognise(t, np.zeros((10, 2)), [reference], tolerance=-1)
    with pytest.raises(ValueError, match=r"a log of 3 axes against program 'p' of 2: expected the same axes"):
        align.fit(t, np.zeros((10, 3)), reference)
    with pytest.raises(ValueError, match=r"program 'p': period 0 s: expected a positive time"):
        align.Reference("p", np.zeros((5, 2)), 0)


def test_a_noisy_log_resampled_at_a_rate_that_does_not_divide_the_cycle_is_the_same_program(long_log):
    """The log taken at 100 Hz from a random offset (a cycle of 906 samples at 125 Hz is 724.8 at
    100 Hz) with 2e-3 rad of angle noise (twice an encoder's and tracking's): its period learned
    within 1 ms, and recognised against the reference learned at 125 Hz, its cycles 0.8 of the 125 Hz
    ones within 1 sample."""
    log, length = long_log
    rng = np.random.default_rng(3)
    t = np.arange(log["t"][0] + 0.0037, log["t"][-1], 0.01)
    q = np.column_stack([np.interp(t, log["t"], log["q"][:, a]) for a in range(6)]) + rng.normal(0, 2e-3, (len(t), 6))
    assert abs(align.period(t, q) - length / RATE) < 1e-3
    placed = align.place(t, q, [align.learn("p", log["t"], log["q"])])
    assert placed.recognition.program == "p" and placed.recognition.fits[0].rms < align.TOLERANCE / 4
    assert all(abs((b - a) - 0.8 * length) <= 1 for a, b in placed.cycles.spans)


def test_a_cycle_off_the_program_is_set_apart_and_the_others_kept(placed):
    """A log whose second whole cycle leaves the path (axis 1 0.3 rad off over its middle third: a jog)
    is still of its program (it runs it for a whole period elsewhere): that cycle is set apart as
    off, the others are its whole cycles; a log off the path throughout is refused as off the program."""
    log, p, _, known = next((log, p, truth_of, known) for rows in placed.values() for log, p, truth_of, known in rows
                            if p.cycles and len(p.cycles.spans) >= 2)
    t, q = log["t"], log["q"]
    reference = next(r for r in known if r.name == p.cycles.program)
    clean = p.cycles.spans
    a, b = clean[1]
    jogged = q.copy()
    jogged[a + (b - a) // 3: a + 2 * (b - a) // 3, 0] += 0.3
    again = align.place(t, jogged, [reference])
    assert again.recognition.program == reference.name
    assert [(c.start, c.stop) for c in again.cycles.off] == [(a, b)]
    assert again.cycles.spans == [s for s in clean if s != (a, b)]
    off = align.whole_cycles(t, q + 0.1, reference)
    assert off.why is align.Why.OFF_PROGRAM and f"rad RMS off program {reference.name!r}" in off.detail
