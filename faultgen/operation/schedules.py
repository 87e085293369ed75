"""Wear schedules: the friction multiplier of a worn axis as a function of the cycle index.

A run repeats one task for cycles ``k = 1 .. n_cycles``; ``k = 0`` is the nominal, unworn state.
A :class:`Schedule` maps ``k`` to a dimensionless multiplier ``m(k)`` with ``m(0) = 1`` and
``m(last_cycle) = 1 + increase``, which the simulator applies to the Coulomb (both signs, stored
as magnitudes) and static friction of one axis (thesis ch. 6.3.1: wear raises f_c and f_s).
Beyond ``last_cycle`` each formula simply continues. Every growing fault
(:class:`faultgen.operation.faults.Fault`) has the shape of a schedule, friction wear
(:mod:`faultgen.operation.wear`) among them; this module knows neither.

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
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from faultgen.checks import is_whole

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
INT_PARAMS = ("step_cycle", "onset")

#: Largest final wear increase accepted, as a fraction (5: Coulomb and static friction six times
#: their new level). The thesis's failing gearboxes reach tens of percent (ch. 5-6); far beyond,
#: the motors saturate and the run no longer follows its task (+1e9 gave a 781 mrad tracking error).
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
        kf = check_cycles(k).astype(float)
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


def check_cycles(k: int | np.ndarray) -> np.ndarray:
    arr = np.asarray(k)
    if arr.size == 0:
        return arr.astype(int)  # an empty list is float64 to numpy
    if arr.dtype.kind not in "iu":
        got = repr(arr.item()) if arr.ndim == 0 else f"an array of {arr.dtype}"
        raise ValueError(f"cycle index must be an int or an int array, got {got}")
    if np.any(arr < 0):
        raise ValueError(f"cycle index {int(arr[arr < 0].flat[0])} is negative; expected an int >= 0")
    return arr
