"""A kill at any point of the swap of ``OUT/.state`` never leaves OUT without a state, and a state
a run had not replaced is never deleted (issue 86, item 7).

A child process writes a new ``.state`` and ``units.csv`` into an OUT holding old ones through
:func:`faultgen.data.atomic.atomic_folder`, and SIGKILLs itself just before its k-th rename or
exchange after the block (every k in turn: each point between two system calls of the swap); after
each kill OUT holds the old state or the new one, whole, and so it does after the next write's
clean-up (:func:`faultgen.data.atomic.remove_stale`). Once with the file system's exchange
(``renameat2``), once as on a file system without one (NFS): two renames, the old state given back
by the clean-up.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from faultgen.data import atomic
from faultgen.monitor import state as stored

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import os, signal, sys
from pathlib import Path
from faultgen.data import atomic

out, kill_at, exchange = Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3] == "1"
calls = 0
def point():
    global calls
    calls += 1
    if calls == kill_at:
        os.kill(os.getpid(), signal.SIGKILL)
committing = False
def hook(event, args):
    if committing and event == "os.rename":
        point()
sys.addaudithook(hook)
if hasattr(atomic, "exchange"):
    real = atomic.exchange
    def counted(a, b):
        point()
        return real(a, b) if exchange else False
    atomic.exchange = counted
with atomic.atomic_folder(out) as stage:
    (stage / ".state").mkdir()
    (stage / ".state" / "u1.json").write_text("new")
    (stage / "units.csv").write_text("new")
    committing = True
"""


def _old_out(tmp_path: Path) -> Path:
    out = tmp_path / "OUT"
    (out / ".state").mkdir(parents=True)
    (out / ".state" / "u1.json").write_text("old")
    (out / "units.csv").write_text("old")
    (out / ".cache").mkdir()
    return out


def _state(out: Path) -> str | None:
    path = out / ".state" / "u1.json"
    return path.read_text() if path.is_file() else None


@pytest.mark.parametrize("exchange", [True, False], ids=["exchange", "two-renames"])
def test_a_kill_at_any_point_of_the_swap_leaves_the_old_state_or_the_new_one(tmp_path, exchange):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    seen = set()
    for kill_at in range(1, 10):
        root = tmp_path / str(kill_at)
        out = _old_out(root)
        done = subprocess.run([sys.executable, "-c", CHILD, str(out), str(kill_at), "1" if exchange else "0"],
                              env=env, capture_output=True, text=True)
        killed = done.returncode == -signal.SIGKILL
        assert killed or done.returncode == 0, done.stderr
        now = _state(out)
        if exchange:  # one system call: never without a state, even before the clean-up
            assert now in ("old", "new"), (kill_at, sorted(p.name for p in out.iterdir()))
        atomic.remove_stale(out)  # the next write's clean-up (the child's pid is gone)
        after = _state(out)
        assert after in ("old", "new"), (kill_at, sorted(p.name for p in out.iterdir()))
        assert now is None or after == now  # the clean-up never undoes a swap that was made
        assert sorted(p.name for p in out.iterdir() if p.name.endswith(".part")) == []  # the stage removed
        assert (out / ".cache").is_dir() and (out / "units.csv").read_text() in ("old", "new")
        seen.add(after)
        if not killed:
            assert after == "new" and (out / "units.csv").read_text() == "new"
            break
    else:
        pytest.fail("the child was killed at every point: the swap took more than 8 system calls")
    assert seen == {"old", "new"}


def test_the_exchange_swaps_two_folders_and_says_where_it_cannot(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir()
    b.mkdir()
    (a / "x").write_text("a")
    (b / "y").write_text("b")
    assert atomic.exchange(a, b) is True  # ext4 and tmpfs here (Linux >= 3.15, glibc >= 2.28)
    assert [p.name for p in a.iterdir()] == ["y"] and [p.name for p in b.iterdir()] == ["x"]
    with pytest.raises(FileNotFoundError):
        atomic.exchange(a, tmp_path / "missing")


def test_a_rerun_after_a_kill_between_two_renames_gets_the_state_back_before_it_reads_it(tmp_path):
    """The state is given back by :func:`faultgen.monitor.state.checked_out`, which the monitor calls
    before it reads OUT's state: the rerun continues it instead of scoring every log again."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    for kill_at in range(1, 10):  # the point between the two renames of .state
        out = _old_out(tmp_path / str(kill_at))
        done = subprocess.run([sys.executable, "-c", CHILD, str(out), str(kill_at), "0"], env=env,
                              capture_output=True, text=True)
        assert done.returncode == -signal.SIGKILL, done.stderr
        if _state(out) is None:
            break
    else:
        pytest.fail("no kill left OUT without its state: nothing to give back")
    stored.checked_out(out)
    assert _state(out) == "old" and (out / "units.csv").read_text() == "old"
    assert [p.name for p in out.iterdir() if p.name.endswith(".part")] == []


def test_a_rename_that_fails_between_the_two_gives_the_old_state_back(tmp_path, monkeypatch):
    """Without the exchange, the old state is moved aside before the new one goes in: when that
    second rename fails (a full or failing disk), the old state is put back, never removed with the stage."""
    out = _old_out(tmp_path)
    real = os.replace

    def failing(src, dst, **kw):
        if Path(dst) == out / ".state" and Path(src).parent.parent == out and Path(src).parent.name != ".replaced":
            raise OSError(5, "Input/output error", str(src))  # the new state's rename in, not the give-back
        return real(src, dst, **kw)

    monkeypatch.setattr(atomic, "exchange", lambda a, b: False)
    monkeypatch.setattr(os, "replace", failing)
    with pytest.raises(OSError, match="Input/output error"):
        with atomic.atomic_folder(out) as stage:
            (stage / ".state").mkdir()
            (stage / ".state" / "u1.json").write_text("new")
    assert _state(out) == "old"
    assert [p.name for p in out.iterdir() if p.name.endswith(".part")] == []
