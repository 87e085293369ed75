"""The template every physical effect follows, the registry, and the motion effects are fitted on.

An effect is one class (:class:`Effect`) registered under its stable id (:func:`register`, the
pattern of :mod:`analysis.isolation`). An instance holds the effect's **absolute** parameters on
the six axes (or, robot-wide, once), in SI units, under one name each: the same names in the
MJCF, in ``report.json``, in ``parameters.json`` and in ``Effect.units``. The class knows

* how it is stored in a robot's MJCF (:meth:`Effect.read` from a compiled ``MjModel``,
  :meth:`Effect.apply` into an ``MjSpec``),
* its drive torque along a motion (:meth:`Effect.torque`, the robot's inverse dynamics add it;
  :meth:`Effect.arm_offset` for an effect that moves the arm against the motor),
* how it acts in the simulation (:meth:`Effect.add_to_simulation`: MuJoCo elements; or a
  per-step update of the rotors' dry friction, :meth:`Effect.dry_friction_factor` and
  :meth:`Effect.dry_friction_extra`),
* its regressors for identification (:meth:`Effect.columns`, :meth:`Effect.grid`, or its own
  :meth:`Effect.search`) and how fitted values become its parameters (:meth:`Effect.params`),
* how a hidden effect of it is drawn for the calibration's own checks (:attr:`Effect.signed`,
  :meth:`Effect.draw_direction`, :attr:`Effect.draw_limits`, :attr:`Effect.draw_range`,
  :meth:`Effect.motor_torque`).

Code outside :mod:`faultgen.effects` never branches on an effect's id: it calls these methods.
docs/architecture.md walks through adding an effect.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import mujoco
import numpy as np

from faultgen import axes as axis_numbers

#: Arm-side speed (rad/s) below which an axis counts as at rest: its friction is then stiction,
#: any value up to the breakaway torque, which no kinetic model predicts, so those samples of
#: that axis are neither fitted nor scored (:class:`faultgen.calibrate.search.Split`).
REST_SPEED = 0.05


class ModelError(ValueError):
    """Raised when an MJCF file cannot be compiled or lacks the elements a robot needs.

    The message names the file and, where MuJoCo reports one, the line.
    (:class:`faultgen.model.robots.ModelError` is this class.)
    """


@dataclass(frozen=True)
class Motion:
    """A motion and what the current model says about it; every array ``(n, N)``.

    Attributes
    ----------
    robot : faultgen.model.robots.Robot
        The current model (nominal, or with the effects added so far).
    t : ndarray of shape (n,)
        Time since the first sample, s.
    q, qd, qdd : ndarray of shape (n, N)
        Arm-side angles (rad), velocities (rad/s), accelerations (rad/s^2).
    load : ndarray of shape (n, N)
        Arm-side gearbox load: the rigid-body torque of the arm joints without motor inertia
        and friction, the arm at the motor angle, N m.
    compliance : callable, optional
        The flexible gearbox's torque along the motion,
        ``compliance(robot, t, q, load, widths=None) -> (n, N)`` or ``(m, n, N)`` for dead-band
        widths ``(m, N)`` (:func:`faultgen.calibrate.gearbox.compliance_torque`); needed by the
        effects that change the gearbox (backlash).
    """

    robot: Any
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    load: np.ndarray
    compliance: Callable | None = field(default=None, compare=False, repr=False)
    #: Results an effect computes once per motion for all its grid values (backlash).
    memo: dict = field(default_factory=dict, compare=False, repr=False)

    @classmethod
    def of(cls, robot, t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
           compliance: Callable | None = None) -> Motion:
        """Evaluate ``robot``'s rigid-body load along a motion
        (:meth:`faultgen.model.robots.Robot.gearbox_load`); time counts from the first sample."""
        return cls(robot, np.asarray(t, dtype=float) - float(t[0]), q, qd, qdd, robot.gearbox_load(q, qd, qdd),
                   compliance)

    @property
    def static_load(self) -> np.ndarray:
        """Arm-side torque that holds the arm still at ``q``, N m, shape (n, N): gravity and joint
        springs (:meth:`faultgen.model.robots.Robot.static_load`), computed once per motion."""
        if "static_load" not in self.memo:
            self.memo["static_load"] = self.robot.static_load(self.q)
        return self.memo["static_load"]

    @property
    def motor_velocity(self) -> np.ndarray:
        """Motor-side velocity ``G qd`` in rad/s, shape (n, N)."""
        return self.robot.gear_ratio * self.qd


#: Every registered effect, by id, by :attr:`Effect.rank`: what a robot's MJCF is read into
#: (:func:`read_all`), :func:`get` and :func:`make` know and a fault may grow.
REGISTRY: dict[str, Effect] = {}

#: The calibration's candidates (:attr:`Effect.candidate`), by id, in the order they are tried in
#: identification (ties go to the earlier, simpler one): by :attr:`Effect.rank`. The robot's nominal
#: motor friction (``motor_friction``) is registered but no candidate: the calibration changes parts of it.
EFFECTS: dict[str, Effect] = {}


def register(cls: type[Effect]) -> type[Effect]:
    """Class decorator adding an effect class to :data:`REGISTRY` (and, when a calibration
    :attr:`~Effect.candidate`, to :data:`EFFECTS`) as an instance with the values of an absent
    effect, under its ``id``.

    Raises
    ------
    ValueError
        If the id is already registered to another class.
    """
    if cls.id in REGISTRY and type(REGISTRY[cls.id]) is not cls:
        raise ValueError(f"effect {cls.id!r} is already registered to {type(REGISTRY[cls.id]).__name__}")
    REGISTRY[cls.id] = cls()
    ordered = sorted(REGISTRY.items(), key=lambda item: (item[1].rank, item[0]))
    REGISTRY.clear()
    REGISTRY.update(ordered)
    EFFECTS.clear()
    EFFECTS.update((k, e) for k, e in ordered if e.candidate)
    return cls


def get(effect_id: str) -> Effect:
    """The registered effect ``effect_id`` (absent values); raises ``ValueError`` listing the known ids."""
    try:
        return REGISTRY[effect_id]
    except KeyError:
        raise ValueError(f"unknown effect {effect_id!r}; known effects: {', '.join(REGISTRY)}") from None


def make(effect_id: str, **values) -> Effect:
    """A new effect ``effect_id`` with the given parameters (each a number for all axes or one
    value per axis; missing ones at their absent value).

    Raises
    ------
    ValueError
        For an unknown id (the message lists the known ones) or parameter name, or a value of
        the wrong shape.
    """
    return type(get(effect_id))(**values)


def read_all(model: mujoco.MjModel, path: Path) -> dict[str, Effect]:
    """Every effect stored in its own MJCF elements (absent ones at their absent values), by id.

    Raises
    ------
    ModelError
        If an effect's element holds values it cannot take (wrong count, non-finite, out of range).
    """
    found = {}
    for effect_id, prototype in REGISTRY.items():
        effect = type(prototype).read(model, path)
        if effect is not None:
            found[effect_id] = effect
    return found


class Effect:
    """One physical effect with its parameters. Subclasses set the class attributes and override
    what applies to them; the defaults describe an effect that does nothing there.

    Parameters
    ----------
    n_axes : int, optional
        The robot's number of axes N, for a per-axis effect given no value per axis (without it,
        the length of the values given per axis; with neither, the effect holds one value for all
        axes of any robot, as the registry's prototypes do).
    **values : float or array_like of shape (N,)
        Parameters by name (:attr:`units`), one value for all axes or one per axis; a robot-wide
        effect takes one value each. Missing ones take their :attr:`absent` value.

    Raises
    ------
    ValueError
        For an unknown parameter name or a value of the wrong shape or non-finite.

    Each parameter is a read-only attribute of that name (``effect.offset``, ndarray of shape (N,),
    or a 0-d array when robot-wide or made with one value for all axes and no ``n_axes``; such an
    effect gives that value for every axis in :meth:`values` and :meth:`write`, and is sized by the
    robot where it meets one: :meth:`current`, :meth:`fitted`); :meth:`values` and :meth:`table`
    give plain numbers.

    Attributes
    ----------
    id : str
        Stable effect id used in ``report.json``.
    rank : int
        Place in the calibration's search order (:data:`EFFECTS`; ties go to the lower rank: the
        simpler effect, with fewer parameters).
    summary : str
        One line: the physics, for ``--help`` and the report.
    units : dict
        Parameter name -> SI unit (and the side it is measured at), in the order of the values
        in the effect's MJCF numeric.
    absent : tuple of float
        Parameter values of an absent effect, in the order of :attr:`units`.
    per_axis : bool
        True when the effect has its own parameters on each axis; False for a robot-wide
        effect (payload), fitted on all axes at once.
    n_parameters : int
        Linear parameters per axis (per robot when not ``per_axis``), for the report.
    continuous : bool
        True when the grid samples a continuous parameter, refined by a bounded scalar search.
    stepped : bool
        True when the simulation realises the effect by a per-step update of the rotors' dry
        friction from Python, which only the static friction model (``--friction stribeck``) has.
    plant_fault : bool
        True for a stepped effect that can still grow as a fault: linear in one coefficient, the
        simulation carries that coefficient per cycle in the plant (load-dependent friction, beside
        the unit's gear loss; :attr:`faultgen.operation.faults.Fault.in_plant`).
    numeric, aliases : str
        Name ``<numeric>{i}`` of the effect's MJCF custom numeric on axis i (None when it is
        stored otherwise), and earlier names still read.
    """

    id: ClassVar[str]
    rank: ClassVar[int] = 100
    #: Whether the calibration tries the effect as an explanation of a misfit (:data:`EFFECTS`);
    #: False for the robot's nominal motor friction, which every robot carries.
    candidate: ClassVar[bool] = True
    summary: ClassVar[str]
    units: ClassVar[dict[str, str]]
    absent: ClassVar[tuple[float, ...]]
    per_axis: ClassVar[bool] = True
    n_parameters: ClassVar[int] = 1
    continuous: ClassVar[bool] = False
    stepped: ClassVar[bool] = False
    plant_fault: ClassVar[bool] = False
    numeric: ClassVar[str | None] = None
    aliases: ClassVar[tuple[str, ...]] = ()
    #: Leading values a stored numeric must hold (the rest read as absent: a parameter added
    #: later); None: all of them.
    required: ClassVar[int | None] = None
    #: Parameters that are whole numbers (a pole count): given as int wherever they are reported.
    counts: ClassVar[tuple[str, ...]] = ()
    #: Named groups of parameters a relative fault scales together (:class:`faultgen.operation.faults.Fault`,
    #: friction wear: the motor friction's ``dry``); none by default.
    groups: ClassVar[dict[str, tuple[str, ...]]] = {}
    #: Numbers of leading linear parameters (columns) fitted at each level of detail, simplest first
    #: (the optimiser keeps the most detailed admissible level the Bayesian information criterion
    #: supports, per axis for a per-axis effect); None: all at once.
    levels: ClassVar[tuple[int, ...] | None] = None
    #: What motion tells this effect apart from the others (the calibration's report says it when
    #: a log cannot, :func:`faultgen.calibrate.search.compare`).
    excited_by: ClassVar[str] = ""
    #: Whether the excitation design (:mod:`faultgen.calibrate.excitation`) separates this effect
    #: by the motion's shape: False for one told apart by the log's length (a warm-up) or whose
    #: regressors need the motor angle or gearbox state at the log's rate (cogging, backlash).
    designable: ClassVar[bool] = True
    #: Hidden-effect drawing (:mod:`faultgen.calibrate.synth`): may the drawn effect be negative.
    signed: ClassVar[bool] = False
    #: Hidden-effect drawing: largest value of a parameter; a drawn effect past it is shrunk to it.
    draw_limits: ClassVar[dict[str, float]] = {}
    #: Hidden-effect drawing by a parameter range instead of a torque size, for an effect not
    #: linear in its parameter: (parameter, low, high, smallest size, smallest size on a robot
    #: where no axis reaches it); None: drawn by size.
    draw_range: ClassVar[tuple[str, float, float, float, float] | None] = None
    #: Whether the simulation model's fields are affine in each parameter (its MJCF form and
    #: :meth:`add_to_simulation` linear in it): a growing fault of it is then read from two compiled
    #: models, not three (:func:`faultgen.simulation.prepare._affine_fields`); tests/test_compile_count.py
    #: checks every effect that says so. False: checked at a third value on every run.
    affine_mjcf: ClassVar[bool] = False

    def __init__(self, *, n_axes: int | None = None, **values) -> None:
        unknown = set(values) - set(self.units)
        if unknown:
            raise ValueError(f"{self.id}: unknown parameter {min(unknown)!r}; expected {', '.join(self.units)}")
        if self.per_axis and n_axes is None:  # the axes of the first value given per axis, if any
            n_axes = next((np.shape(v)[0] for v in values.values() if np.ndim(v) == 1), None)
        shape = (n_axes,) if self.per_axis and n_axes is not None else ()
        table = {}
        for k, name in enumerate(self.units):
            value = np.asarray(values.get(name, self.absent[k]), dtype=float)
            try:
                value = np.broadcast_to(value, shape).copy()
            except ValueError:
                raise ValueError(f"{self.id}: parameter {name!r} has shape {value.shape}; expected one value"
                                 + (f" or {n_axes}, one per axis" if self.per_axis else "")) from None
            if not np.all(np.isfinite(value)):
                raise ValueError(f"{self.id}: parameter {name!r} holds a non-finite value")
            value.setflags(write=False)  # an instance is a value: a change makes a new one (fitted)
            table[name] = value
        self._values = table

    def __getattr__(self, name: str) -> np.ndarray:
        values = self.__dict__.get("_values", {})
        if name in values:
            return values[name]
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def __repr__(self) -> str:
        values = ", ".join(f"{k}={v.tolist()}" for k, v in self._values.items())
        return f"{type(self).__name__}({values})"

    def __eq__(self, other: object) -> bool:
        """Same effect with the same parameters (an instance is a value)."""
        if type(other) is not type(self):
            return NotImplemented
        return all(np.array_equal(v, other._values[k]) for k, v in self._values.items())

    __hash__ = None  # equal by value, and its arrays are not hashed

    # -- parameters -------------------------------------------------------------------------

    def values(self, axis: int | None = None) -> dict[str, float]:
        """Parameters of ``axis`` (0-based; None for a robot-wide effect) as plain numbers (int for
        the :attr:`counts`)."""
        return {k: self._plain(k, v if axis is None or v.ndim == 0 else v[axis]) for k, v in self._values.items()}

    def table(self) -> dict[str, list[float] | float]:
        """All parameters as plain lists over axes 1..N (one number when robot-wide), ``parameters.json``."""
        return {k: [self._plain(k, x) for x in v] if v.ndim else self._plain(k, v) for k, v in self._values.items()}

    def _plain(self, name: str, value) -> float | int:
        return int(value) if name in self.counts else float(value)

    def report(self, axes: list[int]) -> dict[str, dict[str, float]]:
        """The parameters on ``axes`` (0-based) as ``report.json`` gives them: keyed by the axis
        number a user reads (``"1"``..``"6"``), or ``"robot"`` for a robot-wide effect."""
        if not self.per_axis:
            return {"robot": self.values()}
        return {str(axis_numbers.number(a)): self.values(a) for a in axes}

    def active(self) -> np.ndarray:
        """Per axis (or once), whether the effect differs from its absent values, bool."""
        differs = [v != a for v, a in zip(self._values.values(), self.absent, strict=True)]
        return np.any(differs, axis=0)

    @classmethod
    def of(cls, robot) -> Effect:
        """The effect of this class a robot carries (:attr:`faultgen.model.robots.Robot.effects`)."""
        return robot.effects[cls.id]

    # -- the MJCF -------------------------------------------------------------------------

    @classmethod
    def read(cls, model: mujoco.MjModel, path: Path) -> Effect | None:
        """The effect as ``model`` stores it (absent values when it has no element there); None for
        an effect stored as part of something else (the friction parameters).

        The default reads the custom numerics ``<numeric>{i}`` (or an earlier name,
        :attr:`aliases`), one value per parameter (at least the :attr:`required` leading ones).

        Raises
        ------
        ModelError
            If a numeric has the wrong number of values or holds values :meth:`check` refuses.
        """
        if cls.numeric is None:
            return None
        size = len(cls.units)
        n_axes = axis_numbers.count(model)
        rows = np.tile(np.array(cls.absent, dtype=float), (n_axes, 1))
        for k in range(n_axes):
            for name in (cls.numeric, *cls.aliases):
                idx = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_NUMERIC, f"{name}{k + 1}")
                if idx >= 0:
                    break
            if idx < 0:
                continue
            given = int(model.numeric_size[idx])
            if not (cls.required or size) <= given <= size:
                raise ModelError(f"{path}: numeric '{name}{k + 1}' has {given} values, expected "
                                 f"{size}: {' '.join(cls.units)}")
            adr = model.numeric_adr[idx]
            rows[k, :given] = model.numeric_data[adr: adr + given]
        if not np.all(np.isfinite(rows)):
            raise ModelError(f"{path}: numeric '{cls.numeric}' holds a non-finite value")
        problem = cls.check(rows)
        if problem:
            raise ModelError(f"{path}: numeric '{cls.numeric}' {problem}")
        return cls(n_axes=n_axes, **{name: rows[:, k] for k, name in enumerate(cls.units)})

    @classmethod
    def check(cls, rows: np.ndarray) -> str | None:
        """What is wrong with the stored values ``rows`` (N, n parameters), or None."""
        return None

    def apply(self, spec: mujoco.MjSpec, robot, axis: int | None, params: dict[str, float]) -> None:
        """Write the effect with the absolute ``params`` on ``axis`` (0-based; None for robot-wide)
        into ``spec``. The default writes the numeric ``<numeric>{axis + 1}`` (dropping one of an
        earlier name)."""
        name = f"{self.numeric}{axis + 1}"
        data = [float(params[k]) for k in self.units]
        for old in self.aliases:
            element = spec.numeric(f"{old}{axis + 1}")
            if element is not None:
                spec.delete(element)
        existing = spec.numeric(name)
        if existing is None:
            spec.add_numeric(name=name, data=data)
        else:
            existing.data = data

    def write(self, spec: mujoco.MjSpec, robot, axes: list[int] | None = None) -> None:
        """Write this instance's parameters on ``axes`` (0-based; all of the robot's when omitted; ignored for
        a robot-wide effect) into ``spec``, over what ``robot`` has there."""
        if not self.per_axis:
            self.apply(spec, robot, None, self.values())
            return
        for axis in range(robot.n_axes) if axes is None else axes:
            self.apply(spec, robot, axis, self.values(axis))

    # -- acting --------------------------------------------------------------------------

    def torque(self, robot, q: np.ndarray, qd: np.ndarray, load: np.ndarray, t: np.ndarray
               ) -> np.ndarray | None:
        """Arm-side drive torque of the effect along a motion, N m, shape (n, N), that the
        rigid-body model does not already carry (None: nothing). ``load`` is the arm-side gearbox
        load (N m), ``t`` the time since the start of the run (s)."""
        return None

    def arm_offset(self, load: np.ndarray) -> np.ndarray | None:
        """Arm angle minus motor angle over G under the arm-side gearbox ``load`` (n, N), rad, for
        an effect that lets the arm trail the motor (None: it does not)."""
        return None

    def add_to_simulation(self, spec: mujoco.MjSpec, robot) -> None:
        """Add the MuJoCo elements that realise the effect in the simulation, in place (the
        default adds nothing: the effect is in the MJCF itself, or it is :attr:`stepped`)."""

    def dry_friction_factor(self, time: np.ndarray) -> np.ndarray | None:
        """Factor on the rotors' dry friction (Coulomb plus Stribeck) at ``time`` (r, 1) s since
        the start of each run, shape (r, N); None: none. Only for a :attr:`stepped` effect."""
        return None

    def dry_friction_extra(self, robot, deflection: np.ndarray, static_load: Callable[[], np.ndarray]
                           ) -> np.ndarray | None:
        """Motor-side dry friction the effect adds given the gearbox deflections ``deflection``
        (r, N) rad (eq. 6.2a) and ``static_load()``, the arm-side torque (r, N) that would hold the
        arms still where they are (:meth:`faultgen.model.robots.Robot.static_load_of`; computed only when
        called), N m, shape (r, N); None: none. Only for a :attr:`stepped` effect."""
        return None

    def dry_friction_load_terms(self) -> tuple[np.ndarray, np.ndarray] | None:
        """:meth:`dry_friction_extra` as arrays a stepping backend can hold, for an extra of the form
        ``coefficient * |load| / G``: per axis the ``coefficient`` (N,) and whether the load is the
        static one (True) or the transmitted one ``K deflection`` (False), (N,) bool. None (the
        default): not of that form, so a run with the effect sets the rotors' friction level from
        Python before every step (docs/architecture.md, "Stepping backends")."""
        return None

    # -- identification ------------------------------------------------------------------

    def grid(self, motion: Motion, axis: int) -> list:
        """Values of the nonlinear parameter to search; ``[None]`` when the effect is linear."""
        return [None]

    def search(self, motion: Motion, residual: np.ndarray, rows: np.ndarray, scale: np.ndarray) -> list | None:
        """The effect's own fit of all axes to ``residual`` (n, N) on the samples of ``rows``
        (n, N), axis a weighted by ``1 / scale[a]**2`` (its torque RMS, N m): per axis
        ``(h, theta, predicted torque (n,))``. None (the default): the generic per-axis least
        squares over :meth:`grid` and :meth:`columns`."""
        return None

    def replicate(self, motion: Motion, residual: np.ndarray, rows: np.ndarray, scale: np.ndarray,
                  axes: list[int]) -> list | None:
        """A jackknife replicate of this *fitted* effect (:func:`faultgen.calibrate.search.
        standard_errors`): its fit to ``residual`` on ``rows`` like :meth:`search`, allowed to
        start from its own values on ``axes`` (0-based), since a replicate leaves out one block of
        the data and lands near the full fit. None (the default): fitted afresh."""
        return None

    def columns(self, motion: Motion, axis: int | None, h) -> tuple[np.ndarray, np.ndarray]:
        """Regressors ``Phi`` (n, k) and known part ``offset`` (n,) of the torque change of
        ``axis`` (0-based) over ``motion.robot``, or of all axes ``(n, N, k)`` / ``(n, N)`` when
        not ``per_axis``: the change is ``Phi @ theta + offset``."""
        raise NotImplementedError

    def params(self, motion: Motion, axis: int | None, theta: np.ndarray, h) -> dict[str, float]:
        """The absolute parameters (:attr:`units`) of ``axis`` after the fitted change ``theta``
        (with grid value ``h``) over ``motion.robot``."""
        raise NotImplementedError

    def complete(self, motion: Motion, axis: int | None, theta: np.ndarray, level: int) -> np.ndarray:
        """The full change ``theta`` (k,) when only its first ``level`` entries were fitted (a
        nested :attr:`levels` fit): the others set to what those imply (the payload's inertia
        about the flange from its mass and centre of mass). Default: left as they are (zero)."""
        return theta

    def admissible(self, motion: Motion, axis: int | None, params: dict[str, float]) -> bool:
        """False when ``params`` are not physical for the current model (a negative mass or
        backlash, a friction level below zero); such a fit is never selected."""
        return True

    def fitted(self, robot, params: dict[int | None, dict[str, float]]) -> Effect:
        """A new instance: ``robot``'s values of this effect with ``params`` in place, keyed by
        axis (0-based), or by None for a robot-wide effect; a parameter not given keeps its value."""
        current = self.current(robot)
        table = {k: v.copy() for k, v in current._values.items()}
        for axis, values in params.items():
            for name, value in values.items():
                if axis is None:
                    table[name] = np.asarray(value, dtype=float)
                else:
                    table[name][axis] = value
        return type(self)(n_axes=robot.n_axes, **table)

    def current(self, robot) -> Effect:
        """This effect's values in ``robot`` (the absent values when the robot does not carry it)."""
        return robot.effects.get(self.id, type(self)(n_axes=robot.n_axes))

    def scaled(self, axis: int, parameters: tuple[str, ...], factor: float) -> Effect:
        """A new instance with ``parameters`` of ``axis`` (0-based) multiplied by ``factor``: a
        relative fault's effect (:meth:`faultgen.operation.faults.Fault.scaled`). Raises
        ValueError for a robot-wide effect or one without values per axis."""
        if not self.per_axis or any(v.ndim == 0 for v in self._values.values()):
            raise ValueError(f"{self.id}: scaled() needs values per axis")
        table = {k: v.copy() for k, v in self._values.items()}
        for name in parameters:
            table[name][axis] = table[name][axis] * factor
        return type(self)(**table)

    def reopened(self) -> Effect:
        """The effect as the calibration's per-axis re-search (:func:`faultgen.calibrate.search.reopen`)
        and the backfitting of a step it completed fit it: itself, unless a subclass offers a wider
        variant there (:meth:`faultgen.effects.stribeck.Stribeck.reopened`: the other axes' evidence
        stands for the hump, so one whose fall the log shows only in part may be offered)."""
        return self

    # -- hidden-effect drawing -----------------------------------------------------------

    def draw_grid(self, motion: Motion, axis: int) -> list:
        """Values of the nonlinear parameter a hidden effect is drawn between (inside the second
        and the last-but-one); default: the searched :meth:`grid`."""
        return self.grid(motion, axis)

    def draw_direction(self, rng: np.random.Generator) -> np.ndarray:
        """Unit direction of the linear parameters of a drawn hidden effect, shape (k,)."""
        return np.ones(1)

    def motor_torque(self, motion: Motion, axis: int, params: dict[str, float]) -> float:
        """Largest motor torque (N m) the effect with ``params`` takes on ``axis`` along ``motion``
        (0: it takes none of its own). A fit above the motor's torque limit is never selected
        (:func:`faultgen.calibrate.search.fit_effect`), and hidden-effect drawing keeps it within a
        share of that limit."""
        return 0.0
