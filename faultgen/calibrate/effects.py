"""The effect library as the calibration uses it: :mod:`faultgen.effects`, with the motion the
effects are fitted on evaluated through the calibration's gearbox model.

Each effect of :mod:`faultgen.effects` gives the regressors of its torque change over the
current model (the candidate-term library of PySINDy, one term family per class): columns
``Phi`` and a known part ``offset`` such that the change is ``Phi @ theta + offset``, linear in
``theta``; a nonlinear parameter (a Stribeck velocity, a pole count, a time constant) is a small
grid searched outside the linear least squares, and an effect with no linear parameter
(backlash) brings its own search. The torque an effect predicts and the torque of the model it
writes are the same function (tests/test_calibrate_effects.py checks every effect), so the
model the workflow writes reproduces what was fitted. The thesis has no calibration chapter: the
friction effects refine its eq. 6.3 (Coulomb, viscous, Stribeck) and its wear model of eq. 6.6
(friction that changes with time); the others are the standard unmodelled effects of robot
identification.

All torques here are arm-side drive torques in N m (motor torque times the gear ratio G), the
unit of the measured ``tau`` columns.
"""

from __future__ import annotations

import numpy as np

from faultgen.calibrate import gearbox
from faultgen.effects import EFFECTS, REST_SPEED, Effect, Motion, get

__all__ = ["EFFECTS", "REST_SPEED", "Effect", "Motion", "get", "motion"]


def motion(robot, t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> Motion:
    """The :class:`~faultgen.effects.Motion` of a measured motion (time from its first sample) on
    ``robot``, with the flexible gearbox of :func:`faultgen.calibrate.gearbox.compliance_torque`."""
    return Motion.of(robot, t, q, qd, qdd, compliance=gearbox.compliance_torque)
