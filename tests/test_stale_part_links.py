"""A link planted in or beside an output folder under the name of a killed writer's temporary
file or folder (``.NAME.<pid>@<host>.x.part``) is passed over, never followed or removed, and
every later write of that output works (issue 86, item 11: it made each write fail with "Cannot
call rmtree on a symbolic link")."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from faultgen.data import atomic


def _dead_pid() -> int:
    done = subprocess.Popen([sys.executable, "-c", "pass"])
    done.wait()
    return done.pid  # no process of it runs any more


def test_a_link_named_as_a_stale_temporary_is_passed_over_and_the_writes_go_on(tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "precious.txt").write_text("mine")
    parent = tmp_path / "parent"
    out = parent / "OUT"
    (out / ".state").mkdir(parents=True)
    pid, host = _dead_pid(), atomic._host()
    links = [parent / f".OUT.{pid}@{host}.abc.part",  # where a new OUT is staged
             out / f".OUT.{pid}@{host}.def.part",  # where an existing OUT is staged
             out / f".alarms.csv.{pid}@{host}.ghi.part",  # a file's temporary
             out / f".units.csv.{pid}@{host}.jkl.part"]
    for link in links[:3]:
        link.symlink_to(elsewhere, target_is_directory=True)
    links[3].symlink_to(elsewhere / "precious.txt")
    stale = out / f".scores.csv.{pid}@{host}.mno.part"  # a real leftover: still removed
    stale.write_text("half")
    for _ in range(2):  # every later write, not only the first
        with atomic.atomic_folder(out) as stage:
            (stage / "alarms.csv").write_text("a")
        with atomic.atomic_path(out / "alarms.csv") as tmp:
            tmp.write_text("b")
        with atomic.atomic_path(out / "units.csv") as tmp:
            tmp.write_text("c")
        atomic.write_text(out / "scores.csv", "d")
    assert (out / "alarms.csv").read_text() == "b" and (out / "units.csv").read_text() == "c"
    assert all(link.is_symlink() for link in links)  # passed over: neither followed nor removed
    assert (elsewhere / "precious.txt").read_text() == "mine" and sorted(p.name for p in elsewhere.iterdir()) == [
        "precious.txt"]
    assert not stale.exists()
