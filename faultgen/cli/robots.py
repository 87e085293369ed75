"""``faultgen robots``: the robot models and their nominal parameters."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from faultgen.cli.base import Command
from faultgen.cli.main import app

if TYPE_CHECKING:
    from faultgen.model.robot import Robot

#: The largest rated payload `robots add --payload` takes, kg.
MAX_PAYLOAD = 10_000.0


#: The options of `faultgen robots` and `robots add`.
RobotOrAdd = Annotated[
    str | None,
    typer.Argument(help="Show the nominal parameters of this robot (name, robot folder or MJCF file) "
                        "instead of the list; or `add` to add a robot."),
]
AddSource = Annotated[
    Path | None,
    typer.Option("--from", help="With `add`: the arm, a URDF, xacro, plain MJCF or DH table (.toml)."),
]
AddDrivetrain = Annotated[
    Path | None,
    typer.Option(help="With `add`: a drivetrain.toml with some or all drivetrain numbers; the rest are "
                      "sized."),
]
AddPayload = Annotated[
    float | None,
    typer.Option(help="With `add`: rated payload in kg, 0..10000 (the datasheet's; the largest industrial arms "
                      "carry about 2300). The drives are sized to hold and accelerate it; default: the "
                      "source's, else guessed as 15 % of the moving mass (said as a guess).",
                 min=0.0, max=MAX_PAYLOAD),
]
AddOut = Annotated[
    Path | None, typer.Option("-o", "--out", help="With `add`: the robot folder to write (new).")
]
AddPackages = Annotated[
    list[str] | None,
    typer.Option(help="With `add`: NAME=DIR, the folder of ROS package NAME, for `package://NAME/...` "
                      "meshes and xacro's `$(find NAME)` (repeatable). The source reads only its own "
                      "folder and these."),
]


@app.command("robots", cls=Command)
def robots_command(
    name: RobotOrAdd = None,
    new_name: Annotated[str | None, typer.Argument(help="With `add`: the new robot's name.")] = None,
    source: AddSource = None,
    drivetrain: AddDrivetrain = None,
    payload: AddPayload = None,
    out: AddOut = None,
    package: AddPackages = None,
) -> None:
    """List the robot models, show one model's nominal parameters, or add a robot from an arm file.

    `faultgen robots add NAME --from FILE -o DIR` writes DIR with NAME.xml (the arm with rotors,
    gearboxes, motors and motor friction), scene.xml, drivetrain.toml, tasks.toml (the three thesis
    tasks, generated and checked) and README.md (where every number came from). Every command then
    takes DIR as its robot. docs/robots.md, "Your own robot", gives the file formats and the sizing
    rules.

    Examples:

    \b
      faultgen robots            # one line per robot
      faultgen robots irb6700    # gear ratios, stiffness, friction per axis, SI units
      faultgen robots add kr210 --from kr210l150.urdf -o kr210
      faultgen robots add ur5 --from ur5_dh.toml --drivetrain my_drives.toml -o ur5
      faultgen robots add kr120 --from kuka_kr120/urdf/kr120r2500pro.xacro --package kuka_kr120_support=kuka_kr120 -o kr120
    """
    from faultgen.model import robots

    if name == "add":
        from faultgen.model import folder, importers
        from faultgen.operation import taskgen

        if new_name is None or source is None or out is None:
            raise ValueError("robots add needs NAME, --from FILE and -o DIR, e.g. "
                             "faultgen robots add kr210 --from kr210l150.urdf -o kr210")
        packages = parse_packages(package or [])
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", importers.GeometryDropped)
            added = folder.add(new_name, source, out, drivetrain=drivetrain, payload=payload,
                               tasks=taskgen.generate, packages=packages)
        for warning in caught:
            typer.echo(f"warning: {warning.message}", err=True)
        robot = added.robot
        typer.echo(f"{robot.name}: {robot.n_axes} axes from {added.arm.kind} {source} -> {added.folder} "
                   f"(rated payload {added.payload:.4g} kg, {added.payload_origin}; sizing rule {added.rule}; "
                   f"provenance in {added.folder / 'README.md'})")
        typer.echo(f"plausibility: {added.plausibility}: "
                   + (f"{len(added.findings)} finding(s)" if added.findings else "nothing implausible found"))
        for finding in added.findings:
            typer.echo(f"warning: {finding}", err=True)
        return
    if any(value is not None for value in (new_name, source, drivetrain, payload, out)) or package:
        raise ValueError("NAME, --from, --drivetrain, --payload, --package and -o go with `faultgen robots add`")
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


def parse_packages(items: list[str]) -> dict[str, Path]:
    """``--package NAME=DIR`` options: ROS package name -> its folder.

    Raises
    ------
    ValueError
        Naming an item that is not NAME=DIR.
    """
    packages = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key or not value:
            raise ValueError(f"--package {item!r}; expected NAME=DIR, e.g. "
                             "--package kuka_kr210_support=kuka_kr210")
        packages[key] = Path(value)
    return packages


def describe(robot: Robot) -> str:
    """A per-axis table of a robot's nominal parameters, SI units."""
    import numpy as np

    from faultgen.effects.friction import FIELDS as FRICTION_FIELDS
    from faultgen.effects.friction import UNITS as FRICTION_UNITS

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
    return head + "\n".join(lines + gearbox_lines(robot, label))


def gearbox_lines(robot: Robot, label: int) -> list[str]:
    """The gearbox rating rows (:mod:`faultgen.model.rating`): a row of defaults labelled
    ``(default)``, a default among given values marked ``*``; each default's rule below."""
    from faultgen.model import rating

    ratings = rating.of_robot(robot)
    lines, used = [], []
    for key, title in (("gearbox_type", "gearbox type"), ("rated_torque", "rated torque [N m]"),
                       ("rated_speed", "rated speed [rad/s]"), ("rated_life", "rated life L10 [h]")):
        marks = ["*" if key in r.defaults else "" for r in ratings]
        every = all(marks)
        used += [key] if any(marks) else []
        cells = "".join(f"{(v if isinstance(v, str) else 'none' if v != v else f'{v:.5g}') + ('' if every else m):>12}"
                        for v, m in zip((getattr(r, key) for r in ratings), marks))
        lines.append(f"{title + (' (default)' if every else ''):<{label}}{cells}")
    return (lines + [f"(default, or * where others are given) {key}: {rating.RULES[key]}" for key in used]
            + [f"axis {k}: {r.unrated}" for k, r in enumerate(ratings, start=1) if r.unrated])
