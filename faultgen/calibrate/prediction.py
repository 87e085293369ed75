"""A model's drive torque along a measured motion: what calibration compares with the measured
torque (:func:`predict`), and the motion it was evaluated on (:func:`predicted_motion`, which the
effect search fits on). Both the calibration loop (:mod:`faultgen.calibrate`) and the sysid refit
(:mod:`faultgen.calibrate.refit`) use it.
"""

from __future__ import annotations

import numpy as np

from faultgen.calibrate import gearbox
from faultgen.calibrate.effects import Motion
from faultgen.calibrate.effects import motion as motion_of
from faultgen.logs import measured as measured_io
from faultgen.model import robots


def predict(robot: robots.Robot, data: measured_io.MeasuredData) -> np.ndarray:
    """A model's drive torque along a measured motion, N m at the arm side, shape (n, 6).

    :meth:`faultgen.model.robots.Robot.inverse_dynamics` (rigid body, motor inertia, friction and the
    model's optional effects, time from the first sample) plus the torque of the flexible
    gearboxes (:func:`faultgen.calibrate.gearbox.compliance_torque`).
    """
    return predicted_motion(robot, data)[0]


def predicted_motion(robot: robots.Robot, data: measured_io.MeasuredData) -> tuple[np.ndarray, Motion]:
    """:func:`predict` and the :class:`Motion` it evaluated (the search fits effects on it)."""
    motion = motion_of(robot, data.t, data.q, data.qd, data.qdd)
    rigid = robot.inverse_dynamics(data.q, data.qd, data.qdd, t=motion.t)
    return rigid + gearbox.compliance_torque(robot, data.t, data.q, motion.load), motion
