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


def test_a_run_config_from_a_name_loads_nothing_when_constructed(monkeypatch):
    """scikit-learn's rule (issue 84, item 5): constructing a RunConfig loads no robot, reads and plans
    no task and looks no friction model up; resolve does, and refuses what the robot refuses."""
    from faultgen.operation import programs
    from faultgen.operation.wear import WearPlan
    from faultgen.simulation import friction_models, prepare
    from faultgen.simulation.config import RunConfig

    robot = robots.load("puma560")
    for module, name in [(robots, "load"), (prepare, "task_path"), (programs, "check_name"),
                         (friction_models, "get")]:
        monkeypatch.setattr(module, name, lambda *a, _n=name, **k: pytest.fail(f"{_n} called on construction"))
    worn = WearPlan.from_specs(["7:exp4:20"], 3)  # axis 7 of a 6-axis robot: the robot's check, not the values'
    config = RunConfig("puma560", "no_such_task.toml", friction="no_such_model", wear=worn, cycles=3)
    assert config.resolved is None and config.robot == "puma560" and config.cycles == 3
    with pytest.raises(ValueError, match="cycles = 0"):  # the values are still checked
        RunConfig("puma560", "pick_place", cycles=0)
    monkeypatch.undo()
    with pytest.raises(ValueError, match="axis 7 is out of range"):
        resolve(RunSpec("puma560", "pick_place", wear=worn, cycles=3), resolved=robot)
    with pytest.raises(ValueError, match="no_such_model"):
        resolve(RunSpec("puma560", "pick_place", friction="no_such_model", cycles=3), resolved=robot)
    from faultgen.simulation import stepping

    with pytest.raises(ValueError, match="axis 7 is out of range"):  # built from a name: checked when simulated
        stepping.simulate(RunConfig("puma560", "pick_place", wear=worn, cycles=3), progress=False)
