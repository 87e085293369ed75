"""The designed excitation's regressor condition number against the default motions' (issue 39).

For each robot, ``faultgen excitation``'s design (:func:`faultgen.calibrate.excitation.design`,
default settings, seed 0): the condition number of the stacked, column-normalised regressors of
the designable effects of its first random start, of the best of its random starts and of the
optimised design; then, on the same columns (the design's ``columns``), the independent set's
random Fourier excitations (tests/independent_set.py, one per case seed of that robot) and the
narrow motion of its ``-15`` logs, each on one 10 s period at 100 Hz.

    python benchmarks/calibration_excitation.py                  # both robots, a few minutes each
    python benchmarks/calibration_excitation.py --robots puma560
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import independent_set  # tests/independent_set.py

from faultgen.calibrate import excitation
from faultgen.model import robots


def run(name: str) -> dict:
    robot = robots.load(name)
    started = time.perf_counter()
    designed = excitation.design(robot)
    seconds = time.perf_counter() - started
    keep = list(designed.columns)
    default = []
    narrow = None
    for case in independent_set.CASES:
        if case.robot != name or case.designed:
            continue
        rng = np.random.default_rng(case.seed)
        middle = None
        if case.range_share is not None:
            middle = independent_set.heavy_pose(robot, independent_set.toolbox(name))
        t, q, qd, qdd = independent_set.excitation(robot, 100, 10.0, rng, case.range_share, middle)
        value = excitation.condition_number(robot, t, q, qd, qdd, keep=keep)
        if case.range_share is not None:
            narrow = value if narrow is None else narrow  # the -15 logs' motion (its -16 twin is not narrow)
        elif case.seed not in [c.seed for c in independent_set.CASES if c.robot == name and c.range_share] and \
                "-16-" not in case.name:
            default.append(value)
    return {"robot": name, "designed": designed.condition_number, "first_start": designed.start_condition_number,
            "best_start": designed.best_start_condition_number, "default": np.array(default), "narrow": narrow,
            "seconds": seconds}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--robots", nargs="*", default=["puma560", "irb6700"])
    args = parser.parse_args()
    rows = [run(name) for name in args.robots]
    print("| motion | " + " | ".join(r["robot"] for r in rows) + " |")
    print("| --- | " + " | ".join("---" for _ in rows) + " |")
    print("| default: the independent set's random Fourier excitation, one per seed | " + " | ".join(
        f"median {np.median(r['default']):.1f} ({r['default'].min():.1f}-{r['default'].max():.1f}, "
        f"{len(r['default'])} seeds)" for r in rows) + " |")
    print("| the -15 narrow motion | " + " | ".join(f"{r['narrow']:.0f}" for r in rows) + " |")
    print("| design: first random start | " + " | ".join(f"{r['first_start']:.1f}" for r in rows) + " |")
    print(f"| design: best of {excitation.STARTS} random starts | "
          + " | ".join(f"{r['best_start']:.1f}" for r in rows) + " |")
    print(f"| designed (L-BFGS-B, {excitation.ITERATIONS} iterations from the best start) | "
          + " | ".join(f"{r['designed']:.1f} ({r['seconds']:.0f} s)" for r in rows) + " |")


if __name__ == "__main__":
    main()
