"""How far a dataset's operating conditions hide its wear: the failing axis's daily load, per worn run.

    python benchmarks/fault_visibility.py fleet.h5 [fleet-nc.h5 ...] [--threshold 10]

For every worn run of each file: the worn axis's mean load torque per sample (the dataset's
``average_load_torque``, N m, what the "+estM" block of ``faultgen classify`` adds), its change
from the samples before the wear starts (true friction multiplier 1) to the failed samples (true
wear at least ``--threshold`` percent, the labels of ``faultgen classify``; for a fault other than
friction wear, that share of its final value, ``analysis.benchmark.fault_progress``), in percent
of the level before, and the same change over the sample-to-sample standard deviation before (a z-score). A
fault a classifier can find on a robot's own record has a large z; where the conditions move the
load more from day to day than the wear does, z falls below 1. docs/reproduction.md ("What the
operating conditions do to detection") holds the figures of the fleets measured.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from analysis.benchmark import fault_progress
from faultgen import axes
from faultgen.data import reader


def visibility(path: Path, threshold: float) -> list[dict]:
    """One row per worn run of ``path``: robot, task, worn axis (1..6), samples before the wear and
    failed, change of the worn axis's mean load torque (%) and its z-score."""
    rows = []
    with reader.open(path) as data:
        runs = [(run, fault_progress(run, run.worn_axes[0]), run.array("average_load_torque"))
                for run in data.failing]
    for run, grown, loads in runs:
        axis = axes.index(run.worn_axes[0])
        wear = (grown - 1.0) * 100.0
        load = loads[:, axis]
        before, failed = load[wear == 0.0], load[wear >= threshold]
        if before.size < 2 or not failed.size:
            continue
        change = failed.mean() - before.mean()
        rows.append({"run": run.id, "axis": axes.number(axis), "before": before.size, "failed": failed.size,
                     "change %": 100.0 * change / before.mean(), "z": change / before.std(ddof=1)})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="+", type=Path)
    parser.add_argument("--threshold", type=float, default=10.0, help="wear (%%) from which a sample is failed")
    args = parser.parse_args()
    for path in args.files:
        rows = visibility(path, args.threshold)
        print(f"\n{path}: {len(rows)} worn runs with samples before the wear and failed ones\n")
        print("| run | axis | before | failed | change % | z |\n| --- | --- | --- | --- | --- | --- |")
        for r in rows:
            print(f"| {r['run']} | {r['axis']} | {r['before']} | {r['failed']} | {r['change %']:+.1f} | {r['z']:+.2f} |")
        if rows:
            z = np.array([r["z"] for r in rows])
            print(f"\nz: median {np.median(z):+.2f}, {int(np.sum(z < 1))} of {len(z)} below 1")


if __name__ == "__main__":
    main()
