"""The registry of log formats (:data:`FORMATS`): the measured format, its default entry
(:data:`DEFAULT`, :data:`MEASURED`), and the layouts robots and datasets really have, read into it.

Each other format maps a foreign file's columns onto the measured format's (``t``, ``q1..qN``,
``tau1..tauN`` arm side, optional ``qd1..qdN`` and ``cycle``) and hands them to
:func:`faultgen.logs.measured.from_columns`, which checks them as it checks a measured log (the
same refusals, by data row). Registered by name (:func:`register`, :data:`FORMATS`), chosen with
``--format NAME`` (``logs import``, ``calibrate``, ``monitor``, ``simulate --task LOG``);
docs/dataset.md, "Adapters", gives each layout. Each reads a log whole (:meth:`LogFormat.columns`)
or in blocks of rows (:meth:`LogFormat.blocks`, :meth:`LogFormat.source`: a log too long to read whole,
calibrated by :mod:`faultgen.logs.longlog` or replayed streamed by
:mod:`faultgen.operation.replay`) with the same checks and messages; :data:`MEASURED` is the
measured format's own readers as a registered format (docs/architecture.md, "Log formats").

- ``ur-rtde``: Universal Robots' RTDE recorder CSV (comma- or space-separated; ``.csv`` or
  ``.csv.gz``): ``timestamp`` (s), ``actual_q_0..5`` (rad), optional ``actual_qd_0..5`` (rad/s) and
  ``joint_temperatures_0..5`` (deg C, all or none), and the joint torque, the first of: the
  measured current as torque by the controller's own constants, ``actual_current_as_torque_0..5``
  (N m; RTDE output of e-Series controllers from PolyScope 5.23); with ``torque_constants`` given
  (N m/A at the joint, one per axis), the measured ``actual_current_0..5`` (A) times them; the
  commanded ``target_moment_0..5`` (N m). Which one was taken is the log's note.
- ``voraus``: the voraus-AD dataset's Parquet layout (Brockmann et al. 2023, CC BY-NC-SA 4.0: never
  shipped with faultgen; read from your copy): ``time`` (s), ``joint_position_1..6`` (rad),
  ``joint_velocity_1..6`` (rad/s) and ``motor_torque_1..6`` (N m at the motor, referred to the
  arm by the robot's gear ratio), 100 Hz; its ``sample`` column (one recording) becomes the cycle.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from faultgen import inputs
from faultgen.logs import blocks, delimited, jointlog, measured
from faultgen.logs.columns import (
    CSV_SUFFIXES, CYCLE_COLUMN, HDF5_SUFFIXES, MAX_ROWS, T_COLUMN, LogBoundError, column_names,
    temperature_columns,
)
from faultgen.model import robots

#: name -> log format class, in the order registered: :data:`DEFAULT` first, then ``ur-rtde``,
#: ``voraus`` and a user's (:func:`register`).
FORMATS: dict[str, type[LogFormat]] = {}
#: The format a log is read in when none is named (``--format measured``): :mod:`faultgen.logs.measured`.
DEFAULT = "measured"
#: N m/A: the torque constants at the joint a ``ur-rtde`` log may be read with (a UR joint's is
#: about 10: the motor's 0.1 times the gear ratio 101).
MIN_TORQUE_CONSTANT, MAX_TORQUE_CONSTANT = 1e-3, 1e4


#: A log's torque source in words: the import's summary, units.csv's
#: ``torque_source`` and the monitor's page say it (:func:`torque_source`). The commanded moment of a
#: fixed program is the controller's model of the motion, the same every day whatever the joint's
#: friction: it cannot show wear. RTDE's ``actual_current_as_torque`` (PolyScope >= 5.23) is the
#: measured current turned into torque by the controller's own constants.
MEASURED_CURRENT, COMMANDED_MOMENT = "measured current x torque constant", "commanded moment (cannot show wear)"
CURRENT_AS_TORQUE = "current as torque (controller's own constants)"


class TorqueNote(str):
    """A reader's note naming the log's torque source (``ur-rtde``'s "torque from ..."), its
    :attr:`source` one of :data:`CURRENT_AS_TORQUE`, :data:`MEASURED_CURRENT`, :data:`COMMANDED_MOMENT`."""

    def __new__(cls, text: str, source: str = ""):  # the default: unpickled, its source set after
        note = super().__new__(cls, text)
        note.source = source
        return note


def torque_source(notes) -> str:
    """The source of the :class:`TorqueNote` among a log's ``notes`` (:attr:`faultgen.logs.measured.
    MeasuredData.notes`); "" when none names one (the measured format: the logged arm torque)."""
    return next((note.source for note in notes if isinstance(note, TorqueNote)), "")


#: Data rows of the first block read to learn a log's columns before its blocks are read
#: (:class:`Blocks`).
PEEK_ROWS = 16


def register(name: str):
    """Class decorator: register an :class:`LogFormat` under ``name`` (its ``--format``)."""
    def decorate(cls):
        cls.name = name
        FORMATS[name] = cls
        return cls
    return decorate


@dataclass(frozen=True)
class LogFormat:
    """Base of a log format: ``suffixes`` (lower case) of the files it reads, and its two readers
    with the same checks and messages: whole (:meth:`columns`, :meth:`read`) and in blocks of rows
    (:meth:`blocks`, :meth:`source`) for a log too long to read whole (the calibration's
    :mod:`faultgen.logs.longlog`, the replay's streaming, :mod:`faultgen.logs.blocks`).

    A column-mapping format defines :meth:`convert` alone (one block of the file, its cells as
    floats, mapped onto the measured format's names and units) and :attr:`separator`: the base
    reads the file as delimited text, whole or in chunks (:meth:`frames`), so it gets both readers.
    A format with a reader of its own overrides :meth:`columns` and, to read in blocks with bounded
    memory, :meth:`blocks` and :meth:`rows` (else its blocks are its whole read, sliced).

    ``reads_held``: :meth:`columns` takes the file's bytes read once (:class:`faultgen.inputs.Held`)
    for its path, reading through :mod:`faultgen.inputs` (``open_bytes``, ``open_text``,
    ``csv_header``) or from ``held.data``, so ``faultgen monitor`` opens each log once. False (the
    default, a plug-in written against a path): :meth:`read` hands it the held file's path, which
    it then opens again."""

    name = ""
    reads_held = False
    suffixes: tuple[str, ...] = ()
    #: The column separator of a delimited-text format read by :meth:`frames`.
    separator = ","
    #: Data row index (0-based, from the file's first data row) -> its name in messages.
    label = staticmethod(jointlog.index_label)

    def convert(self, frame: pd.DataFrame, robot: robots.Robot):
        """One block of the file (``frame``: its columns by the file's names, every cell a finite
        float) as the measured format's columns: a dict of name (``t`` s, ``q1..qN`` rad,
        ``tau1..tauN`` N m at the arm, optional ``qd1..qdN`` rad/s, ``temperature1..N``,
        ``cycle``) to ndarray of shape (rows,), or ``(columns, notes)``. Defined by a
        column-mapping format (class docstring); a column it names that the file lacks is refused
        with the file's columns (:meth:`frames`)."""
        raise NotImplementedError

    def _maps(self) -> bool:
        return type(self).convert is not LogFormat.convert

    def frames(self, path: Path | inputs.Held, size: int | None) -> Iterator[tuple[int, pd.DataFrame]]:
        """The delimited-text file ``path`` (:attr:`separator`, a header row; plain or gzip) as
        ``(start, frame)``: its first data row's index and ``size`` rows of it (the whole file when
        None), every cell a finite float.

        Raises
        ------
        faultgen.logs.measured.MeasuredDataError
            Not a regular file, unreadable as such text, a column named twice in the header, a
            cell that is not a finite number (the data row, column and value named).
        """
        what = f"{self.name} log"
        names, _ = delimited.header(path, what, self.separator, what)
        if size is None:
            jointlog.csv_rows(path, len(names), f"a {what}", what)  # whole: bounded by WHOLE_MAX_BYTES
        start = 0
        for values in delimited.text_chunks(path, what, f"a {what}", names, self.separator, names, self.label, size):
            frame = pd.DataFrame(values, columns=names)
            yield start, frame
            start += len(frame)
        if not start:  # no data row: the header's columns, empty
            yield 0, pd.DataFrame({name: np.empty(0) for name in names}, columns=names)

    def _converted(self, path, frame: pd.DataFrame, robot: robots.Robot) -> tuple[dict, tuple[str, ...]]:
        try:
            out = self.convert(frame, robot)
        except KeyError as err:
            raise measured.MeasuredDataError(
                f"{inputs.path_of(path)}: missing column {err} of the {self.name} layout; found "
                f"{', '.join(map(str, frame.columns[:40])) or '(none)'}") from None
        columns, notes = out if isinstance(out, tuple) else (out, ())
        return columns, tuple(notes)

    def columns(self, path: Path, robot: robots.Robot) -> tuple:
        """``(columns, label)`` or ``(columns, label, notes)``: the file's columns under the
        measured format's names (dict of ndarray of shape (n,)), the data-row labeller of messages,
        and what the reading chose (which torque source, say), kept in
        :attr:`faultgen.logs.measured.MeasuredData.notes`. The base: :meth:`convert` of the
        whole file (:meth:`frames`)."""
        if not self._maps():
            raise NotImplementedError(f"log format {self.name}: define convert() or columns()")
        parts, notes = {}, ()
        for _, frame in self.frames(path, None):  # converted chunk by chunk, as the blocks are
            columns, notes = self._converted(path, frame, robot)
            for name, values in columns.items():
                parts.setdefault(name, []).append(values)
        return {name: jointlog.joined(chunks) for name, chunks in parts.items()}, self.label, notes

    def blocks(self, path: Path, robot: robots.Robot, size: int) -> Iterator[tuple]:
        """The log in blocks of ``size`` data rows (the last one shorter), each as :meth:`columns`
        gives the whole file: ``(columns, label, notes)``, the label naming rows from the file's
        first data row. The base: :meth:`convert` of each chunk of :meth:`frames`; for a format
        without :meth:`convert`, its whole read sliced (memory that of the whole read).

        Raises
        ------
        faultgen.logs.measured.MeasuredDataError
            What :meth:`columns` refuses, with the same message.
        """
        if self._maps():
            for _, frame in self.frames(path, size):
                columns, notes = self._converted(path, frame, robot)
                yield columns, self.label, notes
            return
        columns, label, *notes = self.columns(path, robot)
        n = len(next(iter(columns.values()), ()))
        for start in range(0, n, size):
            yield {k: np.asarray(v)[start:start + size] for k, v in columns.items()}, label, tuple(*notes)

    def motion(self, path: Path, robot: robots.Robot) -> tuple:
        """``(columns, label)`` of the whole log as a replay reads it: ``t`` and ``q1..qN`` used
        (:func:`faultgen.operation.replay.from_columns`). The base: :meth:`columns`."""
        return self.columns(path, robot)[:2]

    @property
    def key(self) -> str:
        """The format with its options as a cache or a monitor's state records it (its ``repr``)."""
        return repr(self)

    def rows(self, path: Path) -> int:
        """An upper bound of the log's data rows, found before they are parsed. The base: the lines
        of the delimited-text file but its header (:func:`faultgen.inputs.count_lines`)."""
        try:
            return max(inputs.count_lines(path, f"{self.name} log", inputs.CSV_ROW_MAX_BYTES) - 1, 0)
        except inputs.InputError as err:
            raise LogBoundError(str(err)) from None
        except (OSError, UnicodeDecodeError, EOFError) as err:
            raise measured.MeasuredDataError(f"{path}: cannot read the file: {err}") from err

    def source(self, path: str | Path, robot: robots.Robot, motion_only: bool = False):
        """The log ``path`` as blocks of the measured format's columns (:class:`Blocks`: the block
        source :mod:`faultgen.logs.blocks` reads), ``motion_only`` as there (``t`` and
        ``q1..qN``: a replay)."""
        return Blocks(self, Path(path), robot, motion_only)

    def read(self, path: Path, robot: robots.Robot, accelerations: bool = True) -> measured.MeasuredData:
        """Read and check one log (:func:`faultgen.logs.measured.from_columns`; ``accelerations``
        as :func:`faultgen.logs.measured.read`); ``path`` may be held (:attr:`reads_held`)."""
        given = path if self.reads_held and isinstance(path, inputs.Held) else inputs.path_of(path)
        columns, label, *notes = self.columns(given, robot)
        return measured.from_columns(columns, robot, inputs.path_of(path), label, accelerations,
                                     notes=notes[0] if notes else ())


def make(name: str, **options) -> LogFormat:
    """The adapter ``name`` with its options.

    Raises
    ------
    ValueError
        For an unknown name (the message lists the known ones) or a bad option.
    """
    if name not in FORMATS:
        raise ValueError(f"unknown log format {name!r}; expected {DEFAULT} (the default) or one of "
                         f"{', '.join(n for n in FORMATS if n != DEFAULT)}")
    cls = FORMATS[name]
    known = [f.name for f in dataclasses.fields(cls) if f.name != "suffixes"]
    unknown = [key for key in options if key not in known]
    if unknown:
        raise ValueError(f"log format {name} takes no option {', '.join(unknown)}"
                         + (f"; its options: {', '.join(known)}" if known else ""))
    return cls(**options)


class Blocks:
    """A log read through its format's :meth:`LogFormat.blocks` as the block source
    :mod:`faultgen.logs.blocks` reads: ``path``, ``wanted`` (the measured format's columns
    read, in the order of a block's columns: :func:`faultgen.logs.jointlog.select_columns`),
    ``extra`` (none: the adapter chose its columns), ``notes`` (what the reading chose), ``rows``
    (an upper bound of the data rows, :meth:`LogFormat.rows`), ``label`` and :meth:`blocks`. Its first
    :data:`PEEK_ROWS` rows are read here, to learn the columns.

    Raises
    ------
    faultgen.logs.measured.MeasuredDataError
        A missing column (as :func:`faultgen.logs.measured.from_columns` names it), a log of more
        rows than :data:`faultgen.logs.columns.MAX_ROWS`, or what the adapter refuses.
    """

    def __init__(self, adapter: LogFormat, path: Path, robot: robots.Robot, motion_only: bool = False):
        self.adapter, self.path, self.robot, self.extra = adapter, path, robot, []
        peek = iter(adapter.blocks(path, robot, PEEK_ROWS))
        try:
            first = next(peek, None)
        finally:
            getattr(peek, "close", lambda: None)()  # a generator's file closed now
        if first is None:  # no data row: the whole read says what is wrong
            self.wanted, self.notes, self.rows, self.label = [], (), 0, adapter.label
            return
        columns, self.label, *notes = first
        self.notes = tuple(notes[0]) if notes else ()
        self.wanted, _ = jointlog.select_columns(path, list(columns), robot.n_axes, motion_only)
        self.rows = adapter.rows(path)
        if self.rows > MAX_ROWS:
            raise measured.MeasuredDataError(f"{path}: {self.rows} data rows; a log has at most {MAX_ROWS} "
                                             "(MAX_ROWS: a day at 1 kHz)")

    def blocks(self, size: int) -> Iterator[tuple[int, np.ndarray]]:
        """``(start, block)``: the index of the block's first data row and its ``wanted`` columns
        (ndarray of shape (size, len(wanted)), floats; the last block shorter), every cell refused
        unless finite, as :func:`faultgen.logs.measured.from_columns` refuses it."""
        start, held, count = 0, [], 0  # held: rows read, not yet yielded (``count`` of them)
        for columns, *_ in self.adapter.blocks(self.path, self.robot, size):
            values = {name: np.asarray(columns[name], dtype=float) for name in self.wanted}
            lengths = {len(v) for v in values.values()}
            if len(lengths) > 1:
                raise measured.MeasuredDataError(f"{self.path}: columns of different lengths {sorted(lengths)}")
            first = start + count
            jointlog.refuse_non_finite(self.path, values, self.wanted, lambda i, s=first: self.label(s + i))
            held.append(np.column_stack([values[name] for name in self.wanted]))
            count += len(held[-1])
            while count >= size:  # blocks of exactly ``size`` rows, whatever the adapter's
                rows = np.concatenate(held) if len(held) > 1 else held[0]
                yield start, rows[:size]
                start, count = start + size, count - size
                held = [rows[size:]] if count else []
        if count:
            yield start, np.concatenate(held)


@register(DEFAULT)
@dataclass(frozen=True)
class Measured(LogFormat):
    """The measured format (:mod:`faultgen.logs.measured`; ``--format measured``, the default) as an
    adapter: read whole by :func:`faultgen.logs.measured.read`, in blocks by its own block reader
    (:func:`faultgen.logs.blocks.source`: CSV or HDF5, ``extra`` its ignored columns)."""

    name = "measured"
    reads_held = True
    suffixes: tuple[str, ...] = CSV_SUFFIXES + HDF5_SUFFIXES

    def columns(self, path, robot: robots.Robot) -> tuple:
        columns, extra, label = jointlog.read_columns(path, robot.n_axes)
        return columns, label, tuple([f"ignored extra columns: {', '.join(extra)}"] if extra else [])

    def motion(self, path: Path, robot: robots.Robot) -> tuple:
        columns, _, label = jointlog.read_columns(path, robot.n_axes, motion_only=True)  # no torque needed
        return columns, label

    @property
    def key(self) -> str:
        return DEFAULT

    def read(self, path, robot: robots.Robot, accelerations: bool = True) -> measured.MeasuredData:
        return measured.read(path, robot, accelerations)

    def source(self, path: str | Path, robot: robots.Robot, motion_only: bool = False):
        return blocks.source(Path(path), robot.n_axes, motion_only)

    def blocks(self, path: Path, robot: robots.Robot, size: int) -> Iterator[tuple]:
        src = self.source(path, robot)
        notes = (f"ignored extra columns: {', '.join(src.extra)}",) if src.extra else ()
        for _, block in src.blocks(size):
            yield {name: block[:, j] for j, name in enumerate(src.wanted)}, src.label, notes


#: The measured format, the default entry of :data:`FORMATS`.
MEASURED = FORMATS[DEFAULT]()





@register("ur-rtde")
@dataclass(frozen=True)
class URRTDE(LogFormat):
    """Universal Robots' RTDE recorder CSV (module docstring).

    Parameters
    ----------
    torque_constants : tuple of float, optional
        N m/A at the joint, per axis: read the torque as ``actual_current_i`` times them when the
        file has no ``actual_current_as_torque`` columns (the controller's own conversion,
        preferred: :meth:`_torque`).
    """

    reads_held = True
    suffixes: tuple[str, ...] = (".csv", ".csv.gz")
    torque_constants: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        if self.torque_constants is not None:
            try:
                constants = np.asarray(self.torque_constants, dtype=float)
            except (TypeError, ValueError):
                constants = np.full(0, np.nan)
            if constants.ndim != 1 or not constants.size or not np.all(
                    (constants >= MIN_TORQUE_CONSTANT) & (constants <= MAX_TORQUE_CONSTANT)):
                raise ValueError(f"torque constants {self.torque_constants!r}: expected one number in "
                                 f"{MIN_TORQUE_CONSTANT:g} .. {MAX_TORQUE_CONSTANT:g} N m/A per axis")

    label = staticmethod(jointlog.csv_label)

    def _plan(self, path: Path | inputs.Held, robot: robots.Robot) -> dict:
        """What to read of the RTDE log ``path`` from its header: ``names``, ``separator``,
        ``wanted`` (its columns read), ``map`` (measured name -> (its column, factor)) and ``note``
        (the torque source), or refused (a missing column, a name twice)."""
        n_axes = robot.n_axes
        names, separator = delimited.header(path, "RTDE log", None, "CSV")
        axes = range(n_axes)
        q = [f"actual_q_{k}" for k in axes]
        qd = [f"actual_qd_{k}" for k in axes]
        temperature = [f"joint_temperatures_{k}" for k in axes]
        torque, scale, source = self._torque(path, names, n_axes)
        with_qd, with_temperature = all(c in names for c in qd), all(c in names for c in temperature)
        wanted = ["timestamp", *q, *torque, *(qd if with_qd else []), *(temperature if with_temperature else [])]
        delimited.require(path, names, wanted, "RTDE recorder")
        q_names, qd_names, tau_names = column_names(n_axes)
        mapping = {T_COLUMN: ("timestamp", None)}
        mapping.update({q_names[k]: (q[k], None) for k in axes})
        mapping.update({tau_names[k]: (torque[k], scale[k]) for k in axes})
        if with_qd:
            mapping.update({qd_names[k]: (qd[k], None) for k in axes})
        if with_temperature:
            mapping.update({name: (temperature[k], None)
                            for k, name in enumerate(temperature_columns(n_axes))})
        return {"names": names, "separator": separator, "wanted": wanted, "map": mapping, "note": source}

    def _torque(self, path: Path | inputs.Held, names: list[str], n_axes: int) -> tuple[list, list, str]:
        """The joint torque's columns in the RTDE log's header ``names``, their factors and the
        note naming the source, the first the file has of: ``actual_current_as_torque_i`` (N m, the
        measured current as torque by the controller's own constants: RTDE output of e-Series
        controllers from PolyScope 5.23); ``actual_current_i`` (A) times :attr:`torque_constants`
        when given; ``target_moment_i`` (N m, commanded). Refused with none of them."""
        axes = range(n_axes)
        as_torque = [f"actual_current_as_torque_{k}" for k in axes]
        current = [f"actual_current_{k}" for k in axes]
        moment = [f"target_moment_{k}" for k in axes]
        if all(c in names for c in as_torque):
            unused = "; the torque constants given are not used" if self.torque_constants is not None else ""
            return as_torque, [1.0] * n_axes, TorqueNote(
                "torque from actual_current_as_torque_i (the measured current as torque by the controller's own "
                f"constants){unused}", CURRENT_AS_TORQUE)
        if self.torque_constants is not None and all(c in names for c in current):
            if len(self.torque_constants) != n_axes:
                raise ValueError(f"{len(self.torque_constants)} torque constants for a robot of {n_axes} axes")
            return current, [float(k) for k in self.torque_constants], TorqueNote(
                "torque from actual_current_i x the torque constants given (measured)", MEASURED_CURRENT)
        if all(c in names for c in moment):
            return moment, [1.0] * n_axes, TorqueNote(
                "torque from target_moment_i (the controller's commanded moment, not a measurement: it cannot "
                "show wear; --torque-constants K1,...,KN reads the measured actual_current_i instead, "
                "the UR arms' constants: docs/dataset.md, \"Adapters\")"
                + (" (the file has actual_current_i)" if all(c in names for c in current) else ""), COMMANDED_MOMENT)
        raise measured.MeasuredDataError(
            f"{inputs.path_of(path)}: no joint torque: expected actual_current_as_torque_0..{n_axes - 1} (N m), "
            f"target_moment_0..{n_axes - 1} (N m), or actual_current_0..{n_axes - 1} (A) with the torque "
            "constants given (--torque-constants)")

    @staticmethod
    def _chunks(path, plan: dict, size: int | None = None) -> Iterator[dict[str, np.ndarray]]:
        return delimited.text_chunks(path, "RTDE log", "an RTDE recorder CSV", plan["names"], plan["separator"],
                            plan["wanted"], URRTDE.label, size)

    @staticmethod
    def _mapped(plan: dict, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        return {name: values[column] if factor is None else values[column] * factor
                for name, (column, factor) in plan["map"].items()}

    def columns(self, path: Path, robot: robots.Robot):
        plan = self._plan(path, robot)
        jointlog.csv_rows(path, len(plan["wanted"]), "an RTDE log", "RTDE log")
        parts = {name: [] for name in plan["wanted"]}
        for values in self._chunks(path, plan):
            for name in plan["wanted"]:
                parts[name].append(values[name])
        values = {name: jointlog.joined(chunks) for name, chunks in parts.items()}
        return self._mapped(plan, values), self.label, (plan["note"],)

    def blocks(self, path: Path, robot: robots.Robot, size: int) -> Iterator[tuple]:
        plan = self._plan(path, robot)
        for values in self._chunks(path, plan, size):
            yield self._mapped(plan, values), self.label, (plan["note"],)



@contextmanager
def _named(path: Path | inputs.Held) -> Iterator[None]:
    """Turn pyarrow's errors reading the Parquet file ``path`` (a truncated or corrupt file) into a
    :class:`~faultgen.logs.measured.MeasuredDataError` that names it."""
    import pyarrow as pa

    try:
        yield
    except (pa.ArrowException, OSError) as err:
        raise measured.MeasuredDataError(f"{inputs.path_of(path)}: not a readable Parquet file ({str(err)[:200]}); "
                                         "a voraus-AD log is a Parquet table") from None


@register("voraus")
@dataclass(frozen=True)
class Voraus(LogFormat):
    """The voraus-AD dataset's Parquet layout (module docstring)."""

    reads_held = True
    suffixes: tuple[str, ...] = (".parquet",)

    @staticmethod
    def _parquet(path: Path | inputs.Held):
        """The file as pyarrow reads it (:class:`pyarrow.parquet.ParquetFile` of ``path`` or the held
        bytes: not reopened), its footer read, no row yet.

        Raises
        ------
        faultgen.logs.measured.MeasuredDataError
            Naming the file: not a regular file of at most :data:`faultgen.logs.delimited.MAX_BYTES`, or not a Parquet file
            pyarrow reads (truncated: no footer; another format).
        """
        import pyarrow as pa
        import pyarrow.parquet as pq

        inputs.regular_file(path, "voraus-AD log", delimited.MAX_BYTES)
        with _named(path):
            return pq.ParquetFile(pa.BufferReader(path.data) if isinstance(path, inputs.Held) else path)

    @classmethod
    def _plan(cls, path: Path | inputs.Held, robot: robots.Robot) -> tuple:
        """The file (:meth:`_parquet`), its columns read (refused when missing) and its rows, checked
        from the metadata before any is read against the bound of a log read whole
        (:func:`faultgen.logs.jointlog.check_whole_rows`; a few MB of constant columns may hold
        10^8 rows, and pyarrow decodes a row group whole even when it is read in batches): every
        path that reads a voraus log (``logs import``, the monitor, ``calibrate``) goes through here."""
        parquet = cls._parquet(path)
        names = parquet.schema_arrow.names
        axes = range(1, robot.n_axes + 1)
        velocity = [f"joint_velocity_{k}" for k in axes]
        wanted = ["time", *(f"joint_position_{k}" for k in axes), *(f"motor_torque_{k}" for k in axes),
                  *(velocity if all(c in names for c in velocity) else [])]
        delimited.require(path, names, wanted, "voraus-AD")
        wanted += ["sample"] if "sample" in names else []
        rows = parquet.metadata.num_rows
        jointlog.check_whole_rows(inputs.path_of(path), rows, len(wanted), what="a voraus-AD log")
        return parquet, wanted, rows

    @staticmethod
    def _mapped(values: dict[str, np.ndarray], robot: robots.Robot) -> dict[str, np.ndarray]:
        q_names, qd_names, tau_names = column_names(robot.n_axes)
        out = {T_COLUMN: values["time"]}
        for k in range(robot.n_axes):
            out[q_names[k]] = values[f"joint_position_{k + 1}"]
            out[tau_names[k]] = values[f"motor_torque_{k + 1}"] * robot.gear_ratio[k]  # motor side -> arm side
            if f"joint_velocity_{k + 1}" in values:
                out[qd_names[k]] = values[f"joint_velocity_{k + 1}"]
        if "sample" in values:
            out[CYCLE_COLUMN] = values["sample"]
        return out

    def columns(self, path: Path | inputs.Held, robot: robots.Robot):
        parquet, wanted, _ = self._plan(path, robot)
        with _named(path):
            frame = parquet.read(columns=wanted).to_pandas()
        return self._mapped(delimited.numbers(path, frame, wanted, self.label), robot), self.label

    def blocks(self, path: Path, robot: robots.Robot, size: int) -> Iterator[tuple]:
        parquet, wanted, _ = self._plan(path, robot)
        start = 0
        with _named(path):
            batches = parquet.iter_batches(batch_size=size, columns=wanted)
            for batch in batches:
                values = delimited.numbers(path, batch.to_pandas(), wanted, lambda i, s=start: self.label(s + i))
                yield self._mapped(values, robot), self.label, ()
                start += batch.num_rows

    def rows(self, path: Path) -> int:
        return self._parquet(path).metadata.num_rows
