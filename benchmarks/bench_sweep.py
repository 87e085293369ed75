"""Sweep throughput, its ratio to MuJoCo's C stepping, parallel efficiency, HDF5 share, memory.

    python benchmarks/bench_sweep.py [--cycles 20] [--axes 4] [--j2] [--no-larger]

In one run of this script, on a grid of IRB-6700-like pick-and-place runs (no wear and worn
axes 1.., two seeds, every cycle recorded):

- throughput: simulated seconds per wall second per core, on 1 job;
- C limit: the same runs' stepping as one ``Batch.rollout`` call each (same set-points and
  disturbances, no Python in the loop, one thread), and the sweep's wall time over it;
- parallel efficiency on 2 jobs: t(1 job) / (2 t(2 jobs)); and, less moved by other work on a
  shared machine, the CPU time (this process and its workers, user + system) of each: CPU(1 job) /
  CPU(2 jobs) bounds the efficiency on 2 idle cores from above (at best the two cores are busy all
  through t(2 jobs); 1 job runs in this process, on one core), and the difference is what the
  2 jobs do more: the workers' start-up (their imports, the robot's compile) and the merge;
- a worker's start: the CPU time of a fresh ``python -P -c "import faultgen.runs.worker"`` (median
  of 3) against ``python -P -c pass``, the fixed cost each worker of the 2 jobs adds;
- HDF5 share: time writing part files plus the final merge, over the workers' busy time;
- peak memory (RSS of this process and its workers) for the grid and for a grid three times
  larger: it must not grow with the number of runs (--no-larger: not run);
- with --j2: wall time of the j2 preset on 2 jobs (thesis ch. 6: 21 runs x 100 cycles).

The last line is ``ratio <float>``: sweep wall time on 1 job over the C limit (goal <= 1.25).
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from benchmarks_common import PeakRSS, same_work_seconds  # sibling module

from faultgen import children
from faultgen.runs import sweep
from faultgen.runs.context import ExecutionContext


def tree_cpu() -> float:
    """CPU seconds (user + system) of this process, its ended children and its live ones (the
    sweep's workers, which loky keeps for the next sweep)."""
    import psutil

    me = psutil.Process()
    own = me.cpu_times()
    total = own.user + own.system + own.children_user + own.children_system
    for child in me.children(recursive=True):
        try:
            times = child.cpu_times()
        except psutil.Error:  # ended meanwhile: counted in children_* once reaped
            continue
        total += times.user + times.system
    return total


def import_cpu(code: str, repeat: int = 3) -> float:
    """Median CPU seconds (user + system) of a fresh ``python -P -c CODE``."""
    times = []
    for _ in range(repeat):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run(children.command("-c", code), env=children.environment(), check=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        times.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    return statistics.median(times)


def timed_sweep(grid: sweep.Grid, jobs: int, folder: Path) -> dict:
    stats, timings = [], {}
    with PeakRSS() as memory:
        cpu = tree_cpu()
        started = time.perf_counter()
        sweep.run(grid, folder / f"sweep-{jobs}-{len(grid.runs())}.h5", ExecutionContext(jobs), progress=False,
                  on_run=stats.append, timings=timings)
        wall = time.perf_counter() - started
        cpu = tree_cpu() - cpu
    return dict(wall=wall, cpu=cpu, stats=stats, merge=timings["merge"], peak=memory.peak)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cycles", type=int, default=20, help="cycles per run, all recorded")
    parser.add_argument("--axes", type=int, default=4, help="no wear + worn axes 1..AXES-1 (2..7), x 2 seeds")
    parser.add_argument("--j2", action="store_true", help="also time the j2 preset on 2 jobs")
    parser.add_argument("--no-larger", action="store_true", help="leave out the memory check's larger grid")
    args = parser.parse_args()
    # equal runs, an even number of them: the fair test of 2 jobs; the larger grid has three times
    # as many runs of the same size, so only the number of runs changes
    axes = list(range(args.axes))
    grid = sweep.Grid(robots=["irb6700"], tasks=["pick_place"], axes=axes, cycles=args.cycles, seeds=[0, 1])
    big = sweep.Grid(robots=["irb6700"], tasks=["pick_place"], axes=axes, cycles=args.cycles, seeds=list(range(6)))
    folder = Path(tempfile.mkdtemp(prefix="faultgen-bench-"))
    try:
        one = timed_sweep(grid, 1, folder)
        two = timed_sweep(grid, 2, folder)
        larger = None if args.no_larger else timed_sweep(big, 2, folder)
        start, bare = import_cpu("import faultgen.runs.worker"), import_cpu("pass")
        limit = sum(same_work_seconds(config) for _, config in grid.runs())
        simulated = sum(s.simulated for s in one["stats"])
        busy = sum(s.total for s in one["stats"])
        writing = sum(s.writing for s in one["stats"]) + one["merge"]
        stepping = sum(s.stepping for s in one["stats"])
        print(f"grid: {len(grid.runs())} runs x {args.cycles} cycles of pick and place, {simulated:.0f} simulated s")
        print(f"1 job:  wall {one['wall']:.2f} s, throughput {simulated / one['wall']:.1f} simulated s per wall s per core")
        print(f"        of which stepping {stepping:.2f} s, set-up and features {busy - stepping - writing + one['merge']:.2f} s, "
              f"HDF5 {writing:.2f} s")
        print(f"C limit (one Batch.rollout per run, 1 thread): {limit:.2f} s")
        print(f"2 jobs: wall {two['wall']:.2f} s, parallel efficiency {one['wall'] / (2 * two['wall']):.3f}")
        print(f"CPU (process and workers): 1 job {one['cpu']:.2f} s, 2 jobs {two['cpu']:.2f} s "
              f"(+{two['cpu'] - one['cpu']:.2f} s: workers' start-up, merge); efficiency bound on 2 idle cores "
              f"{one['cpu'] / two['cpu']:.3f}; load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
        print(f"a worker's start: import faultgen.runs.worker {start:.2f} s CPU (median of 3; python -c pass "
              f"{bare:.2f} s)")
        print(f"HDF5 share of busy time (1 job): {writing / (busy + one['merge']):.3f}")
        print(f"peak memory, 2 jobs: {two['peak'] / 1e6:.0f} MB for {len(grid.runs())} runs"
              + ("" if larger is None else f", {larger['peak'] / 1e6:.0f} MB for {len(big.runs())} runs"))
        if args.j2:
            started = time.perf_counter()
            sweep.run(sweep.Grid.from_preset("j2"), folder / "j2.h5", ExecutionContext(2), progress=True)
            print(f"j2 preset, 2 jobs: wall {time.perf_counter() - started:.1f} s")
        print(f"ratio {one['wall'] / limit:.3f}")
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
