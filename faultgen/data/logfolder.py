"""A fleet's folder of measured logs: its layout, the stamps of its logs, its events and the labels
they give each log (what :func:`faultgen.data.fleetlogs.import_logs` reads, docs/dataset.md
"A fleet's logs")::

    LOGS/
      events.csv                 optional: unit, stamp, event, axis (one row per event)
      <unit>/<stamp>.csv         one log: one or more cycles in the measured format
      <unit>/<stamp>.csv.gz      (faultgen.logs.measured), or the layout of an adapter
      <unit>/<stamp>.h5          (faultgen.logs.formats)
      <unit>/friction-test/<stamp>.csv   optional: the unit's friction tests (the same suffixes and
                                 stamps as its logs; never taken as logs: :func:`scan_tests`)

Symbolic links may stay inside ``LOGS`` (a unit folder or a log linked to another place in it);
a unit folder, a log or ``events.csv`` whose link leads out of ``LOGS`` is refused, named by its
place in ``LOGS`` (:func:`faultgen.inputs.within`), before anything behind it is listed or read.

``<stamp>`` is an ISO date (``2026-03-01``), an ISO date and time (``2026-03-01T08:30:00``, also
``2026-03-01T08-30-00`` or ``2026-03-01T0830``, as file names cannot hold ``:`` everywhere; naive
times are read as UTC) or a sequence number (``17``); one unit's logs use one kind. The logs of
a unit are taken in stamp order.

Events (``event`` column) and the labels they give (per log and axis: worn, healthy, unknown;
without events every log is unknown):

==================  =========================================================================
``onset``           the axis starts wearing at this stamp: its logs from here on are worn
``failure``         the axis failed at this stamp (a gearbox failure, thesis ch. 5): its log at
                    or just before the stamp is worn (from an earlier ``onset``: every log since),
                    and so are its later logs, until a repair
``repair``,         the axis was repaired or its gearbox replaced at this stamp: its last log
``gearbox_change``  before it is worn (from an earlier ``onset`` or ``failure``: every log since),
                    its logs from the stamp on healthy (a new part)
``healthy``         the axis (empty ``axis``: every axis) was found healthy at this stamp (an
                    inspection): its logs since its previous event, up to the stamp, are healthy
==================  =========================================================================
"""

from __future__ import annotations

import csv
import io
import os
import re
import stat
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from faultgen import axes, inputs

#: The events of ``events.csv`` (module docstring).
EVENTS = ("onset", "failure", "repair", "gearbox_change", "healthy")
#: The columns of ``events.csv``, in order.
EVENT_COLUMNS = ("unit", "stamp", "event", "axis")
#: Largest events file read, bytes (a row is some 40 bytes: 50 000 events, a hundred units' two
#: decades of maintenance; at most 160 000 rows of the shortest form). Read row by row, each event
#: kept as a small object whose unit, event and kind are shared strings: at most about 15 times the
#: file. Bounded so that a unit's repairs, kept in its state (some 65 bytes each), stay well inside
#: :data:`faultgen.monitor.state.STATE_MAX_BYTES` (16 MiB): at most 10 MB of them.
EVENTS_MAX_BYTES = 2 * 2**20
#: Per log and axis: the label codes of an imported dataset's ``label`` array.
UNKNOWN, HEALTHY, WORN = -1, 0, 1
#: What a link out of the folder is called in its refusal (:func:`faultgen.inputs.within`).
FOLDER = "logs folder"
#: The reason a log whose link leads out of the folder is not a log (listed with the files that are not).
LINK_OUT = "a symbolic link out of the logs folder; links must stay inside the folder"

#: A unit's folder of friction tests (``LOGS/<unit>/friction-test/<stamp>.csv``, :func:`scan_tests`):
#: passed over by :func:`scan`, whose logs are a unit's production logs.
TESTS = "friction-test"
#: Stamp kinds: a date or date-time (key: seconds since 1970-01-01 UTC) or a sequence number.
TIME, SEQUENCE = "time", "sequence"
#: Most digits of a sequence number (below 2^53: every one a distinct float key).
MAX_SEQUENCE_DIGITS = 15

_DATE_TIME = re.compile(r"(\d{4}-\d{2}-\d{2})(?:[T_ ](\d{2})[-:]?(\d{2})(?:[-:]?(\d{2}(?:\.\d+)?))?)?")


@dataclass(frozen=True)
class LogFile:
    """One log of the folder.

    Attributes
    ----------
    unit : str
        The unit's folder name.
    stamp : str
        The stamp as written in the file name.
    key : float
        The stamp as a number that sorts them: seconds since 1970-01-01 UTC, or the sequence number.
    kind : {"time", "sequence"}
    path : Path
    name : str
        The path relative to the folder (``<unit>/<file>``), what the manifest records.
    """

    unit: str
    stamp: str
    key: float
    kind: str
    path: Path
    name: str


@dataclass(frozen=True, slots=True)
class Event:
    """One row of ``events.csv``: ``axis`` 1..N, or 0 for every axis (a ``healthy`` event only)."""

    unit: str
    stamp: str
    key: float
    kind: str
    event: str
    axis: int
    line: int


class StampError(ValueError):
    """A stamp that does not parse (:func:`parse_stamp`): ``where`` it was found, and ``reason`` (what is
    wrong with it and what was expected); its message is ``"where: reason"``. Its ``args`` are the two, so
    it pickles (a worker process's error reaches the parent as it was raised)."""

    def __init__(self, where: str, reason: str):
        super().__init__(where, reason)
        self.where, self.reason = where, reason

    def __str__(self) -> str:
        return f"{self.where}: {self.reason}"


def parse_stamp(text: str, where: str) -> tuple[float, str]:
    """``(key, kind)`` of a stamp (module docstring).

    Raises
    ------
    StampError
        (a ValueError) If ``text`` is neither an ISO date or date-time nor a whole number of at most
        :data:`MAX_SEQUENCE_DIGITS` ASCII digits; names ``where``.
    """
    if text.isdigit():  # ASCII digits only: "²" and "٣" are digits to str.isdigit, not to a sequence
        if not (text.isascii() and len(text) <= MAX_SEQUENCE_DIGITS):
            raise StampError(where, f"stamp {_shown(text)}: expected a sequence number of at most "
                             f"{MAX_SEQUENCE_DIGITS} digits 0-9 (17), an ISO date (2026-03-01) or an ISO "
                             "date and time (2026-03-01T08:30:00)")
        return float(int(text)), SEQUENCE
    match = _DATE_TIME.fullmatch(text)
    try:
        if match is None:
            moment = datetime.fromisoformat(text)
        else:
            day, hour, minute, second = match.groups()
            moment = datetime.fromisoformat(day if hour is None else f"{day}T{hour}:{minute}:{second or '00'}")
        key = (moment if moment.tzinfo is not None else moment.replace(tzinfo=timezone.utc)).timestamp()
    except (ValueError, OverflowError):
        raise StampError(where, f"stamp {_shown(text)} is neither an ISO date (2026-03-01), an ISO date "
                         "and time (2026-03-01T08:30:00 or 2026-03-01T08-30-00) nor a sequence number "
                         "(17)") from None
    return key, TIME


def _shown(text: str) -> str:
    """A stamp for a message: quoted, cut to 40 characters (a 5000-digit stamp is not echoed)."""
    return repr(text) if len(text) <= 40 else f"{text[:40]!r}... ({len(text)} characters)"


def stamp_of(name: str, suffixes: tuple[str, ...]) -> str | None:
    """The stamp of a log's file name (its name without the first matching suffix), or None if it
    has none of ``suffixes`` (lower-case, compared case-insensitively)."""
    lower = name.lower()
    for suffix in sorted(suffixes, key=len, reverse=True):
        if lower.endswith(suffix) and len(name) > len(suffix):
            return name[: -len(suffix)]
    return None


def scan(folder: Path, suffixes: tuple[str, ...]) -> tuple[dict[str, list[LogFile]], list[tuple[str, str]]]:
    """The logs of ``folder``, per unit in stamp order, and the files that are not logs.

    Hidden entries (``.name``) are passed over. A file at the top of ``folder`` other than
    ``events.csv``, and a file in a unit folder whose name has none of ``suffixes``, whose stamp
    does not parse or whose link leads out of ``folder`` (:data:`LINK_OUT`: not read), is returned
    in the second list as ``(name, reason)``.

    Raises
    ------
    ValueError
        If ``folder`` is not a folder or holds no unit folder; a unit folder or ``events.csv`` whose
        link leads out of ``folder`` (:class:`faultgen.inputs.InputError`, nothing behind it listed);
        an ``events.csv`` that is not a regular file; an
        entry that is neither a file nor a folder (a FIFO, a broken link); a unit folder or log whose
        name is not UTF-8; two logs of one unit with the same stamp; one unit's stamps of both kinds.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"{folder}: no such folder; expected LOGS/<unit>/<stamp>.csv|.csv.gz|.h5")
    units, bad = {}, []
    for entry in sorted(folder.iterdir()):
        if entry.name.startswith("."):
            continue
        _utf8(entry)
        inputs.within(entry, folder, FOLDER)
        if entry.name == "events.csv":
            if not entry.is_file():
                raise ValueError(f"{entry}: {_kind(entry)}; the events file must be a regular file (unit, stamp, "
                                 "event, axis)")
            continue
        if entry.is_file():  # a stray file (notes.txt) is listed with the files that are not logs
            bad.append((entry.name, "not a log: a file at the top of the logs folder; expected one folder per "
                                    "unit (LOGS/<unit>/<stamp>.csv) and optionally events.csv"))
            continue
        if not entry.is_dir():
            raise ValueError(f"{entry}: neither a unit folder nor events.csv ({_kind(entry)}); expected "
                             "one folder per unit (LOGS/<unit>/<stamp>.csv) and optionally events.csv")
        units[entry.name] = _listing(entry, folder, suffixes, entry.name, bad)
    if not units:
        raise ValueError(f"{folder}: no unit folders; expected LOGS/<unit>/<stamp>.csv|.csv.gz|.h5")
    return units, bad


def _listing(where: Path, folder: Path, suffixes: tuple[str, ...], unit: str, bad: list,
             what: str = "log") -> list[LogFile]:
    """The logs of the folder ``where`` (a unit's, or its :data:`TESTS` folder) in stamp order, the
    files that are not logs added to ``bad`` (:func:`scan`'s rules; a file without a stamp is "not a
    ``what``"); a unit's :data:`TESTS` folder is passed over (its tests are no logs: :func:`scan_tests`)."""
    logs = []
    for path in sorted(where.iterdir()):
        if path.name.startswith("."):
            continue
        _utf8(path)
        name = f"{where.relative_to(folder).as_posix()}/{path.name}"
        if not inputs.inside(path, folder):
            bad.append((name, LINK_OUT))
            continue
        if path.name == TESTS and where.name == unit and path.is_dir():
            continue
        stamp = stamp_of(path.name, suffixes) if path.is_file() else None
        if stamp is None:
            bad.append((name, f"not a {what}: expected <stamp>{' or <stamp>'.join(suffixes)}"))
            continue
        try:
            key, kind = parse_stamp(stamp, name)
        except StampError as err:
            bad.append((name, err.reason))
            continue
        logs.append(LogFile(unit, stamp, key, kind, path, name))
    kinds = {log.kind for log in logs}
    if len(kinds) > 1:
        raise ValueError(f"{where}: the logs mix dates and sequence numbers as stamps "
                         f"({next(g.name for g in logs if g.kind == TIME)}, "
                         f"{next(g.name for g in logs if g.kind == SEQUENCE)}); use one kind per unit")
    logs.sort(key=lambda g: g.key)
    for a, b in zip(logs, logs[1:]):
        if a.key == b.key:
            raise ValueError(f"{a.name} and {b.name} have the same stamp; keep one log per stamp")
    return logs


def scan_tests(folder: Path, units,
               suffixes: tuple[str, ...]) -> tuple[dict[str, list[LogFile]], list[tuple[str, str]]]:
    """Each unit's friction tests, ``LOGS/<unit>/friction-test/<stamp><suffix>`` (:data:`TESTS`), in
    stamp order (units without the folder left out), and the files there that are not tests, as
    :func:`scan` lists a unit's logs: the same suffixes, stamps, names and links (a test folder whose
    link leads out of ``folder`` is refused, :class:`faultgen.inputs.InputError`; a test's link out is
    listed as not a test, never read).

    Raises
    ------
    ValueError
        As :func:`scan` for a unit's logs: a name not UTF-8, two tests of one stamp, stamps of both kinds;
        a ``friction-test`` entry that is not a folder.
    """
    folder = Path(folder)
    found, bad = {}, []
    for unit in units:
        where = folder / unit / TESTS
        if not (where.exists() or where.is_symlink()):
            continue
        inputs.within(where, folder, FOLDER)
        if not where.is_dir():
            raise ValueError(f"{where}: {_kind(where)}; expected a folder of the unit's friction tests "
                             f"(LOGS/<unit>/{TESTS}/<stamp>.csv)")
        found[unit] = _listing(where, folder, suffixes, unit, bad, "friction test")
    return found, bad


def _utf8(path: Path) -> None:
    """Refuse a name that is not UTF-8 (a unit's name is stored as text in the dataset and the
    monitor's tables), shown with its undecodable bytes escaped."""
    try:
        path.name.encode("utf-8")
    except UnicodeEncodeError:
        shown = os.fsencode(path).decode("utf-8", "backslashreplace")
        raise ValueError(f"{shown}: the name is not UTF-8 text; rename it (unit folders and logs are named in "
                         "UTF-8)") from None


def _kind(path: Path) -> str:
    """What ``path`` is, for a message: a folder, a FIFO, a broken symbolic link, ..."""
    try:
        info = path.stat()
    except OSError:
        return "a broken symbolic link" if path.is_symlink() else "not readable"
    return "a regular file" if stat.S_ISREG(info.st_mode) else inputs._kind(info.st_mode)  # its wording of file kinds


def read_events(path: Path, units: dict[str, list[LogFile]], n_axes: int,
                folder: Path | None = None, bad: list[tuple[str, str]] | None = None) -> list[Event]:
    """The rows of ``events.csv`` (module docstring), checked against the units' logs.

    Parameters
    ----------
    folder : Path, optional
        The logs folder the file must lie in (links followed); default the file's own folder.
    bad : list, optional
        Where a bad row goes instead of stopping the read (``faultgen monitor``: a bad row stops its
        unit only): ``(unit, message)``, the message naming the file by its name and the row's line,
        ``unit`` "" for a row that names no unit of ``units``; the row itself passed over.

    Raises
    ------
    ValueError
        Naming the file and line: a header other than :data:`EVENT_COLUMNS`; without ``bad``, a row
        with a unit without a folder, a stamp that does not parse or is of another kind than the
        unit's logs, an unknown event, an axis outside 1..N (empty only for ``healthy``); a file
        whose link leads out of ``folder`` (before it is read: nothing of it is quoted).
    """
    path = inputs.within(path, Path(path).parent if folder is None else folder, FOLDER)
    inputs.regular_file(path, "events file", EVENTS_MAX_BYTES)
    try:
        with inputs.open_bytes(path, "events file", EVENTS_MAX_BYTES) as fh:
            return _events(path, fh, units, n_axes, bad)
    except UnicodeDecodeError:
        inputs.read_text(path, "events file", EVENTS_MAX_BYTES)  # refuses it naming the byte offset in the file
        raise
    except csv.Error as err:
        raise ValueError(f"{path}: cannot read the events: {err}") from None


def _events(path: Path, fh, units: dict[str, list[LogFile]], n_axes: int, bad: list | None = None) -> list[Event]:
    """The events of the open ``events.csv`` (:func:`read_events`), read row by row (no list of rows)."""
    reader = csv.reader(io.TextIOWrapper(fh, encoding="utf-8-sig", newline=""))
    first = next(reader, None)
    header = tuple(cell.strip() for cell in first) if first is not None else ()
    if header != EVENT_COLUMNS:
        raise ValueError(f"{path}: line 1 is {','.join(header) or '(empty)'}; expected the header "
                         f"{','.join(EVENT_COLUMNS)}")
    shared = {name: name for name in (*units, *EVENTS)}  # one string per unit and event, not one per row
    events = []
    for line, row in enumerate(reader, start=2):
        if not any(cell.strip() for cell in row):
            continue
        try:
            events.append(_event(row, line, units, n_axes, shared))
        except ValueError as err:
            if bad is None:
                raise ValueError(f"{path}: {err}") from None
            unit = row[0].strip() if row else ""
            bad.append((unit if unit in units else "", f"{path.name}: {err}"))
    return events


def _event(row: list[str], line: int, units: dict[str, list[LogFile]], n_axes: int, shared: dict) -> Event:
    """The event of ``row`` (line ``line`` of the events file); ValueError naming the line."""
    where = f"line {line}"
    if len(row) != len(EVENT_COLUMNS):
        raise ValueError(f"{where}: {len(row)} fields; expected {len(EVENT_COLUMNS)} ({','.join(EVENT_COLUMNS)})")
    unit, stamp, event, axis = (cell.strip() for cell in row)
    if unit not in units:
        raise ValueError(f"{where}: unit {unit!r} has no folder of logs; units: {', '.join(sorted(units))}")
    key, kind = parse_stamp(stamp, where)
    logs = units[unit]
    if logs and kind != logs[0].kind:
        raise ValueError(f"{where}: stamp {stamp!r} is a {kind} stamp, but the logs of {unit} have {logs[0].kind} "
                         "stamps")
    if event not in EVENTS:
        raise ValueError(f"{where}: event {event!r}; expected one of {', '.join(EVENTS)}")
    if axis == "" and event == "healthy":
        number = 0
    else:
        try:
            number = axes.check(int(axis), n_axes)
        except ValueError:
            raise ValueError(f"{where}: axis {axis!r}; expected an axis 1..{n_axes}"
                             + (" (or empty: every axis)" if event == "healthy" else "")) from None
    return Event(shared[unit], stamp, key, kind, shared[event], number, line)


def labels(keys: np.ndarray, events: list[Event], n_axes: int) -> np.ndarray:
    """Per log and axis, :data:`WORN`, :data:`HEALTHY` or :data:`UNKNOWN` from a unit's events
    (module docstring), ndarray of int8 of shape (n_logs, N).

    Parameters
    ----------
    keys : ndarray of shape (n_logs,)
        The unit's log stamps (:attr:`LogFile.key`), increasing.
    events : list of Event
        The unit's events.
    """
    keys = np.asarray(keys, dtype=float)
    out = np.full((len(keys), n_axes), UNKNOWN, dtype=np.int8)
    for k in range(n_axes):
        column = out[:, k]
        mine = sorted((e for e in events if e.axis in (0, k + 1)), key=lambda e: (e.key, e.line))
        previous, wearing = -np.inf, False  # the key of the axis's previous event; worn since an onset or failure
        for event in mine:
            before = np.flatnonzero(keys <= event.key)
            if event.event == "onset":
                column[keys >= event.key] = WORN
                wearing = True
            elif event.event == "failure":
                if not wearing and before.size:
                    column[before[-1]] = WORN
                column[keys > event.key] = WORN
                wearing = True
            elif event.event in ("repair", "gearbox_change"):
                earlier = np.flatnonzero(keys < event.key)
                if not wearing and earlier.size:
                    column[earlier[-1]] = WORN
                column[keys >= event.key] = HEALTHY
                wearing = False
            else:  # healthy
                column[(keys > previous) & (keys <= event.key)] = HEALTHY
            previous = event.key
    return out
