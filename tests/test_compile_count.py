"""One robot model per run (issue 47, item 1): a default ``faultgen simulate`` resolves its robot once
and compiles at most twice (the robot, its simulation model); a ``--fault`` run at most three times
(the faulted model and the two the fault's fields are read from are derived from the robot's spec).

Each count is taken in a fresh interpreter, so no cache of an earlier test hides a compile. Run with
another checkout first on ``PYTHONPATH`` (``FAULTGEN_CHECKOUT=/work/main``), the same test shows
what that checkout does.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from faultgen import effects
from faultgen.model import robots
from faultgen.operation import faults
from faultgen.simulation import prepare

ROOT = Path(os.environ.get("FAULTGEN_CHECKOUT", Path(__file__).resolve().parents[1]))

#: Runs in the fresh interpreter: counts ``robots.load`` calls and every MuJoCo compile (an MjSpec
#: compiled, or an MjModel made from an MJCF file, string or binary) while the CLI runs; main
#: before issue 47 (aa73f68): 9 resolutions and 3 compiles, a --fault run 13 and 6.
COUNTER = r"""
import collections, json, sys
import mujoco
import mujoco.batch  # compiles an empty model at import to list its fields: MuJoCo's, not a robot
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
                         env=env, cwd=tmp_path, capture_output=True, text=True, timeout=600, check=False)
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


#: A growing fault of every effect that says its simulation model is affine in its parameters.
AFFINE = ["backlash:2:width:0.01", "cogging:3:amplitude:0.05:poles=8", "torque_offset:2:offset:3"]


def test_every_effect_that_says_its_model_is_affine_is_listed_here():
    said = {name for name in effects.EFFECTS if type(effects.get(name)).affine_mjcf}
    assert said == {text.split(":")[0] for text in AFFINE}


@pytest.mark.parametrize("friction_model", ["lugre", "stribeck"])
@pytest.mark.parametrize("text", AFFINE)
def test_an_effect_that_says_its_model_is_affine_in_its_parameter_is(text, friction_model):
    """What lets a fault run skip the third compile: the fields at a quarter of the growth are
    where the line through the final and half-way models puts them (else ValueError)."""
    fault = faults.parse_fault(text, last_cycle=10)
    model_at = prepare.fault_model(robots.load("puma560"), friction_model, fault)
    moved = prepare._affine_fields(model_at, fault.start, fault.final, model_at(fault.final).model, checked=True)
    assert moved  # the parameter moves some field, so the check compared something


def test_a_field_that_is_not_affine_in_the_parameter_is_refused():
    fault = faults.parse_fault("backlash:2:width:0.01", last_cycle=10)
    linear = prepare.fault_model(robots.load("puma560"), "stribeck", fault)

    def bent(value):  # a plug-in whose MJCF form is quadratic in its parameter
        return linear(fault.final * (value / fault.final) ** 2)

    with pytest.raises(ValueError, match="non-linearly"):
        prepare._affine_fields(bent, fault.start, fault.final, bent(fault.final).model, checked=True)
