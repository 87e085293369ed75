"""The simulation's hot paths bit-identical before and after a change to their Python (round 10,
"ssim"): sha256 of every output array of

- ``faultgen simulate``, the default (``lugre``) and the static friction model (``stribeck``, stepped
  one step at a time with the friction update applied from Python), both robots;
- a monitor twin's signature cycles (:class:`faultgen.monitor.twin.Twin`, one batch);
- hidden-effect logs of :func:`faultgen.calibrate.synth.record` (the CSV's bytes) and the
  ``report.json`` of ``faultgen calibrate`` on them (IRB-6700-like backlash, integrated gearboxes;
  PUMA 560 backlash, rigid contact), paths left out;
- ``faultgen fleet --friction-test-every``;
- the functions themselves on seeded inputs: ``Robot.inverse_dynamics`` (with and without a
  dead band), ``gearbox_load``, ``static_load``, ``arm_mass_matrix``,
  ``calibrate.gearbox.compliance_torque`` (one and many dead-band sets), every task's trajectory
  (``operation.tasks.ptp``), ``MotorFriction.stribeck_level`` and ``stribeck_torque``.

Run it with each checkout first on ``PYTHONPATH`` (the same interpreter) and compare the two
outputs (about 2 minutes each on the shared 2-core machine)::

    PYTHONPATH=/work/main python benchmarks/sim_hot_paths_identical.py /tmp/id_main > main.txt
    PYTHONPATH=. python benchmarks/sim_hot_paths_identical.py /tmp/id_new > new.txt
    diff main.txt new.txt && echo identical

Each line is ``name sha256``; the last line is ``all <sha256 of the lines above>``.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import h5py
import numpy as np


def digest(*arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(str((a.dtype.str, a.shape)).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def h5_digest(path: Path) -> str:
    """Every dataset of an HDF5 file, by name (attributes, which hold provenance, left out)."""
    h = hashlib.sha256()

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            h.update(name.encode())
            h.update(digest(obj[()]).encode())

    with h5py.File(path) as f:
        f.visititems(visit)
    return h.hexdigest()


def cli(*args: str) -> None:
    from typer.testing import CliRunner

    from faultgen.cli import app

    result = CliRunner().invoke(app, list(args))
    if result.exit_code != 0:
        raise SystemExit(f"faultgen {' '.join(args)} failed:\n{result.output}")


def main(out: Path) -> None:
    from faultgen.calibrate import calibrate, synth
    from faultgen.model import robots
    from faultgen.monitor.twin import Twin

    import faultgen

    print("faultgen from", Path(faultgen.__file__).parent, file=sys.stderr)
    out.mkdir(parents=True, exist_ok=True)
    lines = []

    def put(name, value):
        lines.append(f"{name} {value}")
        print(lines[-1], flush=True)

    # (a) faultgen simulate
    runs = {
        "simulate_lugre_puma": ["--robot", "puma560", "--task", "pick_place", "--wear", "2:linear:20",
                                "--cycles", "6", "--record", "1,6", "--seed", "3"],
        "simulate_stribeck_puma": ["--robot", "puma560", "--task", "pick_place", "--friction", "stribeck",
                                   "--wear", "2:linear:20", "--wear", "5:step:30", "--cycles", "6",
                                   "--record", "1,3,6", "--seed", "4"],
        "simulate_stribeck_irb": ["--robot", "irb6700", "--task", "spot_weld", "--friction", "stribeck",
                                  "--wear", "3:exp4:40", "--cycles", "4", "--record", "1,4", "--seed", "5"],
    }
    for name, args in runs.items():
        path = out / f"{name}.h5"
        path.unlink(missing_ok=True)
        cli("simulate", *args, "-o", str(path))
        put(name, h5_digest(path))
    # (b) a monitor twin's signature cycles, one batch
    puma, irb = robots.load("puma560"), robots.load("irb6700")
    log = synth.record(puma, synth.Hidden(None), out / "twin_program.csv", cycles=1, seed=1)
    twin = Twin(puma, log, out / "twin_cache_new")
    put("twin_signatures", digest(twin.signatures, twin.cycle(float("nan"), 0.0)))
    for f in (out / "twin_cache_new").glob("*.json"):
        f.unlink()
    # (c) hidden-effect logs and their calibration
    for robot, seed, cycles in ((irb, 4, 1), (puma, 0, 1)):
        hidden = synth.draw(robot, "backlash", np.random.default_rng(seed))
        folder = out / f"hidden_{robot.name}"
        path = synth.record(robot, hidden, folder / "measured.csv", seed=seed, cycles=cycles)
        put(f"hidden_log_{robot.name}", hashlib.sha256(path.read_bytes()).hexdigest())
        calibrate(robot.name, path, folder / "out", figure=False)
        report = json.loads((folder / "out" / "report.json").read_text())
        for key in ("measured", "model_out"):
            report.pop(key, None)
        put(f"calibrate_report_{robot.name}", hashlib.sha256(json.dumps(report, sort_keys=True).encode()).hexdigest())
    # (d) a fleet with friction tests
    path = out / "fleet_tested.h5"
    path.unlink(missing_ok=True)
    cli("fleet", "--robots", "2", "--failing", "1", "--robot", "puma560", "--days", "6", "--cycles-per-day", "1",
        "--friction-test-every", "2", "--seed", "2", "--jobs", "1", "--no-progress", "-o", str(path))
    put("fleet_friction_tests", h5_digest(path))
    functions(put, puma, irb)
    put("all", hashlib.sha256("\n".join(lines).encode()).hexdigest())


def functions(put, puma, irb) -> None:
    """The functions on seeded inputs, each line through ``put(name, sha256)``."""
    from faultgen.calibrate import gearbox
    from faultgen.effects.backlash import Backlash
    from faultgen.operation import programs

    rng = np.random.default_rng(0)
    for robot in (puma, irb):
        n, N = 400, robot.n_axes
        q = robot.home + rng.normal(0, 0.3, (n, N))
        qd, qdd = rng.normal(0, 1.0, (n, N)), rng.normal(0, 3.0, (n, N))
        t = np.arange(n) * 0.004
        put(f"inverse_dynamics_{robot.name}", digest(robot.inverse_dynamics(q, qd, qdd, t=t),
                                                     robot.inverse_dynamics(q, qd, qdd, friction=False)))
        backlash = Backlash().fitted(robot, {a: {"width": 0.01} for a in range(N)})
        dead = robot.edited(lambda spec: backlash.write(spec, robot, list(range(N))))
        put(f"inverse_dynamics_backlash_{robot.name}", digest(dead.inverse_dynamics(q, qd, qdd, t=t)))
        load = robot.gearbox_load(q, qd, qdd)
        put(f"loads_{robot.name}", digest(load, robot.static_load(q), robot.arm_mass_matrix(q[:50])))
        widths = np.abs(rng.normal(0, 0.01, (5, N)))
        smooth = robot.home + 0.3 * np.sin(np.outer(t, np.arange(1, N + 1)))
        sload = robot.gearbox_load(smooth, np.gradient(smooth, t, axis=0),
                                   np.gradient(np.gradient(smooth, t, axis=0), t, axis=0))
        put(f"compliance_{robot.name}", digest(gearbox.compliance_torque(robot, t, smooth, sload),
                                               gearbox.compliance_torque(robot, t, smooth, sload, widths[0]),
                                               gearbox.compliance_torque(robot, t, smooth, sload, widths)))
        paths = []
        for task in ("pick_place", "spot_weld", "arc_weld"):
            path = programs.load(robot, task).trajectory(0.004)
            paths += [path.q, path.qd, path.qdd]
        put(f"trajectories_{robot.name}", digest(*paths))
        v = rng.normal(0, 50.0, (n, N))
        v[::7] = 0.0
        f = robot.friction
        put(f"stribeck_{robot.name}", digest(f.stribeck_level(v), f.stribeck_level(v, rng.uniform(1, 2, (n, N))),
                                             f.stribeck_torque(v)))


if __name__ == "__main__":
    main(Path(sys.argv[1]))
