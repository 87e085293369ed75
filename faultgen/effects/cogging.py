"""Cogging: a motor torque periodic in the motor angle."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from faultgen.effects.base import Effect, register
from faultgen.effects.friction import add_passive_dcmotor


@register
class Cogging(Effect):
    """Cogging ``amplitude sin(poles theta_m + phase)`` at the motor side (amplitude N m, poles
    periods per motor revolution, phase rad; MuJoCo ``dcmotor`` ``cogging``); MJCF: custom numeric
    ``cogging{i}`` = amplitude, poles, phase. The drive holds against it, so the arm-side drive
    torque gains ``-G amplitude sin(poles G q + phase)``.

    In the simulation a passive ``dcmotor`` ``cogging{i}`` with no input and no electrical branch
    whose only force is its cogging term (position-dependent, in C at the physics rate).
    Identified per pole count of :data:`POLES` with ``sin`` and ``cos`` regressors.
    """

    id = "cogging"
    rank = 80
    designable = False
    excited_by = (
        "slow steady motion over several motor revolutions (the ripple repeats with the motor angle)")
    summary = "cogging torque (periodic in the motor angle)"
    units: ClassVar[dict[str, str]] = {"amplitude": "N m (motor side)", "poles": "1", "phase": "rad"}
    affine_mjcf: ClassVar[bool] = True
    absent = (0.0, 0.0, 0.0)
    numeric = "cogging"
    n_parameters = 2
    counts = ("poles",)
    POLES = tuple(range(1, 25))

    def torque(self, robot, q, qd, load, t):
        G = robot.gear_ratio
        return -G * self.amplitude * np.sin(self.poles * G * q + self.phase)

    def add_to_simulation(self, spec, robot):
        for k, rotor in enumerate(robot.rotor_names):
            if not self.amplitude[k]:
                continue
            add_passive_dcmotor(spec, f"cogging{k + 1}", rotor,
                                cogging=[float(self.amplitude[k]), float(self.poles[k]), float(self.phase[k])])

    def grid(self, motion, axis):
        return list(self.POLES)

    def columns(self, motion, axis, h):
        G = motion.robot.gear_ratio[axis]
        angle = h * G * motion.q[:, axis]
        return G * np.stack([np.sin(angle), np.cos(angle)], axis=1), np.zeros(len(motion.t))

    def params(self, motion, axis, theta, h):
        # -A sin(x + phi) = -A cos(phi) sin(x) - A sin(phi) cos(x)
        amplitude = float(np.hypot(*theta))
        phase = float(np.arctan2(-theta[1], -theta[0]))
        return {"amplitude": amplitude, "poles": int(h), "phase": phase}

    def draw_direction(self, rng):
        phase = rng.uniform(0, 2 * np.pi)
        return np.array([np.cos(phase), np.sin(phase)])

    def motor_torque(self, motion, axis, params):
        return params["amplitude"]
