"""The fleet (`faultgen fleet`): wall time, file size, validity, and memory flat in the robots.

    python benchmarks/fleet.py [--jobs 2] [--days 60] [--small 4] [--skip-full]

In one run of this script:

- the default fleet (26 robots, 60 days, 2 cycles a day) on ``--jobs`` workers: wall time
  (goal <= 15 min on this 2-core machine), file size (goal <= 200 MB), validity;
- peak memory (RSS of this process and its workers, sampled every 50 ms) of a fleet of N and of
  2N robots (``--small`` N, 10 days each): the ratio must stay near 1 (runs are independent and
  the merge copies one run at a time).

The last line is ``memory ratio <2N over N>``.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from benchmarks_common import PeakRSS  # sibling module

from faultgen.data import dataset
from faultgen.runs import fleet, sweep
from faultgen.runs.context import ExecutionContext


def timed(plan: fleet.Fleet, jobs: int, out: Path) -> tuple[float, int]:
    """Wall time (s) and peak RSS of the process tree (bytes) of one fleet."""
    with PeakRSS() as memory:
        started = time.perf_counter()
        sweep.run(plan, out, ExecutionContext(jobs), progress=False)
        wall = time.perf_counter() - started
    return wall, memory.peak


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--days", type=int, default=60)
    parser.add_argument("--small", type=int, default=4, help="N of the memory comparison (N and 2N robots)")
    parser.add_argument("--skip-full", action="store_true", help="only the memory comparison")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        if not args.skip_full:
            plan = fleet.Fleet(days=args.days)
            out = folder / "fleet.h5"
            wall, peak = timed(plan, args.jobs, out)
            problems = dataset.validate(out)
            print(f"fleet {plan.size} robots x {plan.days} days x {plan.cycles_per_day} cycles/day, {args.jobs} jobs: "
                  f"{wall:.0f} s ({wall / 60:.1f} min), {out.stat().st_size / 1e6:.1f} MB, peak RSS {peak / 1e6:.0f} MB, "
                  f"{'valid' if not problems else 'INVALID: ' + problems[0]}")
        peaks = []
        for size in (args.small, 2 * args.small):
            plan = fleet.Fleet(size=size, failing=size // 2, days=10)
            wall, peak = timed(plan, args.jobs, folder / f"fleet-{size}.h5")
            peaks.append(peak)
            print(f"fleet {size} robots x 10 days: {wall:.0f} s, peak RSS {peak / 1e6:.0f} MB")
    print(f"memory ratio {peaks[1] / peaks[0]:.2f}")


if __name__ == "__main__":
    main()
