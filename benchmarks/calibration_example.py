"""The worked example of docs/calibration.md: a PUMA 560 torque log with two hidden effects.

Writes ``OUT/measured.csv``, made by our simulator with a 2.2 kg payload at the flange and extra
Coulomb friction on axis 5, then runs ``faultgen calibrate`` on it (the workflow is given the file
and the robot name only); the figure is ``OUT/calibration/calibration.png``. It writes nothing
else: ``--figure docs/images/calibration_example.png`` also copies the figure there, to refresh
the docs' image (a tracked file: only when the docs are to change).

    python benchmarks/calibration_example.py --out calib_example
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
from pathlib import Path

from faultgen import children
from faultgen.calibrate import synth
from faultgen.model import robots


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path("calib_example"))
    parser.add_argument("--cycles", type=int, default=4, help="Cycles of pick and place in the log (the docs': 4)")
    parser.add_argument("--figure", type=Path, default=None,
                        help="Also copy the figure here (docs/images/calibration_example.png refreshes the docs')")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    robot = robots.load("puma560")
    friction = robot.friction  # both Coulomb levels of axis 5 0.03 N m (motor side) higher
    payload = synth.Hidden.of(robot, "payload", {None: {"mass": 2.2}})
    coulomb = synth.Hidden.of(robot, "coulomb", {4: {"coulomb_pos": float(friction.coulomb_pos[4] + 0.03),
                                                     "coulomb_neg": float(friction.coulomb_neg[4] + 0.03)}})
    with_both = robots.load(synth.write_model(robot, payload, args.out / "hidden_model"))
    log = synth.record(with_both, coulomb, args.out / "measured.csv", seed=3, cycles=args.cycles)
    print(f"hidden: {payload}, {coulomb}\nmeasured log: {log}", flush=True)
    subprocess.run([*children.command("-m", "faultgen.cli"), "calibrate", "--robot", "puma560", "--measured", str(log),
                    "--out", str(args.out / "calibration")], env=children.environment(), check=True)
    figure = args.out / "calibration" / "calibration.png"
    if args.figure is not None:
        args.figure.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(figure, args.figure)
        figure = args.figure
    print(f"figure: {figure}")


if __name__ == "__main__":
    main()
