"""``faultgen monitor`` into an OUT that is a mount point of its own (a docker or k8s volume, NFS)
and into an OUT whose parent folder is read-only (issue 86, item 4).

The run stages its outputs inside OUT (:func:`faultgen.data.atomic.atomic_folder`), so no rename
crosses OUT's mount and nothing is made beside it; a read-only OUT is refused before the work.
Where the machine allows a mount namespace (``unshare -m``, as root here and in CI) the monitor runs
in one, with OUT a bind mount in a read-only bind of its parent: a rename out of OUT fails there with
EXDEV as on a volume. Where it does not, the same runs take place with the mount simulated (every
rename across OUT's boundary fails with EXDEV, nothing can be made in its parent) and the test says
so in a warning.
"""

from __future__ import annotations

import errno
import json
import os
import shutil
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
import fleetlog_folder

from faultgen.data import atomic
from faultgen.model import robots

ROOT = Path(__file__).resolve().parents[1]

#: The three runs, in one process: a first run into OUT (a mount in a read-only parent), the same
#: command again (continued), and one into OUT made read-only. Prints one JSON line per run.
RUNS = r"""
import json, os, subprocess, sys
from pathlib import Path
from typer.testing import CliRunner
from faultgen.cli import app

logs, out, read_only = sys.argv[1], Path(sys.argv[2]), sys.argv[3]
def run():
    result = CliRunner().invoke(app, ["monitor", logs, "--robot", "puma560", "-o", str(out), "--protocol", "own",
                                      "--no-progress"])
    print(json.dumps({"code": result.exit_code, "output": result.output,
                      "entries": sorted(p.name for p in out.iterdir()) if out.is_dir() else None}), flush=True)
run()
run()
subprocess.run(read_only, shell=True, check=True)
run()
"""


def _can_mount() -> bool:
    if shutil.which("unshare") is None:
        return False
    probe = subprocess.run(["unshare", "-m", "sh", "-c", "mount --make-rprivate / && mount -t tmpfs none /mnt"],
                           capture_output=True)
    return probe.returncode == 0


@pytest.fixture(scope="module")
def fleet(tmp_path_factory) -> Path:
    """Two units of four logs; u1 with a friction test that cannot be read (named in its reason), so
    that the run writes tests.csv."""
    logs = fleetlog_folder.write_fleet(tmp_path_factory.mktemp("fleet") / "LOGS", robots.load("puma560"), units=2,
                                       days=4)
    (logs / "u1" / "friction-test").mkdir()
    (logs / "u1" / "friction-test" / "2026-03-02.csv").write_text("t,q1\n0,0\n")
    return logs


def _in_a_mount_namespace(fleet: Path, parent: Path, volume: Path) -> list[dict]:
    out = parent / "OUT"
    script = (f"mount --make-rprivate / && mount --bind {parent} {parent} && mount -o remount,bind,ro {parent} "
              f"&& mount --bind {volume} {out} && exec {sys.executable} -c \"$RUNS\" {fleet} {out} "
              f"'mount -o remount,bind,ro {out}'")
    done = subprocess.run(["unshare", "-m", "sh", "-c", script], capture_output=True, text=True, timeout=600,
                          env={**os.environ, "PYTHONPATH": str(ROOT), "RUNS": RUNS})
    assert done.returncode == 0, done.stderr[-3000:]
    return [json.loads(line) for line in done.stdout.splitlines() if line.startswith("{")]


def _simulated(fleet: Path, parent: Path, volume: Path, monkeypatch) -> list[dict]:
    """The runs of :data:`RUNS` with OUT's mount simulated: a rename across OUT's boundary fails
    with EXDEV, nothing can be made in its parent (EROFS), and after two runs OUT takes no file."""
    from typer.testing import CliRunner

    from faultgen.cli import app

    out = parent / "OUT"
    out.symlink_to(volume, target_is_directory=True)
    inside = volume.resolve()
    state = {"read_only": False}
    real_replace, real_mkdtemp, real_mkstemp = os.replace, tempfile.mkdtemp, tempfile.mkstemp

    def under(path) -> bool:
        return inside in [Path(os.path.realpath(path)), *Path(os.path.realpath(path)).parents]

    def replace(src, dst, **kw):
        if under(src) != under(os.path.dirname(os.path.abspath(dst))):
            raise OSError(errno.EXDEV, "Invalid cross-device link", str(src), None, str(dst))
        return real_replace(src, dst, **kw)

    def refused(dir) -> bool:
        return Path(dir or ".").resolve() == parent.resolve() or (state["read_only"] and under(dir or "."))

    def mkdtemp(*a, dir=None, **kw):
        if refused(dir):
            raise OSError(errno.EROFS, "Read-only file system")
        return real_mkdtemp(*a, dir=dir, **kw)

    def mkstemp(*a, dir=None, **kw):
        if refused(dir):
            raise OSError(errno.EROFS, "Read-only file system")
        return real_mkstemp(*a, dir=dir, **kw)

    monkeypatch.setattr(os, "replace", replace)
    monkeypatch.setattr(tempfile, "mkdtemp", mkdtemp)
    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)
    results = []
    for run in range(3):
        state["read_only"] = run == 2
        result = CliRunner().invoke(app, ["monitor", str(fleet), "--robot", "puma560", "-o", str(out), "--protocol",
                                          "own", "--no-progress"])
        results.append({"code": result.exit_code, "output": result.output,
                        "entries": sorted(p.name for p in out.iterdir())})
    return results


def test_the_monitor_writes_into_an_out_on_its_own_mount_in_a_read_only_parent(fleet, tmp_path, monkeypatch):
    parent, volume = tmp_path / "parent", tmp_path / "volume"
    (parent / "OUT").mkdir(parents=True)
    volume.mkdir()
    if _can_mount():
        first, again, read_only = _in_a_mount_namespace(fleet, parent, volume)
    else:
        (parent / "OUT").rmdir()
        warnings.warn("no mount namespace on this machine (unshare -m refused): OUT's own mount and the read-only "
                      "parent simulated (renames across OUT fail with EXDEV, its parent takes no file)")
        first, again, read_only = _simulated(fleet, parent, volume, monkeypatch)
    out = parent / "OUT"
    outputs = [".cache", ".state", "alarms.csv", "life.csv", "report.html", "rul.csv", "scores.csv", "settings.json",
               "tests.csv", "u1.png", "u2.png", "units.csv", "wear.csv"]
    assert first["code"] == 0, first["output"]
    assert first["entries"] == outputs  # every output, no stage left, the cache kept
    closing = first["output"].strip().splitlines()[-1]  # item 13: every table written is named
    assert closing == (f"wrote {', '.join(str(out / n) for n in ('units.csv', 'alarms.csv', 'scores.csv', 'wear.csv'))}"
                       f", {out / 'rul.csv'}, {out / 'life.csv'}, {out / 'tests.csv'}, 2 charts and the fleet report "
                       f"{out / 'report.html'}"), closing
    assert again["code"] == 0 and again["entries"] == outputs, again["output"]
    assert read_only["code"] == 1, read_only["output"]
    assert f"cannot write in {out}" in read_only["output"] and "ead-only" in read_only["output"]
    assert read_only["entries"] == outputs  # refused before the work: the state and cache kept
    assert sorted(p.name for p in parent.iterdir()) == ["OUT"]  # nothing made beside OUT
    assert sorted(p.name for p in volume.iterdir()) == outputs  # written on OUT's own file system


def test_an_existing_folder_is_staged_inside_itself_and_nothing_is_made_beside_it(tmp_path):
    """The staging logic the runs above rest on, on one file system."""
    out = tmp_path / "OUT"
    (out / ".state").mkdir(parents=True)
    (out / ".state" / "u1.json").write_text("old")
    (out / "mine.txt").write_text("kept")
    with atomic.atomic_folder(out) as stage:
        assert stage.parent == out and stage.name.startswith(".OUT.") and stage.name.endswith(".part")
        assert os.stat(stage).st_dev == os.stat(out).st_dev
        assert sorted(p.name for p in tmp_path.iterdir()) == ["OUT"]
        (stage / ".state").mkdir()
        (stage / ".state" / "u1.json").write_text("new")
        (stage / "units.csv").write_text("new")
    assert sorted(p.name for p in out.iterdir()) == [".state", "mine.txt", "units.csv"]
    assert (out / ".state" / "u1.json").read_text() == "new" and (out / "mine.txt").read_text() == "kept"
    new = tmp_path / "NEW"  # a folder that does not exist yet: staged beside it, renamed whole
    with atomic.atomic_folder(new) as stage:
        assert stage.parent == tmp_path
        (stage / "a.csv").write_text("a")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["NEW", "OUT"] and (new / "a.csv").read_text() == "a"
