"""Thesis Table 6.1 on the IRB-6700-like arm: 20 % wear on axis i, last cycle, all tasks.

For each task, one run with no wear and one run per worn axis (exp4 schedule to +20 % over 100
cycles, thesis eq. 6.6); only cycle 100 is simulated, with the same seed, so the runs differ only
by the wear. Prints, per task and worn axis, the mean +- std of the absolute motor torque of every
axis in cycle 100 (the layout of Table 6.1), and for the worn axis:

- the rise of its mean absolute motor torque against no wear;
- the added friction along the motion, mean(sign(v_m) (tau_f,worn - tau_f,nominal));
- the extra drive torque along the motion, mean(sign(v_m) (tau_m,worn - tau_m,nominal)),
  which equals the added friction when the drives pass all of it to the motor torque.

    python benchmarks/table_6_1.py [--friction lugre] [--seed 0] > table.md
"""

from __future__ import annotations

import argparse

import numpy as np

from faultgen.operation import tasks
from faultgen.operation.wear import WearPlan
from faultgen.simulation import stepping as sim
from faultgen.simulation.resolve import resolve
from faultgen.simulation.spec import RunSpec


def last_cycle(task: str, worn_axis: int, friction: str, seed: int) -> sim.RunResult:
    wear = WearPlan.from_specs([f"{worn_axis}:exp4:20"] if worn_axis else [], last_cycle=100)
    config = resolve(RunSpec(robot="irb6700", task=task, friction=friction, wear=wear, cycles=100,
                             record=(100,), seed=seed)).config
    return sim.simulate(config, progress=False)


def table(friction: str, seed: int) -> list[dict]:
    """One row per task and worn axis (0 = none), with the per-axis figures of cycle 100."""
    rows = []
    for task in tasks.TASKS:
        nominal = last_cycle(task, 0, friction, seed)
        base_torque = np.mean(np.abs(nominal.tau_m[-1]), axis=0)
        rows.append(dict(task=task, axis=0, torque=base_torque, std=np.std(np.abs(nominal.tau_m[-1]), axis=0)))
        direction = np.sign(nominal.qd_m[-1])
        for axis in range(1, 7):
            run = last_cycle(task, axis, friction, seed)
            torque = np.mean(np.abs(run.tau_m[-1]), axis=0)
            rows.append(dict(
                task=task, axis=axis, torque=torque, std=np.std(np.abs(run.tau_m[-1]), axis=0),
                rise=torque - base_torque,
                added_friction=np.mean(direction * (run.tau_f[-1] - nominal.tau_f[-1]), axis=0),
                extra_drive=np.mean(direction * (run.tau_m[-1] - nominal.tau_m[-1]), axis=0),
            ))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--friction", default="lugre")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    rows = table(args.friction, args.seed)
    print(f"Mean +- std of |motor torque| (N m, motor side) in cycle 100, IRB-6700-like, {args.friction} friction, "
          f"seed {args.seed}.\n")
    print("| task | worn axis | " + " | ".join(f"axis {i}" for i in range(1, 7))
          + " | rise of mean abs torque | added friction along motion | extra drive torque along motion"
          " | extra / added |")
    print("|" + " --- |" * 12)
    for row in rows:
        cells = " | ".join(f"{m:.3f} ± {s:.3f}" for m, s in zip(row["torque"], row["std"]))
        if row["axis"]:
            k = row["axis"] - 1
            added, extra = row["added_friction"][k], row["extra_drive"][k]
            tail = f"{row['rise'][k]:+.4f} | {added:.4f} | {extra:.4f} | {extra / added:.3f}"
        else:
            tail = "- | - | - | -"
        print(f"| {row['task']} | {row['axis']} | {cells} | {tail} |")
    worn = [r for r in rows if r["axis"]]
    ratio = np.array([r["extra_drive"][r["axis"] - 1] / r["added_friction"][r["axis"] - 1] for r in worn])
    others = np.array([np.max(np.abs(np.delete(r["rise"], r["axis"] - 1))) / r["added_friction"][r["axis"] - 1]
                       for r in worn])
    rises = sum(r["rise"][r["axis"] - 1] > 0 for r in worn)
    print(f"\nextra drive torque / added friction on the worn axis: min {ratio.min():.3f}, max {ratio.max():.3f}. "
          f"Mean abs torque of the worn axis rose in {rises} of {len(worn)} cases. Largest change of another "
          f"axis's mean abs torque, as a fraction of the worn axis's added friction: {others.max():.3f}.")


if __name__ == "__main__":
    main()
