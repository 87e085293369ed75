"""One run's configuration (:class:`RunConfig`): values only, checked without a robot on
construction; :func:`faultgen.simulation.resolve.resolve` loads the robot, plans the task and checks
the run against them."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from faultgen.checks import MAX_SEED, is_whole
from faultgen.model import robots
from faultgen.model.robot import Robot
from faultgen.operation.conditions import Conditions
from faultgen.operation.faults import Fault
from faultgen.operation.wear import WearPlan
from faultgen.simulation import friction_models
from faultgen.simulation.spec import RunFields


@dataclass(frozen=True)
class RunConfig(RunFields):
    """One run: a robot repeating a task for ``cycles`` cycles while the axes of ``wear`` wear.

    Attributes
    ----------
    robot : str
        Robot name (``faultgen robots``), robot folder or MJCF path: what the dataset's provenance
        and configuration key record. A :class:`~faultgen.model.robot.Robot` may be given instead;
        it is then held as :attr:`model` and this becomes its name (a known robot) or MJCF path.
    task : str or faultgen.operation.tasks.LogTask
        One of :data:`faultgen.operation.tasks.TASKS`, or a program file (``.toml``) or joint log to replay
        (``.csv``, ``.h5``; a :class:`~faultgen.operation.tasks.LogTask` for a log in another format,
        :func:`faultgen.operation.programs.log_task`): :func:`faultgen.operation.programs.load`.
    friction : str
        Friction model, one of :data:`faultgen.effects.friction.MODELS`.
    wear : WearPlan
        Worn axes and their schedules; empty for no wear. The simulation applies it as faults
        (:attr:`faults`: one relative fault on the motor friction per worn axis).
    cycles : int
        Number of cycles of the run (cycle indices 1..cycles); >= 1.
    record : tuple of int, optional
        The cycles to simulate and record; all of them when omitted.
    seed : int
        Seed of the disturbance and encoder noise; >= 0.
    noise : NoiseConfig
        Disturbance and encoder noise levels.
    nthread : int
        Threads for stepping (0: all CPUs).
    back_to_back : bool
        Step the cycles one after the other in one simulation, each starting where the previous
        one ended (gearbox deflections, backlash flanks, drive integrators carry over), instead of
        each from the start state. Only without wear and with every cycle recorded.
    conditions : Conditions
        Operating conditions over the cycles (joint temperature, payloads, task mix, unit spread;
        :mod:`faultgen.operation.conditions`); none by default.
    signals : bool
        Keep the 250 Hz signals in the dataset (False: the per-cycle features and truth only).
    fault : Fault or None
        A fault other than friction wear: an effect's parameter growing over the cycles
        (:mod:`faultgen.operation.faults`), absolute; the controller does not know it.
    daily : bool
        Record one remote-monitoring sample per day of ``conditions.cycles_per_day`` cycles, the
        day's maximum (thesis ch. 5.3.2; :func:`daily_record`), instead of every cycle; every
        cycle is simulated, no signals are kept.
    resolved : Robot, optional (keyword only)
        The robot :attr:`robot` names, already resolved (:func:`faultgen.simulation.resolve.resolve`
        gives it); when omitted, :attr:`model` loads it on first use (a worker that received the run
        pickled, :func:`faultgen.model.robots.load`). Not compared; not pickled when read from a file
        (a worker resolves :attr:`robot` again, once), pickled when edited in memory (no file holds it).

    Construction does no work (scikit-learn's rule): nothing is loaded, read, planned or looked up.
    Build a run with :func:`faultgen.simulation.resolve.resolve`, which loads the robot, checks and
    plans the task and checks the run against both (:meth:`check`); one built here from a name
    is checked against its robot when simulated.

    Raises
    ------
    ValueError
        On construction: cycles < 1, a recorded cycle outside 1..cycles, a negative seed or nthread,
        ``back_to_back`` with wear, operating conditions, a fault or a ``record`` subset, ``daily``
        with a ``record`` subset, signals, or cycles that are not whole days, a relative fault as
        ``fault`` (friction wear is ``wear``), a fault whose last cycle is not the run's, a task mix
        without the run's task or with signals. By :meth:`check` (:func:`resolve`): an unknown
        friction model, an axis out of range, a fault whose effect the robot already carries, a
        growing in-plant fault or a unit spread with a gear loss under the ``lugre`` friction
        model. By :func:`resolve`: an unknown robot or an invalid robot file, an unknown task. The
        message names the value.
    TypeError
        On construction: a wear plan, conditions, fault or ``resolved`` of the wrong type.
    """

    resolved: Robot | None = field(default=None, compare=False, repr=False, kw_only=True)

    def __post_init__(self) -> None:
        # no work on construction (scikit-learn's rule): nothing loaded, read, planned or looked up;
        # the values checked here need no robot, the rest :meth:`check` (resolve, simulate)
        if isinstance(self.robot, Robot):
            object.__setattr__(self, "resolved", self.robot)
            object.__setattr__(self, "robot", robots.source_of(self.robot))
        elif self.resolved is not None and not isinstance(self.resolved, Robot):
            raise TypeError(f"resolved: expected a Robot, got {type(self.resolved).__name__}")
        if not is_whole(self.cycles, 1):
            raise ValueError(f"cycles = {self.cycles!r}; expected a whole number >= 1")
        if self.record is not None:
            record = tuple(int(c) for c in self.record)
            if not record:
                raise ValueError("record is empty; give at least one cycle, or omit it to record all")
            bad = [c for c in record if not 1 <= c <= self.cycles]
            if bad:
                raise ValueError(f"recorded cycle {bad[0]} is out of range 1..{self.cycles}")
            object.__setattr__(self, "record", tuple(sorted(set(record))))
        if not is_whole(self.seed, 0) or self.seed > MAX_SEED:
            raise ValueError(f"seed = {self.seed!r}; expected a whole number in 0 .. {MAX_SEED}")
        if not isinstance(self.wear, WearPlan):
            raise TypeError(f"wear: expected a WearPlan, got {type(self.wear).__name__}")
        if self.nthread < 0:
            raise ValueError(f"nthread = {self.nthread!r}; expected >= 0 (0 uses all CPUs)")
        if not isinstance(self.conditions, Conditions):
            raise TypeError(f"conditions: expected a Conditions, got {type(self.conditions).__name__}")
        self._check_fault()
        self._check_together()

    def _check_fault(self) -> None:
        """:attr:`fault`'s checks that need no robot."""
        if self.fault is None:
            return
        if not isinstance(self.fault, Fault):
            raise TypeError(f"fault: expected a Fault, got {type(self.fault).__name__}")
        if self.fault.relative:
            raise ValueError(f"fault {self.fault.to_dict()} is relative growth of the motor friction: friction wear, "
                             "given as wear (WearPlan, --wear AXIS:KIND:PERCENT), whose labels and truth array the "
                             "dataset keeps")
        if self.fault.last_cycle != self.cycles:
            raise ValueError(f"fault last_cycle {self.fault.last_cycle} differs from the run's {self.cycles} cycles")
        if self.back_to_back:
            raise ValueError("a fault grows from cycle to cycle: run the cycles independently (no back_to_back)")

    def _check_together(self) -> None:
        """The values that exclude one another: back to back, a task mix, daily records."""
        if self.back_to_back and (self.wear.schedules or self.conditions.active
                                  or self.record not in (None, tuple(range(1, self.cycles + 1)))):
            raise ValueError("back_to_back runs step every cycle in one simulation without wear or operating "
                             f"conditions; got wear on axes {list(self.wear.schedules)}, conditions "
                             f"{'on' if self.conditions.active else 'off'} and record = {self.record!r}: drop "
                             "them, or run the cycles independently")
        mix = self.conditions.task_mix
        if mix is not None and self.task not in mix.tasks:
            raise ValueError(f"task {self.task!r} is not in the task mix ({', '.join(mix.tasks)}); a run's own task "
                             "must be one of the tasks its cycles run")
        if mix is not None and self.signals:
            raise ValueError(f"a task mix ({', '.join(mix.tasks)}) keeps no signals: cycles of different tasks differ "
                             "in length; record features only (--features-only, signals=False)")
        if self.daily:
            per_day = self.conditions.cycles_per_day
            if self.record is not None or self.signals or self.cycles % per_day:
                raise ValueError(f"daily records need every cycle recorded, no signals and whole days: got record = "
                                 f"{self.record!r}, signals = {self.signals}, {self.cycles} cycles at {per_day} a day")

    def check(self, robot: Robot) -> None:
        """The checks that need the robot (:attr:`model`) and the friction model, looked up here
        (:func:`faultgen.simulation.friction_models.get`): :func:`faultgen.simulation.resolve.resolve`
        calls it before any run starts, :func:`faultgen.simulation.stepping.simulate` before
        stepping a configuration that holds no robot yet (built from a name, or unpickled). Raises ValueError (the friction model unknown, an axis out of range, a fault the
        robot already carries, or one the ``lugre`` model cannot grow; each named)."""
        stepping = friction_models.get(self.friction)
        self.wear.check(robot.n_axes)  # "axis 7 is out of range 1..6"
        if self.fault is not None:
            self.fault.check(robot.n_axes)
            if self.fault.effect in robot.effects and np.any(robot.effects[self.fault.effect].active()):
                raise ValueError(f"{self.robot} already carries {self.fault.effect}; a growing {self.fault.effect} fault "
                                 "needs a robot without it")
            if self.fault.in_plant and not stepping.per_step:
                raise ValueError(f"a growing {self.fault.effect} fault needs the static friction model "
                                 "(friction='stribeck', --friction stribeck): friction growing with the load is "
                                 "updated every step from Python, and the lugre model runs inside MuJoCo")
        spread = self.conditions.spread
        if spread is not None and spread.gear_loss > 0 and not stepping.per_step:
            raise ValueError(f"unit spread gear_loss = {spread.gear_loss!r} needs the static friction model "
                             "(friction='stribeck', --friction stribeck): friction growing with the load is "
                             "updated every step from Python, and the lugre model runs inside MuJoCo")

    @property
    def model(self) -> Robot:
        """The resolved robot (:class:`~faultgen.model.robot.Robot`) the run simulates: the one
        given or resolved on construction; after unpickling in another process, :attr:`robot`
        resolved there once."""
        robot = self.resolved
        if robot is None:
            robot = robots.load(self.robot)
            object.__setattr__(self, "resolved", robot)
        return robot

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        if self.resolved is not None and self.resolved.digest is not None:
            state["resolved"] = None  # a worker resolves the robot from its own files, once
        return state  # a robot edited in memory travels with the configuration (as its MJCF text)

    @property
    def faults(self) -> tuple[Fault, ...]:
        """Every fault of the run: friction wear (:meth:`WearPlan.faults`, relative) and :attr:`fault`."""
        return self.wear.faults() + (() if self.fault is None else (self.fault,))

    @property
    def recorded_cycles(self) -> np.ndarray:
        """Indices of the simulated cycles, ``ndarray of shape (n_recorded,)``."""
        if self.record is None:
            return np.arange(1, self.cycles + 1)
        return np.array(self.record)
