"""Every command's runs through ``resolve(RunSpec)`` (issue 84, item 5; docs/architecture.md, "Every
command's runs through resolve"): no ``RunConfig`` built outside ``faultgen/simulation``, a robot the
caller holds taken as it is, and a worker's run shipped without its compiled robot, its stepper on it."""

import ast
import pickle
from pathlib import Path

import pytest

from faultgen.model import robots
from faultgen.simulation import backends
from faultgen.simulation.resolve import Run, resolve
from faultgen.simulation.spec import RunSpec

ROOT = Path(__file__).resolve().parents[1]


def _run_configs_built(path: Path) -> list[str]:
    """Where ``path`` calls ``RunConfig(...)`` or ``X.RunConfig(...)``."""
    tree = ast.parse(path.read_text(), str(path))
    return [f"{path.relative_to(ROOT)}:{node.lineno}" for node in ast.walk(tree) if isinstance(node, ast.Call)
            and (getattr(node.func, "id", None) == "RunConfig" or getattr(node.func, "attr", None) == "RunConfig")]


def test_no_run_config_is_built_outside_the_simulation_package():
    files = [p for p in sorted((ROOT / "faultgen").rglob("*.py")) if "simulation" not in p.relative_to(ROOT).parts]
    assert [where for path in files for where in _run_configs_built(path)] == []
    # the scan sees a construction where there is one
    assert _run_configs_built(ROOT / "faultgen" / "simulation" / "resolve.py")


def test_resolve_takes_the_robot_the_caller_holds(monkeypatch):
    robot = robots.load("puma560")
    loads = []
    monkeypatch.setattr(robots, "load", lambda name: loads.append(name))
    run = resolve(RunSpec("puma560", "pick_place", cycles=2, stepper="loop"), resolved=robot)
    assert loads == []
    assert run.config.model is robot and run.config.robot == "puma560" and run.config.cycles == 2
    assert run.stepper == backends.LoopStepper()


def test_resolve_refuses_a_robot_that_is_not_a_robot():
    with pytest.raises(TypeError, match="resolved = a str; expected a Robot"):
        resolve(RunSpec("puma560", "pick_place", cycles=1), resolved="puma560")


def test_a_run_travels_to_a_worker_without_its_compiled_robot():
    run = resolve(RunSpec("puma560", "pick_place", cycles=1, stepper="loop"))
    sent = pickle.dumps(run)
    back = pickle.loads(sent)
    assert len(sent) < 4000  # names and values only: the compiled model is megabytes
    assert back.config.resolved is None and back.config == run.config and back.stepper == backends.LoopStepper()
    assert back.config.model.digest == run.config.model.digest  # loaded again where it arrives
    assert isinstance(back, Run)
