"""The ``faultgen`` command: parse arguments, call the library, print. Nothing else lives here."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from typer.core import TyperArgument, TyperCommand, TyperGroup, TyperOption

from faultgen import __version__
from faultgen.model import robots
from faultgen.effects.friction import FIELDS as FRICTION_FIELDS
from faultgen.effects.friction import UNITS as FRICTION_UNITS


class _PlainHelp:
    """Help without typer's type tags (``<bool>``, ``<list[int]>``): a flag shows nothing after
    its name, an option taking a value its metavar, by default the option's name in capitals as
    argparse writes it (``--cycles CYCLES``), and an argument its name in capitals (``FILE``)."""

    def get_params(self, ctx):
        params = super().get_params(ctx)
        for param in params:
            if isinstance(param, TyperOption) and param.metavar is None:
                long_name = max(param.opts, key=len).lstrip("-")
                param.metavar = "" if param.is_flag else long_name.upper().replace("-", "_")
            elif isinstance(param, TyperArgument) and param.metavar is None:
                param.metavar = param.name.upper()
                param.display_type_rich = _no_type_tag  # typer has no setting for the argument's tag
        return params


def _no_type_tag(ctx) -> None:
    return None


class PlainHelpCommand(_PlainHelp, TyperCommand):
    """A command whose help has no type tags (:class:`_PlainHelp`)."""


class PlainHelpGroup(_PlainHelp, TyperGroup):
    """The command group, with the same plain help."""


#: The ``--overwrite`` flag of every command that writes: without it an existing output is refused.
Overwrite = Annotated[bool, typer.Option("--overwrite", help="Replace existing outputs; without it they are refused.")]
QAlpha = Annotated[float, typer.Option("--alpha", help="Significance of the Q limit (0.05: 95 % limit).")]

#: Operating-condition options of `simulate` and `sweep` (faultgen.operation.conditions).
Temperature = Annotated[bool, typer.Option(
    "--temperature", help="Joint temperature on: hall air 20 degC +- 5 K seasonal +- 2 K daily, joints warming "
    "15 K over a shift (1 h time constant), friction following the gear oil's viscosity (docs/simulation.md).")]
DryShare = Annotated[float | None, typer.Option(
    "--dry-share", metavar="S", help="The exponent of the oil viscosity's ratio that the dry (Coulomb, Stribeck) "
    "friction follows with the joint temperature, 0..1; default 0.25 (ours, not measured), 0: only the viscous "
    "friction moves with temperature, 1: the dry moves as much. Needs the temperature (--temperature; on by "
    "default in a fleet).", show_default=False)]
PayloadParts = Annotated[str | None, typer.Option(
    "--payloads", help="Parts carried, MASS:SIZE in kg:m, comma-separated, e.g. 20:0.2,80:0.4 (uniform cubes "
    "hanging from the flange; the controller knows each).")]
PayloadPattern = Annotated[str, typer.Option(
    help="Which part each cycle carries: alternate, blocks (10 cycles each) or random.")]
UnitSpreadFlag = Annotated[bool, typer.Option(
    "--unit-spread", help="The run's robot draws its own friction levels (15 % log-normal per axis) and link masses "
    "(2 %) from its seed; the controller keeps the nominal model.")]
GearLoss = Annotated[float, typer.Option(
    "--gear-loss", metavar="C",
    help="With --unit-spread: each unit's gearboxes also lose a share of the transmitted torque as Coulomb friction, "
    "drawn per axis uniformly in 0..C (1 minus the gear efficiency under load; e.g. 0.1). Needs --friction "
    "stribeck. Default 0: none.")]
TaskMixTasks = Annotated[str | None, typer.Option(
    "--task-mix", metavar="TASK,TASK,...",
    help="Each cycle runs one of these tasks (the run's own among them), e.g. pick_place,spot_weld; needs "
    "--features-only (cycles of different tasks differ in length).")]
TaskMixPattern = Annotated[str, typer.Option(
    help="Which task each cycle runs: alternate, blocks (10 cycles each) or random.")]
CyclesPerDay = Annotated[int, typer.Option(
    help="Recorded cycles per day of the robot's life (the calendar of the temperature; default: one a day).")]
StartDay = Annotated[float, typer.Option(help="Day of the year of cycle 1.")]


def _conditions(temperature: bool, payloads: str | None, pattern: str, spread: bool, cycles_per_day: int,
                start_day: float, task_mix: str | None = None, task_pattern: str = "alternate",
                gear_loss: float = 0.0, dry_share: float | None = None) -> dict | None:
    """The conditions table (:meth:`Conditions.from_dict`) of the command-line options; None when
    no condition is on. Raises ValueError naming a malformed ``--payloads`` part, a
    ``--gear-loss`` without ``--unit-spread`` or a ``--dry-share`` without ``--temperature``."""
    table: dict = {}
    if dry_share is not None and not temperature:
        raise ValueError(f"--dry-share {dry_share:g} sets how friction follows the joint temperature: add --temperature")
    if temperature:
        table["thermal"] = {} if dry_share is None else {"dry_share": dry_share}
    if payloads:
        masses, sizes = [], []
        for part in payloads.split(","):
            try:
                mass, size = (float(v) for v in part.split(":"))
            except ValueError:
                raise ValueError(f"--payloads part {part.strip()!r}: expected MASS:SIZE in kg:m, e.g. 20:0.2") from None
            masses.append(mass)
            sizes.append(size)
        table["payloads"] = {"masses": masses, "sizes": sizes, "pattern": pattern}
    if gear_loss and not spread:
        raise ValueError(f"--gear-loss {gear_loss:g} is a part of the unit spread: add --unit-spread")
    if spread:
        table["spread"] = {"gear_loss": gear_loss} if gear_loss else {}
    if task_mix:
        table["task_mix"] = {"tasks": [t.strip() for t in task_mix.split(",")], "pattern": task_pattern}
    if not table:
        return None
    return {**table, "cycles_per_day": cycles_per_day, "start_day": start_day}


app = typer.Typer(
    cls=PlainHelpGroup,
    help=(
        "Simulate wear faults in industrial robots and analyse them.\n\n"
        "A first dataset: `faultgen sweep --preset quick -o quick.h5` (under a minute), then "
        "`faultgen info quick.h5` and `faultgen plot quick.h5`. Analyse it with `faultgen "
        "bench-isolators`, `detect` and `classify`. `faultgen robots` lists the robot models; "
        "`faultgen robots NAME` shows one model's parameters."
    ),
    no_args_is_help=True,
    add_completion=False,
)


def _version(value: bool) -> None:
    if value:
        typer.echo(f"faultgen {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: Annotated[
        bool | None,
        typer.Option("--version", callback=_version, is_eager=True, help="Print the version and exit."),
    ] = None,
) -> None:
    """faultgen: labelled wear-fault data for industrial robots."""


@app.command("robots", cls=PlainHelpCommand)
def robots_command(
    name: Annotated[
        str | None,
        typer.Argument(help="Show the nominal parameters of this robot (or MJCF file) instead of the list."),
    ] = None,
) -> None:
    """List the robot models, or show one model's nominal parameters.

    Examples:

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
    try:
        robot = robots.load(name)
    except (robots.UnknownRobotError, robots.ModelError) as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(2) from err
    typer.echo(_describe(robot))


def _describe(robot: robots.Robot) -> str:
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
    lines = [" " * label + "".join(f"{'axis ' + str(i):>12}" for i in range(1, 7))]
    for title, unit, values in rows:
        cells = "".join(f"{v:>12.5g}" for v in np.asarray(values))
        lines.append(f"{title + ' [' + unit + ']':<{label}}{cells}")
    return head + "\n".join(lines)


@app.command("simulate", cls=PlainHelpCommand)
def simulate_command(
    robot: Annotated[str, typer.Option(
        "--robot", "--model",
        help="Robot name (see `faultgen robots`) or MJCF file, e.g. the model `faultgen calibrate` wrote.")] = "irb6700",
    task: Annotated[str, typer.Option(help="pick_place, spot_weld or arc_weld (thesis ch. 6.3.1 tasks 1-3).")] = "pick_place",
    friction_model: Annotated[
        str, typer.Option("--friction", help="Motor-side friction model: lugre (dynamic) or stribeck (static eq. 6.3; "
                          "needed for calibrated load-dependent friction and warm-up drift).")
    ] = "lugre",
    wear: Annotated[
        list[str] | None,
        typer.Option(
            help="A worn axis as AXIS:KIND:PERCENT[:key=value], e.g. 2:exp4:20 (20 % more Coulomb and static "
            "friction on axis 2 by the last cycle, thesis eq. 6.6). KIND: exp4, logistic, linear, step. Repeat "
            "for several axes. No --wear: no wear."
        ),
    ] = None,
    cycles: Annotated[int, typer.Option(help="Cycles in the run; wear schedules reach PERCENT at the last one.")] = 100,
    record: Annotated[
        str | None,
        typer.Option(help="Cycles to simulate and record, e.g. '1,50,100' or '90-100'. Default: all."),
    ] = None,
    seed: Annotated[int, typer.Option(help="Seed of the disturbance and encoder noise.")] = 0,
    disturbance: Annotated[
        float, typer.Option(help="Load disturbance std as a fraction of mean |torque| per axis (thesis ch. 3.3.2).")
    ] = 0.01,
    encoder_noise: Annotated[float, typer.Option(help="Encoder noise std, rad (thesis ch. 3.3.2).")] = 1e-4,
    threads: Annotated[int, typer.Option(help="Threads for stepping; 0 uses all CPUs.")] = 0,
    fault: Annotated[str | None, typer.Option(
        help="A fault other than friction wear, growing to FINAL by the last cycle: EFFECT:AXIS:PARAMETER:FINAL"
        "[:key=value,...], e.g. backlash:2:width:0.01 (a 10 mrad dead band on axis 2) or "
        "cogging:3:amplitude:0.05:poles=8,kind=exp4. Effects: faultgen.effects (not payload, load friction, "
        "warm-up).")] = None,
    temperature: Temperature = False,
    dry_share: DryShare = None,
    payloads: PayloadParts = None,
    payload_pattern: PayloadPattern = "alternate",
    unit_spread: UnitSpreadFlag = False,
    gear_loss: GearLoss = 0.0,
    cycles_per_day: CyclesPerDay = 1,
    start_day: StartDay = 0.0,
    out: Annotated[Path, typer.Option("--out", "-o", help="HDF5 file to write.")] = Path("run.h5"),
    overwrite: Overwrite = False,
    progress: Annotated[bool, typer.Option(help="Show a progress bar.")] = True,
) -> None:
    """Simulate one run: a robot repeating a task while chosen axes wear, into an HDF5 file.

    Only the recorded cycles are simulated, all at once, each from the task's start state with its
    own wear level. Signals are logged at 250 Hz.

    Examples:

      faultgen simulate --robot irb6700 --task pick_place --wear 1:exp4:20 --cycles 100 -o axis1.h5

      faultgen simulate --task spot_weld --wear 2:exp4:20 --wear 5:linear:10 --record 1,100 -o two.h5

      faultgen simulate --wear 3:exp4:20 --temperature --payloads 20:0.2,80:0.4 --unit-spread -o real.h5

      faultgen simulate --friction stribeck --wear 2:exp4:20 --unit-spread --gear-loss 0.1 -o lossy.h5
    """
    from faultgen.data import dataset
    from faultgen.operation import conditions as conditions_module
    from faultgen.operation import faults as faults_module
    from faultgen.operation import wear as wear_module
    from faultgen.simulation import sensors
    from faultgen.simulation import stepping as sim

    try:
        _check_outputs([out], overwrite)
        if cycles < 1:
            raise ValueError(f"--cycles {cycles}: expected a whole number >= 1")
        config = sim.RunConfig(
            robot=robot, task=task, friction=friction_model,
            wear=wear_module.WearPlan.from_specs(wear or [], last_cycle=cycles), cycles=cycles,
            record=None if record is None else _parse_cycles(record), seed=seed,
            noise=sensors.NoiseConfig(disturbance=disturbance, encoder=encoder_noise), nthread=threads,
            conditions=conditions_module.Conditions.from_dict(
                _conditions(temperature, payloads, payload_pattern, unit_spread, cycles_per_day, start_day,
                            gear_loss=gear_loss, dry_share=dry_share) or {}),
            fault=None if fault is None else faults_module.parse_fault(fault, last_cycle=cycles),
        )
    except ValueError as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(2) from err
    try:
        result = sim.simulate(config, progress=progress)
    except sim.SimulationDiverged as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(1) from err
    command = shlex.join(["faultgen", *sys.argv[1:]])
    dataset.write_run(out, result, command=command)
    typer.echo(_summary(result, out))


@app.command("calibrate", cls=PlainHelpCommand)
def calibrate_command(
    robot: Annotated[str, typer.Option(help="Robot name (see `faultgen robots`) or MJCF file of the nominal model.")],
    measured: Annotated[Path, typer.Option(
        help="Measured torque log: CSV (.csv, .csv.gz) or HDF5 with columns t, q1..q6 (rad), tau1..tau6 (N m, arm "
             "side) and optionally qd1..qd6 (rad/s); at least 2 s at >= 100 Hz.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder (created): model/, report.json, calibration.png.")],
    max_steps: Annotated[int, typer.Option(help="Most effects to add.")] = 6,
    overwrite: Overwrite = False,
) -> None:
    """Find what the model misses in a measured torque log, add it, and show the gap shrink.

    The nominal model predicts the measured torque along the measured motion; every effect of
    the library is fitted to the residual on the first 70 % of the record and judged on the last
    30 % (held out); the effect that cuts the held-out error most, on the axes where the cut is
    significant, is written into the model, and the search repeats until nothing significant is
    left. A log the robot cannot explain (another robot, motor-side torque, a column in another
    unit or with the other sign) is refused before anything is written, naming what to check.

    Effects: torque_offset (constant offset), coulomb (Coulomb friction level), viscous (viscous
    friction), stribeck (low-speed friction hump), load_dependent_friction (friction growing with
    the gearbox load: the transmitted torque or the gravity load), temperature (friction drifting
    with time, warm-up), payload (mass, centre of mass and inertia at the flange), cogging (torque
    periodic in the motor angle), backlash (gearbox dead band in the flexible-gearbox equation). Every fitted parameter is reported with
    its standard error.

    Writes into OUT: model/<robot>_calibrated.xml (run it with `faultgen simulate --model ...`)
    and model/parameters.json, report.json (gap before/after per axis, each effect with its axes,
    parameters and evidence) and calibration.png (measured vs model torque and the residual
    before and after, per axis). Method and accuracy: docs/calibration.md.

    Example:

      faultgen calibrate --robot puma560 --measured log.csv --out calib
    """
    from faultgen import calibrate

    try:
        _check_output_folder(out, overwrite)
        result = calibrate.calibrate(robot, measured, out, max_steps=max_steps, progress=True)
    except ValueError as err:  # unknown robot, bad model file, refused measured data, bad option
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(2) from err
    typer.echo(result.summary())
    typer.echo(f"wrote {out / 'report.json'} and {out / 'calibration.png'}")


@app.command("sweep", cls=PlainHelpCommand)
def sweep_command(
    preset: Annotated[
        str | None, typer.Option(help="A named grid: quick (a first look, under a minute on 2 cores), j2 (thesis ch. 6, 3-6 min), c2 (thesis ch. 3, 70 min or more, features only); times on 2 cores, by the machine.")
    ] = None,
    config: Annotated[
        Path | None, typer.Option(help="A TOML file whose keys are the grid fields below (and optionally preset).")
    ] = None,
    robots_: Annotated[list[str] | None, typer.Option("--robot", help="Robot(s); repeat for several.")] = None,
    tasks_: Annotated[list[str] | None, typer.Option("--task", help="Task(s); repeat for several.")] = None,
    axes: Annotated[list[int] | None, typer.Option("--axis", help="Worn axis 1..6, or 0 for a run without wear; repeat.")] = None,
    increases: Annotated[list[float] | None, typer.Option("--wear-pct", help="Final wear in %; repeat.")] = None,
    schedules: Annotated[list[str] | None, typer.Option("--schedule", help="exp4, logistic, linear or step; repeat.")] = None,
    friction_model: Annotated[str | None, typer.Option("--friction", help="lugre or stribeck.")] = None,
    cycles: Annotated[int | None, typer.Option(help="Cycles per run.")] = None,
    record: Annotated[str | None, typer.Option(help="Cycles to record, e.g. '1,50,100' or '90-100'. Default: all.")] = None,
    seeds: Annotated[list[int] | None, typer.Option("--seed", help="Seed(s); repeat.")] = None,
    fault: Annotated[str | None, typer.Option(
        help="Instead of friction wear, each worn axis gets this fault: EFFECT:PARAMETER:FINAL[:key=value,...], "
        "e.g. backlash:width:0.01 or cogging:amplitude:0.05:poles=8 (see `simulate --fault`).")] = None,
    temperature: Temperature = False,
    dry_share: DryShare = None,
    payloads: PayloadParts = None,
    payload_pattern: PayloadPattern = "alternate",
    unit_spread: UnitSpreadFlag = False,
    gear_loss: GearLoss = 0.0,
    task_mix: TaskMixTasks = None,
    task_pattern: TaskMixPattern = "alternate",
    cycles_per_day: CyclesPerDay = 1,
    start_day: StartDay = 0.0,
    features_only: Annotated[bool | None, typer.Option(
        "--features-only/--signals", help="Keep only the per-cycle features and truth, not the 250 Hz signals (a "
        "fraction of the size; detect and classify give the same tables, only bench-isolators --speed-window needs "
        "the signals), or keep the signals. Default: the preset's (c2: features only), else signals.",
        show_default=False)] = None,
    jobs: Annotated[int, typer.Option(help="Local worker processes.")] = 2,
    scheduler: Annotated[
        str | None, typer.Option(help="Dask scheduler address (tcp://host:port) to run on a cluster; workers must see OUT's folder.")
    ] = None,
    out: Annotated[Path, typer.Option("--out", "-o", help="Dataset file to write (HDF5).")] = Path("sweep.h5"),
    overwrite: Overwrite = False,
    progress: Annotated[bool, typer.Option(help="Show a progress bar.")] = True,
) -> None:
    """Simulate a grid of runs (robot x task x worn axis x wear x schedule x seed) into one dataset.

    The grid comes from --preset, --config or the options (options override the preset or file).
    Killed or failed? Run the same command again: finished runs are kept, only missing ones run.

    Examples:

      faultgen sweep --preset quick -o quick.h5

      faultgen sweep --preset j2 --jobs 2 -o j2.h5

      faultgen sweep --robot puma560 --task spot_weld --axis 0 --axis 3 --wear-pct 10 --wear-pct 20 -o s.h5

      faultgen sweep --preset j2 --temperature --unit-spread -o j2-conditions.h5

      faultgen sweep --task pick_place --axis 0 --axis 2 --task-mix pick_place,spot_weld --features-only -o mix.h5
    """
    from faultgen.runs import sweep

    options = {"robots": robots_, "tasks": tasks_, "axes": axes, "increases": increases, "schedules": schedules,
               "friction": friction_model, "cycles": cycles, "seeds": seeds,
               "record": record}
    options = {k: v for k, v in options.items() if v is not None}  # every option given, whatever its value
    try:
        table = _conditions(temperature, payloads, payload_pattern, unit_spread, cycles_per_day, start_day,
                            task_mix, task_pattern, gear_loss, dry_share)
        if table is not None:
            options["conditions"] = table
        if features_only is not None:
            options["signals"] = not features_only
        if fault is not None:
            options["fault"] = fault
        if record is not None:
            options["record"] = list(_parse_cycles(record))
        if config is not None:
            grid = sweep.Grid.from_toml(config)
            if options:
                grid = sweep.Grid(**{**{f: getattr(grid, f) for f in grid.__dataclass_fields__}, **options})
        elif preset is not None:
            grid = sweep.Grid.from_preset(preset, **options)
        else:
            grid = sweep.Grid(**{"robots": ["irb6700"], "tasks": ["pick_place"], "axes": [0], **options})
        if jobs < 1:
            raise ValueError(f"--jobs {jobs}: expected >= 1")
        _check_outputs([out], overwrite)
    except ValueError as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(2) from err
    where = f" on {scheduler}" if scheduler else f" with {jobs} job(s)"

    def announce(n_runs: int, done: int) -> None:
        typer.echo(f"{n_runs} runs -> {out}{where}")
        if done:
            typer.echo(f"resuming: {done} of {n_runs} runs already finished in {sweep.parts_folder(out)}, kept as "
                       "they are")

    _run_sweep(grid, out, jobs=jobs, scheduler=scheduler, progress=progress, overwrite=overwrite, announce=announce)
    typer.echo(f"wrote {out}\nlook at it with:\n  faultgen info {out}\n  faultgen validate {out}\n"
               f"  faultgen plot {out} -o {out.with_suffix('.png')}")


@app.command("fleet", cls=PlainHelpCommand)
def fleet_command(
    size: Annotated[int, typer.Option("--robots", help="Robots in the fleet (thesis ch. 5.3.1: 26).")] = 26,
    failing: Annotated[int, typer.Option(help="Of them, robots whose gearbox fails (thesis: 13).")] = 13,
    models: Annotated[list[str] | None, typer.Option(
        "--robot", help="Robot model(s) of the fleet, taken in turn; repeat for several (default: irb6700 and "
        "puma560). One model makes every robot that model, e.g. for a fault whose FINAL suits only it.")] = None,
    days: Annotated[int, typer.Option(help="Days recorded per robot; a failing robot fails on the last one.")] = 60,
    cycles_per_day: Annotated[int, typer.Option(
        help="Cycles simulated per day, reduced to the day's maximum (thesis ch. 5.3.2: 1-4 samples a day).")] = 2,
    failure_wear: Annotated[float, typer.Option(
        help="Coulomb and static friction increase of the failing axis on the failure day, %.")] = 50.0,
    seed: Annotated[int, typer.Option(help="Seed of every draw: models, tasks, parts, climate, units, faults, noise.")] = 0,
    conditions: Annotated[bool, typer.Option(
        help="Each robot's climate, parts and unit spread; --no-conditions: robots differ only by model, "
        "process and fault.")] = True,
    without: Annotated[list[str] | None, typer.Option(
        "--without", metavar="CONDITION", help="Leave one condition out of every robot, the others drawn as in the "
        "full fleet: thermal (hall climate, warm-up), payloads (the parts) or spread (unit spread); repeat for "
        "several.", show_default=False)] = None,
    task_mix: Annotated[bool, typer.Option(
        "--task-mix", help="Each robot also runs a second task, drawn from the other two, in a random half of "
        "its cycles (default: one task per robot).")] = False,
    friction_model: Annotated[str, typer.Option(
        "--friction", help="Motor-side friction model of every robot: lugre (dynamic, the default) or stribeck "
        "(static eq. 6.3; needed for --gear-loss; the fleet took 12 min instead of 9 on 2 cores).")] = "lugre",
    dry_share: DryShare = None,
    gear_loss: Annotated[float, typer.Option(
        "--gear-loss", metavar="C", help="Each unit's gearboxes also lose a share of the transmitted torque as "
        "Coulomb friction, drawn per axis in 0..C (1 minus the gear efficiency under load); needs --friction "
        "stribeck.")] = 0.0,
    fault: Annotated[str | None, typer.Option(
        help="Instead of friction wear, a failing robot's drawn axis gets this fault, growing on the exp4 schedule "
        "from its onset day to FINAL on the failure day: EFFECT:PARAMETER:FINAL[:key=value,...], e.g. "
        "backlash:width:0.01 (see `simulate --fault`); the same FINAL on every model (--robot picks them).")] = None,
    jobs: Annotated[int, typer.Option(help="Local worker processes.")] = 2,
    out: Annotated[Path, typer.Option("--out", "-o", help="Dataset file to write (HDF5).")] = Path("fleet.h5"),
    overwrite: Overwrite = False,
    progress: Annotated[bool, typer.Option(help="Show a progress bar.")] = True,
) -> None:
    """Simulate a fleet like the thesis's 26 robots (ch. 5): daily remote-monitoring records.

    Half the robots develop a gearbox fault (friction wear of one drawn axis, rising from a drawn
    day to failure on the last day), half stay healthy; each robot has its own model, process,
    parts, hall climate and unit spread (docs/simulation.md, "Operating conditions and fleets").
    Killed? Run the same command again: finished robots are kept.

    Examples:

      faultgen fleet -o fleet.h5

      faultgen classify fleet.h5 --wear-threshold 10

      faultgen fleet --friction stribeck --gear-loss 0.1 -o fleet-lossy.h5

      faultgen fleet --fault backlash:width:0.01 -o fleet-backlash.h5

      faultgen fleet --robot irb6700 --fault cogging:amplitude:0.5:poles=8 -o fleet-cogging.h5

      faultgen fleet --without payloads -o fleet-no-parts.h5
    """
    from faultgen.runs import fleet

    try:
        chosen = {"models": tuple(models)} if models else {}
        if dry_share is not None:
            chosen["dry_share"] = dry_share
        if without:
            chosen["without"] = tuple(without)
        plan = fleet.Fleet(size=size, failing=failing, days=days, cycles_per_day=cycles_per_day, **chosen,
                           failure_wear=failure_wear, seed=seed, conditions=conditions, task_mix=task_mix,
                           friction=friction_model, gear_loss=gear_loss, fault=fault)
        if jobs < 1:
            raise ValueError(f"--jobs {jobs}: expected >= 1")
        _check_outputs([out], overwrite)
    except ValueError as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(2) from err

    def announce(n_runs: int, done: int) -> None:
        typer.echo(f"{n_runs} robots x {days} days -> {out} with {jobs} job(s)"
                   + (f"; resuming, {done} robots already finished" if done else ""))

    _run_sweep(plan, out, jobs=jobs, scheduler=None, progress=progress, overwrite=overwrite, announce=announce)
    typer.echo(f"wrote {out}\nanalyse it with:\n  faultgen info {out}\n  faultgen classify {out}\n"
               f"  faultgen detect {out}")


def _run_sweep(plan, out: Path, *, jobs: int, scheduler: str | None, progress: bool, overwrite: bool,
               announce) -> None:
    """:func:`faultgen.runs.sweep.run` for a command: its errors as messages and exit codes (2
    refused before anything ran, 130 interrupted with the finished runs kept, 1 a run failed)."""
    from faultgen.runs import sweep

    try:
        sweep.run(plan, out, jobs=jobs, scheduler=scheduler, progress=progress, overwrite=overwrite,
                  command=shlex.join(["faultgen", *sys.argv[1:]]), on_start=announce)
    except sweep.SweepRefused as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(2) from err
    except sweep.SweepInterrupted as err:
        typer.echo(str(err), err=True)
        raise typer.Exit(130) from err
    except sweep.SweepError as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(1) from err


@app.command("info", cls=PlainHelpCommand)
def info_command(file: Annotated[Path, typer.Argument(help="A faultgen dataset (HDF5).")]) -> None:
    """Summarise a dataset: runs, robots, tasks, worn axes, cycles, provenance."""
    from faultgen.data import dataset

    try:
        typer.echo(dataset.summary(file))
    except dataset.DatasetError as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(1) from err


@app.command("validate", cls=PlainHelpCommand)
def validate_command(file: Annotated[Path, typer.Argument(help="A faultgen dataset (HDF5).")]) -> None:
    """Check a dataset against the schema (docs/dataset.md); exit 1 with the reasons if it fails."""
    from faultgen.data import dataset

    problems = dataset.validate(file)
    if problems:
        for problem in problems[:50]:
            typer.echo(f"invalid: {problem}", err=True)
        raise typer.Exit(1)
    typer.echo(f"{file}: valid ({len(dataset.list_runs(file))} runs)")


@app.command("export", cls=PlainHelpCommand)
def export_command(
    file: Annotated[Path, typer.Argument(help="A faultgen dataset (HDF5).")],
    out: Annotated[Path, typer.Option("--out", "-o", help="Table to write: .csv, .csv.gz or .parquet.")],
    overwrite: Overwrite = False,
) -> None:
    """Write every per-cycle feature of a dataset as one tidy table (CSV or Parquet).

    One row per run, recorded cycle and axis: the run's labels, the true wear of the axis, mean
    and RMS motor torque, friction torque, tracking error and the 12-bin histograms (a column per
    bin). Columns and units: docs/dataset.md. Read it with pandas: `pandas.read_parquet(OUT)`.

    Example:

      faultgen export quick.h5 -o quick.parquet
    """
    from faultgen.data import dataset

    try:
        _check_outputs([out], overwrite)
        dataset.export_features(file, out)
    except ValueError as err:  # a broken dataset (1); a refused output (2)
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(1 if isinstance(err, dataset.DatasetError) else 2) from err
    typer.echo(f"wrote {out}")


@app.command("plot", cls=PlainHelpCommand)
def plot_command(
    file: Annotated[Path, typer.Argument(help="A faultgen dataset (HDF5).")],
    run: Annotated[str | None, typer.Option(help="Plot one run (default: the whole sweep, or its only run).")] = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="PNG to write (default: FILE with .png).")] = None,
    overwrite: Overwrite = False,
) -> None:
    """Draw how each axis's mean |motor torque| follows its true wear, as a PNG.

    A sweep: per axis, the change (%) of every run wearing it against the unworn run of the same
    task and seed. One run (or --run ID): mean |motor torque| per cycle with the true wear.

    Example:

      faultgen plot quick.h5 -o quick.png
    """
    from faultgen import plot
    from faultgen.data import dataset

    target = out or file.with_suffix(".png")
    try:
        _check_outputs([target], overwrite)
        plot.plot(file, target, run=run)
    except ValueError as err:  # a broken dataset (1); refused: an existing or non-PNG output, an unknown run (2)
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(1 if isinstance(err, dataset.DatasetError) else 2) from err
    typer.echo(f"wrote {target}")


def _analysis_input(file: Path, outputs: list[Path], overwrite: bool) -> None:
    """Refuse a dataset that fails validation, or outputs that exist, before any analysis runs."""
    from faultgen.data import dataset

    problems = dataset.validate(file)
    if problems:
        typer.echo(f"error: {file} fails validation (run `faultgen validate {file}`): {problems[0]}", err=True)
        raise typer.Exit(2)
    try:
        _check_outputs(outputs, overwrite)
    except ValueError as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(2) from err


def _table_command(file: Path, out: Path | None, overwrite: bool, suffix: str, digits: int, compute) -> None:
    """Validate ``file``, compute a table, write it as CSV and Markdown, print it."""
    from analysis import benchmark

    stem = out or file.with_name(file.stem + suffix)
    _analysis_input(file, [stem.with_suffix(".csv"), stem.with_suffix(".md")], overwrite)
    try:
        table = compute()
    except ValueError as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(2) from err
    written = benchmark.write_outputs(table, stem)
    typer.echo(benchmark.markdown(table, digits=digits))
    typer.echo("wrote " + ", ".join(map(str, written)))


@app.command("bench-isolators", cls=PlainHelpCommand)
def bench_isolators_command(
    file: Annotated[Path, typer.Argument(help="A faultgen dataset with runs that wear one axis.")],
    bins: Annotated[list[int] | None, typer.Option("--bins", help="Transfer-entropy bin counts; repeat. Default 5 and 10.")] = None,
    levels: Annotated[str, typer.Option(help="Wear levels in %, comma-separated (thesis Table 6.2).")] = "1,5,10,15",
    speed_window: Annotated[str | None, typer.Option(
        metavar="LOW,HIGH",
        help="Average |motor torque| only over samples whose motor speed lies in LOW..HIGH rad/s (thesis ch. "
             "6.3.2: 50,120); axes that leave the window empty in some cycle keep the whole-cycle mean. Prints "
             "how the window covers each task's motor speeds.")] = None,
    plugins: Annotated[list[str] | None, typer.Option(
        "--isolator", metavar="MODULE:CLASS",
        help="Also run your own isolator, a scikit-learn estimator setting source_axis_ in fit(X) (see "
             "analysis.isolation), e.g. mine:MyIsolator for class MyIsolator in mine.py in the current folder; "
             "repeat for several.")] = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Output stem (default: FILE without .h5 + '-isolation').")] = None,
    overwrite: Overwrite = False,
    progress: Annotated[bool, typer.Option(help="Show a progress bar.")] = True,
) -> None:
    """Accuracy of every isolator (transfer entropy, cross-correlation, Granger, ...) at finding the
    worn axis, per task and wear level: CSV, Markdown (thesis Table 6.2 layout) and a PNG heatmap."""
    from analysis import benchmark

    stem = out or file.with_name(file.stem + "-isolation")
    confusion_stem = stem.with_name(stem.name + "-confusion")
    _analysis_input(file, [stem.with_suffix(".csv"), stem.with_suffix(".md"), stem.with_suffix(".png"),
                           confusion_stem.with_suffix(".csv"), confusion_stem.with_suffix(".png")], overwrite)
    try:
        wear_levels = [float(x) for x in levels.split(",")]
        window = _parse_window(speed_window) if speed_window is not None else None
        isolators = benchmark.default_isolators(bins or (5, 10))
        isolators.update({spec.rpartition(":")[2]: benchmark.load_estimator(spec) for spec in plugins or []})
        table = benchmark.isolation_table(file, isolators, wear_levels, progress=progress, speed_window=window)
    except ValueError as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(2) from err
    written = benchmark.write_outputs(table, stem, benchmark.isolation_markdown(table))
    written.append(benchmark.isolation_heatmap(table, stem.with_suffix(".png")))
    confusion = benchmark.isolation_confusion(table)
    confusion.to_csv(confusion_stem.with_suffix(".csv"))
    written += [confusion_stem.with_suffix(".csv"), benchmark.confusion_figure(confusion, confusion_stem.with_suffix(".png"))]
    if window is not None:
        typer.echo(f"motor speeds against the window {window[0]:g}-{window[1]:g} rad/s (runs without wear):")
        typer.echo(benchmark.markdown(benchmark.motor_speed_coverage(file, window), digits=4))
    accuracy = benchmark.isolation_accuracy(table).rename(index={0.0: "no fault"}, level="wear_pct")
    typer.echo(benchmark.markdown(accuracy, digits=4))
    typer.echo("wear_pct \"no fault\": runs without wear, accuracy = share left undecided (naming an axis is a false "
               "isolation)")
    starved = benchmark.starved_isolators(table)
    if starved:
        typer.echo(f"note: this dataset lacks cycles: with at most {int(table['cycles'].max())} recorded cycles per "
                   f"run, {', '.join(starved)} named no axis (undecided, or too few cycles to run) in most worn "
                   "cases. These isolators need tens of cycles (thesis Table 6.2: up to 86, every cycle recorded): "
                   "use `faultgen sweep --preset j2`, or --record with more cycles")
    typer.echo("wrote " + ", ".join(map(str, written)))


@app.command("detect", cls=PlainHelpCommand)
def detect_command(
    file: Annotated[Path, typer.Argument(help="A faultgen dataset with worn runs and runs without wear.")],
    protocol: Annotated[str, typer.Option(
        help="Where the monitor learns normal operation: other-seeds (runs without wear of the other seeds: other "
             "units), first-cycles (the first --first samples of the tested run: its first days, thesis ch. 4), "
             "same-run (the run without wear of the same seed: thesis ch. 3, optimistic) or auto (other-seeds where "
             "the dataset has several seeds, else first-cycles where runs are longer than --first, else same-run).")] = "auto",
    first: Annotated[int, typer.Option(help="Samples the first-cycles protocol learns from.")] = 20,
    variance: Annotated[float, typer.Option(help="Explained variance that sets the PCA components (thesis: 0.75).")] = 0.75,
    alpha: QAlpha = 0.05,
    limit_folds: Annotated[int, typer.Option(
        help="Folds over which the Q limit is estimated out of sample under other-seeds and first-cycles: a limit "
             "from the training samples alone (0; the thesis's eq. 2.6) alarms on more than ALPHA of new healthy "
             "data (j2, three seeds: 9.0 % at 5 %; 20 folds: 6.2 %). same-run always uses the thesis's limit.")] = 20,
    persistence: Annotated[
        int, typer.Option(help="Samples in a row above the limit to call an onset. 1 is the thesis's rule, but a 95 % "
                          "limit is then crossed by 5 % of normal samples, so long runs always alarm early.")
    ] = 3,
    period: Annotated[int | None, typer.Option(help="Average the histograms of each PERIOD cycles into one sample (60: hours of one-minute cycles, c2).")] = None,
    plugin: Annotated[str | None, typer.Option(
        "--detector", metavar="MODULE:CLASS",
        help="Your own detector instead of the PCA monitor: a scikit-learn estimator whose fit(X) learns healthy "
             "samples and whose predict(X) gives one alarm per sample, e.g. mine:MyDetector (mine.py in the "
             "current folder).")] = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Output stem (default: FILE without .h5 + '-detection').")] = None,
    overwrite: Overwrite = False,
    progress: Annotated[bool, typer.Option(help="Show a progress bar.")] = True,
) -> None:
    """PCA onset detection (Q statistic) and location per worn run, thesis Table 3.5 layout, with the
    false-alarm rate on healthy runs the monitor did not learn from; summary per task and axis.

    Writes OUT.csv and OUT.md (per run) and OUT-summary.csv (per task, per worn axis, all).

    Example:

      faultgen detect j2.h5 --protocol other-seeds -o j2-detection
    """
    from analysis import benchmark

    stem = out or file.with_name(file.stem + "-detection")
    summary_csv = stem.with_name(stem.name + "-summary.csv")
    _analysis_input(file, [stem.with_suffix(".csv"), stem.with_suffix(".md"), summary_csv], overwrite)
    try:
        table = benchmark.detection_table(
            file, variance=variance, alpha=alpha, persistence=persistence, period=period, progress=progress,
            detector=benchmark.load_estimator(plugin) if plugin else None, protocol=protocol, first=first,
            limit_folds=limit_folds or None)
    except ValueError as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(2) from err
    summary = benchmark.detection_summary(table)
    written = benchmark.write_outputs(table, stem)
    summary.to_csv(summary_csv)
    typer.echo(benchmark.markdown(table, digits=4))
    typer.echo("\nsummary (false_alarm_pct: alarms on healthy runs the monitor did not learn from, %):")
    typer.echo(benchmark.markdown(summary, digits=4))
    held_in = table[table["protocol"] != "other-seeds"]
    if protocol == "auto" and len(held_in):
        typer.echo(f"note: this dataset lacks runs without wear of other seeds, so {len(held_in)} of {len(table)} runs "
                   f"were judged by a monitor that learned from {', '.join(sorted(set(held_in['protocol'])))}. For "
                   "false alarms on healthy runs of other units, sweep several seeds: `faultgen sweep --preset quick "
                   "--seed 0 --seed 1 --seed 2`")
    typer.echo("wrote " + ", ".join(map(str, [*written, summary_csv])))


@app.command("training-source", cls=PlainHelpCommand)
def training_source_command(
    file: Annotated[Path, typer.Argument(help="A fleet (`faultgen fleet`): daily records of failing and normal robots.")],
    training_days: Annotated[int, typer.Option(help="Days each PCA model learns (thesis ch. 4.3.2: 40).")] = 40,
    test_days: Annotated[int, typer.Option(help="Days tested after them (thesis: 15).")] = 15,
    gap_days: Annotated[int, typer.Option(help="Last days left out, the failure day included (thesis: 5).")] = 5,
    variance: Annotated[float, typer.Option(help="Explained variance that sets the PCA components (thesis: 0.90).")] = 0.90,
    alpha: QAlpha = 0.05,
    limit_folds: Annotated[int, typer.Option(
        help="Folds over which the Q limit is estimated out of sample; 0: from the training days alone, the "
             "thesis's eq. 2.6, which alarms on most test days of normal robots when the features are nearly as "
             "many as the training days.")] = 20,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Output stem (default: FILE without .h5 + '-training-source').")] = None,
    overwrite: Overwrite = False,
    progress: Annotated[bool, typer.Option(help="Show a progress bar.")] = True,
) -> None:
    """Thesis ch. 4: the training-source study of Table 4.1 on a fleet. Each robot is tested on its
    test days by a PCA model learnt from its own first days (one-to-one, OTO) or from those of
    each normal robot of its model (one-to-many, OTM), on raw, absolute-difference and combined
    signals; the Q residual's coefficient of variation, samples above the limit and lead time
    are compared by a three-way ANOVA and Tukey's HSD (Tables 4.2-4.4, Figs. 4-4 to 4-6).

    Writes OUT-cases.csv (one row per test case), OUT-anova.csv, OUT-tukey.csv, OUT.md, OUT.png.

    Example:

      faultgen fleet -o fleet.h5 && faultgen training-source fleet.h5 -o fleet-ch4
    """
    from analysis import benchmark
    from analysis import training_source as ts

    stem = out or file.with_name(file.stem + "-training-source")
    paths = {name: stem.with_name(stem.name + suffix) for name, suffix in
             (("cases", "-cases.csv"), ("anova", "-anova.csv"), ("tukey", "-tukey.csv"), ("md", ".md"),
              ("png", ".png"))}
    _analysis_input(file, list(paths.values()), overwrite)
    try:
        window = ts.Window(training_days, test_days, gap_days)
        cases = ts.study(file, window, variance=variance, alpha=alpha, limit_folds=limit_folds or None,
                         progress=progress)
    except ValueError as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(2) from err
    parts = ["Design (thesis Table 4.1), test cases:\n\n" + benchmark.markdown(ts.design(cases)),
             "Descriptors of the Q residual over the test days, mean and standard error:\n\n"
             + benchmark.markdown(ts.group_means(cases))]
    tukey = None
    try:
        anova, tukey = ts.anova(cases), ts.tukey(cases)
    except ValueError as err:  # an empty cell: the cases and means stand, the tests cannot be run
        parts.append(f"No ANOVA or Tukey HSD: {err}")
        del paths["anova"], paths["tukey"]
    else:
        parts += ["Three-way ANOVA, type III (thesis Tables 4.2-4.4):\n\n" + benchmark.markdown(anova),
                  "Tukey HSD, failure against normal robots per training source and signal type (the starred bars "
                  "of thesis Figs. 4-4 to 4-6):\n\n" + benchmark.markdown(ts.failure_vs_normal(tukey))]
        anova.to_csv(paths["anova"], index=False)
        tukey.to_csv(paths["tukey"], index=False)
    text = "\n\n".join(parts)
    cases.to_csv(paths["cases"], index=False)
    paths["md"].write_text(text + "\n")
    ts.figure(cases, paths["png"], marked=tukey)
    typer.echo(text)
    typer.echo("wrote " + ", ".join(map(str, paths.values())))


@app.command("classify", cls=PlainHelpCommand)
def classify_command(
    file: Annotated[Path, typer.Argument(help="A faultgen dataset with worn runs and runs without wear.")],
    wear_threshold: Annotated[float, typer.Option(help="A cycle is 'failed' when its true wear is at least this, %.")] = 10.0,
    pairs: Annotated[int, typer.Option(help="Worn/unworn run pairs left out (Procedure 1); 0 = all.")] = 20,
    horizon: Annotated[int | None, typer.Option(
        help="The thesis's protocol (ch. 5.3.3): keep each run's samples from HORIZON + 10 to HORIZON before its "
        "last (T-13 to T-3 for 3; T the failure day of a failing robot), labelled by the robot's state, failing or "
        "healthy, instead of by --wear-threshold. Table 5.2 used 3.", min=0)] = None,
    matched_days: Annotated[bool, typer.Option(
        "--matched-days", help="A time control: rank a failing run's failed samples only against the healthy run's "
        "samples at the same positions in its record (same day of the record), not against earlier days. Labels by "
        "wear put a failing robot's failed days last, so whatever drifts along a record (season, the indicators "
        "settling) scores without any fault; matched it cannot. No change with --horizon.")] = False,
    permutations: Annotated[int, typer.Option(
        help="Also the chance level of each cell on these robots: the AUC again with the runs' labels exchanged "
        "this many times (columns 'null', their mean, and 'p', the permutation p-value of the AUC). Each costs as "
        "much as the table: choose cells with --classifier/--preprocessing. 0 = none.", min=0)] = 0,
    classifiers: Annotated[list[str] | None, typer.Option(
        "--classifier", help="Only this classifier (lr, svm, rf, stacking); repeat for several. Default all.")] = None,
    preprocessing: Annotated[list[str] | None, typer.Option(
        "--preprocessing", help="Only this row of Table 5.2 (control, +diff, +estM+diff+var3+pca, ...); repeat for "
        "several. Default all.")] = None,
    seed: Annotated[int, typer.Option(help="Seed for the choice of pairs, the permutations and the random forest.")] = 0,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Output stem (default: FILE without .h5 + '-classification').")] = None,
    overwrite: Overwrite = False,
    progress: Annotated[bool, typer.Option(help="Show a progress bar.")] = True,
) -> None:
    """AUC of LR, SVM, RF and stacking per preprocessing combination, thesis Table 5.2 layout.

    A sample is a recorded cycle (a day in a fleet). Its features per axis are those of thesis
    Table 5.1: the speed and torque indicators (the axis's average speed and mean load over its
    production so far) and the KL divergences of its angle, speed and torque histograms against
    the run's first sample; the "+estM" rows add each sample's own average speed and load. A
    sample is 'failed' when its true wear reaches --wear-threshold. Procedure 1 holds out one
    worn and one unworn run at a time, trains on the rest and scores the pair by AUC; --pairs 0
    takes every pair, as the thesis did.

    Robots of one kind (process, model) look alike, so chance is not 0.5 here: --permutations
    measures it on the same robots, and 'p' says whether the AUC beats it. With labels by wear a
    failing robot's failed days are its last, so a classifier that only learns when in the record
    a day lies scores well above 0.5; --matched-days compares them with the same days of the
    healthy robot instead.

    Examples (the thesis's Table 5.2: its window before failure, every pair; then the chance
    level of two cells on labels by wear; then of one with the time control):

      faultgen fleet -o fleet.h5 && faultgen classify fleet.h5 --horizon 3 --pairs 0

      faultgen classify fleet.h5 --classifier lr --preprocessing control --preprocessing +diff --permutations 19

      faultgen classify fleet.h5 --matched-days --classifier lr --preprocessing +diff --permutations 19
    """
    from analysis import benchmark

    cells = {"classifiers": classifiers} if classifiers else {}
    if preprocessing:
        cells["preprocessing"] = preprocessing
    _table_command(file, out, overwrite, "-classification", 3, lambda: benchmark.classification_table(
        file, wear_threshold=wear_threshold, n_pairs=pairs or None, random_state=seed, progress=progress,
        horizon=horizon, permutations=permutations, matched=matched_days, **cells))


def _check_outputs(files: list[Path], overwrite: bool) -> None:
    """Refuse, before any work, output files that exist (unless ``overwrite``), are folders, or
    whose folder does not exist; raises ValueError naming the file and what to do."""
    for path in files:
        if path.is_dir():
            raise ValueError(f"{path} is a folder; --out expects a file name")
        if path.exists() and not overwrite:
            raise ValueError(f"{path} exists; pass --overwrite to replace it or choose another --out")
        folder = path.parent if str(path.parent) else Path(".")
        if not folder.is_dir():
            raise ValueError(f"cannot write {path}: folder {folder} does not exist")


def _check_output_folder(folder: Path, overwrite: bool) -> None:
    """Refuse an output folder that is a file, or holds files already (unless ``overwrite``)."""
    if folder.exists() and not folder.is_dir():
        raise ValueError(f"{folder} is a file; --out expects a folder to write the results into")
    if folder.is_dir() and any(folder.iterdir()) and not overwrite:
        raise ValueError(f"{folder} holds earlier results; pass --overwrite to replace them or choose another --out")


def _parse_window(text: str) -> tuple[float, float]:
    """'50,120' -> (50.0, 120.0); raises ValueError naming the text."""
    try:
        low, high = (float(x) for x in text.split(","))
    except ValueError:
        raise ValueError(f"--speed-window {text!r}: expected LOW,HIGH in rad/s, e.g. 50,120") from None
    if not 0 <= low < high:
        raise ValueError(f"--speed-window {text!r}: expected 0 <= LOW < HIGH")
    return low, high


def _parse_cycles(text: str) -> tuple[int, ...]:
    """'1,50,90-100' -> (1, 50, 90, ..., 100); raises ValueError naming the bad part."""
    cycles: list[int] = []
    for part in text.split(","):
        part = part.strip()
        try:
            if "-" in part:
                first, last = (int(x) for x in part.split("-", 1))
                cycles.extend(range(first, last + 1))
            else:
                cycles.append(int(part))
        except ValueError:
            raise ValueError(f"--record part {part!r} is not a cycle number or range like 90-100") from None
    return tuple(cycles)


def _summary(result, out: Path) -> str:
    """What a user wants to see after a run: where it is and what happened per axis."""
    last = -1
    mean_torque = np.mean(np.abs(result.tau_m[last]), axis=0)
    rows = [
        ("wear multiplier, last cycle", result.friction_multiplier[last], ".4f"),
        ("mean |motor torque| [N m]", mean_torque, ".4g"),
        ("mean |friction torque| [N m]", result.mean_friction_torque[last], ".4g"),
        ("max tracking error [mrad]", 1e3 * np.max(result.tracking_error, axis=0), ".3g"),
    ]
    config = result.config
    lines = [
        f"wrote {out}: {config.robot} {config.task}, {config.friction} friction, {len(result.cycles)} recorded "
        f"cycle(s) of {result.t[-1]:.2f} s (last: cycle {int(result.cycles[last])} of {config.cycles})",
        " " * 30 + "".join(f"{'axis ' + str(i):>11}" for i in range(1, 7)),
    ]
    lines += [f"{title:<30}" + "".join(f"{v:>11{fmt}}" for v in values) for title, values, fmt in rows]
    c = result.conditions
    if c is not None:
        lines.append(f"conditions, last cycle: day {c.day[last]:.0f} at {c.hour[last]:.1f} h; dry friction x "
                     + " ".join(f"{v:.3f}" for v in c.dry_friction_factor[last]) + ", viscous x "
                     + " ".join(f"{v:.3f}" for v in c.viscous_factor[last]))
        if config.conditions.thermal is not None:
            lines.append(f"  joint temperature {np.min(c.joint_temperature):.1f}..{np.max(c.joint_temperature):.1f} degC "
                         "over the recorded cycles")
        if np.any(c.gear_loss):
            lines.append("  gear loss (load-dependent friction coefficient) " + " ".join(f"{v:.3f}" for v in c.gear_loss))
        if config.conditions.payloads is not None:
            lines.append("  payload mass per cycle [kg]: " + " ".join(f"{m:g}" for m in c.payload_mass[:12])
                         + (" ..." if len(c.payload_mass) > 12 else ""))
    lines.append(f"read it with: python -c \"from faultgen import dataset; a, labels = dataset.read_run('{out}')\"")
    return "\n".join(lines)


if __name__ == "__main__":
    app()
