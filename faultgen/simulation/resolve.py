"""A run built from its text once (:func:`resolve`): the one place below the CLI where a run's robot,
task, friction model and stepper are looked up.

``resolve(spec) -> Run``: the robot by :func:`faultgen.model.robots.load` (one compiled robot per
file content, its SHA-1), or the one the caller already holds (``resolved``); the task as
:func:`task` reads it (its kind decided by :func:`faultgen.operation.programs.kind`, read and
planned at the robot's physics step once per process and content:
:func:`faultgen.simulation.prepare.task_path`, keyed by the SHA-256 of the robot's ``tasks.toml``
and of a program or log file, :func:`faultgen.simulation.prepare.digests`, not by file times); the
stepper by :func:`stepper`; the friction model by :meth:`RunConfig.check
<faultgen.simulation.config.RunConfig.check>` (:func:`faultgen.simulation.friction_models.get`), which
checks the run against the robot. A :class:`~faultgen.simulation.config.RunConfig` loads and plans
nothing when constructed: this is the one place that does. The :class:`Run` holds the objects;
:func:`faultgen.simulation.stepping.simulate` steps it (``simulate(run.config,
stepper=run.stepper)``, or :meth:`Run.simulate`). Every command that simulates builds its runs
here (docs/architecture.md, "Every command's runs through resolve").
"""

from __future__ import annotations

from dataclasses import dataclass

from faultgen.model import robots
from faultgen.operation import programs, tasks
from faultgen.simulation import backends, prepare
from faultgen.simulation.config import RunConfig
from faultgen.simulation.spec import RunSpec


@dataclass(frozen=True)
class Run:
    """A run of objects: ``config`` (a :class:`~faultgen.simulation.config.RunConfig` holding the
    resolved robot; its task checked and planned) and ``stepper`` (a
    :class:`faultgen.simulation.backends.Stepper`)."""

    config: RunConfig
    stepper: backends.Stepper

    def simulate(self, progress: bool = True, **options):
        """:func:`faultgen.simulation.stepping.simulate` of the run on its stepper; ``options`` as there."""
        from faultgen.simulation import stepping

        return stepping.simulate(self.config, progress=progress, stepper=self.stepper, **options)


def robot(name: str) -> robots.Robot:
    """The robot ``name`` (a known name, a robot folder or an MJCF file): :func:`faultgen.model.robots.load`,
    one compiled robot per file content. Raises ValueError (UnknownRobotError, ModelError) naming it."""
    return robots.load(name)


def task(robot_: robots.Robot, given) -> tuple[tasks.Task, tasks.JointPath]:
    """The task ``given`` (a thesis task name, a program or log file, a program's text, a log in
    another format or a motion in memory: :func:`faultgen.operation.programs.kind`) of ``robot_``
    and its checked path at the robot's physics step, read and planned once per process, robot and
    content (:func:`faultgen.simulation.prepare.digests`).

    Raises
    ------
    ValueError
        An unknown task, a missing file, or a task that cannot run on the robot (file, segment and
        value named).
    """
    programs.check_name(given)
    return prepare.task_path(robot_, given, *prepare.digests(robot_, given))


def stepper(name: str) -> backends.Stepper:
    """The stepper registered as ``name`` (:data:`faultgen.simulation.backends.STEPPERS`); ValueError
    naming the known ones."""
    return backends.get(name)


def resolve(spec: RunSpec, resolved: robots.Robot | None = None) -> Run:
    """The run ``spec`` describes, built from objects (module docstring). ``resolved``: the robot
    ``spec.robot`` names, already resolved by the caller (a grid or fleet resolves each robot once
    for all its runs; a model compiled in memory, such as a hidden-effect model or a unit's twin,
    whose ``spec.robot`` is :func:`faultgen.model.robots.source_of` it); loaded here when omitted.

    Raises
    ------
    TypeError
        ``spec`` is not a :class:`~faultgen.simulation.spec.RunSpec`, ``resolved`` not a Robot.
    ValueError
        An unknown robot, task, friction model or stepper, a file that does not load, or a value
        :class:`~faultgen.simulation.config.RunConfig` refuses (each named).
    """
    if not isinstance(spec, RunSpec):
        raise TypeError(f"resolve: expected a RunSpec, got {type(spec).__name__}")
    if resolved is not None and not isinstance(resolved, robots.Robot):
        raise TypeError(f"resolve: resolved = a {type(resolved).__name__}; expected a Robot (or None to load "
                        f"{spec.robot!r})")
    found = robot(spec.robot) if resolved is None else resolved
    stepping = stepper(spec.stepper)
    programs.check_name(spec.task)  # a thesis task, or a program / joint log file
    if programs.is_given_task(spec.task):  # planned before any simulation (segment and value named)
        task(found, spec.task)
    config = RunConfig(robot=spec.robot, resolved=found, **spec.run_fields())
    config.check(found)  # the friction model looked up, the run checked against the robot
    return Run(config, stepping)
