"""Cost of `faultgen simulate`'s stepping against MuJoCo's own C stepping of the same model.

Measured: the stepping phase of ``faultgen.sim.simulate`` (set-point and disturbance hand-over a
chunk at a time, recording, divergence checks). Baselines, on the very model `faultgen simulate`
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
import time

import mujoco
import numpy as np
from mujoco import batch as mjbatch

from faultgen import control, robots, sensors, sim, tasks
from faultgen.wear import WearPlan


def _batch(model_sim: sim.SimModel, q0: np.ndarray, n_sim: int, nthread: int) -> mjbatch.Batch:
    batch = mjbatch.Batch(model_sim.model, nsim=n_sim, nthread=nthread)
    batch.qpos, batch.qvel = sim.start_state(model_sim.robot, q0)
    batch.act = 0.0
    return batch


def hold_time(model_sim: sim.SimModel, q0: np.ndarray, n_sim: int, n_steps: int, nthread: int) -> float:
    """Seconds for ``Batch.step`` to step ``n_sim`` simulations holding ``q0`` for ``n_steps``."""
    batch = _batch(model_sim, q0, n_sim, nthread)
    ctrl = np.zeros(model_sim.model.nu)
    ctrl[model_sim.drive_ctrl[:, 0]] = model_sim.robot.gear_ratio * q0
    batch.ctrl = ctrl
    started = time.perf_counter()
    batch.step(nstep=n_steps)
    return time.perf_counter() - started


def same_work_time(model_sim: sim.SimModel, path, n_sim: int, n_steps: int, nthread: int) -> float:
    """Seconds for one ``Batch.rollout`` of the simulate workload: same inputs, same records."""
    model, robot = model_sim.model, model_sim.robot
    inputs = control.setpoints(robot, path.q, path.qd, path.qdd)
    inputs = np.vstack([inputs, np.repeat(inputs[-1:], max(0, n_steps - len(inputs)), axis=0)])[:n_steps]
    rng = np.random.default_rng(0)
    control_in = np.zeros((n_sim, n_steps, model.nu + model.nv))
    control_in[:, :, : model.nu][:, :, model_sim.drive_ctrl] = inputs
    control_in[:, :, model.nu + robot.arm_dof] = rng.standard_normal((n_sim, n_steps, 6))
    batch = _batch(model_sim, path.q[0], n_sim, nthread)
    spec = mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_QFRC_APPLIED
    started = time.perf_counter()
    batch.rollout(n_steps, control=control_in, control_spec=spec, record=("qpos", "qvel", "actuator_force"))
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

    path = tasks.load(robot, args.task).trajectory(model_sim.model.opt.timestep)
    ours, same, hold = [], [], []
    for _ in range(args.repeat):
        hold.append(hold_time(model_sim, path.q[0], args.cycles, n_steps, args.threads))
        same.append(same_work_time(model_sim, path, args.cycles, n_steps, args.threads))
        ours.append(sim.simulate(config, progress=False).stepping_time)
    best = {"MuJoCo, hold (Batch.step)": min(hold), "MuJoCo, same work (Batch.rollout)": min(same),
            "faultgen simulate stepping": min(ours)}
    print(f"{args.robot} {args.task}, {args.friction} friction, {args.cycles} cycles x {n_steps} steps "
          f"({sim_seconds:.0f} simulated s), {args.threads} thread(s), best of {args.repeat}")
    for name, seconds in best.items():
        print(f"{name:<36}{seconds:8.3f} s  {1e3 * seconds / sim_seconds:7.3f} ms per simulated s")
    print(f"ratio to hold {min(ours) / min(hold):.3f}")
    print(f"ratio {min(ours) / min(same):.3f}")


if __name__ == "__main__":
    main()
