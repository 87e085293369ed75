"""Motor-side friction parameters and the static Stribeck friction map.

The parameters of one robot live in its MJCF as one ``<numeric name="friction{i}">`` per axis
(see ``robots/<robot>/README.md``); :class:`MotorFriction` holds them as arrays over the six
axes. All quantities are at the motor side (thesis ch. 6.3.1: only motor-side friction is
modelled).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

#: Order of the values in each ``friction{i}`` numeric of a robot's MJCF.
FIELDS = (
    "coulomb_pos",
    "coulomb_neg",
    "static",
    "stribeck_velocity",
    "stribeck_exponent",
    "viscous",
    "bristle_stiffness",
    "bristle_damping",
)

#: SI unit of each field, motor side.
UNITS = {
    "coulomb_pos": "N m",
    "coulomb_neg": "N m",
    "static": "N m",
    "stribeck_velocity": "rad/s",
    "stribeck_exponent": "1",
    "viscous": "N m s/rad",
    "bristle_stiffness": "N m/rad",
    "bristle_damping": "N m s/rad",
}


@dataclass(frozen=True)
class MotorFriction:
    """Motor-side friction parameters of all axes, each an ``ndarray of shape (n_axes,)``.

    Attributes
    ----------
    coulomb_pos, coulomb_neg : ndarray of shape (n_axes,)
        Coulomb friction f_c in N m for positive / negative joint velocity, as magnitudes
        (the asymmetric Coulomb model of the Robotics Toolbox; thesis eq. 3.7 grows both).
    static : ndarray of shape (n_axes,)
        Static friction excess f_s in N m: friction at rest is f_c + f_s (thesis eq. 6.3).
    stribeck_velocity : ndarray of shape (n_axes,)
        Stribeck velocity in rad/s at the motor side (thesis eq. 6.3).
    stribeck_exponent : ndarray of shape (n_axes,)
        Exponent gamma of the Stribeck curve, dimensionless (thesis eq. 6.3).
    viscous : ndarray of shape (n_axes,)
        Viscous friction f_v in N m s/rad (thesis eq. 6.3).
    bristle_stiffness, bristle_damping : ndarray of shape (n_axes,)
        LuGre sigma_0 in N m/rad and sigma_1 in N m s/rad (Astrom & Canudas-de-Wit 2008).

    Raises
    ------
    ValueError
        On construction, when a field is not finite, is negative, or (for the Stribeck velocity
        and exponent) is not positive; the message names the axis (1-based) and the field.
    """

    coulomb_pos: np.ndarray
    coulomb_neg: np.ndarray
    static: np.ndarray
    stribeck_velocity: np.ndarray
    stribeck_exponent: np.ndarray
    viscous: np.ndarray
    bristle_stiffness: np.ndarray
    bristle_damping: np.ndarray

    def __post_init__(self) -> None:
        n = None
        for f in fields(self):
            value = np.array(getattr(self, f.name), dtype=float)
            if value.ndim != 1:
                raise ValueError(f"friction field {f.name!r} must be 1-D over axes, got shape {value.shape}")
            if n is None:
                n = value.shape[0]
            elif value.shape[0] != n:
                raise ValueError(f"friction field {f.name!r} has {value.shape[0]} axes, expected {n}")
            positive = f.name in ("stribeck_velocity", "stribeck_exponent")
            for axis, v in enumerate(value, start=1):
                if not np.isfinite(v) or v < 0 or (positive and v == 0):
                    need = "> 0" if positive else ">= 0"
                    raise ValueError(
                        f"axis {axis}: friction {f.name} = {float(v)!r} {UNITS[f.name]}, expected a finite value {need}"
                    )
            value.setflags(write=False)
            object.__setattr__(self, f.name, value)

    @classmethod
    def from_rows(cls, rows: np.ndarray) -> MotorFriction:
        """Build from an ``ndarray of shape (n_axes, 8)`` whose columns are :data:`FIELDS`."""
        rows = np.asarray(rows, dtype=float)
        if rows.ndim != 2 or rows.shape[1] != len(FIELDS):
            raise ValueError(f"friction table must have shape (n_axes, {len(FIELDS)}), got {rows.shape}")
        return cls(**{name: rows[:, k] for k, name in enumerate(FIELDS)})

    def as_rows(self) -> np.ndarray:
        """Return the parameters as an ``ndarray of shape (n_axes, 8)`` with columns :data:`FIELDS`."""
        return np.stack([getattr(self, name) for name in FIELDS], axis=1)

    def stribeck_torque(self, v_m: np.ndarray) -> np.ndarray:
        """Static friction torque at the motor side, thesis eq. 6.3.

        ``f = (f_c + f_s exp(-|v / v_s|^gamma)) sign(v) + f_v v``, with ``f_c`` taken from
        ``coulomb_pos`` for ``v > 0`` and ``coulomb_neg`` for ``v < 0``; zero at ``v = 0``
        (no stiction: this is the kinetic map used by inverse dynamics, not a simulator).

        Parameters
        ----------
        v_m : ndarray of shape (n, n_axes)
            Motor velocity in rad/s.

        Returns
        -------
        ndarray of shape (n, n_axes)
            Friction torque in N m at the motor side, with the sign of ``v_m`` (it opposes
            motion, so a drive must supply it).
        """
        v = np.asarray(v_m, dtype=float)
        sign = np.sign(v)
        coulomb = np.where(v > 0, self.coulomb_pos, self.coulomb_neg)
        stribeck = self.static * np.exp(-np.abs(v / self.stribeck_velocity) ** self.stribeck_exponent)
        return (coulomb + stribeck) * sign + self.viscous * v
