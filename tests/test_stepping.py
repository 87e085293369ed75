"""Both robots step cleanly for 10 s under a PD hold and under a scripted motion.

The controller here is a test fixture, not the project's controller: a motor-side PD on motor
angle and velocity with inverse-dynamics feedforward, gains set for a 5 Hz, 0.7-damped loop.
"""

import mujoco
import numpy as np
import pytest

from faultgen.model import robots

ROBOTS = ["puma560", "irb6700"]
DURATION = 10.0  # s
FEEDFORWARD_PERIOD = 0.004  # s: torque feedforward refreshed at 250 Hz, held in between


def pd_gains(robot):
    """Motor-side kp (N m/rad) and kd (N m s/rad) for a 5 Hz, 0.7-damped loop per axis."""
    data = mujoco.MjData(robot.model)
    data.qpos[:], _ = robot.rigid_state(robot.home)
    mujoco.mj_forward(robot.model, data)
    full = np.zeros((robot.model.nv, robot.model.nv))
    mujoco.mj_fullM(robot.model, data, full)
    inertia = full[robot.arm_dof, robot.arm_dof] + robot.gear_ratio**2 * robot.motor_inertia  # arm side
    omega = 2 * np.pi * 5.0
    G2 = robot.gear_ratio**2
    return inertia * omega**2 / G2, 2 * 0.7 * omega * inertia / G2


def run(robot, q_ref, qd_ref, qdd_ref):
    """Step the full model along an arm-side reference sampled at every physics step.

    Returns the arm angles, rotor angles and warning counts after each step.
    """
    model = robot.model
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = robot.rigid_state(q_ref[0], qd_ref[0])
    G = robot.gear_ratio
    kp, kd = pd_gains(robot)
    hold = int(round(FEEDFORWARD_PERIOD / model.opt.timestep))
    feedforward = robot.inverse_dynamics(q_ref[::hold], qd_ref[::hold], qdd_ref[::hold], friction=False) / G
    arm = np.empty_like(q_ref)
    rotor = np.empty_like(q_ref)
    for k in range(len(q_ref)):
        error = G * q_ref[k] - data.qpos[robot.rotor_qpos]
        rate_error = G * qd_ref[k] - data.qvel[robot.rotor_dof]
        data.ctrl[:] = kp * error + kd * rate_error + feedforward[k // hold]
        mujoco.mj_step(model, data)
        arm[k] = data.qpos[robot.arm_qpos]
        rotor[k] = data.qpos[robot.rotor_qpos]
    warnings = {mujoco.mjtWarning(i).name: int(w.number) for i, w in enumerate(data.warning) if w.number}
    return arm, rotor, warnings


def scripted_motion(robot):
    """Smooth motion over a quarter of each joint's range (at most 0.8 rad), 0.2-0.45 Hz."""
    dt = robot.model.opt.timestep
    t = np.arange(int(DURATION / dt))[:, None] * dt
    span = np.minimum(0.25 * np.diff(robot.joint_range, axis=1)[:, 0], 0.8)
    omega = 2 * np.pi * np.array([0.2, 0.25, 0.3, 0.35, 0.4, 0.45])
    start = np.clip(robot.home, robot.joint_range[:, 0], robot.joint_range[:, 1] - span)
    q = start + span * (1 - np.cos(omega * t)) / 2
    qd = span * omega * np.sin(omega * t) / 2
    qdd = span * omega**2 * np.cos(omega * t) / 2
    return q, qd, qdd


@pytest.mark.parametrize("name", ROBOTS)
def test_pd_hold_at_home_is_clean_and_gearbox_deflects_by_torque_over_stiffness(name):
    robot = robots.load(name)
    n = int(DURATION / robot.model.opt.timestep)
    q_ref = np.tile(robot.home, (n, 1))
    zeros = np.zeros_like(q_ref)
    arm, rotor, warnings = run(robot, q_ref, zeros, zeros)
    assert warnings == {}
    assert np.all(np.isfinite(arm)) and np.all(np.isfinite(rotor))

    deflection = rotor[-1] / robot.gear_ratio - arm[-1]
    # static arm-side torque the gearbox must carry at the pose the arm settled in
    static = robot.inverse_dynamics(arm[-1][None], zeros[:1], zeros[:1], friction=False)[0]
    expected = static / robot.gearbox_stiffness
    print(f"{name} deflection [rad]: {deflection}\n{name} torque / K  [rad]: {expected}")
    loaded = np.abs(static) > 1e-3
    assert loaded.any()
    np.testing.assert_allclose(deflection[loaded], expected[loaded], rtol=0.01)
    np.testing.assert_allclose(deflection[~loaded], 0.0, atol=1e-9)


@pytest.mark.parametrize("name", ROBOTS)
def test_scripted_motion_is_clean_tracks_and_repeats_bit_for_bit(name):
    robot = robots.load(name)
    q, qd, qdd = scripted_motion(robot)
    arm, rotor, warnings = run(robot, q, qd, qdd)
    assert warnings == {}
    assert np.all(np.isfinite(arm)) and np.all(np.isfinite(rotor))
    tracking = np.max(np.abs(arm[:-1] - q[1:]), axis=0)
    print(f"{name} largest tracking error per axis [rad]: {tracking}")
    assert np.all(tracking < 5e-3)
    again, _, _ = run(robot, q, qd, qdd)
    assert np.array_equal(arm, again)
