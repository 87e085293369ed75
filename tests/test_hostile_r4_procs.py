"""Hostile inputs, round 4, the processes faultgen starts: every Python child without the current
folder on its path (:mod:`faultgen.children`), a monitor's workers that end with it, its ``--jobs``
warned above the cores, and a failed monitor that removes only what it made."""

from __future__ import annotations

import ast
import concurrent.futures
import importlib.util
import os
import re
import signal
import subprocess
import time
from pathlib import Path

import psutil
import pytest
from typer.testing import CliRunner

import fleetlog_folder
from test_reliability import marked  # every process carrying the test's environment mark
from faultgen import children, pools
from faultgen.cli import app
from faultgen.model import robots

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()


# -- every Python child is started by faultgen.children ------------------------------------------

#: Where faultgen's own code starts processes: the package, the analysis, the benchmarks, the docs' scripts.
SOURCES = ["faultgen", "analysis", "benchmarks", "docs"]
PYTHON = re.compile(r"(.*/)?python[0-9.]*")


def python_starts(source: str) -> list[int]:
    """The lines of ``source`` that start a Python process other than by :func:`faultgen.children.command`:
    any use of ``sys.executable`` (the interpreter, or a console script beside it), a command list
    whose program is a ``python`` name, or one whose second item is ``-m`` or ``-c`` after a program
    given as an expression."""
    lines = []
    for node in ast.walk(ast.parse(source)):
        if (isinstance(node, ast.Attribute) and node.attr == "executable" and isinstance(node.value, ast.Name)
                and node.value.id == "sys"):
            lines.append(node.lineno)
        elif isinstance(node, ast.List | ast.Tuple) and node.elts:
            first = node.elts[0]
            if isinstance(first, ast.Constant) and isinstance(first.value, str) and PYTHON.fullmatch(first.value):
                lines.append(node.lineno)
            elif (len(node.elts) > 1 and not isinstance(first, ast.Constant) and isinstance(node.elts[1], ast.Constant)
                  and node.elts[1].value in ("-m", "-c")):
                lines.append(node.lineno)
    return sorted(set(lines))


@pytest.mark.parametrize(("code", "flagged"), [
    ('subprocess.run([sys.executable, "-m", "faultgen.cli", "monitor"])', True),
    ('command = [*FAULTGEN, "x"]\nFAULTGEN = [sys.executable, "-P", "-m", "faultgen.cli"]', True),
    ('subprocess.Popen(["python3", "-c", code])', True),
    ('subprocess.run(["/usr/bin/python3.11", script])', True),
    ('subprocess.run([interpreter, "-m", "faultgen.cli"])', True),
    ('str(Path(sys.executable).with_name("faultgen"))', True),
    ('subprocess.run([*children.command("-m", "faultgen.cli"), "monitor"], env=children.environment())', False),
    ('subprocess.run(["git", "-C", root, "archive"]); subprocess.run(["bash", "-c", "true"])', False),
])
def test_the_python_start_check_tells_the_forms_apart(code, flagged):
    assert bool(python_starts(code)) is flagged


def test_every_python_child_is_started_by_faultgen_children():
    """``python -m``/``-c`` put the current folder first on the child's path: a planted ``h5py.py``
    ran in each child of benchmarks/bench_all.py and twin_baseline.py. Only faultgen/children.py
    names the interpreter; everything else builds its command with :func:`faultgen.children.command`."""
    found = {}
    for top in SOURCES:
        for path in sorted((ROOT / top).rglob("*.py")):
            relative = path.relative_to(ROOT).as_posix()
            if relative == "faultgen/children.py":
                continue
            lines = python_starts(path.read_text())
            if lines:
                found[relative] = lines
    assert not found, f"Python started without faultgen.children.command (file: lines): {found}"


def planted(folder: Path) -> Path:
    """Modules that every faultgen command imports, planted in ``folder``, each writing the marker it
    returns when imported."""
    marker = folder / "planted-module-ran"
    for name in ("h5py", "numpy", "typer"):
        (folder / f"{name}.py").write_text(f"open({str(marker)!r}, 'a').write({name!r} + '\\n')\n")
    return marker


def test_the_twin_baselines_monitor_in_a_folder_with_a_planted_h5py_runs_none_of_it(tmp_path, monkeypatch):
    """benchmarks/twin_baseline.py's `faultgen monitor`, started in a folder holding an h5py.py (and
    numpy.py, typer.py): the child imports the installed packages, and the monitor refuses the
    missing logs, the marker never written."""
    spec = importlib.util.spec_from_file_location("twin_baseline", ROOT / "benchmarks" / "twin_baseline.py")
    twin_baseline = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(twin_baseline)
    from faultgen.bench import rawlogs

    here = tmp_path / "stranger"
    here.mkdir()
    marker = planted(here)
    monkeypatch.chdir(here)
    written = rawlogs.Written(logs=tmp_path / "no-logs", robot="irb6700", records={})
    with pytest.raises(SystemExit, match="no-logs"):  # the monitor ran and refused the missing folder
        twin_baseline.monitor(written, tmp_path / "out", 10, False, 1)
    assert not marker.exists(), marker.read_text()


# -- a monitor's workers end with it --------------------------------------------------------------

@pytest.fixture(scope="module")
def small_fleet(tmp_path_factory) -> Path:
    """3 units x 12 daily logs of irb6700 (synthetic, tests/fleetlog_folder.py; the model's torque,
    which the twin takes: issue 88)."""
    return fleetlog_folder.write_fleet(tmp_path_factory.mktemp("fleet") / "logs", robots.load("irb6700"), model=True)


def wait_for(condition, what: str, seconds: float) -> float:
    """Poll ``condition`` until it holds; the seconds it took (fail naming ``what`` after ``seconds``)."""
    start = time.monotonic()
    while not condition():
        if time.monotonic() - start > seconds:
            pytest.fail(f"waited {seconds} s for {what}")
        time.sleep(0.05)
    return time.monotonic() - start


def workers_of(pid: int) -> list[psutil.Process]:
    try:
        return psutil.Process(pid).children()
    except psutil.NoSuchProcess:
        return []


@pytest.mark.parametrize("how", [signal.SIGKILL, signal.SIGTERM])
def test_a_killed_monitor_leaves_no_worker_running(small_fleet, tmp_path, how):
    """`monitor --jobs 2` killed (its own process only, as `kill PID` does) while its two forked
    workers score units: both end within a second or two (PR_SET_PDEATHSIG, and a thread watching
    the parent: faultgen.pools.watch_parent). Before, they waited on the task queue for good,
    400-600 MB each."""
    mark = str(tmp_path)
    proc = subprocess.Popen(children.command("-m", "faultgen.cli", "monitor", str(small_fleet), "--robot", "irb6700",
                                             "-o", str(tmp_path / "out"), "--no-calibrate", "--jobs", "2",
                                             "--no-progress"),
                            cwd=tmp_path, env=children.environment({"FAULTGEN_TEST_MARK": mark}),
                            start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        wait_for(lambda: len(workers_of(proc.pid)) >= 2, "the monitor's two workers", 180)
        assert proc.poll() is None, "the monitor ended before it could be killed"
        proc.send_signal(how)
        proc.wait(timeout=60)
        took = wait_for(lambda: not marked(mark), "every worker of the killed monitor to end", 10)
    finally:
        for p in marked(mark):
            p.kill()
    assert took < 5


# -- --jobs: at most one worker per unit, a warning above the cores ---------------------------------

def test_monitor_jobs_above_the_units_and_cores_starts_one_worker_per_unit_and_warns(small_fleet, tmp_path,
                                                                                  monkeypatch):
    """`monitor --jobs 1024` on 3 units of a 2-core machine: 3 workers, and the sweep's warning."""
    started = []

    class Counted(concurrent.futures.ProcessPoolExecutor):
        def __init__(self, max_workers=None, *args, **kw):
            started.append(max_workers)
            super().__init__(max_workers, *args, **kw)

    monkeypatch.setattr(pools, "ProcessPoolExecutor", Counted)  # the pool faultgen.pools.forked_pool makes
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    result = runner.invoke(app, ["monitor", str(small_fleet), "--robot", "irb6700", "-o", str(tmp_path / "out"),
                                 "--protocol", "own", "--jobs", "1024", "--no-progress"])
    assert result.exit_code in (0, 3), result.output
    assert started == [3]
    assert ("warning: --jobs 1024 is more than the 2 CPU cores: the units share them and each takes longer"
            in result.output), result.output


# -- a failed monitor removes only what it made -----------------------------------------------------

@pytest.mark.parametrize("other_run", [True, False])
def test_a_failed_monitor_keeps_another_runs_outputs_in_the_new_parent_they_share(tmp_path, monkeypatch, other_run):
    """Two monitors into new folders under one new parent (`-o new/a`, `-o new/b`), started
    together: b found `new` missing, a finished its outputs there, then b failed. b removes its OUT
    and `new` only if nothing else is in it: a's outputs survive (b removed the whole of `new`)."""
    from faultgen.monitor import loop

    logs = tmp_path / "logs"
    logs.mkdir()
    new = tmp_path / "new"

    def other_run_finishes_then_this_one_fails(run):
        (run.out / ".cache").mkdir(parents=True)  # this run's cache, as loop.monitor makes it
        if other_run:
            (new / "a").mkdir()
            (new / "a" / "units.csv").write_text("unit,status\n")
        raise ValueError("a unit's log is refused")

    monkeypatch.setattr(loop, "monitor", other_run_finishes_then_this_one_fails)
    result = runner.invoke(app, ["monitor", str(logs), "--robot", "irb6700", "-o", str(new / "b"), "--no-progress"])
    assert result.exit_code == 2 and "a unit's log is refused" in result.output, result.output
    assert not (new / "b").exists()
    if other_run:
        assert (new / "a" / "units.csv").read_text() == "unit,status\n"
    else:
        assert not new.exists()  # nothing of b's left: the new parent too
