"""The wear in the robot's own scale (issue 59, part 1) against the truth of two independent fleets.

    python benchmarks/monitor_wear_scale.py --law first|hump [--seed 0] [--work DIR] [--robot DIR]
                                            [--out monitor] [--no-calibrate]

In one run of this script:

- the fleet, 12 units x 120 days, 8 worn (linearly from a day drawn in 20-50 to 60 % on day 120),
  in ``WORK/logs`` with its truth in ``WORK/truth.csv``: ``--law first`` the generator of
  :mod:`faultgen.bench.independent` (wear grows Coulomb and Stribeck friction alike), ``--law
  hump`` the same draws with a growing, widening Stribeck hump (``benchmarks/wear_hump_fleet.py``);
  the truth is the increase of the worn axis's dry friction in % of the unit's own. A fleet already
  there is kept (its units are drawn from the seed: the same files);
- ``faultgen monitor LOGS --robot KR210 -o WORK/OUT`` (the calibrated twin, the default; an OUT of
  an earlier run is continued, so a rerun only rewrites the outputs), timed;
- per worn unit, over its logs with true wear in [10, 40] %, from ``OUT/wear.csv``: the worn axis's
  scale (the slope of its estimate on the true wear past 5 %), the median absolute error, the share
  of logs whose 90 % interval covers the truth, and the true wear at the unit's alarm
  (``alarms.csv``); the healthy units' alarms.

Each figure is printed beside the issue's criterion and its verdict: the 90 % interval covers the
truth on at least 80 % of the worn axis's logs, the median absolute error is at most 3 points, the
default alarm (``--wear-limit 10``) falls between 10 and 15 % true wear; healthy units quiet.
"""

from __future__ import annotations

import argparse
import csv
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from faultgen import children

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import independent_fleet
import pinocchio_log
import wear_hump_fleet

COVERAGE, ERROR, ALARM = 0.80, 3.0, (10.0, 15.0)


def verdict(ok: bool) -> str:
    return "met" if ok else "NOT met"


def evaluate(truth_path: Path, out: Path) -> tuple[list[dict], list[str]]:
    """Per worn unit its figures (module docstring); the healthy units that alarm."""
    truth = independent_fleet.read_truth(truth_path)
    outcome = independent_fleet.evaluate(truth_path, out / "alarms.csv")
    estimates: dict[tuple[str, int], dict[str, tuple[float, float, float]]] = {}
    with open(out / "wear.csv", newline="") as f:
        for r in csv.DictReader(f):
            estimates.setdefault((r["unit"], int(r["axis"])), {})[r["stamp"]] = (
                float(r["wear"]), float(r["wear_5"]), float(r["wear_95"]))
    rows = []
    for unit, t in truth.items():
        if not t["axis"]:
            continue
        true = dict(zip(t["stamps"], t["wear"]))
        est = estimates.get((unit, t["axis"]), {})
        p = np.array([(true[s], *est[s]) for s in est])
        window = (p[:, 0] >= 10) & (p[:, 0] <= 40)
        past5 = p[:, 0] > 5
        error = p[window, 1] - p[window, 0]
        covered = (p[window, 2] <= p[window, 0]) & (p[window, 0] <= p[window, 3])
        o = outcome[unit]
        rows.append({"unit": unit, "axis": t["axis"], "scale": float(np.polyfit(p[past5, 0], p[past5, 1], 1)[0]),
                     "errors": np.abs(error), "bias": float(np.median(error)), "covered": covered,
                     "half": float(np.median(p[window, 3] - p[window, 2]) / 2), "alarm": o["wear"],
                     "named": o["source"]})
    healthy = [u for u, o in outcome.items() if not o["axis"] and o["alarm"]]
    return rows, healthy


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--law", choices=("first", "hump"), default="first")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--work", type=Path, default=None)
    parser.add_argument("--robot", type=Path, default=None, help="The KR210 folder (made in WORK/kr210 if not given).")
    parser.add_argument("--out", default="monitor", help="The monitor's OUT, inside WORK.")
    parser.add_argument("--no-calibrate", action="store_true")
    parser.add_argument("--wear-growth", type=float, default=1.0,
                        help="The wear's exponent from its onset (faultgen.bench.independent.wear_percent; 1 linear).")
    args = parser.parse_args()
    work = args.work or Path(tempfile.mkdtemp(prefix="wear-scale-"))
    robot = args.robot or pinocchio_log.add_kr210(work / "kr210")
    spec = independent_fleet.FleetSpec(units=12, worn=8, days=120, seed=args.seed, wear_growth=args.wear_growth)
    if args.law == "first":
        _, logs, truth = independent_fleet.write_fleet(work, spec, robot=robot)
    elif (work / "truth.csv").is_file():
        logs, truth = work / "logs", work / "truth.csv"
    else:
        logs, truth = wear_hump_fleet.write_fleet(work, spec, robot)
    out = work / args.out
    command = [*children.command("-m", "faultgen.cli"), "monitor", str(logs), "--robot", str(robot), "-o", str(out),
               "--no-progress"] + (["--no-calibrate"] if args.no_calibrate else [])
    started = time.perf_counter()
    result = subprocess.run(command, env=children.environment(), capture_output=True, text=True, check=False)
    if result.returncode not in (0, 3):
        raise SystemExit(f"{' '.join(command)} failed:\n{result.stderr[-3000:]}")
    print(f"{args.law} law, seed {args.seed}: faultgen monitor {'--no-calibrate ' if args.no_calibrate else ''}"
          f"in {time.perf_counter() - started:.0f} s (an OUT continued only rewrites its outputs)")
    rows, healthy = evaluate(truth, out)
    print("| unit (worn axis) | scale (estimate per % true wear) | median abs. error, points (bias) | "
          "90 % interval: median half-width, covers truth | true wear at the alarm (axis named) |")
    print("| --- | --- | --- | --- | --- |")
    for r in rows:
        alarm = "none" if r["alarm"] is None else f"{r['alarm']:.1f} % (axis {r['named']})"
        print(f"| {r['unit']} ({r['axis']}) | {r['scale']:.2f} | {np.median(r['errors']):.1f} ({r['bias']:+.1f}) | "
              f"{r['half']:.1f}, {r['covered'].sum()} of {r['covered'].size} ({r['covered'].mean():.0%}) | {alarm} |")
    errors = np.concatenate([r["errors"] for r in rows])
    covered = np.concatenate([r["covered"] for r in rows])
    alarms = [r["alarm"] for r in rows]
    inside = sum(a is not None and ALARM[0] <= a <= ALARM[1] for a in alarms)
    named = sum(r["named"] == r["axis"] for r in rows)
    print(f"| fleet | {min(r['scale'] for r in rows):.2f}-{max(r['scale'] for r in rows):.2f} | "
          f"{np.median(errors):.2f} (<= {ERROR:g}: {verdict(np.median(errors) <= ERROR)}) | "
          f"{covered.sum()} of {covered.size} ({covered.mean():.1%}; >= {COVERAGE:.0%}: "
          f"{verdict(covered.mean() >= COVERAGE)}) | {inside} of {len(alarms)} in {ALARM[0]:g}-{ALARM[1]:g} % "
          f"({verdict(inside == len(alarms))}; at "
          f"{', '.join('none' if a is None else f'{a:.1f}' for a in sorted(alarms, key=lambda a: a or 1e9))}); "
          f"axis named {named} of {len(rows)}; healthy units alarming: {len(healthy)} "
          f"({verdict(not healthy)}) |")


if __name__ == "__main__":
    main()
