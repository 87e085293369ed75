"""Issue 50 item 6 (and the unclear I/O messages of item 5): a command's outputs appear as a set,
all or none, so a full disk never leaves some of them looking complete and blocking the rerun;
an I/O error names the file asked for, never a hidden temporary one; MuJoCo leaves no
MUJOCO_LOG.TXT in the current folder."""

import errno
from pathlib import Path

import pytest
from typer.testing import CliRunner

from analysis import benchmark
from faultgen.cli import app
from faultgen.data import atomic

runner = CliRunner()


@pytest.fixture(scope="module")
def small(shared_sweep):
    return shared_sweep("analysis-small", robots=["irb6700"], tasks=["pick_place"], axes=[0, 1, 5], cycles=40)


def _disk_full(*args, **kwargs):
    """A last write that fails as on a full disk: part of a file written, then ENOSPC (no file named)."""
    Path(args[1]).write_bytes(b"\x89PNG partial")
    raise OSError(errno.ENOSPC, "No space left on device")


@pytest.mark.parametrize(("command", "last", "outputs"), [
    (["detect", "--protocol", "same-run"], "detection_figure", ["out.csv", "out.md", "out-summary.csv", "out.png"]),
    (["bench-isolators", "--bins", "5", "--levels", "5"], "confusion_figure",
     ["out.csv", "out.md", "out.png", "out-confusion.csv", "out-confusion.png"]),
    (["classify", "--classifier", "lr", "--preprocessing", "control", "--no-chance", "--jobs", "1"],
     "classification_heatmap", ["out.csv", "out.md", "out.png"]),
])
def test_a_failing_last_write_leaves_no_output_and_the_rerun_works(small, tmp_path, monkeypatch, command, last,
                                                                   outputs):
    args = [command[0], str(small), *command[1:], "--no-progress", "-o", str(tmp_path / "out")]
    with monkeypatch.context() as patch:
        patch.setattr(benchmark, last, _disk_full)
        result = runner.invoke(app, args)
    assert result.exit_code == 1, result.output
    lines = result.output.strip().splitlines()
    assert lines[-1].startswith("error: cannot write ") and "No space left on device" in lines[-1], result.output
    assert str(tmp_path / "out.csv") in lines[-1]  # the outputs are named, not a hidden folder
    assert list(tmp_path.iterdir()) == []  # no output, no hidden staging folder
    rerun = runner.invoke(app, args)
    assert rerun.exit_code == 0, rerun.output
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(outputs)


def test_an_output_set_is_all_or_nothing_and_replaces_only_when_complete(tmp_path):
    a, b = tmp_path / "a.csv", tmp_path / "b.md"
    a.write_text("old a\n")
    with pytest.raises(OSError, match=f"cannot write {b}: File too large"):
        with atomic.output_set([a, b]) as staged:
            staged(a).write_text("new a\n")
            raise OSError(errno.EFBIG, "File too large", str(staged(b)))
    assert a.read_text() == "old a\n" and not b.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv"]
    with atomic.output_set([a, b]) as staged:
        staged(a).write_text("new a\n")
        staged(b).write_text("b\n")
        assert not b.exists()  # nothing appears before the set is complete
    assert a.read_text() == "new a\n" and b.read_text() == "b\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv", "b.md"]


def test_an_unwritable_folder_is_named_not_the_hidden_temporary_file():
    # /sys takes no new file even for root; /proc says ENOENT, which read as "no such file"
    with pytest.raises(OSError) as raised:
        with atomic.atomic_path("/sys/q.h5"):
            pass
    assert str(raised.value).startswith("[Errno 13] cannot write /sys/q.h5: Permission denied")
    assert ".part" not in str(raised.value)
    with pytest.raises(OSError, match="cannot write in /proc: this folder takes no new files"):
        atomic.check_writable("/proc/q.h5")
    result = runner.invoke(app, ["simulate", "--cycles", "1", "-o", "/proc/q.h5"])
    assert result.exit_code == 1 and "No such file or directory" not in result.output, result.output


def test_a_simulation_mujoco_warns_about_leaves_no_mujoco_log(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, ["simulate", "--fault", "torque_offset:2:offset:1e30", "--cycles", "1",
                                 "--no-progress", "-o", "x.h5"])
    assert result.exit_code == 1 and "diverged" in result.output, result.output
    assert list(tmp_path.iterdir()) == []  # no MUJOCO_LOG.TXT, no output


def test_a_failed_write_of_one_file_names_it(tmp_path):
    target = tmp_path / "sw.toml"
    with pytest.raises(OSError) as raised:
        with atomic.atomic_path(target):
            raise OSError(errno.ENOSPC, "No space left on device")  # as a write on a full disk: no file named
    assert str(raised.value) == f"[Errno 28] cannot write {target}: No space left on device"
    assert list(tmp_path.iterdir()) == []
