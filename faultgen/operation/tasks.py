"""What a task is: the cycle a robot repeats, as a time-parameterised arm-side joint path.

A task is anything that satisfies :class:`Task`: a program (:class:`faultgen.operation.programs.
Program`, read from a program file or from a section of a robot folder's ``tasks.toml``) or a
replayed joint log (:class:`faultgen.operation.replay.Replay`). :meth:`Task.trajectory` gives a
:class:`JointPath`; :func:`faultgen.operation.programs.load` gives the task a name or file stands for.

The built-in tasks are programs: thesis ch. 6.3.1 simulates three, task 1 a pick and place moving
each axis over a large part of its range, task 2 a discontinuous process with many stops at maximum
acceleration (spot welding), task 3 a continuous process (arc welding). Each robot folder's
``tasks.toml`` holds them as program tables ``[pick_place]``, ``[spot_weld]``, ``[arc_weld]``
beside the robot's planning ``[limits]``; they plan as any program does:

- point-to-point moves: ruckig (:func:`ptp`: jerk-limited, time-optimal, rest to rest, all axes
  finishing together, duration a whole number of planning periods, :data:`PLAN_PERIOD`);
- weld points and seam: flange IK with mink on an arm-only model (:mod:`faultgen.operation.ik`);
- the seam: IK every :data:`IK_STEP` along the tool path, a clamped cubic spline through the
  solutions sampled at dt, its derivatives giving qd and qdd.

Every cycle starts and ends at the task's ``start`` angles at rest, so cycles repeat. Every
segment lasts whole planning periods, so the path is one continuous function of time, whatever
step ``dt`` samples it (the physics step or the 4 ms log period): a finer physics step refines
the simulation of the same cycle, not a different cycle (docs/simulation.md, "Numerical
convergence").
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from dataclasses import dataclass
from itertools import chain
from pathlib import Path
from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np
from ruckig import DurationDiscretization, InputParameter, Result, Ruckig, Trajectory

from faultgen import inputs
from faultgen.logs import columns as log_columns

if TYPE_CHECKING:
    from faultgen.model.robots import Robot

#: The built-in tasks of thesis ch. 6.3.1 (the ``tasks.toml`` tables every robot folder has), and
#: the process each is (its ``process`` key).
TASKS = ("pick_place", "spot_weld", "arc_weld")
PROCESSES = {"pick_place": "point-to-point", "spot_weld": "discontinuous", "arc_weld": "continuous"}
IK_STEP = 0.01  # s: knot step of the seam IK; the spline interpolates in between
#: s: every move, dwell and seam lasts a whole number of these (the thesis's 4 ms sampling period,
#: ch. 6.3.2), so a path sampled at any step that divides it is the same path.
PLAN_PERIOD = 0.004
#: Longest cycle a task, program or replayed log may make, s, and most samples of its path: checked
#: before a piece of path is allocated (a ``dwell time = 1e9`` asked for 87 TiB, a program of 10^4
#: moves took 5.4 GB). An hour is far beyond an industrial cycle (seconds to minutes).
MAX_CYCLE_DURATION = 3600.0
MAX_CYCLE_SAMPLES = 7_200_000  # an hour at the finest step, 0.5 ms
SAMPLE_BLOCK = 4096  # samples of a ruckig move converted to arrays at a time (ptp)
SEAM_TOLERANCE = 5e-4  # m: largest allowed flange distance from the commanded seam point
SEAM_LIMIT_TOLERANCE = 0.01  # relative excess over a velocity/acceleration limit allowed on the seam
LIMIT_TOLERANCE = 1e-9  # relative (velocity, acceleration) and rad (position) elsewhere


class ProgramError(ValueError):
    """A task (a program or a replayed log) cannot run; the message names the file, the segment and
    the value."""


@dataclass(frozen=True)
class Load:
    """A payload carried from sample ``first`` to sample ``last`` of a path (inclusive), with the
    :class:`faultgen.effects.payload.Payload` parameters ``params``; ``segment`` names the grip."""

    first: int
    last: int
    params: dict
    segment: str


@dataclass(frozen=True, eq=False)
class JointPath:
    """One task cycle as arm-side joint samples at a constant time step.

    Attributes
    ----------
    t : ndarray of shape (n,)
        Time in s, ``k * dt`` from 0.
    q, qd, qdd : ndarray of shape (n, N)
        Arm joint angles (rad), velocities (rad/s) and accelerations (rad/s^2), N the robot's axes.
        A program's last sample equals its first: same angles, zero velocity and acceleration.
    target : ndarray of shape (n, 3)
        Commanded flange position in m, world frame, where the task defines one (weld points
        during their dwell, the seam); NaN elsewhere.
    segments : tuple of (str, int, int)
        ``(label, first, last)``: consecutive parts of the cycle as inclusive sample indices
        (neighbours share their boundary sample), labelled as the program's segments are (the
        thesis tasks: ``move``, ``dwell``, ``weld``, ``approach``, ``seam``, ``retract``).
    loads : tuple of Load
        Payloads the task grips and releases within the cycle (sample ranges and parameters).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    target: np.ndarray
    segments: tuple[tuple[str, int, int], ...]
    loads: tuple[Load, ...] = ()

    @property
    def duration(self) -> float:
        """Cycle duration in s."""
        return float(self.t[-1])


@runtime_checkable
class Task(Protocol):
    """What the simulation needs of a task: programs and replayed logs both are one.

    Attributes
    ----------
    name : str
        What the task is called (a program's ``name``, a log's file stem).
    robot_name : str
    process : str
        What kind of work it is (a program's ``process``; ``"replay"`` for a log).
    source : Path or None
        The file it was read from (None for a program read from text).
    start : ndarray of shape (N,)
        Arm angles in rad where the cycle starts.
    velocity_limit, acceleration_limit, jerk_limit : ndarray of shape (N,)
        Joint limits it is planned to, rad/s, rad/s^2, rad/s^3 (the speed features' design maximum
        is ``velocity_limit``).
    robot : faultgen.model.robots.Robot
        The robot it runs on.

    Methods
    -------
    trajectory(dt) -> JointPath
        The cycle sampled every ``dt`` s (a step dividing :data:`PLAN_PERIOD`), checked against the
        robot's limits; the payloads it carries are the path's :attr:`JointPath.loads`. Raises
        ValueError naming what cannot run.
    """

    name: str
    robot_name: str
    process: str
    source: Path | None
    start: np.ndarray
    velocity_limit: np.ndarray
    acceleration_limit: np.ndarray
    jerk_limit: np.ndarray
    robot: Robot

    def trajectory(self, dt: float) -> JointPath: ...


@dataclass(frozen=True)
class LogTask:
    """A joint log to replay that is read through a registered log format
    (:mod:`faultgen.logs.formats`; ``faultgen simulate --task LOG --format NAME``) instead of the
    measured format, whose log stays a plain path. It stands where a task name does
    (:func:`faultgen.operation.programs.load` replays it): ``str()`` and ``os.fspath()`` give the
    path as given; hashable, so the task's cached preparations are keyed by path and format.

    Attributes
    ----------
    path : str
        The log file, as given.
    adapter : object
        The format's adapter (a :class:`faultgen.logs.formats.LogFormat`; this layer only calls its
        ``columns(path, robot)``, reads its ``name``, ``suffixes`` and dataclass fields).
    """

    path: str
    adapter: object

    def __str__(self) -> str:
        return self.path

    def __fspath__(self) -> str:
        return self.path

    @property
    def stem(self) -> str:
        """The file's name less the format's longest suffix it ends with (less its last suffix when
        it ends with none)."""
        name = Path(self.path).name
        ends = [s for s in self.adapter.suffixes if name.lower().endswith(s)]
        return name[: -len(max(ends, key=len))] if ends else Path(name).stem

    def log_format(self) -> dict:
        """The format as a dataset records it: ``name`` and the adapter's options (its dataclass
        fields but ``suffixes``; tuples as lists)."""
        fields = dataclasses.fields(self.adapter) if dataclasses.is_dataclass(self.adapter) else ()
        options = {f.name: getattr(self.adapter, f.name) for f in fields if f.name != "suffixes"}
        return {"name": self.adapter.name,
                **{k: list(v) if isinstance(v, tuple) else v for k, v in options.items()}}


class Motion:
    """A joint motion to replay, given in memory rather than as a log file: the twin's smoothed
    program cycle (:mod:`faultgen.monitor.twin`). It stands where a joint log's path does;
    :func:`faultgen.operation.programs.load` replays it
    (:meth:`faultgen.operation.replay.Replay.from_motion`) with the checks and messages of a log
    read whole. Equal, and hashed, by its name and the SHA-256 of its samples (:attr:`sha256`), so
    the cached preparations of a run are keyed by content; pickles with its samples.

    Parameters
    ----------
    name : str
        What it is called (run ids, progress bars, the replay's :attr:`~faultgen.operation.replay.Replay.name`).
    t : array_like of shape (n,)
        Sample times, s.
    q : array_like of shape (n, N)
        Arm angles, rad.
    source : str, optional
        What messages name as its origin (e.g. the log it was derived from); ``name`` by default.

    Raises
    ------
    ValueError
        An empty name, or ``t`` and ``q`` not of shapes (n,) and (n, N) (the shapes named).
    """

    __slots__ = ("name", "t", "q", "source", "sha256")

    def __init__(self, name: str, t, q, source: str = "") -> None:
        t, q = np.array(t, dtype=float), np.array(q, dtype=float)
        if not isinstance(name, str) or not name:
            raise ValueError(f"Motion name {name!r}: expected a non-empty string")
        if t.ndim != 1 or q.ndim != 2 or len(q) != len(t):
            raise ValueError(f"Motion {name!r}: expected t of shape (n,) and q of shape (n, N), got {t.shape} and {q.shape}")
        t.setflags(write=False)
        q.setflags(write=False)
        digest = hashlib.sha256(repr(q.shape).encode() + t.tobytes() + q.tobytes()).hexdigest()
        for key, value in zip(self.__slots__, (name, t, q, source or name, digest), strict=True):
            object.__setattr__(self, key, value)

    def __setattr__(self, key, value):
        raise AttributeError(f"Motion is read-only ({key})")

    def __reduce__(self):
        return Motion, (self.name, self.t, self.q, self.source)

    def __eq__(self, other) -> bool:
        return isinstance(other, Motion) and (self.name, self.sha256) == (other.name, other.sha256)

    def __hash__(self) -> int:
        return hash((self.name, self.sha256))

    def __str__(self) -> str:
        return self.name

    def __repr__(self) -> str:
        return f"Motion({self.name!r}, {len(self.t)} samples x {self.q.shape[1]} axes, sha256 {self.sha256[:12]})"


class TextProgram(str):
    """A program file given by its text rather than a path (a fleet's friction test travels
    in its runs' configuration, so that two machines or two caches make the same runs). It stands
    where a program file's path does: ``str()`` is its name, ``<stem>-<SHA-256 of the text, 12 hex>.toml``
    (a name, not a file: the digest in it makes equal names equal texts), ``text`` the TOML;
    :func:`faultgen.operation.programs.load` parses the text and
    :func:`faultgen.operation.programs.record` keeps it, as for a file. Pickles with its text (to a
    worker process or a cluster's worker)."""

    text: str

    def __new__(cls, stem: str, text: str, *, named: bool = False) -> "TextProgram":
        if not isinstance(text, str) or not isinstance(stem, str) or not stem:
            raise ValueError(f"TextProgram({stem!r}, ...): expected a non-empty name and the program's TOML text")
        name = stem if named else f"{stem}-{hashlib.sha256(text.encode()).hexdigest()[:12]}.toml"
        self = super().__new__(cls, name)
        self.text = text
        return self

    def __getnewargs_ex__(self):
        return (str(self), self.text), {"named": True}


#: File suffixes read as programs; the rest of :data:`REPLAY_SUFFIXES` are replayed joint logs.
PROGRAM_SUFFIXES = (".toml",)
REPLAY_SUFFIXES = (".csv", ".csv.gz", ".h5", ".hdf5")


#: The kinds of task (:func:`kind`): a thesis task of the robot folder's ``tasks.toml``, a program
#: file, a program's text (:class:`TextProgram`), a joint log file in the measured format, a joint
#: log in another format (:class:`LogTask`), a motion in memory (:class:`Motion`).
THESIS, PROGRAM, TEXT, LOG, FORMAT_LOG, MOTION = "thesis", "program", "text", "log", "format-log", "motion"
#: The kinds that are programs (planned from TOML), and those that name a file of this machine.
PROGRAM_KINDS, FILE_KINDS = (PROGRAM, TEXT), (PROGRAM, LOG, FORMAT_LOG)


def kind(task) -> str | None:
    """What ``task`` is, one of the kinds above (None: none of them, an unknown name): decided here
    and nowhere else, by its type and then a file name's suffix (:data:`PROGRAM_SUFFIXES`,
    :data:`REPLAY_SUFFIXES`). Looks at no file."""
    if isinstance(task, Motion):
        return MOTION
    if isinstance(task, LogTask):
        return FORMAT_LOG
    if isinstance(task, TextProgram):
        return TEXT
    if not isinstance(task, str) or not task:
        return None
    if task in TASKS:
        return THESIS
    name = task.lower()
    return PROGRAM if name.endswith(PROGRAM_SUFFIXES) else LOG if name.endswith(REPLAY_SUFFIXES) else None


def check_file(task: str) -> str:
    """``task`` (a program file or joint log) if it names a regular file, looked at without opening
    it; ValueError saying that it does not exist, or what it is instead (a FIFO, a link to a device
    such as ``/dev/zero``, a folder: :func:`faultgen.inputs.regular_file`)."""
    if not (Path(task).exists() or Path(task).is_symlink()):
        raise ValueError(f"task file {str(task)!r} does not exist")
    inputs.regular_file(task, "task file")
    return task


def file_bytes(task: str) -> bytes | None:
    """A program file's bytes, read through :mod:`faultgen.inputs` (a regular file of at most
    :data:`faultgen.inputs.TOML_MAX_BYTES`, its size checked before the read); None for a joint
    log (hashed in blocks: :func:`file_sha256`). InputError naming the file otherwise."""
    if kind(task) != PROGRAM:
        return None
    return inputs.read_bytes(task, "program file", inputs.TOML_MAX_BYTES)


def file_sha256(task: str) -> str:
    """SHA-256 (hex) of a file task's bytes: a program file's (:func:`file_bytes`) or a joint log's,
    read in blocks up to :data:`faultgen.logs.columns.LOG_MAX_BYTES`, its size checked first (a
    sparse file of 20 GiB apparent was read whole: a MemoryError). InputError naming the file."""
    data = file_bytes(task)
    if data is not None:
        return hashlib.sha256(data).hexdigest()
    return inputs.sha256_of(str(task), "joint log", log_columns.LOG_MAX_BYTES)


def check_step(dt) -> float:
    """``dt`` as a float if it is a positive step in s that divides :data:`PLAN_PERIOD` into whole
    steps (e.g. 0.004, 0.002, 0.001, 0.0005), else ValueError saying so."""
    if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a positive number of seconds, got {dt!r}")
    if abs(PLAN_PERIOD / dt - round(PLAN_PERIOD / dt)) > 1e-9:
        raise ValueError(f"dt = {dt!r} s does not divide the {PLAN_PERIOD * 1e3:g} ms planning period into whole "
                         "steps; expected e.g. 0.004, 0.002, 0.001 or 0.0005")
    return float(dt)


def ptp(q_from: np.ndarray, q_to: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray, jerk: np.ndarray,
        dt: float, where: str, elapsed: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
    elapsed : float
        Duration of the path before the move, s: the cycle, this move included, is checked against
        :data:`MAX_CYCLE_DURATION` and :data:`MAX_CYCLE_SAMPLES` (:func:`check_cycle_length`) from the
        move's planned duration, before it is sampled.

    Returns
    -------
    q, qd, qdd : ndarray of shape (n, N)
        From ``q_from`` to ``q_to`` inclusive; the first and last samples at rest.

    Raises
    ------
    ValueError
        If ruckig finds no move; :class:`CycleTooLong` if the cycle would be too long with it.
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
    try:
        result = otg.calculate(inp, trajectory)
    except ValueError:  # a code its Python enum lacks, e.g. -101: the duration beyond ruckig's numbers
        result = None
    if result not in (Result.Working, Result.Finished):
        raise ValueError(f"{where}: ruckig found no move to {np.round(q_to, 4)} within the limits (velocity "
                         f"{np.round(np.rad2deg(velocity), 4)} deg/s, acceleration {np.round(np.rad2deg(acceleration), 4)} "
                         f"deg/s^2, jerk {np.round(np.rad2deg(jerk), 4)} deg/s^3)")
    check_cycle_length(elapsed + trajectory.duration, dt, where)
    steps = round(trajectory.duration / dt)
    q, qd, qdd = np.empty((steps + 1, n)), np.zeros((steps + 1, n)), np.zeros((steps + 1, n))
    # into the arrays a block of samples at a time (a list of ruckig's samples took 15 times their
    # memory; one row assignment per sample cost twice ruckig's own evaluation)
    at_time = trajectory.at_time
    for first in range(0, steps, SAMPLE_BLOCK):
        last = min(first + SAMPLE_BLOCK, steps)
        values = chain.from_iterable(chain.from_iterable(at_time(k * dt) for k in range(first, last)))
        block = np.fromiter(values, dtype=float, count=(last - first) * 3 * n).reshape(last - first, 3, n)
        q[first:last], qd[first:last], qdd[first:last] = block[:, 0], block[:, 1], block[:, 2]
    q[steps] = q_to
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


class PathBuilder:
    """Collects the pieces of a path sampled every ``dt`` s from the angles ``q0`` at rest; each piece
    starts at the previous piece's last sample (:meth:`add`, :meth:`hold`); :meth:`build` joins them."""

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

    def build(self, loads: tuple[Load, ...] = ()) -> JointPath:
        q = np.concatenate(self.q)
        return JointPath(
            t=np.arange(len(q)) * self.dt,
            q=q,
            qd=np.concatenate(self.qd),
            qdd=np.concatenate(self.qdd),
            target=np.concatenate(self.target),
            segments=tuple(self.segments),
            loads=loads,
        )
