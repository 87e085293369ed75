"""Friction wear: which axes of a run wear, each on its own schedule.

A :class:`WearPlan` gives each worn axis of a run its own :class:`~faultgen.operation.schedules.Schedule`
(the multiplier ``m(k)`` of its Coulomb and static friction at cycle ``k``; the kinds ``exp4``,
``logistic``, ``linear`` and ``step`` and their formulas are in :mod:`faultgen.operation.schedules`,
whose names this module re-exports). It parses the wear specs (``--wear 2:exp4:20``) and labels
the run, and is turned into one relative :class:`faultgen.operation.faults.Fault` per worn axis on
the motor friction's ``dry`` parameters (:meth:`WearPlan.faults`), which is how the simulation
applies it (:func:`faultgen.operation.faults.dry_multipliers`): friction wear is a fault, and
every fault's shape is a :class:`Schedule`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from faultgen import axes
from faultgen.effects.motor_friction import MotorFriction
from faultgen.operation.faults import Fault, dry_multipliers
from faultgen.operation.schedules import INT_PARAMS, MAX_INCREASE, SCHEDULES, Schedule, check_cycles
from faultgen.operation.spec_options import key_values

__all__ = ["DRY", "MAX_INCREASE", "SCHEDULES", "Schedule", "WearPlan", "parse_wear"]

#: The motor friction's parameter group friction wear raises (:attr:`MotorFriction.groups`).
DRY = "dry"

_SPEC_FORM = (
    "the form is AXIS:KIND:PERCENT[:key=value,...], e.g. '2:exp4:20', '2:exp4:50:onset=40', "
    "'3:logistic:10:shape=2' or '5:step:20:step_cycle=40'"
)


def _check_axis(axis: object) -> int:
    return axes.check(axis)  # 1..7 here; a run checks against its robot's N (WearPlan.check)


@dataclass(frozen=True)
class WearPlan:
    """The worn axes of a run, each with its own :class:`Schedule`; empty for a fault-free run.

    Attributes
    ----------
    schedules : mapping of int to Schedule
        1-based axis number (1..N) -> schedule, sorted by axis. Read-only. A plan does not know its
        robot: construction accepts any axis a robot can have (1..7); :meth:`check` and
        :meth:`multipliers` hold it to a robot's N.

    Raises
    ------
    ValueError
        On construction, for an axis outside 1..7.
    TypeError
        On construction, for a value that is not a :class:`Schedule`.
    """

    schedules: Mapping[int, Schedule] = field(default_factory=dict)

    def __post_init__(self) -> None:
        checked = {}
        for axis, schedule in self.schedules.items():
            if not isinstance(schedule, Schedule):
                raise TypeError(f"axis {axis!r}: expected a Schedule, got {type(schedule).__name__}")
            checked[_check_axis(axis)] = schedule
        object.__setattr__(self, "schedules", MappingProxyType(dict(sorted(checked.items()))))

    @classmethod
    def from_specs(cls, specs: Iterable[str], last_cycle: int, n_axes: int | None = None) -> WearPlan:
        """Build from command-line specs (see :func:`parse_wear`; ``n_axes``: the robot's N, the
        axes checked against it); an axis may appear once."""
        schedules, seen = {}, {}
        for spec in specs:
            axis, schedule = parse_wear(spec, last_cycle, n_axes)
            if axis in seen:
                raise ValueError(
                    f"axis {axis} has two wear specs, {seen[axis]!r} and {spec!r}; give one per axis"
                )
            schedules[axis], seen[axis] = schedule, spec
        return cls(schedules)

    def faults(self) -> tuple:
        """The plan as faults: per worn axis a relative :class:`faultgen.operation.faults.Fault` on
        the motor friction's ``dry`` group (Coulomb both directions and static friction) growing on
        its schedule, :meth:`Schedule.multiplier` as its value; in axis order."""
        out = []
        for axis, s in self.schedules.items():
            options = {k: v for k, v in s.params.items() if k != "onset"}
            out.append(Fault(MotorFriction.id, axis, DRY, s.increase, s.last_cycle, kind=s.kind,
                             onset=s.params.get("onset", 0), growth="relative", options=options))
        return tuple(out)

    @property
    def worn_axes(self) -> tuple[int, ...]:
        """1-based numbers of the worn axes, ascending."""
        return tuple(self.schedules)

    def check(self, n_axes: int) -> None:
        """Raise ValueError naming the first worn axis a robot of ``n_axes`` axes does not have
        ("axis 7 is out of range 1..6")."""
        for axis in self.schedules:
            axes.index(axis, n_axes)

    def multipliers(self, cycles: int | np.ndarray, n_axes: int) -> np.ndarray:
        """Friction multiplier of every axis at each cycle.

        Parameters
        ----------
        cycles : int or ndarray of int of shape (n,)
            Cycle indices >= 0.
        n_axes : int
            The robot's number of axes N (``Robot.n_axes``).

        Returns
        -------
        ndarray of shape (n, N)
            Dimensionless multipliers, column ``i - 1`` for axis ``i``; 1.0 for unworn axes.

        Raises
        ------
        ValueError
            For a bad cycle index, or a worn axis outside 1..N.
        """
        k = np.atleast_1d(check_cycles(cycles))
        if k.ndim != 1:
            raise ValueError(f"cycles must be an int or a 1-D int array, got shape {k.shape}")
        self.check(n_axes)
        return dry_multipliers(self.faults(), k, n_axes)

    def to_dict(self) -> dict[str, object]:
        """JSON-serialisable labels: ``worn_axes`` and one schedule dict (with ``axis``) per axis."""
        return {
            "worn_axes": list(self.worn_axes),
            "schedules": [{"axis": axis, **s.to_dict()} for axis, s in self.schedules.items()],
        }


def parse_wear(spec: str, last_cycle: int, n_axes: int | None = None) -> tuple[int, Schedule]:
    """Parse a command-line wear spec ``AXIS:KIND:PERCENT[:key=value,...]``.

    Parameters
    ----------
    spec : str
        E.g. ``"2:exp4:20"`` (axis 2, +20 % at ``last_cycle``), ``"3:logistic:10:shape=2"`` or
        ``"5:step:20:step_cycle=40"``. PERCENT is in percent; options are :attr:`Schedule.params`.
    last_cycle : int
        Cycle at which the increase is reached, normally the run's number of cycles.
    n_axes : int, optional
        The robot's number of axes N: AXIS must be in 1..N (omitted: 1..7, and a run holds it to
        its robot's N).

    Returns
    -------
    axis : int
        1-based axis number.
    schedule : Schedule

    Raises
    ------
    ValueError
        If the spec is malformed or a value is invalid; the message quotes the spec and shows the
        expected form with examples.
    """

    def fail(reason: str) -> ValueError:
        return ValueError(f"bad wear spec {spec!r}: {reason}; {_SPEC_FORM}")

    parts = [part.strip() for part in spec.strip().split(":")]
    if len(parts) not in (3, 4):
        raise fail(f"it has {len(parts)} ':'-separated field(s), expected 3 or 4")
    axis_text, kind, percent_text = parts[:3]
    try:
        axis = int(axis_text)
    except ValueError:
        raise fail(f"AXIS {axis_text!r} is not an int") from None
    try:
        percent = float(percent_text)
    except ValueError:
        raise fail(f"PERCENT {percent_text!r} is not a number") from None
    if not math.isfinite(percent) or percent < 0:
        raise fail(f"PERCENT {percent_text} is not a finite number >= 0 (20 means +20 % friction)")
    params: dict[str, float | int] = {}
    if len(parts) == 4:
        for key, value in key_values(parts[3], fail):
            try:
                params[key] = int(value) if key in INT_PARAMS else float(value)
            except ValueError:
                expected = "an int" if key in INT_PARAMS else "a number"
                raise fail(f"option {key}={value} is not {expected}") from None
    try:
        return axes.check(axis, n_axes), Schedule(kind, percent / 100.0, last_cycle, params)
    except ValueError as err:
        raise fail(str(err)) from None
