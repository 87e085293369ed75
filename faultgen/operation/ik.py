"""Flange inverse kinematics (mink, daqp QP solver) and Cartesian tool paths for task planning.

The robot models carry six motor-rotor joints besides the six arm joints (see
:mod:`faultgen.model.robots`). A rotor is a leaf body that moves nothing else, so it has no effect on
the flange; IK therefore runs on an *arm-only* copy of the model built with ``mujoco.MjSpec``
(rotor bodies, gearbox tendons, motors and keyframes deleted). Its ``qpos`` is exactly the six
arm angles in axis order, so no index bookkeeping or frozen-joint constraints are needed.
"""

from __future__ import annotations

import itertools

import mujoco
import numpy as np

from faultgen.model.robots import Robot

FLANGE = "flange"
POSITION_TOL = 1e-6  # m: a solve stops once the flange is this close to its target ...
ORIENTATION_TOL = 1e-6  # rad: ... and this close in orientation
MAX_ITERATIONS = 200
POSTURE_COST = 1e-3  # posture task weight (mink cost, per rad)
POLISH_BELOW = 1e-4  # m or rad: closer than this, iterate without the posture task (no bias)


class Unreachable(ValueError):
    """IK found no arm angles for a flange pose; ``position_error`` (m) and ``orientation_error``
    (rad) are what remained of the target when the iteration stopped."""

    def __init__(self, message: str, position_error: float, orientation_error: float) -> None:
        super().__init__(message)
        self.position_error, self.orientation_error = position_error, orientation_error


def arm_model(robot: Robot) -> mujoco.MjModel:
    """Arm-only copy of a robot's model: the six arm joints, no rotors, tendons or motors.

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    mujoco.MjModel
        A model with ``nq == nv == 6``, ``qpos`` = arm angles of axes 1..6 in rad, and the
        ``flange`` site.
    """
    spec = mujoco.MjSpec.from_file(str(robot.path))
    for element in [*spec.actuators, *spec.tendons, *spec.keys]:
        spec.delete(element)
    for name in robot.rotor_names:
        spec.delete(spec.body(name))
    model = spec.compile()
    names = tuple(model.joint(i).name for i in range(model.njnt))
    if names != robot.joint_names or model.nq != robot.n_axes:
        raise ValueError(f"{robot.path}: arm-only model has joints {names}, expected {robot.joint_names}")
    return model


def tool_rotation(z_axis: np.ndarray, x_axis: np.ndarray) -> np.ndarray:
    """Rotation matrix of the flange frame from its z (tool) axis and a hint for its x axis.

    Parameters
    ----------
    z_axis : ndarray of shape (3,)
        Tool direction in the world frame (e.g. ``(0, 0, -1)``: pointing down).
    x_axis : ndarray of shape (3,)
        Desired flange x axis; its component along ``z_axis`` is removed.

    Returns
    -------
    ndarray of shape (3, 3)
        Columns are the flange x, y, z axes in the world frame.
    """
    z = np.asarray(z_axis, float)
    if not np.linalg.norm(z) > 1e-9:
        raise ValueError("tool z axis must not be zero")
    z = z / np.linalg.norm(z)
    x = np.asarray(x_axis, float) - np.dot(x_axis, z) * z
    if not np.linalg.norm(x) > 1e-6:
        raise ValueError("tool x axis must not be zero or parallel to the tool z axis")
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


class FlangeIK:
    """Iterative flange IK on the arm-only model.

    Each :meth:`solve` runs Gauss-Newton steps of mink's differential IK (a ``FrameTask`` on the
    flange site, a weak ``PostureTask`` toward ``posture`` that regularises the steps and keeps
    the arm on the posture's branch, and a ``ConfigurationLimit`` that keeps every iterate
    within the joint ranges) from a warm start until the flange is within ``POSITION_TOL`` and
    ``ORIENTATION_TOL`` of the target; the last steps, within ``POLISH_BELOW``, drop the posture
    task, whose weight would otherwise shift the solution by a few micrometres. Warm-starting
    from the previous sample keeps a path continuous.

    Parameters
    ----------
    robot : Robot
    posture : ndarray of shape (6,)
        Arm angles in rad the posture task pulls toward.
    """

    def __init__(self, robot: Robot, posture: np.ndarray) -> None:
        import mink  # qpsolvers and scipy: for a Cartesian path's planning, not a run's import

        self.model = arm_model(robot)
        self.configuration = mink.Configuration(self.model, np.asarray(posture, float))
        self.frame = mink.FrameTask(FLANGE, "site", position_cost=1.0, orientation_cost=1.0, lm_damping=1.0)
        self.posture = mink.PostureTask(self.model, cost=POSTURE_COST)
        self._posture = np.asarray(posture, float)
        self.posture.set_target(self._posture)
        self.limits = [mink.ConfigurationLimit(self.model)]
        self._data = mujoco.MjData(self.model)
        self._site = self.model.site(FLANGE).id

    def flange(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Flange position (3,) in m and rotation matrix (3, 3) in the world frame at arm angles q."""
        self._data.qpos[:] = q
        mujoco.mj_kinematics(self.model, self._data)
        return self._data.site_xpos[self._site].copy(), self._data.site_xmat[self._site].reshape(3, 3).copy()

    def solve(self, position: np.ndarray, rotation: np.ndarray, q_init: np.ndarray) -> np.ndarray:
        """Arm angles that put the flange at a pose.

        Parameters
        ----------
        position : ndarray of shape (3,)
            Flange position in m, world frame.
        rotation : ndarray of shape (3, 3)
            Flange rotation matrix in the world frame.
        q_init : ndarray of shape (6,)
            Warm start, arm angles in rad.

        Returns
        -------
        ndarray of shape (6,)
            Arm angles in rad within the joint ranges.

        Raises
        ------
        ValueError
            If the iteration does not reach the tolerances (target out of reach or past a
            joint limit); the message gives the remaining position and orientation error.
        """
        import mink

        target = mink.SE3.from_rotation_and_translation(mink.SO3.from_matrix(rotation), position)
        self.frame.set_target(target)
        config = self.configuration
        config.update(np.asarray(q_init, float))
        for _ in range(MAX_ITERATIONS):
            error = self.frame.compute_error(config)
            if np.linalg.norm(error[:3]) <= POSITION_TOL and np.linalg.norm(error[3:]) <= ORIENTATION_TOL:
                return config.q.copy()
            # The posture task biases the fixed point by a few um; drop it for the last steps.
            tasks = [self.frame] if np.linalg.norm(error) < POLISH_BELOW else [self.frame, self.posture]
            velocity = mink.solve_ik(config, tasks, 1.0, "daqp", damping=1e-9, limits=self.limits)
            config.integrate_inplace(velocity, 1.0)
        raise Unreachable(
            f"IK did not converge to flange position {np.round(position, 4).tolist()} m: "
            f"remaining error {np.linalg.norm(error[:3]):.2e} m, {np.linalg.norm(error[3:]):.2e} rad",
            float(np.linalg.norm(error[:3])), float(np.linalg.norm(error[3:])),
        )

    def nearest(self, position: np.ndarray, q_init: np.ndarray, starts: int = 16) -> float:
        """Distance in m from ``position`` to the nearest flange position the arm reaches within its
        joint ranges, in any orientation: the iteration of :meth:`solve` on the position alone, from
        ``q_init``, the range centres and ``starts`` angles drawn uniformly within the ranges (a fixed
        seed), the smallest of the local minima (a joint limit can stop one start short)."""
        import mink

        frame = mink.FrameTask(FLANGE, "site", position_cost=1.0, orientation_cost=0.0, lm_damping=1.0)
        target = np.asarray(position, float)
        frame.set_target(mink.SE3.from_rotation_and_translation(mink.SO3.identity(), target))
        low, high = self.model.jnt_range[:, 0], self.model.jnt_range[:, 1]
        inits = [np.asarray(q_init, float), (low + high) / 2,
                 *np.random.default_rng(0).uniform(low, high, (starts, len(low)))]
        config, best = self.configuration, np.inf
        for q0 in inits:
            config.update(q0)
            for _ in range(MAX_ITERATIONS):
                velocity = mink.solve_ik(config, [frame], 1.0, "daqp", damping=1e-9, limits=self.limits)
                config.integrate_inplace(velocity, 1.0)
            best = min(best, float(np.linalg.norm(self.flange(config.q)[0] - target)))
        return best

    def follow(
        self, knots: np.ndarray, points: np.ndarray, rotation: np.ndarray, q_start: np.ndarray, t: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Joint path that moves the flange through points at knot times, from rest to rest.

        IK is solved at every knot, each from the previous solution (on a redundant arm, N > 6,
        with the posture task pulling toward that solution: the arm does not move along its null
        space between knots), and a cubic spline with zero end velocities runs through the solutions; its derivatives give velocity and
        acceleration, and the first and last samples are set exactly at rest.

        Parameters
        ----------
        knots : ndarray of shape (m,)
            Knot times in s, increasing, from 0.
        points : ndarray of shape (m, 3)
            Flange positions in m at the knots; the first must be reached by ``q_start``.
        rotation : ndarray of shape (3, 3)
            Constant flange rotation matrix.
        q_start : ndarray of shape (6,)
            Arm angles in rad at the first knot.
        t : ndarray of shape (n,)
            Sample times in s, from ``knots[0]`` to ``knots[-1]``.

        Returns
        -------
        q, qd, qdd : ndarray of shape (n, 6)
            rad, rad/s, rad/s^2.

        Raises
        ------
        ValueError
            If IK fails at a knot; the message names the knot.
        """
        solutions = [np.asarray(q_start, float)]
        # A redundant arm (N > 6) has a null space: a posture task pulling toward the program's start
        # would move the arm along it between knots (a Panda: axes 1 and 3 0.2 deg apart inside the
        # first 10 ms knot, issue 88), so there each knot's posture target is the previous solution.
        redundant = self.model.nv > 6
        try:
            for k in range(1, len(knots)):
                if redundant:
                    self.posture.set_target(solutions[-1])
                try:
                    solutions.append(self.solve(points[k], rotation, solutions[-1]))
                except ValueError as err:
                    raise ValueError(f"IK knot {k} (t = {knots[k]:.3f} s): {err}") from err
        finally:
            if redundant:
                self.posture.set_target(self._posture)
        from scipy.interpolate import CubicSpline  # imports scipy.optimize: not at a run's import

        spline = CubicSpline(knots, np.array(solutions), bc_type="clamped", axis=0)
        q, qd, qdd = spline(t), spline(t, 1), spline(t, 2)
        q[0], q[-1] = solutions[0], solutions[-1]
        qd[[0, -1]] = qdd[[0, -1]] = 0.0
        return q, qd, qdd

    def deviation(self, q: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Flange distance in m from ``points`` (n, 3) at arm angles ``q`` (n, 6), shape (n,)."""
        return np.array([np.linalg.norm(self.flange(qk)[0] - p) for qk, p in zip(q, points)])


class Seam:
    """A planar polyline with rounded corners, parameterised by arc length.

    Parameters
    ----------
    vertices : ndarray of shape (k, 3)
        Polyline vertices in m, all in one plane, k >= 2.
    radius : float
        Corner radius in m: each corner is replaced by a circular arc tangent to both segments.
    tool_axis : ndarray of shape (3,)
        Fixes the plane of a straight polyline (the plane holding the seam and the tool axis).

    Attributes
    ----------
    normal : ndarray of shape (3,)
        Unit normal of the seam plane.
    length : float
        Arc length in m.

    Raises
    ------
    ValueError
        If the vertices are not in one plane, a segment is too short for its corners' arcs, or a
        corner turns by more than 170 deg.
    """

    def __init__(self, vertices: np.ndarray, radius: float, tool_axis: np.ndarray) -> None:
        v = np.asarray(vertices, float)
        d = np.diff(v, axis=0)
        lengths = np.linalg.norm(d, axis=1)
        if np.any(lengths < 1e-9):
            raise ValueError("seam has two equal consecutive vertices")
        d = d / lengths[:, None]
        turns = [np.cross(a, b) for a, b in itertools.pairwise(d) if np.linalg.norm(np.cross(a, b)) > 1e-9]
        normal = turns[0] if turns else np.cross(np.cross(d[0], tool_axis), d[0])
        if not np.linalg.norm(normal) > 1e-9:  # a straight line along the tool axis: any plane holds it
            normal = np.cross(d[0], np.eye(3)[int(np.argmin(np.abs(d[0])))])
        self.normal = normal / np.linalg.norm(normal)
        if np.max(np.abs((v - v[0]) @ self.normal)) > 1e-9:
            raise ValueError("seam vertices must lie in one plane")
        turn = np.arccos(np.clip(np.sum(d[:-1] * d[1:], axis=1), -1.0, 1.0))
        if np.any(turn > np.radians(170)):
            raise ValueError("seam corner sharper than 10 deg")
        trim = np.concatenate([[0.0], radius * np.tan(turn / 2), [0.0]])  # tangent lengths
        straight = lengths - trim[:-1] - trim[1:]
        if np.any(straight < 0):
            raise ValueError(
                f"seam segment {int(np.argmin(straight)) + 1} is too short for the corner radius"
            )
        # ("line", start, direction, length) or ("arc", start, d_in, d_towards_centre, radius, angle)
        self._pieces: list[tuple] = []
        for i in range(len(d)):
            self._pieces.append(("line", v[i] + trim[i] * d[i], d[i], straight[i]))
            if i < len(turn) and turn[i] > 1e-9:
                towards = d[i + 1] - np.dot(d[i + 1], d[i]) * d[i]
                start = v[i + 1] - trim[i + 1] * d[i]
                self._pieces.append(("arc", start, d[i], towards / np.linalg.norm(towards), radius, turn[i]))
        sizes = np.array([p[3] if p[0] == "line" else p[4] * p[5] for p in self._pieces])
        self._starts = np.concatenate([[0.0], np.cumsum(sizes)[:-1]])
        self.length = float(np.sum(sizes))

    def evaluate(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Positions and unit tangents at arc lengths.

        Parameters
        ----------
        s : ndarray of shape (n,)
            Arc length in m, clipped to [0, length].

        Returns
        -------
        position, tangent : ndarray of shape (n, 3)
            Position in m and unit tangent, world frame.
        """
        s = np.clip(np.asarray(s, float), 0.0, self.length)
        index = np.searchsorted(self._starts, s, side="right") - 1
        local = (s - self._starts[index])[:, None]
        position, tangent = np.empty((len(s), 3)), np.empty((len(s), 3))
        for k, piece in enumerate(self._pieces):
            sel = index == k
            if piece[0] == "line":
                position[sel] = piece[1] + local[sel] * piece[2]
                tangent[sel] = piece[2]
            else:
                _, start, d_in, d_mid, radius, _ = piece
                phi = local[sel] / radius
                position[sel] = start + radius * (np.sin(phi) * d_in + (1 - np.cos(phi)) * d_mid)
                tangent[sel] = np.cos(phi) * d_in + np.sin(phi) * d_mid
        return position, tangent


class Arc:
    """A circular arc through three points, parameterised by arc length (the same interface as
    :class:`Seam`: ``normal``, ``length``, ``evaluate``).

    Parameters
    ----------
    start, via, end : ndarray of shape (3,)
        Points in m: the arc runs from ``start`` through ``via`` to ``end``.

    Raises
    ------
    ValueError
        If the points are (nearly) on one line or two coincide.
    """

    def __init__(self, start: np.ndarray, via: np.ndarray, end: np.ndarray) -> None:
        a, b, c = (np.asarray(p, float) for p in (start, via, end))
        n = np.cross(b - a, c - a)
        scale = max(np.linalg.norm(b - a), np.linalg.norm(c - a), 1e-12)
        if not np.linalg.norm(n) > 1e-6 * scale**2:
            raise ValueError("the arc's start, via and end points are on one line (or two coincide)")
        self.normal = n / np.linalg.norm(n)
        # circumcentre of the triangle a, b, c
        ab, ac = b - a, c - a
        centre = a + (np.dot(ac, ac) * np.cross(n, ab) - np.dot(ab, ab) * np.cross(n, ac)) / (2 * np.dot(n, n))
        self.centre, self.radius = centre, float(np.linalg.norm(a - centre))
        self._u = (a - centre) / self.radius
        self._v = np.cross(self.normal, self._u)
        d = c - centre
        angle = float(np.arctan2(np.dot(d, self._v), np.dot(d, self._u))) % (2 * np.pi)
        self.length = self.radius * angle

    def evaluate(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Positions and unit tangents, each ``(n, 3)``, at arc lengths ``s`` (n,) in m."""
        phi = np.clip(np.asarray(s, float), 0.0, self.length)[:, None] / self.radius
        position = self.centre + self.radius * (np.cos(phi) * self._u + np.sin(phi) * self._v)
        return position, -np.sin(phi) * self._u + np.cos(phi) * self._v


def ramp_arc_length(t: np.ndarray, speed: float, ramp: float, duration: float) -> np.ndarray:
    """Distance travelled along a path at constant speed with smooth start and stop.

    The acceleration is a raised cosine ``(speed / ramp) (1 - cos(2 pi t / ramp))`` over the
    first ``ramp`` seconds (zero acceleration and jerk at rest), the speed is then constant, and
    the stop mirrors the start. The distance covered is ``speed * (duration - ramp)``.

    Parameters
    ----------
    t : ndarray of shape (n,)
        Time in s, clipped to [0, duration].
    speed : float
        Constant speed in m/s.
    ramp : float
        Time to reach ``speed`` in s, at most ``duration / 2``.
    duration : float
        Total time in s.

    Returns
    -------
    ndarray of shape (n,)
        Distance in m.
    """
    t = np.clip(np.asarray(t, float), 0.0, duration)

    def ramp_distance(tau: np.ndarray) -> np.ndarray:
        tau = np.clip(tau, 0.0, ramp)
        return speed / ramp * (tau**2 / 2 + (ramp / (2 * np.pi)) ** 2 * (np.cos(2 * np.pi * tau / ramp) - 1))

    s = speed * (t - ramp / 2)
    s = np.where(t < ramp, ramp_distance(t), s)
    return np.where(t > duration - ramp, speed * (duration - ramp) - ramp_distance(duration - t), s)
