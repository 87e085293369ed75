"""Static-friction runs bit-identical before and after the per-step friction update became arrays
(issue 57, item 4: ``faultgen.simulation.friction_update``).

Writes one robot model (puma560 with a warm-up drift in time, ``temperature``, on axes 1 and 3, and
load-dependent friction on axis 2 in the transmitted-load form and on axis 3 in the static-load
form; a growing fault runs on the drift alone) and simulates with each checkout (first on
``PYTHONPATH``, the same interpreter), on the ``batch`` and the ``loop`` backend: wear on two axes
with the operating conditions on (joint temperature, unit spread with a gear loss), and a growing
load-dependent friction fault (a gear loss per cycle) beside wear; pick and place grips a part
mid-cycle. Every array of every run is compared bit for bit; then the loop backend against the
batch one within the new checkout (about 80 s on the shared 2-core machine).

    python benchmarks/stribeck_update_identical.py --base /tmp/base --new . -o /tmp/sui

Exit status 0 when every array is identical, 1 otherwise.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

from faultgen import children

import numpy as np

#: The runs: name -> (keyword arguments of RunConfig beyond the robot, backend).
RUNS = {
    "conditions_batch": ("conditions", "batch"),
    "conditions_loop": ("conditions", "loop"),
    "fault_batch": ("fault", "batch"),
    "fault_loop": ("fault", "loop"),
}


def write_robot(folder: Path) -> Path:
    """The puma560 with the stepped effects above, as an MJCF file in ``folder`` (beside it
    ``puma560_drift.xml``, the drift alone: a growing load-dependent fault needs a robot without
    the effect)."""
    import shutil

    import mujoco

    from faultgen import effects
    from faultgen.model import robots

    robot = robots.load("puma560")
    folder.mkdir(parents=True, exist_ok=True)
    spec = mujoco.MjSpec.from_file(str(robot.path))
    drift = effects.get("temperature").fitted(robot, {0: {"amplitude": 0.4, "time_constant": 3.0},
                                                      2: {"amplitude": 0.2, "time_constant": 8.0}})
    drift.write(spec, robot, [0, 2])
    (folder / "puma560_drift.xml").write_text(spec.to_xml())
    load = effects.get("load_dependent_friction").fitted(robot, {1: {"coefficient": 0.04, "gravity_load": 0},
                                                                 2: {"coefficient": 0.06, "gravity_load": 1}})
    load.write(spec, robot, [1, 2])
    path = folder / "puma560_stepped.xml"
    path.write_text(spec.to_xml())
    shutil.copyfile(robot.path.parent / "tasks.toml", folder / "tasks.toml")
    return path


def simulate(robot: Path, out: Path) -> None:
    """Every run of :data:`RUNS` on ``robot`` with the faultgen on the path, into ``out`` (npz)."""
    import faultgen
    from faultgen.operation import conditions as c
    from faultgen.operation.faults import parse_fault
    from faultgen.operation.wear import WearPlan, parse_wear
    from faultgen.simulation import stepping as sim

    out.mkdir(parents=True, exist_ok=True)
    common = {"task": "pick_place", "friction": "stribeck", "cycles": 6, "record": (1, 4, 6), "seed": 3,
              "nthread": 1}
    two_axes = WearPlan(dict(parse_wear(w, 6) for w in ("2:linear:30", "3:exp4:20")))
    configs = {
        "conditions": sim.RunConfig(str(robot), **common, wear=two_axes,
                                    conditions=c.Conditions(thermal=c.Temperature(),
                                                            spread=c.UnitSpread(gear_loss=0.2))),
        "fault": sim.RunConfig(str(robot.with_name("puma560_drift.xml")), **common,
                               wear=WearPlan(dict([parse_wear("1:linear:30", 6)])),
                               fault=parse_fault("load_dependent_friction:2:coefficient:0.06", last_cycle=6)),
    }
    for name, (config, backend) in RUNS.items():
        from faultgen.simulation import backends  # steppers travel as objects since r7; names before
        given = {"stepper": backends.get(backend)} if hasattr(backends, "STEPPERS") else {"backend": backend}
        run = faultgen.simulate(configs[config], progress=False, **given)
        arrays = {k: np.asarray(v) for k, v in vars(run).items()
                  if isinstance(v, np.ndarray) and v.dtype.kind in "fiub"}
        np.savez(out / f"{name}.npz", **arrays)


def differences(a: Path, b: Path) -> list[str]:
    """The arrays that differ between the npz files ``a`` and ``b`` (NaN equal to NaN)."""
    x, y = np.load(a), np.load(b)
    found = [f"{k}: in one only" for k in sorted(set(x.files) ^ set(y.files))]
    for k in sorted(set(x.files) & set(y.files)):
        if x[k].shape != y[k].shape or not np.array_equal(x[k], y[k], equal_nan=x[k].dtype.kind == "f"):
            found.append(f"{k}: differs")
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", type=Path, help="checkout before the change")
    parser.add_argument("--new", type=Path, help="checkout after the change")
    parser.add_argument("-o", "--out", type=Path, required=True)
    parser.add_argument("--simulate", type=Path, help=argparse.SUPPRESS)  # a child: the robot's MJCF
    parser.add_argument("--write-robot", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.write_robot:
        print(write_robot(args.out))
        return 0
    if args.simulate:
        simulate(args.simulate, args.out)
        return 0
    environments = {label: children.environment({"PYTHONPATH": str(checkout.resolve())})
                    for label, checkout in (("new", args.new), ("base", args.base))}
    robot = args.out / "robot" / "puma560_stepped.xml"
    if not robot.exists():
        subprocess.run(children.command(__file__, "--write-robot", "-o", str(robot.parent)),
                       env=environments["new"], check=True)
    for label, env in environments.items():
        if not (args.out / label).exists():
            subprocess.run(children.command(__file__, "--simulate", str(robot), "-o", str(args.out / label)),
                           env=env, check=True)
    bad = 0
    pairs = [(f"{name}: base vs new", args.out / "base" / f"{name}.npz", args.out / "new" / f"{name}.npz")
             for name in RUNS]
    pairs += [(f"{config}: loop vs batch (new)", args.out / "new" / f"{config}_loop.npz",
               args.out / "new" / f"{config}_batch.npz") for config in ("conditions", "fault")]
    for label, a, b in pairs:
        found = differences(a, b)
        print(f"{label}: {len(np.load(a).files)} arrays, " + ("identical" if not found else ", ".join(found)))
        bad += bool(found)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
