"""The figures behind the calibration's plausibility guard (faultgen/calibrate/plausibility.py).

Per axis, the slope of the measured torque on the nominal model's prediction (with an intercept,
over the moving samples), on:

* hidden-effect logs of our own simulator (every effect and none, both robots, ``--seeds``
  seeds, two pick-and-place cycles each): what a right log looks like, effects included;
* roboticstoolbox-python's PUMA 560 (``rne``) along an excitation inside both robots' joint
  ranges, given as the PUMA 560 (right) and as the IRB-6700-like arm (wrong robot);
* every own log with its torque at the motor side (divided by the gear ratio).

Prints the range of the slopes per kind of log and whether the guard accepted every right log
and refused every wrong one.

    python benchmarks/calibration_plausibility.py --seeds 2      # about 6 minutes on 2 cores
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
import roboticstoolbox as rtb
from joblib import Parallel, delayed

from faultgen.calibrate import EFFECTS, ImplausibleLogError, plausibility, predict, search, synth
from faultgen.logs import measured
from faultgen.model import robots


def judged(robot: robots.Robot, data: measured.MeasuredData, tau: np.ndarray) -> tuple[np.ndarray, bool]:
    """The slopes of ``tau`` along ``data``'s motion on ``robot``, and whether the guard accepts it."""
    predicted = predict(robot, data)
    moving = np.abs(data.qd) >= search.REST_SPEED
    try:
        plausibility.check(robot, tau, predicted, moving)
        accepted = True
    except ImplausibleLogError:
        accepted = False
    return plausibility.slopes(tau, predicted, moving), accepted


def own_log(robot_name: str, effect: str | None, seed: int) -> dict:
    robot = robots.load(robot_name)
    hidden = synth.draw(robot, effect, np.random.default_rng(seed))
    with tempfile.TemporaryDirectory() as folder:
        path = synth.record(robot, hidden, Path(folder) / "measured.csv", cycles=2, seed=seed)
        data = measured.read(path, robot)
    return {"own, right robot": judged(robot, data, data.tau),
            "own, motor side": judged(robot, data, data.tau / robot.gear_ratio)}


def toolbox_logs() -> dict:
    puma, irb = robots.load("puma560"), robots.load("irb6700")
    t, q, qd, qdd = synth.excitation([puma, irb], 40.0, 0.002)
    tau = np.asarray(rtb.models.DH.Puma560().rne(q, qd, qdd))
    tau = tau + np.random.default_rng(0).normal(size=tau.shape) * 0.01 * np.sqrt(np.mean(tau**2, axis=0))
    as_puma = measured.from_arrays(t, q, tau, robot=puma)
    as_irb = measured.from_arrays(t, q, tau, robot=irb)
    return {"toolbox PUMA 560, right robot": judged(puma, as_puma, as_puma.tau),
            "toolbox PUMA 560, given as irb6700": judged(irb, as_irb, as_irb.tau)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=2)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    cases = [(r, e, s) for r in ("puma560", "irb6700") for e in (None, *EFFECTS) for s in range(args.seeds)]
    results = Parallel(n_jobs=args.jobs)(delayed(own_log)(*c) for c in cases)
    results.append(toolbox_logs())
    kinds: dict[str, list] = {}
    for result in results:
        for kind, outcome in result.items():
            kinds.setdefault(kind, []).append(outcome)
    print(f"| log ({len(cases)} own logs) | logs | judged axes | slope min | slope max | accepted |")
    print("| --- | --- | --- | --- | --- | --- |")
    for kind, outcomes in kinds.items():
        slopes = np.concatenate([s for s, _ in outcomes])
        finite = slopes[np.isfinite(slopes)]
        accepted = sum(a for _, a in outcomes)
        print(f"| {kind} | {len(outcomes)} | {finite.size} | {finite.min():.3g} | {finite.max():.3g} | "
              f"{accepted} of {len(outcomes)} |")


if __name__ == "__main__":
    main()
