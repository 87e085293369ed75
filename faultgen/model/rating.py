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
- ``rated_torque``: the axis's arm-side peak torque (motor torque limit x gear ratio, the
  drivetrain's sizing rule, :mod:`faultgen.model.sizing`) / :data:`PEAK_TO_RATED` (2.5: Nabtesco's
  RV-E catalogue allows 2.5 x the rated torque when starting and stopping; Harmonic Drive's
  CSF/CSG repeated peak torque is 2-3 x the rated torque);
- ``rated_speed``: cycloid 15 rpm at the output (Nabtesco RV-E's rated output speed); strain-wave
  2000 rpm at the input (Harmonic Drive's rated input speed), so 2000 rpm / G at the output;
- ``rated_life``: cycloid 6000 h (Nabtesco RV-E's rated service life K, L10); strain-wave 7000 h
  (Harmonic Drive CSF/HFUC/CSD: L50 = 35000 h, L10 about L50 / 5; Harmonic Drive engineering data,
  "Life of the wave generator bearing").

Both are lives of the gear's main bearings, L10 (10 % of a population failed) in both defaults.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from faultgen import inputs
from faultgen.model.drivetrain import (GEARBOX_EXPONENTS, RATING_BOUNDS, RATING_KEYS, RATING_UNITS, AxisDrive,
                                       Drivetrain, DrivetrainError, check_rating)
from faultgen.model.sizing import main_axes

#: Gearbox types and their life exponent p, the rating keys' units, bounds and check (kept in
#: :mod:`faultgen.model.drivetrain`, whose reader checks them in ``drivetrain.toml``).
EXPONENTS, UNITS, KEYS, BOUNDS = GEARBOX_EXPONENTS, RATING_UNITS, RATING_KEYS, RATING_BOUNDS
check = check_rating

#: Arm-side peak torque / rated torque of the default (module docstring).
PEAK_TO_RATED = 2.5
#: Rated speeds of the defaults: cycloid at the output, strain-wave at the input, rad/s.
CYCLOID_SPEED = 15.0 * 2 * math.pi / 60
STRAIN_WAVE_INPUT_SPEED = 2000.0 * 2 * math.pi / 60
#: Rated lives of the defaults, h (L10).
RATED_LIFE = {"cycloid": 6000.0, "strain-wave": 7000.0}
#: How each default is made, as ``faultgen robots NAME`` and the docs say it.
RULES = {
    "gearbox_type": "cycloid (RV) on the main axes, strain-wave on the wrist axes",
    "rated_torque": f"motor torque limit x G / {PEAK_TO_RATED:g}",
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

    def __post_init__(self) -> None:
        for key in KEYS:
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
    return {"gearbox_type": kind, "rated_torque": drive.motor_torque_limit * drive.gear_ratio / PEAK_TO_RATED,
            "rated_speed": speed, "rated_life": RATED_LIFE[kind]}


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
    return ratings(drivetrain, given(path, len(drivetrain)) if path.is_file() else None)
