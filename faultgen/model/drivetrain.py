"""A robot's drivetrain as data: per axis gear ratio, motor, gearbox and motor-side friction.

The drivetrain is what faultgen adds to an arm (a URDF, a plain MJCF, a DH table) and what wear
acts on. :class:`AxisDrive` holds one axis, :class:`Drivetrain` all N of them; ``drivetrain.toml``
in a robot folder stores them, one table per axis::

    [axis.1]
    gear_ratio = 62.6111          # 1, motor angle / arm angle
    motor_inertia = 0.0002        # kg m^2, motor side
    ...

:func:`read_table` reads such a file (a full one, or the partial one ``--drivetrain`` may give),
:meth:`Drivetrain.to_toml` writes one with every number at full precision.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from pathlib import Path

from faultgen import inputs
from faultgen.effects.friction import FIELDS as FRICTION_FIELDS
from faultgen.effects.friction import UNITS as FRICTION_UNITS

#: Unit and meaning of every field of :class:`AxisDrive`, in file order.
UNITS = {
    "gear_ratio": "1, motor angle / arm angle",
    "motor_inertia": "kg m^2, motor side (rotor and brake)",
    "gearbox_stiffness": "N m/rad, arm side (thesis eq. 6.2a)",
    "gearbox_damping": "N m s/rad, arm side (thesis eq. 6.2a)",
    "motor_torque_limit": "N m, motor side (actuator ctrlrange)",
    **{name: FRICTION_UNITS[name] + ", motor side" for name in FRICTION_FIELDS},
}

#: Fields that must be strictly positive (the others must be >= 0).
POSITIVE = (
    "gear_ratio",
    "motor_inertia",
    "gearbox_stiffness",
    "motor_torque_limit",
    "stribeck_velocity",
    "stribeck_exponent",
)


#: Bounds of every field, (low, high) in its unit: far outside any industrial drive (gear ratios
#: 1..300, motor inertias 1e-5..0.05 kg m^2, stiffness 1e4..1e7 N m/rad, Stribeck exponents 0.5..2),
#: and inside what the sizing and the integrator compute without overflow. ``low`` 0 with the key in
#: :data:`POSITIVE` means > 0.
BOUNDS = {
    "gear_ratio": (0.1, 1e4),
    "motor_inertia": (0.0, 1e3),
    "gearbox_stiffness": (0.0, 1e10),
    "gearbox_damping": (0.0, 1e8),
    "motor_torque_limit": (0.0, 1e6),
    **{name: (0.0, 1e6) for name in FRICTION_FIELDS},  # N m, N m s/rad: Coulomb, static, viscous
    "stribeck_velocity": (0.0, 1e4),
    "stribeck_exponent": (0.0, 10.0),
    "bristle_stiffness": (0.0, 1e10),
    "bristle_damping": (0.0, 1e8),
}


class DrivetrainError(ValueError):
    """A drivetrain table that cannot be used: the message names the file, axis and key."""


#: The gearbox rating (:mod:`faultgen.model.rating`), whose keys :func:`read_table` checks.
#: Gearbox types and the life exponent p of each (Harmonic Drive: 3; Nabtesco RV and ISO 281's
#: roller bearings: 10/3).
GEARBOX_EXPONENTS = {"strain-wave": 3.0, "cycloid": 10.0 / 3.0}
#: Unit and meaning of each rating key, in file order.
RATING_UNITS = {
    "gearbox_type": f"one of {', '.join(GEARBOX_EXPONENTS)}",
    "rated_torque": "N m, arm side (gear output), at the rated speed",
    "rated_speed": "rad/s, arm side (gear output)",
    "rated_life": "h at rated torque and speed, L10",
}
RATING_KEYS = tuple(RATING_UNITS)
#: Bounds of the numbers, (low, high), inclusive: far outside any robot gear (rated torques
#: 1 .. 10^5 N m, output speeds 0.1 .. 10 rad/s, lives 10^3 .. 10^5 h), and within them the rated-life
#: formula stays representable (:func:`faultgen.monitor.life.consumed`: its denominator
#: ``n_N T_N^p L_n 3600`` at least 3.6e-26, so a log's share of life stays finite, where a rated torque
#: of 1e-300 made it 0 and the share inf or NaN).
RATING_BOUNDS = {"rated_torque": (1e-6, 1e7), "rated_speed": (1e-6, 1e4), "rated_life": (1e-3, 1e7)}


def check_rating(key: str, value) -> str | float:
    """``value`` of rating key ``key`` checked: a type of :data:`GEARBOX_EXPONENTS`, or a finite
    number within :data:`RATING_BOUNDS`.

    Raises
    ------
    DrivetrainError
        Naming the key, the value and what was expected.
    """
    if key == "gearbox_type":
        if not isinstance(value, str) or value not in GEARBOX_EXPONENTS:
            raise DrivetrainError(f"gearbox_type = {str(value)[:40]!r}; expected one of {', '.join(map(repr, GEARBOX_EXPONENTS))}")
        return value
    low, high = RATING_BOUNDS[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
            or not low <= value <= high:
        raise DrivetrainError(f"{key} = {str(value)[:40] if isinstance(value, str) else value!r}; expected a finite "
                              f"number > 0, from {low:g} to {high:g} ({RATING_UNITS[key]}; the rated-life formula's "
                              "range)")
    return float(value)


def check_value(key: str, value) -> float:
    """``value`` of field ``key`` as a float within :data:`BOUNDS` (> 0 for :data:`POSITIVE`).

    Raises
    ------
    DrivetrainError
        Naming the key, the value and the range.
    """
    low, high = BOUNDS[key]
    positive = key in POSITIVE
    need = f"{'> ' if positive and low == 0 else '>= '}{low:g} and <= {high:g}"
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise DrivetrainError(f"{key} = {value!r}; expected a number {need} ({UNITS[key]})")
    value = float(value)
    if not math.isfinite(value) or not low <= value <= high or (positive and value == 0):
        raise DrivetrainError(f"{key} = {value!r}; expected a finite value {need} ({UNITS[key]})")
    return value


@dataclass(frozen=True)
class AxisDrive:
    """The drivetrain of one axis; units in :data:`UNITS`.

    Raises
    ------
    DrivetrainError
        If a value is not finite, is negative, or is zero where :data:`POSITIVE` needs > 0.
    """

    gear_ratio: float
    motor_inertia: float
    gearbox_stiffness: float
    gearbox_damping: float
    motor_torque_limit: float
    coulomb_pos: float
    coulomb_neg: float
    static: float
    stribeck_velocity: float
    stribeck_exponent: float
    viscous: float
    bristle_stiffness: float
    bristle_damping: float

    def __post_init__(self) -> None:
        for f in fields(self):
            object.__setattr__(self, f.name, check_value(f.name, getattr(self, f.name)))

    @property
    def friction_row(self) -> list[float]:
        """The motor-side friction values in the order of ``friction{i}`` (:data:`FRICTION_FIELDS`)."""
        return [getattr(self, name) for name in FRICTION_FIELDS]


#: Keys of one axis table, in file order.
KEYS = tuple(f.name for f in fields(AxisDrive))


@dataclass(frozen=True)
class Drivetrain:
    """The drivetrain of all N axes, axis 1 first (``axes[k]`` is axis k + 1)."""

    axes: tuple[AxisDrive, ...]

    def __len__(self) -> int:
        return len(self.axes)

    @classmethod
    def from_table(
        cls, table: dict[int, dict[str, float]], n_axes: int, source: str = "drivetrain"
    ) -> Drivetrain:
        """A full drivetrain from ``{axis number: {key: value}}`` (as :func:`read_table` gives).

        Raises
        ------
        DrivetrainError
            If an axis 1..n_axes or a key of one is missing, or a value is out of range.
        """
        axes = []
        for axis in range(1, n_axes + 1):
            if axis not in table:
                raise DrivetrainError(f"{source}: axis {axis} is missing; the arm has {n_axes} axes")
            missing = [k for k in KEYS if k not in table[axis]]
            if missing:
                raise DrivetrainError(f"{source}: axis {axis} lacks {', '.join(missing)}")
            try:
                axes.append(AxisDrive(**{k: table[axis][k] for k in KEYS}))
            except DrivetrainError as err:
                raise DrivetrainError(f"{source}: axis {axis}: {err}") from None
        return cls(tuple(axes))

    def to_toml(self, notes: dict[int, dict[str, str]] | None = None, header: str = "",
                ratings: dict[int, dict] | None = None) -> str:
        """The drivetrain as ``drivetrain.toml`` text, every number at full precision (``repr``);
        ``notes[axis][key]`` is written as a comment after the value (its source); ``ratings[axis]``
        the gearbox rating keys given (:data:`RATING_KEYS`), written after the axis's numbers."""
        lines = [f"# {line}" if line else "#" for line in header.splitlines()]
        lines += ["# Units: " + "; ".join(f"{k}: {u}" for k, u in UNITS.items()), ""]
        for axis, drive in enumerate(self.axes, start=1):
            lines.append(f"[axis.{axis}]")
            for key, value in asdict(drive).items():
                note = (notes or {}).get(axis, {}).get(key)
                lines.append(f"{key} = {value!r}" + (f"  # {note}" if note else ""))
            given = (ratings or {}).get(axis, {})
            lines += [f"{key} = {given[key]!r}  # given in --drivetrain" for key in RATING_KEYS if key in given]
            lines.append("")
        return "\n".join(lines)


def read_table(path: str | Path, n_axes: int, partial: bool = False) -> dict[int, dict[str, float]]:
    """Read a ``drivetrain.toml``: ``{axis number: {key: value}}``.

    Parameters
    ----------
    path : str or Path
        The file.
    n_axes : int
        The arm's number of axes N; tables ``[axis.1]`` .. ``[axis.N]`` are expected.
    partial : bool, default False
        Accept missing axes and keys (``--drivetrain`` may give only some numbers; the others
        are sized). Values given are still checked.

    Raises
    ------
    DrivetrainError
        If the file is not TOML, has a key other than ``axis`` at the top or an unknown key in an
        axis table (the gearbox rating's keys, :data:`RATING_KEYS`, are checked and
        left out of the table: :func:`faultgen.model.rating.given` reads them), names an axis
        outside 1..N, gives a value that is not a finite number or is
        negative (or zero where :data:`POSITIVE` needs > 0), or (``partial=False``) lacks an axis
        or a key. The message names the file, the axis and the key.
    """
    path = Path(path)
    try:
        data = inputs.read_toml(path, "TOML drivetrain table")
    except inputs.InputError as err:
        raise DrivetrainError(str(err)) from None
    unknown = sorted(set(data) - {"axis"})
    if unknown:
        raise DrivetrainError(
            f"{path}: unknown key {unknown[0]!r}; expected only [axis.1] .. [axis.{n_axes}] tables"
        )
    axes = data.get("axis", {})
    if not isinstance(axes, dict):
        raise DrivetrainError(f"{path}: 'axis' must be tables [axis.1] .. [axis.{n_axes}]")
    table: dict[int, dict[str, float]] = {}
    for label, values in axes.items():
        try:
            axis = int(label)
        except ValueError:
            axis = 0
        if not 1 <= axis <= n_axes or str(axis) != str(label):
            raise DrivetrainError(f"{path}: [axis.{label}] is not an axis of this arm (1..{n_axes})")
        if not isinstance(values, dict):
            raise DrivetrainError(f"{path}: axis.{label} must be a table")
        bad = sorted(set(values) - set(KEYS) - set(RATING_KEYS))
        if bad:
            raise DrivetrainError(
                f"{path}: axis {axis}: unknown key {bad[0]!r}; expected some of: {', '.join(KEYS + RATING_KEYS)}"
            )
        try:
            for k in sorted(set(values) & set(RATING_KEYS)):
                check_rating(k, values[k])
            table[axis] = {k: check_value(k, v) for k, v in values.items() if k not in RATING_KEYS}
        except DrivetrainError as err:
            raise DrivetrainError(f"{path}: axis {axis}: {err}") from None
    if not partial:
        Drivetrain.from_table(table, n_axes, str(path))
    return table


def read(path: str | Path, n_axes: int) -> Drivetrain:
    """A full :class:`Drivetrain` from a ``drivetrain.toml``; raises :class:`DrivetrainError` as
    :func:`read_table`."""
    return Drivetrain.from_table(read_table(path, n_axes), n_axes, str(path))
