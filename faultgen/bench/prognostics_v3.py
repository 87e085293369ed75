"""The prognostics track's version 3 units (issue 85): a fleet's daily records whose lives vary with
duty and unit, drawn at the record level (one record a day per unit), with the truth apart.

**Why the record level.** Version 3 asks for 240-365 days of records on some 120 units (train,
test and eight test variants): through the dynamics simulators that is days of CPU; the daily
aggregate a controller logs (:data:`faultgen.bench.files.OBSERVABLES`) is drawn here from a load
model of a KR210-class arm instead. What a method reads is what versions 1 and 2 give (the mean
absolute torque per axis, the payload, the joint temperatures, the friction tests' readings) and
the duty of the day (``speed_override``, ``operating_hours``); the torques are not a dynamics
simulation (docs/bench/prognostics.md, version 3).

**Duty.** Per unit: a mean payload (kg, uniform in :data:`PAYLOAD`), a speed override (uniform in
:data:`OVERRIDE`), shifts (one, two or three: :data:`SHIFT_HOURS`), each with day-to-day variation, no
work on Sundays, and with probability 1/2 one change of program (payload and override drawn again)
on a day of the record. Per axis ``j`` and day the average output torque is
``T_j = BASE_j + PER_KG_j payload + INERTIAL_j override^2`` (N m) and speed ``n_j = SPEED_j override``
(rad/s), and the day consumes ``hours n_j / n_N (T_j / T_N)^p`` of the rated life (the load-life
law of Harmonic Drive's and Nabtesco's catalogues, ISO 281's form, as ``faultgen.monitor.life``
integrates it; ``p`` = 10/3 for the RV gears of axes 1-3, 3 for the strain-wave gears of 4-6):
:func:`consumption`. The **relative duty** is the day's consumption over that of the reference day
(:data:`REFERENCE`).

**Wear.** A worn unit's axis (1-5) starts wearing on a day in :data:`ONSET`; its wear age is
``x(t) = u sum_{onset..t} duty / LIFE_DAYS`` with ``u`` the unit factor (log-normal, sigma
:data:`UNIT_SIGMA`), and its wear ``FAILURE_WEAR G(x)`` % of its dry friction, ``G`` one of
:data:`LAWS` (linear ``x``, power ``x^1.5`` and ``x^2``, exponential ``(e^{kx} - 1) / (e^k - 1)``,
``k`` = :data:`EXP_K`), all reaching the failure wear at ``x = 1``: the end of life (the wear grows on
after it, capped at :data:`WEAR_CAP`, to the record's end, which does not tell the end of life). A unit whose
wear does not reach it within its record is censored; :data:`HEALTHY_SHARE` of the units wear no
axis.

**Records.** One a working day (a Sunday, without work, logs none; ``cycles`` is the day number).
The mean absolute torque of axis ``j`` is its load torque plus its friction:
``T_j + F_j (1 + w_j / 100) theta(T_joint) s_j(d) + V_j n_j`` with ``F_j``, ``V_j`` the unit's dry and
viscous friction (spread per unit), ``theta`` the friction's fall with temperature, ``s_j(d)`` the
**daily friction scatter** (log-normal, sigma :data:`SCATTER`; 1 in the variants without it) and a
measurement noise. A **friction test** every ``k`` days (days 1, 1 + k, ...) reads each axis's dry
friction with a 2 % noise (:data:`faultgen.bench.files.TEST_ARRAYS`). Every draw comes from its own
stream (``[seed, unit, component]``), so the variants (:data:`VARIANTS`) hold the same units, duty
and wear, and a variant's test readings on a day are the same in every variant that tests that day.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from faultgen.bench import files

FAILURE_WEAR = 40.0
#: The wear grows on after the end of life (the records go on to the record's end) up to this, %.
WEAR_CAP = 100.0
LAWS = ("linear", "power1.5", "power2", "exponential")
EXP_K = 3.0
ONSET = (5, 150)
RECORD_DAYS = (240, 365)
#: Days from the onset to the end of life at the reference duty with a unit factor of 1.
LIFE_DAYS = 90.0
UNIT_SIGMA = 0.4
HEALTHY_SHARE = 0.15
PAYLOAD = (10.0, 30.0)
OVERRIDE = (0.7, 1.0)
SHIFT_HOURS = (7.5, 15.0, 22.0)
SCATTER = 0.05
#: Axes 1-6 of a KR210-class arm: load torque with no payload and per kg of payload (N m, N m/kg),
#: inertial torque at override 1 (N m), mean speed at override 1 (rad/s), dry and viscous friction.
BASE = np.array([180.0, 900.0, 450.0, 60.0, 70.0, 25.0])
PER_KG = np.array([3.0, 14.0, 7.0, 1.0, 1.2, 0.4])
INERTIAL = np.array([30.0, 120.0, 60.0, 5.0, 6.0, 2.0])
SPEED = np.array([0.8, 0.6, 0.7, 1.5, 1.5, 2.0])
DRY = np.array([45.0, 70.0, 50.0, 12.0, 12.0, 6.0])
VISCOUS = np.array([40.0, 60.0, 40.0, 8.0, 8.0, 4.0])
#: The gears' rated output torque (N m) and speed (rad/s), and their life exponents (RV 10/3, strain wave 3).
RATED_TORQUE = np.array([2500.0, 6000.0, 3000.0, 500.0, 500.0, 200.0])
RATED_SPEED = np.array([1.5, 1.5, 1.5, 3.0, 3.0, 3.0])
EXPONENT = np.array([10 / 3, 10 / 3, 10 / 3, 3.0, 3.0, 3.0])
#: The reference day of the relative duty: payload 20 kg, override 0.85, 16 h.
REFERENCE = (20.0, 0.85, 16.0)
#: The friction tests' reading noise, share of the axis's dry friction (one standard deviation).
TEST_NOISE = 0.02
#: The test split's variants: name -> (daily friction scatter, days between friction tests, 0 none);
#: ``test.h5`` is :data:`DEFAULT_VARIANT`, each other one ``test-<name>.h5``.
VARIANTS = {f"{s}-{k or 'none'}": (s == "scatter", k) for s in ("scatter", "noscatter") for k in (14, 7, 28, 0)}
DEFAULT_VARIANT = "scatter-14"
_PLAN, _DUTY, _CLIMATE, _SCATTER, _NOISE, _TESTS = range(6)


def consumption(payload, override, hours) -> np.ndarray:
    """Each axis's consumption of its rated life per day (module docstring), arrays of shape (days,)
    in, (days, 6) out; 1 / h units (the rated life left out: it divides every day alike)."""
    payload, override, hours = (np.asarray(v, dtype=float)[:, None] for v in (payload, override, hours))
    torque = BASE + PER_KG * payload + INERTIAL * override ** 2
    return hours * (SPEED * override / RATED_SPEED) * (torque / RATED_TORQUE) ** EXPONENT


def relative_duty(payload, override, hours) -> np.ndarray:
    """:func:`consumption` over the reference day's (:data:`REFERENCE`): shape (days, 6)."""
    ref = consumption(*([v] for v in REFERENCE))
    return consumption(payload, override, hours) / ref


def growth(law: str, x) -> np.ndarray:
    """The share of the failure wear at wear age ``x`` (>= 0) by ``law`` (:data:`LAWS`): 1 at ``x = 1``."""
    x = np.maximum(np.asarray(x, dtype=float), 0.0)
    if law == "linear":
        return x
    if law.startswith("power"):
        return x ** float(law[5:])
    if law == "exponential":
        return np.expm1(EXP_K * x) / np.expm1(EXP_K)
    raise ValueError(f"growth law {law!r}; expected one of {', '.join(LAWS)}")


@dataclass
class Truth:
    """One unit's plan and truth: its duty per day, its worn axis (0 none), law, onset, unit factor,
    wear per day (%), end of life (the day, or None: censored or healthy)."""

    index: int
    days: int
    payload: np.ndarray
    override: np.ndarray
    hours: np.ndarray
    axis: int
    law: str
    onset: int
    factor: float
    wear: np.ndarray
    eol: int | None


def _rng(seed: int, index: int, component: int) -> np.random.Generator:
    return np.random.default_rng([seed, index, component])


def _duty(seed: int, index: int, days: int, plan: np.random.Generator):
    """(payload kg, override, hours) per day 1..days of unit ``index``."""
    rng = _rng(seed, index, _DUTY)
    means = [(plan.uniform(*PAYLOAD), plan.uniform(*OVERRIDE))]
    hours_mean = SHIFT_HOURS[int(plan.integers(len(SHIFT_HOURS)))]
    change = int(plan.integers(1, days)) if plan.random() < 0.5 else days + 1
    means.append((plan.uniform(*PAYLOAD), plan.uniform(*OVERRIDE)))
    day = np.arange(1, days + 1)
    which = (day >= change).astype(int)
    mean_payload = np.array([m[0] for m in means])[which]
    mean_override = np.array([m[1] for m in means])[which]
    payload = np.clip(mean_payload * rng.uniform(0.8, 1.2, days), 0.0, None)
    override = np.clip(mean_override + rng.normal(0.0, 0.03, days), 0.3, 1.0)
    hours = hours_mean * rng.uniform(0.85, 1.0, days) * (day % 7 != 0)  # no work on Sundays
    return payload, override, hours


def truth(seed: int, index: int, days: tuple[int, int] = RECORD_DAYS, onset: tuple[int, int] = ONSET,
          life_days: float = LIFE_DAYS) -> Truth:
    """Unit ``index`` of the fleet seeded ``seed`` (module docstring)."""
    plan = _rng(seed, index, _PLAN)
    n = int(plan.integers(days[0], days[1] + 1))
    healthy = plan.random() < HEALTHY_SHARE
    axis = 0 if healthy else int(plan.integers(1, 6))
    law = LAWS[int(plan.integers(len(LAWS)))]
    start = int(plan.integers(onset[0], onset[1] + 1))
    factor = float(np.exp(plan.normal(0.0, UNIT_SIGMA)))
    payload, override, hours = _duty(seed, index, n, plan)
    wear = np.zeros(n)
    eol = None
    if axis:
        duty = relative_duty(payload, override, hours)[:, axis - 1]
        age = factor * np.cumsum(np.where(np.arange(1, n + 1) >= start, duty, 0.0)) / life_days
        wear = np.minimum(FAILURE_WEAR * growth(law, age), WEAR_CAP)
        reached = np.flatnonzero(wear >= FAILURE_WEAR)
        eol = int(reached[0]) + 1 if reached.size else None
    return Truth(index, n, payload, override, hours, axis, law, start, factor, wear, eol)


def fleet(seed: int, failing: int, **sizes) -> list[Truth]:
    """Units 0, 1, ... of the fleet ``seed`` up to the one that makes ``failing`` units reach their end
    of life within their records (the censored and healthy units drawn on the way kept)."""
    out, reached, index = [], 0, 0
    while reached < failing:
        unit = truth(seed, index, **sizes)
        out.append(unit)
        reached += unit.eol is not None
        index += 1
    return out


def observe(seed: int, unit: Truth, variant: str = DEFAULT_VARIANT) -> files.Unit:
    """The records of ``unit`` in ``variant`` (:data:`VARIANTS`), labelled (fault_level: the worn axis's
    wear; 0 for a healthy unit)."""
    scatter_on, every = VARIANTS[variant]
    n, k = unit.days, unit.index
    day = np.arange(1, n + 1)
    plan = _rng(seed, k, _CLIMATE)
    dry = DRY * np.exp(plan.normal(0.0, 0.1, 6))
    viscous = VISCOUS * np.exp(plan.normal(0.0, 0.1, 6))
    phase = plan.uniform(0.0, 365.0)
    ambient = 18.0 + 6.0 * np.sin(2 * np.pi * (day + phase) / 365.0) + plan.normal(0.0, 1.0, n)
    joint = ambient[:, None] + 8.0 * unit.override[:, None] * (unit.hours[:, None] > 0) + plan.normal(0.0, 0.5, (n, 6))
    wear = np.zeros((n, 6))
    if unit.axis:
        wear[:, unit.axis - 1] = unit.wear
    scatter = np.exp(_rng(seed, k, _SCATTER).normal(0.0, SCATTER, (n, 6))) if scatter_on else np.ones((n, 6))
    friction = dry * (1.0 + wear / 100.0) * np.exp(-0.012 * (joint - 20.0)) * scatter
    load = BASE + PER_KG * unit.payload[:, None] + INERTIAL * unit.override[:, None] ** 2
    torque = load + friction + viscous * SPEED * unit.override[:, None]
    torque *= 1.0 + _rng(seed, k, _NOISE).normal(0.0, 0.003, (n, 6))
    arrays = {"cycles": day.astype(np.int64), "day": day.astype(float), "mean_abs_torque": torque,
              "payload_mass": unit.payload, "speed_override": unit.override, "operating_hours": unit.hours,
              "ambient_temperature": ambient, "joint_temperature": joint}
    if every:
        arrays.update(_tests(seed, unit, every, friction, viscous, joint))
    worked = unit.hours > 0  # a day without work (Sunday) logs no record
    arrays = {name: values[worked] for name, values in arrays.items()}
    out = files.Unit(id="", robot="kr210", task="pick_place", sample="day", arrays=arrays)
    out.fault_level, out.worn_axis = unit.wear[worked], unit.axis
    out.fault = "friction_wear" if unit.axis else "none"
    return out


def _tests(seed: int, unit: Truth, every: int, friction, viscous, joint) -> dict:
    """The friction tests' arrays (:data:`faultgen.bench.files.TEST_ARRAYS`) on days 1, 1 + every, ..."""
    n = unit.days
    noise = _rng(seed, unit.index, _TESTS).normal(0.0, TEST_NOISE, (n, 6)) * DRY  # a draw for every day
    on = (np.arange(n) % every) == 0
    sigma = TEST_NOISE * DRY
    coulomb = np.where(on[:, None], friction + noise, 0.0)
    return {"friction_test": on.astype(np.int8), "friction_test_coulomb": coulomb,
            "friction_test_coulomb_low": np.where(on[:, None], coulomb - 1.96 * sigma, 0.0),
            "friction_test_coulomb_high": np.where(on[:, None], coulomb + 1.96 * sigma, 0.0),
            "friction_test_viscous": np.where(on[:, None], viscous, 0.0),
            "friction_test_temperature": np.where(on[:, None], joint, 0.0)}


def split_units(spec: dict, variants: tuple[str, ...] = (DEFAULT_VARIANT,)) -> dict[str, list[files.Unit]]:
    """A ``records`` part's units for one seed (``spec``: ``seed``, ``failing``, and optionally ``days``,
    ``onset``, ``life_days``) in each of ``variants``: variant -> units, in the fleet's order."""
    sizes = {key: tuple(spec[key]) if key in ("days", "onset") else float(spec[key])
             for key in ("days", "onset", "life_days") if key in spec}
    units = fleet(int(spec["seed"]), int(spec["failing"]), **sizes)
    return {name: [observe(int(spec["seed"]), unit, name) for unit in units] for name in variants}


def lives_summary(units: list[Truth]) -> dict:
    """The lives' figures a card states: units, failing, censored, healthy, and the coefficient of
    variation of the failing units' lives (end-of-life days)."""
    lives = np.array([u.eol for u in units if u.eol is not None], dtype=float)
    return {"units": len(units), "failing": int(lives.size), "healthy": sum(not u.axis for u in units),
            "censored": sum(bool(u.axis) and u.eol is None for u in units),
            "life_cv": float(lives.std(ddof=1) / lives.mean()) if lives.size > 1 else float("nan"),
            "life_range": [float(lives.min()), float(lives.max())] if lives.size else []}
