"""The PCA isolator (``pca_contribution``) with reconstruction-based contributions against each
axis's share of Q, on six irb6700 pick-and-place runs of 100 cycles, exp4 wear to +20 % on each
axis in turn (seed 1, the sweep of ``benchmarks/te_records.py``), for three explained variances:
the axis each names from the per-cycle mean absolute motor torque (0: undecided, a tie).

    python benchmarks/pca_isolator_rbc.py -o te-sweep.h5      # the sweep (about 4 min on 2 shared cores), then the table
"""

from __future__ import annotations

import argparse
import subprocess
from pathlib import Path

import h5py
import numpy as np

from analysis import isolation
from faultgen import children


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--out", type=Path, required=True, help="the sweep file (made when missing)")
    args = parser.parse_args()
    if not args.out.exists():
        axes = [a for k in range(1, 7) for a in ("--axis", str(k))]
        subprocess.run(children.command("-m", "faultgen.cli", "sweep", "--robot", "irb6700", "--task", "pick_place",
                        *axes, "--wear-pct", "20", "--schedule", "exp4", "--cycles", "100", "--seed", "1",
                        "--features-only", "--jobs", "1", "--no-progress", "-o", str(args.out)),
                       env=children.environment(), check=True)
    with h5py.File(args.out) as f:
        runs = sorted(f["runs"])
        data = [f["runs"][r]["mean_abs_torque"][()] for r in runs]
        worn = [int(f["runs"][r].attrs["worn_axes"][0]) for r in runs]
    print("| variance | components | worn axis | RBC names | share of Q names |\n| --- | --- | --- | --- | --- |")
    right = {}
    for variance in (0.9, 0.75, 0.5):
        for X, axis in zip(data, worn):
            est = isolation.make("pca_contribution", variance=variance).fit(X)
            Z = (X[est.n_reference:] - est.mean_) / est.scale_
            share = ((Z - Z @ est.components_.T @ est.components_) ** 2).mean(axis=0)  # the isolator before RBC
            share_axis = isolation._pick(share)  # the isolators' rule: the unique largest, 0 on a tie
            print(f"| {variance:g} | {est.n_components_} | {axis} | {est.source_axis_} | {share_axis} |")
            right.setdefault(variance, [0, 0])
            right[variance][0] += est.source_axis_ == axis
            right[variance][1] += share_axis == axis
    for variance, (rbc, share) in right.items():
        print(f"variance {variance:g}: RBC names the worn axis on {rbc} of {len(data)} runs, the share of Q on {share} "
              f"(chance 1 in 6)")


if __name__ == "__main__":
    main()
