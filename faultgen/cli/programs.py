"""``faultgen tasks``: a robot's programs (the thesis tasks and program files): list, show, export."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from faultgen.cli.base import Command, Group, check_outputs
from faultgen.cli.main import app
from faultgen.cli.options import Overwrite

tasks_app = typer.Typer(cls=Group, no_args_is_help=True, rich_markup_mode=None)
app.add_typer(tasks_app, name="tasks")


@tasks_app.callback()
def tasks_group() -> None:
    """A robot's programs: the thesis tasks (pick_place, spot_weld, arc_weld) and program files.

    Export a task as a program file to edit, then run it with `faultgen simulate --task FILE`
    (docs/simulation.md, "Your own programs"). A joint log (.csv: t, q1..qN in rad) runs as a task
    the same way.

    Examples:

    \b
      faultgen tasks list irb6700
      faultgen tasks export irb6700 spot_weld -o sw.toml
      faultgen simulate --robot irb6700 --task sw.toml --cycles 10 -o sw.h5
    """


@tasks_app.command("list", cls=Command)
def list_command(robot: Annotated[str, typer.Argument(help="Robot name or MJCF file.")]) -> None:
    """List a robot's programs: its thesis tasks and the program files in its folder's programs/.

    Examples:

    \b
      faultgen tasks list irb6700
    """
    from faultgen.model import robots
    from faultgen.operation import programs

    rows = programs.available(robots.load(robot))  # the robot resolved here, once
    if not rows:
        typer.echo(f"{robot}: no tasks (no tasks.toml, no programs/ folder)")
        return
    width = max(len(name) for name, _ in rows)
    for name, what in rows:
        typer.echo(f"{name:<{width}}  {what}")


@tasks_app.command("show", cls=Command)
def show_command(
    robot: Annotated[str, typer.Argument(help="Robot name or MJCF file.")],
    task: Annotated[str, typer.Argument(help="A thesis task name or a program file.")],
    check: Annotated[bool, typer.Option(help="Also plan the cycle and run every check (limits, reach, torque).")] = False,
) -> None:
    """Print a program: a thesis task in the program format, or a program file's text.

    Examples:

    \b
      faultgen tasks show irb6700 arc_weld
      faultgen tasks show irb6700 my_program.toml --check
    """
    from faultgen.model import robots
    from faultgen.operation import programs

    loaded = robots.load(robot)  # once, for the text and the check
    typer.echo(programs.show(loaded, task), nl=False)
    if check:
        path = programs.load(loaded, task).trajectory(loaded.model.opt.timestep)
        typer.echo(f"# checked: {path.duration:.3f} s cycle, {len(path.segments)} path segments, "
                   f"{len(path.loads)} payload(s) carried", err=True)


@tasks_app.command("export", cls=Command)
def export_command(
    robot: Annotated[str, typer.Argument(help="Robot name or MJCF file.")],
    task: Annotated[str, typer.Argument(help="pick_place, spot_weld or arc_weld.")],
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Program file to write (default: print).")] = None,
    overwrite: Overwrite = False,
) -> None:
    """Write a thesis task as a program file to edit; it runs the same path, bit for bit.

    Examples:

    \b
      faultgen tasks export irb6700 spot_weld -o sw.toml
      faultgen simulate --robot irb6700 --task sw.toml --wear 2:exp4:20 -o sw.h5
    """
    from faultgen.data.atomic import atomic_path
    from faultgen.model import robots
    from faultgen.operation import programs

    text = programs.export(robots.load(robot), task)
    if out is None:
        typer.echo(text, nl=False)
        return
    check_outputs([out], overwrite)
    with atomic_path(out) as tmp:
        Path(tmp).write_text(text)
    typer.echo(f"wrote {out}: {task} of {robot} as a program file")


@tasks_app.command("friction-test", cls=Command)
def friction_test_command(
    robot: Annotated[str, typer.Argument(help="Robot name or MJCF file.")],
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Program file to write (default: print).")] = None,
    axes: Annotated[str | None, typer.Option(help="Axes to test, comma-separated, e.g. 1,2 (default: all).")] = None,
    speeds: Annotated[int, typer.Option(help="Constant speeds per axis and direction (at least 3).")] = 7,
    overwrite: Overwrite = False,
) -> None:
    """Write a friction test as a program file: each axis in turn at constant speeds, both ways.

    Per axis: speeds spaced in log from inside the Stribeck region to 80 % of the speed limit, each
    over a stroke inside the joint limits (1.5 s steady, jerk-limited ramps, dwells), from a posture
    where gravity on that axis changes least. Its duration is printed. Run it like any task
    (`simulate --task`, sweeps) and read its log with `faultgen friction-test` (docs/friction-test.md).

    Examples:

    \b
      faultgen tasks friction-test puma560 -o test.toml
      faultgen tasks friction-test puma560 --axes 1 --speeds 3 -o short.toml
      faultgen simulate --robot puma560 --task short.toml --cycles 1 -o short.h5
    """
    from faultgen.data.atomic import atomic_path
    from faultgen.model import robots
    from faultgen.operation import friction_test, programs

    chosen = None
    if axes is not None:
        try:
            chosen = [int(a) for a in axes.split(",")]
        except ValueError:
            raise ValueError(f"--axes {axes!r}: expected axis numbers separated by commas, e.g. 1,2") from None
    if out is not None:
        check_outputs([out], overwrite)
    loaded = robots.load(robot)
    text = friction_test.text(loaded, chosen, speeds)
    duration = programs.parse(text, loaded, where="friction test").trajectory(loaded.model.opt.timestep).duration
    if out is None:
        typer.echo(text, nl=False)
        typer.echo(f"# friction test of {robot}: {duration:.1f} s", err=True)
        return
    with atomic_path(out) as tmp:
        Path(tmp).write_text(text)
    typer.echo(f"wrote {out}: friction test of {robot}, {duration:.1f} s ({duration / 60:.1f} min)")
