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
go through flange IK every :data:`~faultgen.operation.tasks.IK_STEP` and a spline
(:class:`faultgen.operation.ik.FlangeIK`); the segments are planned by
:class:`faultgen.operation.planner.Planner`.

The built-in tasks are programs too: each table of a robot folder's ``tasks.toml`` but ``[limits]``
(the thesis tasks ``[pick_place]``, ``[spot_weld]``, ``[arc_weld]``) holds a program's keys less its
name (the table's), robot (the folder's) and limits (the file's), and :func:`builtin` reads it
through the same reader as a file; :func:`export` writes it as a program file. :func:`load` gives
the :class:`~faultgen.operation.tasks.Task` a task name or file stands for.

Before any simulation :meth:`Program.trajectory` refuses, naming the segment and the value: an
unknown key, a Cartesian target out of reach (with the distance to the nearest reachable point), a
joint angle, speed or acceleration limit exceeded (and by how much), a seam or line leaving the
flange more than :data:`faultgen.operation.tasks.SEAM_TOLERANCE` from its path, and a motor torque
above the drives' capacity (peak motor torque times gear ratio, the payload included).

Generic in the number of axes: N is the robot model's (``len(robot.joint_names)``).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from faultgen import inputs
from faultgen.model import robots
from faultgen.model.robots import Robot
from faultgen.operation.ik import tool_rotation

# re-exported: the names callers (replay, the simulation's preparation) know programs by
from faultgen.operation.planner import GRIP_BODY, TORQUE_CAPACITY, Planner, Segment, add_part, check_torque  # noqa: F401
from faultgen.operation.program_format import (
    BUILTIN_KEYS, LIMIT_BOUNDS, LIMIT_KEYS, MAX_SEGMENTS, PROGRAM_PROCESSES, SEGMENT_KEYS, TOOL_KEYS, TOP_KEYS, dumps,
)
from faultgen.operation.tables import Table
from faultgen.operation.tasks import (  # noqa: F401
    PLAN_PERIOD,
    PROCESSES,
    TASKS,
    JointPath,
    Load,
    FILE_KINDS,
    FORMAT_LOG,
    LOG,
    MOTION,
    PROGRAM,
    PROGRAM_KINDS,
    PROGRAM_SUFFIXES,
    REPLAY_SUFFIXES,
    TEXT,
    THESIS,
    LogTask,
    Motion,
    check_file, file_bytes, file_sha256,  # a file task read through faultgen.inputs, bounded
    ProgramError,
    Task,
    TextProgram,
    check_step,
    kind,
)

if TYPE_CHECKING:
    from faultgen.logs import formats


class ProgramBoundError(ProgramError, inputs.InputError):
    """A program refused before it is checked or planned, by a bound on its size (:data:`MAX_SEGMENTS`):
    a :class:`ProgramError` and a :class:`faultgen.inputs.InputError`."""


def is_file_task(task: str | LogTask) -> bool:
    """Whether ``task`` is a program or log (a file's, or a program's text) rather than a thesis
    task or a motion in memory (:func:`kind`)."""
    return kind(task) in (*PROGRAM_KINDS, LOG, FORMAT_LOG)


def is_given_task(task) -> bool:
    """Whether ``task`` is one the user gave (a program or log file, a program's text, a motion in
    memory) rather than a thesis task: its path is planned and checked when a run is configured."""
    return kind(task) not in (THESIS, None)


def log_task(task: str, adapter: formats.LogFormat) -> str | LogTask:
    """The task ``task`` with its log read through the log format ``adapter`` (a
    :class:`faultgen.logs.formats.LogFormat`): a :class:`LogTask`; ``task`` itself in
    the registry's default format (:data:`faultgen.logs.formats.DEFAULT`: a measured log, a program
    or a thesis task, recorded as named). ValueError when another format is given with a thesis task
    or a program file (a format reads a joint log)."""
    from faultgen.logs import formats  # the log reader (pandas, scipy.signal): for a log task only

    if adapter.name == formats.DEFAULT:
        return task
    if kind(task) in (THESIS, *PROGRAM_KINDS):
        what = "a thesis task" if kind(task) == THESIS else "a program file"
        raise ValueError(f"log format {adapter.name} reads a joint log to replay; task {str(task)!r} is {what} "
                         "(a format other than measured is for a log only)")
    return LogTask(str(task), adapter)


def check_name(task: str) -> str:
    """``task`` if it is a thesis task name or an existing program / log file, else ValueError naming
    it and what is expected."""
    found = kind(task)
    if found is None and (not isinstance(task, str) or not task):
        raise ValueError(f"task {task!r}: expected a task name ({', '.join(TASKS)}) or a program file (.toml) "
                         "or joint log (.csv, .h5)")
    if found in FILE_KINDS:
        return check_file(task)  # missing, or what it is instead (a FIFO, a link to /dev/zero)
    if found is not None:  # a thesis task, a program's text or a motion in memory: no file to look for
        return task
    raise ValueError(f"unknown task {task!r}; expected one of: {', '.join(TASKS)}, or a program file (.toml) "
                     "or a joint log (.csv, .h5) to replay")


def label(task: str) -> str:
    """A short name for ``task`` in run ids and progress bars: the thesis name, or the file's stem
    (a :class:`Motion`'s name)."""
    found = kind(task)
    if found == MOTION:
        return task.name
    if found in (THESIS, None):
        return task
    if found == FORMAT_LOG:
        return task.stem
    name = Path(task).name
    for suffix in sorted(PROGRAM_SUFFIXES + REPLAY_SUFFIXES, key=len, reverse=True):
        if name.lower().endswith(suffix):
            return name[: -len(suffix)]
    return name


def load(robot: Robot, task: str) -> Task:
    """The task ``task`` of ``robot``: a thesis task by name (a program from the robot folder's
    ``tasks.toml``, :func:`builtin`), a program file (``.toml``, :func:`read`) or a joint log to replay
    (``.csv``, ``.csv.gz``, ``.h5``, or a :class:`LogTask` in another format;
    :func:`faultgen.operation.replay.read`).

    Returns
    -------
    faultgen.operation.tasks.Task
        A :class:`Program` or a :class:`~faultgen.operation.replay.Replay`.

    Raises
    ------
    TypeError
        If ``robot`` is not a :class:`Robot` (a name is resolved once, at the boundary:
        :func:`faultgen.model.robots.load`).
    ValueError
        For an unknown task or a file that cannot run on ``robot`` (:class:`ProgramError`).
    """
    robots.require(robot, "programs.load")
    check_name(task)
    found = kind(task)
    if found == THESIS:
        return builtin(robot, task)
    if found == TEXT:
        return parse(task.text, robot, where=f"program {task}")
    if found == PROGRAM:
        return read(task, robot)
    # only a replayed log needs the log reader (pandas, h5py, scipy.signal: about 1 s to import,
    # which a thesis task or program would spend before its first physics step for nothing)
    from faultgen.logs import formats
    from faultgen.operation import replay

    if found == MOTION:
        return replay.Replay.from_motion(task, robot, _limits({}, robot, task.source), check_torque)
    adapter = task.adapter if found == FORMAT_LOG else formats.MEASURED
    return replay.read(str(task), robot, _limits({}, robot, str(task)), check_torque, adapter=adapter)


def record(task: str) -> dict | None:
    """What a dataset keeps of a file task so the run can be made again: ``name`` (the program's, or
    the log's stem), ``file`` (as given), ``sha256`` of the file's bytes, for a program its ``text``
    and for a :class:`LogTask` its ``format`` (:meth:`LogTask.log_format`); for a :class:`Motion`
    its ``name``, ``source`` and :attr:`Motion.sha256`; None for a thesis task."""
    found = kind(task)
    if found == MOTION:
        return {"name": task.name, "source": task.source, "sha256": task.sha256}
    if found in (THESIS, None):
        return None
    data = task.text.encode() if found == TEXT else file_bytes(task)  # bounded, size first; None: a log
    digest = hashlib.sha256(data).hexdigest() if data is not None else file_sha256(task)
    out = {"file": str(task), "sha256": digest}
    if found in PROGRAM_KINDS:
        text = data.decode()
        try:
            out["name"] = str(inputs.loads_toml(text, task, "program file").get("name", label(task)))
        except inputs.InputError:
            out["name"] = label(task)
        out["text"] = text
    else:
        out["name"] = label(task)
    if found == FORMAT_LOG:
        out["format"] = task.log_format()
    return out


def identity(robot: Robot, task: str) -> tuple[str, str]:
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
            With ``loads``: the payload carried over sample ranges
            (:class:`~faultgen.operation.tasks.Load`).

        Raises
        ------
        ProgramError
            Naming the segment and the value (module docstring).
        """
        return Planner(self, check_step(dt)).run()


# -- reading -------------------------------------------------------------------------------------


def read(path: str | Path, robot: Robot) -> Program:
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


def parse(text: str, robot: Robot, source: Path | None = None, where: str | None = None) -> Program:
    """A :class:`Program` from TOML ``text`` (see :func:`read`); ``where`` names it in messages (default
    ``source``). TypeError if ``robot`` is not a :class:`Robot` (:func:`faultgen.model.robots.load`
    resolves a name)."""
    robots.require(robot, "programs.parse")
    where = where or str(source or "program")
    try:
        data = inputs.loads_toml(text, where, "program file")
    except inputs.InputError as err:
        raise ProgramError(str(err)) from None
    raw = data.get("segment", [])
    if isinstance(raw, list) and len(raw) > MAX_SEGMENTS:
        raise ProgramBoundError(f"{where}: {len(raw)} [[segment]] tables; a program has at most {MAX_SEGMENTS} "
                                "(MAX_SEGMENTS): split it into several programs")
    top = Table(where, "", data, TOP_KEYS)
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
    tool = Table(where, "[tool] ", data.get("tool", {}), TOOL_KEYS)
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


def _check_robot(top: Table, robot: Robot) -> None:
    """Refuse a program whose ``robot`` key names another robot than the one it runs on (its joint
    angles, poses and limits were written for that robot). A model ``faultgen calibrate`` wrote,
    ``<robot>_calibrated``, runs the programs of ``<robot>``."""
    named = top.text("robot")
    if robot.name not in (named, f"{named}_calibrated"):
        top.fail("robot", f"the program is for {named!r}, not for {robot.name!r} (its angles, poses and limits are "
                          f"that robot's); run it with --robot {named}, or write {robot.name!r} there")


def robot_limits(robot: Robot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The joint velocity, acceleration and jerk limits of a robot folder (its ``tasks.toml``
    ``[limits]``), rad/s, rad/s^2, rad/s^3, each of shape (N,): the limits the thesis tasks are
    planned to, and the speed histogram's design maximum of their per-cycle features.

    Raises
    ------
    TypeError
        If ``robot`` is not a :class:`Robot` (:func:`faultgen.model.robots.load` resolves a name).
    ProgramError
        If the folder has no ``tasks.toml`` or its ``[limits]`` are missing or malformed.
    """
    robots.require(robot, "programs.robot_limits")
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
    values = Table(origin, "[limits] ", table if isinstance(table, dict) else {}, LIMIT_KEYS)
    n = len(robot.joint_names)
    limits = []
    for key in LIMIT_KEYS:
        given = values.array(key, (n,), 1.0, positive=True)
        low, high, unit = LIMIT_BOUNDS[key]
        outside = np.flatnonzero((given < low) | (given > high))
        if outside.size:
            values.fail(key, f"axis {outside[0] + 1}: {given[outside[0]]:g} {unit}; expected {low:g} .. {high:g} {unit} "
                             "on every axis")
        limits.append(given * (np.pi / 180))  # as Table.array scales: the same floats, the same plans
    return tuple(limits)


def _segment(where: str, number: int, table, robot: Robot) -> Segment:
    if not isinstance(table, dict):
        raise ProgramError(f"{where}: segment {number}: expected a [[segment]] table, got {table!r}")
    kind = table.get("type")
    if kind not in SEGMENT_KEYS:
        raise ProgramError(f"{where}: segment {number}: type = {kind!r}; expected one of {', '.join(SEGMENT_KEYS)}")
    t = Table(where, f"segment {number} ({kind}) ", table, ("type", "label", *SEGMENT_KEYS[kind]))
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


# -- export --------------------------------------------------------------------------------------


def builtin(robot: Robot, name: str) -> Program:
    """The built-in task ``name`` of ``robot``: the table ``[name]`` of its folder's ``tasks.toml``
    read as a program, with the file's ``[limits]`` (the thesis tasks of ch. 6.3.1 are the tables
    :data:`~faultgen.operation.tasks.TASKS`). Its :attr:`Program.text` is what :func:`export` writes.

    Raises
    ------
    TypeError
        If ``robot`` is not a :class:`Robot` (:func:`faultgen.model.robots.load` resolves a name).
    ProgramError
        For a robot without a ``tasks.toml``, a name that is no table of it (the message lists the
        tables), or a table that does not read as a program (the file, the table, the segment and
        the key named).
    """
    robots.require(robot, "programs.builtin")
    source = robot.path.parent / "tasks.toml"
    if not source.is_file():
        raise ProgramError(f"{source}: no tasks file for robot {robot.name!r}")
    try:
        data = inputs.read_toml(source, "tasks file")
    except inputs.InputError as err:
        raise ProgramError(str(err)) from None
    known = [key for key in data if key != "limits"]
    if name not in known:
        raise ProgramError(f"unknown task {name!r}; known tasks of {robot.name}: {', '.join(known)} ({source})")
    where = f"{source} [{name}]"
    table = Table(str(source), f"[{name}] ", data[name], BUILTIN_KEYS).data
    limits = Table(str(source), "[limits] ", data.get("limits"), LIMIT_KEYS)
    program = {"name": name, "robot": robot.name, **table, "limits": {key: limits.get(key) for key in LIMIT_KEYS}}
    title = f"Thesis ch. 6.3.1 task {TASKS.index(name) + 1}" if name in TASKS else f"Task {name}"
    header = (f"{title} ({table.get('process', 'program')}) of {robot.name}, exported from {source.name} by "
              "`faultgen tasks export`.")
    return parse(dumps(program, header, where), robot, source, where)


def export(robot: Robot, name: str) -> str:
    """The built-in task ``name`` of ``robot`` (a table of its ``tasks.toml``, :func:`builtin`) as a
    program file's text to edit: the same program, so the same path bit for bit (numbers are written
    as the file gives them).

    Raises
    ------
    ProgramError
        As :func:`builtin`.
    """
    return builtin(robot, name).text


def show(robot: Robot, task: str) -> str:
    """The text of a task: a thesis task exported (:func:`export`), or a program file's own text."""
    if task in TASKS:
        return export(robot, task)
    check_name(task)
    if kind(task) not in PROGRAM_KINDS:
        raise ValueError(f"{task}: a joint log has no program text; `faultgen tasks show` prints programs")
    return task.text if kind(task) == TEXT else inputs.read_text(task, "program file", inputs.TOML_MAX_BYTES)


def available(robot: Robot) -> list[tuple[str, str]]:
    """The programs of ``robot``: ``(name, what)`` for each thesis task in its ``tasks.toml`` and each
    program file in its folder's ``programs/``. TypeError if ``robot`` is not a :class:`Robot`."""
    robots.require(robot, "programs.available")
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
