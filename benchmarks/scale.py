"""Scaling a fleet out on a Dask cluster: cost per robot-day, memory per worker, output size, 1 vs 2
workers, results sent back vs a shared folder, and the client's merge at 500 robots x 365 days.

    python benchmarks/scale.py [--robots 2 4] [--days 10 30] [--merge-robots 500] [--merge-days 365]

In one run of this script, on local Dask clusters (``distributed.LocalCluster``, worker processes
of one thread on 127.0.0.1, the runs sent back to this process as in ``--scheduler``):

1. growth: a fleet of R robots x D days for each R of ``--robots`` and D of ``--days`` (2 cycles
   a day, as ``faultgen fleet``) on 2 workers, each fleet on a fresh cluster: worker core
   seconds per robot-day, the peak resident set of a worker, the file size per robot-day, the
   client's time writing parts; and over all runs, a robot's worker time fitted as a set-up
   (compiling its models: each robot carries its own parts) plus a cost per day;
2. efficiency: the fleet of the largest R and smallest D on 1 worker and on 2, alternated twice:
   t(1) / (2 t(2)) from the best of each;
3. transfer vs shared folder: a sweep whose runs keep their 250 Hz signals (4 runs x 10 cycles of
   pick and place), sent back through Dask or written by the workers into a folder they share;
4. merge: ``--merge-robots`` x ``--merge-days`` synthetic part files (a real fleet robot's daily
   records of each model repeated to the days, every float scaled by 1 + 1e-9 noise so that
   they compress like measured ones), written as the client writes parts, then merged as a
   sweep merges them: time, size and the client's peak memory.

The last lines are the plan for ``--merge-robots`` x ``--merge-days`` on N cores from these
figures (docs/performance.md, "Scaling out").
"""

from __future__ import annotations

import argparse
import tempfile
import time
from dataclasses import fields, replace
from pathlib import Path

import numpy as np
from benchmarks_common import PeakRSS  # sibling module

from faultgen.data import dataset
from faultgen.operation.conditions import CycleConditions
from faultgen.runs import cluster as cluster_module
from faultgen.runs import fleet, sweep
from faultgen.runs.context import ExecutionContext
from faultgen.simulation import stepping as sim

CYCLES_PER_DAY = 2


def local_cluster(workers: int):
    from distributed import LocalCluster

    return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                        dashboard_address=None, memory_limit=0)


def on_cluster(plan, out: Path, workers: int, shared: bool = False) -> dict:
    """Run ``plan`` on a fresh local cluster; wall time (cluster up), per-run stats, file size."""
    stats: list[sweep.RunStats] = []
    with local_cluster(workers) as cluster:
        started = time.perf_counter()
        sweep.run(plan, out, ExecutionContext(scheduler=cluster.scheduler_address), progress=False,
                  on_run=stats.append, shared=shared)
        wall = time.perf_counter() - started
    return {"wall": wall, "stats": stats, "size": out.stat().st_size,
            "worker_seconds": sum(s.total for s in stats), "writing": sum(s.writing for s in stats),
            "memory": max(s.memory for s in stats)}


def growth(folder: Path, robots: list[int], days: list[int]) -> list[dict]:
    rows = []
    print("fleet on 2 workers   robot-days  wall s  worker s/robot-day  peak per worker MB  kB/robot-day  "
          "client writing s")
    for r in robots:
        for d in days:
            plan = fleet.Fleet(size=r, failing=r // 2, days=d, cycles_per_day=CYCLES_PER_DAY)
            row = on_cluster(plan, folder / f"fleet-{r}x{d}.h5", 2)
            row.update(robots=r, days=d, robot_days=r * d)
            rows.append(row)
            print(f"{r:3d} robots x {d:3d} days  {r * d:10d}  {row['wall']:6.1f}  {row['worker_seconds'] / (r * d):18.3f}"
                  f"  {row['memory'] / 1e6:18.0f}  {row['size'] / (r * d) / 1e3:12.2f}  {row['writing']:16.2f}")
    return rows


def efficiency(folder: Path, robots: int, days: int) -> tuple[float, float]:
    plan = fleet.Fleet(size=robots, failing=robots // 2, days=days, cycles_per_day=CYCLES_PER_DAY)
    walls = {1: [], 2: []}
    for repeat in range(2):  # alternated: other work on the machine comes and goes
        for workers in (1, 2):
            walls[workers].append(on_cluster(plan, folder / f"eff-{workers}-{repeat}.h5", workers)["wall"])
    one, two = min(walls[1]), min(walls[2])
    print(f"{robots} robots x {days} days: 1 worker {' '.join(f'{w:.1f}' for w in walls[1])} s, 2 workers "
          f"{' '.join(f'{w:.1f}' for w in walls[2])} s; efficiency t(1) / (2 t(2)) = {one / (2 * two):.3f} (best of each)")
    return one, two


def transfer_vs_shared(folder: Path) -> dict:
    grid = sweep.Grid(robots=["irb6700"], tasks=["pick_place"], axes=[0, 1, 2, 3], cycles=10)
    out = {}
    for shared in (False, True):
        out["shared" if shared else "transfer"] = on_cluster(grid, folder / f"signals-{shared}.h5", 2, shared=shared)
    for key, row in out.items():
        n = len(row["stats"])
        print(f"signals sweep, {key:8s}: wall {row['wall']:.1f} s, {row['size'] / n / 1e6:.1f} MB per run, "
              f"writing {row['writing'] / n:.3f} s per run ({'client' if key == 'transfer' else 'worker'}), "
              f"simulating {row['worker_seconds'] / n:.2f} s per run")
    return out


def synthetic_parts(folder: Path, robots: int, days: int, template_days: int = 10) -> tuple[list, float]:
    """Part files of a fleet of ``robots`` x ``days`` from one simulated robot of each model."""
    plan = fleet.Fleet(size=robots, failing=robots // 2, days=days, cycles_per_day=CYCLES_PER_DAY)
    small = dict(fleet.Fleet(size=2, failing=1, days=template_days, cycles_per_day=CYCLES_PER_DAY).runs())
    templates = {config.robot: sim.simulate(config, progress=False) for config in small.values()}
    rng = np.random.default_rng(0)
    rows = np.arange(days) % template_days

    def grow(a):
        a = np.asarray(a)[rows]
        return a * (1 + 1e-9 * rng.standard_normal(a.shape)) if a.dtype.kind == "f" and a.size else a

    parts, writing = [], 0.0
    for run_id, config in plan.runs():
        t = templates[config.robot]
        conditions = replace(t.conditions, **{f.name: grow(getattr(t.conditions, f.name))
                                              for f in fields(CycleConditions) if f.name not in CycleConditions.PER_UNIT})
        result = replace(t, config=config, cycles=np.arange(1, days + 1), conditions=conditions,
                         features={name: grow(v) for name, v in t.features.items()},
                         **{name: grow(getattr(t, name)) for name in (*cluster_module.SIGNALS, "friction_multiplier",
                                                                      "mean_friction_torque", "tracking_error")})
        part = folder / f"{run_id}.h5"
        started = time.perf_counter()
        dataset.write_run(part, result, run_id=run_id)
        writing += time.perf_counter() - started
        parts.append((run_id, part))
    return parts, writing


def merge_cost(folder: Path, robots: int, days: int) -> dict:
    parts_folder = folder / "synthetic.parts"
    parts_folder.mkdir()
    parts, writing = synthetic_parts(parts_folder, robots, days)
    out = folder / "synthetic.h5"
    with PeakRSS() as memory:
        started = time.perf_counter()
        dataset.merge(parts, out)
        merge = time.perf_counter() - started
    size = out.stat().st_size
    print(f"synthetic {robots} robots x {days} days: writing the parts {writing:.1f} s ({writing / robots * 1e3:.0f} ms "
          f"per robot), merge {merge:.1f} s, {size / 1e6:.0f} MB ({size / (robots * days) / 1e3:.2f} kB per robot-day), "
          f"client peak RSS during the merge {memory.peak / 1e6:.0f} MB")
    return {"writing": writing, "merge": merge, "size": size, "memory": memory.peak}


def fit(rows: list[dict]) -> tuple[float, float, float]:
    """Worker seconds per robot-day at the longest days measured (each robot's set-up, compiling
    its models, spread over those days: an upper bound for longer records), the slowest robot's
    there, and for information a least-squares split of a robot's time into set-up + cost per day
    (unreliable when the machine's load moves between the fleets)."""
    longest = max(r["days"] for r in rows)
    at = [r for r in rows if r["days"] == longest]
    cost = sum(r["worker_seconds"] for r in at) / sum(r["robot_days"] for r in at)
    slowest = max(s.total / longest for r in at for s in r["stats"])
    days = np.array([r["days"] for r in rows for _ in r["stats"]], dtype=float)
    seconds = np.array([s.total for r in rows for s in r["stats"]])
    (per_day, setup), *_ = np.linalg.lstsq(np.column_stack([days, np.ones_like(days)]), seconds, rcond=None)
    print(f"at {longest} days: {cost:.3f} worker s per robot-day, slowest robot {slowest:.3f}; least squares over "
          f"{len(seconds)} runs: a robot = {setup:.1f} s set-up + {per_day:.3f} s per day")
    return cost, slowest


def plan(rows: list[dict], one: float, two: float, merged: dict, robots: int, days: int) -> None:
    """Time on N cores for ``robots`` x ``days`` from the measured costs."""
    cost, slowest = fit(rows)
    eff = one / (2 * two)
    work = robots * days * cost  # worker seconds
    longest = slowest * days
    memory = max(r["memory"] for r in rows)
    write_per_robot = merged["writing"] / robots
    print(f"plan for {robots} robots x {days} days ({robots * days} robot-days): {work / 3600:.1f} worker hours, "
          f"efficiency {eff:.3f} (measured on 2), memory {memory / 1e6:.0f} MB per worker, output "
          f"{merged['size'] / 1e9:.2f} GB, longest robot about {longest / 60:.1f} min, client writing "
          f"{write_per_robot * 1e3:.0f} ms per robot (as they arrive) + merge {merged['merge']:.0f} s at the end")
    for cores in (2, 16, 64, 256, robots):
        compute = max(work / (cores * eff), longest)  # one robot is one task: no faster than it
        print(f"  {cores:4d} cores: simulation {compute / 3600:7.2f} h + merge {merged['merge'] / 60:.1f} min "
              f"= {(compute + merged['merge']) / 3600:.2f} h; client busy writing parts "
              f"{100 * write_per_robot * robots / compute:.1f} % of the time")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[2, 4])
    parser.add_argument("--days", type=int, nargs="+", default=[10, 30])
    parser.add_argument("--merge-robots", type=int, default=500)
    parser.add_argument("--merge-days", type=int, default=365)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        rows = growth(folder, args.robots, args.days)
        one, two = efficiency(folder, max(args.robots), min(args.days))
        transfer_vs_shared(folder)
        merged = merge_cost(folder, args.merge_robots, args.merge_days)
        plan(rows, one, two, merged, args.merge_robots, args.merge_days)


if __name__ == "__main__":
    main()
