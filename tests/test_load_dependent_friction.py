"""Load-dependent friction's two forms: the static load against the toolbox, the simulation's
per-step form against the model's, and the gravity form named by the calibration.

Independent: the static load against roboticstoolbox-python's ``gravload``. Not independent (our
simulator, our model): the simulation's kinematic form and the hidden-effect round trip.
"""

import numpy as np
import pytest
import roboticstoolbox as rtb  # test dependency, declared in pyproject.toml [test]
from mujoco import batch as mjbatch
from toolbox_robots import irb6700, irb6700_balance_torque

from faultgen.calibrate import calibrate, synth
from faultgen.model import robots


@pytest.mark.parametrize("name", ["puma560", "irb6700"])
def test_static_load_is_the_toolbox_gravity_load(name):
    """The torque that holds the arm still: the toolbox's ``gravload`` plus, on the IRB-6700-like
    arm, the balancing spring the axis-2 drive holds."""
    robot = robots.load(name)
    rng = np.random.default_rng(560)
    q = rng.uniform(robot.joint_range[:, 0], robot.joint_range[:, 1], (50, 6))
    toolbox = rtb.models.DH.Puma560() if name == "puma560" else irb6700()
    ref = np.asarray(toolbox.gravload(q)) + (irb6700_balance_torque(q) if name == "irb6700" else 0.0)
    ours = robot.static_load(q)
    scale = np.sqrt(np.mean(ref**2, axis=0))
    # the IRB's README rounds its inertial parameters to 3 digits; axis 6 carries almost no load
    assert np.all(np.sqrt(np.mean((ours - ref) ** 2, axis=0)) <= 1e-3 * np.maximum(scale, scale.max() * 1e-3))


@pytest.mark.parametrize("name", ["puma560", "irb6700"])
def test_simulation_form_of_the_static_load_is_the_models(name):
    """What the stepping loop evaluates from MuJoCo's kinematics of many runs at once."""
    robot = robots.load(name)
    q = np.random.default_rng(6).uniform(robot.joint_range[:, 0], robot.joint_range[:, 1], (20, 6))
    batch = mjbatch.Batch(robot.model, nsim=len(q))
    qpos = np.zeros((len(q), robot.model.nq))
    qpos[:, robot.arm_qpos], qpos[:, robot.rotor_qpos] = q, robot.gear_ratio * q
    batch.qpos, batch.qvel = qpos, 0.0
    fields = [batch.bind(f) for f in ("subtree_com", "xanchor", "xaxis")]
    batch.forward()
    ours = robot.static_load(q)
    np.testing.assert_allclose(robot.static_load_of(*fields, batch.bind("qpos")), ours,
                               atol=1e-9 * np.max(np.abs(ours)))


def test_gravity_form_is_simulated_and_named(tmp_path):
    """Friction on the PUMA 560's shoulder growing with its gravity load, simulated (static model,
    the per-step update), is named in that form on that axis with the gap halved. One cycle (two
    before 2026-11-27): the coefficient 0.4992, the gap after 0.22 of the gap before."""
    robot = robots.load("puma560")
    hidden = synth.Hidden.of(robot, "load_dependent_friction", {1: {"coefficient": 0.5, "gravity_load": 1}}, 1.0)
    path = synth.record(robot, hidden, tmp_path / "measured.csv", cycles=1, seed=1)
    result = calibrate("puma560", path, tmp_path / "out", figure=False)
    first = result.steps[0]
    assert (first.effect.id, first.axes) == ("load_dependent_friction", [1]), result.summary()
    assert first.effect.values(1)["gravity_load"] == 1
    assert first.effect.coefficient[1] == pytest.approx(0.5, rel=0.05)
    assert result.gap_after["total_nrmse"] <= 0.5 * result.gap_before["total_nrmse"], result.summary()
