"""The robot as one constant model (issue 47, item 1): resolved once at the boundary, held by the
run's configuration, simulation models derived from its spec in memory."""

import dataclasses
import pickle
import shutil
from pathlib import Path

import cloudpickle
import mujoco
import numpy as np
import pytest

from faultgen.model import robots
from faultgen.operation.wear import WearPlan
from faultgen.simulation import prepare
from faultgen.simulation import stepping as sim
from resolved_runs import run_config


def fields(model: mujoco.MjModel) -> dict:
    return {k: getattr(model, k) for k in dir(model) if not k.startswith("_") and isinstance(getattr(model, k), np.ndarray)}


def test_a_config_holds_the_robot_given_and_records_its_name():
    robot = robots.load("puma560")
    config = run_config(robot=robot, task="pick_place", cycles=2)
    assert config.model is robot and config.robot == "puma560"
    by_name = run_config(robot="puma560", task="pick_place", cycles=2)
    assert by_name.model is robot and by_name == config  # the same run, whichever way it was named


def test_a_config_of_an_edited_robot_records_its_path(tmp_path):
    robot = robots.load("puma560").edited(lambda spec: None)
    config = run_config(robot=robot, task="pick_place", cycles=2)
    assert config.model is robot and config.robot == str(robot.path) and robot.digest is None


def test_a_given_robot_is_not_resolved_again(monkeypatch):
    robot = robots.load("puma560")
    monkeypatch.setattr(robots, "load", lambda name: pytest.fail(f"resolved {name!r} again"))
    config = run_config(robot="puma560", task="pick_place", cycles=2, resolved=robot)
    assert dataclasses.replace(config, seed=3).model is robot
    assert sim.cycle_duration(config.model, config.task) > 0


def test_a_pickled_config_leaves_the_robot_behind_and_resolves_it_once_there():
    """As Dask sends it to a worker (cloudpickle: a WearPlan's read-only mapping needs it)."""
    config = run_config(robot="puma560", task="pick_place", wear=WearPlan.from_specs(["2:exp4:20"], 2), cycles=2)
    state = config.__getstate__()
    assert state["resolved"] is None and config.resolved is not None
    back = cloudpickle.loads(cloudpickle.dumps(config))
    assert back == config and back.resolved is None
    assert back.model is robots.load("puma560") and back.resolved is back.model


def test_a_pickled_robot_derives_the_same_models():
    robot = robots.load("irb6700")
    back = pickle.loads(pickle.dumps(robot))
    a, b = fields(robot.new_spec().compile()), fields(back.new_spec().compile())
    assert all(np.array_equal(a[k], b[k]) for k in a)
    edited = robot.edited(lambda spec: setattr(spec.option, "timestep", 0.0005))
    again = pickle.loads(pickle.dumps(edited))
    assert again.model.opt.timestep == 0.0005 and again.new_spec().compile().opt.timestep == 0.0005


def test_the_simulation_model_is_derived_from_the_robot_s_spec_not_its_file(tmp_path):
    """A copy of the robot's file edited after it was read changes nothing the robot derives."""
    folder = tmp_path / "puma560"
    shutil.copytree(robots.available()["puma560"].parent, folder)
    robot = robots.load(folder)
    before = fields(prepare.prepared_for(robot, "pick_place", "stribeck").sim.model)
    path = Path(robot.path)
    path.write_text(path.read_text().replace('<numeric name="friction1" data="0.395', '<numeric name="friction1" data="0.5'))
    derived = fields(prepare.build(robot, "stribeck").model)
    assert all(np.array_equal(before[k], derived[k]) for k in before)
    assert robots.load(folder) is not robot  # the edited file is another robot, resolved anew


def test_a_spec_handed_out_is_a_copy():
    robot = robots.load("puma560")
    spec = robot.new_spec()
    spec.option.timestep = 0.01
    assert robot.new_spec().option.timestep == robot.model.opt.timestep != 0.01


def test_a_config_of_a_robot_edited_in_memory_takes_it_along_when_pickled():
    robot = robots.load("puma560").edited(lambda spec: setattr(spec.option, "timestep", 0.0005))
    config = run_config(robot=robot, task="pick_place", cycles=2)
    back = cloudpickle.loads(cloudpickle.dumps(config))
    assert back.resolved is not None and back.model.model.opt.timestep == 0.0005
