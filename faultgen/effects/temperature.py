"""Friction drifting with time: a cold gearbox warming up."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from faultgen.checks import is_number
from faultgen.effects.base import Effect, register

#: Joint temperature at which a robot's nominal friction parameters hold, deg C: a joint warmed up
#: in production (ambient 20 deg C plus the 15 K a running joint settles above it,
#: :class:`faultgen.operation.conditions.Temperature`).
REFERENCE_TEMPERATURE = 35.0
#: Kinematic viscosity of the gearbox oil at 40 and 100 deg C, mm^2/s: an ISO VG 220 mineral gear
#: oil (ISO 3448 grade 220: 198-242 mm^2/s at 40 deg C; 19.0 mm^2/s at 100 deg C is a typical data
#: sheet value for viscosity index 95-97).
OIL_VISCOSITY = {40.0: 220.0, 100.0: 19.0}
#: Share of the viscosity's change that the dry (Coulomb and Stribeck) friction follows, as an
#: exponent: dry ~ viscosity ** DRY_SHARE. Chosen, not measured: in mixed and boundary lubrication
#: friction falls with temperature less than in a full oil film (Bittencourt, Wernholt,
#: Sander-Tavallaey & Brogardh 2010 and Bittencourt & Gunnarsson 2012 report the larger change at
#: high speeds); with 1/4 a joint at 20 deg C has 30 % more dry and 2.9 times the viscous friction
#: of one at :data:`REFERENCE_TEMPERATURE`. The default of
#: :attr:`faultgen.operation.conditions.Temperature.dry_share`, which a run can set (0..1).
DRY_SHARE = 0.25


def oil_viscosity(temperature, points: dict[float, float] = OIL_VISCOSITY) -> np.ndarray:
    """Kinematic viscosity of the gearbox oil at ``temperature`` (deg C, any shape), mm^2/s, by
    Walther's equation ``log10 log10(nu + 0.7) = A - B log10(T / 1 K)`` (ASTM D341, the standard
    viscosity-temperature relation of petroleum oils) through two ``points`` {deg C: mm^2/s}
    (default :data:`OIL_VISCOSITY`). Checked against published mineral-oil viscosities at 30, 60
    and 100 deg C (tests/test_conditions.py)."""
    (t1, nu1), (t2, nu2) = sorted(points.items())

    def walther(nu):
        return np.log10(np.log10(nu + 0.7))

    slope = (walther(nu1) - walther(nu2)) / (np.log10(t2 + 273.15) - np.log10(t1 + 273.15))
    offset = walther(nu1) + slope * np.log10(t1 + 273.15)
    return 10 ** (10 ** (offset - slope * np.log10(np.asarray(temperature, dtype=float) + 273.15))) - 0.7


def friction_factors(temperature, dry_share: float = DRY_SHARE) -> tuple[np.ndarray, np.ndarray]:
    """Multipliers of the dry (Coulomb and Stribeck) and of the viscous friction of a joint at
    ``temperature`` (deg C, any shape) over their values at :data:`REFERENCE_TEMPERATURE`.

    The viscous friction of a full oil film is proportional to the oil's viscosity (Petroff's
    law), :func:`oil_viscosity`; the dry friction follows the viscosity's ratio to the power
    ``dry_share`` (default :data:`DRY_SHARE`; 0: the dry friction does not move with
    temperature, 1: it moves as the viscous). Both fall with temperature, as measured on robot
    joints (Bittencourt & Gunnarsson 2012), the viscous part most.

    Returns
    -------
    (ndarray, ndarray)
        Dry and viscous multipliers, each of ``temperature``'s shape, > 0; 1 at the reference.

    Raises
    ------
    ValueError
        For a temperature that is not finite or outside -20..120 deg C (outside a mineral gear
        oil's working range), or a ``dry_share`` that is not a number within 0..1.
    """
    if not is_number(dry_share, 0, 1):
        raise ValueError(f"dry_share = {dry_share!r}: expected a number within 0..1 (the exponent of the viscosity "
                         f"ratio that dry friction follows; default {DRY_SHARE})")
    temperature = np.asarray(temperature, dtype=float)
    if not np.all(np.isfinite(temperature)) or np.any((temperature < -20) | (temperature > 120)):
        raise ValueError(f"joint temperature {np.min(temperature):g}..{np.max(temperature):g} deg C: expected "
                         "finite values within -20..120 deg C")
    viscous = oil_viscosity(temperature) / oil_viscosity(REFERENCE_TEMPERATURE)
    return viscous**dry_share, viscous


@register
class Temperature(Effect):
    """Warm-up within a log: the dry friction (Coulomb plus Stribeck, eq. 6.3) times
    ``1 + amplitude exp(-t / time_constant)``, t (s) from the start of the run, amplitude a
    fraction; MJCF: custom numeric ``temperature{i}`` = amplitude, time constant (``thermal{i}``
    read too).

    In the simulation the rotor's dry friction level is scaled every step (only the static
    friction model). Identified with the amplitude linear and the time constant searched from 0.3
    to 5 times the record length, so the drift is visible within the record.

    How friction follows the joint temperature from cycle to cycle (the operating conditions of a
    sweep, :mod:`faultgen.operation.conditions`) is :func:`friction_factors`.
    """

    id = "temperature"
    rank = 60
    designable = False
    excited_by = (
        "a long log from a cold start (the warm-up fades with its time constant, a level does not)")
    summary = "friction drifting with time (a gearbox warming up)"
    units: ClassVar[dict[str, str]] = {"amplitude": "1", "time_constant": "s"}
    absent = (0.0, 1.0)
    numeric = "temperature"
    aliases = ("thermal",)
    continuous = True
    stepped = True
    draw_limits: ClassVar[dict[str, float]] = {"amplitude": 3.0}

    @classmethod
    def check(cls, rows):
        return "needs a time constant > 0 s" if np.any(rows[:, 1] <= 0) else None

    def _drift(self, time):
        return self.amplitude * np.exp(-time / self.time_constant)

    def torque(self, robot, q, qd, load, t):
        G = robot.gear_ratio
        drift = self._drift(t[:, None])
        return drift * G * robot.friction.stribeck_level(G * qd) * np.sign(qd)

    def dry_friction_factor(self, time):
        return 1 + self._drift(time)

    def grid(self, motion, axis):
        duration = float(motion.t[-1])
        return list(np.geomspace(0.3 * duration, 5 * duration, 12))

    def columns(self, motion, axis, h):
        G = motion.robot.gear_ratio[axis]
        v = motion.motor_velocity
        dry = motion.robot.friction.stribeck_level(v)[:, axis] * np.sign(v[:, axis])
        return (G * dry * np.exp(-motion.t / h))[:, None], np.zeros(len(motion.t))

    def params(self, motion, axis, theta, h):
        return {"amplitude": float(theta[0]), "time_constant": float(h)}

    def admissible(self, motion, axis, params):
        return params["amplitude"] > -1

    def motor_torque(self, motion, axis, params):
        f = motion.robot.friction
        dry = max(f.coulomb_pos[axis], f.coulomb_neg[axis]) + f.static[axis]
        return dry * (1 + params["amplitude"])
