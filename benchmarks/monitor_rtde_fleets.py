"""Two independent UR fleets in the RTDE recorder's layout through ``faultgen monitor --format ur-rtde``
(issue 72, "What it must show": two independent fleets in RTDE layout, per fleet a table of status,
true wear at the alarm, axis and wear error; docs/analysis.md, "Independent UR fleets in the RTDE
recorder's layout").

    python benchmarks/monitor_rtde_fleets.py [--fleet ur5|ur10|both] [--units 6] [--days 40] [--work DIR]

What is independent and what is ours:

- **The arms**: the UR5 added from the shipped DH table (docs/examples/ur5_dh.toml) and a UR10 added
  from a DH table this script writes from roboticstoolbox-python's ``models/DH/UR10.py`` (Universal
  Robots' published kinematics, masses, centres of mass and inertias; the last link's Ixx, 0 there,
  set to 2e-4 kg m^2 so that the tensor is positive definite and meets the triangle inequality MuJoCo checks; speed, torque and payload limits
  from Universal Robots' UR10 data sheet: 120 deg/s on axes 1-2, 180 deg/s on 3-6, 330/330/150/56/56/56
  N m, 10 kg), each with ``faultgen robots add`` as a user would (its drivetrain sized by faultgen's rule).
- **The plant: not faultgen's.** Pinocchio's RNEA on a URDF that this script writes from the same DH
  table (:func:`dh_urdf`: one revolute joint and one fixed DH transform per row; faultgen's MuJoCo
  model is built from the table by its own importer), and the motor-side friction law, conditions,
  wear and noise of :mod:`faultgen.bench.independent` (Lorentzian Stribeck hump, arctangent sign,
  viscous friction falling with joint temperature; unlike faultgen's eq. 6.3). The RTDE layout, as
  the adapter reads it, carries no payload, so the parts are kept negligible (``max_part`` 0.05 kg).
- **The logs**: each day's log written in the RTDE recorder's layout (`tests/ur_rtde_logs.write_ur_log`:
  space-separated, ``timestamp``, ``actual_q_i``, ``actual_current_i`` = the arm torque over torque constants of ours
  (:data:`TORQUE_CONSTANTS`: NOT Universal Robots' numbers), ``target_moment_i`` (the first log's
  torque, the same every day, as a fixed program's command is), ``joint_temperatures_i`` and
  placeholder columns the recorder's default recipe has). The truth (truth.csv) is never read by the monitor.

The monitor runs as ``faultgen monitor LOGS --robot R --format ur-rtde --torque-constants K --train 10``
in a child process; the table per unit: the status in units.csv, the true wear at the stamp the alarm
became known (alarms.csv ``known``; the first alarming log in brackets), the alarm's axis against
the worn one, and the median absolute error of the filtered wear estimate (wear.csv, the worn axis,
monitoring logs with true wear > 0; percentage points).
"""

from __future__ import annotations

import argparse
import csv
import datetime
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import independent_fleet  # noqa: E402
import ur_rtde_logs  # noqa: E402

from faultgen import children  # noqa: E402
from faultgen.bench import independent  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
UR5_DH = ROOT / "docs/examples/ur5_dh.toml"
#: N m/A at the joint per fleet: ours, chosen (about a UR joint's order: motor constant times gear
#: ratio), not Universal Robots' numbers.
TORQUE_CONSTANTS = {"ur5": (11.0, 11.0, 11.0, 8.5, 8.5, 8.5), "ur10": (14.0, 14.0, 12.0, 8.5, 8.5, 8.5)}
#: The monitor's learning logs.
TRAIN = 10


def ur10_dh_table() -> str:
    """A DH table (TOML, :mod:`faultgen.model.import_dh`'s format) of the UR10 from
    roboticstoolbox-python's ``models.DH.UR10`` (module docstring)."""
    from roboticstoolbox.models.DH import UR10

    arm = UR10()
    speeds = np.radians([120, 120, 180, 180, 180, 180])
    efforts = (330.0, 330.0, 150.0, 56.0, 56.0, 56.0)
    lines = ["# The UR10 from roboticstoolbox-python's models/DH/UR10.py (Universal Robots' published",
             "# parameters); link 6's Ixx 2e-4 (0 there); limits from Universal Robots' UR10 data sheet.",
             'name = "ur10"', 'description = "Universal Robots UR10: toolbox DH kinematics and dynamics"',
             'convention = "standard"', "rated_payload = 10.0"]
    for k, link in enumerate(arm.links):
        inertia = np.array(link.I, dtype=float)
        if inertia[0, 0] <= 0.0:
            inertia[0, 0] = 2e-4
        six = [float(inertia[i, j]) for i, j in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))]
        lines += ["", "[[link]]", f"d = {float(link.d)!r}", f"a = {float(link.a)!r}", f"alpha = {float(link.alpha)!r}",
                  f"mass = {float(link.m)!r}", f"com = {[float(c) for c in link.r]!r}", f"inertia = {six!r}",
                  "qlim = [-6.283185307179586, 6.283185307179586]", f"speed = {float(speeds[k])!r}",
                  f"effort = {efforts[k]!r}"]
    return "\n".join(lines) + "\n"


def dh_urdf(table: Path) -> str:
    """A URDF of the standard DH ``table`` (TOML): per row a revolute joint about the previous DH
    frame's z and a fixed joint ``Tz(d) Tx(a) Rx(alpha)`` to the link's DH frame, which carries its
    mass, centre of mass and inertia (as the table gives them, in that frame); ``tool0`` at the last."""
    import tomllib

    data = tomllib.loads(Path(table).read_text())
    name = data["name"]
    parts = [f'<robot name="{name}">', '<link name="base_link"/>']
    parent = "base_link"
    for k, row in enumerate(data["link"], start=1):
        ixx, iyy, izz, ixy, ixz, iyz = row["inertia"]
        com = " ".join(f"{c!r}" for c in row["com"])
        low, high = row["qlim"]
        parts += [
            f'<link name="rot{k}"/>',
            f'<joint name="joint{k}" type="revolute"><parent link="{parent}"/><child link="rot{k}"/>'
            f'<axis xyz="0 0 1"/><limit lower="{low!r}" upper="{high!r}" effort="{row["effort"]!r}" '
            f'velocity="{row["speed"]!r}"/></joint>',
            f'<link name="link{k}"><inertial><origin xyz="{com}" rpy="0 0 0"/><mass value="{row["mass"]!r}"/>'
            f'<inertia ixx="{ixx!r}" iyy="{iyy!r}" izz="{izz!r}" ixy="{ixy!r}" ixz="{ixz!r}" iyz="{iyz!r}"/>'
            "</inertial></link>",
            f'<joint name="dh{k}" type="fixed"><parent link="rot{k}"/><child link="link{k}"/>'
            f'<origin xyz="{row["a"]!r} 0 {row["d"]!r}" rpy="{row["alpha"]!r} 0 0"/></joint>',
        ]
        parent = f"link{k}"
    parts += ['<link name="tool0"/>', f'<joint name="flange" type="fixed"><parent link="{parent}"/>'
              '<child link="tool0"/><origin xyz="0 0 0" rpy="0 0 0"/></joint>', "</robot>"]
    return "\n".join(parts) + "\n"


def add_arm(work: Path, name: str) -> Path:
    """``faultgen robots add NAME --from TABLE -o WORK/NAME`` (once), and the DH table's URDF as the
    folder's ``urdf_used.urdf``, the file the independent plant's Pinocchio model is read from."""
    folder = work / name
    if not folder.is_dir():
        table = UR5_DH
        if name == "ur10":
            table = work / "ur10_dh.toml"
            table.write_text(ur10_dh_table())
        added = subprocess.run([*children.command("-m", "faultgen.cli"), "robots", "add", name, "--from", str(table),
                                "-o", str(folder)], capture_output=True, text=True)
        if added.returncode:
            raise SystemExit(f"robots add {name}: {added.stdout}{added.stderr}")
        (folder / "urdf_used.urdf").write_text(dh_urdf(table))
    return folder


def spec(units: int, days: int, seed: int) -> independent.FleetSpec:
    """Half the units wearing (one axis of 1..6 each, from a day in the first third to 45 % on the last),
    one gearbox change (logged in events.csv), parts of at most 0.05 kg (the RTDE layout has no
    payload), 125 Hz logs."""
    return independent.FleetSpec(units=units, worn=max(1, units // 2), days=days, seed=seed,
                                 onset=(TRAIN + 2, max(TRAIN + 2, days // 3)), final_wear=45.0,
                                 wearable=(1, 2, 3, 4, 5, 6), max_part=0.05, rate=125.0,
                                 gearbox_changes=1 if days >= 36 else 0)


def write_fleet(work: Path, name: str, args) -> tuple[Path, Path, Path]:
    """The fleet ``name`` under ``WORK/NAME``: its robot folder, the independent generator's logs
    converted to ``rtde/<unit>/<stamp>.csv`` and its truth.csv. Returns (robot, RTDE logs, truth)."""
    robot = add_arm(work, name)
    root = work / f"{name}-fleet"
    logs, truth = independent.write_fleet(root, spec(args.units, args.days, args.seed), robot)
    rtde = root / "rtde"
    n = 6
    for unit_dir in sorted(p for p in logs.iterdir() if p.is_dir()):
        commanded = None
        for log in sorted(unit_dir.glob("*.csv")):
            target = rtde / unit_dir.name / log.name
            data = np.loadtxt(log, delimiter=",", skiprows=1)
            t, q, tau, temperature = data[:, 0], data[:, 1:1 + n], data[:, 1 + n:1 + 2 * n], data[0, 1 + 2 * n:1 + 3 * n]
            if commanded is None:
                commanded = tau.copy()
            if not target.is_file():
                ur_rtde_logs.write_ur_log(target, t, q, tau, temperature, commanded, TORQUE_CONSTANTS[name])
    if (logs / "events.csv").is_file():
        (rtde / "events.csv").write_bytes((logs / "events.csv").read_bytes())
    return robot, rtde, truth


def wear_error(wear_csv: Path, truth: dict) -> dict[str, float]:
    """Per worn unit, the median absolute error (percentage points) of wear.csv's filtered wear
    (``wear``, one row per log and axis) of its worn axis on monitoring logs whose true wear is above 0."""
    errors: dict[str, list[float]] = {}
    with open(wear_csv, newline="") as f:
        for row in csv.DictReader(f):
            t = truth.get(row["unit"])
            if not t or not t["axis"] or row["phase"] != "monitoring" or row["axis"] != str(t["axis"]):
                continue
            true = float(t["wear"][t["stamps"].index(row["stamp"])])
            if row["wear"] and true > 0:
                errors.setdefault(row["unit"], []).append(abs(float(row["wear"]) - true))
    return {unit: float(np.median(e)) for unit, e in errors.items()}


def _model(row: dict) -> str:
    """units.csv's model, with why a twin fell back from the calibrated one (the reason's first clause)."""
    model, reason = row.get("model", ""), row.get("reason", "")
    if "failed (" in reason:
        why = reason.split("failed (", 1)[1].split("); nominal model")[0]
        model += f"; the calibrated twin failed: {why}"
    return model


def table(name: str, out: Path, truth_path: Path) -> list[str]:
    """The fleet's markdown table, one row per unit (module docstring)."""
    truth = independent.read_truth(truth_path)
    outcome = independent_fleet.evaluate(truth_path, out / "alarms.csv")
    with open(out / "units.csv", newline="") as f:
        units = {row["unit"]: row for row in csv.DictReader(f)}
    errors = wear_error(out / "wear.csv", truth) if (out / "wear.csv").is_file() else {}
    rows = [f"| {name} unit | worn axis | status (model) | alarm known (first) | true wear at known (first), % "
            "| alarm axis | closed by | median wear error, pp |", "|---|---|---|---|---|---|---|---|"]
    for unit, o in outcome.items():
        u = units.get(unit, {})
        known = f"{o['known_wear']:.1f}" if o["known_wear"] is not None else "-"
        first = f"{o['wear']:.1f}" if o["wear"] is not None else "-"
        error = f"{errors[unit]:.1f}" if unit in errors else "-"
        closed = (o["alarms"][0].get("closed_by") or "open") if o["alarms"] else "-"
        rows.append(f"| {unit} | {o['axis'] or 'healthy'} | {u.get('status', 'absent')} ({_model(u)}) "
                    f"| {o['known'] or '-'} ({o['alarm'] or '-'}) | {known} ({first}) | {o['source'] or '-'} "
                    f"| {closed} | {error} |")
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fleet", choices=("ur5", "ur10", "both"), default="both")
    parser.add_argument("--units", type=int, default=6)
    parser.add_argument("--days", type=int, default=40)
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("--work", type=Path, default=Path("monitor_rtde_work"))
    args = parser.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    for name in ("ur5", "ur10") if args.fleet == "both" else (args.fleet,):
        began = time.perf_counter()
        robot, rtde, truth = write_fleet(args.work, name, args)
        written = time.perf_counter() - began
        out = args.work / f"{name}-out-{time.strftime('%Y%m%dT%H%M%S')}"
        command = [*children.command("-m", "faultgen.cli"), "monitor", str(rtde), "--robot", str(robot), "-o", str(out),
                   "--format", "ur-rtde", "--torque-constants", ",".join(f"{k:g}" for k in TORQUE_CONSTANTS[name]),
                   "--train", str(TRAIN), "--no-progress"]
        began = time.perf_counter()
        run = subprocess.run(command, capture_output=True, text=True)
        took = time.perf_counter() - began
        print(f"## {name}: {args.units} units x {args.days} days, seed {args.seed} "
              f"({datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC; fleet written in {written:.0f} s, "
              f"monitor {took:.0f} s, exit {run.returncode}, load {os.getloadavg()[0]:.1f})\n")
        if not (out / "units.csv").is_file():
            print(run.stdout[-3000:], run.stderr[-3000:])
            continue
        print("\n".join(table(name, out, truth)) + "\n")


if __name__ == "__main__":
    main()
