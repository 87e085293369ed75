"""Replay a measured joint trajectory as a task: the motion a user's robot actually performed.

A log is a CSV file (``.csv`` or gzip-compressed ``.csv.gz``, a header row) or an HDF5 file (``.h5``,
``.hdf5``; one 1-D dataset per column at the root) with the columns ``t`` (s, strictly increasing)
and ``q1`` .. ``qN`` (rad, N the robot's axes); other columns are ignored, so the measured-log format
of ``faultgen calibrate`` (:mod:`faultgen.logs.measured`: ``t, q, tau``, optional ``qd``) reads as
it is.

The reference (:meth:`Replay.trajectory`):

- velocity and acceleration of the log by the calibration's own estimator on the log's samples
  (:func:`faultgen.derivatives.derivatives`: Savitzky-Golay, cubic, 0.05 s window), so a replayed
  log and the same log calibrated see one motion;
- angles, velocities and accelerations each a cubic spline through the log's samples, sampled at
  the step ``dt``; the log's motion is cut to whole planning periods (the last < 4 ms dropped), so
  the path is one function of time whatever step samples it, and equals the log at its times;
- time 0 of the run is the log's first sample: the run starts in the log's first state, at rest
  or, for a log that starts moving (a snippet of continuous motion), at its first velocity and
  acceleration (:func:`faultgen.simulation.batch.start_state`), so the recorded reference
  ``q_ref`` is the log at the recorded times;
- a log that does not end at rest gets a run-out: a ruckig jerk-limited ramp from its last state
  to rest, within the robot's planning limits (its folder's ``tasks.toml`` ``[limits]``), after
  the log's times. At rest means every axis below :data:`REST_SPEED` and
  :data:`REST_ACCELERATION`; such an end is set exactly at rest.

A log that does not start at rest gets no run-in (a ramp from rest into its first state): one
would shift the whole log later in the run, and the recorded reference would be off the log at
the recorded times (by up to 0.8 rad).

The log is read by the measured-log reader (:mod:`faultgen.logs.jointlog`: one parser, one
set of checks, one derivative estimator; the torque columns are not needed), in blocks
(:mod:`faultgen.logs.blocks`), so memory does not grow with the log's rows: a log of at
most one row per physics step of the robot is read whole; a denser one is checked row by row as
it streams by and then replayed as every ``k``-th row from the first, at most one row per step
(what the reference, sampled at that step, can use), kept as it is read: the log as if it had been
recorded at that rate (the reference passes through its own samples, time 0 is its first).
A log in another registered format (:mod:`faultgen.logs.formats`, ``--format NAME``) is
streamed the same way through its adapter's block reader; read whole (at most a row per physics
step), its columns are replayed by :func:`from_columns` with the same checks and messages.

Refused before any simulation (:class:`faultgen.logs.columns.LogError`, a ValueError naming
the file, the row or column and the value): a missing column, a non-finite value, time not
increasing, a log shorter than :data:`MIN_DURATION`, a gap longer than
:data:`faultgen.logs.columns.MAX_GAP`, a log longer than
:data:`faultgen.operation.tasks.MAX_CYCLE_DURATION` (as soon as a block shows it, before the rest
is read), an angle outside the joint range (by how much), and a motor torque above the drives'
capacity.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from ruckig import ControlInterface, DurationDiscretization, InputParameter, Result, Ruckig, Trajectory
from scipy.interpolate import CubicSpline

from faultgen.model.robots import Robot
from faultgen.logs import blocks, formats, jointlog
from faultgen.logs.columns import MAX_GAP, T_COLUMN, LogError, column_names
from faultgen.operation.tasks import MAX_CYCLE_DURATION, PLAN_PERIOD, JointPath, Motion

#: Shortest log replayed, s (four filter windows); the longest interval between samples is the
#: measured-log reader's :data:`faultgen.logs.columns.MAX_GAP` (the derivative filter's window).
MIN_DURATION = 0.2
#: Rows read at a time: a replay's peak memory is that of its reference at the physics step, so its
#: blocks are smaller than the calibration's (:data:`faultgen.logs.blocks.BLOCK_ROWS`).
BLOCK_ROWS = 50_000
#: A log end is at rest when every axis is below these, rad/s and rad/s^2.
REST_SPEED = 1e-3
REST_ACCELERATION = 1e-2


@dataclass(frozen=True, eq=False)
class Replay:
    """A joint log to replay (module docstring).

    Attributes
    ----------
    name : str
        The file's stem.
    robot_name : str
    process : str
        ``"replay"``.
    source : Path
    t, q : ndarray of shape (n,), (n, N)
        The log's times (s, from its first sample) and angles (rad).
    qd, qdd : ndarray of shape (n, N)
        Their velocity and acceleration (rad/s, rad/s^2) by the calibration's estimator.
    velocity_limit, acceleration_limit, jerk_limit : ndarray of shape (N,)
        Planning limits of the run-out, rad/s, rad/s^2, rad/s^3.
    start : ndarray of shape (N,)
        Where the cycle starts, rad: the log's first angles.
    robot : Robot
    check_torque : callable
        Refuses a reference above the drives' capacity (:func:`read`).
    """

    name: str
    robot_name: str
    process: str
    source: Path
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    velocity_limit: np.ndarray
    acceleration_limit: np.ndarray
    jerk_limit: np.ndarray
    start: np.ndarray
    robot: Robot = field(repr=False)
    check_torque: Callable = field(repr=False)

    @classmethod
    def from_motion(cls, motion: Motion, robot: Robot, limits: tuple[np.ndarray, np.ndarray, np.ndarray],
                    check_torque: Callable) -> Replay:
        """The replay of a motion given in memory (a :class:`faultgen.operation.tasks.Motion`: its
        ``t`` s and ``q`` rad), with the checks and messages of a measured log read whole
        (:func:`from_columns`; its samples named ``sample K``); named ``motion.name``, its source
        ``motion.source``. ``robot``, ``limits``, ``check_torque``: as :func:`read`.

        Raises
        ------
        faultgen.logs.columns.LogError
            As :func:`read`; also for angles of another number of axes than ``robot``'s.
        """
        n = robot.n_axes
        if motion.q.shape[1] != n:
            raise LogError(f"{motion.source}: {motion.q.shape[1]} angle columns; {robot.name} has {n} axes")
        columns = {T_COLUMN: motion.t, **dict(zip(column_names(n)[0], motion.q.T, strict=True))}
        found = from_columns(columns, lambda i: f"sample {i}", Path(motion.source), robot, limits, check_torque)
        return dataclasses.replace(found, name=motion.name)

    @property
    def duration(self) -> float:
        """The replayed part of the log, s: whole planning periods."""
        return np.floor(self.t[-1] / PLAN_PERIOD + 1e-9) * PLAN_PERIOD

    def trajectory(self, dt: float) -> JointPath:
        """The reference sampled every ``dt`` s: the log from its first sample at time 0, then the
        run-out (module docstring); segments are labelled ``replay`` and ``run-out``.

        Raises
        ------
        faultgen.logs.columns.LogError
            If the path leaves the joint ranges or needs more than the drives' torque.
        """
        steps = round(self.duration / dt)
        times = np.arange(steps + 1) * dt
        q, qd, qdd = (CubicSpline(self.t, x, axis=0)(times) for x in (self.q, self.qd, self.qdd))
        if _at_rest(qd[0], qdd[0]):
            qd[0], qdd[0] = 0.0, 0.0
        pieces, labels = [(q, qd, qdd)], ["replay"]
        after = _run_out(self, q[-1], qd[-1], qdd[-1], dt)
        if after is None:
            qd[-1], qdd[-1] = 0.0, 0.0
        else:
            pieces.append(after)
            labels.append("run-out")
        out = {k: [pieces[0][i][:1]] for i, k in enumerate(("q", "qd", "qdd"))}
        segments, count = [], 1
        for piece, name in zip(pieces, labels, strict=True):
            for i, k in enumerate(("q", "qd", "qdd")):
                out[k].append(piece[i][1:])
            segments.append((name, count - 1, count - 1 + len(piece[0]) - 1))
            count += len(piece[0]) - 1
        q, qd, qdd = (np.concatenate(out[k]) for k in ("q", "qd", "qdd"))
        path = JointPath(np.arange(len(q)) * dt, q, qd, qdd, np.full((len(q), 3), np.nan), tuple(segments))
        where = f"{self.source} (replay)"

        def fail(segment, problem):
            raise LogError(f"{where}, {segment}: {problem}")

        low, high = self.robot.joint_range[:, 0], self.robot.joint_range[:, 1]
        bad = (q < low) | (q > high)
        if np.any(bad):
            k, axis = np.argwhere(bad)[0]
            edge = low[axis] if q[k, axis] < low[axis] else high[axis]
            part = next(name for name, a, b in segments if a <= k <= b)
            fail(part, f"axis {axis + 1} reaches {q[k, axis]:.4f} rad at t = {k * dt:.3f} s, "
                 f"{abs(q[k, axis] - edge):.4f} rad beyond its range {low[axis]:.4f}..{high[axis]:.4f} rad")
        self.check_torque(self.robot, path, lambda k: next(name for name, a, b in segments if a <= k <= b), fail)
        return path


def _at_rest(qd: np.ndarray, qdd: np.ndarray) -> bool:
    """Whether every axis is below :data:`REST_SPEED` and :data:`REST_ACCELERATION`."""
    return bool(np.all(np.abs(qd) <= REST_SPEED) and np.all(np.abs(qdd) <= REST_ACCELERATION))


def _run_out(replay: Replay, q, qd, qdd, dt: float):
    """A ruckig velocity-interface ramp from (q, qd, qdd) to rest, sampled at ``dt``; None when the
    state is at rest."""
    if _at_rest(qd, qdd):
        return None
    n = len(q)
    otg = Ruckig(n, PLAN_PERIOD)
    inp = InputParameter(n)
    inp.control_interface = ControlInterface.Velocity
    inp.current_position = q
    inp.current_velocity = qd
    inp.current_acceleration = qdd
    inp.target_velocity = inp.target_acceleration = np.zeros(n)
    inp.max_velocity = replay.velocity_limit
    inp.max_acceleration = replay.acceleration_limit
    inp.max_jerk = replay.jerk_limit
    inp.duration_discretization = DurationDiscretization.Discrete
    trajectory = Trajectory(n)
    over = np.abs(qdd) > replay.acceleration_limit
    if np.any(over):
        axis = int(np.argmax(over))
        raise LogError(f"{replay.source} (replay): the log ends moving with an "
                           f"acceleration of {qdd[axis]:.4g} rad/s^2 on axis {axis + 1}, above the planning limit "
                           f"{replay.acceleration_limit[axis]:.4g} rad/s^2 the ramp out of "
                           "it may use")
    if otg.calculate(inp, trajectory) not in (Result.Working, Result.Finished):
        raise LogError(f"{replay.source} (replay): ruckig found no ramp out of the "
                           "log's motion within the robot's planning limits")
    steps = round(trajectory.duration / dt)
    samples = [trajectory.at_time(k * dt) for k in range(steps)]
    rest = trajectory.at_time(trajectory.duration)
    pos = np.array([s[0] for s in samples] + [rest[0]]).reshape(-1, n)
    vel = np.array([s[1] for s in samples] + [np.zeros(n)]).reshape(-1, n)
    acc = np.array([s[2] for s in samples] + [np.zeros(n)]).reshape(-1, n)
    return pos, vel, acc


def read(path: str | Path, robot: Robot, limits: tuple[np.ndarray, np.ndarray, np.ndarray],
         check_torque: Callable, adapter: formats.LogFormat = formats.MEASURED) -> Replay:
    """Read a joint log to replay on ``robot`` (module docstring) by the readers of its format
    ``adapter`` (the measured format's by default: :mod:`faultgen.logs.jointlog`, no torque
    columns), streamed (:mod:`faultgen.logs.blocks`) through the format's block source; a log of
    at most a row per physics step then read whole (the format's :meth:`~faultgen.logs.formats.LogFormat.motion`,
    checked by :func:`from_columns`).

    Parameters
    ----------
    path : str or Path
        A ``.csv``, ``.csv.gz``, ``.h5`` or ``.hdf5`` log with columns ``t`` (s) and ``q1..qN`` (rad);
        with ``adapter``, a log in that format.
    robot : Robot
        Resolved by the caller (:func:`faultgen.operation.programs.load`).
    limits : tuple of three ndarray of shape (N,)
        The robot's planning limits (velocity, acceleration, jerk; rad/s, rad/s^2, rad/s^3) of the
        run-out: :func:`faultgen.operation.programs.robot_limits`.
    check_torque : callable
        ``check_torque(robot, path, segment_at, fail)`` refusing a reference above the drives'
        capacity: :func:`faultgen.operation.programs.check_torque`.
    adapter : faultgen.logs.formats.LogFormat, optional
        The log's format (default :data:`faultgen.logs.formats.MEASURED`): ``source(path, robot, motion_only=True)``
        gives its blocks of the measured format's columns (``t``, ``q1..qN`` used; the block source
        of :mod:`faultgen.logs.blocks`), ``motion(path, robot)`` the whole file's, which
        :func:`from_columns` checks.

    Raises
    ------
    faultgen.logs.columns.LogError
        A ValueError naming the file and the row or column: a missing file or column, a non-finite
        value, time that does not increase, a log that is too short, has a gap or runs longer than
        :data:`faultgen.operation.tasks.MAX_CYCLE_DURATION`, or an angle outside the joint ranges.
        What the format's reader refuses too (a ValueError naming the file).
    """
    path = Path(path)
    n_axes = robot.n_axes
    src = adapter.source(path, robot, motion_only=True)
    times = blocks.TimeScan(path, src.label, lambda first, last, rows: _check_length(path, first, last))
    scan = blocks.scan(src, robot, times, BLOCK_ROWS)
    rows = times.rows
    most = _most_rows(times, robot)  # a row per physics step
    if rows <= most:  # read whole by the format's reader, as the calibration reads it
        columns, label = adapter.motion(path, robot)
        return from_columns(columns, label, path, robot, limits, check_torque, adapter.suffixes)
    # denser than the physics step: every k-th row kept while read, once every row is checked
    times.check(MIN_DURATION, 1 / MAX_GAP)
    q_cols = [src.wanted.index(c) for c in column_names(n_axes)[0]]
    jointlog.check_angles(path, scan.kept[:, q_cols], robot, lambda i: src.label(int(scan.kept_rows[i])), 0.0)
    k = -(-rows // most)
    columns, label = blocks.thinned(src, k, BLOCK_ROWS), lambda i: src.label(i * k)
    return _replay(columns, label, path, robot, limits, check_torque, adapter.suffixes)


def from_columns(columns: dict[str, np.ndarray], label: Callable[[int], str], path: str | Path, robot: Robot,
                 limits: tuple[np.ndarray, np.ndarray, np.ndarray], check_torque: Callable,
                 suffixes: tuple[str, ...] = ()) -> Replay:
    """A log already parsed into the measured format's columns (a log format's adapter,
    :meth:`faultgen.logs.formats.LogFormat.columns`), replayed on ``robot`` with the checks and
    messages :func:`read` gives a measured log read whole: a missing column, a non-finite value,
    time not increasing, too short, a gap, too long, an angle outside the joint range; a log denser
    than one row per physics step is replayed as every ``k``-th row, as :func:`read` does.

    Parameters
    ----------
    columns : dict of str to ndarray of shape (n,)
        ``t`` (s) and ``q1..qN`` (rad) used; other columns ignored.
    label : callable
        Data row index (0-based) -> its name in messages (:func:`faultgen.logs.jointlog.index_label`).
    path : str or Path
        The file, named in messages; its name less the longest of ``suffixes`` it ends with is the
        replay's :attr:`Replay.name` (less its last suffix when none).
    robot, limits, check_torque
        As :func:`read`.

    Raises
    ------
    faultgen.logs.columns.LogError
        As :func:`read`.
    """
    path = Path(path)
    wanted, _ = jointlog.select_columns(path, list(columns), robot.n_axes, motion_only=True)
    motion = {name: np.asarray(columns[name], dtype=float) for name in wanted}
    jointlog.refuse_non_finite(path, motion, wanted, label)
    times = blocks.TimeScan(path, label, lambda first, last, rows: _check_length(path, first, last))
    if len(motion[T_COLUMN]):  # none: refused by the whole-log checks below, as read() refuses it
        times.add(0, motion[T_COLUMN])
    most = _most_rows(times, robot)
    if times.rows > most:  # denser than the physics step: every k-th row, as read() keeps of a measured log
        times.check(MIN_DURATION, 1 / MAX_GAP)
        q = np.column_stack([motion[c] for c in column_names(robot.n_axes)[0]])
        jointlog.check_angles(path, q, robot, label, 0.0)
        k = -(-times.rows // most)
        kept = {name: np.ascontiguousarray(values[::k]) for name, values in motion.items()}
        motion, label = kept, lambda i, whole=label: whole(i * k)
    return _replay(motion, label, path, robot, limits, check_torque, suffixes)


def _most_rows(times: blocks.TimeScan, robot: Robot) -> int:
    """The rows a log of these ``times`` is replayed with at most: one per physics step."""
    step = robot.model.opt.timestep
    rows = times.rows
    return int((times.last - times.first) / step + 1e-6) + 1 if rows > 1 else rows


def _replay(columns: dict[str, np.ndarray], label: Callable[[int], str], path: Path, robot: Robot, limits: tuple,
            check_torque: Callable, suffixes: tuple[str, ...]) -> Replay:
    """The :class:`Replay` of a log's ``t`` and ``q`` ``columns`` (at most a row per physics step),
    checked and differentiated (:func:`faultgen.logs.jointlog.motion`)."""
    found = jointlog.motion(columns, robot, path, label, [], min_duration=MIN_DURATION, min_rate=1 / MAX_GAP,
                            tolerance=0.0)
    t, q, (qd, qdd) = found["t"], found["q"], found["derivatives"]
    ends = [s for s in suffixes if path.name.lower().endswith(s)]
    name = path.name[: -len(max(ends, key=len))] if ends else path.stem
    velocity, acceleration, jerk = limits
    return Replay(name=name, robot_name=robot.name, process="replay", source=path, t=t - t[0],
                  q=q, qd=qd, qdd=qdd, velocity_limit=velocity, acceleration_limit=acceleration, jerk_limit=jerk,
                  start=q[0], robot=robot, check_torque=check_torque)


def _check_length(path: Path, first: float, last: float) -> None:
    """Refuse a log longer than a cycle may be, as soon as a block shows it."""
    if last - first > MAX_CYCLE_DURATION:
        raise LogError(f"{path}: the log runs longer than {MAX_CYCLE_DURATION:g} s (t = {first:.6g} .. beyond "
                       f"{last:.6g} s); a replayed log is one cycle, of at most {MAX_CYCLE_DURATION:g} s "
                       "(MAX_CYCLE_DURATION): replay a part of it")
