"""Coulomb friction of another level (thesis eq. 6.3's f_c), both directions alike or each its own."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from faultgen.effects.base import register
from faultgen.effects.motor_friction import FrictionParameter


@register
class Coulomb(FrictionParameter):
    """Coulomb friction levels ``coulomb_pos`` / ``coulomb_neg`` (N m, motor side, magnitudes for
    positive / negative speed; thesis eq. 6.3).

    Identified as one change ``df_c`` of both levels (the arm-side drive torque changes by
    ``G df_c sign(qd)``), or, at the second of :attr:`levels` and where the Bayesian information
    criterion supports it, with a further change ``df_+`` of the positive-direction level alone
    (``G df_+`` while ``qd > 0``): a drive's Coulomb friction differs per direction (the PUMA 560's
    consensus levels do, Corke & Armstrong-Helouvry 1994, roboticstoolbox ``Tc``). A fit that would
    take a level below zero is not admissible.
    """

    id = "coulomb"
    rank = 20
    excited_by = (
        "reversals at several speeds under a steady load (a Coulomb level keeps its size at every speed "
        "and load)")
    summary = "Coulomb friction level differs (constant torque against the motion)"
    units: ClassVar[dict[str, str]] = {"coulomb_pos": "N m (motor side)", "coulomb_neg": "N m (motor side)"}
    absent = (0.0, 0.0)
    n_parameters = 2
    levels = (1, 2)  # both directions alike; the positive one on its own too

    def columns(self, motion, axis, h):
        G = motion.robot.gear_ratio[axis]
        qd = motion.qd[:, axis]
        return G * np.column_stack([np.sign(qd), qd > 0]), np.zeros(len(motion.t))

    def draw_direction(self, rng):
        return np.array([1.0, 0.0])  # a drawn hidden change shifts both directions alike

    def params(self, motion, axis, theta, h):
        f = motion.robot.friction
        return {"coulomb_pos": float(f.coulomb_pos[axis] + theta[0] + theta[1]),
                "coulomb_neg": float(f.coulomb_neg[axis] + theta[0])}

    def admissible(self, motion, axis, params):
        return min(params["coulomb_pos"], params["coulomb_neg"]) >= 0

    def motor_torque(self, motion, axis, params):
        f = motion.robot.friction
        return max(params["coulomb_pos"], params["coulomb_neg"]) + f.static[axis]
