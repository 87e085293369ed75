"""Each axis's gearbox rating: its type, rated torque, rated speed and rated life.

What the rated-life formula of the gearbox makers needs (:mod:`faultgen.monitor.life` computes the
life a log consumed from it). ``drivetrain.toml`` may give it per axis, beside the drivetrain's
numbers::

    [axis.1]
    gearbox_type = "cycloid"      # "strain-wave" (exponent 3) or "cycloid" (RV, 10/3)
    rated_torque = 412.0          # N m, arm side (the gear's output)
    rated_speed = 1.5708          # rad/s, arm side (the gear's output)
    rated_life = 6000.0           # h, L10 at rated torque and speed

Every value not given is a **default** (:func:`defaults`), said as one wherever it is shown
(``faultgen robots NAME``, ``OUT/life.csv``):

- ``gearbox_type``: cycloid (RV) on the main axes (:func:`faultgen.model.sizing.main_axes`),
  strain-wave on the wrist axes: the usual layout of six-axis industrial arms (RV reducers carry
  the base and shoulder, strain-wave gears the light wrist);
- ``rated_torque``, cycloid: a gear size chosen for the axis's load as Nabtesco's RV-E selection
  procedure does it (the catalogue's "Selection flow chart": the load torque when starting and
  stopping must not exceed the allowable acceleration/deceleration torque, 2.5 x the rated torque
  in the RV-E rating table): the smallest size of :data:`RV_E_RATED_TORQUE` whose 2.5 ``T0``
  covers the gear output's peak torque the drivetrain was sized for
  (:func:`faultgen.model.sizing.output_peak`: the rated load held and accelerated along the
  planning limits). No size covers it (a load above the largest, RV-450E's 11 kN m): **no rating**
  (:attr:`GearboxRating.unrated` says why; ``life.csv`` then gives no consumption and no date, and
  ``faultgen robots NAME`` shows how to give one in ``drivetrain.toml``). The life check of the
  selection needs the duty, which the monitor measures: it is ``life.csv``.
- ``rated_torque``, strain-wave: the axis's arm-side peak torque (motor torque limit x gear ratio,
  the drivetrain's sizing rule, :mod:`faultgen.model.sizing`) / :data:`PEAK_TO_RATED` (2.5:
  Harmonic Drive's CSF/CSG repeated peak torque is 2-3 x the rated torque);
- ``rated_speed``: cycloid 15 rpm at the output (Nabtesco RV-E's rated output speed); strain-wave
  2000 rpm at the input (Harmonic Drive's rated input speed), so 2000 rpm / G at the output;
- ``rated_life``: cycloid 6000 h (Nabtesco RV-E's rated service life K, L10); strain-wave 7000 h
  (Harmonic Drive CSF/HFUC/CSD: L50 = 35000 h, L10 about L50 / 5; Harmonic Drive engineering data,
  "Life of the wave generator bearing").

Both are lives of the gear's main bearings, L10 (10 % of a population failed) in both defaults.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

from faultgen import inputs
from faultgen.model.drivetrain import (GEARBOX_EXPONENTS, RATING_BOUNDS, RATING_KEYS, RATING_UNITS, AxisDrive,
                                       Drivetrain, DrivetrainError, check_rating)
from faultgen.model.sizing import main_axes, output_peak

#: Gearbox types and their life exponent p, the rating keys' units, bounds and check (kept in
#: :mod:`faultgen.model.drivetrain`, whose reader checks them in ``drivetrain.toml``).
EXPONENTS, UNITS, KEYS, BOUNDS = GEARBOX_EXPONENTS, RATING_UNITS, RATING_KEYS, RATING_BOUNDS
check = check_rating

#: Arm-side peak torque / rated torque of the strain-wave default (module docstring).
PEAK_TO_RATED = 2.5
#: Nabtesco RV-E rating table: each size's rated torque T0, N m (at 15 rpm output, K = 6000 h), and
#: the allowable acceleration/deceleration torque's ratio to it (Nabtesco, "Precision reduction gear
#: RV, E series", rating table and selection flow chart).
RV_E_RATED_TORQUE = {"RV-6E": 58.0, "RV-20E": 167.0, "RV-40E": 412.0, "RV-80E": 784.0, "RV-110E": 1078.0,
                     "RV-160E": 1568.0, "RV-320E": 3136.0, "RV-450E": 4410.0}
RV_E_ACCELERATION = 2.5
#: Rated speeds of the defaults: cycloid at the output, strain-wave at the input, rad/s.
CYCLOID_SPEED = 15.0 * 2 * math.pi / 60
STRAIN_WAVE_INPUT_SPEED = 2000.0 * 2 * math.pi / 60
#: Rated lives of the defaults, h (L10).
RATED_LIFE = {"cycloid": 6000.0, "strain-wave": 7000.0}
#: How each default is made, as ``faultgen robots NAME`` and the docs say it.
RULES = {
    "gearbox_type": "cycloid (RV) on the main axes, strain-wave on the wrist axes",
    "rated_torque": f"cycloid: the smallest Nabtesco RV-E size whose allowable acceleration torque ({RV_E_ACCELERATION:g} "
    f"x rated) covers the gear output's peak (the sizing's rated load), none above RV-450E; strain-wave: motor "
    f"torque limit x G / {PEAK_TO_RATED:g}",
    "rated_speed": "cycloid 15 rpm (Nabtesco RV-E); strain-wave 2000 rpm / G (Harmonic Drive's rated input speed)",
    "rated_life": "cycloid 6000 h (Nabtesco RV-E, L10); strain-wave 7000 h (Harmonic Drive L50 35000 h / 5)",
}


@dataclass(frozen=True)
class GearboxRating:
    """One axis's gearbox rating (units in :data:`UNITS`); ``defaults`` the keys that were not given.

    Raises
    ------
    DrivetrainError
        A value out of range (:func:`check`).
    """

    gearbox_type: str
    rated_torque: float
    rated_speed: float
    rated_life: float
    defaults: tuple[str, ...] = field(default=())
    #: Why the axis has no rated torque (no catalogue size fits its load), or "": rated.
    unrated: str = ""

    def __post_init__(self) -> None:
        for key in KEYS:
            if key == "rated_torque" and self.unrated:
                object.__setattr__(self, key, math.nan)
                continue
            object.__setattr__(self, key, check(key, getattr(self, key)))

    @property
    def exponent(self) -> float:
        """The life exponent p of :attr:`gearbox_type` (:data:`EXPONENTS`)."""
        return EXPONENTS[self.gearbox_type]

    def source(self, key: str) -> str:
        """``"(default)"`` for a key that was not given, else ``""``."""
        return "(default)" if key in self.defaults else ""


def defaults(drive: AxisDrive, axis: int, n_axes: int, gearbox_type: str | None = None) -> dict:
    """The default rating of axis ``axis`` (1..``n_axes``) driven by ``drive`` (module docstring);
    ``gearbox_type`` the type given, which the speed and life defaults follow."""
    kind = gearbox_type or ("cycloid" if axis <= main_axes(n_axes) else "strain-wave")
    speed = CYCLOID_SPEED if kind == "cycloid" else STRAIN_WAVE_INPUT_SPEED / drive.gear_ratio
    out = {"gearbox_type": kind, "rated_torque": drive.motor_torque_limit * drive.gear_ratio / PEAK_TO_RATED,
           "rated_speed": speed, "rated_life": RATED_LIFE[kind]}
    if kind == "cycloid":
        peak = output_peak(drive, axis, n_axes)
        size = next((name for name, torque in RV_E_RATED_TORQUE.items() if RV_E_ACCELERATION * torque >= peak), None)
        out["rated_torque"] = RV_E_RATED_TORQUE[size] if size else None
        if size is None:
            out["unrated"] = (f"its gear output's peak {peak:.4g} N m is above the largest Nabtesco RV-E size's "
                              f"allowable acceleration torque, {RV_E_ACCELERATION * max(RV_E_RATED_TORQUE.values()):.4g} N m")
    return out


def catalogue_size(rated: GearboxRating) -> str:
    """The RV-E size whose rated torque ``rated`` has, or "" (given, strain-wave or no rating)."""
    return next((name for name, torque in RV_E_RATED_TORQUE.items()
                 if rated.gearbox_type == "cycloid" and rated.rated_torque == torque), "")


def given(path: str | Path, n_axes: int) -> dict[int, dict]:
    """The rating keys ``drivetrain.toml`` gives, ``{axis: {key: value}}``, each checked (the other
    keys are :func:`faultgen.model.drivetrain.read_table`'s).

    Raises
    ------
    DrivetrainError
        The file cannot be read as TOML, or a rating value is bad (file, axis and key named).
    """
    try:
        data = inputs.read_toml(path, "TOML drivetrain table")
    except inputs.InputError as err:
        raise DrivetrainError(str(err)) from None
    out: dict[int, dict] = {}
    axes = data.get("axis", {})
    for label, values in (axes.items() if isinstance(axes, dict) else ()):
        if not (isinstance(values, dict) and str(label).isdigit() and 1 <= int(label) <= n_axes):
            continue  # read_table names such a table
        try:
            out[int(label)] = {k: check(k, values[k]) for k in KEYS if k in values}
        except DrivetrainError as err:
            raise DrivetrainError(f"{path}: axis {label}: {err}") from None
    return out


def ratings(drivetrain: Drivetrain, table: dict[int, dict] | None = None) -> tuple[GearboxRating, ...]:
    """Every axis's rating: ``table``'s values (as :func:`given` reads them), the defaults for the rest."""
    out = []
    n = len(drivetrain)
    for axis, drive in enumerate(drivetrain.axes, start=1):
        mine = (table or {}).get(axis, {})
        values = {**defaults(drive, axis, n, mine.get("gearbox_type")), **mine}
        if "rated_torque" in mine:
            values.pop("unrated", None)
        out.append(GearboxRating(**values, defaults=tuple(k for k in KEYS if k not in mine)))
    return tuple(out)


def of_robot(robot) -> tuple[GearboxRating, ...]:
    """The ratings of a loaded robot (:class:`faultgen.model.robots.Robot`): those its folder's
    ``drivetrain.toml`` gives, the defaults for the rest (all defaults for a robot without one).

    Raises
    ------
    DrivetrainError
        As :func:`given`.
    """
    from faultgen.model.robot import drivetrain_of

    drivetrain = drivetrain_of(robot)
    path = Path(robot.path).parent / "drivetrain.toml"
    out = ratings(drivetrain, given(path, len(drivetrain)) if path.is_file() else None)
    hint = f"`faultgen robots {robot.name}` shows how to add one (drivetrain.toml's rated_torque)"
    return tuple(replace(r, unrated=f"no rating given ({r.unrated}): {hint}") if r.unrated else r for r in out)
