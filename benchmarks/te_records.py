"""How many records a unit transfer entropy needs to name the worn axis (issue 59, part 5: the
records behind :func:`faultgen.bench.verdicts.records_needed`).

Six irb6700 pick-and-place runs of 100 cycles, exp4 wear to +20 % on each axis in turn (seed 1), by
`faultgen sweep`; then, for n records, 30 random subsets of n of the 100 cycles (in time order) of
every run, and the share of them on which transfer entropy (10 and 5 bins, history 1) names the worn
axis, and the share it leaves undecided (tied scores).

    python benchmarks/te_records.py -o te-sweep.h5      # the sweep (about 4 min on 2 shared cores), then the table
"""

from __future__ import annotations

import argparse
import subprocess
from pathlib import Path

import h5py
import numpy as np

from analysis import isolation
from faultgen import children


def worn_runs(out: Path) -> tuple[list[np.ndarray], list[int]]:
    """The six runs' per-cycle mean absolute motor torque (100, 6) and worn axis, from the sweep
    file ``out`` (made by `faultgen sweep` when missing)."""
    if not out.exists():
        axes = [a for k in range(1, 7) for a in ("--axis", str(k))]
        subprocess.run([*children.command("-m", "faultgen.cli"), "sweep", "--robot", "irb6700", "--task", "pick_place",
                        *axes, "--wear-pct", "20", "--schedule", "exp4", "--cycles", "100", "--seed", "1",
                        "--features-only", "--jobs", "1", "--no-progress", "-o", str(out)],
                       env=children.environment(), check=True)
    with h5py.File(out) as f:
        runs = sorted(f["runs"])
        return ([f["runs"][r]["mean_abs_torque"][()] for r in runs],
                [int(f["runs"][r].attrs["worn_axes"][0]) for r in runs])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--out", type=Path, required=True, help="the sweep file (made when missing)")
    args = parser.parse_args()
    data, worn = worn_runs(args.out)
    rng = np.random.default_rng(0)
    print("| bins | records | worn axis named % | undecided % |\n| --- | --- | --- | --- |")
    for bins in (10, 5):
        for n in (12, 16, 21, 26, 31, 36, 41, 51):
            named = []
            for _ in range(30):
                rows = np.sort(rng.choice(100, n, replace=False))
                named += [(isolation.make("transfer_entropy", bins=bins).fit(X[rows]).source_axis_, w)
                          for X, w in zip(data, worn, strict=True)]
            print(f"| {bins} | {n} | {100 * np.mean([a == w for a, w in named]):.0f} | "
                  f"{100 * np.mean([a == 0 for a, _ in named]):.0f} |")


if __name__ == "__main__":
    main()
