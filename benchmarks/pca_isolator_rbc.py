"""The PCA isolator (``pca_contribution``) with reconstruction-based contributions against each
axis's share of Q, on six irb6700 pick-and-place runs of 100 cycles, exp4 wear to +20 % on each
axis in turn (seed 1, the sweep of ``benchmarks/te_records.py``), for three explained variances:
the axis each names from the per-cycle mean absolute motor torque (0: undecided, a tie).

    python benchmarks/pca_isolator_rbc.py -o te-sweep.h5      # the sweep (about 4 min on 2 shared cores), then the table
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import te_records  # noqa: E402  (the same sweep, made and read once)
from analysis import isolation  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--out", type=Path, required=True, help="the sweep file (made when missing)")
    args = parser.parse_args()
    data, worn = te_records.worn_runs(args.out)
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
