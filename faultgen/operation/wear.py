"""Wear schedules: the friction multiplier of a worn axis as a function of the cycle index.

A run repeats one task for cycles ``k = 1 .. n_cycles``; ``k = 0`` is the nominal, unworn state.
A :class:`Schedule` maps ``k`` to a dimensionless multiplier ``m(k)`` with ``m(0) = 1`` and
``m(last_cycle) = 1 + increase``, which the simulator applies to the Coulomb (both signs, stored
as magnitudes) and static friction of one axis (thesis ch. 6.3.1: wear raises f_c and f_s).
Beyond ``last_cycle`` each formula simply continues. A :class:`WearPlan` gives each worn axis
of a run its own schedule: it parses the wear specs (``--wear 2:exp4:20``) and labels the run,
and is turned into one relative :class:`faultgen.operation.faults.Fault` per worn axis on the
motor friction's ``dry`` parameters (:meth:`WearPlan.faults`), which is how the simulation
applies it (:func:`faultgen.operation.faults.dry_multipliers`): friction wear is a fault, and
every fault's shape is a :class:`Schedule`.

Schedules (``increase`` = p, ``last_cycle`` = K):

``exp4``
    ``m(k) = exp(c1 k^4)``, ``c1 = ln(1 + p) / K^4`` (thesis eq. 6.6); with an ``onset`` cycle
    k0 the same rise starts there: ``m(k) = exp(c1 max(k - k0, 0)^4)``, ``c1 = ln(1 + p) / (K - k0)^4``
    (a fleet's robots start wearing on different days).
``logistic``
    ``m(k) = 1 + p (s(k) - 1/2) / (s(K) - 1/2)``, ``s(k) = 1 / (1 + exp(-(c2 k)^4))``,
    ``c2 = shape / K`` (thesis eq. 3.7, see :class:`Schedule`).
``linear``
    ``m(k) = 1 + p k / K``.
``step``
    ``m(k) = 1`` for ``k < step_cycle``, ``1 + p`` from ``step_cycle`` on (an abrupt fault).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from faultgen import axes
from faultgen.checks import is_whole
from faultgen.effects.motor_friction import MotorFriction

#: The motor friction's parameter group friction wear raises (:attr:`MotorFriction.groups`).
DRY = "dry"

#: Known schedule kinds.
SCHEDULES = ("exp4", "logistic", "linear", "step")


#: Optional parameters of each kind and their defaults (``None``: derived from ``last_cycle``).
_PARAMS: dict[str, dict[str, float | None]] = {
    "exp4": {"onset": 0},
    "logistic": {"shape": 1.5},
    "linear": {},
    "step": {"step_cycle": None},
}

#: Schedule parameters that are cycle numbers.
_INT_PARAMS = ("step_cycle", "onset")

_SPEC_FORM = (
    "the form is AXIS:KIND:PERCENT[:key=value,...], e.g. '2:exp4:20', '2:exp4:50:onset=40', "
    "'3:logistic:10:shape=2' or '5:step:20:step_cycle=40'"
)


#: Largest final wear increase accepted, as a fraction (5: Coulomb and static friction six times
#: their new level). The thesis's failing gearboxes reach tens of percent (ch. 5-6); far beyond,
#: the motors saturate and the run no longer follows its task (issue 42: +1e9 gave 781 mrad).
MAX_INCREASE = 5.0


@dataclass(frozen=True)
class Schedule:
    """Friction multiplier of one axis over the cycles of a run; validated on construction.

    Attributes
    ----------
    kind : str
        One of :data:`SCHEDULES`.
    increase : float
        Friction increase at ``last_cycle`` as a fraction (0.2 for +20 %), finite and >= 0.
    last_cycle : int
        Cycle K >= 1 at which the multiplier reaches ``1 + increase``.
    params : mapping
        Kind-specific parameters, filled with their defaults: ``onset`` (exp4, the cycle the rise
        starts from, 0..K-1, default 0), ``shape`` (logistic, dimensionless, > 0, default 1.5) and
        ``step_cycle`` (step, 1..K, default ``K // 2 + 1``, so that the second half of the cycles
        is worn). Read-only.

    Notes
    -----
    exp4: thesis eq. 6.6, ``f_{m,k} = f_{m,0} exp(c1 k^4)`` with c1 "computed by solving (6.6)
    for desired increase in friction at the end of a hundred cycles", i.e.
    ``c1 = ln(1 + p) / K^4``: 20 % over 100 cycles gives c1 = 1.823e-9. The thesis prints
    1.785e-9, which gives only +19.54 % at k = 100; we follow its stated rule, not the number.

    logistic: thesis eq. 3.7, ``mu_k = r0 + c1 / (1 + exp(-(c2 k)^4))`` with r0 set so that mu_0
    is nominal. With ``s(k) = 1 / (1 + exp(-(c2 k)^4))``, ``s(0) = 1/2`` so ``r0 = mu_0 - c1/2``
    and ``mu_k = mu_0 + c1 (s(k) - 1/2)``; ``mu_K = mu_0 (1 + p)`` fixes
    ``c1 = p mu_0 / (s(K) - 1/2)``, hence ``m(k) = mu_k / mu_0 = 1 + p (s(k) - 1/2) / (s(K) - 1/2)``,
    exactly 1 at k = 0 and 1 + p at k = K. ``c2 = shape / K``: the larger ``shape``, the earlier
    the rise saturates (at 1.5, ``s(K) = 0.9937``). The thesis's minus sign for mu^- only keeps
    the negative-velocity coefficient negative; we scale magnitudes, so one multiplier serves
    both. Computed as ``s(k) - 1/2 = tanh((c2 k)^4 / 2) / 2``, which stays accurate for small
    ``shape``.

    Raises
    ------
    ValueError
        For an unknown kind (listing the known ones), an increase that is not a finite number
        >= 0, a ``last_cycle`` that is not an int >= 1, an unknown parameter, a logistic
        ``shape`` that is not finite and > 0, or a ``step_cycle`` outside 1..last_cycle.
    """

    kind: str
    increase: float
    last_cycle: int
    params: Mapping[str, float | int] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.kind not in SCHEDULES:
            raise ValueError(f"unknown wear schedule {self.kind!r}; known schedules: {', '.join(SCHEDULES)}")
        expected = "expected a fraction >= 0 such as 0.2 for 20 %"
        try:
            if isinstance(self.increase, (bool, np.bool_)):
                raise TypeError
            increase = float(self.increase)
        except (TypeError, ValueError):
            raise ValueError(f"wear increase {self.increase!r} is not a number; {expected}") from None
        if not math.isfinite(increase):
            raise ValueError(f"wear increase {increase!r} is not finite; {expected}")
        if increase < 0:
            raise ValueError(f"wear increase {increase!r} is negative; {expected}")
        if increase > MAX_INCREASE:
            raise ValueError(f"wear increase {increase:g} (+{100 * increase:g} %) is beyond the bound of "
                             f"{MAX_INCREASE:g} (+{100 * MAX_INCREASE:g} %, friction x{1 + MAX_INCREASE:g}): a gearbox "
                             "has failed long before, and the motors saturate")
        if not is_whole(self.last_cycle, 1):
            raise ValueError(f"last_cycle {self.last_cycle!r} is invalid; expected an int >= 1 such as 100")
        last = int(self.last_cycle)
        known = _PARAMS[self.kind]
        for key in self.params:
            if key not in known:
                takes = f"parameters: {', '.join(known)}" if known else "no parameters"
                raise ValueError(f"{self.kind} schedule has no parameter {key!r}; it takes {takes}")
        params = {**known, **self.params}
        if self.kind == "logistic":
            shape = params["shape"]
            ok = isinstance(shape, (int, float, np.integer, np.floating)) and not isinstance(shape, bool)
            if not ok or not math.isfinite(shape) or shape <= 0:
                raise ValueError(
                    f"logistic shape {shape!r} is invalid; expected a finite number > 0 such as 1.5"
                )
            params["shape"] = float(shape)
            if _half_tanh(params["shape"], 1.0) == 0:
                raise ValueError(f"logistic shape {shape!r} is too small to compute; expected e.g. 0.5 .. 5")
        if self.kind == "exp4":
            onset = params["onset"]
            if not is_whole(onset) or not 0 <= onset < last:
                raise ValueError(f"exp4 onset {onset!r} is invalid; expected an int in 0..{last - 1} (below last_cycle)")
            params["onset"] = int(onset)
        if self.kind == "step":
            step = last // 2 + 1 if params["step_cycle"] is None else params["step_cycle"]
            if not is_whole(step):
                raise ValueError(f"step_cycle {step!r} is not an int; expected one in 1..{last} (last_cycle)")
            if not 1 <= step <= last:
                raise ValueError(f"step_cycle {step!r} is out of range 1..{last} (last_cycle)")
            params["step_cycle"] = int(step)
        object.__setattr__(self, "increase", increase)
        object.__setattr__(self, "last_cycle", last)
        object.__setattr__(self, "params", MappingProxyType(params))

    @property
    def constants(self) -> dict[str, float | int]:
        """Parameters and derived constants: ``c1`` (exp4, and its ``onset`` when not 0), ``shape``
        and ``c2`` (logistic), ``step_cycle`` (step); empty for linear."""
        if self.kind == "exp4":
            onset = self.params["onset"]
            c1 = {"c1": math.log1p(self.increase) / float(self.last_cycle - onset) ** 4}
            return {**c1, "onset": onset} if onset else c1
        if self.kind == "logistic":
            return {"shape": self.params["shape"], "c2": self.params["shape"] / self.last_cycle}
        return dict(self.params)

    def multiplier(self, k: int | np.ndarray) -> np.ndarray:
        """Friction multiplier at cycle(s) ``k``.

        Parameters
        ----------
        k : int or ndarray of int, any shape
            Cycle indices >= 0 (0 is the nominal state).

        Returns
        -------
        ndarray of float, same shape as ``k``
            Dimensionless multiplier of the nominal Coulomb and static friction.

        Raises
        ------
        ValueError
            If ``k`` is not integer-valued or holds a negative index (the message names it).
        """
        kf = _cycles(k).astype(float)
        p, last, c = self.increase, self.last_cycle, self.constants
        if self.kind == "exp4":
            return np.exp(c["c1"] * np.maximum(kf - self.params["onset"], 0.0) ** 4)
        if self.kind == "logistic":
            return 1.0 + p * _half_tanh(c["c2"], kf) / _half_tanh(c["shape"], 1.0)
        if self.kind == "linear":
            return 1.0 + p * kf / last
        return np.where(kf >= c["step_cycle"], 1.0 + p, 1.0)

    def to_dict(self) -> dict[str, object]:
        """JSON-serialisable labels: kind, increase (fraction), last_cycle and :attr:`constants`."""
        return {"kind": self.kind, "increase": self.increase, "last_cycle": self.last_cycle, **self.constants}


def _half_tanh(c2: float, k: float | np.ndarray) -> np.ndarray:
    """``2 (s(k) - 1/2) = tanh((c2 k)^4 / 2)``, overflow to 1 allowed."""
    with np.errstate(over="ignore", under="ignore"):
        return np.tanh((np.float64(c2) * k) ** 4 / 2)


def _cycles(k: int | np.ndarray) -> np.ndarray:
    arr = np.asarray(k)
    if arr.size == 0:
        return arr.astype(int)  # an empty list is float64 to numpy
    if arr.dtype.kind not in "iu":
        got = repr(arr.item()) if arr.ndim == 0 else f"an array of {arr.dtype}"
        raise ValueError(f"cycle index must be an int or an int array, got {got}")
    if np.any(arr < 0):
        raise ValueError(f"cycle index {int(arr[arr < 0].flat[0])} is negative; expected an int >= 0")
    return arr


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
    def from_specs(cls, specs: Iterable[str], last_cycle: int) -> WearPlan:
        """Build from command-line specs (see :func:`parse_wear`); an axis may appear once."""
        schedules, seen = {}, {}
        for spec in specs:
            axis, schedule = parse_wear(spec, last_cycle)
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
        from faultgen.operation.faults import Fault  # faults shapes its growth with this module's Schedule

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
        from faultgen.operation.faults import dry_multipliers

        k = np.atleast_1d(_cycles(cycles))
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


def parse_wear(spec: str, last_cycle: int) -> tuple[int, Schedule]:
    """Parse a command-line wear spec ``AXIS:KIND:PERCENT[:key=value,...]``.

    Parameters
    ----------
    spec : str
        E.g. ``"2:exp4:20"`` (axis 2, +20 % at ``last_cycle``), ``"3:logistic:10:shape=2"`` or
        ``"5:step:20:step_cycle=40"``. PERCENT is in percent; options are :attr:`Schedule.params`.
    last_cycle : int
        Cycle at which the increase is reached, normally the run's number of cycles.

    Returns
    -------
    axis : int
        1-based axis number, 1..7 (a run holds it to its robot's N).
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
        for option in parts[3].split(","):
            key, sep, value = (s.strip() for s in option.partition("="))
            if not sep or not key or not value:
                raise fail(f"option {option!r} is not key=value")
            try:
                params[key] = int(value) if key in _INT_PARAMS else float(value)
            except ValueError:
                expected = "an int" if key in _INT_PARAMS else "a number"
                raise fail(f"option {key}={value} is not {expected}") from None
    try:
        return _check_axis(axis), Schedule(kind, percent / 100.0, last_cycle, params)
    except ValueError as err:
        raise fail(str(err)) from None
