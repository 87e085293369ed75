"""How long `faultgen calibrate` takes on a 40 s log at 500 Hz (goal: <= 60 s on the 2-core machine).

Logs of 40 s at 500 Hz (20 000 samples):

* roboticstoolbox-python's PUMA 560 (its own ``rne``: dynamics and friction of another library)
  along an excitation inside the joint ranges, 1 % torque noise, given as the PUMA 560;
* the same log with a hidden Coulomb friction rise on axis 2 (+30 % of the model's level, added at
  the arm side), so the loop has an effect to add;
* the IRB-6700-like arm along the same excitation, its torque from our own inverse dynamics (for
  speed only: not an independent check), 1 % noise and the same Coulomb rise on axis 2;
* two logs of the independent-simulator test set (tests/independent_set.py) with a payload and a
  Stribeck hump, one per robot: two steps, then backfitting.

Each is calibrated once (the whole workflow: plausibility guard, effect search, standard errors,
outputs). The baseline, measured in the same run, is one nominal prediction of the log
(``faultgen.calibrate.predict``: the rigid-body inverse dynamics every effect search starts from).
Prints seconds, the ratio to the 60 s goal and the ratio to the baseline.

    python benchmarks/calibration_speed.py
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import roboticstoolbox as rtb

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import independent_set  # tests/independent_set.py: the set has one definition, shared with the tests

from faultgen.calibrate import calibrate, predict, synth
from faultgen.logs import measured
from faultgen.model import robots

GOAL = 60.0
DURATION, PERIOD = 40.0, 0.002
#: Logs of tests/independent_set.py, 40 s at 500 Hz, with a payload and a Stribeck hump.
PAIRS = ("puma560-12-payload+stribeck_exponent", "irb6700-12-payload+stribeck_exponent")


def coulomb_rise(robot: robots.Robot, qd: np.ndarray, axis: int) -> np.ndarray:
    """Arm-side torque (n,) of a Coulomb level 30 % above the model's mean level on ``axis``."""
    coulomb = 0.5 * (robot.friction.coulomb_pos[axis] + robot.friction.coulomb_neg[axis])
    return 0.3 * coulomb * robot.gear_ratio[axis] * np.sign(qd[:, axis])


def logs() -> dict[str, tuple[robots.Robot, measured.MeasuredData]]:
    puma, irb = robots.load("puma560"), robots.load("irb6700")
    t, q, qd, qdd = synth.excitation([puma, irb], DURATION, PERIOD)
    tau = np.asarray(rtb.models.DH.Puma560().rne(q, qd, qdd))
    tau = tau + np.random.default_rng(0).normal(size=tau.shape) * 0.01 * np.sqrt(np.mean(tau**2, axis=0))
    worn = tau.copy()
    worn[:, 1] += coulomb_rise(puma, qd, 1)
    own = predict(irb, measured.from_arrays(t, q, np.zeros_like(tau), robot=irb))  # our own inverse dynamics
    own = own + np.random.default_rng(1).normal(size=own.shape) * 0.01 * np.sqrt(np.mean(own**2, axis=0))
    own[:, 1] += coulomb_rise(irb, qd, 1)
    found = {"toolbox PUMA 560": (puma, measured.from_arrays(t, q, tau, robot=puma)),
             "toolbox PUMA 560, Coulomb +30 % on axis 2": (puma, measured.from_arrays(t, q, worn, robot=puma)),
             "IRB-6700-like (own inverse dynamics), Coulomb +30 % on axis 2": (irb, measured.from_arrays(t, q, own, robot=irb))}
    # two effects (the loop, then backfitting): logs of the independent-simulator test set
    folder = tempfile.mkdtemp()
    for case in independent_set.CASES:
        if case.name in PAIRS:
            robot = puma if case.robot == "puma560" else irb
            path, _ = independent_set.make(case, folder)
            found[f"{case.name} (toolbox, Fourier excitation)"] = (robot, measured.read(path, robot))
    return found


def main() -> None:
    print(f"| log ({DURATION:g} s at {1 / PERIOD:g} Hz) | baseline: one prediction (s) | calibrate (s) | "
          f"/ goal {GOAL:g} s | / baseline | effects added |")
    print("| --- | --- | --- | --- | --- | --- |")
    worst = 0.0
    for name, (robot, data) in logs().items():
        start = time.perf_counter()
        predict(robot, data)
        baseline = time.perf_counter() - start
        with tempfile.TemporaryDirectory() as folder:
            start = time.perf_counter()
            result = calibrate(robot.name, data, Path(folder) / "out")
            seconds = time.perf_counter() - start
        added = ", ".join(f"{s.effect.id} on {[a + 1 for a in s.axes]}" for s in result.steps) or "none"
        worst = max(worst, seconds / GOAL)
        print(f"| {name} | {baseline:.2f} | {seconds:.1f} | {seconds / GOAL:.2f} | {seconds / baseline:.0f} | {added} |")
    print(f"worst ratio to the {GOAL:g} s goal: {worst:.2f} ({'met' if worst <= 1 else 'NOT met'})")


if __name__ == "__main__":
    main()
