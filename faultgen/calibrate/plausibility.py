"""Is the log one the robot can explain at all? The guard the workflow runs before it fits anything.

A missing effect changes the drive torque by a part of it; a log from another robot, a torque
column at the motor side or in another unit changes it by a factor. Per axis, the measured torque
is regressed on the nominal model's prediction along the measured motion (least squares with an
intercept, so a torque offset does not count, over the samples where the axis moves): the slope
is about 1 for the right robot whatever the library's effects add (hidden-effect logs of every
effect on both robots, 2 seeds: 0.65-2.0; an independent simulator's PUMA 560: 1.00), and far
from it otherwise (arm-side torque of a PUMA 560 read as an IRB-6700-like arm: 0.006-0.03; the
other way round 12-105; motor-side torque: 1 / gear ratio, 0.004-0.03). docs/calibration.md
lists the figures and the script that measured them.

An axis is judged only where its predicted torque varies (standard deviation at least
:data:`MIN_VARIATION` of its RMS over at least :data:`MIN_SAMPLES` moving samples): a slope
against a nearly constant prediction is not defined.
"""

from __future__ import annotations

import numpy as np

from faultgen import axes

#: Slopes of the measured on the predicted torque accepted as the same robot, units and side.
SLOPE_RANGE = (0.2, 5.0)
#: Smallest standard deviation of an axis's predicted torque, as a share of its RMS, to judge it.
MIN_VARIATION = 0.1
#: Fewest moving samples of an axis to judge it.
MIN_SAMPLES = 100


class ImplausibleLogError(ValueError):
    """Raised when the nominal model cannot explain a log: another robot, motor-side torque, a
    torque column in another unit or with the other sign. The message names the column, the
    factor found and what to check."""


def slopes(tau: np.ndarray, predicted: np.ndarray, moving: np.ndarray) -> np.ndarray:
    """Per axis, the least-squares slope of the measured torque ``tau`` (n, 6) on the predicted
    ``predicted`` (n, 6) with an intercept, over the samples of ``moving`` (n, 6); NaN where the
    axis is not judged (see the module docstring). Dimensionless, shape (6,)."""
    out = np.full(tau.shape[1], np.nan)
    for k in range(tau.shape[1]):
        rows = moving[:, k]
        if rows.sum() < MIN_SAMPLES:
            continue
        x, y = predicted[rows, k], tau[rows, k]
        spread = x.std()
        if spread < MIN_VARIATION * np.sqrt(np.mean(x**2)) or spread == 0:
            continue
        out[k] = np.cov(x, y, bias=True)[0, 1] / spread**2
    return out


def check(robot, tau: np.ndarray, predicted: np.ndarray, moving: np.ndarray) -> None:
    """Refuse a log the nominal ``robot`` cannot explain (module docstring).

    Parameters
    ----------
    robot : faultgen.model.robots.Robot
        The nominal model (its name and gear ratios go into the message).
    tau, predicted : ndarray of shape (n, 6)
        Measured and predicted arm-side drive torque, N m.
    moving : ndarray of bool, shape (n, 6)
        Samples where each axis moves.

    Raises
    ------
    ImplausibleLogError
        If a judged axis has a slope outside :data:`SLOPE_RANGE`.
    """
    s = slopes(tau, predicted, moving)
    low, high = SLOPE_RANGE
    bad = [k for k in range(len(s)) if np.isfinite(s[k]) and not low <= s[k] <= high]
    if not bad:
        return
    judged = [k for k in range(len(s)) if np.isfinite(s[k])]
    G = np.asarray(robot.gear_ratio)
    found = ", ".join(f"tau{axes.number(k)} {s[k]:.3g}" for k in judged)
    if all(0.5 <= s[k] * G[k] <= 2.0 for k in judged):
        raise ImplausibleLogError(
            f"the torque looks like motor-side torque: on every axis it is about 1 / gear ratio of what "
            f"{robot.name} predicts at the arm side ({found}; gear ratios "
            f"{', '.join(f'{g:.4g}' for g in G)}); the calibration needs arm-side torque (N m): multiply each "
            f"column tau1..tau6 by its axis's gear ratio")
    negative = [k for k in bad if s[k] < 0]
    if negative:
        columns = ", ".join(f"tau{axes.number(k)}" for k in negative)
        raise ImplausibleLogError(
            f"column(s) {columns} run against the torque {robot.name} predicts along this motion (slope "
            f"{', '.join(f'{s[k]:.3g}' for k in negative)}; expected about 1): check the sign convention of "
            f"those columns, and that the log is from a {robot.name} (--robot)")
    columns = ", ".join(f"tau{axes.number(k)} is {s[k]:.3g} x" for k in bad)
    raise ImplausibleLogError(
        f"the measured torque is not what {robot.name} could produce along this motion: {columns} the torque "
        f"the model predicts (accepted {low:g}-{high:g} x; every judged axis: {found}). Check that the log is "
        f"from a {robot.name} (--robot; `faultgen robots` lists the models), that tau is in N m and at the arm "
        f"side (motor torque times gear ratio)")


#: A calibrated Stribeck velocity more than this many times the nominal one (or less than its
#: inverse) is not a friction the drive has: a hump fitted to something else (a KR210 calibrated on
#: a log whose only differences from nominal were unit spread and temperature got 216 rad/s,
#: nominal 10, and its twin saturated two axes).
STRIBECK_RATIO = 10.0
#: A calibrated dry friction (Coulomb or static, motor side) above this share of the motor's
#: torque limit leaves the drive too little to move the arm: not a friction a working robot has.
FRICTION_SHARE = 0.5
#: A calibrated Coulomb level more than this many times the nominal one (or less than its
#: inverse) is not a unit's spread (15 % on the independent fleets) nor its wear (the monitor reads
#: up to 40-60 %): on a motion of few steady speeds a lower dry level and a higher viscous one give
#: nearly the same torque, and a fit can trade one for the other. On 70 calibrations of six
#: independent fleets (docs/analysis.md, "A calibration refused as implausible") the levels lay at
#: 0.61-1.59 x nominal; the own friction fitted on a KR210 L150's nominal model alone put axis 2's
#: at 0.16 x (its viscous level 3.45 x), and that healthy unit's axis 2 read 23 % wear.
COULOMB_RATIO = 3.0


def implausible_parameters(nominal, calibrated) -> list[str]:
    """What makes a calibrated robot's friction implausible against its nominal model, one text per
    finding (empty when none): a Stribeck velocity beyond :data:`STRIBECK_RATIO` times the nominal
    one, a Coulomb level (the mean of both directions) beyond :data:`COULOMB_RATIO` times the
    nominal one, a Coulomb or static friction above :data:`FRICTION_SHARE` of the motor's torque limit.
    ``nominal`` and ``calibrated`` are :class:`faultgen.model.robots.Robot` of the same axes."""
    found = []
    f0, f1 = nominal.friction, calibrated.friction
    for i in range(nominal.n_axes):
        v0, v1 = float(f0.stribeck_velocity[i]), float(f1.stribeck_velocity[i])
        if v0 > 0 and not (1 / STRIBECK_RATIO <= v1 / v0 <= STRIBECK_RATIO):
            found.append(f"axis {i + 1}: Stribeck velocity {v1:.3g} rad/s, {v1 / v0:.3g} x its nominal {v0:.3g} "
                         f"(accepted: {1 / STRIBECK_RATIO:g}-{STRIBECK_RATIO:g} x)")
        c0 = (abs(float(f0.coulomb_pos[i])) + abs(float(f0.coulomb_neg[i]))) / 2
        c1 = (abs(float(f1.coulomb_pos[i])) + abs(float(f1.coulomb_neg[i]))) / 2
        if c0 > 0 and not (1 / COULOMB_RATIO <= c1 / c0 <= COULOMB_RATIO):
            found.append(f"axis {i + 1}: Coulomb friction {c1:.3g} N m at the motor, {c1 / c0:.3g} x its nominal "
                         f"{c0:.3g} (accepted: {1 / COULOMB_RATIO:.3g}-{COULOMB_RATIO:g} x)")
        dry = max(abs(float(f1.coulomb_pos[i])), abs(float(f1.coulomb_neg[i])), abs(float(f1.static[i])))
        limit = float(calibrated.motor_torque_limit[i])
        if dry > FRICTION_SHARE * limit:
            found.append(f"axis {i + 1}: dry friction {dry:.3g} N m at the motor, {dry / limit:.2g} of the motor's "
                         f"torque limit {limit:.3g} N m (accepted: <= {FRICTION_SHARE:g})")
    return found
