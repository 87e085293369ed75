"""The static friction model's per-step update and a per-step stepping loop's inputs, compiled.

A batch stepped one step at a time from Python (:func:`faultgen.simulation.batch._step_each`:
the ``stribeck`` friction model on a backend that does not apply the update itself) pays, before
every MuJoCo step, the rotors' friction loss (:func:`faultgen.simulation.friction_update.apply`),
the drives' set-points, the load disturbance and the record of the last step's velocities. As
NumPy calls on a few numbers that cost several times MuJoCo's own step (docs/performance.md,
"Issue 87: the friction update compiled"); :func:`before_step` does all of it in one numba call.

The bits are :func:`~faultgen.simulation.friction_update.apply`'s: the same IEEE operations in the
same order on each element (no fastmath: no fused multiply-add, no reassociation), and ``exp`` and
``**`` calls of the C library's ``exp`` and ``pow``, which NumPy's float64 loops also call where
they are not dispatched to their own SIMD code (AVX-512). :func:`matches_numpy` says whether that
holds on this machine; where it does not, the caller keeps NumPy's update.

The kernels' arguments are typed once (explicit signatures: read-only inputs and writable
outputs of any layout), so one compilation, cached on disk (``cache=True``, numba's cache beside
this module), serves C-contiguous arrays and the strided views of a batch's state alike.
"""

from __future__ import annotations

import functools
import math
import platform

import numba
import numpy as np
from numba import types

#: Rows of the per-axis constants ``axis`` (8, N) the kernels read.
AXIS_ROWS = ("coulomb_pos", "coulomb_neg", "larger", "speed_scale", "exponent", "static", "gear_ratio", "stiffness")
#: Rows of the per-axis indices ``cols`` (4, N): where the speed and angles are read and the loss written.
COLS_ROWS = ("rotor_dof", "rotor_qpos", "arm_qpos", "target")

_R = {d: types.Array(types.float64, d, "A", readonly=True) for d in (1, 2, 3, 4)}
_W = {d: types.Array(types.float64, d, "A") for d in (2, 3)}
_I = {d: types.Array(types.int64, d, "A", readonly=True) for d in (1, 2)}
#: k, qvel, qpos, level, axis, cols, load, target
_FRICTION = (types.int64, _R[2], _R[2], _R[3], _R[2], _I[2], _R[4], _W[2])
#: k, at, per_log, friction, ctrl, drive_ctrl, inputs, applied, arm_dof, dist, speeds, velocity
_INPUTS = (types.int64, types.int64, types.int64, types.boolean, _W[2], _I[2], _R[3], _W[2], _I[1], _R[3], _R[2],
           _W[3])

#: Arguments of :func:`write` for no run (:func:`before_step` without the friction loss).
NO_UPDATE = (np.zeros((0, 0)), np.zeros((0, 0)), np.zeros((0, 0, 0)), np.zeros((8, 0)), np.zeros((4, 0), np.int64),
             np.zeros((2, 0, 0, 0)), np.zeros((0, 0)))

#: NumPy's float64 ``exp`` and ``power`` loop targets whose bits are the C library's (the
#: scalar ``exp`` / ``pow``), as numba's are: checked on 2 million random values (x86-64 AVX2,
#: NumPy 2.4, numba 0.68, 2026-11-28). An AVX-512 (X86_V4) target runs NumPy's own SIMD code.
LIBM_TARGETS = ("baseline(X86_V2)", "X86_V3")


def matches_numpy(info: dict | None = None, machine: str | None = None, svml: bool | None = None) -> bool:
    """Whether the kernels' ``exp`` and ``**`` give NumPy's float64 bits here: an x86-64 machine
    where NumPy runs the C library's ``exp`` and ``pow`` (its loops dispatched to a target of
    :data:`LIBM_TARGETS`, from :func:`numpy.lib.introspect.opt_func_info`, or ``info`` of that
    form) and numba does not use Intel's SVML (``svml``, numba's ``USING_SVML``)."""
    if info is None:
        from numpy.lib.introspect import opt_func_info
        info = opt_func_info(func_name="^(exp|power)$", signature="^float64")
    machine = platform.machine() if machine is None else machine
    svml = numba.config.USING_SVML if svml is None else svml
    try:
        current = (info["exp"]["dd"]["current"], info["power"]["ddd"]["current"])
    except KeyError:
        return False
    return machine.lower() in ("x86_64", "amd64") and not svml and all(t in LIBM_TARGETS for t in current)


@functools.cache
def numpy_bits() -> bool:
    """:func:`matches_numpy` on this machine (asked once a process)."""
    return matches_numpy()


@numba.njit(cache=True)
def _friction(k, qvel, qpos, level, axis, cols, load, target):
    """The friction loss of :func:`faultgen.simulation.friction_update.apply` at step ``k``
    into ``target[:, cols[3]]``: per run and axis the dry level by the speed's sign (the larger at
    rest), plus ``static exp(-(|v| / |v_s|) ^ g)``, times the step's level, plus each transmitted
    load term ``outer (inner |K (q_m / G - q_a)| / G)`` of ``load`` (2, nsim, T, N), in order."""
    nsim, n = level.shape[0], level.shape[2]
    for i in range(nsim):
        for a in range(n):
            v = qvel[i, cols[0, a]]
            if v > 0:
                coulomb = axis[0, a]
            elif v < 0:
                coulomb = axis[1, a]
            else:  # at rest (or NaN: the loss is NaN either way)
                coulomb = axis[2, a]
            stribeck = axis[5, a] * math.exp(-((abs(v) / axis[3, a]) ** axis[4, a]))
            loss = (coulomb + stribeck) * level[i, k, a]
            if load.shape[2]:
                G = axis[6, a]
                transmitted = axis[7, a] * (qpos[i, cols[1, a]] / G - qpos[i, cols[2, a]])
                for t in range(load.shape[2]):
                    loss = loss + load[1, i, t, a] * (load[0, i, t, a] * abs(transmitted) / G)
            target[i, cols[3, a]] = loss


@numba.njit(_FRICTION, cache=True)
def write(k, qvel, qpos, level, axis, cols, load, target):
    """:func:`_friction` alone (``friction_update.writer``'s step)."""
    _friction(k, qvel, qpos, level, axis, cols, load, target)


@numba.njit(_INPUTS + _FRICTION[1:], cache=True)
def before_step(k, at, per_log, friction, ctrl, drive_ctrl, inputs, applied, arm_dof, dist, speeds, velocity,
                qvel, qpos, level, axis, cols, load, target):
    """What a per-step loop does before MuJoCo's step ``at`` (``k`` of its chunk): the last step's
    velocities ``speeds`` (the live ``qvel``) into ``velocity[:, k - 1]`` (from the second step
    on), the friction loss (:func:`_friction` of the last seven arguments, where ``friction``), the
    set-points ``ctrl[:, drive_ctrl] = inputs[at]`` and, at a log period's first step or the
    chunk's first, the disturbance ``applied[:, arm_dof] = dist[:, at // per_log]``."""
    nsim = ctrl.shape[0]
    if k > 0:
        for i in range(nsim):
            for j in range(velocity.shape[2]):
                velocity[i, k - 1, j] = speeds[i, j]
    if friction:
        _friction(k, qvel, qpos, level, axis, cols, load, target)
    for i in range(nsim):
        for a in range(drive_ctrl.shape[0]):
            for j in range(drive_ctrl.shape[1]):
                ctrl[i, drive_ctrl[a, j]] = inputs[at, a, j]
    if k == 0 or at % per_log == 0:
        period = at // per_log
        for i in range(nsim):
            for a in range(arm_dof.shape[0]):
                applied[i, arm_dof[a]] = dist[i, period, a]
