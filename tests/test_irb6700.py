"""IRB-6700-like arm: kinematics and dynamics against independent DH models, mass, torque capacity."""

import mujoco
import numpy as np
import pytest
from toolbox_robots import irb6700, irb6700_balance_torque

from faultgen.model import robots


@pytest.fixture(scope="module")
def irb():
    return robots.load("irb6700")


@pytest.fixture(scope="module")
def dh_model():
    """Standard DH model of the IRB 6700-200/2.60 from the published dimensions
    (:func:`toolbox_robots.irb6700`, whose dynamics this kinematics check does not use).

    Base 0.78 m, shoulder offset 0.32 m, upper arm 1.125 m, wrist offset 0.2 m, forearm
    1.1425 m, flange 0.2 m; joint directions and zero pose of the ROS-Industrial description
    (lower arm vertical, forearm along +x at zero).
    """
    return irb6700()


def flange_pose(robot, q):
    """World position (m) and tool z axis of the flange site for arm angles q (rigid gearbox)."""
    model = robot.model
    data = mujoco.MjData(model)
    data.qpos[:], _ = robot.rigid_state(q)
    mujoco.mj_kinematics(model, data)
    site = model.site("flange").id
    return data.site_xpos[site].copy(), data.site_xmat[site].reshape(3, 3)[:, 2].copy()


def test_forward_kinematics_match_dh_at_home_and_20_random_poses(irb, dh_model):
    rng = np.random.default_rng(6700)
    poses = np.vstack([irb.home, rng.uniform(irb.joint_range[:, 0], irb.joint_range[:, 1], (20, 6))])
    worst = 0.0
    for q in poses:
        position, tool_z = flange_pose(irb, q)
        T = dh_model.fkine(q).A
        worst = max(worst, np.linalg.norm(position - T[:3, 3]))
        np.testing.assert_allclose(tool_z, T[:3, 2], atol=1e-9)
    print(f"largest flange position difference: {worst:.3g} m")
    assert worst <= 1e-3


def test_home_is_the_published_geometry(irb):
    position, tool_z = flange_pose(irb, irb.home)
    # reach 0.32 + 1.1425 + 0.2 ahead of axis 1, height 0.78 + 1.125 + 0.2
    np.testing.assert_allclose(position, [1.6625, 0.0, 2.105], atol=1e-12)
    np.testing.assert_allclose(tool_z, [1.0, 0.0, 0.0], atol=1e-12)


def test_total_mass_is_that_of_the_real_robot(irb):
    assert mujoco.mj_getTotalmass(irb.model) == pytest.approx(1170.0, rel=0.05)


def test_gravity_torques_at_home_are_within_motor_capacity(irb):
    zeros = np.zeros((1, 6))
    gravity = irb.inverse_dynamics(irb.home[None], zeros, zeros, friction=False)[0]
    capacity = irb.motor_torque_limit * irb.gear_ratio
    print("gravity at home [N m]:", np.round(gravity, 1), "capacity [N m]:", capacity)
    assert np.all(np.abs(gravity) <= capacity)
    # the forearm, wrist and flange ahead of axes 2 and 3 load them: the torque is not trivial
    assert abs(gravity[1]) > 500 and abs(gravity[2]) > 500


def test_gravity_torque_stays_within_capacity_with_rated_payload_over_the_workspace(irb):
    """200 kg at the flange (as a point mass), over random poses: still within capacity."""
    model = irb.model.__copy__()
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    data = mujoco.MjData(model)
    rng = np.random.default_rng(200)
    capacity = irb.motor_torque_limit * irb.gear_ratio
    site = model.site("flange").id
    for q in rng.uniform(irb.joint_range[:, 0], irb.joint_range[:, 1], (200, 6)):
        data.qpos[:], data.qvel[:] = irb.rigid_state(q)
        mujoco.mj_forward(model, data)
        jacp = np.zeros((3, model.nv))
        mujoco.mj_jacSite(model, data, jacp, None, site)
        payload = jacp.T @ np.array([0.0, 0.0, 200.0 * 9.81])
        tau = irb.inverse_dynamics(q[None], np.zeros((1, 6)), np.zeros((1, 6)), friction=False)[0]
        tau = tau + payload[irb.arm_dof] + irb.gear_ratio * payload[irb.rotor_dof]
        assert np.all(np.abs(tau) <= capacity), (q, tau)


def test_axis2_balancing_spring_offsets_gravity(irb):
    """Leaning the lower arm forward, the balancing spring takes a large share of the load."""
    zeros = np.zeros((1, 6))
    q = irb.home.copy()
    q[1] = 0.5
    with_spring = irb.inverse_dynamics(q[None], zeros, zeros, friction=False)[0, 1]
    stiffness = irb.model.jnt_stiffness[irb.model.joint("joint2").id]
    without_spring = with_spring - stiffness * q[1]
    assert stiffness > 0
    assert abs(with_spring) < 0.5 * abs(without_spring)


def test_inverse_dynamics_match_toolbox_rne(irb):
    """Rigid inverse dynamics against the toolbox's Newton-Euler on the README's parameters.

    Same physics on both sides: rigid bodies, gravity, motor inertia G^2 Jm qdd and the axis-2
    balancing spring, arm side; friction off (ours ``friction=False``, the toolbox's
    ``nofriction``). Then the friction each adds, Coulomb + viscous through G, is the same where
    our static (Stribeck) excess, which the toolbox lacks, is below exp(-36).
    """
    rng = np.random.default_rng(6700)
    n = 500
    q = rng.uniform(irb.joint_range[:, 0], irb.joint_range[:, 1], (n, 6))
    qd = rng.uniform(-1.0, 1.0, (n, 6))
    qdd = rng.uniform(-3.0, 3.0, (n, 6))
    toolbox = irb6700()
    frictionless = toolbox.nofriction(coulomb=True, viscous=True)
    ours = irb.inverse_dynamics(q, qd, qdd, friction=False)
    ref = frictionless.rne(q, qd, qdd) + irb6700_balance_torque(q)
    rel = np.sqrt(np.mean((ours - ref) ** 2, axis=0)) / np.sqrt(np.mean(ref**2, axis=0))
    print("per-axis relative RMS difference:", np.array2string(rel, precision=6))
    # about 1e-4: the README rounds the inertias to 3 digits (with MuJoCo's own values, 1e-9)
    assert np.all(rel <= 1e-3), rel

    away = np.abs(irb.gear_ratio * qd) >= 6 * irb.friction.stribeck_velocity
    our_friction = irb.inverse_dynamics(q, qd, qdd) - ours
    toolbox_friction = toolbox.rne(q, qd, qdd) - frictionless.rne(q, qd, qdd)
    np.testing.assert_allclose(our_friction[away], toolbox_friction[away], rtol=1e-9)
