"""A friction test motion: each axis in turn at a list of constant speeds, both directions, as a
program file (``faultgen tasks friction-test``).

The field's friction experiment (Bittencourt 2014, constant-speed experiments per joint;
Nevmerzhitskiy et al. 2019, a list of speeds each run over a stroke and back; KUKA's brake test,
US 12,257,722, each motor driven both ways): at constant speed and one axis moving, the arm-side
torque is ``tau(q, +v) = g(q) + F(v)`` and ``tau(q, -v) = g(q) - F(v)``, so a read of both
directions over the same angles cancels gravity and inertia (:mod:`faultgen.calibrate.friction_test`).

The motion, per axis ``k`` (1..N in turn):

- **Posture**: the other axes held where the gravity torque on axis ``k`` changes least over the
  longest stroke (peak-to-peak of :meth:`Robot.static_load` over the stroke, a seeded search of
  :data:`CANDIDATES` postures within the middle of every range, the flange kept at least
  :data:`FLOOR_SHARE` of the reach above the floor); the stroke centred in it, :data:`MARGIN` clear of
  both joint limits.
- **Speeds**: :data:`SPEEDS` speeds spaced evenly in log from half the axis's Stribeck velocity (the
  drivetrain's motor-side value over the gear ratio, but no slower than the program format's
  slowest override, 1 % of the speed limit) to :data:`TOP_SHARE` of the speed limit (``[limits]
  velocity`` of the robot's tasks.toml; lower where the stroke cannot give :data:`STEADY` s of it).
- **Each speed**: a move to one end of its stroke, a dwell of :data:`DWELL` s, the stroke at that
  speed (ruckig, jerk-limited ramps at the robot's acceleration limit), a dwell, the stroke back, a
  dwell; the moves between strokes at a tenth of the acceleration limit (no constant speed). Each stroke is as long as :data:`STEADY` s at speed plus both ramps needs (at most
  :data:`STROKE_SHARE` of the range).

Generic in the number of axes.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from faultgen.model import folder
from faultgen.model.robots import Robot
from faultgen.operation import programs
from faultgen.operation.ik import FLANGE
from faultgen.operation.tables import MIN_SCALE

#: Constant speeds per axis and direction (the reader needs at least 3 each way).
SPEEDS = 7
#: Steady time at each speed, s (the reader needs at least 0.5 s).
STEADY = 1.5
#: Top speed as a share of the axis's speed limit.
TOP_SHARE = 0.8
#: Lowest speed as a share of the axis's Stribeck velocity (arm side).
LOW_SHARE = 0.5
#: Longest stroke as a share of the joint range, and its clearance from each limit, rad.
STROKE_SHARE, MARGIN = 0.6, math.radians(3.0)
#: Dwell at each end of a stroke, s; acceleration scale of the moves between strokes (slow
#: ramps, so that they never hold a constant speed a reader could take for a test speed).
DWELL, REPOSITION = 0.4, 0.1
#: Postures searched per axis, their seed, and the flange's least height above the floor (share of the reach).
CANDIDATES, SEED, FLOOR_SHARE = 300, 0, 0.2


def speeds(robot: Robot, axis: int, velocity: np.ndarray, acceleration: np.ndarray, jerk: np.ndarray,
           count: int = SPEEDS) -> np.ndarray:
    """The test speeds of ``axis`` (0-based), rad/s, shape (count,), slowest first: see the module
    docstring. ``velocity``, ``acceleration``, ``jerk`` are the robot's limits (rad/s, rad/s^2,
    rad/s^3, shape (N,))."""
    k = axis
    stribeck = float(robot.friction.stribeck_velocity[k] / robot.gear_ratio[k])
    low = max(LOW_SHARE * stribeck, MIN_SCALE * velocity[k] * 1.0001)
    span = robot.joint_range[k, 1] - robot.joint_range[k, 0]
    longest = min(STROKE_SHARE * span, span - 2 * MARGIN)
    a, ramp = acceleration[k], acceleration[k] / jerk[k]
    # the fastest v whose stroke v (STEADY + v / a + a / j) fits the longest stroke
    b = STEADY + ramp
    fits = (-b + math.sqrt(b * b + 4 * longest / a)) / (2 / a)
    high = min(TOP_SHARE * velocity[k], 0.95 * fits)
    if high <= low:
        raise ValueError(f"axis {k + 1}: the stroke of {math.degrees(longest):.3g} deg gives no speed above "
                         f"{low:.3g} rad/s {STEADY:g} s of steady motion")
    return np.geomspace(low, high, count)


def stroke(v: float, acceleration: float, jerk: float) -> float:
    """The stroke, rad, giving :data:`STEADY` s at ``v`` rad/s between jerk-limited ramps."""
    return v * (STEADY + v / acceleration + acceleration / jerk)


def posture(robot: Robot, axis: int, length: float) -> np.ndarray:
    """The posture, rad, shape (N,), that axis ``axis`` (0-based) is tested from: its own angle the
    centre of a stroke of ``length`` rad, the others where gravity on it changes least over the
    stroke (module docstring). ValueError when no candidate keeps the flange off the floor."""
    k, n = axis, robot.n_axes
    low, high = robot.joint_range.T
    middle, half = (low + high) / 2, (high - low) / 2
    rng = np.random.default_rng(SEED + k)
    q = np.vstack([middle, middle + rng.uniform(-0.6, 0.6, (CANDIDATES - 1, n)) * half])
    inner = (low[k] + length / 2 + MARGIN, high[k] - length / 2 - MARGIN)
    q[:, k] = np.clip(q[:, k], *inner) if inner[0] <= inner[1] else middle[k]
    offsets = np.linspace(-length / 2, length / 2, 9)
    sweep = np.repeat(q, len(offsets), axis=0)
    sweep[:, k] += np.tile(offsets, len(q))
    g = robot.static_load(sweep)[:, k].reshape(len(q), len(offsets))
    change = g.max(axis=1) - g.min(axis=1)
    model, data = robot.model, mujoco.MjData(robot.model)
    site = model.site(FLANGE).id
    floor = FLOOR_SHARE * folder.reach(robot)
    height = np.empty(len(sweep))
    for row, angles in enumerate(sweep):
        data.qpos[:], _ = robot.rigid_state(angles)
        mujoco.mj_kinematics(model, data)
        height[row] = data.site_xpos[site][2]
    clear = height.reshape(len(q), len(offsets)).min(axis=1) >= floor
    if not clear.any():
        raise ValueError(f"axis {k + 1}: no posture keeps the flange {floor:.3g} m above the floor over the stroke")
    return q[np.flatnonzero(clear)[np.argmin(change[clear])]]


def _deg(q: np.ndarray) -> list[float]:
    return [round(float(v), 6) for v in np.degrees(q)]


def program(robot: Robot, axes: list[int] | None = None, count: int = SPEEDS) -> dict:
    """The friction test of ``robot`` as a program table (what :func:`faultgen.operation.program_format.dumps`
    writes): ``axes`` (1-based, default all) in turn, ``count`` speeds each (module docstring).

    Raises
    ------
    ValueError
        For an axis outside 1..N, fewer than 3 speeds, or an axis whose stroke leaves no speed.
    """
    n = robot.n_axes
    axes = list(range(1, n + 1)) if axes is None else list(axes)
    bad = [a for a in axes if not (isinstance(a, int) and 1 <= a <= n)]
    if bad or not axes:
        raise ValueError(f"axes {bad or axes}: expected axis numbers in 1..{n}")
    if not (isinstance(count, int) and 3 <= count <= 50):
        raise ValueError(f"speeds = {count!r}: expected a whole number of speeds per direction in 3..50 "
                         "(the reader needs at least 3 each way)")
    velocity, acceleration, jerk = programs.robot_limits(robot)
    segments, start = [], None
    for axis in axes:
        k = axis - 1
        v = speeds(robot, k, velocity, acceleration, jerk, count)
        longest = stroke(float(v[-1]), acceleration[k], jerk[k])
        q0 = posture(robot, k, longest)
        start = q0 if start is None else start
        for speed in v:
            half = stroke(float(speed), acceleration[k], jerk[k]) / 2
            a, b = q0.copy(), q0.copy()
            a[k] -= half
            b[k] += half
            scale = round(float(speed / velocity[k]), 6)
            label = f"axis {axis} at {speed:.4g} rad/s"
            segments += [
                {"type": "move", "to": _deg(a), "acceleration_scale": REPOSITION},
                {"type": "dwell", "time": DWELL},
                {"type": "move", "to": _deg(b), "velocity_scale": scale, "label": f"{label}, +"},
                {"type": "dwell", "time": DWELL},
                {"type": "move", "to": _deg(a), "velocity_scale": scale, "label": f"{label}, -"},
                {"type": "dwell", "time": DWELL},
            ]
    segments.append({"type": "move", "to": _deg(start), "acceleration_scale": REPOSITION})
    # no ``robot`` key: the test runs on the robot's calibrated or hidden-effect copies too
    return {"name": f"friction_test_{robot.name}", "process": "friction test",
            "description": f"constant-speed friction test, axes {', '.join(map(str, axes))}, {count} speeds each way",
            "start": _deg(start), "segment": segments}


def text(robot: Robot, axes: list[int] | None = None, count: int = SPEEDS) -> str:
    """The friction test (:func:`program`) as a program file's text, with a header that says what
    it is; raises as :func:`program`."""
    header = (f"Friction test of {robot.name}, written by `faultgen tasks friction-test` "
              "(faultgen.operation.friction_test: its docstring gives every rule).\n"
              "Each axis in turn: constant speeds both ways over a stroke; read it with `faultgen friction-test`.")
    return programs.dumps(program(robot, axes, count), header)
