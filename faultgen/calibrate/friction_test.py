"""Reading a friction test from a log: its constant-speed segments found without being told where
they are, and each axis's friction torque at each speed by direction differencing.

Any log of a test motion reads, faultgen's (``faultgen tasks friction-test``) or a maker's own
routine, as long as it holds the minimum (:data:`MIN_SPEEDS`, :data:`MIN_STEADY`): per axis at least
3 distinct constant speeds in each direction, each held at least 0.5 s with only that axis moving.

**Segments** (:func:`segments`). A sample belongs to axis ``k`` when ``|qd_k|`` is above
:data:`SPEED_FLOOR` and at least :data:`DOMINANCE` times every other axis's speed. In each run of
such samples of one sign, the plateau speed is the median of the samples within 5 % of the run's
99th-percentile speed; the steady part is the longest stretch within :data:`SPEED_TOLERANCE` of it,
less :data:`TRIM` s at each end; kept when it lasts :data:`MIN_STEADY` s.

**Differencing** (:func:`friction_points`). Segments of one axis whose speeds agree within
:data:`SAME_SPEED` are one speed. With both directions, over the angles both cover, in
:data:`BINS` bins: ``F(|v|) = (tau(q, +v) - tau(q, -v)) / 2`` per bin (at constant speed inertia is
zero, with one axis moving Coriolis terms are zero, and gravity ``g(q)`` is the same both ways, so it
cancels; the half sum is ``g(q)`` plus half the difference of the two directions' dry levels), then
averaged over the bins; its standard error from their spread. The read does not rest on the
model. With one direction only, ``F = sign(v) (tau - tau_model)``, ``tau_model`` the robot's rigid-body
torque at that angle and speed (:meth:`Robot.inverse_dynamics` without friction): the point is
marked ``model`` and a note says so.

All torques arm side (motor torque times the gear ratio), N m; speeds arm side, rad/s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from faultgen.logs.measured import MeasuredData
from faultgen.model.robots import Robot

#: The reader's minimum: distinct speeds per axis and direction, and steady time per segment, s.
MIN_SPEEDS, MIN_STEADY = 3, 0.5
#: Slowest speed read as motion, rad/s (0.06 deg/s).
SPEED_FLOOR = 1e-3
#: The moving axis's speed is at least this many times every other axis's.
DOMINANCE = 10.0
#: Steady: within this share of the plateau speed (a drive at a slow speed wavers by 10 % and more as
#: friction grips and slips), or NOISE_SIGMAS times the averaged speed's noise.
SPEED_TOLERANCE, NOISE_SIGMAS = 0.15, 4.0
#: Speeds are averaged over this time, s (the segments found on them: encoder noise on a slow speed).
SMOOTH = 0.25
#: Time dropped at each end of a steady stretch besides SMOOTH / 2, s (the controller's settling).
TRIM = 0.05
#: Two segments' speeds are one speed when they agree within this share.
SAME_SPEED = 0.05
#: Angle bins of the differencing.
BINS = 20


@dataclass(frozen=True)
class Segment:
    """One constant-speed segment: ``axis`` (0-based), ``speed`` (signed, rad/s, the mean over it),
    sample rows ``start``..``stop`` (exclusive), its ``duration`` s, and the mean logged
    ``temperature`` of the axis, degC (NaN without)."""

    axis: int
    speed: float
    start: int
    stop: int
    duration: float
    temperature: float


@dataclass(frozen=True)
class Point:
    """The friction of ``axis`` (0-based) at ``speed`` (rad/s, > 0): ``friction`` and its standard
    error ``stderr`` (N m, arm side), from ``source`` ``"differenced"`` or ``"model"`` (one direction
    only); ``samples`` the log rows used; ``temperature`` degC (NaN without)."""

    axis: int
    speed: float
    friction: float
    stderr: float
    samples: int
    source: str
    temperature: float


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(np.int8), [0]])))
    return list(zip(edges[::2], edges[1::2]))


def smoothed_speed(log: MeasuredData) -> tuple[np.ndarray, np.ndarray]:
    """Each axis's speed averaged over :data:`SMOOTH` s (the angle's central difference across it),
    rad/s, shape (n, N); and the noise of that average per axis, rad/s, shape (N,): ``sqrt(2) s_q / SMOOTH``,
    ``s_q`` the angle noise (1.4826 times the median absolute deviation of ``q`` from a Savitzky-Golay fit
    over :data:`SMOOTH` / 2 s)."""
    t, q = np.asarray(log.t), np.asarray(log.q)
    dt = float(np.median(np.diff(t)))
    h = max(1, int(round(SMOOTH / 2 / dt)))
    ahead, behind = np.minimum(np.arange(len(t)) + h, len(t) - 1), np.maximum(np.arange(len(t)) - h, 0)
    speed = (q[ahead] - q[behind]) / (t[ahead] - t[behind])[:, None]
    window = min(2 * (h // 2) + 1, len(t) - (1 - len(t) % 2))
    residual = q - signal.savgol_filter(q, max(window, 5), 3, axis=0)
    noise = 1.4826 * np.median(np.abs(residual - np.median(residual, axis=0)), axis=0)
    return speed, np.sqrt(2) * noise / SMOOTH


def segments(log: MeasuredData) -> list[Segment]:
    """The constant-speed segments of ``log`` (module docstring), in time order."""
    t, q = np.asarray(log.t), np.asarray(log.q)
    qd, noise = smoothed_speed(log)
    floor = np.maximum(SPEED_FLOOR, NOISE_SIGMAS * noise)
    found = []
    for k in range(qd.shape[1]):
        speed = np.abs(qd[:, k])
        others = np.delete(np.abs(qd) - floor, k, axis=1).max(axis=1) if qd.shape[1] > 1 else np.zeros(len(t))
        moving = (speed > floor[k]) & (speed >= DOMINANCE * others)
        for sign in (1.0, -1.0):
            for a, b in _runs(moving & (np.sign(qd[:, k]) == sign)):
                v = speed[a:b]
                top = np.percentile(v, 99)
                plateau = np.median(v[v >= 0.95 * top])
                steady = np.abs(v - plateau) <= max(SPEED_TOLERANCE * plateau, NOISE_SIGMAS * noise[k])
                stretches = _runs(steady)
                if not stretches:
                    continue
                s0, s1 = max(stretches, key=lambda r: t[a + r[1] - 1] - t[a + r[0]])
                i0 = int(np.searchsorted(t, t[a + s0] + SMOOTH / 2 + TRIM))
                i1 = int(np.searchsorted(t, t[a + s1 - 1] - SMOOTH / 2 - TRIM, side="right"))
                if i1 - i0 < 3 or t[i1 - 1] - t[i0] < MIN_STEADY:
                    continue
                temperature = (float(np.mean(log.joint_temperature[i0:i1, k]))
                               if log.joint_temperature is not None else float("nan"))
                mean = (q[i1 - 1, k] - q[i0, k]) / (t[i1 - 1] - t[i0])
                found.append(Segment(k, float(mean), i0, i1, float(t[i1 - 1] - t[i0]), temperature))
    return sorted(found, key=lambda s: s.start)


def speed_groups(found: list[Segment]) -> dict[int, list[list[Segment]]]:
    """The segments per axis (0-based) grouped by speed (|speed| within :data:`SAME_SPEED`), slowest first."""
    groups: dict[int, list[list[Segment]]] = {}
    for seg in sorted(found, key=lambda s: (s.axis, abs(s.speed))):
        axis = groups.setdefault(seg.axis, [])
        if axis and abs(seg.speed) <= (1 + SAME_SPEED) * abs(axis[-1][0].speed):
            axis[-1].append(seg)
        else:
            axis.append([seg])
    return groups


def _difference(log: MeasuredData, k: int, up: list[Segment], down: list[Segment]) -> tuple[float, float, int] | None:
    q, tau = np.asarray(log.q)[:, k], np.asarray(log.tau)[:, k]
    rows = {d: np.concatenate([np.arange(s.start, s.stop) for s in segs]) for d, segs in (("+", up), ("-", down))}
    low = max(q[rows["+"]].min(), q[rows["-"]].min())
    high = min(q[rows["+"]].max(), q[rows["-"]].max())
    if not high > low:
        return None
    edges = np.linspace(low, high, BINS + 1)
    means = {}
    for d, r in rows.items():
        inside = r[(q[r] >= low) & (q[r] <= high)]
        which = np.clip(np.searchsorted(edges, q[inside], side="right") - 1, 0, BINS - 1)
        count = np.bincount(which, minlength=BINS)
        means[d] = np.where(count > 0, np.bincount(which, tau[inside], minlength=BINS) / np.maximum(count, 1), np.nan)
    half = (means["+"] - means["-"]) / 2
    half = half[np.isfinite(half)]
    if half.size < 2:
        return None
    used = sum(int(np.sum((q[r] >= low) & (q[r] <= high))) for r in rows.values())
    return float(np.mean(half)), float(np.std(half, ddof=1) / np.sqrt(half.size)), used


def _modelled(log: MeasuredData, robot: Robot, k: int, segs: list[Segment]) -> tuple[float, float, int]:
    rows = np.concatenate([np.arange(s.start, s.stop) for s in segs])
    q, qd = np.asarray(log.q)[rows], np.asarray(log.qd)[rows]
    rigid = robot.inverse_dynamics(q, qd, np.zeros_like(q), friction=False)[:, k]
    f = np.sign(qd[:, k]) * (np.asarray(log.tau)[rows, k] - rigid)
    return float(np.mean(f)), float(np.std(f, ddof=1) / np.sqrt(len(f))), len(rows)


def friction_points(log: MeasuredData, robot: Robot) -> tuple[list[Point], list[str]]:
    """The friction of every axis at every speed of the test in ``log`` (module docstring), and the
    notes a reader must see (each speed read through the model, each axis that holds less than the
    minimum). ValueError when no axis holds the minimum, naming it."""
    found = segments(log)
    points, notes = [], []
    for k, groups in sorted(speed_groups(found).items()):
        each_way = {d: sum(any((s.speed > 0) == (d > 0) for s in g) for g in groups) for d in (1, -1)}
        if max(each_way.values()) < MIN_SPEEDS:
            notes.append(f"axis {k + 1}: {each_way[1]} speeds in + and {each_way[-1]} in -; not read (the minimum is "
                         f"{MIN_SPEEDS} speeds each way, each steady {MIN_STEADY:g} s)")
            continue
        for group in groups:
            up = [s for s in group if s.speed > 0]
            down = [s for s in group if s.speed < 0]
            speed = float(np.mean([abs(s.speed) for s in group]))
            temperature = float(np.mean([s.temperature for s in group]))
            read = _difference(log, k, up, down) if up and down else None
            if read is not None:
                points.append(Point(k, speed, *read, "differenced", temperature))
                continue
            why = "one direction only" if not (up and down) else "no angles both directions cover"
            notes.append(f"axis {k + 1} at {speed:.4g} rad/s: {why}; friction read through the model "
                         "(rigid-body torque subtracted)")
            points.append(Point(k, speed, *_modelled(log, robot, k, up or down), "model", temperature))
    if not points:
        raise ValueError(f"{log.source}: no axis holds a friction test: {len(found)} constant-speed segments found; "
                         f"expected per axis at least {MIN_SPEEDS} speeds each way, each steady at least "
                         f"{MIN_STEADY:g} s with only that axis moving")
    return points, notes
