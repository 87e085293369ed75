"""Friction drifting with time: a cold gearbox warming up."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from faultgen.effects.base import Effect, register


@register
class Temperature(Effect):
    """Warm-up: the dry friction (Coulomb plus Stribeck, eq. 6.3) times
    ``1 + amplitude exp(-t / time_constant)``, t (s) from the start of the run, amplitude a
    fraction; MJCF: custom numeric ``temperature{i}`` = amplitude, time constant (``thermal{i}``
    read too).

    In the simulation the rotor's dry friction level is scaled every step (only the static
    friction model). Identified with the amplitude linear and the time constant searched from 0.3
    to 5 times the record length, so the drift is visible within the record.
    """

    id = "temperature"
    rank = 60
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
