"""What ``faultgen monitor`` keeps in ``OUT`` between runs, in formats that cannot run code.

An output folder may come from someone else (docs/reliability.md, "Threat model: output folders"),
so nothing in it is unpickled or imported, nothing it names is opened outside ``OUT`` and ``LOGS``,
and every file is checked against the settings and inputs it belongs to before it is used:

- ``OUT/.state/<unit>.json`` (:func:`write_unit`, :func:`read_unit`): the inputs the unit's monitor
  was fed, one entry per scored log (stamp, the log's SHA-256, its residual, mean joint temperature,
  payload and the twin's expectation), the twin's wear signatures, the log whose motion the twin
  replays (by unit and stamp inside ``LOGS``, never a path) and the digest of the run's settings
  (:func:`settings_digest`). A rerun replays these entries into a new
  :class:`~faultgen.monitor.scoring.UnitMonitor` (:func:`replay`): the same arithmetic in the same
  order, so the continued monitor is bit for bit the one the earlier run ended with.
- ``OUT/.cache/cycles/<digest>.json`` (:func:`write_cycle`, :func:`read_cycle`): one simulated
  cycle's features beside the key that determined them (model and program SHA-256, friction model,
  temperature, payload, worn axis); a file whose key is not the one asked for, or whose features
  are not finite numbers of the expected length, is refused.
- ``OUT/.cache/calibrated/<digest>/`` and ``<digest>.json`` (:func:`write_calibration`,
  :func:`read_calibration`): a unit's calibration, under the digest of what it was made from, and
  a record of the calibrated model's SHA-256; the model itself is loaded as any robot description
  (:func:`faultgen.model.robots.load`: no file outside its folder, no plugin).

Every refusal is a :class:`StateError` (a :class:`faultgen.inputs.InputError`) naming the file and what did not match, and
saying what to do (score into a new ``OUT``, or delete the named file).
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from faultgen import inputs
from faultgen.data import atomic, logfolder
from faultgen.data.confined import Confined
from faultgen.monitor import programs
from faultgen.monitor.scoring import Settings, UnitMonitor

#: The state files' format: 2, three features per axis (with ``friction_torque``); a state of
#: format 1 holds residuals of two and is refused (a new OUT).
FORMAT = "faultgen-monitor-state/2"
CYCLE_FORMAT = "faultgen-twin-cycle/1"
CALIBRATION_FORMAT = "faultgen-monitor-calibration/1"
#: Size bound of one unit's state file, written (:func:`write_unit` refuses a larger one) and read back
#: (checked before it is parsed): about 0.85 kB per scored log with its load record, so some 20 000 logs (a log an hour for
#: two years). ``json`` takes up to 27 times the file's size to parse (a file of empty lists): 0.44 GB.
STATE_MAX_BYTES = 16 * 2**20
#: The entries of ``OUT/.cache`` (module docstring; ``programs``: the twins' replayed motion, which earlier versions wrote;
#: ``friction-tests``: the tests' readings, :mod:`faultgen.monitor.friction_tests`).
CACHE = ("cycles", "calibrated", "programs", "friction-tests")
#: Events of ``events.csv`` given to a unit's monitor (and kept in its state): after them its
#: offset is learned again and its open alarm closed.
MAINTENANCE = ("repair", "gearbox_change")
#: Size bound of one cached cycle (a few hundred bytes).
CYCLE_MAX_BYTES = 2**20


class StateError(inputs.InputError):
    """A state or cache file in OUT refused (module docstring): it stops the run as a whole, before
    any output is written, where a unit's own trouble (a log, a twin) only degrades that unit."""


def sha256_file(path: str | Path) -> str:
    """SHA-256 of a file's bytes (a robot model, a log), hex, through :func:`faultgen.inputs.sha256_of`:
    a regular file of at most :data:`faultgen.logs.columns.LOG_MAX_BYTES`, its size checked before
    the read (a sparse file of terabytes apparent was hashed whole). InputError naming the file otherwise."""
    from faultgen.logs.columns import LOG_MAX_BYTES

    return inputs.sha256_of(path, "file", LOG_MAX_BYTES)


#: Longest unit name kept as it is in a file name of OUT (``<unit>.png``, ``.state/<unit>.json``),
#: UTF-8 bytes: with its suffix and an atomic write's temporary name (``.<name>.<pid>@<host>.XXXXXXXX.part``,
#: up to 87 bytes more) it stays within the 255 bytes a file name may have.
UNIT_FILE_MAX_BYTES = 128


def unit_file(unit: str, suffix: str) -> str:
    """The file name of ``unit``'s chart or state in OUT: ``<unit><suffix>``, or for a name longer
    than :data:`UNIT_FILE_MAX_BYTES` bytes its first 100 bytes (whole characters), ``-`` and 16 hex
    digits of the SHA-256 of the whole name (units.csv and the state itself keep the whole name)."""
    raw = unit.encode("utf-8")
    if len(raw) <= UNIT_FILE_MAX_BYTES:
        return unit + suffix
    return f"{raw[:100].decode('utf-8', 'ignore')}-{hashlib.sha256(raw).hexdigest()[:16]}{suffix}"


def key_name(key: dict) -> str:
    """The file name of a cache entry made from ``key`` (a JSON-able dict): the first 24 hex digits
    of the SHA-256 of its canonical JSON."""
    return hashlib.sha256(json.dumps(key, sort_keys=True).encode()).hexdigest()[:24]


def settings_digest(settings: Settings, model: str, twin_temperature: bool, robot_sha256: str,
                    log_format: str = "measured") -> dict:
    """What a state belongs to, as a JSON-able dict: the monitor's settings, the model source
    ("nominal", "per-unit" or the SHA-256 of a given calibrated model), whether the twin predicts
    the temperature's effect, the SHA-256 of the robot's MJCF and the logs' format (with its
    options)."""
    return {**asdict(settings), "model": model, "twin_temperature": bool(twin_temperature), "robot": robot_sha256,
            "format": log_format}


@dataclass(frozen=True)
class Entry:
    """One scored log as the monitor was fed it: ``stamp``, the log file's ``sha256``, its
    ``residual`` (n_features,), mean joint ``temperature`` (deg C, NaN when not logged), ``payload``
    (kg), the twin's ``expected`` features (n_features,; None without a twin), the log's ``load``
    (:func:`faultgen.monitor.life.load_integrals`, (2, n_axes): what the rated life it consumed is
    computed from; None in a state written before it) and its ``duration`` (s)."""

    stamp: str
    sha256: str
    residual: np.ndarray
    temperature: float
    payload: float
    expected: np.ndarray | None
    load: np.ndarray | None = None
    duration: float = math.nan
    program: int = 0  # the unit's program it ran: 0 its first, k the k-th of program_changes


@dataclass(frozen=True)
class Skipped:
    """A log the monitor could not score (unreadable, or its twin could not replay it): ``stamp``,
    the file's ``sha256`` and the ``reason``."""

    stamp: str
    sha256: str
    reason: str


@dataclass(frozen=True)
class Maintenance:
    """A repair or gearbox change (``event``) of ``axis`` at ``stamp``, given to the unit's monitor
    before its entry number ``at`` (:meth:`faultgen.monitor.scoring.UnitMonitor.maintenance`)."""

    stamp: str
    event: str
    axis: int
    at: int

    @property
    def identity(self) -> tuple[str, str, int]:
        """``(stamp, event, axis)``: the same for the same event of ``events.csv`` (wherever it was given)."""
        return self.stamp, self.event, self.axis


@dataclass(frozen=True)
class ProgramChange:
    """The unit ran another program from log ``stamp`` on (not logged: its motion left the twin's
    program); its monitor restarted before its entry number ``at`` with the twin of ``program``
    (unit, stamp) and that twin's ``signatures`` (n_axes, n_features); ``source`` the torque source
    of its logs (:mod:`faultgen.monitor.sources`: a change of source alone is a program change on
    the program's own log), "" when unnamed (written only when named)."""

    stamp: str
    program: tuple[str, str]
    at: int
    signatures: np.ndarray
    source: str = ""


#: A unit's model kinds: a given calibrated model, its own calibration, its own friction on the
#: nominal model (:data:`faultgen.monitor.unit.FALLBACK`), the nominal model, none.
MODELS = ("given", "calibrated", "friction", "nominal", "none")


@dataclass
class UnitState:
    """A unit's state (module docstring): ``program`` the (unit, stamp) of the log its twin replays
    (None without a twin), ``signatures`` (n_axes, n_features) of its first program's twin (those of
    each later program are in ``program_changes``) or None, ``entries`` in stamp order,
    ``model`` of :data:`MODELS` ("none": protocol own), ``first`` the (stamp, SHA-256) of the unit's
    first log, the logs ``skipped``, the ``notes`` on fallbacks taken and the ``maintenance``
    events given to its monitor."""

    unit: str
    settings: dict
    program: tuple[str, str] | None
    signatures: np.ndarray | None
    entries: list[Entry]
    model: str = "nominal"
    first: tuple[str, str] = ("", "")
    skipped: list[Skipped] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    maintenance: list[Maintenance] = field(default_factory=list)
    program_changes: list[ProgramChange] = field(default_factory=list)
    torque_source: str = ""  # its logs' torque source (faultgen.logs.formats.torque_source); "" unnamed
    off_monitor: str = ""  # why it was taken off the monitor; "" while on it


def replay(state: UnitState, settings: Settings, n_axes: int, tests=None) -> UnitMonitor:
    """A :class:`UnitMonitor` fed ``state``'s entries in order, each with its program's baseline
    (:mod:`faultgen.monitor.programs`): the monitor the run that wrote ``state`` ended with
    (``tests``: its friction tests' scale, :attr:`UnitMonitor.tests`, given before the entries)."""
    monitor = UnitMonitor(state.unit, settings, n_axes, state.signatures)
    monitor.wear.tests = tests
    maintenance: dict[int, list[Maintenance]] = {}
    for m in state.maintenance:  # grouped by entry, in their order: each looked at once
        maintenance.setdefault(m.at, []).append(m)
    changes: dict[int, list[ProgramChange]] = {}
    for c in state.program_changes:
        changes.setdefault(c.at, []).append(c)
    baselines = programs.baselines_of(monitor)
    for i, e in enumerate(state.entries):
        for m in maintenance.get(i, ()):
            baselines.maintenance(monitor, m.stamp, m.event, m.axis)
        for c in changes.get(i, ()):
            baselines.new(monitor, c.signatures)
        baselines.run(monitor, e.program, lambda e=e: monitor.add(e.stamp, e.residual, e.temperature, e.payload,
                                                                  e.expected))
    for m in maintenance.get(len(state.entries), ()):
        baselines.maintenance(monitor, m.stamp, m.event, m.axis)
    return monitor


def _program(log: dict, path: Path, where: str, known: int) -> int:
    """A stored log's program index (0 when not written: the unit's first), checked against the
    ``known`` programs after the first."""
    program = log.get("program", 0)
    if isinstance(program, bool) or not isinstance(program, int) or not 0 <= program <= known:
        raise StateError(f"{path}: {where}.program = {str(program)[:40]!r}; expected a program index 0..{known} "
                         "(0: the unit's first program, k: its k-th program change)")
    return program


def _floats(values) -> list[float]:
    return [float(v) for v in np.ravel(values)]


def write_unit(path: Path, state: UnitState) -> None:
    """Write ``state`` as JSON (floats written exactly: ``repr`` round-trips; NaN as ``NaN``).

    Raises
    ------
    StateError
        The state would be larger than :data:`STATE_MAX_BYTES` (a later run could not read it back);
        nothing is written.
    """
    document = {
        "format": FORMAT, "unit": state.unit, "settings": state.settings,
        "program": list(state.program) if state.program else None,
        "model": state.model, "first": list(state.first), "notes": list(state.notes),
        "torque_source": state.torque_source, "off_monitor": state.off_monitor,
        "skipped": [{"stamp": k.stamp, "sha256": k.sha256, "reason": k.reason} for k in state.skipped],
        "maintenance": [{"stamp": m.stamp, "event": m.event, "axis": m.axis, "at": m.at} for m in state.maintenance],
        "program_changes": [{"stamp": c.stamp, "program": list(c.program), "at": c.at,
                             "signatures": [_floats(row) for row in c.signatures],
                             **({"source": c.source} if c.source else {})} for c in state.program_changes],
        "signatures": None if state.signatures is None else [_floats(row) for row in state.signatures],
        "logs": [{"stamp": e.stamp, "sha256": e.sha256, "residual": _floats(e.residual),
                  "temperature_C": float(e.temperature), "payload_kg": float(e.payload),
                  "expected": None if e.expected is None else _floats(e.expected),
                  **({} if e.load is None else {"load": _floats(e.load), "duration_s": float(e.duration)}),
                  **({"program": e.program} if e.program else {})}
                 for e in state.entries],
    }
    text = json.dumps(document, separators=(",", ":"))
    if len(text) > STATE_MAX_BYTES:
        raise StateError(f"{path}: the state of {state.unit} would be {len(text)} bytes ({len(state.entries)} logs); "
                         f"a state is kept up to {STATE_MAX_BYTES} bytes: score the later logs into a new OUT")
    atomic.write_text(path, text)


def out_folder(out: str | Path) -> Confined:
    """``OUT`` as the monitor reads and writes it (:class:`faultgen.data.confined.Confined`): a path
    that leads, through a link, outside it is refused as a :class:`StateError` naming it (an output
    folder never makes faultgen read or write outside itself)."""
    return Confined(out, "monitor output folder", StateError)


def checked_out(out: str | Path) -> Confined:
    """:func:`out_folder` after checking, before a run reads or writes anything there, that OUT's
    ``.state``, ``.cache`` and each :data:`CACHE` entry, where they exist, lead inside OUT, and that an
    existing OUT takes new files (a read-only OUT refused before the work, not after it). A killed
    run's stage in OUT is removed first (:func:`faultgen.data.atomic.remove_stale`), giving back a
    ``.state`` it had moved aside and not replaced, so that the state read is the last one written.

    Raises
    ------
    StateError
        One of them is a link leading outside OUT (named).
    OSError
        OUT is on a read-only file system, takes no new file or is full (:func:`faultgen.data.atomic.check_writable`).
    """
    if Path(out).is_dir():
        atomic.remove_stale(out)
        atomic.check_writable(Path(out) / ".state")
    confined = out_folder(out)
    for entry in (".state", ".cache", *(f".cache/{name}" for name in CACHE)):
        confined.path(Path(out) / entry)
    return confined


def inside(path: Path, root: Path) -> Path:
    """``path`` after checking that it leads inside ``root`` (:func:`out_folder`)."""
    return out_folder(root).path(path)


def _load_json(path: Path, what: str, max_bytes: int) -> dict:
    try:
        text = inputs.read_text(path, what, max_bytes)
    except inputs.InputError as err:
        raise StateError(str(err)) from None
    try:
        document = json.loads(text)
    except (ValueError, RecursionError) as err:
        raise StateError(f"{path}: not a {what} ({type(err).__name__}: {str(err)[:80]})") from None
    if not isinstance(document, dict):
        raise StateError(f"{path}: not a {what} (expected a JSON object)")
    return document


def _vector(value, path: Path, name: str, length: int, finite: bool = True) -> np.ndarray:
    if not (isinstance(value, list) and len(value) == length
            and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
        raise StateError(f"{path}: {name} is not a list of {length} numbers")
    array = np.asarray(value, dtype=float)
    if finite and not np.all(np.isfinite(array)):
        raise StateError(f"{path}: {name} holds a value that is not a finite number")
    return array


def _number(value, path: Path, name: str) -> float:
    if not isinstance(value, (int, float)) or isinstance(value, bool):
        raise StateError(f"{path}: {name} = {str(value)[:40]!r} is not a number")
    return float(value)


def _stamp(value, path: Path, name: str, refuse: str) -> float:
    """The key of a stamp read from a state (:func:`faultgen.data.logfolder.parse_stamp`)."""
    if not isinstance(value, str):
        raise StateError(f"{path}: {name} is not a stamp{refuse}")
    try:
        return logfolder.parse_stamp(value, f"{path}: {name}")[0]
    except ValueError as err:
        raise StateError(f"{err}{refuse}") from None


def _digest(value, path: Path, name: str, refuse: str, empty: bool = False) -> str:
    """A SHA-256 read from a state: 64 lower-case hex digits (or, with ``empty``, "": a log that
    could not be read at all)."""
    if not (isinstance(value, str) and ((empty and value == "") or (len(value) == 64 and all(
            c in "0123456789abcdef" for c in value)))):
        raise StateError(f"{path}: {name} is not a SHA-256 (64 hex digits){refuse}")
    return value


def _load(log: dict, path: Path, where: str, n_axes: int) -> tuple[np.ndarray | None, float]:
    """An entry's ``load`` and ``duration_s`` (:class:`Entry`): both or neither; the load's values
    >= 0, the duration > 0."""
    if "load" not in log and "duration_s" not in log:
        return None, math.nan
    load = _vector(log.get("load"), path, f"{where}.load", 2 * n_axes).reshape(2, n_axes)
    duration = _number(log.get("duration_s"), path, f"{where}.duration_s")
    if np.any(load < 0) or not (math.isfinite(duration) and duration > 0):
        raise StateError(f"{path}: {where}: load below 0 or duration_s not a finite number > 0")
    return load, duration


def setting_moved(key: str, then, now, robot: str = "") -> str:
    """A setting of a state that differs from the run's, for its refusal: the robot's and a given
    model's file by what they are and the first 12 hex digits of each SHA-256 (the run's robot named
    ``robot``), any other by its values."""
    if key in ("robot", "model") and isinstance(then, str) and isinstance(now, str) and len(then) == len(now) == 64:
        what = f"the robot model{f' {robot}' if robot else ''}" if key == "robot" else "the given --calibrated model"
        return (f"{what}: its model file is not the one the state was made with (SHA-256 {str(then)[:12]}... then, "
                f"{now[:12]}... now: another robot or an edited model file)")
    return f"{key} {then!r} (now {now!r})"


def read_unit(path: Path, root: Path, unit: str, settings: dict, n_axes: int, n_features: int,
              robot: str = "") -> UnitState:
    """Read and check the state of ``unit`` written by :func:`write_unit`: every value one a run
    writes (stamps that parse, the logs' in increasing order and each stamp handled once, SHA-256s
    of 64 hex digits, finite numbers where a run writes them: a temperature finite or NaN (not
    logged), a maintenance event of :data:`MAINTENANCE` on an axis 1..``n_axes``, given before an
    entry that exists).

    Raises
    ------
    StateError
        The file is a link leading outside ``root`` or not a regular file, is above :data:`STATE_MAX_BYTES`, is not
        such a state, belongs to another unit or to other settings (the differing settings named),
        or holds a value of the wrong type, length or range (named; a changed model file by what it
        is, the robot ``robot`` by its name, not by a digest alone: :func:`setting_moved`).
    """
    refuse = f"; score the logs into a new OUT (or delete {path.parent} to start this one again)"
    d = _load_json(inside(path, root), "monitor state", STATE_MAX_BYTES)
    if d.get("format") != FORMAT:
        raise StateError(f"{path}: format {str(d.get('format'))[:40]!r}, expected {FORMAT!r} (a state written by "
                         f"another version of faultgen, whose monitor watched other features){refuse}")
    if d.get("unit") != unit:
        raise StateError(f"{path}: the state of unit {str(d.get('unit'))[:40]!r}, expected {unit!r}{refuse}")
    if d.get("settings") != settings:
        theirs = d.get("settings") if isinstance(d.get("settings"), dict) else {}
        moved = [setting_moved(k, theirs.get(k), v, robot) for k, v in settings.items() if theirs.get(k) != v]
        raise StateError(f"{path}: holds a monitor run with other settings or inputs: "
                                f"{', '.join(moved) or 'unknown keys'}{refuse}")
    program = d.get("program")
    if program is not None and not (isinstance(program, list) and len(program) == 2
                                    and all(isinstance(p, str) for p in program)):
        raise StateError(f"{path}: program is not [unit, stamp]{refuse}")
    if program is not None:
        _stamp(program[1], path, "program[1]", refuse)
    signatures = d.get("signatures")
    if signatures is not None:
        if not (isinstance(signatures, list) and len(signatures) == n_axes):
            raise StateError(f"{path}: signatures is not a list of {n_axes} rows{refuse}")
        signatures = np.stack([_vector(row, path, f"signatures row {i + 1}", n_features)
                               for i, row in enumerate(signatures)])
    model, first, notes, skipped = d.get("model"), d.get("first"), d.get("notes"), d.get("skipped")
    if model not in MODELS:
        raise StateError(f"{path}: model {str(model)[:40]!r} is not one of {', '.join(MODELS)}{refuse}")
    if not (isinstance(first, list) and len(first) == 2 and all(isinstance(p, str) for p in first)):
        raise StateError(f"{path}: first is not [stamp, sha256]{refuse}")
    _stamp(first[0], path, "first[0]", refuse)
    _digest(first[1], path, "first[1]", refuse, empty=True)
    if not (isinstance(notes, list) and all(isinstance(n, str) for n in notes)):
        raise StateError(f"{path}: notes is not a list of texts{refuse}")
    facts = {k: d.get(k, "") for k in ("torque_source", "off_monitor")}  # "": a state written before they were kept
    if not all(isinstance(v, str) for v in facts.values()):
        raise StateError(f"{path}: torque_source or off_monitor is not a text{refuse}")
    if not (isinstance(skipped, list) and all(
            isinstance(k, dict) and all(isinstance(k.get(f), str) for f in ("stamp", "sha256", "reason"))
            for k in skipped)):
        raise StateError(f"{path}: skipped is not a list of {{stamp, sha256, reason}}{refuse}")
    handled = {}  # stamp key -> where: each log is scored or skipped once
    for i, k in enumerate(skipped):
        key = _stamp(k["stamp"], path, f"skipped[{i}].stamp", refuse)
        _digest(k["sha256"], path, f"skipped[{i}].sha256", refuse, empty=True)
        if handled.setdefault(key, f"skipped[{i}]") != f"skipped[{i}]":
            raise StateError(f"{path}: skipped[{i}] has the stamp of {handled[key]}{refuse}")
    maintenance = d.get("maintenance")
    if not (isinstance(maintenance, list) and all(
            isinstance(m, dict) and isinstance(m.get("stamp"), str) and isinstance(m.get("event"), str)
            and all(isinstance(m.get(f), int) and not isinstance(m.get(f), bool) and m.get(f) >= 0 for f in ("axis", "at"))
            for m in maintenance)):
        raise StateError(f"{path}: maintenance is not a list of {{stamp, event, axis, at}}{refuse}")
    for i, m in enumerate(maintenance):
        _stamp(m["stamp"], path, f"maintenance[{i}].stamp", refuse)
        if m["event"] not in MAINTENANCE:
            raise StateError(f"{path}: maintenance[{i}].event = {m['event'][:40]!r}; expected one of "
                             f"{', '.join(MAINTENANCE)}{refuse}")
        if not 1 <= m["axis"] <= n_axes:
            raise StateError(f"{path}: maintenance[{i}].axis = {m['axis']}; expected an axis 1..{n_axes}{refuse}")
        if i and m["at"] < maintenance[i - 1]["at"]:
            raise StateError(f"{path}: maintenance[{i}].at is before maintenance[{i - 1}].at{refuse}")
    changes = d.get("program_changes", [])
    if not isinstance(changes, list):
        raise StateError(f"{path}: program_changes is not a list{refuse}")
    program_changes = []
    for i, c in enumerate(changes):
        if not (isinstance(c, dict) and isinstance(c.get("stamp"), str) and isinstance(c.get("at"), int)
                and not isinstance(c.get("at"), bool) and c["at"] >= 0 and isinstance(c.get("program"), list)
                and len(c["program"]) == 2 and all(isinstance(p, str) for p in c["program"])
                and isinstance(c.get("signatures"), list) and len(c["signatures"]) == n_axes
                and isinstance(c.get("source", ""), str)):
            raise StateError(f"{path}: program_changes[{i}] is not {{stamp, program, at, signatures}}{refuse}")
        rows = np.stack([_vector(r, path, f"program_changes[{i}].signatures row {k + 1}", n_features)
                         for k, r in enumerate(c["signatures"])])
        _stamp(c["stamp"], path, f"program_changes[{i}].stamp", refuse)
        _stamp(c["program"][1], path, f"program_changes[{i}].program[1]", refuse)
        program_changes.append(ProgramChange(c["stamp"], tuple(c["program"]), c["at"], rows, c.get("source", "")))
    if (model == "none") != (program is None):
        raise StateError(f"{path}: model {model!r} with program {program!r}{refuse}")
    logs = d.get("logs")
    if not isinstance(logs, list):
        raise StateError(f"{path}: logs is not a list{refuse}")
    entries, last = [], -math.inf
    for i, log in enumerate(logs):
        where = f"logs[{i}]"
        if not (isinstance(log, dict) and isinstance(log.get("stamp"), str) and isinstance(log.get("sha256"), str)):
            raise StateError(f"{path}: {where} has no stamp or SHA-256{refuse}")
        key = _stamp(log["stamp"], path, f"{where}.stamp", refuse)
        _digest(log["sha256"], path, f"{where}.sha256", refuse)
        if handled.setdefault(key, where) != where:
            raise StateError(f"{path}: {where} has the stamp of {handled[key]}{refuse}")
        if entries and key <= last:
            raise StateError(f"{path}: {where}.stamp {log['stamp']!r} is not after logs[{i - 1}]'s; a run scores logs "
                             f"in stamp order{refuse}")
        last = key
        expected = log.get("expected")
        entries.append(Entry(
            log["stamp"], log["sha256"], _vector(log.get("residual"), path, f"{where}.residual", n_features),
            _number(log.get("temperature_C"), path, f"{where}.temperature_C"),
            _number(log.get("payload_kg"), path, f"{where}.payload_kg"),
            None if expected is None else _vector(expected, path, f"{where}.expected", n_features),
            *_load(log, path, where, n_axes), _program(log, path, where, len(changes))))
        if not math.isfinite(entries[-1].payload):
            raise StateError(f"{path}: {where}.payload_kg is not a finite number{refuse}")
        if math.isinf(entries[-1].temperature):  # NaN: not logged
            raise StateError(f"{path}: {where}.temperature_C is infinite; expected a finite number, or NaN when the log "
                             f"has no temperature{refuse}")
    for name, items in (("maintenance", maintenance), ("program_changes", changes)):
        late = next((i for i, m in enumerate(items) if m["at"] > len(entries)), None)
        if late is not None:
            raise StateError(f"{path}: {name}[{late}].at = {items[late]['at']}, after the {len(entries)} logs "
                             f"scored{refuse}")
    return UnitState(unit, settings, tuple(program) if program else None, signatures, entries, model, tuple(first),
                     [Skipped(k["stamp"], k["sha256"], k["reason"]) for k in skipped], list(notes),
                     [Maintenance(m["stamp"], m["event"], m["axis"], m["at"]) for m in maintenance], program_changes,
                     **facts)


def write_cycle(path: Path, root: Path, key: dict, features: np.ndarray) -> None:
    """Cache one simulated cycle's ``features`` beside the ``key`` that determined them, at ``path``
    inside ``root`` (:func:`out_folder`: a link leading out is refused, nothing written)."""
    out_folder(root).write_text(path, json.dumps({"format": CYCLE_FORMAT, "key": key, "features": _floats(features)}))


def read_cycle(path: Path, root: Path, key: dict, n_features: int) -> np.ndarray:
    """The cached features of the cycle ``key``, checked (module docstring).

    Raises
    ------
    StateError
        The file is a link leading outside ``root``, is not a cached cycle of ``key`` or its features are not ``n_features`` finite numbers.
    """
    d = _load_json(inside(path, root), "cached twin cycle", CYCLE_MAX_BYTES)
    if d.get("format") != CYCLE_FORMAT or d.get("key") != key:
        raise StateError(f"{path}: not the cached twin cycle of {key} (another model, program or condition); "
                                "delete it (the twin simulates it again)")
    return _vector(d.get("features"), path, "features", n_features)


def write_calibration(path: Path, root: Path, key: dict, model: Path) -> None:
    """Record that the calibration in ``model``'s folder was made from ``key`` (the nominal model's
    and the log's SHA-256 and the search's length), with ``model``'s own SHA-256, at ``path``
    inside ``root`` (:func:`out_folder`)."""
    folder = out_folder(root)
    folder.write_text(path, json.dumps({"format": CALIBRATION_FORMAT, "key": key,
                                        "model": sha256_file(folder.path(model))}))


def read_calibration(path: Path, root: Path, key: dict, model: Path) -> None:
    """Check a cached calibration's record against ``key`` and the model file it names.

    Raises
    ------
    StateError
        The record or the model is a link out of ``root``, the record belongs to another key, or
        the model file is missing or is not the one the record was written for.
    """
    d = _load_json(inside(path, root), "cached calibration record", CYCLE_MAX_BYTES)
    fix = f"; delete {path} and {path.with_suffix('')} (the unit is calibrated again)"
    if d.get("format") != CALIBRATION_FORMAT or d.get("key") != key:
        raise StateError(f"{path}: not the calibration of this robot and log{fix}")
    if not Path(model).is_file() or sha256_file(inside(model, root)) != d.get("model"):
        raise StateError(f"{model}: not the calibrated model its record {path.name} was written for{fix}")
