"""A robot compiled for simulation: PID drives (:mod:`faultgen.simulation.control`), one
friction model (:mod:`faultgen.simulation.friction_models`) and the MuJoCo elements of its effects;
and the drive torques as MuJoCo's implicit step applied them."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np

from faultgen.model import robots
from faultgen.simulation import control, friction_models


@dataclass(frozen=True)
class SimModel:
    """A robot compiled for simulation: PID drives plus one friction model.

    Attributes
    ----------
    robot : Robot
        The nominal robot the model was built from.
    friction_model : str
    gains : ServoGains
    model : mujoco.MjModel
    drive_ctrl : ndarray of shape (N, 3)
        ``ctrl`` indices of each drive's (pos, vel, ff) inputs.
    drive_ids : ndarray of shape (N,)
        Actuator ids of the drives ``motor{i}``.
    lugre_ids : ndarray of shape (N,)
        Actuator ids of the friction actuators ``lugre{i}`` (empty for ``stribeck``).
    """

    robot: robots.Robot
    friction_model: str
    gains: control.ServoGains
    model: mujoco.MjModel
    drive_ctrl: np.ndarray
    drive_ids: np.ndarray
    lugre_ids: np.ndarray

    @property
    def stepping(self) -> friction_models.FrictionModel:
        """The friction model as a strategy (:mod:`faultgen.simulation.friction_models`)."""
        return friction_models.MODELS[self.friction_model]

    @property
    def implicit_position(self) -> bool:
        """Whether the step is implicit in position too (MuJoCo's ``discrete`` integrator)."""
        return self.model.opt.integrator == mujoco.mjtIntegrator.mjINT_DISCRETE

    def setpoints(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """:func:`faultgen.simulation.control.setpoints` of a path sampled at this model's physics
        step, for its integrator (the drives' position gains when it is implicit in position),
        ``(n, N, 3)``."""
        return control.setpoints(self.robot, q, qd, qdd, self.model.opt.timestep,
                                 self.gains.kp if self.implicit_position else None)

    def applied_force(self, force: np.ndarray, v_m: np.ndarray, v_m_before: np.ndarray) -> np.ndarray:
        """:func:`applied_drive_torque` for this model's drives, on ``actuator_force`` rows.

        Parameters
        ----------
        force : ndarray of shape (..., n_actuators)
            ``actuator_force`` of a step, N m at the motor side.
        v_m, v_m_before : ndarray of shape (..., N)
            Rotor speeds after and before that step, rad/s.

        Returns
        -------
        ndarray of shape (..., n_actuators)
            ``force`` with the drives' rows as the step applied them (the passive actuators, LuGre
            with sigma_1 = 0, cogging and offsets, have no speed or position derivative).
        """
        applied = np.array(force, dtype=float)
        applied[..., self.drive_ids] = applied_drive_torque(
            applied[..., self.drive_ids], v_m, v_m_before, self.gains.kp, self.gains.kd,
            self.robot.motor_torque_limit, self.model.opt.timestep, self.implicit_position)
        return applied


def applied_drive_torque(force: np.ndarray, v: np.ndarray, v_before: np.ndarray, kp: np.ndarray,
                         kd: np.ndarray, limit: np.ndarray, timestep: float, implicit_position: bool) -> np.ndarray:
    """PID drive torques as MuJoCo's implicit step applied them, from those it reports.

    ``mjData.actuator_force`` is a drive's torque at the start of a step, but an implicit step
    applies it linearised at the end: ``f - kd (v+ - v)`` under ``implicitfast`` (its speed
    derivative) and, under ``discrete``, also ``- kp (q+ - q) = - kp h v+`` (its position derivative;
    MuJoCo's integrator documentation). A drive clamped at its torque limit has no derivative.
    Recording the start-of-step value would add ``kd h qdd_m`` (and ``kp h qd_m``) to every logged
    motor torque, a first-order step error (docs/simulation.md, "Numerical convergence"); tested
    against Newton's law on a driven rotor (tests/test_convergence.py).

    Parameters
    ----------
    force : ndarray of shape (..., n)
        Reported drive torques of a step, N m.
    v, v_before : ndarray of shape (..., n)
        Joint speeds after and before that step, rad/s.
    kp, kd : ndarray of shape (n,)
        Position gain, N m/rad, and speed gain, N m s/rad.
    limit : ndarray of shape (n,)
        Torque limit, N m.
    timestep : float
        Physics step h, s.
    implicit_position : bool
        Whether the step is implicit in position too (``discrete``).

    Returns
    -------
    ndarray of shape (..., n)
    """
    change = kd * (v - v_before)
    if implicit_position:
        change = change + kp * timestep * v
    return np.where(np.abs(force) < limit, force - change, force)


def build(robot: robots.Robot, friction_model: str = "lugre",
          edit: Callable[[mujoco.MjSpec], None] | None = None) -> SimModel:
    """Compile ``robot`` with PID drives (:mod:`faultgen.simulation.control`) and a friction model,
    derived in memory from a copy of the robot's spec (:meth:`Robot.new_spec`: the file is not read
    again); ``edit(spec)``, when given, is applied to that copy first (a growing fault's effect).

    Raises
    ------
    ValueError
        For an unknown friction model, or friction parameters the model cannot represent.
    """
    stepping = friction_models.get(friction_model)
    spec = robot.new_spec()
    if edit is not None:
        edit(spec)
    gains = control.ServoGains.for_robot(robot)
    control.add_drives(spec, robot, gains)
    stepping.add(spec, robot, gains)
    _add_effect_forces(spec, robot)
    model = spec.compile()
    drive_ids = np.array([model.actuator(n).id for n in robot.actuator_names])
    drive_ctrl = model.actuator_ctrladr[drive_ids][:, None] + np.arange(len(control.INPUTS))
    return SimModel(robot, friction_model, gains, model, drive_ctrl, drive_ids, stepping.actuator_ids(model, robot))


def _add_effect_forces(spec, robot: robots.Robot) -> None:
    """The MuJoCo elements of the robot's effects (:meth:`faultgen.effects.Effect.add_to_simulation`:
    cogging, a torque offset), in place."""
    for effect in robot.effects.values():
        if np.any(effect.active()):
            effect.add_to_simulation(spec, robot)
