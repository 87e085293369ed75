"""One robot model per run (issue 47, item 1): a default ``faultgen simulate`` resolves its robot once
and compiles at most twice (the robot, its simulation model); a ``--fault`` run at most three times
(the faulted model and the two the fault's fields are read from are derived from the robot's spec).

Each count is taken in a fresh interpreter, so no cache of an earlier test hides a compile. Run with
another checkout first on ``PYTHONPATH`` (``FAULTGEN_CHECKOUT=/work/main``), the same test shows
what that checkout does: before this issue, 9 resolutions and 3 compiles for a default simulate.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(os.environ.get("FAULTGEN_CHECKOUT", Path(__file__).resolve().parents[1]))

#: Runs in the fresh interpreter: counts ``robots.load`` calls and every MuJoCo compile (an MjSpec
#: compiled, or an MjModel made from an MJCF file, string or binary) while the CLI runs.
COUNTER = r"""
import collections, json, sys
import mujoco
from faultgen.model import robots
counts = collections.Counter()

def counted(name, function, method=False):
    def wrapper(*args, **kwargs):
        counts[name] += 1
        return function(*args, **kwargs)
    return wrapper

robots.load = counted("resolved", robots.load)
mujoco.MjSpec.compile = counted("compiled", mujoco.MjSpec.compile)
for name in ("from_xml_path", "from_xml_string", "from_binary_path"):
    setattr(mujoco.MjModel, name, counted("compiled", getattr(mujoco.MjModel, name)))
from faultgen.cli import app
try:
    app(sys.argv[1:], standalone_mode=False)
finally:
    print("COUNTS " + json.dumps(counts))
"""


def counts(tmp_path: Path, *args: str) -> dict:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", COUNTER, "simulate", "--cycles", "2", "--no-progress",
                          "-o", str(tmp_path / "run.h5"), *args],
                         env=env, capture_output=True, text=True, timeout=600, check=False)
    assert out.returncode == 0, out.stdout + out.stderr
    line = [x for x in out.stdout.splitlines() if x.startswith("COUNTS ")][-1]
    return json.loads(line.removeprefix("COUNTS "))


def test_a_default_simulate_resolves_its_robot_once_and_compiles_at_most_twice(tmp_path):
    seen = counts(tmp_path)
    assert seen.get("resolved", 0) == 1, seen
    assert 1 <= seen.get("compiled", 0) <= 2, seen


@pytest.mark.parametrize("fault", ["backlash:2:width:0.01", "cogging:3:amplitude:0.05:poles=8,kind=exp4"])
def test_a_fault_run_compiles_at_most_three_models(tmp_path, fault):
    seen = counts(tmp_path, "--fault", fault)
    assert seen.get("resolved", 0) == 1, seen
    assert 1 <= seen.get("compiled", 0) <= 3, seen
