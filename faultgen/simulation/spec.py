"""A run as text (:class:`RunSpec`): what a command reads off its options, a dataset records and a
worker receives, with nothing looked up yet. :func:`faultgen.simulation.resolve.resolve` turns it
into a run of objects (:class:`faultgen.simulation.resolve.Run`): the robot compiled, the task read
and planned, the friction model and the stepper found, once per process.

Frozen and picklable, no I/O: its fields are names, paths and values (a wear plan, operating
conditions, a noise level, a fault), so two equal specs are the same run on any machine that holds
the same files (:meth:`RunSpec.for_workers` makes its paths absolute for a worker whose folder is
not this process's).
"""

from __future__ import annotations

import copyreg
import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

from faultgen.model import robots
from faultgen.operation import programs
from faultgen.operation.conditions import Conditions
from faultgen.operation.faults import Fault
from faultgen.operation.wear import WearPlan
from faultgen.simulation import backends, sensors

# The values a spec holds keep read-only mappings (a wear schedule's parameters, a fault's options),
# which the standard pickle does not know: they travel as their dict, as cloudpickle (joblib's and
# Dask's pickler) sends them.
def read_only(mapping: dict) -> MappingProxyType:
    """``mapping`` read-only: how a pickled read-only mapping is made again."""
    return MappingProxyType(mapping)


copyreg.pickle(MappingProxyType, lambda mapping: (read_only, (dict(mapping),)))


@dataclass(frozen=True)
class RunFields:
    """The values of one run, declared once: :class:`RunSpec` holds them as text,
    :class:`faultgen.simulation.config.RunConfig` (whose attributes document them) resolved and
    checked. The same names, meanings and defaults in both."""

    robot: str
    task: str | programs.TextProgram | programs.LogTask | programs.Motion
    friction: str = "lugre"
    wear: WearPlan = field(default_factory=lambda: WearPlan({}))
    cycles: int = 100
    record: tuple[int, ...] | None = None
    seed: int = 0
    noise: sensors.NoiseConfig = field(default_factory=sensors.NoiseConfig)
    nthread: int = 0
    back_to_back: bool = False
    conditions: Conditions = field(default_factory=Conditions)
    signals: bool = True
    daily: bool = False
    fault: Fault | None = None


@dataclass(frozen=True)
class RunSpec(RunFields):
    """One run as text (module docstring); the fields of
    :class:`faultgen.simulation.config.RunConfig` (the same names, meanings and defaults), the
    robot and the task as given, and the stepper by name.

    Attributes
    ----------
    robot : str
        Robot name (``faultgen robots``), robot folder or MJCF path.
    task : str or TextProgram or LogTask or Motion
        A thesis task name, a program file or joint log path, or a task value that carries its
        content (:mod:`faultgen.operation.tasks`); its kind is :func:`faultgen.operation.programs.kind`'s.
    friction, wear, cycles, record, seed, noise, nthread, back_to_back, conditions, signals, daily, fault
        As :class:`~faultgen.simulation.config.RunConfig`.
    stepper : str
        The stepping backend by its registered name (:data:`faultgen.simulation.backends.STEPPERS`).

    Raises
    ------
    TypeError
        A robot or stepper that is not a non-empty string (a :class:`Robot` already resolved is given
        to :func:`~faultgen.simulation.resolve.resolve` as ``resolved``, this spec naming it by
        :func:`faultgen.model.robots.source_of`), a task that is none of the kinds above.
    """

    stepper: str = backends.DEFAULT

    def __post_init__(self) -> None:
        for name in ("robot", "stepper"):
            value = getattr(self, name)
            if not isinstance(value, str) or not value:
                given = repr(value) if isinstance(value, str) else f"a {type(value).__name__}"
                raise TypeError(f"RunSpec {name} = {given}: expected a non-empty string (a name or path); "
                                "a resolved robot is given to resolve(spec, resolved=ROBOT)")
        if not isinstance(self.task, str | programs.LogTask | programs.Motion):
            raise TypeError(f"RunSpec task = a {type(self.task).__name__}: expected a task name, a program or log path, or a "
                            "TextProgram, LogTask or Motion")

    def run_fields(self) -> dict:
        """The keyword arguments of :class:`~faultgen.simulation.config.RunConfig` but ``robot``
        (the fields less ``stepper``)."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name not in ("robot", "stepper")}

    def for_workers(self) -> RunSpec:
        """This spec with its robot and task, where they are paths on this machine (a robot folder
        or MJCF file that is not a known robot name, a program or log file), made absolute: a
        worker's folder is not this process's. Looks at the files' existence only."""
        changes = {}
        if self.robot not in robots.available() and Path(self.robot).exists():
            changes["robot"] = str(Path(self.robot).absolute())
        if programs.kind(self.task) in programs.FILE_KINDS and Path(self.task).is_file():
            changes["task"] = absolute_task(self.task)
        return dataclasses.replace(self, **changes) if changes else self


def absolute_task(task: str | programs.LogTask) -> str | programs.LogTask:
    """A program or log file task (:data:`faultgen.operation.programs.FILE_KINDS`) with its path made
    absolute; a :class:`~faultgen.operation.tasks.LogTask` keeps its format."""
    path = str(Path(task).absolute())
    return dataclasses.replace(task, path=path) if programs.kind(task) == programs.FORMAT_LOG else path
