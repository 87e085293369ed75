"""The flexible gearbox in the torque prediction: what a rigid inverse dynamics misses.

A robot logs its motor encoders, ``q = theta_m / G``, while its arm sits on gearbox springs
(thesis eq. 6.2a: stiffness K, damping D per axis). The rigid inverse dynamics charges the arm's
inertia with the motor's motion; in truth the arm lags through the spring, and the drive feels
the spring force, not the rigid-body load. Per axis, with the motor motion as measured and the
deflection ``e = q - q_arm``, the arm's equation ``M_ii q_arm'' = K e + D e' - N(t)`` (N the
rest of the rigid-body load, ``load = M_ii q'' + N``) gives

    M_ii(q) e'' + D e' + K e = load(t),

and the drive torque differs from the rigid prediction by ``K e + D e' - load``. With backlash
b (:attr:`Robot.backlash`) the spring has a dead band, ``K e`` becomes
``S(e) = K sign(e) max(|e| - b/2, 0)``: when the load reverses the arm crosses the gap, feels no
spring while it does (so the motor's motion does not reach it), and lands on the other flank.
The axes are
taken one at a time (their inertial coupling is left in ``load``) and ``M_ii`` is the diagonal
of the arm's inertia matrix along the measured motion. The equation is integrated between
samples with the Newmark average-acceleration rule (implicit, unconditionally stable, no
numerical damping) in sub-steps of at most :data:`SUBSTEP`, the load interpolated linearly
between samples; with a dead band each sub-step's equation is piecewise linear and monotone in
the new acceleration, and is solved exactly (inside the gap, else on the flank it lands on).

On hidden-effect data of the IRB-6700-like arm (locked-arm resonances 10-25 Hz) this takes the
held-out nrmse of a log with nothing hidden from 0.039 / 0.062 to 0.014 / 0.045 on axes 1 / 2;
on the stiffer PUMA 560 it changes less than 0.001 (docs/calibration.md). Against an ODE
solver (LSODA) on a dead-band oscillator of 32 Hz and damping ratio 0.1 the 2 ms sub-steps
are within 3-4 % RMS of the torque (the impacts' timing; 0.5 % at 0.5 ms sub-steps); on
hidden-backlash logs of the IRB-6700-like arm 1 ms and 0.5 ms sub-steps changed no nrmse by
more than 0.0002 (tests/test_calibrate_gearbox.py, docs/calibration.md).
"""

from __future__ import annotations

import numpy as np

from faultgen import robots

#: Longest sub-step, s. The average-acceleration rule's period error is about (w h)^2 / 12: 0.8 %
#: for a 25 Hz resonance (the softest gearbox here); shorter steps changed no figure.
SUBSTEP = 0.002
#: Largest resonance frequency times sub-step, rad, of an axis that is integrated (with 2 ms
#: sub-steps: resonances up to 40 Hz); an axis with a faster one (the light wrist axes) carries
#: its load quasi-statically, e = load / K, and gets no correction.
MAX_PHASE = 0.5


def compliance_torque(robot: robots.Robot, t: np.ndarray, q: np.ndarray, load: np.ndarray,
                      backlash: np.ndarray | None = None) -> np.ndarray:
    """Drive torque the gearbox springs add to the rigid prediction, N m at the arm side.

    Parameters
    ----------
    robot : Robot
        Gives K, D (:attr:`Robot.gearbox_stiffness`, ``gearbox_damping``), the arm inertia and
        the backlash (:attr:`Robot.backlash`) unless ``backlash`` is given.
    t : ndarray of shape (n,)
        Sample times, s, increasing.
    q : ndarray of shape (n, 6)
        Motor-side angles over the gear ratio, rad.
    load : ndarray of shape (n, 6)
        Rigid-body load of the arm joints along the motion, N m.
    backlash : ndarray of shape (6,) or (m, 6), optional
        Dead-band width per axis, rad at the arm side; a 2-D array evaluates ``m`` gearboxes in
        one pass (the backlash search does). Default: the robot's.

    Returns
    -------
    ndarray of shape (n, 6), or (m, n, 6) for a 2-D ``backlash``
        ``S(e) + D e' - load`` per sample and axis; zero on axes carried quasi-statically.

    Raises
    ------
    ValueError
        If ``backlash`` has a negative entry or its last dimension is not 6.
    """
    t = np.asarray(t, dtype=float)
    width = np.asarray(robot.backlash if backlash is None else backlash, dtype=float)
    if width.shape[-1:] != (load.shape[1],) or width.ndim > 2 or np.any(width < 0):
        raise ValueError(f"backlash must be widths >= 0 rad of shape (6,) or (m, 6); got {width!r}")
    half = np.atleast_2d(width) / 2  # (m, 6)
    inertia = robot.arm_inertia(q)
    K, D = robot.gearbox_stiffness, robot.gearbox_damping
    steps = np.diff(t, prepend=t[0])
    substeps = max(1, int(np.ceil(float(np.max(steps)) / SUBSTEP)))
    h_max = float(np.max(steps)) / substeps
    # axes whose resonance the sub-step cannot follow carry their load quasi-statically (K e = load)
    dynamic = np.sqrt(K / np.maximum(inertia.min(axis=0), 1e-12)) * h_max <= MAX_PHASE
    # start at rest on the loaded flank
    e = load[0] / K + np.sign(load[0]) * half
    v = np.zeros_like(half)
    a = np.zeros_like(half)
    out = np.zeros((len(half),) + load.shape)
    fractions = np.arange(1, substeps + 1) / substeps
    for k in range(1, len(t)):
        h = steps[k] / substeps
        m, before, after = inertia[k], load[k - 1], load[k]
        free = m + D * h / 2  # effective mass inside the dead band
        engaged = free + K * h * h / 4  # ... and on a flank
        for fraction in fractions:
            # the load is interpolated across the sample interval: M e'' is a small difference
            # of large terms, and holding the load for a whole sample would shift it by half a
            # sample (an error of load' dt / 2)
            f = before + fraction * (after - before)
            # Newmark average acceleration (trapezoidal rule): unconditionally stable, no
            # numerical damping of the resonance
            predicted_e = e + h * v + h * h / 4 * a
            predicted_v = v + h / 2 * a
            base = f - D * predicted_v
            # the spring S(e) = K sign(e) max(|e| - b/2, 0) is piecewise linear and the step's
            # equation monotone in the new acceleration: solve it inside the dead band, and if
            # the deflection it gives lies past a flank, on that flank (exact, no iteration)
            a_new = base / free
            e_new = predicted_e + h * h / 4 * a_new
            flank = np.where(e_new > half, half, np.where(e_new < -half, -half, np.nan))
            on_flank = ~np.isnan(flank)
            a_flank = (base - K * (predicted_e - np.where(on_flank, flank, 0.0))) / engaged
            a_new = np.where(on_flank, a_flank, a_new)
            e = predicted_e + h * h / 4 * a_new
            v = predicted_v + h / 2 * a_new
            a = a_new
        out[:, k] = -m * a  # = S(e) + D e' - load
    out = np.where(dynamic, out, 0.0)
    return out if width.ndim == 2 else out[0]
