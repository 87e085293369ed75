"""The robot controller: a motor-side PID per axis with feedforward from the nominal model.

Each axis is driven as an industrial servo drive is: a current-controlled motor whose torque
command is a PID on motor angle and speed plus a torque feedforward,

    tau_m = kp (G q_ref - q_m) + kd (G qd_ref - qd_m) + ki x_I + tau_ff,   x_I' = G q_ref - q_m,

saturated at the motor's peak torque. It runs inside MuJoCo at the physics rate, as the on-board
controller of a ``dcmotor`` actuator (inputs ``pos vel ff``; unit motor and torque constants, so
the commanded torque is delivered exactly). The feedforward is the rigid-body inverse dynamics of
the *nominal* model with *nominal* friction (thesis eqs. 6.1-6.3): the controller does not know
about wear, so growing friction shows up in the motor torque, as on a real robot.

Gains are set per axis from the rigid-gearbox inertia seen by the motor at the robot's home pose,
J = (M_aa(home) + G^2 Jm) / G^2 (kg m^2, motor side), for a closed-loop bandwidth of 5 Hz and
damping ratio 0.7:  kp = J w^2,  kd = 2 zeta w J,  ki = kp w / 5,  w = 2 pi 5 rad/s. The
integrator is clamped so that it supplies at most half the peak motor torque (anti-windup).
5 Hz stays below the gearbox resonances of both robots (>= 11.8 Hz, docs/robots.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from faultgen.model.robots import Robot

BANDWIDTH_HZ = 5.0
DAMPING_RATIO = 0.7
INTEGRAL_FRACTION = 0.2  # integral corner frequency as a fraction of the bandwidth
INTEGRAL_TORQUE_SHARE = 0.5  # anti-windup: the integral supplies at most this share of the peak torque

#: Control inputs of every drive, in MuJoCo's ``ctrl`` order: position and speed set-points
#: (motor side, rad and rad/s) and torque feedforward (N m, motor side).
INPUTS = ("pos", "vel", "ff")


@dataclass(frozen=True)
class ServoGains:
    """Motor-side PID gains of the N drives, each an ``ndarray of shape (N,)``.

    Attributes
    ----------
    kp : N m/rad.   kd : N m s/rad.   ki : N m/(rad s).
    integral_limit : rad s, clamp on the integrator state x_I.
    """

    kp: np.ndarray
    kd: np.ndarray
    ki: np.ndarray
    integral_limit: np.ndarray

    @classmethod
    def for_robot(cls, robot: Robot) -> ServoGains:
        """Gains for a 5 Hz, 0.7-damped position loop per axis (see module docstring)."""
        data = mujoco.MjData(robot.model)
        data.qpos[:], _ = robot.rigid_state(robot.home)
        mujoco.mj_forward(robot.model, data)
        full = np.zeros((robot.model.nv, robot.model.nv))
        mujoco.mj_fullM(robot.model, data, full)
        G = robot.gear_ratio
        inertia = (full[robot.arm_dof, robot.arm_dof] + G**2 * robot.motor_inertia) / G**2
        w = 2 * np.pi * BANDWIDTH_HZ
        kp = inertia * w**2
        ki = kp * w * INTEGRAL_FRACTION
        return cls(
            kp=kp,
            kd=2 * DAMPING_RATIO * w * inertia,
            ki=ki,
            integral_limit=INTEGRAL_TORQUE_SHARE * robot.motor_torque_limit / ki,
        )


def add_drives(spec: mujoco.MjSpec, robot: Robot, gains: ServoGains) -> None:
    """Turn the robot's ``motor{i}`` torque actuators into PID servo drives, in place.

    Each becomes a ``dcmotor`` with inputs ``pos vel ff`` (three ``ctrl`` slots, in
    :data:`INPUTS` order), unit torque and back-EMF constants and unit resistance (its driver
    compensates back-EMF, so commanded torque is delivered), and saturation at the robot's
    motor torque limit.
    """
    for k, name in enumerate(robot.actuator_names):
        actuator = spec.actuator(name)
        actuator.set_to_dcmotor(
            motorconst=[1.0, 1.0],
            resistance=1.0,
            saturation=[float(robot.motor_torque_limit[k]), 0.0, 0.0],
            controller=[float(gains.kp[k]), float(gains.ki[k]), float(gains.kd[k]), 0.0,
                        float(gains.integral_limit[k]), 0.0],
            ctrlspec=7,  # pos | vel | ff
        )
        actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE


def setpoints(robot: Robot, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, dt: float | None = None,
              end_gain: np.ndarray | None = None) -> np.ndarray:
    """Drive inputs along an arm-side reference path, with nominal-model feedforward.

    Parameters
    ----------
    robot : Robot
        The nominal robot (its friction parameters are the unworn ones).
    q, qd, qdd : ndarray of shape (n, N)
        Reference arm angles (rad), velocities (rad/s) and accelerations (rad/s^2).
    dt : float, optional
        The physics step in s, when row ``k`` is the input of the step from ``t_k`` to
        ``t_k + dt``. MuJoCo's step moves a joint by ``h v+`` (``q+ = q + h v+``), so the velocity it
        carries is the mean over the step: the speed set-point is then the reference's mean speed
        over the step, ``G (q[k+1] - q[k]) / dt``, and the feedforward its mean,
        ``(tau_ff[k] + tau_ff[k+1]) / 2`` (the last row keeps its own). Set-points taken at the
        step's start instead make the drive lag the reference by ``kd h qdd / (2 kp)``, a
        first-order step error (docs/simulation.md, "Numerical convergence").
    end_gain : ndarray of shape (N,), optional
        With ``dt``, when the step evaluates the drives at its end position (MuJoCo's ``discrete``
        integrator): their position gains kp in N m/rad. The step then sees the position error at
        ``t_k + dt`` while the drive's integrator sees the one at ``t_k`` (explicit Euler), so the
        position set-point stays ``G q[k]`` and the feedforward carries the reference's advance
        over the step, ``kp G (q[k+1] - q[k])``; without it the drive lags one step behind.

    Returns
    -------
    ndarray of shape (n, N, 3)
        Per axis: motor-angle set-point G q (rad), motor-speed set-point G qd (rad/s) and
        torque feedforward tau_ff / G (N m, motor side), where tau_ff is
        :meth:`Robot.inverse_dynamics` with nominal friction.

    Raises
    ------
    ValueError
        If ``dt`` is given and not a positive number.
    """
    G = robot.gear_ratio
    q = np.asarray(q, dtype=float)
    feedforward = robot.inverse_dynamics(q, qd, qdd, friction=True) / G
    inputs = np.stack([G * q, G * np.asarray(qd, dtype=float), feedforward], axis=-1)
    if dt is not None:
        if not dt > 0:
            raise ValueError(f"dt = {dt!r}; expected the physics step, a positive number of seconds")
        inputs[:-1, :, 1] = G * np.diff(q, axis=0) / dt
        inputs[:-1, :, 2] = (feedforward[:-1] + feedforward[1:]) / 2
        if end_gain is not None:
            inputs[:-1, :, 2] += end_gain * G * np.diff(q, axis=0)
    return inputs
