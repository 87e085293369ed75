"""The calibration workflow on robots of 5 and 7 axes: a hidden effect drawn on the test arms made
from the PUMA 560 (tests/axis_robots.py), recorded as a log, then `calibrate` on that log alone.

    python benchmarks/calibration_axes.py [--axes 7] [--effect torque_offset] [--seed 2]

Prints the hidden effect, the effects found and the held-out total nrmse before and after
(docs/calibration.md, "Robots of 5 to 7 axes").
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import axis_robots  # noqa: E402

from faultgen.calibrate import calibrate, synth  # noqa: E402
from faultgen.model import robots  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--axes", type=int, default=7, choices=(5, 7))
    parser.add_argument("--effect", default="torque_offset")
    parser.add_argument("--seed", type=int, default=2)
    parser.add_argument("--cycles", type=int, default=2)
    args = parser.parse_args()
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        robot = robots.load(axis_robots.make(folder, args.axes))
        hidden = synth.draw(robot, args.effect, np.random.default_rng(args.seed))
        log = synth.record(robot, hidden, Path(folder) / "log.csv", cycles=args.cycles)
        calibrate(str(robot.path), log, Path(folder) / "out", max_steps=2, progress=False)
        report = json.loads((Path(folder) / "out" / "report.json").read_text())
    print(f"{robot.name} ({robot.n_axes} axes), hidden: {hidden.record()}")
    print(f"found: {[(s['effect'], s['axes']) for s in report['steps']]}; held-out total nrmse "
          f"{report['gap_before']['total_nrmse']:.4f} -> {report['gap_after']['total_nrmse']:.4f} "
          f"({len(report['gap_before']['nrmse'])} axes); {time.perf_counter() - started:.0f} s")


if __name__ == "__main__":
    main()
