"""Re-simulation along a measured motion, for the one effect with no rigid-body torque: backlash.

A dead band in the gearbox (MuJoCo tendon ``springlength="-b/2 b/2"``) changes nothing in the
inverse dynamics of a rigid arm: its trace in the drive torque is dynamic, the motor crossing
the gap and the arm landing on the other flank each time the gearbox load changes sign. So the
workflow measures it the way it arises: the closed loop of :mod:`faultgen.sim` (PID drives
with nominal feedforward, flexible gearboxes, static Stribeck friction with stiction) is made to
track the measured motion (the set-points are the measured angles, spline-interpolated to the
physics rate, and their filtered derivatives) once per dead-band setting, all settings stepped
together in one ``mujoco.batch.Batch`` with per-simulation ``tendon_lengthspring``. The backlash
torque is the drive torque with the dead band minus the drive torque without it, so the
controller's own tracking error cancels.
"""

from __future__ import annotations

import numpy as np
from mujoco import batch as mjbatch
from scipy.interpolate import CubicSpline

from faultgen import control, robots, sim


def drive_torque(robot: robots.Robot, t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                 backlash: np.ndarray) -> np.ndarray:
    """Arm-side drive torque of the closed loop tracking ``q`` for each set of dead-band widths.

    Parameters
    ----------
    robot : Robot
        The model (its own backlash is replaced by each row of ``backlash``).
    t : ndarray of shape (n,)
        Sample times, s.
    q, qd, qdd : ndarray of shape (n, 6)
        Measured arm-side angles (rad) and their velocities (rad/s) and accelerations (rad/s^2).
    backlash : ndarray of shape (m, 6)
        Dead-band width per simulation and axis, rad at the arm side.

    Returns
    -------
    ndarray of shape (m, n, 6)
        Drive torque times the gear ratio, N m, at the sample times.
    """
    backlash = np.atleast_2d(np.asarray(backlash, dtype=float))
    built = sim.build(robot, "stribeck")
    model = built.model
    dt = model.opt.timestep
    t = np.asarray(t, dtype=float) - float(t[0])
    steps = np.arange(int(np.floor(t[-1] / dt)) + 1) * dt
    q_ref = CubicSpline(t, q)(steps)
    qd_ref = np.stack([np.interp(steps, t, qd[:, i]) for i in range(6)], axis=1)
    qdd_ref = np.stack([np.interp(steps, t, qdd[:, i]) for i in range(6)], axis=1)
    inputs = control.setpoints(robot, q_ref, qd_ref, qdd_ref)
    sample_step = np.minimum(np.round(t / dt).astype(int), len(steps) - 1)

    nsim = len(backlash)
    runs = mjbatch.Batch(model, nsim=nsim, nthread=0)
    qpos, qvel = sim.start_state(robot, q_ref[0])
    qvel[robot.arm_dof] = qd_ref[0]
    qvel[robot.rotor_dof] = robot.gear_ratio * qd_ref[0]
    runs.qpos, runs.qvel = qpos, qvel
    runs.act = 0.0
    tendons = [model.tendon(n).id for n in robot.gearbox_names]
    spring = runs.expand("tendon_lengthspring")
    spring[:, tendons, 0] = -backlash / 2
    spring[:, tendons, 1] = backlash / 2
    frictionloss = runs.expand("dof_frictionloss")
    velocity, ctrl, force = runs.bind("qvel"), runs.bind("ctrl"), runs.bind("actuator_force")
    rotor = robot.rotor_dof
    torque = np.empty((nsim, len(t), 6))
    record_at = np.full(len(steps), -1)
    record_at[sample_step] = np.arange(len(t))  # a step records the last sample that maps to it
    for step in range(len(steps)):
        if record_at[step] >= 0:
            torque[:, sample_step == step] = force[:, built.drive_ids][:, None] * robot.gear_ratio
        frictionloss[:, rotor] = robot.friction.stribeck_level(velocity[:, rotor])
        ctrl[:, built.drive_ctrl] = inputs[step]
        runs.step()
    return torque


def backlash_torque(robot: robots.Robot, t, q, qd, qdd, backlash: np.ndarray) -> np.ndarray:
    """Drive torque the dead bands ``backlash`` (6,) add along the motion, N m, (n, 6)."""
    both = drive_torque(robot, t, q, qd, qdd, np.stack([np.asarray(backlash, dtype=float), np.zeros(6)]))
    return both[0] - both[1]
