"""Reliability (issue 42): what a kill, a full or read-only disk and bad input leave behind.

Tests that wait on another process synchronise on what it does (a file appearing, a process
ending), polling with a generous deadline, never on a fixed sleep: they pass on a loaded machine.
"""

import json
import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import psutil
import pytest
from typer.testing import CliRunner

from faultgen import dataset, sweep
from faultgen.cli import app

runner = CliRunner()
CLI = [sys.executable, "-m", "faultgen.cli"]
# 4 runs of 2 recorded cycles: enough for two workers to be busy when the sweep is killed
GRID_ARGS = ["--robot", "irb6700", "--task", "pick_place", "--task", "spot_weld", "--axis", "0", "--axis", "2",
             "--cycles", "4", "--record", "1,4", "--no-progress"]


def wait_for(condition, what: str, seconds: float = 180) -> None:
    """Poll ``condition`` until it holds; fail naming ``what`` after ``seconds`` (a deadline, not a delay)."""
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > deadline:
            pytest.fail(f"waited {seconds} s for {what}")
        time.sleep(0.05)


def children(pid: int) -> list[psutil.Process]:
    try:
        return psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []


def all_gone(processes: list[psutil.Process]) -> bool:
    return not [p for p in processes if p.is_running() and p.status() != psutil.STATUS_ZOMBIE]


# -- group 1: a killed sweep stops its workers; SIGTERM is handled like Ctrl-C ---------------------

@pytest.mark.parametrize("how", [signal.SIGKILL, signal.SIGTERM])
def test_a_killed_sweep_leaves_no_worker_running(tmp_path, how):
    out = tmp_path / "killed.h5"
    parts = sweep.parts_folder(out)
    proc = subprocess.Popen([*CLI, "sweep", *GRID_ARGS, "--jobs", "2", "-o", str(out)], cwd=tmp_path,
                            start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        wait_for(lambda: (parts / "sweep.json").exists() and len(children(proc.pid)) >= 2, "two workers")
        workers = children(proc.pid)
        proc.send_signal(how)  # the sweep's own process only, as `kill PID` does
        stdout, stderr = proc.communicate(timeout=120)
        wait_for(lambda: all_gone(workers), "the workers to end", seconds=30)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        for p in children(proc.pid):
            p.kill()
    assert not out.exists()
    if how == signal.SIGTERM:
        kept = len(list(parts.glob("*.h5")))
        assert proc.returncode == 143, stdout + stderr
        assert stderr.strip() == (f"terminated (SIGTERM): {kept} of 4 runs kept in {parts}; run the same command "
                                  "to resume")
        assert not (tmp_path / ".killed.h5.lock").exists()
