"""The flexible gearbox in the torque prediction: what a rigid inverse dynamics misses.

A robot logs its motor encoders, ``q = theta_m / G``, while its arm sits on gearbox springs
(thesis eq. 6.2a: stiffness K, damping D per axis). The rigid inverse dynamics charges the arm's
inertia with the motor's motion; in truth the arm lags through the spring, and the drive feels
the spring force, not the rigid-body load. With the motor motion as measured, the deflections
``e = q - q_arm`` (vector over the axes) and the arm's equation ``M(q) q_arm'' + n = K e + D e'``
(thesis eq. 6.1 on the arm side of the springs; ``load = M q'' + n`` the rigid-body load
along the motor motion) give

    M(q) e'' + D e' + K e = load(t),

and the drive torque differs from the rigid prediction by ``K e + D e' - load = -M e''``. With
backlash b (:class:`faultgen.effects.backlash.Backlash`) the spring has a dead band, ``K e`` becomes
``S(e) = K sign(e) max(|e| - b/2, 0)`` per axis: when the load reverses the arm crosses the
gap, feels no spring while it does (the motor's motion does not reach it), and lands on the
other flank. ``M`` is the arm's inertia matrix along the measured motion
(:meth:`Robot.arm_mass_matrix`), so an axis crossing its gap moves the others it is coupled to
(the IRB-6700-like axes 2 and 3). The equation is integrated between samples with the Newmark
average-acceleration rule (implicit, unconditionally stable, no numerical damping) in sub-steps
of at most :data:`SUBSTEP`, the load interpolated linearly between samples; with a dead band
each sub-step is linear once it is known which flank every axis is on (or none), so it is
solved for a guess of the flanks, and again with the flanks the new deflections lie on until
they agree.

The equation is integrated only on the axes whose locked-arm resonance the measured
accelerations resolve (:data:`RESOLVED_HZ`; the derivative filter of :func:`faultgen.logs.measured.read`
has a pass band of about 20 Hz): a resonance above it rings in the equation, driven by the
measured motion, while the motor's answering ringing is filtered out of the measured ``qdd``.
On a stiffer axis (the PUMA 560's; the light wrist axes) the arm follows the motor rigidly,
and a dead band there is rigid contact (:func:`contact_deflection`): the arm crosses the gap
when the load reverses, coupled only by the damper, and lands without rebound; its
``-M e''`` is taken through the same derivative filter as the measured ``qdd``, so the impact's
momentum, which the motor takes up, cancels against the motor's filtered acceleration as it
does in the drive torque.

On hidden-effect data of the IRB-6700-like arm (locked-arm resonances 6-15 Hz) the equation
takes the held-out nrmse of a log with nothing hidden from 0.039 / 0.062 / 0.034 to
0.014 / 0.046 / 0.027 on axes 1 / 2 / 3 (axis by axis, without the coupling: axis 3 0.036; logs
of independently restarted cycles, whose restarts made most of axis 2's 0.046). On a PUMA 560
log with a dead band of 14.6 mrad on axis 1 (resonance 25-40 Hz) the equation at the true width
gave that axis 0.169 against 0.080 rigid, the rigid contact 0.036 (docs/calibration.md).
Against an ODE solver (LSODA) on a dead-band oscillator of 12.7 Hz and damping ratio 0.1 the
2 ms sub-steps are within 0.4-0.7 % RMS of the torque (the impacts' timing); on hidden-backlash
logs of the IRB-6700-like arm 1 ms and 0.5 ms sub-steps changed no nrmse by more than 0.0002.
The rigid contact against an event-located ODE solution: within 0.1 % of the width RMS
(tests/test_calibrate_gearbox.py).
"""

from __future__ import annotations

import hashlib

import numba
import numpy as np

from faultgen.logs import measured
from faultgen.effects.backlash import Backlash
from faultgen.model import robots

#: Longest sub-step, s. The average-acceleration rule's period error is about (w h)^2 / 12: 0.8 %
#: for a 25 Hz resonance (the softest gearbox here); shorter steps changed no figure.
SUBSTEP = 0.002
#: Largest resonance frequency times sub-step, rad, of an axis that is integrated (with 2 ms
#: sub-steps: resonances up to 40 Hz); an axis with a faster one (the light wrist axes) follows
#: the motor rigidly (rigid contact inside a dead band), as does one above :data:`RESOLVED_HZ`.
MAX_PHASE = 0.5
#: Most re-solves of a sub-step while the axes' flanks (dead band or which side) settle.
MAX_FLANK_CHANGES = 8
#: Highest locked-arm resonance, Hz (the lowest along the motion, at the arm's largest inertia),
#: that the spring equation is used for. The accelerations of a measured log come through the
#: derivative filter (:func:`faultgen.logs.measured.read`: Savitzky-Golay, 50 ms window), which keeps
#: 80 % of the amplitude at 18 Hz and half at 25 Hz. Above that the motor's ringing against the
#: arm is not in the measured ``qdd``, and the equation's ringing, driven by the measured motion,
#: is not what the drive felt: on a PUMA 560 log with a hidden dead band of 14.6 mrad on axis 1
#: (lowest resonance 25.5 Hz) the linear equation took that axis's held-out nrmse from 0.080
#: (rigid) to 0.113, and with the dead band to 0.169 (docs/calibration.md). The IRB-6700-like
#: axes 1-3 (5.7-14.5 Hz) are below it, the PUMA 560's above.
RESOLVED_HZ = 18.0
#: Sub-step of the rigid-contact dead band (:func:`contact_deflection`), s. On the PUMA 560 log
#: of docs/calibration.md (14.6 mrad on axis 1, at the fitted width) axis 1's held-out nrmse is
#: 0.0368 / 0.0370 / 0.0378 at 0.25-0.5 / 1 / 4 ms.
CONTACT_SUBSTEP = 1e-3


def compliance_torque(robot: robots.Robot, t: np.ndarray, q: np.ndarray, load: np.ndarray,
                      backlash: np.ndarray | None = None) -> np.ndarray:
    """Drive torque the gearboxes add to the rigid prediction, N m at the arm side: the gearbox
    equation on the axes whose resonance is resolved (:data:`RESOLVED_HZ`), rigid contact in the
    dead band on the others (module docstring).

    Parameters
    ----------
    robot : Robot
        Gives K, D (:attr:`Robot.gearbox_stiffness`, ``gearbox_damping``), the arm's inertia
        matrix (:meth:`Robot.arm_mass_matrix`) and the backlash (:class:`faultgen.effects.backlash.Backlash`) unless
        ``backlash`` is given.
    t : ndarray of shape (n,)
        Sample times, s, increasing.
    q : ndarray of shape (n, 6)
        Motor-side angles over the gear ratio, rad.
    load : ndarray of shape (n, 6)
        Rigid-body load of the arm joints along the motion, N m.
    backlash : ndarray of shape (6,) or (m, 6), optional
        Dead-band width per axis, rad at the arm side; a 2-D array evaluates ``m`` gearbox sets
        in one pass (the backlash search does). Default: the robot's.

    Returns
    -------
    ndarray of shape (n, 6), or (m, n, 6) for a 2-D ``backlash``
        ``-M e''``: ``S(e) + D e' - load`` from the gearbox equation, and the rigid contacts'
        deflection through the measured accelerations' filter; zero from a stiff axis without a
        dead band.

    Raises
    ------
    ValueError
        If ``backlash`` has a negative entry or its last dimension is not the robot's N.
    """
    t = np.asarray(t, dtype=float)
    width = np.asarray(Backlash.of(robot).width if backlash is None else backlash, dtype=float)
    if width.ndim == 0:  # one width for every axis (an effect made without the robot's axis count)
        width = np.full(load.shape[1], float(width))
    if width.shape[-1:] != (load.shape[1],) or width.ndim > 2 or np.any(width < 0):
        raise ValueError(f"backlash must be widths >= 0 rad of shape ({load.shape[1]},) or (m, {load.shape[1]}); "
                         f"got {width!r}")
    mass = _arm_mass(robot, q)
    K, D = robot.gearbox_stiffness, robot.gearbox_damping
    steps, substeps = _substeps(t)
    is_dynamic = _dynamic(robot, mass, float(np.max(steps)) / substeps)
    dynamic = np.flatnonzero(is_dynamic)
    widths = np.atleast_2d(width)
    # the gearbox equation once per distinct set of its axes' widths (a search varying another
    # axis repeats them)
    half, which = np.unique(widths[:, dynamic] / 2, axis=0, return_inverse=True)  # (distinct, d)
    out = np.zeros((len(widths),) + load.shape)
    if len(dynamic):
        out[:, :, dynamic] = _integrate(mass[:, dynamic][:, :, dynamic], K[dynamic], D[dynamic], half, steps,
                                        substeps, load[:, dynamic])[which.ravel()]
    # the dead bands of the other axes, each on its own: one problem per distinct (axis, width)
    # (a backlash search varies one axis at a time, so its sets share most widths), all in one pass
    stiff = np.flatnonzero(~is_dynamic & np.any(widths > 0, axis=0))
    if len(stiff):
        pairs = np.stack(np.broadcast_arrays(stiff, widths[:, stiff]), axis=-1).reshape(-1, 2)
        problems, which = np.unique(pairs, axis=0, return_inverse=True)
        axes = problems[:, 0].astype(int)
        e = contact_deflection(t, np.einsum("nii->ni", mass)[:, axes], D[axes], problems[:, 1], load[:, axes])
        acceleration = measured.acceleration(t, e)[:, which.reshape(len(widths), len(stiff))]  # (n, m, s)
        out -= np.einsum("nja,nma->mnj", mass[:, :, stiff], acceleration)
    return out if width.ndim == 2 else out[0]


#: The arm's inertia matrices along the last motion :func:`compliance_torque` was given, by robot
#: and the bits of ``q``: a backlash search evaluates hundreds of dead-band sets along one motion,
#: and :meth:`Robot.arm_mass_matrix` (four MuJoCo calls a sample) was recomputed for each call.
_LAST_MASS: dict = {}


def _arm_mass(robot: robots.Robot, q: np.ndarray) -> np.ndarray:
    """:meth:`Robot.arm_mass_matrix` of ``q`` (n, N), read-only, computed once for the last motion
    (:data:`_LAST_MASS`)."""
    q = np.ascontiguousarray(q, dtype=float)
    key = (id(robot), q.shape, hashlib.sha1(q.tobytes()).hexdigest())
    hit = _LAST_MASS.get(key)
    if hit is not None and hit[0] is robot:
        return hit[1]
    mass = robot.arm_mass_matrix(q)
    mass.setflags(write=False)
    _LAST_MASS.clear()
    _LAST_MASS[key] = (robot, mass)
    return mass


def contact_deflection(t: np.ndarray, inertia: np.ndarray, damping: np.ndarray, width: np.ndarray,
                       load: np.ndarray) -> np.ndarray:
    """Where the arm sits in the dead band of a stiff gearbox, rad: ``e = q - q_arm``.

    The stiff limit of the gearbox equation (module docstring), for the axes whose resonance
    the derivative filter does not resolve (:data:`RESOLVED_HZ`), each on its own: on a flank the
    arm moves with the motor (``e = +-b/2``, the spring's deflection ``load / K`` neglected)
    while the load presses it there (``load`` of the flank's sign); when the load reverses it
    leaves, and inside the gap only the damper couples it, ``m e'' + D e' = load``; it lands on
    a flank without rebound (the motor, held by its servo, takes the impact). The drive torque
    then differs from the rigid prediction by ``-M e''`` (:func:`compliance_torque` takes ``e''``
    through the measured accelerations' filter: the impact's momentum, which the motor takes
    up, cancels against the motor's filtered acceleration). Measured on a PUMA 560 log with a
    hidden dead band of 14.6 mrad on axis 1: the arm's crossings follow the simulator's within
    0.5 mrad RMS, and the axis's held-out nrmse is 0.036 against 0.080 rigid
    (docs/calibration.md).

    Parameters
    ----------
    t : ndarray of shape (n,)
        Sample times, s, increasing.
    inertia : ndarray of shape (n, p)
        The arm's inertia about the axis along the motion (diagonal element of
        :meth:`Robot.arm_mass_matrix`), kg m^2, per problem.
    damping : ndarray of shape (p,)
        Gearbox damping D of the problem's axis, N m s/rad.
    width : ndarray of shape (p,)
        Dead-band widths b, rad at the arm side, one per problem; 0 keeps ``e = 0``.
    load : ndarray of shape (n, p)
        Rigid-body load of the axis along the motion, N m, per problem.

    Returns
    -------
    ndarray of shape (n, p)
        The deflection at the samples, rad; it starts on the loaded flank.
    """
    half = np.asarray(width, dtype=float) / 2
    steps = np.diff(t)
    substeps = max(1, int(np.ceil(float(np.max(steps)) / CONTACT_SUBSTEP)))
    return _contact(np.ascontiguousarray(inertia, dtype=float), np.asarray(damping, dtype=float), half, steps,
                    substeps, np.ascontiguousarray(load, dtype=float))


def dynamic_axes(robot: robots.Robot, t: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Which axes :func:`compliance_torque` integrates, boolean of shape (6,): those whose
    locked-arm resonance along the motion the measured accelerations resolve
    (:data:`RESOLVED_HZ`) and the sub-steps follow (:data:`MAX_PHASE`); the others follow the
    motor rigidly, or by rigid contact inside a dead band."""
    steps, substeps = _substeps(np.asarray(t, dtype=float))
    return _dynamic(robot, _arm_mass(robot, q), float(np.max(steps)) / substeps)


def _substeps(t: np.ndarray) -> tuple[np.ndarray, int]:
    """Sample intervals (n,), s, and the number of sub-steps per interval."""
    steps = np.diff(t, prepend=t[0])
    return steps, max(1, int(np.ceil(float(np.max(steps)) / SUBSTEP)))


def _dynamic(robot: robots.Robot, mass: np.ndarray, h_max: float) -> np.ndarray:
    inertia = np.maximum(np.einsum("nii->ni", mass), 1e-12)
    fastest = np.sqrt(robot.gearbox_stiffness / inertia.min(axis=0))  # rad/s
    slowest = np.sqrt(robot.gearbox_stiffness / inertia.max(axis=0))
    return (fastest * h_max <= MAX_PHASE) & (slowest <= 2 * np.pi * RESOLVED_HZ)


def _integrate(mass, K, D, half, steps, substeps, load):
    """``-M e''`` of ``M e'' + D e' + S(e) = load`` along the samples, (m, n, d), for the ``m``
    dead-band half-widths ``half`` (m, d); ``mass`` (n, d, d), ``load`` (n, d)."""
    d = half.shape[1]
    # the step's matrix M + D h/2 + (K h^2/4 on the engaged axes) takes one of 2^d forms per
    # sample: invert them all up front (the step then costs a gather and a product)
    patterns = (np.arange(2**d)[:, None] >> np.arange(d)) & 1  # (2^d, d): 1 = on a flank
    h_all = steps / substeps
    diagonal = D * h_all[:, None, None] / 2 + patterns * K * (h_all**2)[:, None, None] / 4  # (n, 2^d, d)
    inverse = np.linalg.inv(mass[:, None] + diagonal[..., None] * np.eye(d))  # (n, 2^d, d, d)
    return _newmark(np.ascontiguousarray(mass), inverse, np.asarray(K, dtype=float), np.asarray(D, dtype=float),
                    np.ascontiguousarray(half), h_all, substeps, np.ascontiguousarray(load, dtype=float))


@numba.njit(cache=True)
def _newmark(mass, inverse, K, D, half, h_all, substeps, load):
    """The time loop of :func:`_integrate`, compiled (a sub-step is a few 3 x 3 products, which
    NumPy calls would spend their time dispatching); ``inverse`` (n, 2^d, d, d) holds the
    step's matrices for every pattern of engaged axes."""
    m, d = half.shape
    n = load.shape[0]
    out = np.zeros((m, n, d))
    e, v, a = np.empty(d), np.empty(d), np.empty(d)
    flank, landed = np.empty(d), np.empty(d)
    pe, pv, rhs, a_new, e_new = np.empty(d), np.empty(d), np.empty(d), np.empty(d), np.empty(d)
    for j in range(m):
        # start at rest, on the loaded flank
        for i in range(d):
            e[i] = load[0, i] / K[i] + np.sign(load[0, i]) * half[j, i]
            v[i] = 0.0
            a[i] = 0.0
            # +1 / -1 on the positive / negative flank, 0 inside the dead band
            flank[i] = np.sign(e[i]) if abs(e[i]) > half[j, i] else 0.0
        for k in range(1, n):
            h = h_all[k]
            for s in range(1, substeps + 1):
                fraction = s / substeps
                for i in range(d):
                    # the load is interpolated across the sample interval: M e'' is a small
                    # difference of large terms, and holding the load for a whole sample would
                    # shift it by half a sample (an error of load' dt / 2)
                    pe[i] = e[i] + h * v[i] + h * h / 4 * a[i]  # Newmark average acceleration
                    pv[i] = v[i] + h / 2 * a[i]
                # S(e) = K (e - flank b/2) on a flank, 0 in the dead band: for a guess of the
                # flanks the step is linear; solve, take the flanks the new deflection lies on
                # and repeat until they agree (an active set; one or two solves per sub-step)
                for _ in range(MAX_FLANK_CHANGES):
                    code = 0
                    for i in range(d):
                        f = load[k - 1, i] + fraction * (load[k, i] - load[k - 1, i])
                        engaged = abs(flank[i])
                        code += int(engaged) << i
                        rhs[i] = f - D[i] * pv[i] - engaged * K[i] * (pe[i] - flank[i] * half[j, i])
                    same = True
                    for i in range(d):
                        acc = 0.0
                        for l in range(d):
                            acc += inverse[k, code, i, l] * rhs[l]
                        a_new[i] = acc
                        e_new[i] = pe[i] + h * h / 4 * acc
                        landed[i] = np.sign(e_new[i]) if abs(e_new[i]) > half[j, i] else 0.0
                        same = same and landed[i] == flank[i]
                    if same:
                        break
                    for i in range(d):
                        flank[i] = landed[i]
                for i in range(d):
                    e[i], v[i], a[i] = e_new[i], pv[i] + h / 2 * a_new[i], a_new[i]
            for i in range(d):
                acc = 0.0
                for l in range(d):
                    acc += mass[k, i, l] * a[l]
                out[j, k, i] = -acc  # = S(e) + D e' - load
    return out


@numba.njit(cache=True)
def _contact(inertia, damping, half, steps, substeps, load):
    """The time loop of :func:`contact_deflection`, compiled, one problem after the other."""
    n, p = load.shape
    out = np.empty((n, p))
    for j in range(p):
        flank = np.sign(load[0, j]) if half[j] > 0 else 0.0  # +1 / -1 on a flank, 0 in the gap
        e = flank * half[j]
        v = 0.0
        out[0, j] = e
        for k in range(1, n):
            h = steps[k - 1] / substeps
            # inside the gap: m e'' + D e' = load, the damper implicit (Euler backward in e')
            gain, decay = h / inertia[k, j], 1 + h * damping[j] / inertia[k, j]
            for s in range(1, substeps + 1):
                f = load[k - 1, j] + s / substeps * (load[k, j] - load[k - 1, j])
                if flank * f < 0:
                    flank = 0.0  # the load reverses: the arm leaves
                if flank == 0:
                    v = (v + gain * f) / decay
                    e = e + h * v
                    if abs(e) >= half[j]:  # landed
                        flank = np.sign(e)
                        e = flank * half[j]
                        v = 0.0
                else:
                    v = 0.0
            out[k, j] = e
    return out
