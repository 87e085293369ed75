"""Cost of `faultgen simulate`'s stepping against MuJoCo's own C stepping of the same model.

Baseline: the very model `faultgen simulate` compiles (robot + PID drives + friction), stepped by
``mujoco.batch.Batch.step(nstep=...)`` in one call: no Python in the loop. Measured: the stepping
phase of ``faultgen.sim.simulate`` (set-point hand-over, disturbance, recording, divergence
checks) for the same number of simulations, steps and threads. Both are timed in this run,
alternately, best of ``--repeat``.

    python benchmarks/bench_simulate.py [--robot irb6700] [--task pick_place] [--friction lugre]
                                        [--cycles 20] [--threads 1] [--repeat 3]

The last line is ``ratio <float>`` (faultgen stepping time / C stepping time; goal <= 1.25).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from mujoco import batch as mjbatch

from faultgen import robots, sensors, sim, tasks
from faultgen.wear import WearPlan


def c_stepping_time(model_sim: sim.SimModel, task: str, n_sim: int, n_steps: int, nthread: int) -> float:
    """Seconds for MuJoCo to step ``n_sim`` copies of the model ``n_steps`` times, no Python in the loop."""
    robot = model_sim.robot
    q0 = tasks.load(robot, task).trajectory(model_sim.model.opt.timestep).q[0]
    batch = mjbatch.Batch(model_sim.model, nsim=n_sim, nthread=nthread)
    batch.qpos, batch.qvel = sim.start_state(robot, q0)
    batch.act = 0.0
    ctrl = np.zeros(model_sim.model.nu)
    ctrl[model_sim.drive_ctrl[:, 0]] = robot.gear_ratio * q0
    batch.ctrl = ctrl
    started = time.perf_counter()
    batch.step(nstep=n_steps)
    return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robot", default="irb6700")
    parser.add_argument("--task", default="pick_place", choices=tasks.TASKS)
    parser.add_argument("--friction", default="lugre")
    parser.add_argument("--cycles", type=int, default=20, help="recorded cycles, stepped together")
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()

    robot = robots.load(args.robot)
    model_sim = sim.build(robot, args.friction)
    config = sim.RunConfig(robot=args.robot, task=args.task, friction=args.friction, wear=WearPlan({}),
                           cycles=args.cycles, seed=0, nthread=args.threads)
    result = sim.simulate(config, progress=False)  # warm-up, and the step count
    n_steps = len(result.t) * int(round(sensors.LOG_PERIOD / model_sim.model.opt.timestep))
    sim_seconds = args.cycles * n_steps * model_sim.model.opt.timestep

    ours, base = [], []
    for _ in range(args.repeat):
        base.append(c_stepping_time(model_sim, args.task, args.cycles, n_steps, args.threads))
        ours.append(sim.simulate(config, progress=False).stepping_time)
    best_ours, best_base = min(ours), min(base)
    print(f"{args.robot} {args.task}, {args.friction} friction, {args.cycles} cycles x {n_steps} steps "
          f"({sim_seconds:.0f} simulated s), {args.threads} thread(s), best of {args.repeat}")
    print(f"MuJoCo C stepping (Batch.step):   {best_base:8.3f} s  {1e3 * best_base / sim_seconds:7.3f} ms per simulated s")
    print(f"faultgen simulate stepping:       {best_ours:8.3f} s  {1e3 * best_ours / sim_seconds:7.3f} ms per simulated s")
    print(f"ratio {best_ours / best_base:.3f}")


if __name__ == "__main__":
    main()
