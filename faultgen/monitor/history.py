"""One record per unit of ``faultgen monitor`` (:class:`UnitHistory`: what its monitor was fed, as
typed fields) and its JSON, the saved state ``OUT/.state/<unit>.json`` (:func:`write_unit`,
:func:`read_unit`). A rerun replays its entries into new stages
(:func:`faultgen.monitor.steps.replay`): the same arithmetic in the same order, so the continued
monitor is bit for bit the one the earlier run ended with. An output folder
may come from someone else (docs/reliability.md, "Threat model: output folders"): the file is read
inside ``OUT`` only, bounded by :data:`faultgen.monitor.state.STATE_MAX_BYTES` before it is parsed,
every value checked (:func:`read_unit`), logs named by unit and stamp, never by a path.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from faultgen.data import atomic, logfolder
from faultgen.logs import measured
from faultgen.monitor.record import LogRow
from faultgen.monitor.scoring import Stages
from faultgen.monitor.state import STATE_MAX_BYTES, StateError, floats, load_json, checked_vector, inside

#: The state files' format: 3, each note of a unit's reason with its kind (:class:`Note`; a column note
#: with its log and the reader's note too: plain in a state written before, so noted again from the next
#: log); a state of format 2 (notes as bare text, whose kind was recovered by matching their start)
#: or 1 (residuals of two features per axis) is refused (a new OUT).
FORMAT = "faultgen-monitor-state/3"
#: Events of ``events.csv`` given to a unit's monitor (and kept in its state): after them its
#: offset is learned again and its open alarm closed.
MAINTENANCE = ("repair", "gearbox_change")


#: The kinds of a unit's notes that a run acts on (:class:`Note`): its twin fell back to another
#: model (:func:`faultgen.monitor.unit.chain_notes`), its first log refused and the unit taken off
#: the monitor (:func:`faultgen.monitor.unit.refuse`), a log reader's note on a column (``log STAMP:
#: note``, :func:`faultgen.monitor.logs.log_notes`; life.csv's verdict of its axis ends with it).
FALLBACK, REFUSED, COLUMN = "fallback", "refused", "column"
NOTE_KINDS = ("", FALLBACK, REFUSED, COLUMN)


class Note(str):
    """A note of a unit's reason (units.csv), as written, with its ``kind`` (:data:`NOTE_KINDS`; ""
    a note nothing acts on), so that no fact is recovered from its text; one of kind :data:`COLUMN`
    with the ``log`` (stamp) and the reader's ``column`` note (:class:`faultgen.logs.measured.ColumnNote`)."""

    def __new__(cls, text: str, kind: str = "", log: str = "", column: measured.ColumnNote | None = None):
        note = super().__new__(cls, text)  # the defaults: unpickled, its fields set after
        note.kind, note.log, note.column = kind, log, column
        return note

    def document(self) -> dict:
        """The note as the saved state writes it: ``text``, ``kind`` unless "", and for a column note its
        ``log`` and the reader's ``column`` note (``text``, ``axis``, ``kind``; read back by :func:`read_unit`)."""
        out = {"text": str(self), **({"kind": self.kind} if self.kind else {})}
        if self.column is not None:
            out.update(log=self.log, column={"text": str(self.column), "axis": self.column.axis,
                                             "kind": self.column.kind})
        return out


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
    before its entry number ``at`` (:func:`faultgen.monitor.steps.maintenance`)."""

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
class UnitHistory:
    """One unit's record (module docstring), the monitor's saved state: ``unit`` its name, ``model``
    of :data:`MODELS` ("none": protocol own), ``program`` the (unit, stamp) of the log its twin
    replays (None without a twin), ``first`` the (stamp, SHA-256) of its first log (which its
    calibration is made from), ``signatures`` (n_axes, n_features) of its first program's twin
    (those of each later program are in ``program_changes``; None until its twin is built), its
    scored logs (``entries``, in stamp order), the logs ``skipped``, the ``notes`` of its reason, the
    ``maintenance`` events and ``program_changes`` given to its monitor, its logs' ``torque_source``
    (:func:`faultgen.logs.formats.torque_source`; "" unnamed) and why it was taken ``off_monitor``
    ("" while on it).

    Not saved, rebuilt by a run: ``stages`` fed its entries (:class:`~faultgen.monitor.scoring.Stages`,
    :func:`faultgen.monitor.steps.replay`), the ``rows`` they made (each log's
    :class:`~faultgen.monitor.record.LogRow`, in stamp order), the ``references`` of its programs in
    the order met (learned from their logs when needed: :mod:`faultgen.monitor.programs`) and the
    twins of its programs after the first (``program_twins``)."""

    unit: str
    model: str = "nominal"
    program: tuple[str, str] | None = None
    first: tuple[str, str] = ("", "")
    signatures: np.ndarray | None = None
    entries: list[Entry] = field(default_factory=list)
    skipped: list[Skipped] = field(default_factory=list)
    notes: list[Note] = field(default_factory=list)  # its reason's notes, in order
    maintenance: list[Maintenance] = field(default_factory=list)
    program_changes: list[ProgramChange] = field(default_factory=list)
    torque_source: str = ""
    off_monitor: str = ""
    stages: Stages | None = field(default=None, repr=False, compare=False)
    rows: list[LogRow] = field(default_factory=list, repr=False, compare=False)
    references: list | None = field(default=None, repr=False, compare=False)
    program_twins: dict = field(default_factory=dict, repr=False, compare=False)

    def saved_signatures(self) -> np.ndarray | None:
        """The signatures a replay starts with: its first program's twin's, or, when none was
        kept, those its stages hold."""
        if self.signatures is None and self.stages is not None:
            return self.stages.baseline.signatures
        return self.signatures


def _program(log: dict, path: Path, where: str, known: int) -> int:
    """A stored log's program index (0 when not written: the unit's first), checked against the
    ``known`` programs after the first."""
    program = log.get("program", 0)
    if isinstance(program, bool) or not isinstance(program, int) or not 0 <= program <= known:
        raise StateError(f"{path}: {where}.program = {str(program)[:40]!r}; expected a program index 0..{known} "
                         "(0: the unit's first program, k: its k-th program change)")
    return program


def write_unit(path: Path, state: UnitHistory, settings: dict) -> None:
    """Write ``state`` as JSON of :data:`FORMAT` under ``settings``
    (:func:`faultgen.monitor.state.settings_digest`; floats written exactly: ``repr`` round-trips;
    NaN as ``NaN``).

    Raises
    ------
    StateError
        The state would be larger than :data:`STATE_MAX_BYTES` (a later run could not read it back);
        nothing is written.
    """
    signatures = state.saved_signatures()
    document = {
        "format": FORMAT, "unit": state.unit, "settings": settings,
        "program": list(state.program) if state.program else None,
        "model": state.model, "first": list(state.first),
        "notes": [n.document() for n in state.notes],
        "torque_source": state.torque_source, "off_monitor": state.off_monitor,
        "skipped": [{"stamp": k.stamp, "sha256": k.sha256, "reason": k.reason} for k in state.skipped],
        "maintenance": [{"stamp": m.stamp, "event": m.event, "axis": m.axis, "at": m.at} for m in state.maintenance],
        "program_changes": [{"stamp": c.stamp, "program": list(c.program), "at": c.at,
                             "signatures": [floats(row) for row in c.signatures],
                             **({"source": c.source} if c.source else {})} for c in state.program_changes],
        "signatures": None if signatures is None else [floats(row) for row in signatures],
        "logs": [{"stamp": e.stamp, "sha256": e.sha256, "residual": floats(e.residual),
                  "temperature_C": float(e.temperature), "payload_kg": float(e.payload),
                  "expected": None if e.expected is None else floats(e.expected),
                  **({} if e.load is None else {"load": floats(e.load), "duration_s": float(e.duration)}),
                  **({"program": e.program} if e.program else {})}
                 for e in state.entries],
    }
    text = json.dumps(document, separators=(",", ":"))
    if len(text) > STATE_MAX_BYTES:
        raise StateError(f"{path}: the state of {state.unit} would be {len(text)} bytes ({len(state.entries)} logs); "
                         f"a state is kept up to {STATE_MAX_BYTES} bytes: score the later logs into a new OUT")
    atomic.write_text(path, text)


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
    load = checked_vector(log.get("load"), path, f"{where}.load", 2 * n_axes).reshape(2, n_axes)
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
              robot: str = "") -> UnitHistory:
    """Read and check the record of ``unit`` written by :func:`write_unit` (its ``stages`` left None:
    :func:`faultgen.monitor.steps.replay` makes them): every value one a run writes (stamps that
    parse, the logs' in increasing order and each stamp handled once, SHA-256s of 64 hex digits,
    finite numbers where a run writes them: a temperature finite or NaN (not logged), a maintenance event of
    :data:`MAINTENANCE` on an axis 1..``n_axes``, given before an entry that exists).

    Raises
    ------
    StateError
        The file is a link leading outside ``root`` or not a regular file, is above :data:`STATE_MAX_BYTES`, is not
        such a state, belongs to another unit or to other settings (the differing settings named),
        or holds a value of the wrong type, length or range (named; a changed model file by what it
        is, the robot ``robot`` by its name, not by a digest alone: :func:`setting_moved`).
    """
    check = _Check(path, f"; score the logs into a new OUT (or delete {path.parent} to start this one again)")
    d = load_json(inside(path, root), "monitor state", STATE_MAX_BYTES)
    check.belongs(d, unit, settings, robot)
    history = check.facts(d, unit, n_axes, n_features)
    handled: dict[float, str] = {}  # stamp key -> where: each log is scored or skipped once
    history.skipped = check.skipped(d.get("skipped"), handled)
    maintenance = check.maintenance(d.get("maintenance"), n_axes)
    history.program_changes = check.program_changes(d.get("program_changes", []), n_axes, n_features)
    if (history.model == "none") != (history.program is None):
        raise check.fail(f"model {history.model!r} with program {d.get('program')!r}")
    history.entries = check.logs(d.get("logs"), handled, n_axes, n_features, len(history.program_changes))
    for name, items in (("maintenance", maintenance), ("program_changes", history.program_changes)):
        late = next((i for i, m in enumerate(items) if m.at > len(history.entries)), None)
        if late is not None:
            raise StateError(f"{path}: {name}[{late}].at = {items[late].at}, after the {len(history.entries)} logs "
                             f"scored{check.refuse}")
    history.maintenance = maintenance
    return history


class _Check:
    """The checks of :func:`read_unit` on one file ``path``, each refusal ending with ``refuse``."""

    def __init__(self, path: Path, refuse: str):
        self.path, self.refuse = path, refuse

    def fail(self, what: str) -> StateError:
        return StateError(f"{self.path}: {what}{self.refuse}")

    def stamp(self, value, name: str) -> float:
        return _stamp(value, self.path, name, self.refuse)

    def belongs(self, d: dict, unit: str, settings: dict, robot: str) -> None:
        """The format, the unit and the settings are the run's."""
        if d.get("format") != FORMAT:
            raise self.fail(f"format {str(d.get('format'))[:40]!r}, expected {FORMAT!r} (a state written by "
                            "another version of faultgen: format 2 kept a unit's notes as bare text, 1 other "
                            "features)")
        if d.get("unit") != unit:
            raise self.fail(f"the state of unit {str(d.get('unit'))[:40]!r}, expected {unit!r}")
        if d.get("settings") != settings:
            theirs = d.get("settings") if isinstance(d.get("settings"), dict) else {}
            moved = [setting_moved(k, theirs.get(k), settings.get(k), robot) for k in {**settings, **theirs}
                     if theirs.get(k) != settings.get(k)]  # a key of either (a --scale-prior given or not)
            raise self.fail(f"holds a monitor run with other settings or inputs: {', '.join(moved) or 'unknown keys'}")

    def facts(self, d: dict, unit: str, n_axes: int, n_features: int) -> UnitHistory:
        """The unit's facts: model, program, first log, signatures, notes, torque source."""
        path = self.path
        program = d.get("program")
        if program is not None and not (isinstance(program, list) and len(program) == 2
                                        and all(isinstance(p, str) for p in program)):
            raise self.fail("program is not [unit, stamp]")
        if program is not None:
            self.stamp(program[1], "program[1]")
        signatures = d.get("signatures")
        if signatures is not None:
            if not (isinstance(signatures, list) and len(signatures) == n_axes):
                raise self.fail(f"signatures is not a list of {n_axes} rows")
            signatures = np.stack([checked_vector(row, path, f"signatures row {i + 1}", n_features)
                                   for i, row in enumerate(signatures)])
        model, first, notes = d.get("model"), d.get("first"), d.get("notes")
        if model not in MODELS:
            raise self.fail(f"model {str(model)[:40]!r} is not one of {', '.join(MODELS)}")
        if not (isinstance(first, list) and len(first) == 2 and all(isinstance(p, str) for p in first)):
            raise self.fail("first is not [stamp, sha256]")
        self.stamp(first[0], "first[0]")
        _digest(first[1], path, "first[1]", self.refuse, empty=True)
        if not (isinstance(notes, list) and all(isinstance(n, dict) and isinstance(n.get("text"), str)
                                                and n.get("kind", "") in NOTE_KINDS for n in notes)):
            raise self.fail(f"notes is not a list of {{text, kind}} (kind one of {', '.join(NOTE_KINDS[1:])} "
                            "or none)")
        notes = [self.column(n, i, n_axes) if n.get("kind") == COLUMN else Note(n["text"], n.get("kind", ""))
                 for i, n in enumerate(notes)]
        facts = {k: d.get(k, "") for k in ("torque_source", "off_monitor")}  # "": a state written before they were kept
        if not all(isinstance(v, str) for v in facts.values()):
            raise self.fail("torque_source or off_monitor is not a text")
        return UnitHistory(unit, model, tuple(program) if program else None, tuple(first), signatures,
                           notes=notes, **facts)

    def column(self, note: dict, i: int, n_axes: int) -> Note:
        """A note of kind :data:`COLUMN`: its log's stamp and the reader's note on an axis 1..``n_axes``."""
        said = note.get("column")
        if not (isinstance(said, dict) and isinstance(said.get("text"), str) and type(said.get("axis")) is int
                and 1 <= said["axis"] <= n_axes and said.get("kind") in measured.COLUMN_KINDS):
            raise self.fail(f"notes[{i}].column is not {{text, axis 1..{n_axes}, kind}} (kind one of "
                            f"{', '.join(measured.COLUMN_KINDS)})")
        self.stamp(note.get("log"), f"notes[{i}].log")
        return Note(note["text"], COLUMN, note["log"], measured.ColumnNote(said["text"], said["axis"], said["kind"]))

    def skipped(self, skipped, handled: dict) -> list[Skipped]:
        if not (isinstance(skipped, list) and all(
                isinstance(k, dict) and all(isinstance(k.get(f), str) for f in ("stamp", "sha256", "reason"))
                for k in skipped)):
            raise self.fail("skipped is not a list of {stamp, sha256, reason}")
        for i, k in enumerate(skipped):
            key = self.stamp(k["stamp"], f"skipped[{i}].stamp")
            _digest(k["sha256"], self.path, f"skipped[{i}].sha256", self.refuse, empty=True)
            if handled.setdefault(key, f"skipped[{i}]") != f"skipped[{i}]":
                raise self.fail(f"skipped[{i}] has the stamp of {handled[key]}")
        return [Skipped(k["stamp"], k["sha256"], k["reason"]) for k in skipped]

    def maintenance(self, maintenance, n_axes: int) -> list[Maintenance]:
        if not (isinstance(maintenance, list) and all(
                isinstance(m, dict) and isinstance(m.get("stamp"), str) and isinstance(m.get("event"), str)
                and all(isinstance(m.get(f), int) and not isinstance(m.get(f), bool) and m.get(f) >= 0
                        for f in ("axis", "at"))
                for m in maintenance)):
            raise self.fail("maintenance is not a list of {stamp, event, axis, at}")
        for i, m in enumerate(maintenance):
            self.stamp(m["stamp"], f"maintenance[{i}].stamp")
            if m["event"] not in MAINTENANCE:
                raise self.fail(f"maintenance[{i}].event = {m['event'][:40]!r}; expected one of {', '.join(MAINTENANCE)}")
            if not 1 <= m["axis"] <= n_axes:
                raise self.fail(f"maintenance[{i}].axis = {m['axis']}; expected an axis 1..{n_axes}")
            if i and m["at"] < maintenance[i - 1]["at"]:
                raise self.fail(f"maintenance[{i}].at is before maintenance[{i - 1}].at")
        return [Maintenance(m["stamp"], m["event"], m["axis"], m["at"]) for m in maintenance]

    def program_changes(self, changes, n_axes: int, n_features: int) -> list[ProgramChange]:
        if not isinstance(changes, list):
            raise self.fail("program_changes is not a list")
        program_changes = []
        for i, c in enumerate(changes):
            if not (isinstance(c, dict) and isinstance(c.get("stamp"), str) and isinstance(c.get("at"), int)
                    and not isinstance(c.get("at"), bool) and c["at"] >= 0 and isinstance(c.get("program"), list)
                    and len(c["program"]) == 2 and all(isinstance(p, str) for p in c["program"])
                    and isinstance(c.get("signatures"), list) and len(c["signatures"]) == n_axes
                    and isinstance(c.get("source", ""), str)):
                raise self.fail(f"program_changes[{i}] is not {{stamp, program, at, signatures}}")
            rows = np.stack([checked_vector(r, self.path, f"program_changes[{i}].signatures row {k + 1}", n_features)
                             for k, r in enumerate(c["signatures"])])
            self.stamp(c["stamp"], f"program_changes[{i}].stamp")
            self.stamp(c["program"][1], f"program_changes[{i}].program[1]")
            program_changes.append(ProgramChange(c["stamp"], tuple(c["program"]), c["at"], rows, c.get("source", "")))
        return program_changes

    def logs(self, logs, handled: dict, n_axes: int, n_features: int, known: int) -> list[Entry]:
        """The scored logs, in increasing stamp order, each stamp handled once."""
        if not isinstance(logs, list):
            raise self.fail("logs is not a list")
        entries, last = [], -math.inf
        for i, log in enumerate(logs):
            where = f"logs[{i}]"
            if not (isinstance(log, dict) and isinstance(log.get("stamp"), str) and isinstance(log.get("sha256"), str)):
                raise self.fail(f"{where} has no stamp or SHA-256")
            key = self.stamp(log["stamp"], f"{where}.stamp")
            _digest(log["sha256"], self.path, f"{where}.sha256", self.refuse)
            if handled.setdefault(key, where) != where:
                raise self.fail(f"{where} has the stamp of {handled[key]}")
            if entries and key <= last:
                raise self.fail(f"{where}.stamp {log['stamp']!r} is not after logs[{i - 1}]'s; a run scores logs "
                                "in stamp order")
            last = key
            entries.append(self.entry(log, where, n_axes, n_features, known))
        return entries

    def entry(self, log: dict, where: str, n_axes: int, n_features: int, known: int) -> Entry:
        path, expected = self.path, log.get("expected")
        entry = Entry(
            log["stamp"], log["sha256"], checked_vector(log.get("residual"), path, f"{where}.residual", n_features),
            _number(log.get("temperature_C"), path, f"{where}.temperature_C"),
            _number(log.get("payload_kg"), path, f"{where}.payload_kg"),
            None if expected is None else checked_vector(expected, path, f"{where}.expected", n_features),
            *_load(log, path, where, n_axes), _program(log, path, where, known))
        if not math.isfinite(entry.payload):
            raise self.fail(f"{where}.payload_kg is not a finite number")
        if math.isinf(entry.temperature):  # NaN: not logged
            raise self.fail(f"{where}.temperature_C is infinite; expected a finite number, or NaN when the log "
                            "has no temperature")
        return entry
