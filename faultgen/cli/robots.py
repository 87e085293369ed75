"""``faultgen robots``: the robot models and their nominal parameters."""

from __future__ import annotations

from typing import Annotated

import numpy as np
import typer

from faultgen.cli.base import Command
from faultgen.cli.main import app
from faultgen.effects.friction import FIELDS as FRICTION_FIELDS
from faultgen.effects.friction import UNITS as FRICTION_UNITS
from faultgen.model import robots


@app.command("robots", cls=Command)
def robots_command(
    name: Annotated[
        str | None,
        typer.Argument(help="Show the nominal parameters of this robot (or MJCF file) instead of the list."),
    ] = None,
) -> None:
    """List the robot models, or show one model's nominal parameters.

    Examples:

    \b
      faultgen robots            # one line per robot
      faultgen robots irb6700    # gear ratios, stiffness, friction per axis, SI units
    """
    if name is None:
        known = robots.available()
        if not known:
            typer.echo(f"no robots found in {robots.robots_dir()}", err=True)
            raise typer.Exit(1)
        width = max(len(n) for n in known)
        for robot_name in known:
            robot = robots.load(robot_name)
            typer.echo(f"{robot_name:<{width}}  {robot.description}")
        return
    typer.echo(describe(robots.load(name)))


def describe(robot: robots.Robot) -> str:
    """A per-axis table of a robot's nominal parameters, SI units."""
    rows = [
        ("gear ratio G", "1", robot.gear_ratio),
        ("motor inertia Jm", "kg m^2", robot.motor_inertia),
        ("gearbox stiffness K", "N m/rad", robot.gearbox_stiffness),
        ("gearbox damping D", "N m s/rad", robot.gearbox_damping),
        ("joint min", "rad", robot.joint_range[:, 0]),
        ("joint max", "rad", robot.joint_range[:, 1]),
        ("motor torque limit", "N m", robot.motor_torque_limit),
        ("home", "rad", robot.home),
    ]
    rows += [(f"friction {f}", FRICTION_UNITS[f], getattr(robot.friction, f)) for f in FRICTION_FIELDS]
    head = f"{robot.name}: {robot.description}\nmodel: {robot.path}\n"
    label = max(len(r[0]) + len(r[1]) + 3 for r in rows)
    lines = [" " * label + "".join(f"{'axis ' + str(i):>12}" for i in range(1, len(robot.gear_ratio) + 1))]
    for title, unit, values in rows:
        cells = "".join(f"{v:>12.5g}" for v in np.asarray(values))
        lines.append(f"{title + ' [' + unit + ']':<{label}}{cells}")
    return head + "\n".join(lines)
