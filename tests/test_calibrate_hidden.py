"""Hidden-effect checks of ``faultgen calibrate`` on data from our own simulator (both robots).

For every effect id, :mod:`faultgen.calibrate.synth` switches the effect on at a randomly drawn
size on random axes (seed 0 for every case, fixed before looking at the outcome; one more case,
IRB-6700-like backlash of seed 4, because it failed in the accuracy benchmark), simulates
one or two closed-loop cycles of the pick-and-place task with sensor noise (:data:`TWO_CYCLES`), and
writes the measured CSV; the workflow gets only that file and the robot name. It must name the
hidden effect first, on the hidden axes, and cut the held-out total nrmse at least in half. Without
a hidden effect it must name nothing, on four cycles (more data makes a false finding more likely).

The suite runs each effect on one robot (alternating, so each robot carries half of them), plus
the case with a robot-specific bound below and the nothing-hidden log of both: one case costs
25-40 s on this machine at two cycles (45-75 s at four) and the whole grid was two thirds of the
suite's time. Every effect on both robots and five seeds, on four-cycle logs, is
``benchmarks/calibration_accuracy.py`` (docs/calibration.md, "Accuracy on hidden effects"), whose
seed-0 rows are the cases left out here. At two cycles the held-out part is most of the second
cycle; every case passed its bound at four cycles too (2026-11-23, before the change to two). A
case whose effect one cycle already shows runs on one (2026-11-27): the held-out part is then the
last 30 % of that cycle, a part of the motion the fit did not see, and the same bounds hold there
(:data:`TWO_CYCLES` names the cases that keep two, and why).

Backlash on the PUMA 560 is named but cannot halve the gap: its stiff gearboxes make a dead band
a small effect on the drive torque (4-9 % of the waist's torque RMS at 5-20 mrad), and the
held-out total nrmse of the log with nothing hidden is already 50-64 % of the gap before
(seeds 0-4, docs/calibration.md), so no model could halve it; the test holds it to its measured
ratio.
"""

import json
import os

import numpy as np
import pytest

from faultgen.calibrate import EFFECTS, calibrate, synth
from faultgen.logs import measured
from faultgen.model import robots
from faultgen.simulation import stepping as sim
from resolved_runs import run_config

SEED = 0
#: Each effect on one robot, alternating in the order of EFFECTS (this order puts PUMA 560
#: backlash, which has a robot-specific bound, SHORT below, on that robot) ...
CASES = [(("puma560", "irb6700")[k % 2], effect, SEED) for k, effect in enumerate(EFFECTS)]
#: ... and one more seed: IRB-6700-like backlash hidden on axes 1 and 2, where the coupled ringing
#: they leave on axis 3 was taken for a third dead band while one more axis needed a 10 % drop
#: of the fitting error (effects.Backlash.MIN_DROP).
CASES.append(("irb6700", "backlash", 4))
#: The PUMA 560's payload case is calibrated by test_outputs_follow_the_contract_and_the_model_runs,
#: which holds it to the same checks (one calibration, not two).
CONTRACT_CASE = ("puma560", "payload", SEED)
#: The case that also checks that the same seed gives the same bytes (:func:`same_seed_same_bytes`;
#: test_same_seed_same_bytes until 2026-11-27, r10, which drew, recorded and calibrated a log of its
#: own, IRB-6700-like Coulomb of seed 11 on one cycle, twice each: the case's draw, log and
#: calibration are now the first of each).
SAME_SEED_CASE = ("irb6700", "coulomb", SEED)
assert SAME_SEED_CASE in CASES and SAME_SEED_CASE != CONTRACT_CASE
#: Cycles of a case's log: one, but two where one cycle does not show the effect well enough to
#: name it and halve the gap (2026-11-27, seed 0 unless given): IRB-6700-like cogging (one
#: cycle: ratio 0.546), PUMA 560 backlash (one cycle: nothing named, the gap before 0.0151 near the
#: floor) and IRB-6700-like backlash of seed 4 (one cycle: found on axis 2 only, hidden on 1 and 2).
#: The one-cycle cases passed with their ratio at most 0.17 (PUMA 560 load-dependent friction 0.162,
#: the others 0.027-0.076).
TWO_CYCLES = {("irb6700", "cogging", 0), ("puma560", "backlash", 0), ("irb6700", "backlash", 4)}


def cycles_of(robot_name, effect, seed):
    """Cycles of the log of a hidden-effect case (:data:`TWO_CYCLES`)."""
    return 2 if (robot_name, effect, seed) in TWO_CYCLES else 1


#: Required held-out gap ratio (after / before): the issue's "at least in half" ...
HALF = 0.5
#: ... except where it cannot be met. PUMA 560 backlash: the floor is more than half the gap
#: before (four cycles, seed 0: 0.0133 of 0.0252), the model at the fitted width leaves 0.0175,
#: ratio 0.69 (seeds 0-4: 0.69-0.76; two cycles, seed 0: 0.67). (IRB-6700-like cogging, held to
#: 0.6 on four cycles, ratio 0.56 there, docs/calibration.md, halves on two: 0.41.)
SHORT = {("puma560", "backlash"): 0.75}
assert all((robot_name, effect, SEED) in CASES for robot_name, effect in SHORT), "a bounded case is not run"
#: Held-out total nrmse of the nominal model on a log with nothing hidden (seeds 0-4: PUMA 560
#: 0.0126-0.0128, IRB-6700-like 0.0124-0.0126, docs/calibration.md; 0.0131-0.0138 before the
#: convergence work). Simulated at the 0.5 ms step with the earlier ``implicitfast`` integrator,
#: its extra inertia raised them to 0.025 and 0.039; with every cycle restarted from the start
#: state instead of back to back, the IRB's was 0.022.
FLOOR = {"puma560": 0.015, "irb6700": 0.015}


def hidden_case(tmp_path, robot_name, effect, seed=SEED, cycles=None, figure=False):
    """The hidden effect drawn, its log recorded and calibrated; ``figure``: calibration.png drawn too
    (only where a test looks at it: about 1.6 s a calibration of six axes); ``cycles``: the case's own
    (:func:`cycles_of`) unless given."""
    cycles = cycles_of(robot_name, effect, seed) if cycles is None else cycles
    robot = robots.load(robot_name)
    hidden = synth.draw(robot, effect, np.random.default_rng(seed))
    path = synth.record(robot, hidden, tmp_path / "measured.csv", seed=seed, cycles=cycles)
    return hidden, calibrate(robot_name, path, tmp_path / "out", figure=figure)


def named_and_halved(hidden, result, robot_name, effect):
    """The hidden effect found first, on its axes, and the held-out gap cut to its bound."""
    assert result.steps, f"nothing found; hidden {hidden}"
    first = result.steps[0]
    assert (first.effect.id, first.axes) == (hidden.effect.id, hidden.axes), f"hidden {hidden}, found {result.summary()}"
    bound = SHORT.get((robot_name, effect), HALF)
    assert result.gap_after["total_nrmse"] <= bound * result.gap_before["total_nrmse"], result.summary()


@pytest.mark.parametrize(("robot_name", "effect", "seed"), [c for c in CASES if c != CONTRACT_CASE])
def test_hidden_effect_is_named_on_its_axes_and_the_gap_halves(tmp_path, robot_name, effect, seed):
    hidden, result = hidden_case(tmp_path, robot_name, effect, seed)
    named_and_halved(hidden, result, robot_name, effect)
    if (robot_name, effect, seed) == SAME_SEED_CASE:
        same_seed_same_bytes(tmp_path, hidden, result)


def same_seed_same_bytes(tmp_path, hidden, result):
    """The same seed draws the same hidden effect, records the same log to the byte, and the log
    calibrated again gives the same report and model file: ``hidden`` and ``result`` are the
    case's (:func:`hidden_case` in ``tmp_path``)."""
    robot_name, effect, seed = SAME_SEED_CASE
    robot = robots.load(robot_name)
    assert synth.draw(robot, effect, np.random.default_rng(seed)) == hidden
    log = tmp_path / "measured.csv"
    again = synth.record(robot, hidden, tmp_path / "again.csv", seed=seed, cycles=cycles_of(*SAME_SEED_CASE))
    assert again.read_bytes() == log.read_bytes()
    first = result.report()
    second = calibrate(robot_name, log, tmp_path / "two", figure=False).report()
    first.pop("model_out"), second.pop("model_out")
    assert first["steps"], "nothing found: the comparison below would show little"
    assert first == second
    model = f"model/{robot_name}_calibrated.xml"
    assert (tmp_path / "out" / model).read_bytes() == (tmp_path / "two" / model).read_bytes()


@pytest.mark.parametrize("robot_name", ["puma560", "irb6700"])
def test_nothing_hidden_names_nothing(tmp_path, robot_name):
    """Also what test_measured_file_is_what_the_reader_accepts checked (merged here 2026-11-27, on
    this log instead of a one-cycle log of its own): the log written is what the reader accepts."""
    _, result = hidden_case(tmp_path, robot_name, None, cycles=4)
    data = measured.read(tmp_path / "measured.csv", robots.load(robot_name))
    assert data.duration > 7.0 and data.velocity_estimated
    assert result.steps == [], result.summary()
    assert result.gap_before["total_nrmse"] < FLOOR[robot_name]
    assert result.gap_after == result.gap_before
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["steps"] == []


def test_outputs_follow_the_contract_and_the_model_runs(tmp_path):
    robot_name, effect, seed = CONTRACT_CASE
    hidden, result = hidden_case(tmp_path, robot_name, effect, seed, figure=True)
    named_and_halved(hidden, result, robot_name, effect)  # the parametrised test's case
    out = tmp_path / "out"
    report = json.loads((out / "report.json").read_text())
    # the contract's keys (design notes), and later additions: the steps not separable on this log, the residual
    # tests after every step, the channel delay check and the library effects not written (issue 73)
    assert set(report) == {"robot", "measured", "gap_before", "steps", "gap_after", "model_out", "ambiguous",
                           "unexplained", "residual_tests", "channel_delay", "not_written"}
    assert report["steps"][0]["units"]["mass"] == "kg" and report["steps"][0]["units"]["com_x"] == "m (flange frame)"
    assert report["robot"] == "puma560" and report["measured"].endswith("measured.csv")
    for gap in (report["gap_before"], report["gap_after"], report["steps"][0]["gap_after"]):
        assert len(gap["rmse_Nm"]) == 6 and len(gap["nrmse"]) == 6
        assert gap["total_nrmse"] == pytest.approx(np.mean(gap["nrmse"]))
    step = report["steps"][0]
    assert step["effect"] == "payload" and step["axes"] == [1, 2, 3, 4, 5, 6]
    mass = step["params"]["robot"]["mass"]
    assert mass == pytest.approx(hidden.effect.mass, rel=0.05)
    assert step["evidence"]["scores"]["payload"] == pytest.approx(step["evidence"]["score"])
    assert (out / "calibration.png").stat().st_size > 10_000
    mask = os.umask(0)
    os.umask(mask)
    for written in (out / "report.json", out / "model" / "puma560_calibrated.xml", out / "model" / "parameters.json"):
        assert written.stat().st_mode & 0o777 == 0o666 & ~mask, written  # not mkstemp's 0600
    assert not list(out.rglob("*.part")), "no temporary file is left behind"
    # the augmented model loads, carries the payload, and the simulator runs it
    model = robots.load(report["model_out"])
    nominal = robots.load("puma560")
    added = model.model.body("payload1").mass[0]
    assert added == pytest.approx(mass, rel=1e-5)
    run = sim.simulate(run_config(robot=report["model_out"], task="pick_place", cycles=1), progress=False)
    assert np.all(np.isfinite(run.tau_m))
    assert np.sum(model.model.body_mass) == pytest.approx(np.sum(nominal.model.body_mass) + mass, rel=1e-5)
    written = json.loads((out / "model" / "parameters.json").read_text())
    assert written["effects"]["payload"]["mass"] == pytest.approx(mass, rel=1e-5)
    assert written["units"]["effects"]["payload"]["mass"] == "kg"
    assert written["gear_ratio"] == pytest.approx(nominal.gear_ratio.tolist(), rel=1e-5)


def test_two_hidden_effects_are_found_one_after_the_other(tmp_path):
    """The loop repeats until nothing is significant: a payload and Coulomb friction on axis 5
    (the worked example of docs/calibration.md), and then it stops. Which comes first is a near
    tie of the search's ranking: payload first before the convergence work (0.2372 -> 0.1191 ->
    0.0129), Coulomb first since (0.2366 -> 0.1304 -> 0.0124; -> 0.0118 since the payload carries
    its inertia; four cycles); on two cycles 0.2438 -> 0.1353 -> 0.0119, mass 2.2085 kg, Coulomb
    +0.02999 N m; on the one cycle of this test (since 2026-11-27) mass 2.2060 kg, Coulomb
    +0.02998 N m, the gap after 0.049 of the gap before. Both are found, with their values."""
    robot = robots.load("puma560")
    payload = synth.Hidden.of(robot, "payload", {None: {"mass": 2.2}})
    with_payload = robots.load(synth.write_model(robot, payload, tmp_path / "payload_model"))
    friction = robot.friction  # both of axis 5's Coulomb levels 0.03 N m higher
    coulomb = synth.Hidden.of(robot, "coulomb", {4: {"coulomb_pos": friction.coulomb_pos[4] + 0.03,
                                                     "coulomb_neg": friction.coulomb_neg[4] + 0.03}})
    path = synth.record(with_payload, coulomb, tmp_path / "measured.csv", seed=3, cycles=1)
    result = calibrate("puma560", path, tmp_path / "out", figure=False)
    found = {s.effect.id: s for s in result.steps}
    assert sorted((s.effect.id, s.axes) for s in result.steps) == [("coulomb", [4]), ("payload", [0, 1, 2, 3, 4, 5])]
    assert found["payload"].effect.mass == pytest.approx(2.2, rel=0.03)
    change = found["coulomb"].effect.coulomb_pos[4] - robot.friction.coulomb_pos[4]
    assert change == pytest.approx(0.03, rel=0.03)
    assert result.steps[0].gap_after["total_nrmse"] < result.gap_before["total_nrmse"]
    assert result.gap_after["total_nrmse"] < 0.15 * result.gap_before["total_nrmse"]
