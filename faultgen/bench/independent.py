"""A "real" fleet's measured logs made by a simulator that is not faultgen: the test split of the
sim-to-real track (docs/bench/sim-to-real.md) and the check of ``faultgen monitor``
(tests/test_monitor.py, benchmarks/monitor_loop.py). faultgen's simulation never uses it.

What is independent and what is ours:

- **Rigid-body dynamics: Pinocchio's** recursive Newton-Euler (``pin.rnea``) on the robot folder's
  ``urdf_used.urdf`` (the URDF as faultgen compiled it, read by Pinocchio's own URDF parser): for the
  benchmark, rtb-data's KR210 L150 URDF (ROS-Industrial's ``kuka_kr210_support``), the robot added to
  faultgen as a user would (``faultgen robots add kr210 --from kr210l150.urdf``; the bench adds it
  with the track version's sizing rule, :func:`faultgen.bench.make.add_robots`: its drives, and so
  this simulator's friction and motor inertia, are the folder's); the payload a box at
  the flange (the URDF's ``tool0`` frame) placed by Pinocchio (:func:`pinocchio_model`). The plant's
  dynamics, motions and friction law are in :mod:`faultgen.bench.plant`.
- **Motor-side friction: ours, written here, in a form faultgen does not use**: at motor speed
  ``w = G qd`` (rad/s), ``f(w) = (Fc + Fs / (1 + (w / ws)^2)) (2 / pi) atan(w / we) + Fv(T) w``
  (a Lorentzian Stribeck hump and an arctangent sign, where faultgen's eq. 6.3 has an exponential
  hump and its own smoothing), referred to the arm through the gear ratio, ``G f(G qd)``; viscous
  friction falling with the joint temperature, ``Fv(T) = Fv0 exp(-VISCOUS_PER_K (T - 20 C))``
  (an Andrade-like law, ours); with :attr:`FleetSpec.dry_per_k` the dry levels ``Fc``, ``Fs`` fall
  as ``1 - dry_per_k (T - 20 C)`` (none by default). Both laws are deterministic: what scatters is
  the day's draw below. The magnitudes of ``Fc``, ``Fs``, ``Fv0`` are the robot folder's
  nominal ones (``drivetrain.toml``), each unit drawing its own (log-normal, :data:`SPREAD`), each
  log scattering about them, dry and viscous alike (log-normal, :attr:`FleetSpec.log_jitter`, by
  default :data:`JITTER`; a friction test by its own :attr:`FleetSpec.test_jitter`); the reflected motor inertia ``G^2 Jm qdd`` with the folder's
  ``Jm``.
- **Conditions: ours**: a seasonal hall temperature (each unit its own mean and swing, on the
  calendar of its stamps: January cold) plus the joints' warm-up; a product change every week
  between two parts per unit (drawn masses up to :attr:`FleetSpec.max_part`; aluminium cubes
  hanging from the flange, as declared in the robot's load data), and from a drawn day between 5/12 and 2/3 of the record a third part
  (a new product) among them; Gaussian torque noise (:data:`NOISE` of each axis's
  torque RMS) and angle noise.
- **Wear: ours**: on a worn unit, one axis (of :attr:`FleetSpec.wearable`) has its Coulomb and
  Stribeck friction grow from an onset day to :attr:`FleetSpec.final_wear` percent on the last day,
  linearly by default (:attr:`FleetSpec.wear_growth` a power, :attr:`FleetSpec.wear_laws` linear,
  quadratic or exponential laws: :func:`faultgen.bench.cell.wear_fraction`).
- **Maintenance and program changes: ours** (none by default): on
  :attr:`FleetSpec.gearbox_changes` worn units the worn axis's gearbox is changed
  :data:`CHANGE_DELAY` days after the wear passed :data:`CHANGE_WEAR` %: from that day the axis's
  friction is the folder's nominal one (a new gearbox: no wear, no unit spread), logged in
  ``logs/events.csv`` (``unit, stamp, event, axis``, the layout ``faultgen monitor`` reads); on
  :attr:`FleetSpec.program_changes` healthy units the program changes on a drawn day nobody logs
  (the pick and place targets :data:`PROGRAM_SHRINK` of the way from the start pose: other target
  poses, another motion). Both in ``ROOT/changes.csv`` (``unit, stamp, change, axis``), the truth,
  never read by the monitor.
- The motion: the robot folder's generated ``pick_place`` cycle (faultgen's planner; the motion is
  logged, so any would do), one cycle per log at :attr:`FleetSpec.rate` by default; with
  :attr:`FleetSpec.cycles` and :attr:`FleetSpec.rates` each log holds a drawn number of back-to-back
  cycles (no ``cycle`` column) at a drawn rate, from a stream of their own
  (:func:`faultgen.bench.layouts.draws`).
- **A real cell: ours** (off by default; :mod:`faultgen.bench.cell`): :attr:`FleetSpec.programs`
  variants of the pick and place in the cell, each unit running a subset (:attr:`FleetSpec.unit_programs`),
  one a day; logs of a random span of cycles from a random phase (:attr:`FleetSpec.span`). Their
  truth per log in ``ROOT/truth_programs.csv`` (:data:`PROGRAM_COLUMNS`), never read by the monitor.
- **Friction tests: the motion faultgen's, the plant ours** (none by default): with
  :attr:`FleetSpec.friction_test_every` ``= D`` every unit runs a friction test on days 1, 1 + D,
  1 + 2 D, ...: the motion of ``faultgen tasks friction-test`` for the robot folder
  (:func:`faultgen.operation.friction_test.program`: each axis in turn at constant speeds both ways)
  driven through this module's dynamics and friction law (Pinocchio's RNEA, no part, the reflected
  motor inertia, :func:`motor_friction` with the day's levels, wear and gearbox), so that the test's
  friction is the plant's; run warm (the day's joint temperature) or cold (before the warm-up: the
  hall's temperature that day), drawn per test (:data:`COLD_SHARE`) and logged, with its own per-log
  scatter and the same noise model. Drawn from a stream of their own (the unit's seed and the
  day): the daily logs are the same with or without tests. Written as
  ``logs/<unit>/friction-test/<stamp>.csv`` (the daily logs' columns, payload 0; the stamp the day's
  date), their truth apart in ``ROOT/truth_tests.csv`` (:data:`TEST_TRUTH_COLUMNS`: per test and axis
  the Coulomb level and viscous coefficient the plant had, arm side, at the test's temperature).

Output (:func:`write_fleet`), the layout ``faultgen logs import`` reads: ``ROOT/logs/<unit>/<stamp>.csv``
with ``t, q1..qN, tau1..tauN, temperature1..N, payload`` (s, rad, N m arm side, deg C, kg), the
stamps ISO dates, one log a day; and the truth apart, ``ROOT/truth.csv``: ``unit, stamp,
worn_axis, wear_percent`` for every log (worn_axis 0 on a healthy unit). Same seed, identical
files. Each log is written atomically and a unit's logs are drawn in one go, so that a write stopped
part-way resumes at the first unit not complete (:func:`write_fleet`).

Needs Pinocchio (``pin``, the ``bench`` extra: ``pip install 'faultgen-robots[bench]'``).
"""

from __future__ import annotations

import csv
import datetime
import io
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from faultgen.bench import cell, layouts, plant
from faultgen.bench.plant import (  # noqa: F401  (the plant's names, read as this module's by tests and benchmarks)
    ANGLE_NOISE,
    FLANGE_FRAME,
    NOISE,
    PART_DENSITY,
    PLAN_RATE,
    PROGRAM_SHRINK,
    SIGN_SPEED,
    STRIBECK_SPEED,
    changed_program,
    friction_test_motion,
    motor_friction,
    pinocchio_model,
    pinocchio_module,
    write_friction_test,
)
from faultgen.data import cells
from faultgen.model import robots
from faultgen.logs.columns import PAYLOAD_COLUMN, T_COLUMN, column_names, temperature_columns

_motion, _rigid, _write_csv = plant.motion, plant.rigid, plant.write_csv
#: Unit-to-unit spread of each friction parameter (log-normal sigma) and its day-to-day scatter,
#: drawn per log and parameter and not logged (the state of the lubricant film, the warm-up the
#: log's hour caught): ours. At 1 % the features of a log repeat to about 0.3 %, and the monitor
#: flagged worn units at 3-8 % wear, before the issue's window (docs/analysis.md). The scatter of the
#: logs and of the tests are :attr:`FleetSpec.log_jitter` and :attr:`FleetSpec.test_jitter`.
SPREAD = 0.15
JITTER = 0.03
#: Viscous friction's fall per kelvin of joint temperature (ours: gear oil thins as it warms).
VISCOUS_PER_K = 0.02
#: Axes that may wear by default (the KR210's axis 6 motor sized by rule 1 is rated 3 N m: its
#: friction is at the noise floor).
WEARABLE = (1, 2, 3, 4, 5)
#: The heaviest part by default, kg (the parts' draws are scaled to :attr:`FleetSpec.max_part`).
MAX_PART = 35.0
#: A gearbox change comes this many days after the worn axis's wear passed CHANGE_WEAR percent.
CHANGE_WEAR, CHANGE_DELAY = 20.0, 10
#: The columns of changes.csv (the truth of the gearbox and program changes).
CHANGE_COLUMNS = ("unit", "stamp", "change", "axis")
#: The columns of truth_programs.csv (a cell of several programs or logs cut anywhere: :mod:`faultgen.bench.cell`):
#: per log its program (0-based), the cycles its samples span and the phase of a cycle it starts at.
PROGRAM_COLUMNS = ("unit", "stamp", "program", "span_cycles", "phase")
#: The columns of truth.csv.
TRUTH_COLUMNS = ("unit", "stamp", "worn_axis", "wear_percent")
#: A unit's friction tests are in this folder of its log folder.
TEST_FOLDER = "friction-test"
#: The columns of truth_tests.csv: per test and axis (1-based) the plant's Coulomb level (N m) and
#: viscous coefficient (N m s/rad), arm side, at the test's joint temperature (deg C, as logged).
TEST_TRUTH_COLUMNS = ("unit", "stamp", "axis", "coulomb_Nm", "viscous_Nms_rad", "temperature_degC")
#: The share of friction tests run cold (before the warm-up: the joints at the hall's temperature).
COLD_SHARE = 0.5


@dataclass(frozen=True)
class FleetSpec:
    """The fleet: ``units`` robots (``worn`` of them wearing), one log a day for ``days`` days from
    ``start``; logs at ``rate`` Hz; a worn unit's wear starts on a day drawn in ``onset`` (1-based)
    and reaches ``final_wear`` % on the last day, on one of the axes ``wearable`` (1-based); parts
    up to ``max_part`` kg (``rated_part``: the fleet's heaviest part drawn is made ``max_part``
    itself, the rated payload carried); ``gearbox_changes`` worn units get a new gearbox on the worn axis and
    ``program_changes`` healthy units an unlogged program change; every ``friction_test_every`` days
    (0: never) each unit runs a friction test (module docstring), its friction scattering by
    ``test_jitter`` (log-normal sigma, as :data:`JITTER` for a log: the test's repeatability, by
    default a log's; a protocol with its own warm-up may repeat better) and a daily log's by
    ``log_jitter``; ``dry_per_k`` the dry friction's fall per kelvin above 20 deg C (a deterministic
    law, as the viscous one, :data:`VISCOUS_PER_K`; 0 by default); ``wear_growth`` the exponent of the
    wear's rise (:func:`wear_percent`; 1, linear, by default), or ``wear_laws`` the laws given to the
    worn units in turn (:data:`faultgen.bench.cell.WEAR_LAWS`), the first worn units wearing
    ``wear_rates`` points a day from their onset instead (a fast and a slow wear); each log holds a number of
    back-to-back cycles drawn from ``cycles`` at a rate drawn from ``rates`` Hz (empty: ``rate``;
    :func:`faultgen.bench.layouts.draws`), or with ``span`` ``(a, b)`` a span of ``a``-``b`` cycles
    from a random phase; the cell has ``programs`` programs, each unit running as many as
    ``unit_programs`` gives it in turn, one a day (:mod:`faultgen.bench.cell`). Every draw comes from
    ``seed``; the defaults draw what the fleet drew before these options existed."""

    units: int = 12
    worn: int = 8
    days: int = 120
    seed: int = 0
    rate: float = 125.0
    start: str = "2026-01-05"
    onset: tuple[int, int] = (20, 50)
    final_wear: float = 60.0
    wearable: tuple[int, ...] = WEARABLE
    max_part: float = MAX_PART
    rated_part: bool = False
    gearbox_changes: int = 0
    program_changes: int = 0
    friction_test_every: int = 0
    test_jitter: float = JITTER
    wear_growth: float = 1.0
    cycles: tuple[int, ...] = (1,)
    rates: tuple[float, ...] = ()
    log_jitter: float = JITTER
    dry_per_k: float = 0.0
    wear_laws: tuple[str, ...] = ()
    programs: int = 1
    unit_programs: tuple[int, ...] = (1,)
    span: tuple[float, ...] = ()
    wear_rates: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        for name, value in cell.check(self).items():
            object.__setattr__(self, name, value)
        cycles, rates = layouts.check(self.cycles, (*self.rates, self.rate), PLAN_RATE)
        object.__setattr__(self, "cycles", cycles)
        object.__setattr__(self, "rates", rates[:-1])
        if isinstance(self.wear_growth, bool) or not 1.0 <= float(self.wear_growth) <= 4.0:
            raise ValueError(f"fleet wear_growth = {self.wear_growth!r}: expected the wear's exponent in [1, 4] "
                             "(1: linear from the onset)")
        for name, low in (("units", 1), ("worn", 0), ("days", 2), ("seed", 0), ("gearbox_changes", 0),
                          ("program_changes", 0), ("friction_test_every", 0)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < low:
                raise ValueError(f"fleet {name} = {value!r}: expected a whole number >= {low}")
        for name, what in (("test_jitter", "a friction test's"), ("log_jitter", "a daily log's friction")):
            value = getattr(self, name)
            if isinstance(value, bool) or not 0.0 <= float(value) <= 0.5:
                raise ValueError(f"fleet {name} = {value!r}: expected {what} scatter (log-normal sigma) in [0, 0.5]")
        if isinstance(self.dry_per_k, bool) or not 0.0 <= float(self.dry_per_k) <= 0.02:
            raise ValueError(f"fleet dry_per_k = {self.dry_per_k!r}: expected the dry friction's fall per kelvin "
                             "in [0, 0.02]")
        if self.worn > self.units:
            raise ValueError(f"fleet worn = {self.worn}: more than its {self.units} units")
        onset = tuple(self.onset)
        if len(onset) != 2 or not all(isinstance(d, int) for d in onset) or not 1 <= onset[0] <= onset[1] <= self.days:
            raise ValueError(f"fleet onset = {self.onset!r}: expected two whole days, 1 <= first <= last <= {self.days}")
        object.__setattr__(self, "onset", onset)
        if not 0.0 < float(self.final_wear) <= 1000.0:
            raise ValueError(f"fleet final_wear = {self.final_wear!r}: expected a percent in (0, 1000]")
        datetime.date.fromisoformat(self.start)
        wearable = tuple(self.wearable)
        if not wearable or not all(isinstance(a, int) and not isinstance(a, bool) and a >= 1 for a in wearable):
            raise ValueError(f"fleet wearable = {self.wearable!r}: expected axes as whole numbers >= 1")
        object.__setattr__(self, "wearable", wearable)
        if not isinstance(self.rated_part, bool):
            raise TypeError(f"fleet rated_part = {self.rated_part!r}: expected True or False")
        if isinstance(self.max_part, bool) or not 0.0 < float(self.max_part) <= 10000.0:
            raise ValueError(f"fleet max_part = {self.max_part!r} kg: expected a mass in (0, 10000]")
        if self.gearbox_changes > self.worn:
            raise ValueError(f"fleet gearbox_changes = {self.gearbox_changes}: more than its {self.worn} worn units")
        if self.program_changes > self.units - self.worn:
            raise ValueError(f"fleet program_changes = {self.program_changes}: more than its "
                             f"{self.units - self.worn} healthy units")


def unit_names(spec: FleetSpec) -> list[str]:
    return [f"unit{i + 1:02d}" for i in range(spec.units)]


def stamps(spec: FleetSpec) -> list[str]:
    first = datetime.date.fromisoformat(spec.start)
    return [(first + datetime.timedelta(days=d)).isoformat() for d in range(spec.days)]


def _units(spec: FleetSpec, n_axes: int) -> list[dict]:
    if max(spec.wearable) > n_axes:
        raise ValueError(f"fleet wearable = {spec.wearable!r}: the robot has axes 1..{n_axes}")
    names = unit_names(spec)
    worn = set(np.random.default_rng([spec.seed, 0]).permutation(spec.units)[: spec.worn].tolist())
    scale = float(spec.max_part) / MAX_PART
    out = []
    for i, name in enumerate(names):
        rng = np.random.default_rng([spec.seed, i + 1])
        spread = np.exp(rng.normal(0.0, SPREAD, (3, n_axes)))
        out.append({
            "unit": name, "spread": spread,
            "axis": int(rng.choice(spec.wearable)) if i in worn else 0,
            "onset": int(rng.integers(spec.onset[0], spec.onset[1] + 1)),
            "ambient": float(rng.uniform(17.0, 23.0)), "swing": float(rng.uniform(4.0, 8.0)),
            "rise": rng.uniform(5.0, 15.0, n_axes),
            "parts": tuple(scale * float(rng.uniform(low, high)) for low, high in ((5.0, 15.0), (20.0, 35.0),
                                                                                    (10.0, 35.0))),
            "weeks": rng.integers(0, 2, spec.days // 7 + 1),
            "seed": int(rng.integers(2**31)),
            "new_part_day": int(rng.integers(spec.days * 5 // 12, spec.days * 2 // 3 + 1)),
            "new_weeks": rng.integers(0, 3, spec.days // 7 + 1),
            "gearbox_day": 0, "program_day": 0, "law": None, "rate": None, "programs": cell.unit_programs(spec, i),
        })
    if spec.rated_part:  # the heaviest part drawn becomes the heaviest allowed
        unit, k = max(((u, k) for u in out for k in range(3)), key=lambda uk: uk[0]["parts"][uk[1]])
        unit["parts"] = tuple(float(spec.max_part) if j == k else m for j, m in enumerate(unit["parts"]))
    # the changes from a stream of their own: without them, the draws above are the fleet's before
    changes = np.random.default_rng([spec.seed, 0, 1])
    worn_units = [u for u in out if u["axis"]]
    for k, u in enumerate(worn_units if spec.wear_laws else ()):  # the laws in turn, no draw
        u["law"] = spec.wear_laws[k % len(spec.wear_laws)]
    for u, rate in zip(worn_units, spec.wear_rates):  # the first worn units at their rates, no draw
        u["rate"] = rate
    for u in [worn_units[k] for k in sorted(changes.permutation(len(worn_units))[: spec.gearbox_changes])]:
        passed = next((d for d in range(1, spec.days + 1) if wear_percent(spec, u["onset"], d, u["law"], u["rate"]) >= CHANGE_WEAR), None)
        if passed is None or passed + CHANGE_DELAY > spec.days:
            raise ValueError(f"fleet gearbox_changes: {u['unit']}'s wear passes {CHANGE_WEAR:g} % on day {passed}, "
                             f"less than {CHANGE_DELAY} days before the last ({spec.days}); expected more days")
        u["gearbox_day"] = passed + CHANGE_DELAY
    healthy = [u for u in out if not u["axis"]]
    for k in sorted(changes.permutation(len(healthy))[: spec.program_changes]):
        healthy[k]["program_day"] = int(changes.integers(spec.days * 2 // 5, spec.days * 3 // 5 + 1))
    return out


def wear_percent(spec: FleetSpec, onset: int, day: int, law: str | None = None, rate: float | None = None) -> float:
    """True wear (% increase of Coulomb and Stribeck friction) on day ``day`` (1-based): ``rate``
    points a day since the onset (:attr:`FleetSpec.wear_rates`), else from the onset to
    ``final_wear`` on the last day, by ``law`` (:func:`faultgen.bench.cell.wear_fraction` of the
    share of the time since the onset) or, None, as the power ``wear_growth`` of that share (1:
    linear; 2: its rate growing in proportion to that time)."""
    if day < onset:
        return 0.0
    if rate is not None:
        return rate * (day - onset)
    if law is not None:
        return spec.final_wear * cell.wear_fraction(law, (day - onset) / max(spec.days - onset, 1))
    if spec.wear_growth == 1.0:
        return spec.final_wear * (day - onset) / max(spec.days - onset, 1)
    return spec.final_wear * ((day - onset) / max(spec.days - onset, 1)) ** spec.wear_growth


def _wear(spec: FleetSpec, unit: dict, day: int) -> float:
    """A unit's true wear on ``day``: 0 on a healthy unit and from its gearbox change on."""
    if not unit["axis"] or (unit["gearbox_day"] and day >= unit["gearbox_day"]):
        return 0.0
    return wear_percent(spec, unit["onset"], day, unit["law"], unit["rate"])


def truth_rows(spec: FleetSpec, n_axes: int = 6) -> list[list]:
    """The rows of truth.csv (:data:`TRUTH_COLUMNS`), unit by unit and day by day, without writing a log."""
    rows = []
    for unit in _units(spec, n_axes):
        for d, stamp in enumerate(stamps(spec), start=1):
            wear = _wear(spec, unit, d)
            rows.append([unit["unit"], stamp, unit["axis"], f"{wear:.4f}"])
    return rows


def own_friction(spec: FleetSpec, robot: robots.Robot) -> dict[str, np.ndarray]:
    """Each unit's own friction levels as the generator draws them, the truth apart (what a unit's
    wear is a percentage of): ``{unit: ndarray of shape (3, N)}``, the Coulomb, static (Stribeck
    hump) and viscous levels at 20 deg C, N m and N m s/rad at the motor, the ``robot`` folder's
    nominal ones times the unit's draw (:data:`SPREAD`), before each log's :data:`JITTER` and any
    wear. Read by ``benchmarks/wear_scale_sources.py``; never by the monitor."""
    f = robot.friction
    nominal = np.array([f.coulomb_pos, f.static, f.viscous], dtype=float)
    return {u["unit"]: nominal * u["spread"] for u in _units(spec, robot.n_axes)}


def day_conditions(unit: dict, day: int, stamp: str, rng: np.random.Generator) -> tuple[float, float]:
    """A unit's joint temperature (deg C: the season's ambient, one draw of ``rng`` for the day's
    weather, plus the unit's rise) and part mass (kg: the week's part, of the new product from its
    day) on ``day`` (1-based) dated ``stamp``; ``unit`` one of :func:`_units`."""
    date = datetime.date.fromisoformat(stamp)
    season = np.cos(2 * np.pi * (date.timetuple().tm_yday - 200) / 365.25)
    ambient = unit["ambient"] + unit["swing"] * season + rng.normal(0.0, 1.0)
    temperature = ambient + unit["rise"]
    week = (day - 1) // 7
    new_product = day >= unit["new_part_day"]
    mass = unit["parts"][int((unit["new_weeks"] if new_product else unit["weeks"])[week])]
    return temperature, mass


def friction_test_days(spec: FleetSpec) -> list[int]:
    """The days (1-based) of each unit's friction tests: 1, 1 + D, 1 + 2 D, ... up to ``spec.days``
    for ``D = spec.friction_test_every``; none for 0."""
    every = spec.friction_test_every
    return list(range(1, spec.days + 1, every)) if every else []


def _levels(spec: FleetSpec, unit: dict, day: int, nominal, jitter: np.ndarray, temperature) -> tuple:
    """A unit's motor-side Coulomb, static and viscous levels on ``day`` (1-based), each (N,): the
    ``nominal`` ones times the unit's spread (the nominal on a changed gearbox's axis), the wear on
    the worn axis's dry friction, the log's ``jitter`` (3, N), the viscous law (and with
    :attr:`FleetSpec.dry_per_k` the dry one) at ``temperature`` deg C."""
    fc0, fs0, fv0 = nominal
    wear = _wear(spec, unit, day)
    grow = np.ones(len(fc0))
    if unit["axis"]:
        grow[unit["axis"] - 1] += wear / 100.0
    spread = unit["spread"]
    if unit["gearbox_day"] and day >= unit["gearbox_day"]:  # a new gearbox: the nominal friction
        spread = spread.copy()
        spread[:, unit["axis"] - 1] = 1.0
    fc = fc0 * spread[0] * grow * jitter[0]
    fs = fs0 * spread[1] * grow * jitter[1]
    fv = fv0 * spread[2] * jitter[2] * np.exp(-VISCOUS_PER_K * (temperature - 20.0))
    if spec.dry_per_k:  # the dry level's deterministic law in temperature
        fall = 1.0 - spec.dry_per_k * (np.asarray(temperature, dtype=float) - 20.0)
        fc, fs = fc * fall, fs * fall
    return fc, fs, fv


@dataclass(frozen=True)
class Day:
    """One day's draws of a unit (:func:`_days`): its day (1-based) and stamp, joint ``temperature``
    (N,) deg C, part ``mass`` kg, friction ``jitter`` (3, N), whether its program ``changed``, the
    log's ``noise`` and ``angle_noise`` (n, N), and its layout: whole ``cycles`` at ``rate`` Hz of
    ``program`` (0-based), or ``span`` cycles (None: whole cycles) from ``phase``."""

    day: int
    stamp: str
    temperature: np.ndarray
    mass: float
    jitter: np.ndarray
    changed: bool
    noise: np.ndarray
    angle_noise: np.ndarray
    cycles: int
    rate: float
    program: int
    phase: float
    span: float | None


def _days(spec: FleetSpec, unit: dict, model: robots.Robot):
    """A unit's daily draws in the order the writer makes them, one :class:`Day` a day (noise and
    angle noise shaped as the day's log: :func:`faultgen.bench.layouts.draws`'s ``cycles`` of the
    motion at ``rate`` Hz, or the ``span`` of cycles from ``phase`` of the day's ``program``
    (:func:`faultgen.bench.cell.day_layouts`); a layout other than one cycle of program 0 at
    :attr:`FleetSpec.rate` draws them from its own stream, after the default layout's draws, so that
    every other draw is the same)."""
    rng = np.random.default_rng(unit["seed"])
    n = model.n_axes
    days_layout = layouts.draws(spec.cycles, spec.rates, spec.rate, unit["seed"])
    days_program = cell.day_layouts(spec, unit["seed"], unit["programs"])
    for d, stamp in enumerate(stamps(spec), start=1):
        temperature, mass = day_conditions(unit, d, stamp, rng)
        jitter = np.exp(rng.normal(0.0, spec.log_jitter, (3, n)))
        changed = bool(unit["program_day"]) and d >= unit["program_day"]
        shape = _motion(model, spec.rate, changed)[1].shape
        noise, angle_noise = rng.normal(0.0, 1.0, shape), rng.normal(0.0, ANGLE_NOISE, shape)
        cycles, rate = next(days_layout)
        program, phase, span = next(days_program)
        if (cycles, rate, program, span) != (1, spec.rate, 0, None):
            other = np.random.default_rng([unit["seed"], 3, d])
            length = len(_motion(model, rate, changed, cell.VARIANT_SHRINK[program])[1])
            shape = (cycles * length if span is None else cell.samples(length, phase, span)[1], n)
            noise, angle_noise = other.normal(0.0, 1.0, shape), other.normal(0.0, ANGLE_NOISE, shape)
        yield Day(d, stamp, temperature, mass, jitter, changed, noise, angle_noise, cycles, rate, program, phase, span)


def friction_test_draws(unit: dict, day: int, temperature: np.ndarray, n_axes: int,
                        scatter: float = JITTER) -> tuple:
    """A friction test's draws on ``day`` (1-based), from the stream of the unit's seed and the day:
    its joint temperature, deg C (N,: the day's ``temperature`` warm, the hall's, without the unit's
    warm-up rise, cold; :data:`COLD_SHARE`), its per-log ``jitter`` (3, N; log-normal, sigma ``scatter``:
    :attr:`FleetSpec.test_jitter`, the same standard normal draws at any ``scatter``) and the generator
    of its noise."""
    rng = np.random.default_rng([unit["seed"], 1, day])
    cold = rng.random() < COLD_SHARE
    jitter = np.exp(rng.normal(0.0, scatter, (3, n_axes)))
    return (temperature - unit["rise"] if cold else np.asarray(temperature, dtype=float)), jitter, rng


def friction_test_truth(unit: str, stamp: str, gear_ratio: np.ndarray, coulomb, viscous, temperature) -> list[list]:
    """truth_tests.csv's rows (:data:`TEST_TRUTH_COLUMNS`) of one test: motor-side ``coulomb`` (N m) and
    ``viscous`` (N m s/rad) levels (N,) referred to the arm (``G`` and ``G^2``), ``temperature`` as logged."""
    return [[unit, stamp, k + 1, f"{gear_ratio[k] * coulomb[k]:.6g}", f"{gear_ratio[k] ** 2 * viscous[k]:.6g}",
             f"{round(float(temperature[k]), 2):.2f}"] for k in range(len(gear_ratio))]


def log_header(n: int) -> list[str]:
    """The columns of a log of ``n`` axes: t, q1..qN, tau1..tauN, temperature1..N, payload."""
    q_names, _, tau_names = column_names(n)
    return [T_COLUMN, *q_names, *tau_names, *temperature_columns(n), PAYLOAD_COLUMN]


def write_fleet(root: Path, spec: FleetSpec, robot: Path) -> tuple[Path, Path]:
    """Write the fleet of the robot folder ``robot`` under ``root``: ``root/logs/<unit>/<stamp>.csv``
    and ``root/truth.csv``; with friction tests also ``root/logs/<unit>/friction-test/<stamp>.csv`` and
    ``root/truth_tests.csv``; returns (logs, truth).

    A unit whose folder holds every log and test (each written atomically) is kept as it is (its
    tests' truth drawn again): a write stopped part-way resumes at the first unit not complete and
    gives the same files. Same ``spec``, identical files.

    Raises
    ------
    ValueError
        For a rate that is not 250 Hz divided by a whole number.
    ImportError
        Without Pinocchio.
    """
    root = Path(root)
    model = robots.load(Path(robot))  # the independent simulator's entry: its robot folder, resolved once
    G, nominal = model.gear_ratio, model.friction
    nominal = tuple(np.asarray(x, dtype=float) for x in (nominal.coulomb_pos, nominal.static, nominal.viscous))
    n = model.n_axes
    logs = root / "logs"
    header = log_header(n)
    days = stamps(spec)
    tested = set(friction_test_days(spec))
    units = _units(spec, n)
    test_rows, program_rows = [], []
    for unit in units:
        folder_of_unit = logs / unit["unit"]
        kept = all((folder_of_unit / f"{stamp}.csv").is_file() for stamp in days) and all(
            (folder_of_unit / TEST_FOLDER / f"{days[d - 1]}.csv").is_file() for d in tested)
        folder_of_unit.mkdir(parents=True, exist_ok=True)
        for day in _days(spec, unit, model):
            d, stamp, temperature = day.day, day.stamp, day.temperature
            if d in tested:
                warmth, test_jitter, rng = friction_test_draws(unit, d, temperature, n, spec.test_jitter)
                fc, fs, fv = _levels(spec, unit, d, nominal, test_jitter, warmth)
                test_rows += friction_test_truth(unit["unit"], stamp, G, fc, fv, warmth)
                if not kept:
                    write_friction_test(folder_of_unit / TEST_FOLDER / f"{stamp}.csv", header, model, spec.rate,
                               lambda w, fc=fc, fs=fs, fv=fv: motor_friction(w, fc, fs, fv), warmth, rng)
            program_rows.append([unit["unit"], stamp, day.program,
                                 f"{day.cycles if day.span is None else day.span:.4f}", f"{day.phase:.4f}"])
            if not kept:  # a kept unit: drawn in one go from its own seed, complete, as the same seed draws it
                levels = _levels(spec, unit, d, nominal, day.jitter, temperature)
                _write_day(folder_of_unit / f"{stamp}.csv", header, model, day, levels)
    truth = root / "truth.csv"
    _write_table(truth, TRUTH_COLUMNS, truth_rows(spec, n))
    if tested:
        _write_table(root / "truth_tests.csv", TEST_TRUTH_COLUMNS, test_rows)
    events = [[u["unit"], days[u["gearbox_day"] - 1], "gearbox_change", u["axis"]] for u in units if u["gearbox_day"]]
    if events:  # the logged maintenance, which the monitor reads
        _write_table(logs / "events.csv", ("unit", "stamp", "event", "axis"), events)
    programs_ = [[u["unit"], days[u["program_day"] - 1], "program_change", ""] for u in units if u["program_day"]]
    if events or programs_:
        _write_table(root / "changes.csv", CHANGE_COLUMNS, sorted(events + programs_))
    if spec.programs > 1 or spec.span:  # the truth of a cell's programs and cut logs
        _write_table(root / "truth_programs.csv", PROGRAM_COLUMNS, program_rows)
    return logs, truth


def _write_day(path: Path, header, model: robots.Robot, day: Day, levels) -> None:
    """Write one daily log (a :class:`Day`) at ``path``: the day's program at its rate, whole
    back-to-back cycles or its span from its phase (:func:`faultgen.bench.cell.cut`), the arm-side
    torque Pinocchio's RNEA with the day's part plus the reflected motor inertia plus ``G f(G qd)``
    at the motor-side friction ``levels`` (Coulomb, static, viscous), and the noise model."""
    G, jm, rate, changed = model.gear_ratio, model.motor_inertia, day.rate, day.changed
    shrink, mass = cell.VARIANT_SHRINK[day.program], round(day.mass, 1)
    cycle = (*_motion(model, rate, changed, shrink)[1:], _rigid(model, rate, mass, changed, shrink))
    if day.span is None:
        q, qd, qdd, rigid = (np.tile(x, (day.cycles, 1)) for x in cycle)
    else:
        q, qd, qdd, rigid = (cell.cut(x, day.phase, day.span) for x in cycle)
    t = np.arange(len(q)) / rate  # back-to-back cycles: the next starts a sample after the last ends
    tau = rigid + G**2 * jm * qdd + G * motor_friction(G * qd, *levels)
    tau = tau + day.noise * NOISE * np.sqrt(np.mean(tau**2, axis=0))
    _write_csv(path, header, t, q + day.angle_noise, tau, np.round(day.temperature, 2), mass)


def _write_table(path: Path, columns, rows) -> None:
    """``path`` as CSV, written atomically and only when its content changes (a resumed write leaves it be)."""
    text = io.StringIO(newline="")
    writer = cells.writer(text)
    writer.writerow(columns)
    writer.writerows(rows)
    content = text.getvalue().encode()
    if not path.is_file() or path.read_bytes() != content:
        part = path.with_name(path.name + ".part")
        part.write_bytes(content)
        os.replace(part, path)


def read_changes(root: Path) -> dict[str, list[dict]]:
    """``{unit: [{"stamp", "change", "axis"}, ...]}`` from ``root/changes.csv`` (empty without one)."""
    path = Path(root) / "changes.csv"
    out: dict[str, list[dict]] = {}
    if path.is_file():
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                out.setdefault(row["unit"], []).append(
                    {"stamp": row["stamp"], "change": row["change"], "axis": int(row["axis"]) if row["axis"] else 0})
    return out


def read_truth(path: Path) -> dict[str, dict]:
    """``{unit: {"axis": worn axis (0 healthy), "stamps": [...], "wear": ndarray %}}`` from truth.csv."""
    out: dict[str, dict] = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            unit = out.setdefault(row["unit"], {"axis": int(row["worn_axis"]), "stamps": [], "wear": []})
            unit["stamps"].append(row["stamp"])
            unit["wear"].append(float(row["wear_percent"]))
    for unit in out.values():
        unit["wear"] = np.array(unit["wear"])
    return out
