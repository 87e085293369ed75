"""Robot programs: a task as a file a user writes, checked before any simulation.

A program is a TOML file (docs/simulation.md, "Your own programs"): a name of the user's choosing,
a start pose, a tool frame, and a list of ``[[segment]]`` tables run in order, from the start pose
at rest back to it (or to wherever the last segment ends, at rest):

===============  ==================================================================================
``type``         what it does (keys)
===============  ==================================================================================
``move``         joint-space point-to-point move, ruckig, rest to rest (:func:`faultgen.operation.
                 tasks.ptp`): to joint angles ``to`` (deg), to a Cartesian ``pose`` (m, through flange
                 IK with mink; ``standoff`` m back along the tool axis), or, with ``standoff`` alone,
                 back along the tool axis from the last Cartesian target; ``velocity_scale``,
                 ``acceleration_scale`` override the program's
``linear``       Cartesian straight line from the last target ``to`` a point (m) at ``speed`` (m/s),
                 ``ramp_time`` (s) from rest and back to rest
``circular``     Cartesian arc from the last target ``via`` a point ``to`` a point, ``speed``,
                 ``ramp_time``
``seam``         a polyline ``vertices`` (m; the first is the last target) with ``corner_radius``
                 (m), followed at ``speed`` with ``ramp_time`` and a ``weave_amplitude`` (m) at
                 ``weave_frequency`` (Hz) across it (thesis task 3)
``dwell``        rest for ``time`` s (``label`` defaults to ``dwell``)
``grip``         the tool takes a payload: ``mass`` (kg) and ``size`` (m, a uniform cube hanging
                 below the flange, as :class:`faultgen.operation.conditions.Payloads`), or ``com``
                 (m, flange frame) and ``inertia`` (kg m^2 at the com: xx, yy, zz, xy, xz, yz);
                 carried by the simulated arm and by the drives' feedforward until ``release``
``release``      the tool lets the payload go
===============  ==================================================================================

Every segment takes a ``label`` (what the dataset's path segments are called). Cartesian segments
go through the same IK and spline as the thesis's seam (:class:`faultgen.operation.ik.FlangeIK`),
sampled at the same knots, so the three thesis tasks written as programs (:func:`export`) give
their paths bit for bit.

Before any simulation :meth:`Program.trajectory` refuses, naming the segment and the value: an
unknown key, a Cartesian target out of reach (with the distance to the nearest reachable point), a
joint angle, speed or acceleration limit exceeded (and by how much), a seam or line leaving the
flange more than :data:`faultgen.operation.tasks.SEAM_TOLERANCE` from its path, and a motor torque
above the drives' capacity (peak motor torque times gear ratio, the payload included).

Generic in the number of axes: N is the robot model's (``len(robot.joint_names)``).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from faultgen import inputs
from faultgen.effects.payload import Payload
from faultgen.model import robots
from faultgen.model.robots import Robot
from faultgen.operation import ik as ik_module
from faultgen.operation.ik import Arc, FlangeIK, Seam, ramp_arc_length, tool_rotation
from faultgen.operation.tasks import (
    IK_STEP, LIMIT_TOLERANCE, PLAN_PERIOD, PROCESSES, SEAM_LIMIT_TOLERANCE, SEAM_TOLERANCE, TASKS, JointPath,
    CycleTooLong, _Builder, _Table, ptp,
)

#: File suffixes read as programs; the rest of :data:`REPLAY_SUFFIXES` are replayed joint logs.
PROGRAM_SUFFIXES = (".toml",)
REPLAY_SUFFIXES = (".csv", ".csv.gz", ".h5", ".hdf5")
#: Keys of each segment type (besides ``type`` and ``label``).
SEGMENT_KEYS = {
    "move": ("to", "pose", "standoff", "velocity_scale", "acceleration_scale"),
    "linear": ("to", "speed", "ramp_time"),
    "circular": ("via", "to", "speed", "ramp_time"),
    "seam": ("vertices", "corner_radius", "speed", "ramp_time", "weave_amplitude", "weave_frequency"),
    "dwell": ("time",),
    "grip": ("mass", "size", "com", "inertia"),
    "release": (),
}
#: What a program's ``process`` key may say (a label the user reads; the motion is the segments'):
#: the thesis's three processes (ch. 6.3.1), the robot applications of industry, or "program", the
#: default. A closed list, so that a typo or a stray value is refused, naming the key.
PROGRAM_PROCESSES = (*PROCESSES.values(), "program", "handling", "pick and place", "palletizing", "packaging",
                     "machine tending", "assembly", "spot welding", "arc welding", "laser welding", "cutting",
                     "painting", "dispensing", "gluing", "grinding", "polishing", "deburring", "inspection")
TOP_KEYS = ("name", "robot", "process", "description", "start", "velocity_scale", "acceleration_scale", "limits",
            "tool", "segment")
LIMIT_KEYS = ("velocity", "acceleration", "jerk")
TOOL_KEYS = ("z", "x", "offset")
#: Largest share of the drives' capacity (peak motor torque x gear ratio) a program may ask for.
TORQUE_CAPACITY = 1.0


class ProgramError(ValueError):
    """A program (or replayed log) cannot run; the message names the file, the segment and the value."""


def is_file_task(task: str) -> bool:
    """Whether ``task`` names a program or log file (by its suffix) rather than a thesis task."""
    name = str(task).lower()
    return name.endswith(PROGRAM_SUFFIXES + REPLAY_SUFFIXES)


def check_name(task: str) -> str:
    """``task`` if it is a thesis task name or an existing program / log file, else ValueError naming
    it and what is expected."""
    if not isinstance(task, str) or not task:
        raise ValueError(f"task {task!r}: expected a task name ({', '.join(TASKS)}) or a program file (.toml) "
                         "or joint log (.csv, .h5)")
    if task in TASKS:
        return task
    if is_file_task(task):
        if not Path(task).is_file():
            raise ValueError(f"task file {task!r} does not exist")
        return task
    raise ValueError(f"unknown task {task!r}; expected one of: {', '.join(TASKS)}, or a program file (.toml) "
                     "or a joint log (.csv, .h5) to replay")


def label(task: str) -> str:
    """A short name for ``task`` in run ids and progress bars: the thesis name, or the file's stem."""
    if task in TASKS or not is_file_task(task):
        return task
    name = Path(task).name
    for suffix in sorted(PROGRAM_SUFFIXES + REPLAY_SUFFIXES, key=len, reverse=True):
        if name.lower().endswith(suffix):
            return name[: -len(suffix)]
    return name


def load(robot: Robot | str, task: str):
    """The task ``task`` of ``robot``: a thesis task by name (:func:`faultgen.operation.tasks.load`), a
    program file (``.toml``, :func:`read`) or a joint log to replay (``.csv``, ``.csv.gz``, ``.h5``;
    :func:`faultgen.operation.replay.read`).

    Returns
    -------
    Task, Program or Replay
        Each has ``name``, ``start``, ``velocity_limit`` and ``trajectory(dt) -> JointPath``.

    Raises
    ------
    ValueError
        For an unknown task or a file that cannot run on ``robot`` (:class:`ProgramError`).
    """
    from faultgen.operation import replay, tasks

    if not isinstance(robot, Robot):
        robot = robots.load(robot)
    check_name(task)
    if task in TASKS:
        return tasks.load(robot, task)
    if str(task).lower().endswith(PROGRAM_SUFFIXES):
        return read(task, robot)
    return replay.read(task, robot, _limits({}, robot, task), check_torque)


def record(task: str) -> dict | None:
    """What a dataset keeps of a file task so the run can be made again: ``name`` (the program's, or
    the log's stem), ``file`` (as given), ``sha256`` of the file's bytes and, for a program, its
    ``text``; None for a thesis task."""
    if task in TASKS or not is_file_task(task):
        return None
    data = Path(task).read_bytes()
    out = {"file": str(task), "sha256": hashlib.sha256(data).hexdigest()}
    if str(task).lower().endswith(PROGRAM_SUFFIXES):
        text = data.decode()
        try:
            out["name"] = str(inputs.loads_toml(text, task, "program file").get("name", label(task)))
        except inputs.InputError:
            out["name"] = label(task)
        out["text"] = text
    else:
        out["name"] = label(task)
    return out


def identity(robot: Robot | str, task: str) -> tuple[str, str]:
    """What a run's program is: ``(label, sha256)``.

    ``sha256`` is the hex digest of the program's text: a program file's or log's bytes, and for a
    thesis task the program file :func:`export` writes for ``robot`` (so a task exported and left
    unchanged is the same program as the task). ``label`` is what the dataset calls it (its
    ``task`` attribute): the thesis name; a program file's ``name`` key, except that a file
    carrying a thesis task's name without being that task (an exported task, edited) is labelled by
    its file name (:func:`label`); a log's file name. Analyses pair runs by the hash, never by the
    label alone (two programs may share a label in files written before the hash existed).

    Raises
    ------
    ValueError
        For an unknown task or missing file (:func:`check_name`).
    """
    check_name(task)
    if task in TASKS:
        return task, hashlib.sha256(export(robot, task).encode()).hexdigest()
    record_ = record(task)
    name, digest = record_["name"], record_["sha256"]
    if name in TASKS:
        try:
            builtin = identity(robot, name)[1]
        except ValueError:  # the robot has no such thesis task: the file is not it
            builtin = ""
        if digest != builtin:
            name = label(task)
    return name, digest


# -- the program ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Segment:
    """One segment of a program: its 1-based ``number``, ``type`` (a key of :data:`SEGMENT_KEYS`),
    ``label`` and its values (angles in rad, positions in m, times in s)."""

    number: int
    type: str
    label: str
    values: dict = field(default_factory=dict)

    @property
    def name(self) -> str:
        return f"segment {self.number} ({self.type})"


@dataclass(frozen=True, eq=False)
class Program:
    """A robot program read from a TOML file (module docstring).

    Attributes
    ----------
    name : str
        The program's name (its ``name`` key).
    robot_name : str
    process : str
        Free text (the thesis tasks: point-to-point, discontinuous, continuous); ``program`` by default.
    source : Path or None
        The file, or None for a program read from text.
    text : str
        The file's text (what a dataset stores).
    velocity_limit, acceleration_limit, jerk_limit : ndarray of shape (N,)
        Joint limits for planning, rad/s, rad/s^2, rad/s^3 (the program's ``[limits]``, else the
        robot folder's ``tasks.toml`` ``[limits]``).
    start : ndarray of shape (N,)
        Arm angles in rad where the cycle starts, at rest.
    velocity_scale, acceleration_scale : float
        Fractions of the limits the moves use (a segment may override them).
    tool_rotation : ndarray of shape (3, 3) or None
        Flange orientation at Cartesian targets (``[tool]`` z and x); None without Cartesian segments.
    tool_offset : ndarray of shape (3,)
        Tool centre point in the flange frame, m: Cartesian targets are the tool's; the flange goes
        to ``target - R offset``.
    segments : tuple of Segment
    robot : Robot
    """

    name: str
    robot_name: str
    process: str
    source: Path | None
    text: str
    velocity_limit: np.ndarray
    acceleration_limit: np.ndarray
    jerk_limit: np.ndarray
    start: np.ndarray
    velocity_scale: float
    acceleration_scale: float
    tool_rotation: np.ndarray | None
    tool_offset: np.ndarray
    segments: tuple[Segment, ...]
    robot: Robot = field(repr=False)

    @property
    def where(self) -> str:
        return f"{self.source or 'program'} ({self.name})"

    def trajectory(self, dt: float) -> JointPath:
        """The program's cycle sampled every ``dt`` s, checked (module docstring).

        Parameters
        ----------
        dt : float
            Time step in s dividing :data:`~faultgen.operation.tasks.PLAN_PERIOD` into whole steps.

        Returns
        -------
        JointPath
            With ``loads``: the payload carried over sample ranges (:class:`Load`).

        Raises
        ------
        ProgramError
            Naming the segment and the value (module docstring).
        """
        if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
            raise ValueError(f"dt must be a positive number of seconds, got {dt!r}")
        if abs(PLAN_PERIOD / dt - round(PLAN_PERIOD / dt)) > 1e-9:
            raise ValueError(f"dt = {dt!r} s does not divide the {PLAN_PERIOD * 1e3:g} ms planning period into whole "
                             "steps; expected e.g. 0.004, 0.002, 0.001 or 0.0005")
        return _Planner(self, float(dt)).run()


@dataclass(frozen=True)
class Load:
    """A payload carried from sample ``first`` to sample ``last`` of a path (inclusive), with the
    :class:`faultgen.effects.payload.Payload` parameters ``params``; ``segment`` names the grip."""

    first: int
    last: int
    params: dict
    segment: str


class _Planner:
    """Turns a program's segments into a :class:`JointPath`, checking as it goes."""

    def __init__(self, program: Program, dt: float) -> None:
        self.p = program
        self.path = _Builder(program.start, dt)
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
        result = self.path.build()
        result = JointPath(result.t, result.q, result.qd, result.qdd, result.target, result.segments,
                           loads=tuple(self.loads))
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
                             f"{self.p.where}, {s.name}")
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
        speed, ramp_time = s.values["speed"], s.values["ramp_time"]
        length = geometry.length
        if length / speed < ramp_time + PLAN_PERIOD:
            self.fail(s, f"the path is {length:.4g} m long: at {speed} m/s it takes {length / speed:.3g} s, "
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
        knots = np.linspace(0.0, duration, math.ceil(duration / IK_STEP - 1e-9) + 1)
        points = tool_path(knots)
        t = np.arange(round(duration / dt) + 1) * dt
        try:
            q, qd, qdd = ik.follow(knots, points, rotation, self.path.last, t)
        except ValueError as err:
            self.fail(s, f"{err}")
        target = tool_path(t)
        deviation = ik.deviation(q, target)
        k = int(np.argmax(deviation))
        if deviation[k] > SEAM_TOLERANCE:
            self.fail(s, f"IK leaves the flange {deviation[k] * 1e3:.3f} mm from the path at t = {k * dt:.3f} s "
                      f"into the segment, more than the tolerance of {SEAM_TOLERANCE * 1e3} mm (a point near the "
                      "edge of the workspace or a wrist singularity)")
        self._check_speed(s, qd, qdd, speed)
        self.path.add(s.label, q, qd, qdd, target=target, tolerance=SEAM_LIMIT_TOLERANCE)
        # the last knot's point (not the last sample's): the next segment starts from it, as task 3's retract
        self.target = points[-1] if not np.any(self.p.tool_offset) else points[-1] + rotation @ self.p.tool_offset

    def flange_target_rows(self, points: np.ndarray) -> np.ndarray:
        if np.any(self.p.tool_offset):
            return points - (self.p.tool_rotation @ self.p.tool_offset)[None]
        return points

    def _check_speed(self, s: Segment, qd: np.ndarray, qdd: np.ndarray, speed: float) -> None:
        """Refuse a Cartesian segment that needs more than a joint's speed or acceleration limit."""
        ratio_v = np.max(np.abs(qd), axis=0) / self.p.velocity_limit
        ratio_a = np.max(np.abs(qdd), axis=0) / self.p.acceleration_limit
        axis = int(np.argmax(np.maximum(ratio_v, ratio_a)))
        worst = max(ratio_v[axis], ratio_a[axis])
        if worst > 1 + SEAM_LIMIT_TOLERANCE:
            fit = speed / max(ratio_v[axis], np.sqrt(ratio_a[axis]))
            kind = "velocity" if ratio_v[axis] >= ratio_a[axis] else "acceleration"
            limit = (self.p.velocity_limit if kind == "velocity" else self.p.acceleration_limit)[axis]
            unit = "deg/s" if kind == "velocity" else "deg/s^2"
            self.fail(s, f"at speed = {speed} m/s axis {axis + 1} needs {worst * np.degrees(limit):.4g} {unit}, "
                      f"{(worst - 1) * 100:.0f} % above its {kind} limit of {np.degrees(limit):.4g} {unit}; a speed "
                      f"of about {fit:.3g} m/s would fit")

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


# -- reading -------------------------------------------------------------------------------------


def read(path: str | Path, robot: Robot | str) -> Program:
    """Read a program file for ``robot``.

    Raises
    ------
    ProgramError
        For a file that is missing or not TOML, or a key or value that is not understood (the
        message names the file, the segment and the key).
    """
    try:
        text = inputs.read_text(path, "program file", inputs.TOML_MAX_BYTES)
    except inputs.InputError as err:
        raise ProgramError(str(err)) from None
    return parse(text, robot, Path(path))


def parse(text: str, robot: Robot | str, source: Path | None = None) -> Program:
    """A :class:`Program` from TOML ``text`` (see :func:`read`)."""
    if not isinstance(robot, Robot):
        robot = robots.load(robot)
    where = str(source or "program")
    try:
        data = inputs.loads_toml(text, where, "program file")
    except inputs.InputError as err:
        raise ProgramError(str(err)) from None
    top = _Values(where, "", data, TOP_KEYS)
    name = top.text("name")
    if "robot" in data:
        _check_robot(top, robot)
    process = "program"
    if "process" in data:
        process = top.text("process")
        if process not in PROGRAM_PROCESSES:
            top.fail("process", f"{process!r} is not a process; expected one of {', '.join(PROGRAM_PROCESSES)}")
    limits = _limits(data, robot, where)
    start = top.angles("start", robot)
    tool = _Values(where, "[tool] ", data.get("tool", {}), TOOL_KEYS)
    rotation, offset = None, np.zeros(3)
    if "z" in tool.data or "x" in tool.data:
        try:
            rotation = tool_rotation(tool.array("z", (3,)), tool.array("x", (3,)))
        except ValueError as err:
            raise ProgramError(f"{where}: [tool] z, x: {err}") from err
    if "offset" in tool.data:
        offset = tool.array("offset", (3,))
    raw = data.get("segment", [])
    if not isinstance(raw, list) or not raw:
        raise ProgramError(f"{where}: no [[segment]] tables; a program needs at least one")
    segments = tuple(_segment(where, k + 1, table, robot) for k, table in enumerate(raw))
    if rotation is None and any(s.type in ("linear", "circular", "seam") or
                                (s.type == "move" and "to" not in s.values) for s in segments):
        first = next(s for s in segments if s.type in ("linear", "circular", "seam", "move") and "to" not in s.values)
        raise ProgramError(f"{where}: {first.name}: a Cartesian target needs the tool orientation; add [tool] z and x")
    return Program(
        name=name, robot_name=robot.name, process=process, source=source, text=text,
        velocity_limit=limits[0], acceleration_limit=limits[1], jerk_limit=limits[2], start=start,
        velocity_scale=top.fraction("velocity_scale", 1.0), acceleration_scale=top.fraction("acceleration_scale", 1.0),
        tool_rotation=rotation, tool_offset=offset, segments=segments, robot=robot,
    )


def _check_robot(top: "_Values", robot: Robot) -> None:
    """Refuse a program whose ``robot`` key names another robot than the one it runs on (its joint
    angles, poses and limits were written for that robot). A model ``faultgen calibrate`` wrote,
    ``<robot>_calibrated``, runs the programs of ``<robot>``."""
    named = top.text("robot")
    if robot.name not in (named, f"{named}_calibrated"):
        top.fail("robot", f"the program is for {named!r}, not for {robot.name!r} (its angles, poses and limits are "
                          f"that robot's); run it with --robot {named}, or write {robot.name!r} there")


def robot_limits(robot: Robot | str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The joint velocity, acceleration and jerk limits of a robot folder (its ``tasks.toml``
    ``[limits]``), rad/s, rad/s^2, rad/s^3, each of shape (N,): the limits the thesis tasks are
    planned to, and the speed histogram's design maximum of their per-cycle features.

    Raises
    ------
    ProgramError
        If the folder has no ``tasks.toml`` or its ``[limits]`` are missing or malformed.
    """
    robot = robot if isinstance(robot, Robot) else robots.load(robot)
    return _limits({}, robot, f"{robot.name} limits")


def _limits(data: dict, robot: Robot, where: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The program's ``[limits]``, else the robot folder's ``tasks.toml`` ones, in rad."""
    table, origin = data.get("limits"), where
    if table is None:
        folder_file = robot.path.parent / "tasks.toml"
        if not folder_file.is_file():
            raise ProgramError(f"{where}: no [limits] table, and {folder_file} (where the robot's limits would be) "
                               "does not exist; add [limits] velocity, acceleration, jerk (deg/s, deg/s^2, deg/s^3)")
        try:
            table = inputs.read_toml(folder_file, "tasks file").get("limits")
        except inputs.InputError as err:
            raise ProgramError(str(err)) from None
        origin = str(folder_file)
    values = _Values(origin, "[limits] ", table if isinstance(table, dict) else {}, LIMIT_KEYS)
    n = len(robot.joint_names)
    return tuple(values.array(key, (n,), np.pi / 180, positive=True) for key in LIMIT_KEYS)


def _segment(where: str, number: int, table, robot: Robot) -> Segment:
    if not isinstance(table, dict):
        raise ProgramError(f"{where}: segment {number}: expected a [[segment]] table, got {table!r}")
    kind = table.get("type")
    if kind not in SEGMENT_KEYS:
        raise ProgramError(f"{where}: segment {number}: type = {kind!r}; expected one of {', '.join(SEGMENT_KEYS)}")
    t = _Values(where, f"segment {number} ({kind}) ", table, ("type", "label", *SEGMENT_KEYS[kind]))
    default_label = {"move": "move", "dwell": "dwell"}.get(kind, kind)
    values: dict = {}
    if kind == "move":
        given = [k for k in ("to", "pose") if k in table]
        if len(given) > 1:
            t.fail("to, pose", "give one target: joint angles (to, deg) or a Cartesian pose (pose, m)")
        if "to" in table:
            values["to"] = t.angles("to", robot)
            if "standoff" in table:
                t.fail("standoff", "a standoff goes with a Cartesian pose, not with joint angles")
        if "pose" in table:
            values["pose"] = t.array("pose", (3,))
        if "standoff" in table:
            values["standoff"] = t.number("standoff", minimum=0.0)
        if not given and "standoff" not in table:
            t.fail("to", "missing: expected to (joint angles, deg), pose (m) or standoff (m)")
        for key in ("velocity_scale", "acceleration_scale"):
            if key in table:
                values[key] = t.fraction(key)
    elif kind == "dwell":
        values["time"] = t.number("time", minimum=0.0)
        if abs(values["time"] / PLAN_PERIOD - round(values["time"] / PLAN_PERIOD)) > 1e-9:
            t.fail("time", f"{values['time']} s is not a whole number of {PLAN_PERIOD * 1e3:g} ms planning periods")
    elif kind in ("linear", "circular"):
        values["to"] = t.array("to", (3,))
        if kind == "circular":
            values["via"] = t.array("via", (3,))
        values["speed"], values["ramp_time"] = t.number("speed"), t.number("ramp_time")
    elif kind == "seam":
        values["vertices"] = t.array("vertices", (None, 3))
        if len(values["vertices"]) < 2:
            t.fail("vertices", "expected at least two points")
        values["corner_radius"] = t.number("corner_radius", minimum=0.0)
        values["speed"], values["ramp_time"] = t.number("speed"), t.number("ramp_time")
        values["weave_amplitude"] = t.number("weave_amplitude", minimum=0.0) if "weave_amplitude" in table else 0.0
        values["weave_frequency"] = t.number("weave_frequency", minimum=0.0) if "weave_frequency" in table else 0.0
    elif kind == "grip":
        mass = t.number("mass", minimum=0.0)
        if "size" in table:
            if "com" in table or "inertia" in table:
                t.fail("size", "give size (a cube) or com and inertia, not both")
            size = t.number("size", minimum=0.0)
            moment = mass * size**2 / 6  # as faultgen.operation.conditions.Payloads
            params = {"mass": mass, "com_x": 0.0, "com_y": 0.0, "com_z": size / 2,
                      "ixx": moment, "iyy": moment, "izz": moment, "ixy": 0.0, "ixz": 0.0, "iyz": 0.0}
        else:
            com = t.array("com", (3,)) if "com" in table else np.zeros(3)
            inertia = t.array("inertia", (6,)) if "inertia" in table else np.zeros(6)
            params = {"mass": mass, **dict(zip(("com_x", "com_y", "com_z"), map(float, com), strict=True)),
                      **dict(zip(("ixx", "iyy", "izz", "ixy", "ixz", "iyz"), map(float, inertia), strict=True))}
        values["part"] = params
    label_ = table.get("label", default_label)
    if not isinstance(label_, str) or not label_:
        t.fail("label", f"expected a non-empty string, got {label_!r}")
    return Segment(number, kind, label_, values)


class _Values(_Table):
    """One table of a program file; every error names the file, the table and the key (the values
    are read as a tasks.toml's are, :class:`faultgen.operation.tasks._Table`)."""

    def __init__(self, where: str, prefix: str, data, keys: tuple[str, ...]) -> None:
        if not isinstance(data, dict):
            raise ProgramError(f"{where}: {prefix.strip() or 'file'}: expected a table, got {data!r}")
        self.where, self.prefix = where, prefix
        self._take(data, keys)

    def fail(self, key: str, problem: str):
        raise ProgramError(f"{self.where}: {self.prefix}{key}: {problem}")

    def text(self, key: str) -> str:
        value = self.get(key)
        if not isinstance(value, str) or not value.strip():
            self.fail(key, f"expected a non-empty string, got {value!r}")
        return value

    def angles(self, key: str, robot: Robot) -> np.ndarray:
        """Joint angles given in deg, shape (N,), as rad within the joint ranges."""
        return super().angles(key, robot)[0]


# -- export --------------------------------------------------------------------------------------


def _toml(value) -> str:
    """A TOML value: numbers as Python writes them (they read back to the same float), lists inline."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, list):
        if value and isinstance(value[0], list):
            return "[\n" + "".join(f"    {_toml(v)},\n" for v in value) + "]"
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    raise TypeError(f"cannot write {value!r} as TOML")


def export(robot: Robot | str, name: str) -> str:
    """The thesis task ``name`` of ``robot`` (its ``tasks.toml`` section) as a program file's text:
    the same path, bit for bit, when read back (numbers are copied as the file gives them).

    Raises
    ------
    ValueError
        For an unknown task or a robot without a ``tasks.toml``.
    """
    from faultgen.operation import tasks

    if not isinstance(robot, Robot):
        robot = robots.load(robot)
    tasks.load(robot, name)  # refuses an unknown task or a malformed file, with the file and the key
    source = robot.path.parent / "tasks.toml"
    data = inputs.read_toml(source, "tasks file")
    t, limits = data[name], data["limits"]
    header = (f"Thesis ch. 6.3.1 task {TASKS.index(name) + 1} ({PROCESSES[name]}) of {robot.name}, exported from "
              f"{source.name} by `faultgen tasks export`.")
    program = {"name": name, "robot": robot.name, "process": PROCESSES[name], "start": t["start"],
               "velocity_scale": t["velocity_scale"], "acceleration_scale": t["acceleration_scale"],
               "limits": {key: limits[key] for key in LIMIT_KEYS}}
    if "tool_z" in t:
        program["tool"] = {"z": t["tool_z"], "x": t["tool_x"]}
    segments: list[dict] = []
    if name == "pick_place":
        for q, rest in zip(t["waypoints"], t["dwell"], strict=True):
            segments += [{"type": "move", "to": q}, {"type": "dwell", "time": rest}]
        segments.append({"type": "move", "to": t["start"]})
    elif name == "spot_weld":
        for point in t["points"]:
            segments += [{"type": "move", "pose": point}, {"type": "dwell", "time": t["dwell"], "label": "weld"}]
        segments.append({"type": "move", "to": t["start"]})
    else:
        seam = t["seam"]
        segments += [
            {"type": "move", "pose": seam[0], "standoff": t["standoff"], "label": "approach"},
            {"type": "move", "pose": seam[0], "label": "approach"},
            {"type": "seam", "vertices": seam, "corner_radius": t["corner_radius"], "speed": t["tool_speed"],
             "ramp_time": t["ramp_time"], "weave_amplitude": t["weave_amplitude"],
             "weave_frequency": t["weave_frequency"]},
            {"type": "move", "standoff": t["standoff"], "label": "retract"},
            {"type": "move", "to": t["start"], "label": "retract"},
        ]
    program["segment"] = segments
    return dumps(program, header)


#: Comments :func:`dumps` writes beside the values it knows.
_UNITS = {"start": "deg", "velocity": "deg/s", "acceleration": "deg/s^2", "jerk": "deg/s^3"}


def dumps(program: dict, header: str = "") -> str:
    """A program file's text from the table a program file reads as (``tomllib.loads`` of it): what
    a program generator (a robot builder writing thesis-like tasks) calls. Numbers are written as
    Python writes them, so they read back to the same floats.

    Parameters
    ----------
    program : dict
        ``name``, ``start`` (deg) and ``segment`` (a list of tables), optionally ``robot``,
        ``process``, ``description``, ``velocity_scale``, ``acceleration_scale``, ``limits``
        (``velocity``, ``acceleration``, ``jerk`` in deg/s, deg/s^2, deg/s^3) and ``tool`` (``z``,
        ``x``, ``offset``); see the module docstring.
    header : str
        A comment for the file's top (one line or several).

    Raises
    ------
    ProgramError
        For a key :func:`parse` would not read (checked without a robot; :func:`parse` checks the
        values).
    """
    _Values("program", "", program, TOP_KEYS)
    for key in ("limits", "tool"):
        _Values("program", f"[{key}] ", program.get(key, {}), LIMIT_KEYS if key == "limits" else TOOL_KEYS)
    for k, table in enumerate(program.get("segment", [])):
        kind = table.get("type") if isinstance(table, dict) else None
        if kind not in SEGMENT_KEYS:
            raise ProgramError(f"program: segment {k + 1}: type = {kind!r}; expected one of {', '.join(SEGMENT_KEYS)}")
        _Values("program", f"segment {k + 1} ({kind}) ", table, ("type", "label", *SEGMENT_KEYS[kind]))
    lines = [f"# {line}" for line in header.splitlines()]
    if header:
        lines.append("# Units: joint angles in deg, positions in m (world frame), times in s, speeds in m/s.")
    for key in TOP_KEYS:
        if key in program and key not in ("limits", "tool", "segment"):
            unit = f"  # {_UNITS[key]}" if key in _UNITS else ""
            lines.append(f"{key} = {_toml(program[key])}{unit}")
    for key, title in (("limits", "joint limits for planning, axes 1..N"),
                       ("tool", "flange orientation at Cartesian targets (world frame); offset: tool centre point, "
                                "m, flange frame")):
        if key in program:
            lines += ["", f"[{key}]  # {title}"]
            for name, value in program[key].items():
                unit = f"  # {_UNITS[name]}" if key == "limits" and name in _UNITS else ""
                lines.append(f"{name} = {_toml(value)}{unit}")
    for segment in program.get("segment", []):
        lines += ["", "[[segment]]"] + [f"{key} = {_toml(value)}" for key, value in segment.items()]
    return "\n".join(lines) + "\n"


def show(robot: Robot | str, task: str) -> str:
    """The text of a task: a thesis task exported (:func:`export`), or a program file's own text."""
    if task in TASKS:
        return export(robot, task)
    check_name(task)
    if not str(task).lower().endswith(PROGRAM_SUFFIXES):
        raise ValueError(f"{task}: a joint log has no program text; `faultgen tasks show` prints programs")
    return Path(task).read_text()


def available(robot: Robot | str) -> list[tuple[str, str]]:
    """The programs of ``robot``: ``(name, what)`` for each thesis task in its ``tasks.toml`` and each
    program file in its folder's ``programs/``."""
    if not isinstance(robot, Robot):
        robot = robots.load(robot)
    out = []
    folder_file = robot.path.parent / "tasks.toml"
    if folder_file.is_file():
        data = inputs.read_toml(folder_file, "tasks file")
        out += [(name, f"thesis task {TASKS.index(name) + 1}, {PROCESSES[name]} ({folder_file.name})")
                for name in TASKS if name in data]
    folder = robot.path.parent / "programs"
    if folder.is_dir():
        out += [(str(p), "program file") for p in sorted(folder.glob("*.toml"))]
    return out
