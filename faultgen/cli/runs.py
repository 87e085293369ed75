"""``faultgen simulate``, ``sweep`` and ``fleet``: runs of the simulator into labelled datasets."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from faultgen.checks import MAX_SEED
from faultgen.cli.base import Command, check_outputs, parse_cycles
from faultgen.cli.main import app
from faultgen.cli.options import (
    MAX_CYCLES, Backend, CyclesPerDay, DryShare, Friction, GearLoss, Jobs, LogFormat, Overwrite, PayloadParts,
    PayloadPattern, Progress, Scheduler, SharedFolder, StartDay, TaskMixPattern, TaskMixTasks, Temperature,
    TorqueConstants, UnitSpreadFlag, conditions_from_options, log_adapter, warn_jobs,
)


#: simulate's options.
RunRobot = Annotated[str, typer.Option(
    "--robot", "--model",
    help="Robot name (see `faultgen robots`), robot folder (from `faultgen robots add`) or MJCF file, e.g. the "
    "model `faultgen calibrate` wrote.")]
RunTask = Annotated[str, typer.Option(help="pick_place, spot_weld or arc_weld (thesis ch. 6.3.1 tasks 1-3), a program file (.toml, `faultgen tasks`) or a joint log to replay (.csv with t, q1..qN in rad, or a log in another --format).")]
WearSpecs = Annotated[
    list[str] | None,
    typer.Option(
        help="A worn axis as AXIS:KIND:PERCENT[:key=value], e.g. 2:exp4:20 (20 % more Coulomb and static "
        "friction on axis 2 by the last cycle, thesis eq. 6.6). KIND: exp4, logistic, linear, step. Repeat "
        "for several axes. No --wear: no wear."
    ),
]
RunCycles = Annotated[int, typer.Option(help="Cycles in the run; wear schedules reach PERCENT at the last one.", min=1, max=MAX_CYCLES)]
RecordCycles = Annotated[
    str | None,
    typer.Option(help="Cycles to simulate and record, e.g. '1,50,100' or '90-100'. Default: all."),
]
RunSeed = Annotated[int, typer.Option(help="Seed of the disturbance and encoder noise.", min=0, max=MAX_SEED)]
Disturbance = Annotated[
    float, typer.Option(help="Load disturbance std as a fraction of mean |torque| per axis (thesis ch. 3.3.2).", min=0.0, max=1.0)
]
EncoderNoise = Annotated[float, typer.Option(help="Encoder noise std, rad (thesis ch. 3.3.2).", min=0.0, max=0.1)]
SteppingThreads = Annotated[int, typer.Option(help="Threads for stepping; 0 uses all CPUs.", min=0, max=1024)]
RunFault = Annotated[str | None, typer.Option(
    help="A fault other than friction wear, growing to FINAL by the last cycle: EFFECT:AXIS:PARAMETER:FINAL"
    "[:key=value,...], e.g. backlash:2:width:0.01 (a 10 mrad dead band on axis 2) or "
    "cogging:3:amplitude:0.05:poles=8,kind=exp4. Effects: faultgen.effects (not payload, load friction, "
    "warm-up, nor the motor friction and its parts coulomb, viscous, stribeck: their fault is --wear).")]
RunOut = Annotated[Path, typer.Option("--out", "-o", help="HDF5 file to write.")]


@app.command("simulate", cls=Command)
def simulate_command(
    robot: RunRobot = "irb6700",
    task: RunTask = "pick_place",
    log_format: LogFormat = "measured",
    torque_constants: TorqueConstants = None,
    friction_model: Friction = "lugre",
    wear: WearSpecs = None,
    cycles: RunCycles = 100,
    record: RecordCycles = None,
    seed: RunSeed = 0,
    disturbance: Disturbance = 0.01,
    encoder_noise: EncoderNoise = 1e-4,
    threads: SteppingThreads = 0,
    fault: RunFault = None,
    temperature: Temperature = False,
    dry_share: DryShare = None,
    payloads: PayloadParts = None,
    payload_pattern: PayloadPattern = "alternate",
    unit_spread: UnitSpreadFlag = False,
    gear_loss: GearLoss = 0.0,
    cycles_per_day: CyclesPerDay = 1,
    start_day: StartDay = 0.0,
    out: RunOut = Path("run.h5"),
    overwrite: Overwrite = False,
    progress: Progress = True,
) -> None:
    """Simulate one run: a robot repeating a task while chosen axes wear, into an HDF5 file.

    Only the recorded cycles are simulated, all at once, each from the task's start state with its
    own wear level. Signals are logged at 250 Hz.

    Examples:

    \b
      faultgen simulate --robot irb6700 --task pick_place --wear 1:exp4:20 --cycles 100 -o axis1.h5
      faultgen simulate --task spot_weld --wear 2:exp4:20 --wear 5:linear:10 --record 1,100 -o two.h5
      faultgen simulate --wear 3:exp4:20 --temperature --payloads 20:0.2,80:0.4 --unit-spread -o real.h5
      faultgen simulate --friction stribeck --wear 2:exp4:20 --unit-spread --gear-loss 0.1 -o lossy.h5
    """
    from faultgen.data import dataset
    from faultgen.model import robots
    from faultgen.operation import conditions as conditions_module
    from faultgen.operation import faults as faults_module
    from faultgen.operation import programs
    from faultgen.operation import wear as wear_module
    from faultgen.simulation import sensors
    from faultgen.simulation.resolve import resolve
    from faultgen.simulation.spec import RunSpec

    check_outputs([out], overwrite)
    if cycles < 1:
        raise ValueError(f"--cycles {cycles}: expected a whole number >= 1")
    loaded = robots.load(robot)  # once, for the options that need its axes and the run
    adapter = log_adapter(log_format, torque_constants, loaded)
    task_of = programs.log_task(task, adapter)  # a LogTask for a log in another format than the default
    run = resolve(RunSpec(
        robot=robot, task=task_of, friction=friction_model,
        wear=wear_module.WearPlan.from_specs(wear or [], last_cycle=cycles,
                                             n_axes=loaded.n_axes if wear else None),
        cycles=cycles,
        record=None if record is None else parse_cycles(record), seed=seed,
        noise=sensors.NoiseConfig(disturbance=disturbance, encoder=encoder_noise), nthread=threads,
        conditions=conditions_from_options(temperature, payloads, payload_pattern, unit_spread, cycles_per_day,
                                           start_day, gear_loss=gear_loss, dry_share=dry_share)
        or conditions_module.Conditions(),
        fault=None if fault is None else faults_module.parse_fault(fault, last_cycle=cycles),
    ), resolved=loaded)
    config = run.config
    from faultgen.data import atomic

    atomic.check_writable(out, dataset.estimated_size(config))  # a read-only or full disk: before simulating
    result = run.simulate(progress=progress)
    command = shlex.join(["faultgen", *sys.argv[1:]])
    dataset.write_run(out, result, command=command)
    typer.echo(summary(result, out))
    if result.saturated.size:
        typer.echo(saturation_warning(result.saturated, task, replayed=isinstance(task_of, programs.LogTask)), err=True)


def saturation_warning(saturated, task: str, replayed: bool = False) -> str:
    """The warning of a run whose drives reached their torque limit (the dataset's ``saturated``
    label): which axes, what it means, and for a replayed log (by its suffix, or ``replayed``: a log
    in another format) the likely causes."""
    axes = ", ".join(str(int(a)) for a in saturated)
    text = (f"warning: the drive of axis {axes} reached its torque limit (saturated): the run does not follow its "
            "task there, and its torques are the drive's limit, not the task's")
    if replayed or Path(task).suffix.lower() in (".csv", ".gz", ".h5", ".hdf5"):
        text += ("; a replayed log is tracked as the drive's reference, so an encoder's noise in its angles, a part "
                 "heavier than the model was sized for or a motion faster than the model's drives can carry "
                 "saturate it (`faultgen monitor` replays a log's angles through the derivative filter)")
    return text


#: sweep's options (its grid's fields).
Preset = Annotated[
    str | None, typer.Option(help="A named grid: quick (a first look at the data, 21 runs; its time: docs/performance.md), first-look (the "
    "README's first analyses: bench-isolators, detect, classify; 14 runs of spot welding, 2 seeds, cycles 41-100), j2 (thesis ch. 6, 3-6 min), c2 (thesis ch. 3, 70 min or more, features only); times on 2 cores, by the machine.")
]
GridConfig = Annotated[
    Path | None, typer.Option(help="A TOML file whose keys are the grid fields below (and optionally preset).")
]
GridRobots = Annotated[list[str] | None, typer.Option("--robot", help="Robot(s): names, robot folders or MJCF files; repeat for several.")]
GridTasks = Annotated[list[str] | None, typer.Option("--task", help="Task(s): a thesis task name, a program file (.toml) or a joint log (.csv); repeat for several.")]
GridAxes = Annotated[list[int] | None, typer.Option("--axis", help="Worn axis 1..N (N the robot's axes), or 0 for a run without wear; repeat.", min=0, max=7)]
GridWear = Annotated[list[float] | None, typer.Option("--wear-pct", help="Final wear in %; repeat.", min=0.0, max=500.0)]
GridSchedules = Annotated[list[str] | None, typer.Option("--schedule", help="exp4, logistic, linear or step; repeat.")]
GridCycles = Annotated[int | None, typer.Option(help="Cycles per run.", min=1, max=MAX_CYCLES)]
GridRecord = Annotated[str | None, typer.Option(help="Cycles to record, e.g. '1,50,100' or '90-100'. Default: all.")]
GridSeeds = Annotated[list[int] | None, typer.Option("--seed", help="Seed(s); repeat.", min=0, max=MAX_SEED)]
GridFault = Annotated[str | None, typer.Option(
    help="Instead of friction wear, a fault (the form of `simulate --fault`): EFFECT:AXIS:PARAMETER:FINAL"
    "[:key=value,...], AXIS 'each' for every worn axis in turn (e.g. backlash:each:width:0.01 with --axis 0 "
    "--axis 2 --axis 3) or a number (backlash:2:width:0.01: with no --axis, the grid is the run without wear "
    "and axis 2).")]
FeaturesOnly = Annotated[bool | None, typer.Option(
    "--features-only/--signals", help="Keep only the per-cycle features and truth, not the 250 Hz signals (a "
    "fraction of the size; detect and classify give the same tables, only bench-isolators --speed-window needs "
    "the signals), or keep the signals. Default: the preset's (c2: features only), else signals.",
    show_default=False)]
SweepOut = Annotated[Path, typer.Option("--out", "-o", help="Dataset file to write (HDF5).")]


@app.command("sweep", cls=Command)
def sweep_command(
    preset: Preset = None,
    config: GridConfig = None,
    robots_: GridRobots = None,
    tasks_: GridTasks = None,
    axes: GridAxes = None,
    increases: GridWear = None,
    schedules: GridSchedules = None,
    friction_model: Friction = None,
    cycles: GridCycles = None,
    record: GridRecord = None,
    seeds: GridSeeds = None,
    fault: GridFault = None,
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
    features_only: FeaturesOnly = None,
    jobs: Jobs = 2,
    scheduler: Scheduler = None,
    shared_folder: SharedFolder = False,
    stepper: Backend = None,
    out: SweepOut = Path("sweep.h5"),
    overwrite: Overwrite = False,
    progress: Progress = True,
) -> None:
    """Simulate a grid of runs (robot x task x worn axis x wear x schedule x seed) into one dataset.

    The grid comes from --preset, --config or the options (options override the preset or file).
    Killed or failed? Run the same command again: finished runs are kept, only missing ones run.

    Examples:

    \b
      faultgen sweep --preset quick -o quick.h5
      faultgen sweep --preset j2 --jobs 2 -o j2.h5
      faultgen sweep --robot puma560 --task spot_weld --axis 0 --axis 3 --wear-pct 10 --wear-pct 20 -o s.h5
      faultgen sweep --preset j2 --temperature --unit-spread -o j2-conditions.h5
      faultgen sweep --task pick_place --axis 0 --axis 2 --task-mix pick_place,spot_weld --features-only -o mix.h5
    """
    from faultgen.operation import faults
    from faultgen.runs import sweep
    from faultgen.runs.context import ExecutionContext

    options = {"robots": robots_, "tasks": tasks_, "axes": axes, "increases": increases, "schedules": schedules,
               "friction": friction_model, "cycles": cycles, "seeds": seeds, "record": record}
    options = {k: v for k, v in options.items() if v is not None}  # every option given, whatever its value
    made = conditions_from_options(temperature, payloads, payload_pattern, unit_spread, cycles_per_day, start_day,
                                   task_mix, task_pattern, gear_loss, dry_share)
    if made is not None:
        options["conditions"] = made
    if features_only is not None:
        options["signals"] = not features_only
    if fault is not None:
        options["fault"] = faults.FaultSpec.parse(fault)  # parsed once, here
    if record is not None:
        options["record"] = list(parse_cycles(record))
    grid = sweep.Grid.of(preset, config, **options)
    if jobs < 1:
        raise ValueError(f"--jobs {jobs}: expected >= 1")
    check_outputs([out], overwrite)
    where = f" on {scheduler}" if scheduler else f" with {jobs} job(s)"

    def announce(n_runs: int, done: int) -> None:
        used = where if scheduler or jobs <= n_runs - done else f" with {max(n_runs - done, 1)} job(s) (one per run)"
        typer.echo(f"{n_runs} runs -> {out}{used}")
        if done:
            typer.echo(f"resuming: {done} of {n_runs} runs already finished in {sweep.parts_folder(out)}, kept as "
                       "they are")

    run_sweep(grid, out, context=ExecutionContext(jobs, scheduler, stepper), progress=progress, overwrite=overwrite,
              announce=announce, shared=shared_folder)
    typer.echo(next_steps(preset, out))


def next_steps(preset: str | None, out: Path) -> str:
    """What ``sweep`` prints when done: how to look at ``out``, and for the ``first-look`` preset the
    README's first analyses (for ``quick``, the preset that carries them)."""
    text = (f"wrote {out}\nlook at it with:\n  faultgen info {out}\n  faultgen validate {out}\n"
            f"  faultgen plot {out} -o {out.with_suffix('.png')}")
    if preset == "first-look":
        text += (f"\nanalyse it with (each result beside its chance level):\n  faultgen bench-isolators {out}\n"
                 f"  faultgen detect {out} --locate contribution\n  faultgen classify {out}")
    elif preset == "quick":
        text += ("\nits 10 cycles per run are too few for the analyses; for those: faultgen sweep --preset first-look "
                 "-o first-look.h5")
    return text


#: fleet's options.
FleetSize = Annotated[int, typer.Option("--robots", help="Robots in the fleet (thesis ch. 5.3.1: 26).", min=2, max=10000)]
Failing = Annotated[int | None, typer.Option(
    help="Of them, robots whose gearbox fails (thesis: 13 of 26). Default: half of --robots, rounded down.",
    min=1, max=10000, show_default=False)]
FleetModels = Annotated[list[str] | None, typer.Option(
    "--robot", help="Robot model(s) of the fleet (names, robot folders or MJCF files, mixed), taken in turn; "
    "repeat for several (default: irb6700 and puma560). One model makes every robot that model, e.g. for a "
    "fault whose FINAL suits only it. Parts are sized from each model's rated payload (docs/simulation.md).")]
FleetDays = Annotated[int, typer.Option(help="Days recorded per robot; a failing robot fails on the last one.", min=6, max=3650)]
FleetCyclesPerDay = Annotated[int, typer.Option(
    help="Cycles simulated per day, reduced to the day's maximum (thesis ch. 5.3.2: 1-4 samples a day).", min=1, max=24)]
FailureWear = Annotated[float, typer.Option(
    help="Coulomb and static friction increase of the failing axis on the failure day, %.", min=0.0,
    max=500.0)]
FleetSeed = Annotated[int, typer.Option(help="Seed of every draw: models, tasks, parts, climate, units, faults, noise.", min=0, max=MAX_SEED)]
FleetConditions = Annotated[bool, typer.Option(
    help="Each robot's climate, parts and unit spread; --no-conditions: robots differ only by model, "
    "process and fault.")]
Without = Annotated[list[str] | None, typer.Option(
    "--without", metavar="CONDITION", help="Leave one condition out of every robot, the others drawn as in the "
    "full fleet: thermal (hall climate, warm-up), payloads (the parts) or spread (unit spread); repeat for "
    "several.", show_default=False)]
FleetTaskMix = Annotated[bool, typer.Option(
    "--task-mix", help="Each robot also runs a second task, drawn from the other two, in a random half of "
    "its cycles (default: one task per robot).")]
TaskPool = Annotated[list[str] | None, typer.Option(
    "--task", help="The tasks robots draw their process from: thesis task names, program files (.toml) or "
    "joint logs (.csv); repeat for several (default: pick_place, spot_weld, arc_weld).")]
FleetFault = Annotated[str | None, typer.Option(
    help="Instead of friction wear, a failing robot's drawn axis gets this fault, growing on the exp4 schedule "
    "from its onset day to FINAL on the failure day: EFFECT:each:PARAMETER:FINAL[:key=value,...] (the "
    "form of `simulate --fault`, AXIS 'each': the drawn axis), e.g. backlash:each:width:0.01; the same FINAL on every model (--robot picks them).")]
FrictionTestEvery = Annotated[int, typer.Option(
    "--friction-test-every", metavar="DAYS", help="Each robot also runs its model's friction test "
    "(`faultgen tasks friction-test`) every DAYS days from day 1: one more run per robot, "
    "<run>-friction-test, its tests' signals labelled record=friction_test (docs/friction-test.md); "
    "0: none.", min=0, max=3650)]
FleetOut = Annotated[Path, typer.Option("--out", "-o", help="Dataset file to write (HDF5).")]


@app.command("fleet", cls=Command)
def fleet_command(
    size: FleetSize = 26,
    failing: Failing = None,
    models: FleetModels = None,
    days: FleetDays = 60,
    cycles_per_day: FleetCyclesPerDay = 2,
    failure_wear: FailureWear = 50.0,
    seed: FleetSeed = 0,
    conditions: FleetConditions = True,
    without: Without = None,
    task_mix: FleetTaskMix = False,
    task_pool: TaskPool = None,
    friction_model: Friction = "lugre",
    dry_share: DryShare = None,
    gear_loss: GearLoss = 0.0,
    fault: FleetFault = None,
    friction_test_every: FrictionTestEvery = 0,
    jobs: Jobs = 2,
    scheduler: Scheduler = None,
    shared_folder: SharedFolder = False,
    stepper: Backend = None,
    out: FleetOut = Path("fleet.h5"),
    overwrite: Overwrite = False,
    progress: Progress = True,
) -> None:
    """Simulate a fleet like the thesis's 26 robots (chapter 5) as daily remote-monitoring records.

    Half the robots develop a gearbox fault (friction wear of one drawn axis, rising from a drawn
    day to failure on the last day), half stay healthy; each robot has its own model, process,
    parts, hall climate and unit spread (docs/simulation.md, "Operating conditions and fleets").
    Killed? Run the same command again: finished robots are kept.

    Examples:

    \b
      faultgen fleet -o fleet.h5
      faultgen classify fleet.h5 --wear-threshold 10
      faultgen fleet --friction stribeck --gear-loss 0.1 -o fleet-lossy.h5
      faultgen fleet --fault backlash:each:width:0.01 -o fleet-backlash.h5
      faultgen fleet --robot irb6700 --fault cogging:each:amplitude:0.5:poles=8 -o fleet-cogging.h5
      faultgen fleet --without payloads -o fleet-no-parts.h5
      faultgen fleet --friction-test-every 14 -o fleet-tested.h5
      faultgen fleet --robots 500 --days 365 --scheduler tcp://10.0.0.5:8786 -o fleet-500.h5
    """
    from faultgen.runs import fleet
    from faultgen.runs.context import ExecutionContext

    chosen = {"models": tuple(models)} if models else {}
    if dry_share is not None:
        chosen["dry_share"] = dry_share
    if without:
        chosen["without"] = tuple(without)
    if task_pool:
        chosen["tasks"] = tuple(task_pool)
    plan = fleet.Fleet(size=size, failing=failing, days=days, cycles_per_day=cycles_per_day, **chosen,
                       failure_wear=failure_wear, seed=seed, conditions=conditions, task_mix=task_mix,
                       friction=friction_model, gear_loss=gear_loss, fault=fault,
                       friction_test_every=friction_test_every)
    if jobs < 1:
        raise ValueError(f"--jobs {jobs}: expected >= 1")
    check_outputs([out], overwrite)

    where = f" on {scheduler}" if scheduler else f" with {jobs} job(s)"

    def announce(n_runs: int, done: int) -> None:
        robots_ = f"{n_runs // 2} robots (and their friction-test runs)" if friction_test_every else f"{n_runs} robots"
        typer.echo(f"{robots_} x {days} days -> {out}{where}"
                   + (f"; resuming, {done} {'runs' if friction_test_every else 'robots'} already finished" if done else ""))

    run_sweep(plan, out, context=ExecutionContext(jobs, scheduler, stepper), progress=progress, overwrite=overwrite,
              announce=announce, shared=shared_folder)
    typer.echo(f"wrote {out}\nanalyse it with:\n  faultgen info {out}\n  faultgen classify {out}\n"
               f"  faultgen detect {out}")


def run_sweep(plan, out: Path, context, *, progress: bool, overwrite: bool, announce, shared: bool = False) -> None:
    """:func:`faultgen.runs.sweep.run` for a command (as ``context`` says, a
    :class:`faultgen.runs.context.ExecutionContext`), recording the command line in the dataset.
    Its errors reach the user through the command's error handler (:class:`Command`): 2 refused
    before anything ran, 130 interrupted with the finished runs kept, 1 a run failed. On a
    cluster, each run's worker is printed as the run is kept."""
    from tqdm.auto import tqdm

    from faultgen.runs import sweep

    if context.scheduler is None:
        warn_jobs(context.jobs, "the runs", "about 150 MB")
    if shared and not context.scheduler:
        raise ValueError("--shared-folder is for the workers of a Dask cluster: add --scheduler ADDRESS, or drop it")
    if context.scheduler:  # a Dask scheduler must answer there, before any work
        from faultgen.runs import cluster

        cluster.probe(context.scheduler)

    def where(stats) -> None:
        tqdm.write(f"{stats.run_id}: {stats.worker}, {stats.total:.1f} s, worker peak {stats.memory / 1e6:.0f} MB")

    sweep.run(plan, out, context, progress=progress, overwrite=overwrite,
              command=shlex.join(["faultgen", *sys.argv[1:]]), on_start=announce, shared=shared,
              on_run=where if context.scheduler else None)


def summary(result, out: Path) -> str:
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
        " " * 30 + "".join(f"{'axis ' + str(i):>11}" for i in range(1, result.tau_m.shape[-1] + 1)),
    ]
    lines += [f"{title:<30}" + "".join(f"{v:>11{fmt}}" for v in values) for title, values, fmt in rows]
    if config.fault is not None:
        fault = config.fault
        value = fault.values(np.array([int(result.cycles[last])]))[0]
        lines.append(f"fault {fault.text()}: {fault.effect} {fault.parameter} on axis {fault.axis} grows {fault.kind} "
                     f"from {fault.start:g} to {fault.final:g} at cycle {config.cycles}; {value:.4g} at the last "
                     "recorded cycle")
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
    lines.append(f"read it with: python -c \"import faultgen; run = faultgen.open('{out}').runs[0]; print(run, run.wear.max())\"")
    return "\n".join(lines)


