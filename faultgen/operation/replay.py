"""Replay a measured joint trajectory as a task: the motion a user's robot actually performed.

A log is a CSV file (``.csv`` or gzip-compressed ``.csv.gz``, a header row) or an HDF5 file (``.h5``,
``.hdf5``; one 1-D dataset per column at the root) with the columns ``t`` (s, strictly increasing)
and ``q1`` .. ``qN`` (rad, N the robot's axes); other columns are ignored, so the measured-log format
of ``faultgen calibrate`` (:mod:`faultgen.data.measured`: ``t, q, tau``, optional ``qd``) reads as
it is.

The reference (:meth:`Replay.trajectory`):

- velocity and acceleration of the log by the calibration's own estimator on the log's samples
  (:func:`faultgen.derivatives.derivatives`: Savitzky-Golay, cubic, 0.05 s window), so a replayed
  log and the same log calibrated see one motion;
- angles, velocities and accelerations each a cubic spline through the log's samples, sampled at
  the step ``dt``; the log's motion is cut to whole planning periods (the last < 4 ms dropped), so
  the path is one function of time whatever step samples it, and equals the log at its times;
- a log that does not start (end) at rest gets a run-in (run-out): a ruckig jerk-limited ramp from
  rest into the log's first state (from its last state to rest), within the robot's planning
  limits (its folder's ``tasks.toml`` ``[limits]``). At rest means every axis below
  :data:`REST_SPEED` and :data:`REST_ACCELERATION`; such an end is set exactly at rest.

Refused before any simulation (:class:`faultgen.operation.programs.ProgramError`, naming the file,
the row and the value): a missing column, a non-finite value, time not increasing, a log shorter than
:data:`MIN_DURATION` or :data:`MIN_SAMPLES`, a gap longer than :data:`MAX_GAP`, an angle outside the
joint range (by how much), and a motor torque above the drives' capacity.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from ruckig import ControlInterface, DurationDiscretization, InputParameter, Result, Ruckig, Trajectory
from scipy.interpolate import CubicSpline

from faultgen import derivatives as savgol
from faultgen import inputs
from faultgen.model import robots
from faultgen.model.robots import Robot
from faultgen.operation.programs import ProgramError, _limits, check_torque, label
from faultgen.operation.tasks import MAX_CYCLE_DURATION, MAX_CYCLE_SAMPLES, PLAN_PERIOD, JointPath

#: Shortest log replayed, s (four filter windows) and fewest samples.
MIN_DURATION = 0.2
MIN_SAMPLES = 10
#: Longest interval between samples, s (the derivative filter's window, as the measured-log reader).
MAX_GAP = 0.05
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
        Planning limits of the run-in and run-out, rad/s, rad/s^2, rad/s^3.
    start : ndarray of shape (N,)
        Where the cycle starts at rest, rad (the log's first angles, or the run-in's start).
    robot : Robot
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

    @property
    def duration(self) -> float:
        """The replayed part of the log, s: whole planning periods."""
        return np.floor(self.t[-1] / PLAN_PERIOD + 1e-9) * PLAN_PERIOD

    def run_in(self, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The ramp from rest into the log's first state, sampled at ``dt`` ((n, N) each), or None."""
        return _ramp(self, self.q[0], self.qd[0], self.qdd[0], dt, reverse=True)

    def trajectory(self, dt: float) -> JointPath:
        """The reference sampled every ``dt`` s: run-in, the log, run-out (module docstring).

        The log's first sample is at ``offset(dt)`` s into the path; segments are labelled
        ``run-in``, ``replay`` and ``run-out``.

        Raises
        ------
        ProgramError
            If the path leaves the joint ranges or needs more than the drives' torque.
        """
        steps = round(self.duration / dt)
        times = np.arange(steps + 1) * dt
        q, qd, qdd = (CubicSpline(self.t, x, axis=0)(times) for x in (self.q, self.qd, self.qdd))
        pieces, labels = [], []
        before = self.run_in(dt)
        if before is None:
            qd[0], qdd[0] = 0.0, 0.0
        else:
            pieces.append(before)
            labels.append("run-in")
        pieces.append((q, qd, qdd))
        labels.append("replay")
        after = _ramp(self, q[-1], qd[-1], qdd[-1], dt, reverse=False)
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
            raise ProgramError(f"{where}, {segment}: {problem}")

        low, high = self.robot.joint_range[:, 0], self.robot.joint_range[:, 1]
        bad = (q < low) | (q > high)
        if np.any(bad):
            k, axis = np.argwhere(bad)[0]
            edge = low[axis] if q[k, axis] < low[axis] else high[axis]
            part = next(name for name, a, b in segments if a <= k <= b)
            fail(part, f"axis {axis + 1} reaches {q[k, axis]:.4f} rad at t = {k * dt:.3f} s, "
                 f"{abs(q[k, axis] - edge):.4f} rad beyond its range {low[axis]:.4f}..{high[axis]:.4f} rad")
        check_torque(self.robot, path, lambda k: next(name for name, a, b in segments if a <= k <= b), fail)
        return path

    def offset(self, dt: float) -> float:
        """Time in the path of the log's first sample, s (the run-in's length)."""
        before = self.run_in(dt)
        return 0.0 if before is None else (len(before[0]) - 1) * dt


def _ramp(replay: Replay, q, qd, qdd, dt: float, reverse: bool):
    """A ruckig velocity-interface ramp from (q, qd, qdd) to rest, sampled at ``dt``; reversed in time
    (a ramp from rest into the state) when ``reverse``. None when the state is at rest."""
    if np.all(np.abs(qd) <= REST_SPEED) and np.all(np.abs(qdd) <= REST_ACCELERATION):
        return None
    n = len(q)
    otg = Ruckig(n, PLAN_PERIOD)
    inp = InputParameter(n)
    inp.control_interface = ControlInterface.Velocity
    inp.current_position = q
    inp.current_velocity = -qd if reverse else qd
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
        raise ProgramError(f"{replay.source} (replay): the log {'starts' if reverse else 'ends'} moving with an "
                           f"acceleration of {qdd[axis]:.4g} rad/s^2 on axis {axis + 1}, above the planning limit "
                           f"{replay.acceleration_limit[axis]:.4g} rad/s^2 the ramp {'into' if reverse else 'out of'} "
                           "it may use")
    if otg.calculate(inp, trajectory) not in (Result.Working, Result.Finished):
        raise ProgramError(f"{replay.source} (replay): ruckig found no ramp {'into' if reverse else 'out of'} the "
                           "log's motion within the robot's planning limits")
    steps = round(trajectory.duration / dt)
    samples = [trajectory.at_time(k * dt) for k in range(steps)]
    rest = trajectory.at_time(trajectory.duration)
    pos = np.array([s[0] for s in samples] + [rest[0]]).reshape(-1, n)
    vel = np.array([s[1] for s in samples] + [np.zeros(n)]).reshape(-1, n)
    acc = np.array([s[2] for s in samples] + [np.zeros(n)]).reshape(-1, n)
    if reverse:  # time runs backwards: angles in reverse order, velocities change sign
        return pos[::-1].copy(), -vel[::-1], acc[::-1].copy()
    return pos, vel, acc


def read(path: str | Path, robot: Robot | str) -> Replay:
    """Read a joint log to replay on ``robot`` (module docstring).

    Raises
    ------
    ProgramError
        For a missing file or column, a non-finite value, time that does not increase, a log that is
        too short or has a gap, or an angle outside the joint ranges; the message names the row.
    """
    if not isinstance(robot, Robot):
        robot = robots.load(robot)
    path = Path(path)
    try:
        inputs.regular_file(path, "joint log")
    except inputs.InputError as err:
        raise ProgramError(str(err)) from None
    n_axes = len(robot.joint_names)
    wanted = ["t", *(f"q{i}" for i in range(1, n_axes + 1))]
    columns = _read_columns(path, wanted)
    t, q = columns[:, 0], columns[:, 1:]
    if len(t) == 0:
        raise ProgramError(f"{path}: the log has a header but no data rows; expected at least {MIN_SAMPLES} samples "
                           f"over {MIN_DURATION} s")
    bad = np.argwhere(~np.isfinite(columns))
    if bad.size:
        row, col = bad[0]
        raise ProgramError(f"{path}: {wanted[col]} at data row {row + 1} is {columns[row, col]!r}; expected a number")
    if len(t) < MIN_SAMPLES or t[-1] - t[0] < MIN_DURATION:  # a header-only log: 0 samples over 0 s
        raise ProgramError(f"{path}: the log is too short: {len(t)} samples over {t[-1] - t[0]:.4g} s; expected at "
                           f"least {MIN_SAMPLES} samples over {MIN_DURATION} s")
    dt = np.diff(t)
    if np.any(dt <= 0):
        row = int(np.argmax(dt <= 0)) + 1
        raise ProgramError(f"{path}: t does not increase at data row {row + 1} (t = {t[row]!r} s after {t[row - 1]!r} "
                           "s); expected strictly increasing times")
    if dt.max() > MAX_GAP * (1 + 1e-9):
        row = int(np.argmax(dt)) + 1
        raise ProgramError(f"{path}: t jumps by {dt.max():.4g} s before data row {row + 1}; expected no interval "
                           f"longer than {MAX_GAP} s")
    low, high = robot.joint_range[:, 0], robot.joint_range[:, 1]
    bad = np.argwhere((q < low) | (q > high))
    if bad.size:
        row, axis = bad[0]
        edge = low[axis] if q[row, axis] < low[axis] else high[axis]
        raise ProgramError(f"{path}: q{axis + 1} at data row {row + 1} (t = {t[row]:.4f} s) is {q[row, axis]:.4f} rad, "
                           f"{abs(q[row, axis] - edge):.4f} rad outside the joint range {low[axis]:.4f}.."
                           f"{high[axis]:.4f} rad of axis {axis + 1} of {robot.name}")
    period = float(np.median(dt))
    qd, qdd = savgol.derivatives(t, q, period, savgol.savgol_window(period, len(t)), savgol.is_uniform(dt, period))
    velocity, acceleration, jerk = _limits({}, robot, str(path))
    replay = Replay(name=label(str(path)), robot_name=robot.name, process="replay", source=path, t=t - t[0], q=q,
                    qd=qd, qdd=qdd, velocity_limit=velocity, acceleration_limit=acceleration, jerk_limit=jerk,
                    start=q[0], robot=robot)
    before = replay.run_in(PLAN_PERIOD)
    if before is not None:
        object.__setattr__(replay, "start", before[0][0])
    return replay


def _read_columns(path: Path, wanted: list[str]) -> np.ndarray:
    """The ``wanted`` columns of a CSV (gzip or not, by content) or HDF5 log, shape (n, len(wanted)),
    read in blocks of :data:`BLOCK_ROWS` and refused (the limit named) as soon as it runs longer than
    a cycle may (:func:`faultgen.operation.tasks.check_cycle_length` at the finest step): memory is
    bounded whatever the file's length. HDF5 links and virtual datasets that reach other files are
    refused (:mod:`faultgen.inputs`)."""
    try:
        if path.name.lower().endswith((".h5", ".hdf5")):
            return _read_hdf5(path, wanted)
        return _read_csv(path, wanted)
    except inputs.InputError as err:
        raise ProgramError(str(err)) from None


#: Rows read at a time, and most rows a replayed log may have (a cycle of at most an hour at 1 kHz...
#: MAX_CYCLE_SAMPLES at the finest step).
BLOCK_ROWS = 500_000


def _check_length(path: Path, t: np.ndarray, rows: int) -> None:
    if rows > MAX_CYCLE_SAMPLES:
        raise ProgramError(f"{path}: more than {MAX_CYCLE_SAMPLES} rows; a replayed log is one cycle, of at most "
                           f"{MAX_CYCLE_SAMPLES} samples (MAX_CYCLE_SAMPLES): replay a part of it")
    if len(t) and np.all(np.isfinite(t[[0, -1]])) and t[-1] - t[0] > MAX_CYCLE_DURATION:
        raise ProgramError(f"{path}: the log runs longer than {MAX_CYCLE_DURATION:g} s (t = {t[0]:.6g} .. beyond "
                           f"{t[-1]:.6g} s); a replayed log is one cycle, of at most {MAX_CYCLE_DURATION:g} s "
                           "(MAX_CYCLE_DURATION): replay a part of it")


def _read_hdf5(path: Path, wanted: list[str]) -> np.ndarray:
    with inputs.open_hdf5(path, "joint log") as f:
        missing = [c for c in wanted if c not in f]
        if missing:
            raise ProgramError(f"{path}: no dataset {missing[0]!r} at the file root; a joint log needs "
                               f"{', '.join(wanted)}")
        columns = [inputs.bounded_dataset(f, c, path, (None,), kinds="fiu") for c in wanted]
        lengths = {ds.shape[0] for ds in columns}
        if len(lengths) > 1:
            raise ProgramError(f"{path}: datasets {', '.join(wanted)} have different lengths "
                               f"({', '.join(str(ds.shape[0]) for ds in columns)}); one row per sample is expected")
        n = lengths.pop()
        if n:
            _check_length(path, np.array([columns[0][0], columns[0][n - 1]], dtype=float), n)
        return np.column_stack([np.asarray(ds[()], dtype=float) for ds in columns]) if n else np.empty((0, len(wanted)))


def _read_csv(path: Path, wanted: list[str]) -> np.ndarray:
    blocks, rows = [], 0
    with inputs.open_text(path, "joint log") as f:
        try:
            reader = pd.read_csv(f, skipinitialspace=True, chunksize=BLOCK_ROWS)
            for table in reader:
                table.columns = [str(c).strip() for c in table.columns]
                missing = [c for c in wanted if c not in table.columns]
                if missing:
                    raise ProgramError(f"{path}: no column {missing[0]!r}; a joint log needs {', '.join(wanted)} "
                                       f"(rad), got {', '.join(table.columns)}")
                try:
                    block = table[wanted].to_numpy(dtype=float)
                except ValueError as err:
                    raise ProgramError(f"{path}: a value in columns {', '.join(wanted)} is not a number ({err})") \
                        from None
                if not len(block):
                    continue
                blocks.append(block)
                rows += len(block)
                _check_length(path, np.array([blocks[0][0, 0], block[-1, 0]]), rows)
        except (ValueError, OSError, pd.errors.ParserError) as err:
            if isinstance(err, (ProgramError, inputs.InputError)):
                raise
            raise ProgramError(f"{path}: not a CSV file with a header row ({err})") from err
    return np.concatenate(blocks) if blocks else np.empty((0, len(wanted)))
