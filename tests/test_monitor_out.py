"""``faultgen monitor``'s output folder never destroys inputs or unrelated files (issue 61, item 6):
a folder that is not an earlier monitor run's output is refused unless --overwrite, OUT apart
from LOGS, and a run that fails leaves no OUT it made. Small synthetic fleets, protocol own."""

from __future__ import annotations

import errno
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.model import robots

sys.path.insert(0, str(Path(__file__).parent))
import fleetlog_folder

runner = CliRunner()


@pytest.fixture(scope="module")
def fleet(tmp_path_factory) -> Path:
    return fleetlog_folder.write_fleet(tmp_path_factory.mktemp("fleet") / "LOGS", robots.load("puma560"), units=2,
                                       days=4)


def _monitor(logs: Path, out: Path, *extra: str):
    return runner.invoke(app, ["monitor", str(logs), "--robot", "puma560", "-o", str(out), "--protocol", "own",
                               *extra])


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_folder_of_other_files_is_refused_unless_overwrite_and_an_earlier_output_is_continued(fleet, tmp_path):
    other = tmp_path / "results"
    other.mkdir()
    (other / "scores.csv").write_text("my own scores\n")
    (other / "notes.txt").write_text("mine\n")
    result = _monitor(fleet, other)
    assert result.exit_code == 2, result.output
    assert f"{other} holds files and is not an earlier monitor run's output" in result.output
    assert "--overwrite" in result.output
    assert _files(other) == {"notes.txt": b"mine\n", "scores.csv": b"my own scores\n"}  # nothing made, nothing replaced
    result = _monitor(fleet, other, "--overwrite")
    assert result.exit_code == 0, result.output
    assert (other / "notes.txt").read_text() == "mine\n" and (other / "scores.csv").read_text().startswith("unit,")
    out = tmp_path / "out"
    assert _monitor(fleet, out).exit_code == 0
    assert _monitor(fleet, out).exit_code == 0  # an earlier monitor output (OUT/.state): continued
    killed = tmp_path / "killed"  # a first run killed before its outputs leaves only its cache: continued
    (killed / ".cache" / "cycles").mkdir(parents=True)
    assert _monitor(fleet, killed).exit_code == 0 and (killed / "alarms.csv").is_file()
    (tmp_path / "file").write_text("x")
    result = _monitor(fleet, tmp_path / "file")
    assert result.exit_code == 2 and "is not a folder" in result.output and (tmp_path / "file").read_text() == "x"


def test_a_mount_point_holding_only_lost_and_found_is_written_as_an_empty_folder(fleet, tmp_path):
    mount = tmp_path / "mnt"  # an ext4 mount point: mkfs made lost+found, the user nothing
    (mount / "lost+found").mkdir(parents=True)
    result = _monitor(fleet, mount)
    assert result.exit_code == 0, result.output
    assert (mount / "alarms.csv").is_file() and not any((mount / "lost+found").iterdir())
    other = tmp_path / "other"  # lost+found beside a file of the user's: refused as before
    (other / "lost+found").mkdir(parents=True)
    (other / "notes.txt").write_text("mine\n")
    result = _monitor(fleet, other)
    assert result.exit_code == 2 and f"{other} holds files" in result.output, result.output
    (tmp_path / "third" / "lost+found").parent.mkdir()
    (tmp_path / "third" / "lost+found").write_text("a file of that name is the user's\n")
    assert _monitor(fleet, tmp_path / "third").exit_code == 2


@pytest.mark.parametrize("where", ["LOGS", "LOGS/mon", "LOGS/u1", "LOGS/../LOGS/mon", ".", "link"])
def test_an_output_that_is_inside_or_holds_the_logs_folder_is_refused_naming_both(fleet, tmp_path, where):
    logs = tmp_path / "LOGS"
    logs.mkdir()
    for unit in ("u1", "u2"):
        (logs / unit).mkdir()
        for log in (fleet / unit).iterdir():
            (logs / unit / log.name).write_bytes(log.read_bytes())
    (tmp_path / "link").symlink_to(logs / "u2", target_is_directory=True)  # a link to a unit folder
    before = _files(logs)
    out = tmp_path / where
    result = _monitor(logs, out)
    assert result.exit_code == 2, result.output
    line = result.output.strip().splitlines()[-1]
    assert line.startswith(f"error: {out} ") and str(logs) in line, line
    assert any(word in line for word in ("itself", "lies inside", "contains")), line
    assert _files(logs) == before and sorted(p.name for p in logs.iterdir()) == ["u1", "u2"]
    imported = runner.invoke(app, ["logs", "import", str(logs), "--robot", "puma560", "-o", str(logs / "f.h5"),
                                   "--no-progress"])
    assert imported.exit_code == 2 and "lies inside the logs folder" in imported.output, imported.output
    assert not (logs / "f.h5").exists()


def test_a_run_that_fails_leaves_no_output_folder_it_made_and_keeps_one_that_was_there(fleet, tmp_path, monkeypatch):
    from faultgen.monitor import record

    def full_disk(table, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(record.Table, "write", full_disk)
    out = tmp_path / "new" / "out"  # two folders the run makes
    result = _monitor(fleet, out)
    assert result.exit_code == 1 and "No space left on device" in result.output, result.output
    assert not (tmp_path / "new").exists()  # no OUT/.cache left, nor the folder above it
    result = _monitor(fleet, tmp_path / "missing-robot", "--robot", "no-such-robot")
    assert result.exit_code == 2 and not (tmp_path / "missing-robot").exists()
    kept = tmp_path / "kept"
    kept.mkdir()
    result = _monitor(fleet, kept)
    assert result.exit_code == 1 and kept.is_dir() and not list(kept.iterdir())  # there before: kept as it was
    (kept / ".cache" / "cycles").mkdir(parents=True)
    (kept / ".cache" / "cycles" / "c.json").write_text("{}")
    result = _monitor(fleet, kept)
    assert result.exit_code == 1 and (kept / ".cache" / "cycles" / "c.json").read_text() == "{}"  # an earlier cache
