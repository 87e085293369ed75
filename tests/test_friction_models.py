"""The simulated friction models against their equations.

A test rig of six free rotors named like a robot's (``rotor1..6``, each with the robot's motor
inertia) gets the robot's friction exactly as a simulation does (``friction.add_lugre`` /
``friction.add_stribeck``); no gearbox or arm is attached, so the rotor feels friction only, and
the damping of its drive's speed loop (joint damping kd), without which the bristles of the lugre
model ring without damping (``friction.check_lugre_step``).
"""

import mujoco
import numpy as np
import pytest

from faultgen.effects import friction
from faultgen.model import robots
from faultgen.simulation import control

TIMESTEP = 0.0005


def rig(robot, model_name, armature=None):
    spec = mujoco.MjSpec()
    spec.option.timestep = TIMESTEP
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    kd = control.ServoGains.for_robot(robot).kd
    for k, name in enumerate(robot.rotor_names):
        body = spec.worldbody.add_body(name=name)
        body.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1],
                       armature=float(robot.motor_inertia[k] if armature is None else armature),
                       damping=float(kd[k]))
        body.mass = 1e-9
        body.inertia = [1e-12] * 3
        body.explicitinertial = True
    if model_name == "lugre":
        friction.add_lugre(spec, robot)
    else:
        friction.add_stribeck(spec, robot)
    return spec.compile()


def rig_friction(model, data, robot, model_name):
    """Friction torque on each rotor, N m, positive when opposing positive motion."""
    if model_name == "lugre":
        ids = [model.actuator(f"lugre{k + 1}").id for k in range(6)]
        return -data.actuator_force[ids] + robot.friction.viscous * data.qvel
    return -data.qfrc_constraint + robot.friction.viscous * data.qvel


def step(model, data, robot, model_name):
    if model_name == "stribeck":  # as faultgen.simulation.friction_models does before every step
        model.dof_frictionloss[:] = robot.friction.stribeck_level(data.qvel[None])[0]
    mujoco.mj_step(model, data)


@pytest.mark.parametrize("name", ["irb6700", "puma560"])
@pytest.mark.parametrize("model_name", friction.MODELS)
def test_friction_at_constant_speed_follows_eq_6_3(name, model_name):
    """LuGre's steady state and the static model both equal the Stribeck curve (eq. 6.3)."""
    robot = robots.load(name)
    # huge rotor inertia: friction cannot change the speed noticeably
    model = rig(robot, model_name, armature=1e6)
    data = mujoco.MjData(model)
    vs = robot.friction.stribeck_velocity
    for ratio in (0.5, 1.0, 2.0, 6.0):
        for sign in (1.0, -1.0):
            mujoco.mj_resetData(model, data)
            data.qvel[:] = sign * ratio * vs
            # 3 s: the slowest bristles (PUMA 560, 0.5 v_s) settle with g / (sigma_0 |v|) = 0.19 s
            for _ in range(6000):
                step(model, data, robot, model_name)
            mujoco.mj_forward(model, data)
            measured = rig_friction(model, data, robot, model_name)
            expected = robot.friction.stribeck_torque(data.qvel[None])[0]
            if model_name == "lugre":  # MuJoCo's LuGre is symmetric: mean Coulomb level
                mean = (robot.friction.coulomb_pos + robot.friction.coulomb_neg) / 2
                expected = expected + np.sign(data.qvel) * (mean - np.where(data.qvel > 0, robot.friction.coulomb_pos,
                                                                             robot.friction.coulomb_neg))
            np.testing.assert_allclose(measured, expected, rtol=2e-3, err_msg=f"v = {sign * ratio} v_s")


@pytest.mark.parametrize("model_name", friction.MODELS)
def test_breakaway_under_slowly_rising_torque_is_coulomb_plus_static(model_name):
    """The breakaway torque, the largest friction torque the rotor takes as the applied torque
    rises slowly past it, is f_c + f_s. (LuGre creeps before it breaks away: its presliding speed
    is the torque rate / (sigma_0 (1 - F / F_s)), so a speed threshold would find it early.)"""
    robot = robots.load("irb6700")
    model = rig(robot, model_name)
    data = mujoco.MjData(model)
    f = robot.friction
    breakaway = f.coulomb_pos + f.static
    duration = 20.0  # s: reach 1.5 times the breakaway level, slowly
    rate = 1.5 * breakaway / duration
    largest = np.zeros(6)
    for k in range(int(duration / TIMESTEP)):
        data.qfrc_applied[:] = rate * k * TIMESTEP
        step(model, data, robot, model_name)
        mujoco.mj_forward(model, data)
        largest = np.maximum(largest, rig_friction(model, data, robot, model_name) - f.viscous * data.qvel)
    assert np.all(data.qvel > 0.05 * f.stribeck_velocity)  # every rotor broke away (lugre rig: damped by kd)
    print(model_name, "breakaway / (f_c + f_s):", largest / breakaway)
    np.testing.assert_allclose(largest, breakaway, rtol=0.01)


def test_lugre_holds_a_torque_below_breakaway_on_its_bristles():
    """Under 10 % of the breakaway torque the rotor comes to rest held by its bristles,
    sigma_0 z = F; its displacement is F / sigma_0 plus what it slipped on the way (1.05-1.17 at
    0.5 ms, 1.05-1.16 at a 0.0625 ms step: the approach is damped only by the drive, sigma_1 = 0)."""
    robot = robots.load("irb6700")
    model = rig(robot, "lugre")
    data = mujoco.MjData(model)
    f = robot.friction
    force = 0.1 * (f.coulomb_pos + f.static)
    data.qfrc_applied[:] = force
    for _ in range(int(1.0 / TIMESTEP)):
        mujoco.mj_step(model, data)
    mujoco.mj_forward(model, data)
    assert np.all(np.abs(data.qvel) < 1e-5)  # at rest: stuck, not sliding
    np.testing.assert_allclose(rig_friction(model, data, robot, "lugre"), force, rtol=1e-3)
    print("presliding displacement / (F / sigma_0):", data.qpos / (force / f.bristle_stiffness))
    assert np.all(data.qpos >= force / f.bristle_stiffness)
    assert np.all(data.qpos < 1.25 * force / f.bristle_stiffness)


def test_static_model_sticks_below_breakaway():
    robot = robots.load("irb6700")
    model = rig(robot, "stribeck")
    data = mujoco.MjData(model)
    data.qfrc_applied[:] = 0.9 * (robot.friction.coulomb_pos + robot.friction.static)
    for _ in range(int(1.0 / TIMESTEP)):
        step(model, data, robot, "stribeck")
    assert np.all(np.abs(data.qpos) < 1e-3)


def test_lugre_needs_gamma_2():
    robot = robots.load("irb6700")
    rows = robot.friction.as_rows()
    rows[2, friction.FIELDS.index("stribeck_exponent")] = 1.5
    with pytest.raises(ValueError, match="axis 3: stribeck_exponent = 1.5"):
        friction.lugre_parameters(friction.MotorFriction.from_rows(rows), 0.0005)
