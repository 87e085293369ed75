"""Reading the friction tests of an independent fleet against their truth (issue 75, item 1's
fleets): `faultgen friction-test` on every test log of a small fleet, each axis's dry level and
viscous coefficient against ``truth_tests.csv``.

    python benchmarks/fleet_friction_tests.py [--law first|hump] [--units 3 --days 60 --every 14]
                                              [--seed 0] [--work DIR] [--robot DIR]

The fleet: the KR210 (rtb-data's URDF, added as a user adds it), ``--units`` units (two worn, on a
drawn axis, linearly from a day in 20-50 to 60 % on the last day) for ``--days`` days, a friction
test every ``--every`` days from day 1: ``--law first`` :mod:`faultgen.bench.independent`
(Lorentzian hump, arctangent sign, viscous falling 2 %/K; wear grows Coulomb and hump alike),
``--law hump`` ``benchmarks/wear_hump_fleet.py`` (exponential hump, tanh sign, dry level falling
0.4 %/K, viscous as 1 / (1 + 0.03 dT); wear grows the hump three times as fast, widens it, and grows
the viscous coefficient as the Coulomb level). Each test is faultgen's motion (``faultgen tasks
friction-test``) driven through that simulator's dynamics (Pinocchio) and friction law, drawn warm
or cold. So the check is on **faultgen's motion through another simulator**: the issue's first
criterion (a motion faultgen did not generate) is benchmarks/friction_test_independent.py's.

Per test log, ``faultgen friction-test LOG --robot KR210 -o OUT`` (the command, a process per log);
per axis over all tests: the largest dry-level and viscous errors (%, read over truth minus one)
and how many tests are within the criterion (dry 3 %, viscous 10 %), with a verdict; then every
miss listed (unit, stamp, axis, wear of the axis, temperature, errors).
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
import pandas as pd

from faultgen import children

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import pinocchio_log  # noqa: E402
import wear_hump_fleet  # noqa: E402

from faultgen.bench import independent  # noqa: E402

DRY, VISCOUS = 3.0, 10.0


def read_truth(path: Path) -> dict[tuple[str, str, int], dict]:
    """truth_tests.csv as ``{(unit, stamp, axis): {"coulomb", "viscous", "temperature"}}``."""
    with open(path, newline="") as f:
        return {(r["unit"], r["stamp"], int(r["axis"])): {"coulomb": float(r["coulomb_Nm"]),
                                                          "viscous": float(r["viscous_Nms_rad"]),
                                                          "temperature": float(r["temperature_degC"])}
                for r in csv.DictReader(f)}


def read_tests(logs: Path, robot: Path, out: Path) -> list[dict]:
    """``faultgen friction-test`` on every ``logs/<unit>/friction-test/<stamp>.csv``: one row per test and axis."""
    rows = []
    for log in sorted(logs.glob(f"*/{independent.TEST_FOLDER}/*.csv")):
        unit, stamp = log.parts[-3], log.stem
        target = out / unit / stamp
        command = [*children.command("-m", "faultgen.cli"), "friction-test", str(log), "--robot", str(robot),
                   "-o", str(target), "--overwrite"]
        result = subprocess.run(command, env=children.environment(), capture_output=True, text=True, check=False)
        if result.returncode:
            raise SystemExit(f"{' '.join(command)} failed:\n{result.stderr[-2000:]}")
        for _, fit in pd.read_csv(target / "friction_fit.csv").iterrows():
            rows.append({"unit": unit, "stamp": stamp, "axis": int(fit["axis"]), "coulomb": float(fit["coulomb_Nm"]),
                         "viscous": float(fit["viscous_Nms_rad"]), "model": fit["model"]})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--law", choices=("first", "hump"), default="first")
    parser.add_argument("--units", type=int, default=3)
    parser.add_argument("--days", type=int, default=60)
    parser.add_argument("--every", type=int, default=14)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--work", type=Path, default=None)
    parser.add_argument("--robot", type=Path, default=None, help="The KR210 folder (made in WORK/kr210 if not given).")
    args = parser.parse_args()
    work = args.work or Path(tempfile.mkdtemp(prefix="fleet-tests-"))
    robot = args.robot or pinocchio_log.add_kr210(work / "kr210")
    spec = independent.FleetSpec(units=args.units, worn=min(2, args.units), days=args.days, seed=args.seed,
                                 friction_test_every=args.every)
    started = time.perf_counter()
    if args.law == "first":
        logs, truth_path = independent.write_fleet(work / "fleet", spec, robot)
    else:
        logs, truth_path = wear_hump_fleet.write_fleet(work / "fleet", spec, robot)
    written = time.perf_counter() - started
    started = time.perf_counter()
    rows = read_tests(logs, robot, work / "read")
    truth, wear = read_truth(work / "fleet" / "truth_tests.csv"), independent.read_truth(truth_path)
    for r in rows:
        t = truth[(r["unit"], r["stamp"], r["axis"])]
        r["dry_error"] = 100 * (r["coulomb"] / t["coulomb"] - 1)
        r["viscous_error"] = 100 * (r["viscous"] / t["viscous"] - 1)
        r["temperature"] = t["temperature"]
        w = wear[r["unit"]]
        r["wear"] = float(w["wear"][w["stamps"].index(r["stamp"])]) if w["axis"] == r["axis"] else 0.0
    tests = len({(r["unit"], r["stamp"]) for r in rows})
    print(f"{args.law} law, seed {args.seed}: {args.units} units x {args.days} days, a test every {args.every} days: "
          f"{tests} tests written in {written:.0f} s, read by `faultgen friction-test` in "
          f"{time.perf_counter() - started:.0f} s (faultgen's motion through the independent simulator)")
    print("| axis | tests | dry level error, % (min..max) | within 3 % | viscous error, % (min..max) | within 10 % |")
    print("| --- | --- | --- | --- | --- | --- |")
    table = pd.DataFrame(rows)
    for axis, g in table.groupby("axis"):
        dry, vis = g["dry_error"].to_numpy(), g["viscous_error"].to_numpy()
        print(f"| {axis} | {len(g)} | {dry.min():+.2f}..{dry.max():+.2f} | {np.sum(np.abs(dry) <= DRY)} of {len(g)} | "
              f"{vis.min():+.2f}..{vis.max():+.2f} | {np.sum(np.abs(vis) <= VISCOUS)} of {len(g)} |")
    missed = table[(table["dry_error"].abs() > DRY) | (table["viscous_error"].abs() > VISCOUS)]
    ok = missed.empty
    print(f"verdict: {'every axis of every test within 3 % (dry) and 10 % (viscous)' if ok else f'{len(missed)} of {len(table)} axis reads outside'}")
    for _, r in missed.iterrows():
        print(f"  missed: {r['unit']} {r['stamp']} axis {r['axis']} (true wear {r['wear']:.1f} %, {r['temperature']:.1f} "
              f"degC, {r['model']}): dry {r['dry_error']:+.2f} %, viscous {r['viscous_error']:+.2f} %")


if __name__ == "__main__":
    main()
