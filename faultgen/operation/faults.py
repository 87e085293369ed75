"""Faults: one effect's parameter growing over a run's cycles, friction wear among them.

A :class:`Fault` names the effect (:mod:`faultgen.effects`), the axis, the parameter and how it
grows, on the shape of a wear schedule (:class:`faultgen.operation.schedules.Schedule`: ``linear`` by
default; ``exp4``, ``logistic``, ``step``). It grows in one of two ways:

``absolute`` (``--fault``)
    the parameter's value goes from ``start`` to ``final`` at the last cycle: a gearbox whose
    backlash grows, a motor whose cogging grows, a drifting torque offset. The effect's own MJCF
    form (:meth:`Effect.apply`) puts it into the simulated robot, so the fault is the same physics
    the calibration identifies; the controller does not know it.
``relative`` (friction wear, ``--wear``)
    the robot's own value of the parameter is multiplied by the schedule's multiplier
    ``m(k)``, with ``m(0) = 1`` and ``m(K) = 1 + final``: thesis eq. 6.6 for ``exp4``,
    ``m(k) = (1 + p)^((k/K)^4)``. Friction wear is such a fault on the motor friction's ``dry``
    parameters (Coulomb both directions and static friction; :class:`faultgen.effects.MotorFriction`),
    one per worn axis (:meth:`faultgen.operation.wear.WearPlan.faults` turns a wear spec into
    one); the simulation applies :func:`dry_multipliers` to the rotors' dry friction level.

Effects that act through a per-step update of the friction level (``stepped``: warm-up) cannot be
scheduled (their per-cycle counterparts are the operating conditions,
:mod:`faultgen.operation.conditions`), with one exception (``plant_fault``): load-dependent friction
in its transmitted-load form, the physics of a unit's gear loss, whose growing coefficient the
simulation carries per cycle in the plant (:class:`faultgen.simulation.batch.Plant`) rather than in
the model; it needs the static friction model, as the gear loss does.

The motor friction and the calibration's effects that change part of it (Coulomb, viscous,
Stribeck) take no absolute fault: both friction models set the rotors'
friction from the robot's nominal friction, so such a fault would move only the MJCF numeric and
change nothing simulated; friction wear is
their fault.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from types import MappingProxyType

import numpy as np

from faultgen import axes, effects
from faultgen.checks import is_whole
from faultgen.effects.base import Effect
from faultgen.effects.motor_friction import FrictionParameter, MotorFriction
from faultgen.operation import schedules
from faultgen.operation.spec_options import key_values

#: How a fault's parameter grows (:attr:`Fault.growth`).
GROWTHS = ("absolute", "relative")

_SPEC_FORM = ("the form is EFFECT:AXIS:PARAMETER:FINAL[:key=value,...], e.g. 'backlash:2:width:0.01', "
              "'cogging:3:amplitude:0.05:poles=8' or 'torque_offset:1:offset:20:kind=exp4' (AXIS 'each' in a sweep "
              "or a fleet: each worn axis)")


@dataclass(frozen=True)
class Fault:
    """An effect's parameter on one axis growing over the cycles of a run; validated on construction.

    Attributes
    ----------
    effect : str
        Effect id (:data:`faultgen.effects.EFFECTS`), not a ``stepped`` one.
    axis : int
        1..N, N the robot's axes (5..7; a run checks it, :meth:`check`; a robot-wide effect, payload, cannot be a growing fault).
    parameter : str
        The parameter that grows (one of the effect's :attr:`~faultgen.effects.Effect.units`), or
        with ``relative`` growth one of its parameter :attr:`~faultgen.effects.Effect.groups`
        (the motor friction's ``dry``: Coulomb both directions and static friction).
    final : float
        With ``absolute`` growth its value at ``last_cycle``, in the parameter's unit; with
        ``relative`` growth its increase there as a fraction (0.2: +20 %, 1.2 times its value).
    last_cycle : int
        The run's last cycle, >= 1.
    kind : str
        Shape of the growth: a wear schedule kind. Absolute: the value is
        ``start + (final - start) g(k)`` with ``g`` the schedule's rise as a fraction of its final
        rise. Relative: the value is multiplied by the schedule's ``m(k)`` (thesis eq. 6.6 for exp4).
    start : float
        Absolute: value at cycle 0 (default 0: a fault that appears). Relative: must be 0.
    others : dict
        The effect's other parameters on the axis (e.g. cogging ``poles`` and ``phase``); those
        not given keep the effect's absent values. Absolute only.
    onset : int
        Last cycle at the start value, with the ``exp4`` kind (the wear schedule's onset: the
        growth runs from it to ``last_cycle``); default 0, growing from cycle 0.
    growth : str
        ``absolute`` (default) or ``relative`` (:data:`GROWTHS`; module docstring).
    options : dict
        Further schedule parameters (:attr:`faultgen.operation.schedules.Schedule.params`: logistic
        ``shape``, step ``step_cycle``), default none.

    Raises
    ------
    ValueError
        For an unknown effect (listing them), a stepped effect (but a ``plant_fault`` one in its
        transmitted-load form) or a robot-wide one, an absolute fault on
        the motor friction or an effect that changes part of it (friction wear is their fault), an
        axis outside 1..7, an unknown parameter or group, a non-finite value, a final value equal
        to the start, a bad schedule kind, onset or option, a relative fault that does not start
        at 0 or takes other parameters, or a value the effect does not admit; the message names it.
    """

    effect: str
    axis: int
    parameter: str
    final: float
    last_cycle: int
    kind: str = "linear"
    start: float = 0.0
    others: dict = field(default_factory=dict)
    onset: int = 0
    growth: str = "absolute"
    options: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        prototype = effects.get(self.effect)  # ValueError lists the known ids
        if self.growth not in GROWTHS:
            raise ValueError(f"fault growth {self.growth!r}: expected one of {', '.join(GROWTHS)}")
        object.__setattr__(self, "options", MappingProxyType(dict(self.options)))
        if self.relative:
            self._check_relative(prototype)
            return
        if isinstance(prototype, (MotorFriction, FrictionParameter)):
            raise ValueError(
                f"fault effect {self.effect!r} is part of the motor friction, which both friction models set from "
                "the robot's nominal values: an absolute fault on it would change nothing simulated. Its fault is "
                "friction wear, which grows the Coulomb and static friction: --wear AXIS:KIND:PERCENT (e.g. "
                "--wear 2:exp4:20)")
        if prototype.stepped and not prototype.plant_fault:
            raise ValueError(f"fault effect {self.effect!r} acts through a per-step friction update and cannot grow "
                             "over cycles; use the operating conditions (--temperature) or the static friction model")
        if not prototype.per_axis:
            raise ValueError(f"fault effect {self.effect!r} is robot-wide; a growing fault sits on one axis (parts "
                             "changing per cycle are an operating condition: --payloads)")
        if not is_whole(self.axis) or not 1 <= self.axis <= axes.MAX_AXES:
            raise ValueError(f"fault axis {self.axis!r}: expected 1..{axes.MAX_AXES}")
        names = list(prototype.units)
        for name in [self.parameter, *self.others]:
            if name not in names:
                raise ValueError(f"{self.effect} has no parameter {name!r}; it has: {', '.join(names)}")
        if self.parameter in self.others:
            raise ValueError(f"fault parameter {self.parameter!r} is also given as another parameter")
        if self.in_plant and (self.parameter != "coefficient" or any(self.others.values())):
            raise ValueError(f"a growing {self.effect} fault grows its coefficient in the transmitted-load form (the "
                             f"gearbox's own loss, gravity_load = 0); got parameter {self.parameter!r}, others "
                             f"{dict(self.others)!r}")
        for name, value in (("final", self.final), ("start", self.start), *self.others.items()):
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                    or not math.isfinite(value):
                raise ValueError(f"fault {name} = {value!r}: expected a finite number")
        if self.final == self.start:
            raise ValueError(f"fault final = start = {self.final!r}: a fault must change its parameter")
        self._schedule()  # names a bad kind, last cycle or onset
        object.__setattr__(self, "others", MappingProxyType(dict(self.others)))
        for value in (self.start, self.final):
            if value < 0 and not prototype.signed:
                raise ValueError(f"fault {self.parameter} = {value!r}: {self.effect} takes values >= 0")
            instance = self.at(value, max(self.axis, axes.MIN_AXES))
            problem = type(prototype).check(np.array([instance.values(self.axis - 1)[n] for n in names])[None])
            if problem:
                raise ValueError(f"fault {self.parameter} = {value!r}: {self.effect} {problem}")

    def _check_relative(self, prototype: Effect) -> None:
        groups = type(prototype).groups
        if self.parameter not in groups:
            has = f"it has: {', '.join(groups)}" if groups else "it has none"
            raise ValueError(f"a relative fault grows a parameter group of its effect; {self.effect} has no group "
                             f"{self.parameter!r} ({has})")
        if not is_whole(self.axis) or not 1 <= self.axis <= axes.MAX_AXES:
            raise ValueError(f"fault axis {self.axis!r}: expected 1..{axes.MAX_AXES}")
        if self.start != 0 or self.others:
            raise ValueError("a relative fault starts from the robot's own value (start = 0, no other parameters); "
                             f"got start = {self.start!r}, others = {dict(self.others)!r}")
        self._schedule()  # names a bad kind, increase, last cycle or option
        object.__setattr__(self, "others", MappingProxyType({}))

    @property
    def relative(self) -> bool:
        """Whether the fault multiplies the robot's own value (friction wear) rather than setting one."""
        return self.growth == "relative"

    @property
    def in_plant(self) -> bool:
        """Whether the simulation carries the fault's value per cycle in the plant, not in the model
        (the effect's ``plant_fault``: a growing load-dependent friction adds to the unit's gear loss)."""
        return type(effects.get(self.effect)).plant_fault

    @property
    def parameters(self) -> tuple[str, ...]:
        """The parameters the fault changes: :attr:`parameter`, or the members of its group."""
        return type(effects.get(self.effect)).groups.get(self.parameter, (self.parameter,))

    def _schedule(self) -> schedules.Schedule:
        """The growth's shape: a wear schedule of the relative increase, or of a unit rise."""
        params = {**({"onset": self.onset} if self.onset else {}), **self.options}
        return schedules.Schedule(self.kind, self.final if self.relative else 1.0, self.last_cycle, params)

    @property
    def schedule(self) -> schedules.Schedule:
        """The schedule of a relative fault (its multiplier is the fault's value); ValueError for an absolute one."""
        if not self.relative:
            raise ValueError(f"the {self.effect} fault is absolute; only a relative fault has a multiplier schedule")
        return self._schedule()

    def values(self, cycles) -> np.ndarray:
        """The parameter at ``cycles`` (ints >= 0, any shape): absolute, in its unit; relative,
        the dimensionless multiplier of the robot's own value (:meth:`schedules.Schedule.multiplier`,
        thesis eq. 6.6 for ``exp4``)."""
        if self.relative:
            return self._schedule().multiplier(np.asarray(cycles))
        rise = self._schedule().multiplier(np.asarray(cycles)) - 1.0
        return self.start + (self.final - self.start) * rise

    def scaled(self, nominal: Effect, cycle: int) -> Effect:
        """A relative fault's effect at ``cycle``: ``nominal`` (the robot's, e.g. ``robot.friction``)
        with the fault's parameters on its axis multiplied by :meth:`values` there."""
        if not self.relative:
            raise ValueError(f"the {self.effect} fault is absolute; at() gives its effect at a value")
        if type(nominal) is not type(effects.get(self.effect)):
            raise ValueError(f"the fault is on {self.effect}; got a {type(nominal).__name__}")
        self.check(np.shape(getattr(nominal, self.parameters[0]))[0])
        return nominal.scaled(self.axis - 1, self.parameters, float(self.values(np.array([cycle]))[0]))

    def check(self, n_axes: int) -> None:
        """Raise ValueError when a robot of ``n_axes`` axes has no axis :attr:`axis`."""
        if self.axis > n_axes:
            raise ValueError(f"fault axis {self.axis} is out of range 1..{n_axes}")

    def at(self, value: float, n_axes: int) -> Effect:
        """The effect with the parameter at ``value`` (and :attr:`others`) on the fault's axis,
        absent on the others of a robot of ``n_axes`` axes. An absolute fault only (a relative one
        scales the robot's own values: :meth:`scaled`)."""
        if self.relative:
            raise ValueError(f"the {self.effect} fault is relative; scaled() gives its effect at a cycle")
        self.check(n_axes)
        cls = type(effects.get(self.effect))
        values = {**self.others, self.parameter: float(value)}
        table = {}
        for k, name in enumerate(cls.units):
            column = np.full(n_axes, cls.absent[k], dtype=float)
            if name in values:
                column[self.axis - 1] = values[name]
            table[name] = column
        return cls(**table)

    def text(self) -> str:
        """The fault text that makes this fault again (:class:`FaultSpec`), e.g. ``backlash:2:width:0.01``;
        a relative fault (friction wear) is not written so and gives its labels instead."""
        if self.relative:
            return f"{self.effect} {self.parameter} x{1 + self.final:g} on axis {self.axis} ({self.kind})"
        return str(FaultSpec(self.effect, self.axis, self.parameter, self.final,
                             None if self.kind == "linear" else self.kind, self.start, self.onset or None,
                             dict(self.others)))

    def to_dict(self) -> dict:
        """JSON-serialisable labels (``onset``, ``growth`` and ``options`` only when not their
        defaults, so absolute faults without them keep their labels)."""
        table = {"effect": self.effect, "axis": self.axis, "parameter": self.parameter, "final": self.final,
                 "start": self.start, "kind": self.kind, "last_cycle": self.last_cycle, "others": dict(self.others)}
        if self.onset:
            table["onset"] = self.onset
        if self.relative:
            table["growth"] = self.growth
        if self.options:
            table["options"] = dict(self.options)
        return table


def dry_multipliers(faults, cycles, n_axes: int) -> np.ndarray:
    """The multiplier of each axis's dry friction (Coulomb and static) at each cycle: the relative
    faults on the motor friction's ``dry`` group (friction wear), 1 elsewhere.

    Parameters
    ----------
    faults : iterable of Fault
        A run's faults; the absolute ones are not friction wear and are passed over.
    cycles : ndarray of int of shape (n,)
        Cycle indices >= 0.
    n_axes : int
        The robot's number of axes N.

    Returns
    -------
    ndarray of shape (n, N)
        Dimensionless, column ``i - 1`` for axis ``i``.

    Raises
    ------
    ValueError
        For an axis outside 1..N, or two faults on the dry friction of one axis.
    """
    k = np.atleast_1d(np.asarray(cycles))
    out = np.ones((k.shape[0], n_axes))
    seen = {}
    for fault in faults:
        if not (fault.relative and fault.effect == MotorFriction.id and fault.parameter in MotorFriction.groups):
            continue
        fault.check(n_axes)
        if fault.axis in seen:
            raise ValueError(f"axis {fault.axis} has two friction wear faults ({seen[fault.axis]} and "
                             f"{fault.to_dict()}); give one per axis")
        seen[fault.axis] = fault.to_dict()
        out[:, axes.index(fault.axis, n_axes)] = fault.values(k)
    return out


#: The axis placeholder of a sweep's or fleet's fault text: the swept or drawn axis.
ANY_AXIS = "each"


@dataclass(frozen=True)
class FaultSpec:
    """The fault text every command takes, parsed once: ``EFFECT:AXIS:PARAMETER:FINAL[:key=value,...]``.

    ``simulate --fault`` names its axis (``backlash:2:width:0.01``). A sweep or a fleet takes the
    same text; there ``AXIS`` may be ``each`` (:data:`ANY_AXIS`; not ``*``, which a shell would
    expand): the axis each run wears (a sweep's ``--axis``, a fleet's drawn axis),
    ``backlash:each:width:0.01``. Options: ``kind`` (wear schedule
    kind), ``start``, ``onset`` (a whole cycle) and the effect's other parameters.

    Attributes
    ----------
    effect, parameter : str
        As in :class:`Fault` (checked when a :class:`Fault` is made: :meth:`fault`).
    axis : int or None
        1..7, or None for ``each``.
    final : float
        The parameter's value at the last cycle, in its unit.
    kind : str or None
        The schedule kind given, None if not (:class:`Fault`'s default, linear).
    start : float
    onset : int or None
    others : dict
        The effect's other parameters given.

    Raises
    ------
    ValueError
        On construction, for an unknown effect (listing the known ones), an axis outside 1..7 or a
        FINAL that is not a finite number; the rest (the parameter, the values the effect admits,
        the schedule) is checked when a :class:`Fault` is made (:meth:`fault`), where the run's
        last cycle is known.
    """

    effect: str
    axis: int | None
    parameter: str
    final: float
    kind: str | None = None
    start: float = 0.0
    onset: int | None = None
    others: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        effects.get(self.effect)  # ValueError lists the known ids
        if self.axis is not None and (not is_whole(self.axis) or not 1 <= self.axis <= axes.MAX_AXES):
            raise ValueError(f"fault axis {self.axis!r}: expected 1..{axes.MAX_AXES} (or {ANY_AXIS!r}: the worn axis "
                             "of a sweep or a fleet)")
        if isinstance(self.final, bool) or not isinstance(self.final, (int, float)) or not math.isfinite(self.final):
            raise ValueError(f"fault FINAL = {self.final!r}: expected a finite number")

    @classmethod
    def parse(cls, spec: str) -> "FaultSpec":
        """Parse ``spec``; ValueError quoting it and the form (the text a command refuses)."""

        def fail(reason: str) -> ValueError:
            return ValueError(f"bad fault spec {spec!r}: {reason}; {_SPEC_FORM}")

        parts = [p.strip() for p in str(spec).strip().split(":")]
        if len(parts) in (3, 4) and not _is_axis(parts[1]) and _is_number(parts[2]):
            # the old sweep/fleet form without the axis: name the one form
            fixed = ":".join([parts[0], ANY_AXIS, *parts[1:]])
            raise fail(f"it has no AXIS; in a sweep or a fleet write {ANY_AXIS!r} for the worn axis: {fixed!r}")
        if len(parts) not in (4, 5):
            raise fail(f"it has {len(parts)} ':'-separated field(s), expected 4 or 5")
        effect, axis_text, parameter, final_text = parts[:4]
        if not _is_axis(axis_text):
            raise fail(f"AXIS {axis_text!r} must be a whole number (or {ANY_AXIS!r} in a sweep or a fleet)")
        if not _is_number(final_text):
            raise fail(f"FINAL {final_text!r} must be a number")
        axis = None if axis_text == ANY_AXIS else int(axis_text)
        kind, start, onset, others = None, 0.0, None, {}
        if len(parts) == 5:
            for key, value in key_values(parts[4], fail):
                if key == "kind":
                    kind = value
                    continue
                if not _is_number(value):
                    raise fail(f"option {key}={value} is not a number")
                number = float(value)
                if key == "start":
                    start = number
                elif key == "onset":
                    if not number.is_integer():
                        raise fail(f"option onset={value} is not a whole cycle")
                    onset = int(number)
                else:
                    others[key] = number
        try:
            return cls(effect, axis, parameter, float(final_text), kind, start, onset, others)
        except ValueError as err:
            raise fail(str(err)) from None

    def fault(self, last_cycle: int, axis: int | None = None, **changes) -> Fault:
        """The :class:`Fault` on ``axis`` (a sweep's or fleet's worn axis; default the spec's own),
        ``changes`` overriding its fields (a fleet sets ``kind`` and ``onset``). ValueError when
        neither gives an axis, when ``axis`` differs from a numbered one, or for a bad fault (its message)."""
        if axis is None:
            axis = self.axis
        if axis is None:
            raise ValueError(f"fault {str(self)!r}: AXIS {ANY_AXIS!r} stands for a sweep's or a fleet's worn axis; "
                             "name the axis here, e.g. " + repr(str(replace(self, axis=2))))
        if self.axis is not None and axis != self.axis:
            raise ValueError(f"fault {str(self)!r} is on axis {self.axis}, not on the worn axis {axis}; write "
                             f"{ANY_AXIS!r} for the axis to give each worn axis the fault")
        fields = {"kind": self.kind or "linear", "start": self.start, "others": dict(self.others),
                  "onset": self.onset or 0, **changes}
        try:
            return Fault(self.effect, axis, self.parameter, self.final, last_cycle, **fields)
        except ValueError as err:
            raise ValueError(f"bad fault spec {str(self)!r}: {err}; {_SPEC_FORM}") from None

    def __str__(self) -> str:
        options = [*([f"kind={self.kind}"] if self.kind else []), *([f"start={_text(self.start)}"] if self.start else []),
                   *([f"onset={self.onset}"] if self.onset is not None else []),
                   *(f"{k}={_text(v)}" for k, v in self.others.items())]
        axis = ANY_AXIS if self.axis is None else str(self.axis)
        fields = [self.effect, axis, self.parameter, _text(self.final)]
        return ":".join([*fields, ",".join(options)] if options else fields)


def _text(value: float) -> str:
    """A number as a fault text writes it: short (``0.01``, ``20``), and exact (a value :g would
    round, such as 0.0123456789, keeps every digit), so the text makes the same fault again."""
    short = f"{value:g}"
    return short if float(short) == value else repr(float(value))


def _is_axis(text: str) -> bool:
    return text == ANY_AXIS or text.isdigit()


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def parse_fault(spec: str, last_cycle: int) -> Fault:
    """A :class:`Fault` from ``EFFECT:AXIS:PARAMETER:FINAL[:key=value,...]`` with a numbered axis
    (:class:`FaultSpec`). Raises ValueError quoting the spec and the form."""
    return FaultSpec.parse(spec).fault(last_cycle)
