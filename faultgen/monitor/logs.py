"""A fleet's measured logs, one at a time, as the monitor reads them: the folder
(:func:`faultgen.data.logfolder.scan`), each log's record by the import's code
(:func:`faultgen.data.fleetlogs.log_record`: the per-cycle features of a simulated fleet's daily
records) and its logged conditions (joint temperature, payload; :mod:`faultgen.logs.measured`).

Each log is read once in a run (:class:`Source`): its bytes held (:func:`faultgen.inputs.hold`),
hashed (the SHA-256 the state and the caches key on) and parsed from them by the log format's
reader, and that :class:`Parsed` log handed to the program's identification, the calibration, the
twin and the scoring.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from faultgen import inputs
from faultgen.data import fleetlogs, logfolder
from faultgen.logs import columns, formats, measured
from faultgen.logs.columns import WHOLE_MAX_BYTES
from faultgen.model.robots import Robot
from faultgen.monitor import history, scoring
from faultgen.operation import programs

#: The features the monitor watches per axis (:data:`faultgen.monitor.scoring.FEATURES`, which says why).
FEATURES = scoring.FEATURES

#: Share of an axis's speed limit below which a sample counts as standing still in
#: ``friction_torque`` (:func:`friction_torque`).
MOVING_SPEED = 0.01

Log = logfolder.LogFile


#: A log reader: (path, robot) -> the checked log (:func:`faultgen.logs.measured.read`, or an
#: adapter's, :mod:`faultgen.logs.formats`).
Reader = Callable[[Path, Robot], measured.MeasuredData]


def reader_of(adapter: formats.LogFormat = formats.MEASURED) -> tuple[Reader, tuple[str, ...]]:
    """The reader and the file suffixes of the log format ``adapter`` (a
    :class:`faultgen.logs.formats.LogFormat`, the measured one by default). It estimates the accelerations,
    as the measured format's reader does: the one parse of a log serves its features, and, for a
    unit's first log, the calibration and the twin, which need them (read without them, every
    ``ur-rtde`` unit's calibrated twin fails on "qdd holds a non-finite value" and falls back to the
    nominal model)."""
    return adapter.read, adapter.suffixes


def fleet(logs_dir: str | Path, suffixes: tuple[str, ...] = fleetlogs.SUFFIXES,
          passed: list[tuple[str, str]] | None = None) -> dict[str, list[Log]]:
    """The units of a fleet folder and each unit's logs (files ending in one of ``suffixes``) in
    stamp order. A file in a unit folder that is not a log (``notes.txt``, ``backup copy.csv``: no
    stamp) is passed over as hidden files are, and added to ``passed`` as ``(name, reason)`` (its
    name in the folder, ``<unit>/<file>``), to be named; without ``passed`` it is refused, and so
    is a log whose link leads out of the folder (:data:`faultgen.data.logfolder.LINK_OUT`) always.

    Raises
    ------
    ValueError
        As :func:`faultgen.data.logfolder.scan`, for a log linked out of the folder, or (without
        ``passed``) for a file in a unit folder that is not a log (named, with what was expected).
    """
    units, found = logfolder.scan(Path(logs_dir), suffixes)
    # a link out of the folder is refused, never passed over: the folder must hold what it shows
    bad = found if passed is None else [(name, reason) for name, reason in found if reason == logfolder.LINK_OUT]
    if bad:
        name, reason = bad[0]
        more = f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""
        raise ValueError(f"{Path(logs_dir) / name}: {reason}{more}")
    if passed is not None:
        passed.extend(found)
    return {unit: logs for unit, logs in units.items() if logs}


def passed_note(passed: list[tuple[str, str]]) -> str:
    """A unit's note on its files passed over (:func:`fleet`'s ``passed``, the unit's own): how many,
    the first named with why, "" for none."""
    if not passed:
        return ""
    name, reason = passed[0]
    more = f" (and {len(passed) - 1} more)" if len(passed) > 1 else ""
    return f"{len(passed)} files passed over, not logs: {passed_entry(name, reason)}{more}"


def passed_entry(name: str, reason: str) -> str:
    """One entry passed over, ``name: reason``."""
    return f"{name}: {reason}"


@dataclass(frozen=True)
class Reading:
    """A log's features (``vector``, :data:`FEATURES` by name then axis), mean joint temperature
    (deg C, NaN when not logged), payload (kg, 0 when not logged) and the reader's ``notes``."""

    vector: np.ndarray
    temperature: float
    payload: float
    notes: tuple[str, ...] = ()
    q: np.ndarray | None = None  # (n, N) rad: the log's angles, which tell a program change


def log_notes(stamp: str, notes, kept) -> list[history.Note]:
    """The unit's notes (``log STAMP: note``, kind :data:`faultgen.monitor.history.COLUMN`) of the reader's
    notes on the columns of the log ``stamp`` (its ``notes``' :class:`faultgen.logs.measured.ColumnNote`: a
    speed column divided by the gear ratio from the motor side, one of another ratio or sign, a torque
    above the arm's limit) that the unit keeps (``kept``, its notes so far), each axis's kind of note
    once, by their fields: the first log that showed it named, later logs saying the same adding nothing."""
    said = {(n.column.axis, n.column.kind) for n in kept if n.kind == history.COLUMN}
    out = []
    for note in notes:
        if isinstance(note, measured.ColumnNote) and (note.axis, note.kind) not in said:
            said.add((note.axis, note.kind))
            out.append(history.Note(f"log {stamp}: {note}", history.COLUMN, stamp, note))
    return out


def feature_vector(record: dict[str, np.ndarray]) -> np.ndarray:
    """:data:`FEATURES` of one record (each (1, N)) as one vector of ``len(FEATURES) * N``."""
    return np.concatenate([np.ravel(record[name]) for name in FEATURES])


@lru_cache(maxsize=8)
def _speed_limit(robot: Robot) -> np.ndarray:
    return programs.robot_limits(robot)[0]


def friction_torque(robot: Robot, data: measured.MeasuredData) -> np.ndarray:
    """Each axis's motor-side torque along its motion, ``mean(sign(qd) tau_m)`` over the log's
    samples, N m, shape (1, N) (a sample standing still, below :data:`MOVING_SPEED` of the axis's
    speed limit, counts 0: there the sign of an estimated speed is noise).

    Along a move from rest to rest the inertial torque adds nothing to it (its integral times the
    speed's sign is the change of the speed's magnitude), gravity and the coupling the same in
    every cycle of a program and part (the twin predicts both), and the friction ``f(w)`` its mean
    ``|f|``: a change of the dry friction moves it by the change of the mean |dry friction| over the
    motion, the wear's own definition, whatever the friction's shape over speed (a Stribeck hump
    that grows faster than the Coulomb level moves it by what it adds there), where the RMS and the
    average load torque weigh friction by the torque it adds to."""
    moving = np.abs(data.qd) > MOVING_SPEED * _speed_limit(robot)
    return np.mean(np.where(moving, np.sign(data.qd), 0.0) * (data.tau / robot.gear_ratio), axis=0)[None]


def features_of(robot: Robot, data: measured.MeasuredData) -> np.ndarray:
    """The feature vector of a measured (or simulated, as arrays) log: the import's record."""
    record = fleetlogs.log_record(data, robot, _speed_limit(robot))
    record["friction_torque"] = friction_torque(robot, data)
    return feature_vector(record)


def read(robot: Robot, log: Log, reader: Reader = measured.read) -> Reading:
    """Read and check one log (``reader``: :func:`faultgen.logs.measured.read` by default; errors
    name the file and row)."""
    return reading_of(robot, reader(log.path, robot))


def reading_of(robot: Robot, data: measured.MeasuredData) -> Reading:
    """The :class:`Reading` of a checked log: its features, mean joint temperature, payload, notes, angles."""
    temperature = float(np.mean(data.joint_temperature)) if data.joint_temperature is not None else float("nan")
    payload = float(np.max(data.payload_mass)) if data.payload_mass is not None else 0.0
    return Reading(features_of(robot, data), temperature, payload, tuple(data.notes), np.asarray(data.q))


#: Largest log held in memory to be read once, bytes on disk: the bound a log read whole puts on its
#: kept cells (:data:`faultgen.logs.columns.WHOLE_MAX_BYTES`), so holding its bytes at most
#: doubles what reading it takes. A larger log is parsed from its path (its header, size and rows
#: each opening it) and hashed by another read.
HOLD_MAX_BYTES = WHOLE_MAX_BYTES


def log_sha256(path: Path) -> str:
    """SHA-256 of a log's (or friction test's) bytes, hex, its size checked first and the read
    bounded by it (:data:`faultgen.logs.columns.LOG_MAX_BYTES`, :func:`faultgen.inputs.sha256_of`).

    Raises
    ------
    faultgen.inputs.InputError
        Naming the file: missing, not a regular file, or above the bound (never read then)."""
    return inputs.sha256_of(path, "joint log", columns.LOG_MAX_BYTES)


@dataclass(frozen=True, eq=False)
class Parsed:
    """A log as one read of it found it: ``path``, ``sha256`` (hex, of its bytes) and the checked
    ``data`` (:class:`faultgen.logs.measured.MeasuredData`), or ``error`` (the ``ValueError`` its
    reading raised, naming the file and row), which :meth:`checked` raises."""

    path: Path
    sha256: str
    data: measured.MeasuredData | None
    error: ValueError | None = None

    def checked(self) -> measured.MeasuredData:
        """:attr:`data`; raises :attr:`error` for a log that cannot be read."""
        if self.error is not None:
            raise self.error
        return self.data


def parse(path: Path, robot: Robot, reader: Reader = measured.read, held: bool = True) -> Parsed:
    """Read the log ``path`` once (:class:`Parsed`): its bytes held (``held`` and at most
    :data:`HOLD_MAX_BYTES`), hashed and parsed by ``reader`` (which then takes a
    :class:`faultgen.inputs.Held` for the path); otherwise parsed from the path and hashed apart.

    A ``ValueError`` of the reader is kept in :attr:`Parsed.error`, and so is a file that cannot be
    read at all (deleted since the folder was listed: an :class:`faultgen.inputs.InputError` naming
    it, :attr:`Parsed.sha256` empty), so that the log is skipped, never the run stopped.
    """
    path = Path(path)
    source = path
    try:
        size = path.stat().st_size
        if size > columns.LOG_MAX_BYTES:  # on its size, before any read: a sparse file's apparent size is free
            return Parsed(path, "", None, inputs.InputError(
                f"{path}: {size} bytes; a joint log is read up to {columns.LOG_MAX_BYTES} bytes (LOG_MAX_BYTES)"))
        if held and size <= HOLD_MAX_BYTES:
            try:
                source = inputs.hold(path, "joint log", HOLD_MAX_BYTES)
            except inputs.InputError:
                source = path  # grown past the bound since its size was read: read from the path
        sha256 = source.sha256 if isinstance(source, inputs.Held) else log_sha256(path)
    except OSError as err:
        return Parsed(path, "", None, inputs.InputError(f"{path}: cannot be read ({err.strerror or err}); it was "
                                                        "removed or replaced since the logs folder was listed"))
    except inputs.InputError as err:  # grown past LOG_MAX_BYTES, or no longer a regular file
        return Parsed(path, "", None, err)
    try:
        return Parsed(path, sha256, reader(source, robot))
    except ValueError as err:
        return Parsed(path, sha256, None, err)
    except OSError as err:  # removed while the reader opened it again (a log read from its path)
        return Parsed(path, sha256, None, inputs.InputError(f"{path}: cannot be read ({err.strerror or err}); it "
                                                            "was removed or replaced while it was read"))


class Source:
    """The logs of one ``faultgen monitor`` run, each read once (:func:`parse`) by the format's
    reader (``log_format``, a :class:`faultgen.logs.formats.LogFormat`; held unless it reads
    only paths: :attr:`faultgen.logs.formats.LogFormat.reads_held`) and kept until :meth:`done` (a
    program, :meth:`keep`, for the run), so a unit's first log serves its program, calibration,
    twin and score from one read. It holds the parsed first log of each unit not yet scored, and
    each program. ``robot`` is the run's nominal robot and ``given`` the model given for every unit
    (``--calibrated``), each resolved once where this process's source was made (the run's
    :func:`faultgen.monitor.run.resolve_run`, or a worker: :meth:`faultgen.monitor.feed.Context.new_source`); ``given`` is
    None without one, or the ValueError its loading raised (each unit then falls back, saying why:
    :func:`faultgen.monitor.unit.twin_of`)."""

    def __init__(self, robot: Robot, log_format: formats.LogFormat = formats.MEASURED,
                 given: Robot | ValueError | None = None):
        self.robot = robot
        self.given = given
        self.reader, _ = reader_of(log_format)
        self.held = bool(log_format.reads_held)
        self.format_key = log_format.key
        self._parsed: dict[Path, Parsed] = {}
        self._kept: set[Path] = set()

    def get(self, log: Log) -> Parsed:
        """The log ``log`` parsed (read now if not yet in this run)."""
        path = Path(log.path)
        if path not in self._parsed:
            self._parsed[path] = parse(path, self.robot, self.reader, self.held)
        return self._parsed[path]

    def keep(self, log: Log) -> None:
        """Keep ``log`` parsed for the run: a program, which twins replay and later logs are compared with."""
        self._kept.add(Path(log.path))

    def done(self, log: Log) -> None:
        """Forget ``log`` (scored), unless it is kept (:meth:`keep`)."""
        if Path(log.path) not in self._kept:
            self._parsed.pop(Path(log.path), None)
