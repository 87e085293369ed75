"""Operating conditions over the cycles of a run: joint temperature, payload, task mix, unit-to-unit spread.

On real robots friction and torque move with the joints' temperature and the load as much as
with wear (Bittencourt & Gunnarsson 2012; thesis ch. 5.3 and ref. [103]), and no two units of a
type are alike. A dataset whose runs differ only by wear flatters every detector and isolator;
these conditions dial realism in. Like wear (:mod:`faultgen.operation.wear`) they are schedules
over a run's cycles, evaluated for the recorded ones (:meth:`Conditions.evaluate`) and written to
the dataset as truth, per cycle.

**The robot's calendar.** Recorded cycle ``k`` (1-based) runs on day ``(k - 1) // cycles_per_day``
of the run, counted from ``start_day`` (day of the year of cycle 1), at a time of day drawn
uniformly within the production hours from the run's seed, or at fixed ``hours`` (a controller
that collects its data on a schedule, at the same time every day: thesis ch. 5.3.2): a 100-cycle
run with one cycle a day spans 100 days of the robot's life, which is what a wear schedule over
100 cycles stands for.

**Joint temperature** (:class:`Temperature`): the ambient air of the hall, a seasonal and a
daily cosine around a mean, plus the heat of running: a joint that starts cold at the start of
a shift approaches ``rise`` above ambient with the joint's thermal time constant,
``T = T_amb + rise (1 - exp(-s / tau))``, ``s`` the time since the shift started (a stop between
shifts is long against ``tau``, so a shift starts at ambient). Friction follows the joint
temperature through :func:`faultgen.effects.temperature.friction_factors` (the oil's viscosity,
ASTM D341; Petroff's law for the viscous part).

**Payload** (:class:`Payloads`): the part the robot carries in a cycle, one of a set, chosen by a
pattern (alternating, in blocks, or at random); each part a uniform cube hanging from the flange
(:class:`faultgen.effects.payload.Payload`). The controller knows the part (the load data an
industrial program sets before each move), so its feedforward carries it.

**Task mix** (:class:`TaskMix`): the program a cycle runs, one of a set of tasks, chosen by the same
patterns, as a robot that welds one product and handles another (the thesis's fleet spanned
several processes, ch. 5.3.1). Each cycle runs its task's own path and feedforward; cycles of
different tasks differ in length, so a run with a task mix keeps features and truth only.

**Unit-to-unit spread** (:class:`UnitSpread`): the run's robot draws its own friction levels
(Coulomb and static, viscous; per axis, log-normal), link masses (per link, normal) and, when asked
for, a gearbox loss growing with the load (per axis, uniform; the shared
:class:`faultgen.effects.load_dependent_friction.LoadDependentFriction`) around the nominal model,
from the run's seed; the controller keeps the nominal model.

The numbers of the defaults are ours and stated as such in the attribute docs: no published
plant record of joint temperatures or unit spread was at hand (docs/simulation.md).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from typing import ClassVar

import numpy as np

from faultgen.checks import is_number, is_whole
from faultgen.effects import temperature as temperature_law
from faultgen.operation import programs
from faultgen.operation.tasks import TASKS

#: Seconds in a day.
DAY = 86400.0
#: Random streams of the conditions (the sensors use 0 and 1 per cycle).
_TIME_OF_DAY, _PAYLOAD, _UNIT, _TASK = 10, 11, 12, 13
#: How a set of choices (payloads, tasks) is scheduled over the cycles.
PATTERNS = ("alternate", "blocks", "random")


def check_number(name: str, value, low: float = -math.inf, high: float = math.inf, whole: bool = False) -> float | int:
    """``value`` as a float (an int when ``whole``), or ValueError naming ``name``, the value and
    the range when it is not a finite number (whole number) within ``low..high``."""
    ok = is_whole(value) and low <= value <= high if whole else is_number(value, low, high)
    if not ok:
        kind = "a whole number" if whole else "a number"
        raise ValueError(f"{name} = {value!r}: expected {kind} within {low:g}..{high:g}")
    return int(value) if whole else float(value)


def _check_pattern(pattern: str, block, pattern_name: str, block_name: str) -> None:
    """Refuse an unknown ``pattern`` or a ``block`` that is not a whole number >= 1; the message
    names the setting (``pattern_name``, ``block_name``) and the value."""
    if pattern not in PATTERNS:
        raise ValueError(f"{pattern_name} {pattern!r}: expected one of {', '.join(PATTERNS)}")
    if not is_whole(block, 1):
        raise ValueError(f"{block_name} = {block!r}: expected a whole number of cycles >= 1")


def _schedule(pattern: str, block: int, n: int, seed: int, cycles: np.ndarray, stream: int) -> np.ndarray:
    """The choice (0..n-1) of each of ``cycles`` (1-based): in turn (``alternate``), ``block``
    cycles each in turn (``blocks``), or drawn with equal odds from (seed, cycle, stream) (``random``)."""
    k = np.asarray(cycles) - 1
    if pattern == "alternate":
        return k % n
    if pattern == "blocks":
        return (k // block) % n
    return np.array([np.random.default_rng([seed, int(c), stream]).integers(n) for c in cycles], dtype=int)


@dataclass(frozen=True)
class Temperature:
    """Joint temperature over the robot's calendar (module docstring); deg C, K, h, s.

    Attributes
    ----------
    ambient : float
        Yearly mean air temperature of the hall, deg C (default 20: a heated factory hall).
    seasonal : float
        Amplitude of the seasonal cosine, K, warmest on ``warmest_day`` (default 5 K, day 200).
    daily : float
        Amplitude of the daily cosine, K, warmest at 15:00 (default 2 K).
    rise : float
        Joint temperature above ambient after a long time running, K (default 15: the nominal
        friction holds at 20 + 15 deg C, :data:`faultgen.effects.temperature.REFERENCE_TEMPERATURE`).
    time_constant : float
        Thermal time constant of a joint, s (default 3600).
    shift : tuple of float
        Production hours, start and end, h (default 6 to 22: two shifts).
    warmest_day : float
        Day of the year of the seasonal maximum (default 200, mid-July in the northern hemisphere).
    dry_share : float
        Exponent of the oil viscosity's ratio that the dry friction follows, 0..1
        (:func:`faultgen.effects.temperature.friction_factors`; default
        :data:`faultgen.effects.temperature.DRY_SHARE`, 0.25, chosen, not measured; 0: only the
        viscous friction moves with temperature).

    Raises
    ------
    ValueError
        On construction, for a value outside its range; the message names it.
    """

    ambient: float = 20.0
    seasonal: float = 5.0
    daily: float = 2.0
    rise: float = 15.0
    time_constant: float = 3600.0
    shift: tuple[float, float] = (6.0, 22.0)
    warmest_day: float = 200.0
    dry_share: float = temperature_law.DRY_SHARE

    def __post_init__(self) -> None:
        check_number("ambient", self.ambient, -20, 60)
        check_number("seasonal", self.seasonal, 0, 30)
        check_number("daily", self.daily, 0, 15)
        check_number("rise", self.rise, 0, 60)
        check_number("time_constant", self.time_constant, 60, 10 * DAY)
        check_number("warmest_day", self.warmest_day, 0, 366)
        object.__setattr__(self, "dry_share", check_number("thermal dry_share", self.dry_share, 0, 1))
        if len(self.shift) != 2:
            raise ValueError(f"shift = {self.shift!r}: expected (start, end) in hours")
        start, end = (check_number("shift hour", h, 0, 24) for h in self.shift)
        if not start < end:
            raise ValueError(f"shift = {self.shift!r}: the start must come before the end")
        object.__setattr__(self, "shift", (start, end))

    def ambient_at(self, day: np.ndarray, hour: np.ndarray) -> np.ndarray:
        """Air temperature, deg C, on day of the year ``day`` at ``hour`` (arrays of one shape)."""
        season = np.cos(2 * np.pi * (np.asarray(day) - self.warmest_day) / 365.0)
        daily = np.cos(2 * np.pi * (np.asarray(hour) - 15.0) / 24.0)
        return self.ambient + self.seasonal * season + self.daily * daily

    def joint_at(self, day: np.ndarray, hour: np.ndarray) -> np.ndarray:
        """Joint temperature, deg C, at ``hour`` of ``day`` within a shift (module docstring)."""
        running = (np.asarray(hour) - self.shift[0]) * 3600.0
        return self.ambient_at(day, hour) + self.rise * (1 - np.exp(-running / self.time_constant))


@dataclass(frozen=True)
class Payloads:
    """The parts a robot carries, one per cycle.

    Attributes
    ----------
    masses : tuple of float
        Mass of each part, kg (>= 0; 0 is an empty gripper).
    sizes : tuple of float
        Edge of each part, m: a uniform cube whose centre hangs ``size / 2`` below the flange
        (along its z axis), inertia ``m size^2 / 6`` about each axis; one per mass.
    pattern : str
        ``alternate`` (parts in turn), ``blocks`` (``block`` cycles of each in turn) or ``random``
        (each cycle a part drawn with equal odds from the run's seed).
    block : int
        Cycles per block of the ``blocks`` pattern.

    Raises
    ------
    ValueError
        On construction, for an empty set, masses and sizes of different lengths, a negative or
        non-finite value, an unknown pattern or a block < 1.
    """

    masses: tuple[float, ...]
    sizes: tuple[float, ...]
    pattern: str = "alternate"
    block: int = 10

    def __post_init__(self) -> None:
        masses = tuple(check_number("payload mass", m, 0, 1000) for m in self.masses)
        sizes = tuple(check_number("payload size", s, 0, 1.0) for s in self.sizes)
        if not masses or len(masses) != len(sizes):
            raise ValueError(f"payloads: {len(masses)} masses and {len(sizes)} sizes; expected one size per mass, "
                             "at least one part")
        _check_pattern(self.pattern, self.block, "payload pattern", "payload block")
        object.__setattr__(self, "masses", masses)
        object.__setattr__(self, "sizes", sizes)

    def index(self, seed: int, cycles: np.ndarray) -> np.ndarray:
        """The part carried in each of ``cycles`` (1-based), indices into :attr:`masses`."""
        return _schedule(self.pattern, self.block, len(self.masses), seed, cycles, _PAYLOAD)

    def parameters(self, part: int) -> dict[str, float]:
        """The :class:`faultgen.effects.payload.Payload` parameters of part ``part``."""
        mass, size = self.masses[part], self.sizes[part]
        moment = mass * size**2 / 6
        return {"mass": mass, "com_x": 0.0, "com_y": 0.0, "com_z": size / 2,
                "ixx": moment, "iyy": moment, "izz": moment, "ixy": 0.0, "ixz": 0.0, "iyz": 0.0}


@dataclass(frozen=True)
class TaskMix:
    """The tasks a robot runs, one per cycle (module docstring).

    Attributes
    ----------
    tasks : tuple of str
        Tasks of :data:`faultgen.operation.tasks.TASKS` or program / joint log files
        (:func:`faultgen.operation.programs.load`); the run's own task must be one of them.
        A task may be listed more than once to run it more often.
    pattern, block : str, int
        How the tasks take turns, as the parts of :class:`Payloads` do.

    Raises
    ------
    ValueError
        On construction, for no task, an unknown task, an unknown pattern or a block < 1.
    """

    tasks: tuple[str, ...]
    pattern: str = "alternate"
    block: int = 10

    def __post_init__(self) -> None:
        tasks = tuple(self.tasks) if not isinstance(self.tasks, str) else (self.tasks,)
        if not tasks:
            raise ValueError("task mix: no task given; expected one or more of " + ", ".join(TASKS))
        for task in tasks:
            try:
                programs.check_name(task)  # a thesis task, or a program / joint log file
            except ValueError as err:
                raise ValueError(f"task mix: {err}") from None
        _check_pattern(self.pattern, self.block, "task mix pattern", "task mix block")
        object.__setattr__(self, "tasks", tasks)

    def index(self, seed: int, cycles: np.ndarray) -> np.ndarray:
        """The task run in each of ``cycles`` (1-based), indices into :attr:`tasks`."""
        return _schedule(self.pattern, self.block, len(self.tasks), seed, cycles, _TASK)


@dataclass(frozen=True)
class UnitSpread:
    """How far a unit's robot is from the nominal model; relative standard deviations.

    Attributes
    ----------
    dry_friction : float
        Of the Coulomb and static levels per axis (log-normal, one draw per axis for both; default
        0.15).
    viscous_friction : float
        Of the viscous coefficient per axis (log-normal; default 0.15).
    link_mass : float
        Of each link's mass and inertia (normal, clipped at 3 standard deviations; default 0.02,
        a casting tolerance).
    gear_loss : float
        Largest load-dependent friction coefficient a unit's gearbox adds per axis, drawn uniformly
        in 0..``gear_loss`` (dimensionless: the share of the transmitted torque lost as Coulomb
        friction, 1 minus the gearbox's efficiency under load; the transmitted-load form of
        :class:`~faultgen.effects.load_dependent_friction.LoadDependentFriction`, added to the
        model's own). Default 0: off. A per-step update, so only the static friction model
        (``friction="stribeck"``) carries it.

    The defaults are ours, not a published spread: a unit's friction within about +-30 % of the
    type's (two standard deviations).

    Raises
    ------
    ValueError
        On construction, for a value outside 0..0.5.
    """

    dry_friction: float = 0.15
    viscous_friction: float = 0.15
    link_mass: float = 0.02
    gear_loss: float = 0.0

    def __post_init__(self) -> None:
        for name in ("dry_friction", "viscous_friction", "link_mass", "gear_loss"):
            check_number(f"unit spread {name}", getattr(self, name), 0, 0.5)

    def draw(self, seed: int, n_axes: int) -> dict[str, np.ndarray]:
        """The unit's draws, from ``seed``, each ``ndarray of shape (N,)`` (axis / link 1..N of a
        robot of ``n_axes`` = N axes; a six-axis robot's draws are those it always had): the
        multipliers ``dry_friction``, ``viscous_friction``, ``link_mass`` (> 0) and the load-dependent
        friction coefficient ``gear_loss`` (0..:attr:`gear_loss`, drawn last, so that the other
        draws of a seed do not depend on it)."""
        rng = np.random.default_rng([seed, 0, _UNIT])
        normal = rng.standard_normal((3, n_axes))
        return {"dry_friction": np.exp(self.dry_friction * normal[0] - self.dry_friction**2 / 2),
                "viscous_friction": np.exp(self.viscous_friction * normal[1] - self.viscous_friction**2 / 2),
                "link_mass": 1 + self.link_mass * np.clip(normal[2], -3, 3),
                "gear_loss": self.gear_loss * rng.random(n_axes)}


@dataclass(frozen=True)
class CycleConditions:
    """The conditions at each recorded cycle of a run (truth, written to the dataset).

    Attributes
    ----------
    day : ndarray of shape (n,)
        Day of the year (may pass 365 on long runs), d.
    hour : ndarray of shape (n,)
        Time of day, h.
    ambient_temperature : ndarray of shape (n,)
        deg C.
    joint_temperature : ndarray of shape (n, N)
        deg C.
    dry_friction_factor, viscous_factor : ndarray of shape (n, N)
        Multipliers of the Coulomb and static, and of the viscous friction, from temperature and
        unit spread (wear not included).
    payload_part : ndarray of shape (n,)
        Index of the part carried (-1: none scheduled).
    payload_mass : ndarray of shape (n,)
        kg.
    link_mass_factor : ndarray of shape (N,)
        Multiplier of each link's mass and inertia (the unit's).
    task_index : ndarray of shape (n,)
        Index of the task the cycle ran, into the task mix's tasks (-1: no mix, the run's task).
    gear_loss : ndarray of shape (N,)
        Load-dependent friction coefficient the unit's gearbox adds per axis (:attr:`UnitSpread.gear_loss`;
        zeros without).
    """

    day: np.ndarray
    hour: np.ndarray
    ambient_temperature: np.ndarray
    joint_temperature: np.ndarray
    dry_friction_factor: np.ndarray
    viscous_factor: np.ndarray
    payload_part: np.ndarray
    payload_mass: np.ndarray
    link_mass_factor: np.ndarray
    task_index: np.ndarray
    gear_loss: np.ndarray

    #: The fields that hold the unit's values, one per axis or link (the others: one row per cycle).
    PER_UNIT: ClassVar[tuple[str, ...]] = ("link_mass_factor", "gear_loss")

    def tasks(self, mix: TaskMix) -> np.ndarray:
        """The task name of each cycle under the task mix ``mix`` that scheduled them,
        ``ndarray of shape (n,)`` of str."""
        return np.array(mix.tasks, dtype=object)[self.task_index]


@dataclass(frozen=True)
class Conditions:
    """The operating conditions of a run; all off by default (the run differs from its reference
    only by wear).

    Attributes
    ----------
    thermal : Temperature or None
        Joint temperature (the CLI's ``--temperature``).
    payloads : Payloads or None
    spread : UnitSpread or None
    task_mix : TaskMix or None
        The task of each cycle (the CLI's ``--task-mix``); None: every cycle runs the run's task.
    cycles_per_day : int
        Recorded-cycle index to calendar day (module docstring); >= 1.
    start_day : float
        Day of the year of cycle 1, 0..365.
    hours : tuple of float, optional
        Time of day (h) of each of a day's ``cycles_per_day`` cycles, in order; default: each
        drawn uniformly within the production hours.

    Raises
    ------
    ValueError
        On construction, for ``cycles_per_day`` < 1, ``start_day`` outside 0..365, or ``hours``
        that are not ``cycles_per_day`` times within 0..24.
    TypeError
        For a condition of the wrong type.
    """

    thermal: Temperature | None = None
    payloads: Payloads | None = None
    spread: UnitSpread | None = None
    task_mix: TaskMix | None = None
    cycles_per_day: int = 1
    start_day: float = 0.0
    hours: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        for name, kind in (("thermal", Temperature), ("payloads", Payloads), ("spread", UnitSpread),
                           ("task_mix", TaskMix)):
            value = getattr(self, name)
            if value is not None and not isinstance(value, kind):
                raise TypeError(f"conditions {name}: expected a {kind.__name__} or None, got {type(value).__name__}")
        if not is_whole(self.cycles_per_day, 1):
            raise ValueError(f"cycles_per_day = {self.cycles_per_day!r}: expected a whole number >= 1")
        check_number("start_day", self.start_day, 0, 365)
        if self.hours is not None:
            hours = tuple(check_number("hour", h, 0, 24) for h in self.hours)
            if len(hours) != self.cycles_per_day:
                raise ValueError(f"hours = {self.hours!r}: expected {self.cycles_per_day} (cycles_per_day) times of day")
            object.__setattr__(self, "hours", hours)

    @property
    def active(self) -> bool:
        """Whether any condition is on."""
        return any(c is not None for c in (self.thermal, self.payloads, self.spread, self.task_mix))

    def evaluate(self, seed: int, cycles: np.ndarray, n_axes: int) -> CycleConditions:
        """The conditions at ``cycles`` (1-based recorded cycle indices, shape (n,)) of a run with
        ``seed`` on a robot of ``n_axes`` axes: bit-identical for the same seed and cycles, whichever
        other cycles are recorded."""
        cycles = np.asarray(cycles, dtype=int)
        n = len(cycles)
        day = self.start_day + (cycles - 1) // self.cycles_per_day
        start, end = (self.thermal or Temperature()).shift
        if self.hours is not None:
            hour = np.array(self.hours)[(cycles - 1) % self.cycles_per_day]
        else:
            hour = np.array([start + (end - start) * np.random.default_rng([seed, int(c), _TIME_OF_DAY]).random()
                             for c in cycles])
        ambient = np.full(n, np.nan)
        joint = np.full((n, n_axes), np.nan)
        dry, viscous = np.ones((n, n_axes)), np.ones((n, n_axes))
        if self.thermal is not None:
            ambient = self.thermal.ambient_at(day, hour)
            joint = np.repeat(self.thermal.joint_at(day, hour)[:, None], n_axes, axis=1)
            dry, viscous = temperature_law.friction_factors(joint, self.thermal.dry_share)
        link_mass, gear_loss = np.ones(n_axes), np.zeros(n_axes)
        if self.spread is not None:
            unit = self.spread.draw(seed, n_axes)
            dry, viscous, link_mass = dry * unit["dry_friction"], viscous * unit["viscous_friction"], unit["link_mass"]
            gear_loss = unit["gear_loss"]
        part, mass = np.full(n, -1), np.zeros(n)
        if self.payloads is not None:
            part = self.payloads.index(seed, cycles)
            mass = np.array(self.payloads.masses)[part]
        task = self.task_mix.index(seed, cycles) if self.task_mix is not None else np.full(n, -1)
        return CycleConditions(day=day.astype(float), hour=hour, ambient_temperature=ambient, joint_temperature=joint,
                               dry_friction_factor=dry, viscous_factor=viscous, payload_part=part, payload_mass=mass,
                               link_mass_factor=link_mass, task_index=task, gear_loss=gear_loss)

    def to_dict(self) -> dict:
        """JSON-serialisable labels (None for a condition that is off; no ``task_mix`` key without
        one, no spread ``gear_loss`` when it is 0 and no thermal ``dry_share`` at its default, so
        runs keep the labels and keys they had before these existed)."""
        table = asdict(self)
        if self.task_mix is None:
            del table["task_mix"]
        if self.spread is not None and self.spread.gear_loss == 0:
            del table["spread"]["gear_loss"]
        if self.thermal is not None and self.thermal.dry_share == temperature_law.DRY_SHARE:
            del table["thermal"]["dry_share"]
        return table

    def to_table(self) -> dict:
        """The short table :meth:`from_dict` reads back into these conditions, as a grid file writes
        it (and a sweep's dataset keeps its grid): each condition that is on, with its parts, tasks
        and pattern and the settings not at their defaults; ``cycles_per_day`` and ``start_day``;
        ``hours`` when set."""
        table: dict = {}
        for name in ("thermal", "payloads", "spread", "task_mix"):
            value = getattr(self, name)
            if value is not None:
                table[name] = {f.name: _plain(getattr(value, f.name)) for f in fields(value)
                               if f.name in ("masses", "sizes", "tasks", "pattern")
                               or getattr(value, f.name) != f.default}
        table.update(cycles_per_day=self.cycles_per_day, start_day=self.start_day)
        if self.hours is not None:
            table["hours"] = list(self.hours)
        return table

    @classmethod
    def from_dict(cls, data: dict) -> Conditions:
        """Inverse of :meth:`to_dict`; unknown keys are refused with their name."""
        known = {"thermal": Temperature, "payloads": Payloads, "spread": UnitSpread, "task_mix": TaskMix}
        plain = ("cycles_per_day", "start_day", "hours")
        unknown = sorted(set(data) - set(known) - set(plain))
        if unknown:
            raise ValueError(f"conditions: unknown key {unknown[0]!r}; expected: {', '.join([*known, *plain])}")
        parts = {}
        for name, kind in known.items():
            value = data.get(name)
            if value is not None:
                if not isinstance(value, dict):
                    raise ValueError(f"conditions {name}: expected a table of settings, got {value!r}")
                names = set(kind.__dataclass_fields__)
                bad = sorted(set(value) - names)
                if bad:
                    raise ValueError(f"conditions {name}: unknown setting {bad[0]!r}; expected: {', '.join(sorted(names))}")
                value = {k: tuple(v) if isinstance(v, list) else v for k, v in value.items()}
                parts[name] = kind(**value)
        rest = {k: tuple(data[k]) if isinstance(data[k], list) else data[k] for k in plain if data.get(k) is not None}
        return cls(**parts, **rest)


def _plain(value):
    """A setting as a table holds it: a tuple as a list."""
    return list(value) if isinstance(value, tuple) else value
