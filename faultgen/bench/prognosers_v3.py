"""The prognostics track version 3's own baselines beside the naive and the health-index fits
(:mod:`faultgen.bench.degradation`): the load-based rated life, a fit of the friction tests
(:class:`TestsFit`, below) and the oracle.

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


#: The friction tests' fit (:class:`TestsFit`): scales of the wear age (1 / duty-days to the end of
#: life), onsets tried at most, draws of its distribution, and the fitted wear now (%) it predicts from.
SCALES = np.geomspace(1 / 3000.0, 1 / 15.0, 90)
ONSETS = 40
DRAWS = 200
DETECT = 8.0


class TestsFit:
    """A condition-based prognoser on the friction tests (``tests_fit``; not the twin).

    From the train split it learns the dry friction's temperature slope ``b`` (least squares of each
    test's log level, its true wear taken out, on its temperature, per unit and axis centred). On a
    test unit, each test's level ``y = log(dry) - b (T - 20)`` per axis; the axis whose last three
    tests rose most over its first three; on it the model ``y = L0 + log(1 + 0.4 G(c (A - A0)+))`` with
    ``A`` the cumulative logged duty (the load-life law of the card), fitted on a grid of every growth
    law of :data:`prognostics_v3.LAWS`, :data:`SCALES` for ``c`` and up to :data:`ONSETS` onsets
    ``A0`` (``L0`` at its least-squares value): the grid's likelihood under a Gaussian noise of the
    best fit's variance weighs it, and :data:`DRAWS` draws from it (seeded by the records shown) give
    the end of life ``A = A0 + 1/c`` at the last :data:`WINDOW` days' duty. No prediction with fewer
    than 4 tests or while the best fit's wear now is under :data:`DETECT` %."""

    def fit(self, units: list[files.Unit], failure_wear: float) -> TestsFit:
        xs, ys = [], []
        for unit in units:
            on = np.flatnonzero(np.asarray(unit.arrays.get("friction_test", ()), dtype=bool))
            if on.size < 3 or unit.fault_level is None:
                continue
            wear = np.zeros((on.size, 6))
            if unit.worn_axis:
                wear[:, unit.worn_axis - 1] = np.asarray(unit.fault_level)[on]
            level = np.log(np.maximum(np.asarray(unit.arrays["friction_test_coulomb"])[on], 1e-9)) - np.log1p(wear / 100)
            temp = np.asarray(unit.arrays["friction_test_temperature"])[on]
            xs.append(temp - temp.mean(axis=0))
            ys.append(level - level.mean(axis=0))
        if not xs:
            raise ValueError("tests_fit: no train unit with three friction tests")
        x, y = np.concatenate(xs).ravel(), np.concatenate(ys).ravel()
        self.slope_, self.failure_wear = float(x @ y / (x @ x)), failure_wear
        return self

    def predict(self, unit: files.Unit):
        on = np.flatnonzero(np.asarray(unit.arrays.get("friction_test", ()), dtype=bool))
        if on.size < 4:
            return None
        level = np.log(np.maximum(np.asarray(unit.arrays["friction_test_coulomb"])[on], 1e-9))
        level -= self.slope_ * (np.asarray(unit.arrays["friction_test_temperature"])[on] - 20.0)
        axis = int(np.argmax(level[-3:].mean(axis=0) - np.median(level[:3], axis=0)))
        y = level[:, axis]
        duty = _duty(unit)
        cumulative = np.cumsum(duty[:, axis])
        onsets = np.unique(cumulative[np.linspace(0, on[-1], min(ONSETS, on[-1] + 1)).astype(int)]) - 1e-9
        age = np.maximum(cumulative[on][None, :] - onsets[:, None], 0.0)  # (onsets, tests)
        fits = []
        for law in prognostics_v3.LAWS:
            shape = np.log1p(self.failure_wear / 100.0 * prognostics_v3.growth(law, SCALES[:, None, None] * age[None]))
            residual = y - shape
            residual -= residual.mean(axis=-1, keepdims=True)  # L0 at its least-squares value
            fits.append((np.sum(residual ** 2, axis=-1), shape[..., -1]))  # (scales, onsets)
        sse = np.stack([f[0] for f in fits])  # (laws, scales, onsets)
        now_wear = 100.0 * np.expm1(np.stack([f[1] for f in fits]))
        best = np.unravel_index(int(np.argmin(sse)), sse.shape)
        if now_wear[best] < DETECT:
            return None
        variance = max(float(sse[best]) / max(on.size - 3, 1), 1e-12)
        weight = np.exp(-(sse - sse[best]) / (2.0 * variance)).ravel()
        picked = np.random.default_rng(len(unit.arrays["cycles"])).choice(weight.size, DRAWS, p=weight / weight.sum())
        _, scale, start = np.unravel_index(picked, sse.shape)
        now = float(unit.arrays["cycles"][-1])
        rate = _rate(unit, duty)[axis]
        left = np.maximum(onsets[start] + 1.0 / SCALES[scale] - cumulative[-1], 0.0)
        return np.minimum(now + left / rate, MAX_TIME) if rate > 0 else np.full(DRAWS, np.inf)
