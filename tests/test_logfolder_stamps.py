"""A log whose stamp does not parse, in a fleet's log folder (:mod:`faultgen.data.logfolder`): the
listing carries the file's name and the reason apart (a typed :class:`~faultgen.data.logfolder.StampError`),
and every message names the file once. Before, the reason was the parser's whole message, which
began with the name: `faultgen logs import` printed it twice ("u1/backup copy.csv: u1/backup
copy.csv: stamp ..."), and the monitor's note recovered it by matching the start of the text. A
file in a unit's friction-test folder is "not a friction test" where it is listed (before, the
monitor replaced "not a log" in the listing's text)."""

from __future__ import annotations

import pickle

import pytest

from faultgen.data import fleetlogs, logfolder
from faultgen.monitor import logs as fleet_logs

REASON = ("stamp 'backup copy' is neither an ISO date (2026-03-01), an ISO date and time "
          "(2026-03-01T08:30:00 or 2026-03-01T08-30-00) nor a sequence number (17)")


@pytest.fixture
def folder(tmp_path):
    (tmp_path / "LOGS/u1").mkdir(parents=True)
    (tmp_path / "LOGS/u1/backup copy.csv").write_text("t,q1,tau1\n")
    (tmp_path / "LOGS/u1/1234567890123456789.csv").write_text("t,q1,tau1\n")  # 19 digits: too long a sequence
    return tmp_path / "LOGS"


def test_the_parser_raises_the_place_and_the_reason_apart():
    with pytest.raises(logfolder.StampError) as caught:
        logfolder.parse_stamp("backup copy", "u1/backup copy.csv")
    assert (caught.value.where, caught.value.reason) == ("u1/backup copy.csv", REASON)
    assert str(caught.value) == f"u1/backup copy.csv: {REASON}" and isinstance(caught.value, ValueError)
    again = pickle.loads(pickle.dumps(caught.value))  # as a worker process's error reaches its parent
    assert type(again) is logfolder.StampError and (again.where, again.reason, str(again)) == (
        caught.value.where, caught.value.reason, str(caught.value))


def test_a_listing_names_each_bad_stamp_once(folder):
    _, bad = logfolder.scan(folder, (".csv",))
    too_long = ("stamp '1234567890123456789': expected a sequence number of at most 15 digits 0-9 (17), "
                "an ISO date (2026-03-01) or an ISO date and time (2026-03-01T08:30:00)")
    assert bad == [("u1/1234567890123456789.csv", too_long), ("u1/backup copy.csv", REASON)]
    assert fleet_logs.passed_note(bad[1:]) == f"1 files passed over, not logs: u1/backup copy.csv: {REASON}"
    with pytest.raises(ValueError) as refused:  # without --skip-bad the import refuses the first, named once
        fleetlogs.import_logs(folder, folder.parent / "f.h5", robot="puma560", progress=False)
    assert str(refused.value).count("1234567890123456789.csv") == 1, refused.value
    assert not (folder.parent / "f.h5").exists()


def test_a_test_folders_stray_file_is_named_not_a_friction_test_where_it_is_listed(folder):
    (folder / "u1/friction-test").mkdir()
    (folder / "u1/friction-test/readme.md").write_text("how the tests were run")
    _, bad = logfolder.scan_tests(folder, ["u1"], (".csv",))  # said so by the listing, not replaced in its text after
    assert bad == [("u1/friction-test/readme.md", "not a friction test: expected <stamp>.csv")]
    assert logfolder.scan(folder, (".csv",))[1][-1] == ("u1/backup copy.csv", REASON)  # the logs' listing as before
