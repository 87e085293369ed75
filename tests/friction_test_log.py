"""A friction test's log made by another simulator, with a friction law unlike faultgen's, for the
test reader (``tests/test_friction_test.py``, ``benchmarks/friction_test_independent.py``).

Independent of faultgen: the rigid-body dynamics (roboticstoolbox-python's recursive Newton-Euler
on the IRB-6700-like arm in DH form, :func:`toolbox_robots.irb6700`, its own friction removed, plus
the axis-2 balancing spring by formula); the test motion, written here and not by
``faultgen tasks friction-test`` (its own posture, speeds, strokes, trapezoidal ramps of constant
acceleration instead of ruckig's jerk-limited ones, the minus direction first); and the friction law
(:func:`friction`): arm side, an exponential Stribeck hump (faultgen's is Gaussian), tanh sign
smoothing (faultgen's static map uses sign, its simulation LuGre bristles), dry and viscous levels
falling with temperature (linear and exponential). Shared: the arm's parameters (those of
robots/irb6700/README.md, as toolbox_robots says) and the reader's robot folder (irb6700), used
by the reader only where a direction is missing.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

import toolbox_robots

#: Log rate, Hz.
RATE = 250.0
#: The truth at REFERENCE_T degC, arm side, per axis: dry level N m, viscous N m s/rad, hump N m
#: and its decay speed rad/s.
DRY = np.array([230.0, 260.0, 370.0, 60.0, 85.0, 60.0])
VISCOUS = np.array([150.0, 210.0, 170.0, 25.0, 35.0, 20.0])
HUMP = 0.3 * DRY
HUMP_SPEED = np.array([0.02, 0.02, 0.025, 0.05, 0.05, 0.06])
REFERENCE_T = 20.0
#: Dry friction falls 0.6 %/K, viscous as exp(-0.015 (T - 20)) (Bittencourt's trend: both fall with temperature).
DRY_SLOPE, VISCOUS_RATE = 0.006, 0.015
#: Sign smoothing speed, rad/s.
SMOOTHING = 2e-3
#: The motion: posture (deg), speeds per axis (rad/s), steady time (s), acceleration (rad/s^2), dwell (s).
POSTURE = np.radians([-20.0, 10.0, -30.0, 40.0, 60.0, -50.0])
SPEEDS = [np.geomspace(0.012, top, 6) for top in (0.96, 0.96, 0.96, 1.6, 1.3, 1.8)]
STEADY, ACCELERATION, DWELL = 1.0, 2.0, 0.3
#: Acceleration of the moves between strokes, rad/s^2: triangular, never at a constant speed.
REPOSITION = 0.5


def truth(temperature: float) -> tuple[np.ndarray, np.ndarray]:
    """The dry level (N m) and viscous coefficient (N m s/rad) per axis at ``temperature`` degC, arm side."""
    dt = temperature - REFERENCE_T
    return DRY * (1 - DRY_SLOPE * dt), VISCOUS * np.exp(-VISCOUS_RATE * dt)


def friction(qd: np.ndarray, temperature: float) -> np.ndarray:
    """Arm-side friction torque, N m, shape of ``qd`` (n, 6): ``tanh(v / s) (F_c + F_h exp(-|v| / v_h)) + F_v v``."""
    dry, viscous = truth(temperature)
    hump = HUMP * (1 - DRY_SLOPE * (temperature - REFERENCE_T))
    return np.tanh(qd / SMOOTHING) * (dry + hump * np.exp(-np.abs(qd) / HUMP_SPEED)) + viscous * qd


def _move(distance: float, v: float, a: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A trapezoidal move of ``distance`` rad (signed) at most ``v`` rad/s, ``a`` rad/s^2, sampled at RATE
    (the first sample excluded): offset, speed and acceleration."""
    d, s = abs(distance), np.sign(distance)
    if d < 1e-12:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    v = min(v, np.sqrt(d * a))
    ta = v / a
    total = 2 * ta + (d - v * ta) / v
    t = np.arange(1, int(np.ceil(total * RATE)) + 1) / RATE
    t = np.minimum(t, total)
    x = np.where(t < ta, 0.5 * a * t**2,
                 np.where(t < total - ta, 0.5 * a * ta**2 + v * (t - ta), d - 0.5 * a * (total - t) ** 2))
    xd = np.where(t < ta, a * t, np.where(t < total - ta, v, a * (total - t)))
    xdd = np.where(t < ta, a, np.where(t < total - ta, 0.0, -a))
    return s * x, s * xd, s * xdd


def motion(axes=range(6), one_way: int | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The test motion: ``t`` (n,) s, ``q``, ``qd``, ``qdd`` (n, 6); per axis, per speed: the stroke's
    far end, then at speed the stroke back (minus first) and forth, with dwells; moves between them
    without a constant speed (triangular, :data:`REPOSITION` rad/s^2). Axis ``one_way`` (0-based) runs
    its minus strokes that way too: its test holds one direction only."""
    q = [POSTURE.copy()]
    qd, qdd = [np.zeros(6)], [np.zeros(6)]

    def go(k, distance, v, a=ACCELERATION):
        x, xd, xdd = _move(distance, v, a)
        rows = np.repeat(q[-1][None], len(x), axis=0)
        rows[:, k] += x
        fast = np.zeros((len(x), 6))
        accel = np.zeros((len(x), 6))
        fast[:, k], accel[:, k] = xd, xdd
        q.extend(rows), qd.extend(fast), qdd.extend(accel)

    def dwell():
        n = int(DWELL * RATE)
        q.extend([q[-1]] * n), qd.extend([np.zeros(6)] * n), qdd.extend([np.zeros(6)] * n)

    for k in axes:
        for v in SPEEDS[k]:
            half = max(v * (STEADY + v / ACCELERATION), np.radians(2.0)) / 2
            go(k, POSTURE[k] + half - q[-1][k], 10.0, REPOSITION)
            dwell()
            if k == one_way:
                go(k, -2 * half, 10.0, REPOSITION)
            else:
                go(k, -2 * half, v)
            dwell()
            go(k, 2 * half, v)
            dwell()
        go(k, POSTURE[k] - q[-1][k], 10.0, REPOSITION)
    q, qd, qdd = np.array(q), np.array(qd), np.array(qdd)
    return np.arange(len(q)) / RATE, q, qd, qdd


def write_log(path: Path, temperature: float, axes=range(6), noise: float = 0.5, seed: int = 0,
              one_way: int | None = None) -> Path:
    """Write the test's log (``t, q1..q6, tau1..tau6, temperature1..6``; no ``qd``: the reader estimates it)
    at ``temperature`` degC, Gaussian torque noise of ``noise`` N m (seeded); ``one_way`` as :func:`motion`."""
    t, q, qd, qdd = motion(axes, one_way)
    arm = toolbox_robots.irb6700().nofriction(coulomb=True, viscous=True)
    tau = arm.rne(q, qd, qdd) + toolbox_robots.irb6700_balance_torque(q) + friction(qd, temperature)
    tau = tau + np.random.default_rng(seed).normal(0.0, noise, tau.shape)
    columns = {"t": t, **{f"q{k + 1}": q[:, k] for k in range(6)}, **{f"tau{k + 1}": tau[:, k] for k in range(6)},
               **{f"temperature{k + 1}": np.full(len(t), temperature) for k in range(6)}}
    pd.DataFrame(columns).to_csv(path, index=False)
    return Path(path)
