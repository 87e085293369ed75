"""What the UR monitor tests share: the UR5 robot folder (``robots add`` of the shipped DH table)
and one log in the RTDE recorder's layout (also benchmarks/monitor_rtde_fleets.py's)."""

import os
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from faultgen.cli import app

UR5_DH = Path(__file__).resolve().parents[1] / "docs/examples/ur5_dh.toml"
#: Columns of the RTDE recorder's default recipe written beside the ones read, as zeros (placeholders).
OTHER_COLUMNS = ("target_q", "target_qd", "target_current", "actual_TCP_pose", "robot_mode", "safety_mode",
                 "speed_scaling", "actual_main_voltage", "actual_robot_current", "actual_joint_voltage")


def add_ur5(root: Path) -> Path:
    """``root``/ur5: the UR5 robot folder ``faultgen robots add`` writes of the shipped DH table."""
    result = CliRunner().invoke(app, ["robots", "add", "ur5", "--from", str(UR5_DH), "-o", str(root / "ur5")])
    assert result.exit_code == 0, result.output
    return root / "ur5"


def write_rtde(path: Path, t, columns: dict, others=()) -> None:
    """One log in the RTDE recorder's layout (space-separated, its column names): ``timestamp``,
    ``columns`` (name -> (n, 6) array) in their order, then ``others`` as zeros (six columns
    ``name_0`` .. ``name_5`` for a ``target``/``actual`` name, else one)."""
    names, values = ["timestamp"], [t]
    for name, array in columns.items():
        names += [f"{name}_{k}" for k in range(6)]
        values += list(np.asarray(array).T)
    for name in others:
        six = name.startswith(("target", "actual"))
        names += [f"{name}_{k}" for k in range(6)] if six else [name]
        values += [np.zeros(len(t))] * (6 if six else 1)
    path.parent.mkdir(parents=True, exist_ok=True)
    part = path.with_name(path.name + ".part")  # a killed writer leaves no log that looks complete
    np.savetxt(part, np.column_stack(values), delimiter=" ", header=" ".join(names), comments="", fmt="%.9g")
    os.replace(part, path)


def write_ur_log(path: Path, t, q, tau, temperature, commanded, constants) -> None:
    """One UR log: ``t`` (n,) s, positions ``q`` (n, 6) rad, motor currents (the arm torque ``tau`` (n, 6)
    N m over ``constants`` (6,) N m/A), the ``commanded`` torque (n, 6) N m, joint ``temperature`` (6,)
    deg C, and :data:`OTHER_COLUMNS` as zeros."""
    write_rtde(path, t, {"actual_q": q, "actual_current": tau / np.asarray(constants),
                         "target_moment": commanded, "joint_temperatures": np.broadcast_to(temperature, q.shape)},
               OTHER_COLUMNS)
