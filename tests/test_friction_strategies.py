"""The simulation's friction models as strategy objects (faultgen.simulation.friction_models):
one per name of faultgen.effects.friction.MODELS, each putting itself into the compiled model."""

import numpy as np
import pytest

from faultgen.effects import friction
from faultgen.model import robots
from faultgen.simulation import friction_models
from faultgen.simulation import stepping as sim


def test_one_strategy_per_friction_model_name():
    assert tuple(friction_models.MODELS) == friction.MODELS
    with pytest.raises(ValueError, match=r"unknown friction model 'coulomb'; expected one of: lugre, stribeck"):
        friction_models.get("coulomb")


@pytest.mark.parametrize("name", friction.MODELS)
def test_a_built_model_carries_its_strategy_and_its_actuators(name):
    robot = robots.load("puma560")
    model = sim.build(robot, name)
    assert model.stepping is friction_models.get(name) and model.friction_model == name
    lugre = [model.model.actuator(k).name for k in model.lugre_ids]
    assert lugre == ([f"lugre{k}" for k in range(1, 7)] if name == "lugre" else [])
    # the static model's friction is the rotors' friction loss, set from Python every step
    assert friction_models.get(name).per_step == (name == "stribeck")
    assert np.any(model.model.dof_frictionloss[robot.rotor_dof] > 0) == (name == "stribeck")
