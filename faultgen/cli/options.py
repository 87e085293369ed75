"""Options that several commands share, declared once: the output, progress and parallelism
options, and the operating conditions of `simulate`, `sweep` and `fleet`
(faultgen.operation.conditions), with :func:`conditions_from_options` turning the latter into the library's
:class:`~faultgen.operation.conditions.Conditions`."""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated

import typer

if TYPE_CHECKING:
    from faultgen.operation.conditions import Conditions

#: Upper bounds of the command-line counts (each far above any use, each keeping the work and its
#: memory finite): cycles of a run, days of a record, samples, Q-limit folds, held-out pairs and
#: label permutations.
MAX_CYCLES = 1_000_000
MAX_DAYS = 3650
MAX_SAMPLES = 1_000_000
MAX_FOLDS = 1000
MAX_PAIRS = 100_000  # as analysis.classify.MAX_PAIRS (the bound on "every pair", --pairs 0)
MAX_PERMUTATIONS = 10_000

#: The ``--overwrite`` flag of every command that writes: without it an existing output is refused.
Overwrite = Annotated[bool, typer.Option("--overwrite", help="Replace existing outputs; without it they are refused.")]
Progress = Annotated[bool, typer.Option(help="Show a progress bar.")]
LogFormat = Annotated[str, typer.Option(
    "--format", help="The logs' layout: measured (t, q1..qN, tau1..tauN; docs/dataset.md), ur-rtde (Universal "
    "Robots' RTDE recorder CSV) or voraus (the voraus-AD Parquet columns; CC BY-NC-SA data: use your own copy).")]
TorqueConstants = Annotated[str | None, typer.Option(
    metavar="K1,...,KN", help="With --format ur-rtde: N m/A at each joint, to read the torque as the measured "
    "actual_current_0.. times them (without it: the commanded target_moment_0.., which cannot show wear; "
    "docs/dataset.md, \"Adapters\", on finding the constants).")]
Jobs = Annotated[int, typer.Option(help="Local worker processes (at most one per run, or per unit of a monitor, is started; more than the CPU cores only slows each down).", min=1, max=1024)]


def warn_jobs(jobs: int, what: str, memory: str) -> None:
    """Warn (stderr) when ``jobs`` local workers are more than this machine's CPU cores: ``what``
    (the runs, the units) share the cores and each takes longer, and each worker takes ``memory``
    (its figure in words, "about 150 MB"). The commands start at most one worker per run or unit;
    the warning is the same for each."""
    import os

    cores = os.cpu_count() or 1
    if jobs > cores:
        typer.echo(f"warning: --jobs {jobs} is more than the {cores} CPU cores: {what} share them and each takes "
                   f"longer (and memory: {memory} per worker); --jobs {cores} is as fast", err=True)


def _scheduler_address(value: str | None) -> str | None:
    """The ``--scheduler`` address, its form checked before any work (typer callback)."""
    if value is not None:
        from faultgen.runs import cluster

        try:
            cluster.check_address(value)
        except ValueError as err:
            raise typer.BadParameter(str(err)) from None
    return value


Scheduler = Annotated[str | None, typer.Option(
    callback=_scheduler_address,
    help="Run on the Dask cluster of this scheduler (tcp://HOST:PORT, or tls://HOST:PORT with Dask's TLS "
    "configuration) instead of local processes: its workers need faultgen, not OUT's folder; each run comes back "
    "to this process, which writes it (docs/dataset.md, \"Running on a cluster\"). Dask sends tasks and results "
    "as pickles, which run code when read: name only a scheduler you trust, on a network you trust, or use TLS "
    "(docs/reliability.md, \"Threat model\"). An address where no Dask scheduler answers is refused in seconds.")]
MonitorScheduler = Annotated[str | None, typer.Option(
    "--scheduler", callback=_scheduler_address,
    help="Score the units on the Dask cluster of this scheduler (tcp://HOST:PORT, or tls://HOST:PORT with Dask's TLS "
    "configuration) instead of local processes: its workers need faultgen and the robot (a known robot's name, or "
    "an added robot's folder at the same path), not LOGS or OUT; each unit's logs and cached twin go to a worker "
    "and its results come back to this process, which writes OUT, the same bytes as --jobs 1 (docs/performance.md, "
    "\"Monitoring a fleet on a cluster\"). Not with --jobs. Dask sends tasks and results as pickles, which run code "
    "when read: name only a scheduler you trust, on a network you trust, or use TLS. An address where no Dask "
    "scheduler answers is refused in seconds.")]


def _stepper(value):
    """The ``--backend`` name resolved, once, to a stepper object before any work (typer callback):
    :func:`faultgen.simulation.backends.get` of it, the default's when not given."""
    from faultgen.simulation import backends

    try:
        return backends.get(backends.DEFAULT if value is None else value)
    except ValueError as err:
        raise typer.BadParameter(str(err)) from None


Backend = Annotated[str | None, typer.Option(
    "--backend", callback=_stepper, show_default=False, help="The stepping backend the simulations run on: "
    "batch (mujoco.batch, threaded C; the default) or loop (a plain mj_step loop, slow: the tests' reference); "
    "every backend gives the same outputs to float tolerance (docs/architecture.md, \"Stepping backends\").")]

SharedFolder = Annotated[bool, typer.Option(
    "--shared-folder", help="With --scheduler: the workers write their runs into OUT's folder themselves, which "
    "they must all see at the same absolute path (a shared file system; checked first): the client then only merges "
    "(docs/performance.md, \"Scaling out\", says when that is faster).")]
QAlpha = Annotated[float, typer.Option("--alpha", help="Significance of the Q limit (0.05: 95 % limit).", min=1e-9, max=0.5)]
Friction = Annotated[str | None, typer.Option(
    "--friction", help="Motor-side friction model: lugre (dynamic) or stribeck (static eq. 6.3; needed for "
    "calibrated load-dependent friction, warm-up drift and --gear-loss).")]

Temperature = Annotated[bool, typer.Option(
    "--temperature", help="Joint temperature on: hall air 20 degC +- 5 K seasonal +- 2 K daily, joints warming "
    "15 K over a shift (1 h time constant), friction following the gear oil's viscosity (docs/simulation.md).")]
DryShare = Annotated[float | None, typer.Option(
    "--dry-share", metavar="S", min=0.0, max=1.0, help="The exponent of the oil viscosity's ratio that the dry (Coulomb, Stribeck) "
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
    "--gear-loss", metavar="C", min=0.0, max=1.0,
    help="Each unit's gearboxes also lose a share of the transmitted torque as Coulomb friction, drawn per axis "
    "uniformly in 0..C (1 minus the gear efficiency under load; e.g. 0.1). Needs --friction stribeck, and "
    "--unit-spread outside a fleet. Default 0: none.")]
TaskMixTasks = Annotated[str | None, typer.Option(
    "--task-mix", metavar="TASK,TASK,...",
    help="Each cycle runs one of these tasks (the run's own among them), e.g. pick_place,spot_weld; needs "
    "--features-only (cycles of different tasks differ in length).")]
TaskMixPattern = Annotated[str, typer.Option(
    help="Which task each cycle runs: alternate, blocks (10 cycles each) or random.")]
CyclesPerDay = Annotated[int, typer.Option(
    help="Recorded cycles per day of the robot's life (the calendar of the temperature; default: one a day).", min=1, max=MAX_CYCLES)]
StartDay = Annotated[float, typer.Option(help="Day of the year of cycle 1.", min=0.0, max=366.0)]


def conditions_from_options(temperature: bool, payloads: str | None, pattern: str, spread: bool, cycles_per_day: int,
                            start_day: float, task_mix: str | None = None, task_pattern: str = "alternate",
                            gear_loss: float = 0.0, dry_share: float | None = None) -> Conditions | None:
    """The :class:`~faultgen.operation.conditions.Conditions` of the command-line options, made
    from them directly; None when no condition is on. Raises ValueError naming a malformed
    ``--payloads`` part, a ``--gear-loss`` without ``--unit-spread``, a ``--dry-share`` without
    ``--temperature``, or a value the conditions refuse."""
    from faultgen.operation import conditions as c

    if dry_share is not None and not temperature:
        raise ValueError(f"--dry-share {dry_share:g} sets how friction follows the joint temperature: add --temperature")
    parts = None
    if payloads:
        masses, sizes = [], []
        for part in payloads.split(","):
            try:
                mass, size = (float(v) for v in part.split(":"))
            except ValueError:
                raise ValueError(f"--payloads part {part.strip()!r}: expected MASS:SIZE in kg:m, e.g. 20:0.2") from None
            masses.append(mass)
            sizes.append(size)
        parts = c.Payloads(tuple(masses), tuple(sizes), pattern)
    if gear_loss and not spread:
        raise ValueError(f"--gear-loss {gear_loss:g} is a part of the unit spread: add --unit-spread")
    made = c.Conditions(
        thermal=(c.Temperature() if dry_share is None else c.Temperature(dry_share=dry_share)) if temperature else None,
        payloads=parts,
        spread=c.UnitSpread(gear_loss=gear_loss) if spread else None,
        task_mix=c.TaskMix(tuple(t.strip() for t in task_mix.split(",")), task_pattern) if task_mix else None,
        cycles_per_day=cycles_per_day, start_day=start_day)
    return made if made.active else None


def log_adapter(log_format: str, torque_constants: str | None, robot):
    """The :class:`faultgen.logs.formats.LogFormat` of ``--format`` (from the registry,
    :data:`faultgen.logs.formats.FORMATS`; ``measured`` its default entry) with ``--torque-constants`` parsed and checked against the axes of ``robot``, the command's
    resolved :class:`~faultgen.model.robot.Robot` (None when no torque constants are given).

    Raises
    ------
    ValueError
        An unknown format; torque constants with another format than ur-rtde, not numbers, not one
        per axis or outside their bounds (named).
    """
    from faultgen.logs import formats

    if torque_constants is not None and log_format != "ur-rtde":
        raise ValueError(f"--torque-constants reads UR's actual_current columns: give it with --format ur-rtde, not "
                         f"--format {log_format}")
    options = {}
    if torque_constants is not None:
        try:
            constants = tuple(float(k) for k in torque_constants.split(","))
        except ValueError:
            constants = ()
        lo, hi = formats.MIN_TORQUE_CONSTANT, formats.MAX_TORQUE_CONSTANT
        n_axes = robot.n_axes
        if len(constants) != n_axes or not all(lo <= k <= hi for k in constants):
            raise ValueError(f"--torque-constants {torque_constants[:200]!r}: expected {n_axes} numbers (the axes "
                             f"of {robot.name}), comma-separated, each {lo:g} .. {hi:g} N m/A at the joint")
        options["torque_constants"] = constants
    return formats.make(log_format, **options)
