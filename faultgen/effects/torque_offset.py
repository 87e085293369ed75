"""A constant offset of the drive torque (current-sensor offset, unmodelled static load)."""

from __future__ import annotations

from typing import ClassVar

import mujoco
import numpy as np

from faultgen.effects.base import Effect, register


@register
class TorqueOffset(Effect):
    """A constant arm-side drive torque offset ``offset`` (N m) per axis; MJCF: custom numeric
    ``torque_offset{i}`` = offset.

    In the simulation a ``general`` actuator ``torque_offset{i}`` puts a constant bias
    ``-offset / G`` on the rotor, which the drive holds against, so the drive torque referred to
    the arm side shifts by ``+offset``. Identified as a change of the offset (one regressor of ones).
    """

    id = "torque_offset"
    rank = 10
    excited_by = (
        "motion in both directions over the range of loads (an offset keeps its sign when the speed "
        "reverses)")
    summary = "a constant torque offset"
    units: ClassVar[dict[str, str]] = {"offset": "N m (arm side)"}
    affine_mjcf: ClassVar[bool] = True
    absent = (0.0,)
    numeric = "torque_offset"
    signed = True

    def torque(self, robot, q, qd, load, t):
        return np.broadcast_to(self.offset, q.shape)

    def add_to_simulation(self, spec, robot):
        for k, rotor in enumerate(robot.rotor_names):
            if not self.offset[k]:
                continue
            actuator = spec.add_actuator(name=f"torque_offset{k + 1}", target=rotor)
            actuator.trntype = mujoco.mjtTrn.mjTRN_JOINT
            actuator.gaintype = mujoco.mjtGain.mjGAIN_FIXED
            actuator.gainprm[0] = 0.0
            actuator.biastype = mujoco.mjtBias.mjBIAS_AFFINE
            actuator.biasprm[:3] = [-float(self.offset[k] / robot.gear_ratio[k]), 0.0, 0.0]
            actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE

    def columns(self, motion, axis, h):
        return np.ones((len(motion.t), 1)), np.zeros(len(motion.t))

    def params(self, motion, axis, theta, h):
        return {"offset": float(self.current(motion.robot).offset[axis] + theta[0])}

    def motor_torque(self, motion, axis, params):
        return abs(params["offset"]) / motion.robot.gear_ratio[axis]
