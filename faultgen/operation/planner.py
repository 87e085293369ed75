"""Planning a program: its segments, in order, into one checked :class:`~faultgen.operation.tasks.JointPath`.

:class:`Planner` is what :meth:`faultgen.operation.programs.Program.trajectory` runs (the segment
types are listed in :mod:`faultgen.operation.programs`): ruckig moves (:func:`~faultgen.operation.
tasks.ptp`), dwells, grips and releases, and Cartesian lines, arcs and seams through the flange IK
and spline of :class:`faultgen.operation.ik.FlangeIK`. Every problem is a :class:`~faultgen.
operation.tasks.ProgramError` naming the program, the segment and the value. :func:`check_torque`,
the drives' capacity check, is shared with replayed logs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from faultgen.effects.payload import Payload
from faultgen.model.robots import Robot
from faultgen.operation import ik as ik_module
from faultgen.operation.ik import Arc, FlangeIK, Seam, ramp_arc_length
from faultgen.operation.tasks import (
    IK_STEP,
    LIMIT_TOLERANCE,
    PLAN_PERIOD,
    SEAM_LIMIT_TOLERANCE,
    SEAM_TOLERANCE,
    CycleTooLong,
    JointPath,
    Load,
    PathBuilder,
    ProgramError,
    check_cycle_length,
    ptp,
)

#: Largest share of the drives' capacity (peak motor torque x gear ratio) a program may ask for.
TORQUE_CAPACITY = 1.0


@dataclass(frozen=True)
class Segment:
    """One segment of a program: its 1-based ``number``, ``type`` (a key of
    :data:`faultgen.operation.programs.SEGMENT_KEYS`), ``label`` and its values (angles in rad,
    positions in m, times in s)."""

    number: int
    type: str
    label: str
    values: dict = field(default_factory=dict)

    @property
    def name(self) -> str:
        return f"segment {self.number} ({self.type})"


class Planner:
    """Turns a program's segments into a :class:`JointPath`, checking as it goes.

    ``program`` is a :class:`faultgen.operation.programs.Program` (its start, limits, scales, tool
    and segments); ``dt`` the sample step, s. :meth:`run` plans and checks the cycle.
    """

    def __init__(self, program, dt: float) -> None:
        self.p = program
        self.path = PathBuilder(program.start, dt)
        self.ik = None
        self.target = None  # last Cartesian target of the tool (m), None after a joint-space move
        self.spans: list[tuple[Segment, int, int]] = []
        self.loads: list[Load] = []
        self.gripped: tuple[int, dict, str] | None = None

    def fail(self, segment: Segment | None, problem: str):
        where = f"{self.p.where}, {segment.name}" if segment is not None else self.p.where
        raise ProgramError(f"{where}: {problem}")

    def flange_ik(self) -> FlangeIK:
        if self.ik is None:
            self.ik = FlangeIK(self.p.robot, self.p.start)
        return self.ik

    def flange_target(self, point: np.ndarray) -> np.ndarray:
        """The flange position that puts the tool centre point at ``point``."""
        if np.any(self.p.tool_offset):
            return point - self.p.tool_rotation @ self.p.tool_offset
        return point

    def run(self) -> JointPath:
        for segment in self.p.segments:
            first = self.path.count - 1
            try:
                getattr(self, f"_{segment.type}")(segment)
            except CycleTooLong as err:  # a path longer than a cycle may be, refused before it is sampled
                self.fail(segment, err.reason)
            self.spans.append((segment, first, self.path.count - 1))
        if self.gripped is not None:
            self.fail(None, f"the payload gripped in segment {self.gripped[2]} is still held at the end of the "
                      "cycle; add a release segment (every cycle starts with an empty gripper)")
        result = self.path.build(loads=tuple(self.loads))
        self.check_limits(result, np.concatenate(self.path.tolerance))
        self.check_torque(result)
        return result

    # -- segments --

    def _solve(self, segment: Segment, position: np.ndarray, q_init: np.ndarray) -> np.ndarray:
        ik = self.flange_ik()
        try:
            return ik.solve(position, self.p.tool_rotation, q_init)
        except ik_module.Unreachable as err:
            distance = ik.nearest(position, q_init)
            if distance > 1e-4:
                self.fail(segment, f"Cartesian target {np.round(position, 4).tolist()} m (flange) is out of reach: "
                          f"the nearest point the flange reaches within the joint ranges is {distance:.3f} m away")
            self.fail(segment, f"Cartesian target {np.round(position, 4).tolist()} m (flange) is reachable, but not "
                      f"in the tool orientation: {err.orientation_error:.3g} rad remain of it ({err})")

    def _move(self, s: Segment) -> None:
        v = s.values
        if "to" in v:
            q_to = v["to"]
            self.target = None
        else:
            if self.p.tool_rotation is None:
                self.fail(s, "a Cartesian move needs the tool orientation: [tool] z and x")
            if "pose" in v:
                point = v["pose"]
                if "standoff" in v:
                    point = point + -v["standoff"] * self.p.tool_rotation[:, 2]
            elif "standoff" in v:
                if self.target is None:
                    self.fail(s, "standoff without pose backs off from the last Cartesian target, and there is none")
                point = self.target + -v["standoff"] * self.p.tool_rotation[:, 2]
            else:
                self.fail(s, "expected one of: to (joint angles, deg), pose (m), standoff (m)")
            q_to = self._solve(s, self.flange_target(point), self.path.last)
            self.target = point
        velocity = v.get("velocity_scale", self.p.velocity_scale) * self.p.velocity_limit
        acceleration = v.get("acceleration_scale", self.p.acceleration_scale) * self.p.acceleration_limit
        try:
            q, qd, qdd = ptp(self.path.last, q_to, velocity, acceleration, self.p.jerk_limit, self.path.dt,
                             f"{self.p.where}, {s.name}", elapsed=(self.path.count - 1) * self.path.dt)
        except CycleTooLong:
            raise  # run() names the segment
        except ValueError as err:
            raise ProgramError(str(err)) from err
        self.path.add(s.label, q, qd, qdd)

    def _dwell(self, s: Segment) -> None:
        target = None if self.target is None else self.flange_target(self.target)
        self.path.hold(s.label, s.values["time"], target=target)

    def _grip(self, s: Segment) -> None:
        if self.gripped is not None:
            self.fail(s, f"the tool already holds the payload gripped in segment {self.gripped[2]}; release it first")
        self.gripped = (self.path.count - 1, s.values["part"], str(s.number))

    def _release(self, s: Segment) -> None:
        if self.gripped is None:
            self.fail(s, "nothing to release: no payload is gripped")
        first, params, number = self.gripped
        self.loads.append(Load(first, self.path.count - 1, params, f"segment {number}"))
        self.gripped = None

    def _start_point(self, s: Segment) -> np.ndarray:
        if self.p.tool_rotation is None:
            self.fail(s, "a Cartesian segment needs the tool orientation: [tool] z and x")
        if self.target is not None:
            return self.target
        # the tool centre point where the last move left it
        position, rotation = self.flange_ik().flange(self.path.last)
        return position + rotation @ self.p.tool_offset

    def _linear(self, s: Segment) -> None:
        start = self._start_point(s)
        try:
            geometry = Seam(np.array([start, s.values["to"]]), 0.0, self.p.tool_rotation[:, 2])
        except ValueError as err:
            self.fail(s, str(err))
        self._follow(s, geometry, 0.0, 0.0)

    def _circular(self, s: Segment) -> None:
        start = self._start_point(s)
        try:
            geometry = Arc(start, s.values["via"], s.values["to"])
        except ValueError as err:
            self.fail(s, str(err))
        self._follow(s, geometry, 0.0, 0.0)

    def _seam(self, s: Segment) -> None:
        v = s.values
        start = self._start_point(s)
        gap = float(np.linalg.norm(v["vertices"][0] - start))
        if gap > SEAM_TOLERANCE:
            self.fail(s, f"the seam starts {gap * 1e3:.1f} mm from where the tool is "
                      f"({np.round(start, 4).tolist()} m); add a move to its first vertex")
        try:
            geometry = Seam(v["vertices"], v["corner_radius"], self.p.tool_rotation[:, 2])
        except ValueError as err:
            self.fail(s, f"vertices: {err}")
        self._follow(s, geometry, v.get("weave_amplitude", 0.0), v.get("weave_frequency", 0.0))

    def _follow(self, s: Segment, geometry, weave_amplitude: float, weave_frequency: float) -> None:
        """The tool along ``geometry`` at the segment's speed: IK every :data:`IK_STEP` from the path's
        last angles, a clamped cubic spline through the solutions (thesis task 3's seam)."""
        speed = s.values["speed"]
        planned = self._along(s, geometry, weave_amplitude, weave_frequency, speed)
        if isinstance(planned, str):
            self.fail(s, planned)
        q, qd, qdd, target, points = planned
        problem = self._over_limits(qd, qdd, speed)
        if problem is not None:
            self.fail(s, problem + self._fitting_speed(s, geometry, weave_amplitude, weave_frequency, speed, qd, qdd))
        self.path.add(s.label, q, qd, qdd, target=target, tolerance=SEAM_LIMIT_TOLERANCE)
        # the last knot's point (not the last sample's): the next segment starts from it, as task 3's retract
        rotation = self.p.tool_rotation
        self.target = points[-1] if not np.any(self.p.tool_offset) else points[-1] + rotation @ self.p.tool_offset

    def _along(self, s: Segment, geometry, weave_amplitude: float, weave_frequency: float, speed: float):
        """The joint path of :meth:`_follow` at ``speed`` (m/s): ``(q, qd, qdd, target, knot points)``, or
        the problem (str) that stops it (too short for its ramps, IK failing, the flange off the path)."""
        ramp_time = s.values["ramp_time"]
        length = geometry.length
        if length / speed < ramp_time + PLAN_PERIOD:
            return (f"the path is {length:.4g} m long: at {speed} m/s it takes {length / speed:.3g} s, "
                    f"not enough for a ramp_time of {ramp_time} s up and down; lower ramp_time or speed")
        duration = math.ceil((length / speed + ramp_time) / PLAN_PERIOD - 1e-9) * PLAN_PERIOD
        half_periods = max(1, round(2 * weave_frequency * length / speed))
        rotation = self.p.tool_rotation

        def tool_path(t: np.ndarray) -> np.ndarray:
            ramp = duration - geometry.length / speed
            arc = ramp_arc_length(t, speed, ramp, duration)
            position, tangent = geometry.evaluate(arc)
            weave = weave_amplitude * np.sin(np.pi * half_periods * arc / geometry.length)
            return self.flange_target_rows(position + weave[:, None] * np.cross(geometry.normal, tangent))

        ik, dt = self.flange_ik(), self.path.dt
        check_cycle_length((self.path.count - 1) * dt + duration, dt, s.label)  # before any array of it
        knots = np.linspace(0.0, duration, math.ceil(duration / IK_STEP - 1e-9) + 1)
        points = tool_path(knots)
        t = np.arange(round(duration / dt) + 1) * dt
        try:
            q, qd, qdd = ik.follow(knots, points, rotation, self.path.last, t)
        except ValueError as err:
            return f"{err}"
        target = tool_path(t)
        deviation = ik.deviation(q, target)
        k = int(np.argmax(deviation))
        if deviation[k] > SEAM_TOLERANCE:
            return (f"IK leaves the flange {deviation[k] * 1e3:.3f} mm from the path at t = {k * dt:.3f} s "
                    f"into the segment, more than the tolerance of {SEAM_TOLERANCE * 1e3} mm (a point near the "
                    "edge of the workspace or a wrist singularity)")
        return q, qd, qdd, target, points

    def flange_target_rows(self, points: np.ndarray) -> np.ndarray:
        if np.any(self.p.tool_offset):
            return points - (self.p.tool_rotation @ self.p.tool_offset)[None]
        return points

    def _ratios(self, qd: np.ndarray, qdd: np.ndarray) -> tuple[int, float, float]:
        """The axis nearest its limits and its speed and acceleration over them."""
        ratio_v = np.max(np.abs(qd), axis=0) / self.p.velocity_limit
        ratio_a = np.max(np.abs(qdd), axis=0) / self.p.acceleration_limit
        axis = int(np.argmax(np.maximum(ratio_v, ratio_a)))
        return axis, float(ratio_v[axis]), float(ratio_a[axis])

    def _over_limits(self, qd: np.ndarray, qdd: np.ndarray, speed: float) -> str | None:
        """A Cartesian segment's need beyond a joint's speed or acceleration limit, in words; None within."""
        axis, ratio_v, ratio_a = self._ratios(qd, qdd)
        worst = max(ratio_v, ratio_a)
        if worst <= 1 + SEAM_LIMIT_TOLERANCE:
            return None
        kind = "velocity" if ratio_v >= ratio_a else "acceleration"
        limit = (self.p.velocity_limit if kind == "velocity" else self.p.acceleration_limit)[axis]
        unit = "deg/s" if kind == "velocity" else "deg/s^2"
        return (f"at speed = {speed} m/s axis {axis + 1} needs {worst * np.degrees(limit):.4g} {unit}, "
                f"{(worst - 1) * 100:.0f} % above its {kind} limit of {np.degrees(limit):.4g} {unit}")

    #: Tries of :meth:`_fitting_speed`, and the margin each asks for below the limits.
    SPEED_TRIES, SPEED_MARGIN = 4, 0.98

    def _fitting_speed(self, s: Segment, geometry, weave_amplitude: float, weave_frequency: float, speed: float,
                       qd: np.ndarray, qdd: np.ndarray) -> str:
        """The advice after :meth:`_over_limits`: a speed planned and checked before it is given. The
        first try scales the speed by the joint speeds' and accelerations' excess (``v / max(ratio_v,
        sqrt(ratio_a))``, exact for a path whose time is stretched); each next by the excess the try
        before left (linear: the ramps' acceleration grows with the speed), up to :data:`SPEED_TRIES`.
        None fitting: the words that no slower speed was found to fit (a need that does not scale with
        the speed, such as the arm changing posture along the line)."""
        _, ratio_v, ratio_a = self._ratios(qd, qdd)
        fit = speed / max(ratio_v, np.sqrt(ratio_a))
        tried = []
        for _ in range(self.SPEED_TRIES):
            tried.append(fit)
            try:
                planned = self._along(s, geometry, weave_amplitude, weave_frequency, fit)
            except CycleTooLong:
                break  # slower still is longer still
            if isinstance(planned, str):
                break
            if self._over_limits(planned[1], planned[2], fit) is None:
                return f"; a speed of about {fit:.3g} m/s would fit (planned and checked)"
            _, ratio_v, ratio_a = self._ratios(planned[1], planned[2])
            fit = self.SPEED_MARGIN * fit / max(ratio_v, ratio_a)
        return (f"; no slower speed was found to fit (planned at {', '.join(f'{v:.3g}' for v in tried)} m/s): the "
                "need does not shrink with the speed; try another start pose or tool orientation")

    # -- checks over the whole cycle --

    def segment_at(self, k: int) -> Segment | None:
        for segment, first, last in self.spans:
            if first < k <= last or (first == k == last):
                return segment
        return None

    def check_limits(self, path: JointPath, tolerance: np.ndarray) -> None:
        robot = self.p.robot
        low, high = robot.joint_range[:, 0], robot.joint_range[:, 1]
        bad = (path.q < low - LIMIT_TOLERANCE) | (path.q > high + LIMIT_TOLERANCE)
        if np.any(bad):
            k, axis = np.argwhere(bad)[0]
            value = path.q[k, axis]
            edge = low[axis] if value < low[axis] else high[axis]
            self.fail(self.segment_at(k), f"axis {axis + 1} reaches {np.degrees(value):.2f} deg at t = {path.t[k]:.3f} "
                      f"s, {abs(np.degrees(value - edge)):.2f} deg beyond its range {np.degrees(low[axis]):.1f}.."
                      f"{np.degrees(high[axis]):.1f} deg")
        for kind, values, limit, unit in (("velocity", path.qd, self.p.velocity_limit, "deg/s"),
                                          ("acceleration", path.qdd, self.p.acceleration_limit, "deg/s^2")):
            bad = np.abs(values) > limit * (1 + tolerance[:, None] + LIMIT_TOLERANCE)
            if np.any(bad):
                k, axis = np.argwhere(bad)[0]
                value = abs(values[k, axis])
                self.fail(self.segment_at(k), f"axis {axis + 1} reaches a {kind} of {np.degrees(value):.4g} {unit} at "
                          f"t = {path.t[k]:.3f} s, {(value / limit[axis] - 1) * 100:.1f} % above its limit of "
                          f"{np.degrees(limit[axis]):.4g} {unit}")

    def check_torque(self, path: JointPath) -> None:
        check_torque(self.p.robot, path, lambda k: self.segment_at(k), self.fail)


#: The body a program's gripped part is, at the flange (not named ``payload*``: those are the robot's
#: own payload effect and the payload condition's, which a grip adds to rather than replaces).
GRIP_BODY = "gripped"


def add_part(spec, robot: Robot, params: dict) -> None:
    """Add a gripped part to an ``MjSpec`` of ``robot``: a body :data:`GRIP_BODY` at the flange with the
    :class:`~faultgen.effects.payload.Payload` parameters ``params`` (the shared payload's body)."""
    mass = params["mass"]
    com = np.array([params[k] for k in ("com_x", "com_y", "com_z")])
    inertia = np.array([params[k] for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")])
    Payload._add_body(spec, robot, GRIP_BODY, max(mass, 1e-9), com, inertia)


def check_torque(robot: Robot, path: JointPath, segment_at, fail) -> None:
    """Refuse a path whose arm-side torque (:meth:`Robot.inverse_dynamics`, the payloads of
    ``path.loads`` included) exceeds the drives' capacity, peak motor torque x gear ratio."""
    stride = max(1, round(PLAN_PERIOD / (path.t[1] - path.t[0]))) if len(path.t) > 1 else 1
    rows = np.arange(0, len(path.t), stride)  # every planning period is enough for a peak
    tau = robot.inverse_dynamics(path.q[rows], path.qd[rows], path.qdd[rows])
    for load in path.loads:
        carrying = robot.edited(lambda spec, p=load.params: add_part(spec, robot, p))
        sel = (rows >= load.first) & (rows <= load.last)
        if np.any(sel):
            tau[sel] = carrying.inverse_dynamics(path.q[rows[sel]], path.qd[rows[sel]], path.qdd[rows[sel]])
    capacity = TORQUE_CAPACITY * robot.motor_torque_limit * robot.gear_ratio
    ratio = np.abs(tau) / capacity
    k, axis = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
    if ratio[k, axis] > 1:
        fail(segment_at(rows[k]), f"axis {axis + 1} needs {abs(tau[k, axis]):.4g} N m (arm side) at t = "
             f"{path.t[rows[k]]:.3f} s, {(ratio[k, axis] - 1) * 100:.1f} % above the drive's capacity of "
             f"{capacity[axis]:.4g} N m (peak motor torque {robot.motor_torque_limit[axis]:.4g} N m x gear ratio "
             f"{robot.gear_ratio[axis]:.4g}); lower the payload, the speed or the acceleration")
