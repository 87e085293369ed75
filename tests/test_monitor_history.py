"""A unit's record (:class:`faultgen.monitor.history.UnitHistory`) and its JSON, the monitor's saved
state: written and read back field for field, its notes' kinds kept (no fact recovered from a
note's text), and a file of another format or with a planted value refused naming the file and
the field. Small planted records, no simulation."""

from __future__ import annotations

import json
import math
import pickle

import numpy as np
import pytest

from faultgen.logs import measured
from faultgen.monitor import history, unit
from faultgen.monitor.history import Entry, Maintenance, Note, ProgramChange, Skipped, UnitHistory
from faultgen.monitor.state import StateError

N_AXES, N_FEATURES = 2, 6
SETTINGS = {"train": 10, "robot": "0" * 64}


def _record() -> UnitHistory:
    rng = np.random.default_rng(7)
    signatures = rng.normal(size=(N_AXES, N_FEATURES))
    fell_back = unit.chain_notes([("calibrated", "a planted error")], "nominal")
    entries = [Entry(f"2026-01-0{d}", f"{d}" * 64, rng.normal(size=N_FEATURES), 21.5 if d != 2 else math.nan,
                     3.0, rng.normal(size=N_FEATURES), np.abs(rng.normal(size=(2, N_AXES))), 60.0, int(d == 3))
               for d in (1, 2, 3)]
    return UnitHistory("u1", "nominal", ("u0", "2026-01-01"), ("2026-01-01", "1" * 64), signatures, entries,
                       [Skipped("2026-01-04", "", "unreadable")],
                       [*fell_back, Note("log 2026-01-02: column qd1 planted"), Note(
                           "log 2026-01-03: column qd2 planted", history.COLUMN, "2026-01-03",
                           measured.ColumnNote("column qd2 planted", 2, measured.SPEED_RATIO))],
                       [Maintenance("2026-01-02", "repair", 2, 1)],
                       [ProgramChange("2026-01-03", ("u1", "2026-01-03"), 2, signatures + 1, "a source")],
                       torque_source="a source")


def _write(tmp_path, record: UnitHistory):
    path = tmp_path / ".state" / "u1.json"
    path.parent.mkdir(exist_ok=True)
    history.write_unit(path, record, SETTINGS)
    return path


def _read(tmp_path, path):
    return history.read_unit(path, tmp_path, "u1", SETTINGS, N_AXES, N_FEATURES)


def test_a_record_is_read_back_field_for_field_with_its_notes_kinds(tmp_path):
    record = _record()
    path = _write(tmp_path, record)
    written = path.read_bytes()
    back = _read(tmp_path, path)
    assert (back.unit, back.model, back.program, back.first, back.notes, back.skipped, back.maintenance,
            back.torque_source, back.off_monitor) == (record.unit, record.model, record.program, record.first,
                                                      record.notes, record.skipped, record.maintenance,
                                                      record.torque_source, record.off_monitor)
    np.testing.assert_array_equal(back.signatures, record.signatures)
    assert [(c.stamp, c.program, c.at, c.source) for c in back.program_changes] == \
        [(c.stamp, c.program, c.at, c.source) for c in record.program_changes]
    assert [(e.stamp, e.sha256, e.payload, e.duration, e.program) for e in back.entries] == \
        [(e.stamp, e.sha256, e.payload, e.duration, e.program) for e in record.entries]
    assert back.stages is None and back.rows == [] and back.program_twins == {}
    history.write_unit(path, back, SETTINGS)
    assert path.read_bytes() == written  # written again byte for byte: nothing lost or reordered
    assert [n.kind for n in back.notes] == [history.FALLBACK, "", history.COLUMN]
    said = back.notes[2]  # the reader's column note: its log, axis and kind as fields, not read from its text
    assert (said.log, said.column, said.column.axis, said.column.kind) == ("2026-01-03", "column qd2 planted", 2,
                                                                          measured.SPEED_RATIO)
    assert back.notes[1].column is None
    assert unit.fallback_notes(back) == [record.notes[0]] and unit.refused_note(back) is None
    for was, now in zip(record.entries, back.entries):
        for name in ("residual", "expected", "load"):
            np.testing.assert_array_equal(getattr(was, name), getattr(now, name))  # floats exactly
        assert math.isnan(now.temperature) == math.isnan(was.temperature)  # NaN kept: not logged


def test_a_note_s_kind_is_its_own_not_its_text(tmp_path):
    """A note that reads like a fallback is not one; a refusal's note is found by its kind alone,
    after a round trip and a pickle (a worker's result)."""
    record = UnitHistory("u1", first=("2026-01-01", ""), model="none",
                         notes=[Note("the twin of the given model failed (typed by hand); nominal model used")])
    unit.refuse(record, ValueError("a planted refusal"))
    back = pickle.loads(pickle.dumps(_read(tmp_path, _write(tmp_path, record))))
    assert unit.fallback_notes(back) == []
    assert unit.refused_note(back) == record.notes[1] and unit.refused_note(back).startswith(unit.REFUSED)


@pytest.mark.parametrize("key, value, said", [
    ("format", "faultgen-monitor-state/2", "format 'faultgen-monitor-state/2', expected 'faultgen-monitor-state/3'"),
    ("notes", ["bare text"], "notes is not a list of {text, kind}"),
    ("notes", [{"text": "x", "kind": "planted"}], "notes is not a list of {text, kind}"),
    ("model", "planted", "model 'planted' is not one of given"),
    ("notes", [{"text": "log 2026-01-02: column qd3 x", "kind": "column", "log": "2026-01-02",
                "column": {"text": "column qd3 x", "axis": 3, "kind": measured.SPEED_RATIO}}],
     "notes[0].column is not {text, axis 1..2, kind}"),
    ("notes", [{"text": "log x: column qd1 x", "kind": "column", "log": "x",
                "column": {"text": "column qd1 x", "axis": 1, "kind": measured.SPEED_RATIO}}], "notes[0].log"),
])
def test_a_planted_value_is_refused_naming_the_file_and_field(tmp_path, key, value, said):
    path = _write(tmp_path, _record())
    document = json.loads(path.read_text())
    document[key] = value
    path.write_text(json.dumps(document))
    with pytest.raises(StateError, match=r"u1\.json: ") as refused:
        _read(tmp_path, path)
    assert said in str(refused.value) and "score the logs into a new OUT" in str(refused.value)


def test_a_written_note_is_plain_json_text_with_its_kind():
    note = Note("the twin of the calibrated model failed (x); nominal model used", history.FALLBACK)
    assert note == str(note) and note.kind == history.FALLBACK and note.column is None
