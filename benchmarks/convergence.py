"""Numerical convergence of the simulation: per-cycle features against the physics step.

Both robots x three tasks x both friction models, each at the model's own step h (0.5 ms) and at
2h, h/2, h/4, h/8: the same MJCF with only ``timestep`` changed (``robots.with_timestep``), one
run of 100 cycles recording cycles 1 and 100, every axis wearing 20 % on the thesis's exp4
schedule (eq. 6.6), sensor noise and disturbance off. Per axis, from cycle 1:

- ``mean|tau|``: mean |motor torque|, N m at the motor side;
- ``rms_tau``: RMS motor torque, N m;
- ``mean|f|``: mean |true friction torque|, N m;
- ``track``: largest |arm angle - reference|, rad;

and ``wear``: mean |motor torque| of cycle 100 minus cycle 1 (the wear signature, N m).

The step -> 0 limit of each is Richardson-extrapolated from h/4 and h/8 for a first-order method
(``2 f(h/8) - f(h/4)``); the error of the default step is ``|f(h) - limit| / |limit|``. The table
prints, per robot, task, model and quantity, the worst axis, its error at h/2, and the ratio of
successive differences ``|f(h/8) - f(h/4)| / |f(h/4) - f(h/2)|`` (0.5 when first order holds
there, as the extrapolation assumes). Goals
(issue "Converged physics"): mean|tau|, rms_tau, mean|f| within 1 %, track and wear within 5 %.

This is an independent check in the sense of docs/simulation.md: the answer must not change
when the step is refined; it does not compare with another simulator.

    python benchmarks/convergence.py [--robots irb6700 puma560] [--tasks ...] [--friction ...]
                                     [--jobs 2] [--csv convergence.csv]

The last line is ``worst <relative error>``: the largest error of the default step, each
quantity divided by its goal and multiplied by 1 % (so <= 0.01 means every goal is met);
the line before it names where.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
from joblib import Parallel, delayed

from faultgen.effects import friction as friction_models
from faultgen.model import robots
from faultgen.operation import tasks
from faultgen.operation.wear import WearPlan
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim
from faultgen.simulation.resolve import resolve
from faultgen.simulation.spec import RunSpec

#: Steps as multiples of the model's own: coarser to show where it breaks, finer for the limit.
FACTORS = (2.0, 1.0, 0.5, 0.25, 0.125)
#: Relative goal per quantity (issue "Converged physics").
GOALS = {"mean|tau|": 0.01, "rms_tau": 0.01, "mean|f|": 0.01, "track": 0.05, "wear": 0.05}
CYCLES = 100


def features(robot_file: Path, task: str, friction: str) -> dict[str, np.ndarray]:
    """Per-axis features of one run at the step of ``robot_file``; NaN when it diverges or the
    model refuses the step (``friction.check_lugre_step``)."""
    config = resolve(RunSpec(
        robot=str(robot_file), task=task, friction=friction, cycles=CYCLES, record=(1, CYCLES),
        wear=WearPlan.from_specs([f"{axis}:exp4:20" for axis in range(1, 7)], last_cycle=CYCLES),
        noise=sensors.NoiseConfig(0.0, 0.0), nthread=1,
    )).config
    try:
        sim.build(robots.load(robot_file), friction)
    except ValueError as err:  # a step the model refuses (friction.check_lugre_step)
        print(f"refused: {err}")
        return {name: np.full(6, np.nan) for name in GOALS}
    try:
        run = sim.simulate(config, progress=False)
    except sim.SimulationDiverged as err:
        print(f"diverged: {err}")
        return {name: np.full(6, np.nan) for name in GOALS}
    mean_abs = np.mean(np.abs(run.tau_m), axis=1)
    return {
        "mean|tau|": mean_abs[0],
        "rms_tau": np.sqrt(np.mean(run.tau_m[0] ** 2, axis=0)),
        "mean|f|": run.mean_friction_torque[0],
        "track": run.tracking_error[0],
        "wear": mean_abs[1] - mean_abs[0],
    }


def one_case(robot: str, task: str, friction: str, folder: str) -> list[dict]:
    """Rows (one per quantity and axis) of one robot, task and friction model."""
    h = robots.load(robot).model.opt.timestep
    results = {}
    for factor in FACTORS:
        path = robots.with_timestep(robot, h * factor, Path(folder) / f"{robot}_{factor}")
        results[factor] = features(path, task, friction)
    rows = []
    for name in GOALS:
        fine, finer = results[0.25][name], results[0.125][name]
        limit = 2 * finer - fine
        for axis in range(6):
            row = {"robot": robot, "task": task, "friction": friction, "quantity": name, "axis": axis + 1,
                   "limit": limit[axis]}
            for factor in FACTORS:
                row[f"h*{factor:g}"] = results[factor][name][axis]
            row["error"] = abs(results[1.0][name][axis] - limit[axis]) / abs(limit[axis])
            row["error_h/2"] = abs(results[0.5][name][axis] - limit[axis]) / abs(limit[axis])
            row["order_ratio"] = abs(finer[axis] - fine[axis]) / max(abs(fine[axis] - results[0.5][name][axis]),
                                                                      1e-300)
            rows.append(row)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", nargs="+", default=sorted(robots.available()))
    parser.add_argument("--tasks", nargs="+", default=list(tasks.TASKS), choices=tasks.TASKS)
    parser.add_argument("--friction", nargs="+", default=list(friction_models.MODELS),
                        choices=friction_models.MODELS)
    parser.add_argument("--jobs", type=int, default=2, help="cases run in parallel")
    parser.add_argument("--csv", type=Path, help="also write every axis and step to this CSV file")
    args = parser.parse_args()

    cases = [(r, t, f) for r in args.robots for t in args.tasks for f in args.friction]
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        rows = Parallel(n_jobs=args.jobs)(delayed(one_case)(*case, folder) for case in cases)
    table = pd.DataFrame([row for case in rows for row in case])
    if args.csv:
        table.to_csv(args.csv, index=False)
    table["score"] = table["error"] / table["quantity"].map(GOALS) * 0.01
    print(f"steps: default h and h x {', '.join(f'{f:g}' for f in FACTORS if f != 1)}; {len(cases)} cases, "
          f"{time.perf_counter() - started:.0f} s; error = |f(h) - limit| / |limit|, limit = 2 f(h/8) - f(h/4)")
    summary = (table.sort_values("error").groupby(["robot", "task", "friction", "quantity"], sort=False).tail(1)
               .sort_values(["robot", "task", "friction", "quantity"]))
    with pd.option_context("display.width", 200, "display.max_rows", 500):
        print(summary[["robot", "task", "friction", "quantity", "axis", "h*1", "limit", "error", "error_h/2",
                       "order_ratio"]].to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    if set(args.friction) == set(friction_models.MODELS):
        print("lugre against the static model at the limit: (lugre - stribeck) / stribeck, per axis, %")
        limits = table.pivot_table(index=["robot", "task", "quantity", "axis"], columns="friction", values="limit")
        difference = 100 * (limits["lugre"] - limits["stribeck"]) / limits["stribeck"].abs()
        for (robot, task, name), part in difference.groupby(level=[0, 1, 2]):
            if name in ("mean|tau|", "mean|f|"):
                print(f"  {robot:8} {task:11} {name:10} " + " ".join(f"{v:+7.2f}" for v in part.to_numpy()))
    for name, goal in GOALS.items():
        part = table[table["quantity"] == name]
        print(f"{name:>10}: worst error {part['error'].max():.4f} (goal {goal:g}), "
              f"met on {int((part['error'] <= goal).sum())} of {len(part)} axis cases")
    worst = table.loc[table["score"].idxmax()]
    print(f"worst: {worst['quantity']} of axis {worst['axis']}, {worst['robot']} {worst['task']} "
          f"{worst['friction']}: error {worst['error']:.4f} against a goal of {GOALS[worst['quantity']]:g}")
    print(f"worst {worst['score']:.4f}")


if __name__ == "__main__":
    main()
