"""A robot's nominal motor-side friction as one registered effect, and the effects that change part of it.

:class:`MotorFriction` (id ``motor_friction``) holds eq. 6.3's Coulomb levels, static friction
excess, Stribeck velocity and exponent and viscous friction, and the LuGre bristle stiffness and
damping (Astrom & Canudas-de-Wit 2008), on every axis, at the motor side (thesis ch. 6.3.1: only
motor-side friction is modelled). It is stored, read and written like every effect
(:meth:`MotorFriction.read` from the ``<numeric name="friction{i}">`` of a robot's MJCF,
:meth:`~faultgen.effects.base.Effect.apply` into an ``MjSpec``, :attr:`~MotorFriction.units`,
:meth:`~faultgen.effects.base.Effect.table`); every robot carries it (``Robot.friction``). The
simulation's friction models (:mod:`faultgen.simulation.friction_models`, through
:mod:`faultgen.effects.friction`) put it into MuJoCo; friction wear is a relative
:class:`faultgen.operation.faults.Fault` on its :attr:`~MotorFriction.groups` ``dry`` (Coulomb
both directions and static friction, thesis eq. 6.6).

It is not a calibration candidate (:attr:`~faultgen.effects.base.Effect.candidate`): the
calibration fits changes of parts of it, the effects ``coulomb``, ``viscous`` and ``stribeck``
(:class:`FrictionParameter`).
"""

from __future__ import annotations

from typing import ClassVar

import mujoco
import numpy as np

from faultgen import axes as axis_numbers
from faultgen.effects.base import Effect, ModelError, register

#: Order of the values in each ``friction{i}`` numeric of a robot's MJCF (the effect's parameters).
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

#: Fields that must be > 0 (the others >= 0).
_POSITIVE = ("stribeck_velocity", "stribeck_exponent")


@register
class MotorFriction(Effect):
    """Motor-side friction parameters of all axes, each an ``ndarray of shape (N,)`` (a registered effect).

    Attributes
    ----------
    coulomb_pos, coulomb_neg : ndarray of shape (N,)
        Coulomb friction f_c in N m for positive / negative joint velocity, as magnitudes
        (the asymmetric Coulomb model of the Robotics Toolbox; thesis eq. 3.7 grows both).
    static : ndarray of shape (N,)
        Static friction excess f_s in N m: friction at rest is f_c + f_s (thesis eq. 6.3).
    stribeck_velocity : ndarray of shape (N,)
        Stribeck velocity in rad/s at the motor side (thesis eq. 6.3).
    stribeck_exponent : ndarray of shape (N,)
        Exponent gamma of the Stribeck curve, dimensionless (thesis eq. 6.3).
    viscous : ndarray of shape (N,)
        Viscous friction f_v in N m s/rad (thesis eq. 6.3).
    bristle_stiffness, bristle_damping : ndarray of shape (N,)
        LuGre sigma_0 in N m/rad and sigma_1 in N m s/rad (Astrom & Canudas-de-Wit 2008).

    Built with keyword values as every effect (``MotorFriction(coulomb_pos=[...], ...)``, one value
    per axis) or from a table (:meth:`from_rows`).

    Raises
    ------
    ValueError
        On construction, when a field is not finite, is negative, or (for the Stribeck velocity
        and exponent) is not positive; the message names the axis (1-based) and the field.
    """

    id = "motor_friction"
    rank = 0
    candidate = False
    summary = "motor-side friction: Coulomb, static (Stribeck), viscous and LuGre bristles (thesis eq. 6.3)"
    units: ClassVar[dict[str, str]] = {name: f"{unit} (motor side)" for name, unit in UNITS.items()}
    absent = (0.0, 0.0, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0)
    numeric = "friction"
    n_parameters = len(FIELDS)
    designable = False
    #: Named groups of parameters a relative fault scales together (:class:`faultgen.operation.faults.Fault`):
    #: ``dry``, the dry friction level f_c + f_s, which friction wear raises (thesis ch. 6.3.1, eq. 6.6).
    groups: ClassVar[dict[str, tuple[str, ...]]] = {"dry": ("coulomb_pos", "coulomb_neg", "static")}

    def __init__(self, *, n_axes: int | None = None, **values) -> None:
        for name, value in values.items():
            if name not in UNITS:
                continue  # Effect names the unknown parameter
            array = np.atleast_1d(np.asarray(value, dtype=float))
            if array.ndim != 1:
                raise ValueError(f"friction field {name!r} must be 1-D over axes, got shape {np.shape(value)}")
            positive = name in _POSITIVE
            for axis, v in enumerate(array, start=1):
                if not np.isfinite(v) or v < 0 or (positive and v == 0):
                    need = "> 0" if positive else ">= 0"
                    raise ValueError(f"axis {axis}: friction {name} = {float(v)!r} {UNITS[name]}, "
                                     f"expected a finite value {need}")
        sizes = {np.shape(v)[0] for v in values.values() if np.ndim(v) == 1}
        if len(sizes) > 1:
            raise ValueError(f"friction fields have different numbers of axes: {sorted(sizes)}")
        super().__init__(n_axes=n_axes, **values)

    @property
    def _one_coulomb(self) -> bool:
        """Whether both directions' Coulomb levels have the same bits: the level of a speed's
        direction is then that level, with no branch on the sign (the same bits as one)."""
        return self.coulomb_pos.tobytes() == self.coulomb_neg.tobytes()

    @classmethod
    def from_rows(cls, rows: np.ndarray) -> MotorFriction:
        """Build from an ``ndarray of shape (N, 8)`` whose columns are :data:`FIELDS`."""
        rows = np.asarray(rows, dtype=float)
        if rows.ndim != 2 or rows.shape[1] != len(FIELDS):
            raise ValueError(f"friction table must have shape (n_axes, {len(FIELDS)}), got {rows.shape}")
        return cls(**{name: rows[:, k] for k, name in enumerate(FIELDS)})

    def as_rows(self) -> np.ndarray:
        """Return the parameters as an ``ndarray of shape (N, 8)`` with columns :data:`FIELDS`."""
        return np.stack([getattr(self, name) for name in FIELDS], axis=1)

    @classmethod
    def read(cls, model: mujoco.MjModel, path) -> MotorFriction:
        """The robot's motor friction from its numerics ``friction1..frictionN``, each of the 8
        values of :data:`FIELDS`.

        Raises
        ------
        ModelError
            If a numeric is missing or has another number of values, or a value is refused
            (the message names the file, the axis and the field).
        """
        n_axes = axis_numbers.count(model)
        rows = np.empty((n_axes, len(FIELDS)))
        for k in range(n_axes):
            name = f"{cls.numeric}{k + 1}"
            idx = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_NUMERIC, name)
            if idx < 0:
                raise ModelError(f"{path}: no custom numeric named {name!r}; a robot needs custom numerics 1..{n_axes}")
            size = model.numeric_size[idx]
            if size != len(FIELDS):
                raise ModelError(f"{path}: numeric {name!r} has {size} values, expected {len(FIELDS)}: "
                                 + " ".join(FIELDS))
            adr = model.numeric_adr[idx]
            rows[k] = model.numeric_data[adr: adr + size]
        try:
            return cls.from_rows(rows)
        except ValueError as err:
            raise ModelError(f"{path}: {err}") from err

    @classmethod
    def of(cls, robot) -> MotorFriction:
        """The robot's motor friction (``robot.friction``; every robot carries it)."""
        return robot.friction

    def current(self, robot) -> MotorFriction:
        return robot.friction

    def stribeck_torque(self, v_m: np.ndarray) -> np.ndarray:
        """Static friction torque at the motor side, thesis eq. 6.3.

        ``f = (f_c + f_s exp(-|v / v_s|^gamma)) sign(v) + f_v v``, with ``f_c`` taken from
        ``coulomb_pos`` for ``v > 0`` and ``coulomb_neg`` for ``v < 0``; zero at ``v = 0``
        (no stiction: this is the kinetic map used by inverse dynamics, not a simulator).

        Parameters
        ----------
        v_m : ndarray of shape (n, N)
            Motor velocity in rad/s.

        Returns
        -------
        ndarray of shape (n, N)
            Friction torque in N m at the motor side, with the sign of ``v_m`` (it opposes
            motion, so a drive must supply it).
        """
        v = np.asarray(v_m, dtype=float)
        sign = np.sign(v)
        coulomb = self.coulomb_pos if self._one_coulomb else np.where(v > 0, self.coulomb_pos, self.coulomb_neg)
        stribeck = self.static * np.exp(-np.abs(v / self.stribeck_velocity) ** self.stribeck_exponent)
        return (coulomb + stribeck) * sign + self.viscous * v

    def stribeck_level(self, v_m: np.ndarray, multiplier: np.ndarray | float = 1.0) -> np.ndarray:
        """Magnitude of the dry part of eq. 6.3, ``(f_c + f_s exp(-|v / v_s|^gamma)) * multiplier``.

        Parameters
        ----------
        v_m : ndarray of shape (n, N)
            Motor velocity in rad/s; the Coulomb level of its direction is used (at rest, the
            larger of the two).
        multiplier : ndarray of shape (n, N) or float
            Multiplier of Coulomb and static friction (friction wear, thesis eq. 6.6, and the
            operating conditions), 1 when unworn.

        Returns
        -------
        ndarray of shape (n, N)
            N m at the motor side, >= 0.
        """
        v = np.asarray(v_m, dtype=float)
        if self._one_coulomb:
            coulomb = self.coulomb_pos
        else:
            coulomb = np.where(v > 0, self.coulomb_pos, np.where(v < 0, self.coulomb_neg,
                                                                    np.maximum(self.coulomb_pos, self.coulomb_neg)))
        stribeck = self.static * np.exp(-np.abs(v / self.stribeck_velocity) ** self.stribeck_exponent)
        return (coulomb + stribeck) * multiplier


class FrictionParameter(Effect):
    """An effect that changes some parameters of the robot's :class:`MotorFriction` (thesis eq. 6.3),
    named as :data:`FIELDS` names them: stored in that effect's ``friction{i}`` numerics, acting
    through the friction model in the simulation and in the inverse dynamics. A calibration
    candidate (``coulomb``, ``viscous``, ``stribeck``). A fitted change may give a negative level,
    which :meth:`Effect.admissible` refuses; :meth:`apply` writes at least zero."""

    @classmethod
    def read(cls, model, path):
        return None  # part of the robot's motor friction, read with it

    def current(self, robot) -> Effect:
        return type(self)(**{name: getattr(robot.friction, name) for name in self.units})

    def apply(self, spec, robot, axis, params):
        element = spec.numeric(f"{MotorFriction.numeric}{axis + 1}")
        row = dict(zip(FIELDS, (float(v) for v in element.data), strict=True))
        row.update({name: max(float(params[name]), 0.0) for name in self.units})  # magnitudes
        MotorFriction().apply(spec, robot, axis, row)
