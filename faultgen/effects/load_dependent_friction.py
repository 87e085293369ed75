"""Friction growing with the gearbox load (tooth-contact friction in the gearbox)."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from faultgen.effects.base import Effect, register


@register
class LoadDependentFriction(Effect):
    """Coulomb friction ``coefficient |tau_load| sign(qd)`` at the arm side, ``tau_load`` the
    arm-side gearbox load (N m), ``coefficient`` dimensionless; MJCF: custom numeric
    ``load_dependent_friction{i}`` (``load_friction{i}`` read too).

    In the simulation the rotor's dry friction gains ``coefficient |K e| / G`` every step, the
    gearbox load from the spring deflection ``e`` (eq. 6.2a): a per-step update, so only the
    static friction model carries it. Identified as a change of the coefficient.
    """

    id = "load_dependent_friction"
    rank = 50
    summary = "friction that grows with the gearbox load"
    units: ClassVar[dict[str, str]] = {"coefficient": "1"}
    absent = (0.0,)
    numeric = "load_dependent_friction"
    aliases = ("load_friction",)
    stepped = True
    draw_limits: ClassVar[dict[str, float]] = {"coefficient": 0.8}

    def torque(self, robot, q, qd, load, t):
        return self.coefficient * np.abs(load) * np.sign(qd)

    def dry_friction_extra(self, robot, deflection):
        return self.coefficient * np.abs(robot.gearbox_stiffness * deflection) / robot.gear_ratio

    def columns(self, motion, axis, h):
        regressor = np.abs(motion.load[:, axis]) * np.sign(motion.qd[:, axis])
        return regressor[:, None], np.zeros(len(motion.t))

    def params(self, motion, axis, theta, h):
        return {"coefficient": float(self.current(motion.robot).coefficient[axis] + theta[0])}

    def admissible(self, motion, axis, params):
        return params["coefficient"] >= 0

    def apply(self, spec, robot, axis, params):
        super().apply(spec, robot, axis, {"coefficient": max(params["coefficient"], 0.0)})

    def motor_torque(self, motion, axis, params):
        G = motion.robot.gear_ratio[axis]
        return params["coefficient"] * np.max(np.abs(motion.load[:, axis])) / G
