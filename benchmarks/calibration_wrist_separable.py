"""The wrist's dry friction level on logs of a known plant (issue 72 item 3): a UR5 fleet simulated
by faultgen's own stepping, each unit's log calibrated as the monitor does, every axis's fitted dry
level against the plant's.

    python benchmarks/calibration_wrist_separable.py [--seeds 1 2 3 4 5 6] [--friction lugre]
        [--no-payload] [--jobs 2] [--csv levels.csv]

As a user would: `faultgen robots add ur5 --from docs/examples/ur5_dh.toml -o ur5` into a temporary
folder; per seed one unit as `faultgen fleet` makes one (`stepping.simulate` with
`Conditions(thermal=Temperature(), payloads=Payloads((1.5, 3.5) kg, blocks), spread=UnitSpread())`,
`--friction` (LuGre, the fleet's default, or `stribeck`: static friction), faultgen's default sensor
noise, one cycle), the units running pick_place, spot_weld and arc_weld in turn, its log in
faultgen's measured format (`t, q, tau, temperature, payload`), calibrated with
`calibrate(..., friction_every_axis=True)` (the monitor's call). Truth: the plant's Coulomb level
over the nominal one (the unit spread's dry multiplier times the temperature law's factor).

Prints per unit and axis the dry level over nominal: the level the interval rule alone wrote (the
joint fit's, or NS: held at nominal) -> the level written now (NS, the check that held it in
brackets: precision or range, faultgen.calibrate.separable) and the truth, then
every miss: a level written that is off the truth by more than the unit spread
(:data:`faultgen.calibrate.separable.SHARE` of nominal), and a level held although the joint fit
was within 5 % of nominal of the truth. Exits 0 (a table, not a gate).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np
from joblib import Parallel, delayed

from faultgen import children
from faultgen.data import cells

TASKS = ("pick_place", "spot_weld", "arc_weld")
DH_TABLE = Path(__file__).resolve().parents[1] / "docs" / "examples" / "ur5_dh.toml"
#: A level held although the joint fit was within this share of nominal of the truth: a price.
RIGHT = 0.05


def add_robot(folder: Path) -> Path:
    """`faultgen robots add ur5 --from docs/examples/ur5_dh.toml -o folder/ur5`; the robot folder."""
    robot = folder / "ur5"
    done = subprocess.run([*children.command("-m", "faultgen.cli"), "robots", "add", "ur5", "--from", str(DH_TABLE),
                           "-o", str(robot)], env=children.environment(), capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"faultgen robots add failed ({done.returncode}):\n{done.stdout}{done.stderr}")
    return robot


def simulate(robot_folder: Path, seed: int, friction: str, payload: bool, out: Path) -> dict:
    """One unit's one-cycle log written to ``out`` (faultgen's measured format); its truth."""
    from faultgen.model import robots
    from faultgen.operation import conditions, wear
    from faultgen.simulation import sensors
    from faultgen.simulation import stepping
    from faultgen.simulation.resolve import resolve
    from faultgen.simulation.spec import RunSpec

    robot = robots.load(str(robot_folder))
    task = TASKS[(seed - 1) % len(TASKS)]
    payloads = conditions.Payloads((1.5, 3.5), (0.08, 0.11), "blocks", 1) if payload else None
    held = conditions.Conditions(thermal=conditions.Temperature(), payloads=payloads, spread=conditions.UnitSpread(),
                                 cycles_per_day=1, start_day=91.0)
    config = resolve(RunSpec(robot=str(robot_folder), task=task, friction=friction, wear=wear.WearPlan({}),
                             cycles=1, seed=seed, noise=sensors.NoiseConfig(), nthread=1, conditions=held,
                             signals=True), resolved=robot).config
    run = stepping.simulate(config, progress=False)
    n = robot.n_axes
    names = ["t", *(f"q{k}" for k in range(1, n + 1)), *(f"tau{k}" for k in range(1, n + 1)),
             *(f"temperature{k}" for k in range(1, n + 1))]
    columns = [run.t, run.q_a[0], run.tau_m[0] * robot.gear_ratio,
               np.repeat(run.conditions.joint_temperature[0][None], len(run.t), axis=0)]
    if payload:
        names.append("payload")
        columns.append(np.full(len(run.t), run.conditions.payload_mass[0]))
    np.savetxt(out, np.column_stack(columns), delimiter=",", header=cells.line(names), comments="", fmt="%.9g")
    return {"task": task, "dry": run.conditions.dry_friction_factor[0], "viscous": run.conditions.viscous_factor[0]}


def calibrate_unit(robot_folder: Path, log: Path, out: Path) -> dict:
    """The monitor's calibration of one log: per axis the dry level over nominal, joint fit and
    written, the viscous level over nominal written, and the check's record."""
    from faultgen.calibrate import calibrate
    from faultgen.model import robots

    nominal = robots.load(str(robot_folder))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = calibrate(nominal, log, out, progress=False, friction_every_axis=True, figure=False)
    f0, f1 = nominal.friction, result.model.friction
    dry0 = (np.abs(f0.coulomb_pos) + np.abs(f0.coulomb_neg)) / 2
    written = (np.abs(f1.coulomb_pos) + np.abs(f1.coulomb_neg)) / 2 / dry0
    checks = next((s["evidence"]["dry_level_check"] for s in result.report()["steps"]
                   if s["evidence"].get("every_axis")), {})
    joint = written.copy()
    for axis, check in checks.items():
        if check.get("fitted_dry_Nm") is not None:
            joint[int(axis) - 1] = check["fitted_dry_Nm"] / dry0[int(axis) - 1]
    return {"written": written, "joint": joint, "viscous": np.asarray(f1.viscous) / np.asarray(f0.viscous),
            "checks": checks}


def reason(check: dict) -> str:
    """The check that held a level, in a word."""
    return (check.get("held_by") or "interval") if not check.get("separable", True) else ""


def before_rule(check: dict, joint: float) -> str:
    """The level the rule of 2026-11-27 (the dry level's 95 % interval within 15 % of nominal, alone)
    wrote: the joint fit's, or 1.00 NS (held at nominal)."""
    if not check:
        return f"{joint:.2f}"
    return f"{joint:.2f}" if check.get("share") is not None and check["share"] <= 0.15 else "1.00 NS"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5, 6], help="one unit a seed")
    parser.add_argument("--friction", choices=("lugre", "stribeck"), default="lugre", help="the plant's friction")
    parser.add_argument("--no-payload", action="store_true", help="no payload (the static-friction variant's)")
    parser.add_argument("--jobs", type=int, default=2, help="units calibrated at once")
    parser.add_argument("--csv", type=Path, help="also write every axis's levels here")
    args = parser.parse_args()
    from faultgen.calibrate import separable

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        robot = add_robot(tmp)
        truths = {s: simulate(robot, s, args.friction, not args.no_payload, tmp / f"unit{s:02d}.csv") for s in args.seeds}
        found = Parallel(n_jobs=args.jobs)(delayed(calibrate_unit)(robot, tmp / f"unit{s:02d}.csv", tmp / f"out{s:02d}")
                                           for s in args.seeds)
    rows, misses = [], []
    print(f"UR5, {args.friction}, payload {'no' if args.no_payload else 'yes'}: dry level over nominal, "
          "before (the interval rule alone) -> after (truth); NS: not separable, held at nominal [by]")
    print("| unit (task) | " + " | ".join(f"axis {a}" for a in range(1, 7)) + " |")
    print("| --- " * 7 + "|")
    for seed, fit in zip(args.seeds, found, strict=True):
        truth = truths[seed]
        line = []
        for a in range(6):
            check = fit["checks"].get(str(a + 1), {})
            held = reason(check)
            before = before_rule(check, fit["joint"][a])
            line.append(f"{before} -> {fit['written'][a]:.2f}{' NS [' + held + ']' if held else ''} "
                        f"({truth['dry'][a]:.2f})")
            rows.append([seed, truth["task"], a + 1, truth["dry"][a], fit["joint"][a], fit["written"][a], held,
                         truth["viscous"][a], fit["viscous"][a]])
            if not held and abs(fit["written"][a] - truth["dry"][a]) > separable.SHARE:
                misses.append(f"unit {seed} axis {a + 1}: written {fit['written'][a]:.2f}, truth {truth['dry'][a]:.2f}"
                              f" (viscous {fit['viscous'][a]:.2f}, truth {truth['viscous'][a]:.2f})")
            elif held and abs(fit["joint"][a] - truth["dry"][a]) <= RIGHT:
                misses.append(f"unit {seed} axis {a + 1}: held [{held}] although fitted right "
                              f"({fit['joint'][a]:.2f}, truth {truth['dry'][a]:.2f})")
        print(f"| {seed} ({truth['task']}) | " + " | ".join(line) + " |")
    print("misses:" if misses else "misses: none")
    for miss in misses:
        print(f"  {miss}")
    if args.csv:
        with open(args.csv, "w", newline="") as out:
            table = cells.writer(out)
            table.writerow(["unit", "task", "axis", "truth_dry", "joint_dry", "written_dry", "held_by",
                            "truth_viscous", "written_viscous"])
            table.writerows(rows)


if __name__ == "__main__":
    main()
