"""Faults other than friction wear: one effect's parameter growing over a run's cycles.

Friction wear (:mod:`faultgen.operation.wear`) is one fault; the effects the calibration
identifies (:mod:`faultgen.effects`) give others: a gearbox whose backlash grows, a motor whose
cogging grows, a drifting torque offset. A :class:`Fault` names the effect,
the axis, the parameter and its value at the last cycle; the value grows from ``start`` on the
shape of a wear schedule kind (``linear`` by default; ``exp4``, ``logistic``, ``step`` as in
:mod:`~faultgen.operation.wear`). The effect's own MJCF form (:meth:`Effect.apply`) puts it into
the simulated robot, so the fault is the same physics the calibration identifies; the controller
does not know it. Effects that act through a per-step update of the friction level (``stepped``:
load-dependent friction, warm-up) cannot be scheduled this way (their per-cycle counterparts are
the operating conditions, :mod:`faultgen.operation.conditions`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from faultgen import effects
from faultgen import axes
from faultgen.checks import is_whole
from faultgen.effects.base import Effect
from faultgen.operation import wear

_SPEC_FORM = ("the form is EFFECT:AXIS:PARAMETER:FINAL[:key=value,...], e.g. 'backlash:2:width:0.01', "
              "'cogging:3:amplitude:0.05:poles=8' or 'torque_offset:1:offset:20:kind=exp4'")


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
        The parameter that grows (one of the effect's :attr:`~faultgen.effects.Effect.units`).
    final : float
        Its value at ``last_cycle``, in the parameter's unit.
    last_cycle : int
        The run's last cycle, >= 1.
    kind : str
        Shape of the growth: a wear schedule kind; the value is ``start + (final - start) g(k)``
        with ``g`` the schedule's rise as a fraction of its final rise.
    start : float
        Value at cycle 0 (default 0: a fault that appears).
    others : dict
        The effect's other parameters on the axis (e.g. cogging ``poles`` and ``phase``); those
        not given keep the effect's absent values.
    onset : int
        Last cycle at the start value, with the ``exp4`` kind (the wear schedule's onset: the
        growth runs from it to ``last_cycle``); default 0, growing from cycle 0.

    Raises
    ------
    ValueError
        For an unknown effect (listing them), a stepped or robot-wide effect, an axis outside
        1..7, an unknown parameter, a non-finite value, a final value equal to the start, a bad
        schedule kind or onset, or a value the effect does not admit; the message names it.
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

    def __post_init__(self) -> None:
        prototype = effects.get(self.effect)  # ValueError lists the known ids
        if prototype.stepped:
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

    def _schedule(self) -> wear.Schedule:
        """The growth's shape: a wear schedule of a unit rise."""
        return wear.Schedule(self.kind, 1.0, self.last_cycle, {"onset": self.onset} if self.onset else {})

    def values(self, cycles) -> np.ndarray:
        """The parameter at ``cycles`` (ints >= 0, any shape), in its unit."""
        rise = self._schedule().multiplier(np.asarray(cycles)) - 1.0
        return self.start + (self.final - self.start) * rise

    def check(self, n_axes: int) -> None:
        """Raise ValueError when a robot of ``n_axes`` axes has no axis :attr:`axis`."""
        if self.axis > n_axes:
            raise ValueError(f"fault axis {self.axis} is out of range 1..{n_axes}")

    def at(self, value: float, n_axes: int) -> Effect:
        """The effect with the parameter at ``value`` (and :attr:`others`) on the fault's axis,
        absent on the others of a robot of ``n_axes`` axes."""
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

    def to_dict(self) -> dict:
        """JSON-serialisable labels (``onset`` only when not 0, so faults without one keep their labels)."""
        table = {"effect": self.effect, "axis": self.axis, "parameter": self.parameter, "final": self.final,
                 "start": self.start, "kind": self.kind, "last_cycle": self.last_cycle, "others": dict(self.others)}
        return {**table, "onset": self.onset} if self.onset else table


def parse_fault(spec: str, last_cycle: int) -> Fault:
    """A :class:`Fault` from ``EFFECT:AXIS:PARAMETER:FINAL[:key=value,...]`` (options: ``kind``,
    ``start``, ``onset`` and the effect's other parameters). Raises ValueError quoting the spec and the form."""

    def fail(reason: str) -> ValueError:
        return ValueError(f"bad fault spec {spec!r}: {reason}; {_SPEC_FORM}")

    parts = [p.strip() for p in spec.strip().split(":")]
    if len(parts) not in (4, 5):
        raise fail(f"it has {len(parts)} ':'-separated field(s), expected 4 or 5")
    effect, axis_text, parameter, final_text = parts[:4]
    try:
        axis, final = int(axis_text), float(final_text)
    except ValueError:
        raise fail("AXIS must be an int and FINAL a number") from None
    options, kind, start, onset = {}, "linear", 0.0, 0
    if len(parts) == 5:
        for option in parts[4].split(","):
            key, sep, value = (s.strip() for s in option.partition("="))
            if not sep or not key or not value:
                raise fail(f"option {option!r} is not key=value")
            if key == "kind":
                kind = value
                continue
            try:
                number = float(value)
            except ValueError:
                raise fail(f"option {key}={value} is not a number") from None
            if key == "start":
                start = number
            elif key == "onset":
                if not number.is_integer():
                    raise fail(f"option onset={value} is not a whole cycle")
                onset = int(number)
            else:
                options[key] = number
    try:
        return Fault(effect, axis, parameter, final, last_cycle, kind=kind, start=start, others=options, onset=onset)
    except ValueError as err:
        raise fail(str(err)) from None
