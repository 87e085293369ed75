"""Cost of `faultgen simulate`'s stepping against MuJoCo's own C stepping of the same model.

Measured: the stepping phase of ``faultgen.simulation.stepping.simulate`` (set-point and disturbance
hand-over a chunk at a time, recording, divergence checks). Baselines, on the very model `faultgen simulate`
compiles (robot + PID drives + friction), the same number of simulations, steps and threads, no
Python in the loop:

- same work: one ``Batch.rollout`` call over the whole cycle with the same set-points and
  disturbances, recording the same fields: the cost of this workload in MuJoCo alone;
- hold: one ``Batch.step(nstep=...)`` call with the drives holding the start pose (no inputs,
  no recording): MuJoCo's bare stepping speed, a lower bound.

All three are timed in this run, alternately, best of ``--repeat``.

    python benchmarks/bench_simulate.py [--robot irb6700] [--task pick_place] [--friction lugre]
                                        [--cycles 20] [--threads 1] [--repeat 3]

The last line is ``ratio <float>``: faultgen stepping time over the same-work baseline (goal <= 1.25).
"""

from __future__ import annotations

import argparse

from benchmarks_common import hold_seconds, same_work_seconds, simulated_seconds  # sibling module

from faultgen.operation import tasks
from faultgen.operation.wear import WearPlan
from faultgen.simulation import stepping as sim
from faultgen.simulation.resolve import resolve
from faultgen.simulation.spec import RunSpec


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robot", default="irb6700")
    parser.add_argument("--task", default="pick_place", choices=tasks.TASKS)
    parser.add_argument("--friction", default="lugre")
    parser.add_argument("--cycles", type=int, default=20, help="recorded cycles, stepped together")
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    config = resolve(RunSpec(robot=args.robot, task=args.task, friction=args.friction, wear=WearPlan({}),
                             cycles=args.cycles, seed=0, nthread=args.threads)).config
    sim.simulate(config, progress=False)  # warm-up
    sim_seconds = simulated_seconds(config)
    ours, same, hold = [], [], []
    for _ in range(args.repeat):
        hold.append(hold_seconds(config))
        same.append(same_work_seconds(config))
        ours.append(sim.simulate(config, progress=False).stepping_time)
    best = {"MuJoCo, hold (Batch.step)": min(hold), "MuJoCo, same work (Batch.rollout)": min(same),
            "faultgen simulate stepping": min(ours)}
    print(f"{args.robot} {args.task}, {args.friction} friction, {args.cycles} cycles "
          f"({sim_seconds:.0f} simulated s), {args.threads} thread(s), best of {args.repeat}")
    for name, seconds in best.items():
        print(f"{name:<36}{seconds:8.3f} s  {1e3 * seconds / sim_seconds:7.3f} ms per simulated s")
    print(f"ratio to hold {min(ours) / min(hold):.3f}")
    print(f"ratio {min(ours) / min(same):.3f}")


if __name__ == "__main__":
    main()
