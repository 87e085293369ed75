"""The industrial tasks a robot repeats as a cycle, as time-parameterised arm-side joint paths.

Thesis ch. 6.3.1 simulates three tasks: task 1, a pick and place moving each axis over a large
part of its range; task 2, a discontinuous process with many stops at maximum acceleration
(spot welding); task 3, a continuous process (arc welding). Their data (joint limits for
planning, waypoints, weld points, seam, speeds, dwell times) live in ``robots/<robot>/tasks.toml``
and :func:`load` reads them into a :class:`Task`, whose :meth:`Task.trajectory` gives a
:class:`JointPath`:

- point-to-point moves: ruckig (jerk-limited, time-optimal, rest to rest, all axes finishing
  together, duration a whole number of planning periods, :data:`PLAN_PERIOD`);
- weld points and seam: flange IK with mink on an arm-only model (:mod:`faultgen.operation.ik`);
- the seam: IK every 10 ms along the tool path, a clamped cubic spline through the solutions
  sampled at dt, its derivatives giving qd and qdd.

Every cycle starts and ends at the task's ``start`` angles at rest, so cycles repeat. Every
segment lasts whole planning periods, so the path is one continuous function of time, whatever
step ``dt`` samples it (the physics step or the 4 ms log period): a finer physics step refines
the simulation of the same cycle, not a different cycle (docs/simulation.md, "Numerical
convergence").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from ruckig import DurationDiscretization, InputParameter, Result, Ruckig, Trajectory

from faultgen import inputs
from faultgen.model import robots
from faultgen.model.robots import Robot
from faultgen.operation.ik import FlangeIK, Seam, ramp_arc_length, tool_rotation

TASKS = ("pick_place", "spot_weld", "arc_weld")
PROCESSES = {"pick_place": "point-to-point", "spot_weld": "discontinuous", "arc_weld": "continuous"}
IK_STEP = 0.01  # s: knot step of the seam IK; the spline interpolates in between
#: s: every move, dwell and seam lasts a whole number of these (the thesis's 4 ms sampling period,
#: ch. 6.3.2), so a path sampled at any step that divides it is the same path.
PLAN_PERIOD = 0.004
#: Longest cycle a task, program or replayed log may make, s, and most samples of its path: checked
#: before a piece of path is allocated (a ``dwell time = 1e9`` asked for 87 TiB, a program of 10^4
#: moves took 5.4 GB; issue 50). An hour is far beyond an industrial cycle (seconds to minutes).
MAX_CYCLE_DURATION = 3600.0
MAX_CYCLE_SAMPLES = 7_200_000  # an hour at the finest step, 0.5 ms
SEAM_TOLERANCE = 5e-4  # m: largest allowed flange distance from the commanded seam point
SEAM_LIMIT_TOLERANCE = 0.01  # relative excess over a velocity/acceleration limit allowed on the seam
LIMIT_TOLERANCE = 1e-9  # relative (velocity, acceleration) and rad (position) elsewhere


@dataclass(frozen=True, eq=False)
class JointPath:
    """One task cycle as arm-side joint samples at a constant time step.

    Attributes
    ----------
    t : ndarray of shape (n,)
        Time in s, ``k * dt`` from 0.
    q, qd, qdd : ndarray of shape (n, 6)
        Arm joint angles (rad), velocities (rad/s) and accelerations (rad/s^2). The last sample
        equals the first: same angles, zero velocity and acceleration.
    target : ndarray of shape (n, 3)
        Commanded flange position in m, world frame, where the task defines one (weld points
        during their dwell, the seam); NaN elsewhere.
    segments : tuple of (str, int, int)
        ``(label, first, last)``: consecutive parts of the cycle as inclusive sample indices
        (neighbours share their boundary sample). Labels: ``move``, ``dwell`` (task 1),
        ``weld`` (task 2), ``approach``, ``seam``, ``retract`` (task 3); a program's own labels.
    loads : tuple of faultgen.operation.programs.Load
        Payloads a program grips and releases within the cycle (sample ranges and parameters);
        empty for the thesis tasks.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    target: np.ndarray
    segments: tuple[tuple[str, int, int], ...]
    loads: tuple = ()

    @property
    def duration(self) -> float:
        """Cycle duration in s."""
        return float(self.t[-1])


@dataclass(frozen=True, eq=False)
class Task:
    """A task of thesis ch. 6.3.1 for one robot, as read from its ``tasks.toml``.

    Attributes
    ----------
    name : str
        One of :data:`TASKS`.
    robot_name : str
    process : str
        ``"point-to-point"`` (task 1), ``"discontinuous"`` (task 2) or ``"continuous"`` (task 3).
    source : Path
        The ``tasks.toml`` the data came from.
    velocity_limit, acceleration_limit, jerk_limit : ndarray of shape (6,)
        Joint limits for planning in rad/s, rad/s^2 and rad/s^3 (the file's ``[limits]``).
    start : ndarray of shape (6,)
        Arm angles in rad at which the cycle starts and ends, at rest.
    velocity_scale, acceleration_scale : float
        Fractions of the velocity and acceleration limits the point-to-point moves use.
    robot : Robot
    """

    name: str
    robot_name: str
    process: str
    source: Path
    velocity_limit: np.ndarray
    acceleration_limit: np.ndarray
    jerk_limit: np.ndarray
    start: np.ndarray
    velocity_scale: float
    acceleration_scale: float
    robot: Robot = field(repr=False)

    def trajectory(self, dt: float) -> JointPath:
        """The task cycle sampled every ``dt`` seconds.

        Parameters
        ----------
        dt : float
            Time step in s that divides :data:`PLAN_PERIOD` (4 ms) into whole steps, e.g. 0.004
            (the thesis's sampling) or the 0.0005 simulation step. The path does not depend on
            it: a finer ``dt`` gives the same path at more instants.

        Returns
        -------
        JointPath
            Deterministic: the same call gives bit-identical arrays.

        Raises
        ------
        ValueError
            If ``dt`` is not a positive step that divides 4 ms, IK fails, the flange leaves the
            seam by more than 0.5 mm, or the path breaks a joint range, velocity or acceleration
            limit.
        """
        if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
            raise ValueError(f"dt must be a positive number of seconds, got {dt!r}")
        if abs(PLAN_PERIOD / dt - round(PLAN_PERIOD / dt)) > 1e-9:
            raise ValueError(f"dt = {dt!r} s does not divide the {PLAN_PERIOD * 1e3:g} ms planning period into whole "
                             "steps; expected e.g. 0.004, 0.002, 0.001 or 0.0005")
        path = _Builder(self.start, float(dt))
        self._plan(path)
        result = path.build()
        _check_limits(self, result, np.concatenate(path.tolerance))
        return result

    def _plan(self, path: _Builder) -> None:
        """Add the task's segments to ``path``: each task class (below) defines its own."""
        raise NotImplementedError(f"{type(self).__name__} does not define its motion")

    def _move(self, path: _Builder, label: str, q_to: np.ndarray) -> None:
        """Append a ruckig rest-to-rest move from the path's last sample to ``q_to``."""
        q, qd, qdd = ptp(path.last, q_to, self.velocity_scale * self.velocity_limit,
                         self.acceleration_scale * self.acceleration_limit, self.jerk_limit, path.dt,
                         f"{self.robot_name} {self.name}")
        path.add(label, q, qd, qdd)

    def _solve(self, ik: FlangeIK, what: str, position, rotation, q_init) -> np.ndarray:
        try:
            return ik.solve(position, rotation, q_init)
        except ValueError as err:
            raise ValueError(f"{self.robot_name} {self.name}, {what}: {err}") from err


@dataclass(frozen=True, eq=False)
class PickPlaceTask(Task):
    """Thesis task 1: joint-space moves start -> waypoint 1 -> ... -> start, resting at each.

    Attributes
    ----------
    waypoints : ndarray of shape (m, 6)
        Arm angles in rad (pick, place, ...).
    dwell : ndarray of shape (m,)
        Rest at each waypoint in s.
    """

    waypoints: np.ndarray
    dwell: np.ndarray

    def _plan(self, path):
        for q, rest in zip(self.waypoints, self.dwell):
            self._move(path, "move", q)
            path.hold("dwell", rest)
        self._move(path, "move", self.start)


@dataclass(frozen=True, eq=False)
class SpotWeldTask(Task):
    """Thesis task 2: short rest-to-rest moves between weld points, stopping at each.

    Attributes
    ----------
    points : ndarray of shape (m, 3)
        Weld points: flange positions in m, world frame, in the order visited.
    tool_rotation : ndarray of shape (3, 3)
        Flange orientation at the weld points (columns: flange x, y, z in the world frame).
    dwell : float
        Stop at each weld point in s.
    """

    points: np.ndarray
    tool_rotation: np.ndarray
    dwell: float

    def _plan(self, path):
        ik = FlangeIK(self.robot, self.start)
        q = self.start
        for k, point in enumerate(self.points):
            q = self._solve(ik, f"weld point {k + 1}", point, self.tool_rotation, q)
            self._move(path, "move", q)
            path.hold("weld", self.dwell, target=point)
        self._move(path, "move", self.start)


@dataclass(frozen=True, eq=False)
class ArcWeldTask(Task):
    """Thesis task 3: approach, a seam at constant tool speed with a weave, retract.

    The seam is a polyline with corners rounded to ``corner_radius``. The tool speeds up from
    rest to ``tool_speed`` in ``ramp_time`` (raised-cosine acceleration; the ramp is lengthened
    by less than :data:`PLAN_PERIOD` so the seam lasts whole planning periods), keeps that speed
    and stops at the seam end.
    The weave ``weave_amplitude * sin(pi m s / L)`` runs across the seam in its plane, with s
    the arc length, L the seam length and m the whole number of half periods nearest to
    ``2 weave_frequency L / tool_speed``: the weave starts and ends on the seam and, at
    constant speed, has a frequency within ``tool_speed / (4 L)`` of ``weave_frequency``.

    Attributes
    ----------
    seam : ndarray of shape (k, 3)
        Seam polyline vertices in m, world frame, in one plane.
    tool_rotation : ndarray of shape (3, 3)
        Constant flange orientation along the seam.
    corner_radius : float
        m.
    tool_speed : float
        m/s along the seam.
    ramp_time : float
        s.
    weave_amplitude : float
        m.
    weave_frequency : float
        Hz.
    standoff : float
        Distance in m back along the tool axis of the approach and retract points.
    """

    seam: np.ndarray
    tool_rotation: np.ndarray
    corner_radius: float
    tool_speed: float
    ramp_time: float
    weave_amplitude: float
    weave_frequency: float
    standoff: float

    def geometry(self) -> Seam:
        """The seam polyline with rounded corners."""
        return Seam(self.seam, self.corner_radius, self.tool_rotation[:, 2])

    def seam_duration(self) -> float:
        """Seam time in s: ``L / tool_speed + ramp_time`` rounded up to whole :data:`PLAN_PERIOD`."""
        periods = math.ceil((self.geometry().length / self.tool_speed + self.ramp_time) / PLAN_PERIOD - 1e-9)
        return periods * PLAN_PERIOD

    def tool_path(self, t: np.ndarray) -> np.ndarray:
        """Commanded flange positions, shape (n, 3) in m, at times t (n,) in s since the seam start."""
        seam = self.geometry()
        duration = self.seam_duration()
        ramp = duration - seam.length / self.tool_speed
        s = ramp_arc_length(t, self.tool_speed, ramp, duration)
        position, tangent = seam.evaluate(s)
        half_periods = max(1, round(2 * self.weave_frequency * seam.length / self.tool_speed))
        weave = self.weave_amplitude * np.sin(np.pi * half_periods * s / seam.length)
        return position + weave[:, None] * np.cross(seam.normal, tangent)

    def _plan(self, path):
        ik = FlangeIK(self.robot, self.start)
        rotation, back = self.tool_rotation, -self.standoff * self.tool_rotation[:, 2]
        duration = self.seam_duration()
        knots = np.linspace(0.0, duration, math.ceil(duration / IK_STEP - 1e-9) + 1)
        points = self.tool_path(knots)
        q_above = self._solve(ik, "approach point", points[0] + back, rotation, self.start)
        q_seam = self._solve(ik, "seam start", points[0], rotation, q_above)
        self._move(path, "approach", q_above)
        self._move(path, "approach", q_seam)

        t = np.arange(round(duration / path.dt) + 1) * path.dt
        try:
            q, qd, qdd = ik.follow(knots, points, rotation, q_seam, t)
        except ValueError as err:
            raise ValueError(f"{self.robot_name} {self.name}, seam: {err}") from err
        target = self.tool_path(t)
        self._check_seam(ik.deviation(q, target), qd, qdd, path.count - 1, path.dt)
        path.add("seam", q, qd, qdd, target=target, tolerance=SEAM_LIMIT_TOLERANCE)

        q_back = self._solve(ik, "retract point", points[-1] + back, rotation, q[-1])
        self._move(path, "retract", q_back)
        self._move(path, "retract", self.start)

    def _check_seam(self, deviation, qd, qdd, first, dt) -> None:
        """Raise if the flange leaves the seam by > 0.5 mm or the seam is too fast for the limits."""
        where = f"{self.robot_name} {self.name}"
        k = int(np.argmax(deviation))
        if deviation[k] > SEAM_TOLERANCE:
            raise ValueError(
                f"{where}: IK leaves the flange {deviation[k] * 1e3:.3f} mm from the seam at sample "
                f"{first + k} (t = {(first + k) * dt:.3f} s), more than {SEAM_TOLERANCE * 1e3} mm"
            )
        speed = np.max(np.abs(qd), axis=0) / self.velocity_limit
        accel = np.max(np.abs(qdd), axis=0) / self.acceleration_limit
        axis = int(np.argmax(np.maximum(speed, accel)))
        if max(speed[axis], accel[axis]) > 1 + SEAM_LIMIT_TOLERANCE:
            # joint velocity grows with the tool speed, joint acceleration about with its square
            fit = self.tool_speed / max(speed[axis], np.sqrt(accel[axis]))
            kind = "velocity" if speed[axis] >= accel[axis] else "acceleration"
            raise ValueError(
                f"{where}: the seam at {self.tool_speed} m/s needs {max(speed[axis], accel[axis]):.2f} times "
                f"the {kind} limit of axis {axis + 1}; a tool_speed of about {fit:.3g} m/s would fit "
                f"({self.source})"
            )


def ptp(q_from: np.ndarray, q_to: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray, jerk: np.ndarray,
        dt: float, where: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A ruckig rest-to-rest joint move (jerk-limited, time-optimal, all axes finishing together,
    lasting whole :data:`PLAN_PERIOD`), sampled every ``dt`` s.

    Parameters
    ----------
    q_from, q_to : ndarray of shape (N,)
        Start and end arm angles, rad (N the robot's axes).
    velocity, acceleration, jerk : ndarray of shape (N,)
        Limits of the move, rad/s, rad/s^2, rad/s^3.
    dt : float
        Sample step, s.
    where : str
        Names the move in an error message.

    Returns
    -------
    q, qd, qdd : ndarray of shape (n, N)
        From ``q_from`` to ``q_to`` inclusive; the first and last samples at rest.

    Raises
    ------
    ValueError
        If ruckig finds no move.
    """
    n = len(q_from)
    otg = Ruckig(n, PLAN_PERIOD)
    inp = InputParameter(n)
    inp.current_position, inp.target_position = q_from, q_to
    inp.current_velocity = inp.current_acceleration = np.zeros(n)
    inp.target_velocity = inp.target_acceleration = np.zeros(n)
    inp.max_velocity = velocity
    inp.max_acceleration = acceleration
    inp.max_jerk = jerk
    inp.duration_discretization = DurationDiscretization.Discrete
    trajectory = Trajectory(n)
    if otg.calculate(inp, trajectory) not in (Result.Working, Result.Finished):
        raise ValueError(f"{where}: ruckig found no move to {np.round(q_to, 4)}")
    check_cycle_length(trajectory.duration, dt, where)
    steps = round(trajectory.duration / dt)
    samples = [trajectory.at_time(k * dt) for k in range(steps)]
    q = np.array([s[0] for s in samples] + [q_to]).reshape(-1, n)
    qd = np.array([s[1] for s in samples] + [np.zeros(n)]).reshape(-1, n)
    qdd = np.array([s[2] for s in samples] + [np.zeros(n)]).reshape(-1, n)
    return q, qd, qdd


class CycleTooLong(ValueError):
    """A path would exceed :data:`MAX_CYCLE_DURATION` or :data:`MAX_CYCLE_SAMPLES`; ``reason`` says
    by how much, without the place (``str`` adds it)."""

    def __init__(self, where: str, reason: str) -> None:
        super().__init__(f"{where}: {reason}")
        self.reason = reason


def check_cycle_length(duration: float, dt: float, where: str) -> None:
    """Refuse (:class:`CycleTooLong`, naming ``where`` and the limit) a path of ``duration`` s at step
    ``dt`` s beyond :data:`MAX_CYCLE_DURATION` or :data:`MAX_CYCLE_SAMPLES`, before it is sampled."""
    if not duration <= MAX_CYCLE_DURATION:  # NaN too
        raise CycleTooLong(where, f"the cycle would last {duration:.6g} s; a cycle lasts at most "
                                  f"{MAX_CYCLE_DURATION:g} s (MAX_CYCLE_DURATION)")
    if duration / dt > MAX_CYCLE_SAMPLES:
        raise CycleTooLong(where, f"the cycle would take {duration / dt:.6g} samples at dt = {dt:g} s; a cycle "
                                  f"has at most {MAX_CYCLE_SAMPLES} (MAX_CYCLE_SAMPLES)")


class _Builder:
    """Collects path pieces; each piece starts at the previous piece's last sample."""

    def __init__(self, q0: np.ndarray, dt: float) -> None:
        self.dt = dt
        n = len(q0)  # the robot's axes
        self.q, self.qd, self.qdd = [q0[None].copy()], [np.zeros((1, n))], [np.zeros((1, n))]
        self.target = [np.full((1, 3), np.nan)]
        self.tolerance = [np.zeros(1)]
        self.segments: list[tuple[str, int, int]] = []
        self.count = 1

    @property
    def last(self) -> np.ndarray:
        return self.q[-1][-1]

    def add(self, label, q, qd, qdd, target=None, tolerance=0.0) -> None:
        steps = len(q) - 1
        if steps == 0:
            return
        check_cycle_length((self.count - 1 + steps) * self.dt, self.dt, label)
        if target is not None:
            self.target[-1][-1] = target[0]
        self.q.append(q[1:])
        self.qd.append(qd[1:])
        self.qdd.append(qdd[1:])
        self.target.append(np.full((steps, 3), np.nan) if target is None else np.array(target[1:]))
        self.tolerance.append(np.full(steps, tolerance))
        self.segments.append((label, self.count - 1, self.count - 1 + steps))
        self.count += steps

    def hold(self, label: str, duration: float, target: np.ndarray | None = None) -> None:
        check_cycle_length((self.count - 1) * self.dt + duration, self.dt, label)
        steps = round(duration / PLAN_PERIOD) * round(PLAN_PERIOD / self.dt)
        q = np.repeat(self.last[None], steps + 1, axis=0)
        zero = np.zeros_like(q)
        self.add(label, q, zero, zero, None if target is None else np.repeat(target[None], steps + 1, axis=0))

    def build(self) -> JointPath:
        q = np.concatenate(self.q)
        return JointPath(
            t=np.arange(len(q)) * self.dt,
            q=q,
            qd=np.concatenate(self.qd),
            qdd=np.concatenate(self.qdd),
            target=np.concatenate(self.target),
            segments=tuple(self.segments),
        )


def _check_limits(task: Task, path: JointPath, tolerance: np.ndarray) -> None:
    """Raise ValueError naming the axis and sample where a path leaves the joint limits."""
    low, high = task.robot.joint_range[:, 0], task.robot.joint_range[:, 1]
    checks = [
        ("angle", path.q, None, "rad"),
        ("velocity", path.qd, task.velocity_limit, "rad/s"),
        ("acceleration", path.qdd, task.acceleration_limit, "rad/s^2"),
    ]
    for kind, values, limit, unit in checks:
        if limit is None:
            bad = (values < low - LIMIT_TOLERANCE) | (values > high + LIMIT_TOLERANCE)
        else:
            bad = np.abs(values) > limit * (1 + tolerance[:, None] + LIMIT_TOLERANCE)
        if np.any(bad):
            k, axis = np.argwhere(bad)[0]
            raise ValueError(
                f"{task.robot_name} {task.name}: joint {kind} {values[k, axis]:.4g} {unit} "
                f"of axis {axis + 1} "
                f"at sample {k} (t = {path.t[k]:.3f} s) is outside the limits ({task.source})"
            )


def load(robot: Robot | str, name: str) -> Task:
    """Read one task of a robot from ``tasks.toml`` in the robot's folder.

    Parameters
    ----------
    robot : Robot or str
        A loaded robot, or a name or MJCF path for :func:`faultgen.model.robots.load`.
    name : str
        One of :data:`TASKS`.

    Returns
    -------
    Task
        A :class:`PickPlaceTask`, :class:`SpotWeldTask` or :class:`ArcWeldTask`.

    Raises
    ------
    ValueError
        For an unknown task (the message lists the known ones), or a missing or malformed
        ``tasks.toml`` (the message names the file and the key).
    """
    if not isinstance(robot, Robot):
        robot = robots.load(robot)
    if name not in TASKS:
        raise ValueError(f"unknown task {name!r}; known tasks: {', '.join(TASKS)}")
    path = robot.path.parent / "tasks.toml"
    if not path.is_file():
        raise ValueError(f"{path}: no tasks file for robot {robot.name!r}")
    data = inputs.read_toml(path, "tasks file")
    for key in data:
        if key not in ("limits", *TASKS):
            raise ValueError(f"{path}: unknown table [{key}]; expected [limits] and {', '.join(TASKS)}")
    limits = _Table(path, data, "limits", ("velocity", "acceleration", "jerk"))
    n_axes = len(robot.joint_names)
    table = _Table(path, data, name, _KEYS[name])
    start = table.angles("start", robot)
    common = {
        "name": name,
        "robot_name": robot.name,
        "process": PROCESSES[name],
        "source": path,
        "velocity_limit": limits.array("velocity", (n_axes,), np.pi / 180, positive=True),
        "acceleration_limit": limits.array("acceleration", (n_axes,), np.pi / 180, positive=True),
        "jerk_limit": limits.array("jerk", (n_axes,), np.pi / 180, positive=True),
        "start": start[0],
        "velocity_scale": table.fraction("velocity_scale"),
        "acceleration_scale": table.fraction("acceleration_scale"),
        "robot": robot,
    }
    if name == "pick_place":
        waypoints = table.angles("waypoints", robot, many=True)
        dwell = table.array("dwell", (len(waypoints),), nonnegative=True)
        return PickPlaceTask(**common, waypoints=waypoints, dwell=dwell)
    rotation = table.rotation()
    if name == "spot_weld":
        points = table.array("points", (None, 3))
        return SpotWeldTask(**common, points=points, tool_rotation=rotation, dwell=table.number("dwell", 0.0))
    task = ArcWeldTask(
        **common,
        seam=table.array("seam", (None, 3)),
        tool_rotation=rotation,
        corner_radius=table.number("corner_radius"),
        tool_speed=table.number("tool_speed"),
        ramp_time=table.number("ramp_time"),
        weave_amplitude=table.number("weave_amplitude", 0.0),
        weave_frequency=table.number("weave_frequency"),
        standoff=table.number("standoff", 0.0),
    )
    try:
        task.geometry()
    except ValueError as err:
        raise ValueError(f"{path}: [arc_weld] seam: {err}") from err
    return task


_COMMON = ("start", "velocity_scale", "acceleration_scale")
_KEYS = {
    "pick_place": (*_COMMON, "waypoints", "dwell"),
    "spot_weld": (*_COMMON, "tool_z", "tool_x", "points", "dwell"),
    "arc_weld": (
        *_COMMON,
        *("tool_z", "tool_x", "seam", "corner_radius", "tool_speed", "ramp_time"),
        *("weave_amplitude", "weave_frequency", "standoff"),
    ),
}


class _Table:
    """One table of a tasks.toml; every error names the file, the table and the key. The reader of
    a program file's tables (:class:`faultgen.operation.programs._Values`) is this one, naming its
    tables its own way (:meth:`fail`)."""

    def __init__(self, path: Path, data: dict, name: str, keys: tuple[str, ...]) -> None:
        if not isinstance(data.get(name), dict):
            raise ValueError(f"{path}: missing table [{name}]")  # noqa: TRY004 (a file error, not a type error)
        self.path, self.name = path, name
        self._take(data[name], keys)

    def _take(self, data: dict, keys: tuple[str, ...]) -> None:
        """Hold the table ``data``, refusing a key not among ``keys``."""
        self.data = data
        for key in data:
            if key not in keys:
                self.fail(key, f"unknown key; expected one of {', '.join(keys)}")

    def fail(self, key: str, problem: str):
        raise ValueError(f"{self.path}: [{self.name}] {key}: {problem}")

    def get(self, key: str):
        if key not in self.data:
            self.fail(key, "missing")
        return self.data[key]

    def array(self, key, shape, scale=1.0, positive=False, nonnegative=False) -> np.ndarray:
        value = self.get(key)
        try:
            arr = np.array(value, dtype=float)
        except (TypeError, ValueError):
            self.fail(key, f"expected numbers, got {value!r}")
        expected = tuple(
            arr.shape[i] if n is None and arr.ndim == len(shape) else n for i, n in enumerate(shape)
        )
        if arr.shape != expected or arr.size == 0:
            self.fail(key, f"expected shape {tuple('m' if n is None else n for n in shape)}, got {arr.shape}")
        if (
            not np.all(np.isfinite(arr))
            or (positive and np.any(arr <= 0))
            or (nonnegative and np.any(arr < 0))
        ):
            sign = " positive" if positive else " non-negative" if nonnegative else ""
            self.fail(key, f"expected finite{sign} numbers, got {value!r}")
        return arr * scale

    def number(self, key: str, minimum: float | None = None) -> float:
        value = self.get(key)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            self.fail(key, f"expected a number, got {value!r}")
        if (minimum is None and value <= 0) or (minimum is not None and value < minimum):
            self.fail(
                key, f"expected a {'positive' if minimum is None else 'non-negative'} number, got {value}"
            )
        return float(value)

    def fraction(self, key: str, default: float | None = None) -> float:
        if default is not None and key not in self.data:
            return default
        value = self.number(key)
        if value > 1:
            self.fail(key, f"expected a fraction in (0, 1], got {value}")
        return value

    def angles(self, key: str, robot: Robot, many: bool = False) -> np.ndarray:
        """Joint angles given in deg, one (6,) or ``many`` (m, 6), as rad (m, 6) within the ranges."""
        n = len(robot.joint_names)
        q = self.array(key, (None, n) if many else (n,), np.pi / 180).reshape(-1, n)
        low, high = robot.joint_range[:, 0], robot.joint_range[:, 1]
        bad = np.argwhere((q < low) | (q > high))
        if bad.size:
            row, axis = bad[0]
            value = q[row, axis]
            edge = low[axis] if value < low[axis] else high[axis]
            self.fail(key, f"axis {axis + 1} at {np.degrees(value):.2f} deg is {abs(np.degrees(value - edge)):.2f} deg "
                      f"outside its range {np.degrees(low[axis]):.1f}..{np.degrees(high[axis]):.1f} deg")
        return q

    def rotation(self) -> np.ndarray:
        try:
            return tool_rotation(self.array("tool_z", (3,)), self.array("tool_x", (3,)))
        except (ValueError, ZeroDivisionError, FloatingPointError) as err:
            self.fail("tool_z, tool_x", str(err))
