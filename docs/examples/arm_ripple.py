"""Your own effect for `faultgen calibrate --effects`: a torque ripple periodic in the ARM angle.

The library's cogging is periodic in the motor angle; a gear's eccentricity, a cable or a
balancing spring's linkage gives a torque periodic in the arm angle instead, which no effect of
the library holds. This class follows the template of faultgen/effects/base.py:

    faultgen calibrate --robot puma560 --measured log.csv --out calib \
        --effects docs/examples/arm_ripple.py:ArmRipple

(or `--effects arm_ripple:ArmRipple` with docs/examples on PYTHONPATH). The calibration then fits
it beside the library's effects; when it explains an axis's remainder it is named and written into
the model (custom numeric `arm_ripple{i}` = amplitude, periods, phase). docs/calibration.md,
"Your own effect".
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from faultgen.effects import Effect


class ArmRipple(Effect):
    """``amplitude sin(periods q + phase)`` of the arm-side drive torque (amplitude N m, periods per
    arm revolution, phase rad), per axis; identified per period count with sin and cos regressors."""

    id = "arm_ripple"
    rank = 90
    summary = "a torque ripple periodic in the arm angle"
    units: ClassVar[dict[str, str]] = {"amplitude": "N m (arm side)", "periods": "1", "phase": "rad"}
    absent = (0.0, 0.0, 0.0)
    numeric = "arm_ripple"
    n_parameters = 2
    counts = ("periods",)
    designable = False
    excited_by = "motion over a wide range of the arm angle (the ripple repeats with it)"
    PERIODS = tuple(range(1, 7))

    def torque(self, robot, q, qd, load, t):
        """The ripple along a motion, N m, (n, N)."""
        return self.amplitude * np.sin(self.periods * q + self.phase)

    def grid(self, motion, axis):
        """Period counts searched."""
        return list(self.PERIODS)

    def columns(self, motion, axis, h):
        """sin and cos of ``h`` times the arm angle: the change is linear in them."""
        angle = h * motion.q[:, axis]
        return np.stack([np.sin(angle), np.cos(angle)], axis=1), np.zeros(len(motion.t))

    def params(self, motion, axis, theta, h):
        """A sin(x + phi) = A cos(phi) sin(x) + A sin(phi) cos(x)."""
        return {"amplitude": float(np.hypot(*theta)), "periods": int(h), "phase": float(np.arctan2(theta[1], theta[0]))}
