"""A Stribeck hump of another size and velocity (thesis eq. 6.3's f_s and v_s)."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from faultgen.effects.base import REST_SPEED, FrictionParameter, register


@register
class Stribeck(FrictionParameter):
    """Static friction excess ``static`` (N m) and Stribeck velocity ``stribeck_velocity`` (rad/s),
    motor side: eq. 6.3's ``f_s exp(-|v/v_s|^gamma) sign(v)``.

    Identified by replacing the model's term with one of a new f_s (linear) and v_s, searched up to
    0.3 times the 95th-percentile motor speed (so a hump is never a disguised Coulomb step), down to
    a tenth of that or three times the rest speed (:data:`REST_SPEED`, below which nothing is
    fitted); gamma is kept.
    """

    id = "stribeck"
    rank = 40
    summary = "Stribeck friction (extra friction at low speed, fading with speed) differs"
    units: ClassVar[dict[str, str]] = {"static": "N m (motor side)", "stribeck_velocity": "rad/s (motor side)"}
    absent = (0.0, 1.0)
    continuous = True

    def grid(self, motion, axis):
        v = np.abs(motion.motor_velocity[:, axis])
        top = 0.3 * float(np.percentile(v, 95))
        low = max(3 * REST_SPEED * motion.robot.gear_ratio[axis], top / 10)
        return list(np.geomspace(low, top, 12)) if top > 2 * low else [None]

    def _shape(self, motion, axis, v_s):
        gamma = motion.robot.friction.stribeck_exponent[axis]
        v = motion.motor_velocity[:, axis]
        return np.exp(-np.abs(v / v_s) ** gamma) * np.sign(v)

    def columns(self, motion, axis, h):
        G = motion.robot.gear_ratio[axis]
        f = motion.robot.friction
        if h is None:
            return np.zeros((len(motion.t), 1)), np.zeros(len(motion.t))
        old = G * f.static[axis] * self._shape(motion, axis, f.stribeck_velocity[axis])
        return (G * self._shape(motion, axis, h))[:, None], -old

    def params(self, motion, axis, theta, h):
        return {"static": float(theta[0]), "stribeck_velocity": float(h or 1.0)}

    def admissible(self, motion, axis, params):
        return params["static"] >= 0

    def motor_torque(self, motion, axis, params):
        f = motion.robot.friction
        dry = max(f.coulomb_pos[axis], f.coulomb_neg[axis]) + f.static[axis]
        return dry - f.static[axis] + params["static"]
