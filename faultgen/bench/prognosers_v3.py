"""The prognostics track version 3's own baselines beside the naive and the health-index fits
(:mod:`faultgen.bench.degradation`): the load-based rated life and the oracle.

- :class:`LoadLife` (``load_life``): the rated life of the gears by their load, as a maker's
  catalogue gives it (``L = L_n (n_N / n_av) (T_N / T_av)^p``, the law
  :func:`faultgen.bench.prognostics_v3.consumption` applies to the logged payload, speed override
  and hours), its rated life ``L_n`` learnt from the train split: each run-to-failure train unit gives
  the consumption of its worn axis at its end of life. At a time of prediction, each such train unit
  gives one sample: the day the test unit's same axis would reach that consumption at its duty of the
  last :data:`WINDOW` days (the samples whose consumption the unit has passed already left out while
  any other is left). It knows the duty; it reads nothing of the unit's condition.
- :class:`Oracle` (``oracle``): the ceiling. It reads the unit's **true** wear so far (the labels:
  its worn axis and wear per record) and fits each growth law of
  :data:`faultgen.bench.prognostics_v3.LAWS` against the unit's cumulative relative duty since the
  onset (least squares on the law's inverse); the law that fits best (the true one: the wear is
  exact) is extrapolated at the duty of the last :data:`WINDOW` days to the failure wear. It misses
  only what the future duty changes; a healthy unit has no end of life (``inf``); before the onset,
  no prediction. Not a prognoser a submission could be (it reads labels): the scoring gives it the
  labelled records (:mod:`faultgen.bench.rul_v3`).
"""

from __future__ import annotations

import numpy as np

from faultgen.bench import files, prognostics_v3
from faultgen.bench.prognosers import MAX_TIME, end_of_life

#: Days of recent duty that set the future duty.
WINDOW = 28


def _duty(unit: files.Unit) -> np.ndarray:
    """The relative duty of each record and axis (shape (records, 6)); ValueError without the duty arrays."""
    missing = [n for n in ("payload_mass", "speed_override", "operating_hours") if n not in unit.arrays]
    if missing:
        raise ValueError(f"unit {unit.id}: no {', '.join(missing)}: the load-based baselines need the duty of "
                         "the prognostics track's version 3")
    return prognostics_v3.relative_duty(unit.arrays["payload_mass"], unit.arrays["speed_override"],
                                        unit.arrays["operating_hours"])


def _rate(unit: files.Unit, duty: np.ndarray) -> np.ndarray:
    """Each axis's duty per calendar day over the last :data:`WINDOW` days of ``unit``'s records."""
    days = np.asarray(unit.arrays["cycles"], dtype=float)
    recent = days > days[-1] - WINDOW
    span = min(float(WINDOW), days[-1] - days[0] + 1.0)
    return duty[recent].sum(axis=0) / max(span, 1.0)


class LoadLife:
    """The load-based rated life (module docstring). No parameter."""

    def fit(self, units: list[files.Unit], failure_wear: float) -> LoadLife:
        used = []
        for unit in units:
            life = end_of_life(unit, failure_wear) if unit.fault_level is not None and unit.worn_axis else None
            if life is not None:
                upto = np.asarray(unit.arrays["cycles"]) <= life
                used.append((unit.worn_axis - 1, float(_duty(unit)[upto, unit.worn_axis - 1].sum())))
        if not used:
            raise ValueError(f"load_life: no train unit reaches the failure wear {failure_wear:g} %")
        self.axes_ = np.array([a for a, _ in used])
        self.consumed_ = np.array([c for _, c in used])
        return self

    def predict(self, unit: files.Unit) -> np.ndarray:
        duty = _duty(unit)
        now = float(unit.arrays["cycles"][-1])
        so_far = duty.sum(axis=0)[self.axes_]
        rate = _rate(unit, duty)[self.axes_]
        left = self.consumed_ - so_far
        keep = left > 0
        if keep.any():
            left, rate = left[keep], rate[keep]
        with np.errstate(divide="ignore"):
            out = now + np.where(rate > 0, np.maximum(left, 0.0) / np.where(rate > 0, rate, 1.0), np.inf)
        return np.minimum(out, MAX_TIME)


def _inverse(law: str, share: np.ndarray) -> np.ndarray:
    """The wear age at ``share`` of the failure wear by ``law`` (:func:`prognostics_v3.growth`'s inverse)."""
    if law == "linear":
        return share
    if law.startswith("power"):
        return share ** (1.0 / float(law[5:]))
    return np.log1p(share * np.expm1(prognostics_v3.EXP_K)) / prognostics_v3.EXP_K


def fit_law(age_duty: np.ndarray, wear: np.ndarray, failure_wear: float) -> tuple[str, float]:
    """(law, scale ``c``) of the growth law of :data:`prognostics_v3.LAWS` that best fits ``wear`` (%)
    against the cumulative duty ``age_duty`` as ``failure_wear G(c age_duty)``: for each law ``c`` by
    least squares of the law's inverse on the duty, the law with the least squared wear error."""
    best = None
    share = np.asarray(wear, dtype=float) / failure_wear
    for law in prognostics_v3.LAWS:
        x = _inverse(law, share)
        c = float(x @ age_duty / (age_duty @ age_duty))
        error = float(np.sum((failure_wear * prognostics_v3.growth(law, c * age_duty) - wear) ** 2))
        if best is None or error < best[2]:
            best = (law, c, error)
    return best[0], best[1]


class Oracle:
    """The oracle (module docstring): reads the labelled records so far."""

    failure_wear = prognostics_v3.FAILURE_WEAR

    def fit(self, units: list[files.Unit], failure_wear: float) -> Oracle:
        self.failure_wear = failure_wear
        return self

    def predict(self, unit: files.Unit):
        if unit.fault_level is None or unit.worn_axis is None:
            raise ValueError("oracle: the unit's labels are needed (the scoring gives them)")
        if not unit.worn_axis:
            return np.array([np.inf])
        wear = np.asarray(unit.fault_level, dtype=float)
        worn = np.flatnonzero(wear > 0)
        if worn.size < 2:
            return None
        duty = _duty(unit)[:, unit.worn_axis - 1]
        age = np.cumsum(np.where(np.arange(len(wear)) >= worn[0], duty, 0.0))
        law, c = fit_law(age[worn], wear[worn], self.failure_wear)
        now = float(unit.arrays["cycles"][-1])
        rate = _rate(unit, _duty(unit))[unit.worn_axis - 1]
        if c <= 0 or rate <= 0:
            return np.array([np.inf])
        return np.array([min(now + max(1.0 / c - age[-1], 0.0) / rate, MAX_TIME)])
