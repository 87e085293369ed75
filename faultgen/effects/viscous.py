"""Viscous friction of another level (thesis eq. 6.3's f_v)."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from faultgen.effects.base import register
from faultgen.effects.motor_friction import FrictionParameter


@register
class Viscous(FrictionParameter):
    """Viscous friction ``viscous`` (N m s/rad, motor side; thesis eq. 6.3).

    Identified as a change ``df_v``: the arm-side drive torque changes by ``G^2 df_v qd``.
    """

    id = "viscous"
    rank = 30
    excited_by = (
        "a wide range of steady speeds (viscous friction grows with the speed, a dry level does not)")
    summary = "viscous friction differs (torque proportional to speed)"
    units: ClassVar[dict[str, str]] = {"viscous": "N m s/rad (motor side)"}
    absent = (0.0,)

    def columns(self, motion, axis, h):
        G = motion.robot.gear_ratio[axis]
        return (G**2 * motion.qd[:, axis])[:, None], np.zeros(len(motion.t))

    def params(self, motion, axis, theta, h):
        return {"viscous": float(motion.robot.friction.viscous[axis] + theta[0])}

    def admissible(self, motion, axis, params):
        return params["viscous"] >= 0

    def motor_torque(self, motion, axis, params):
        return params["viscous"] * float(np.max(np.abs(motion.motor_velocity[:, axis])))
