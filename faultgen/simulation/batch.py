"""Cycles stepped together as the simulations of one ``mujoco.batch.Batch``: their start state,
how each cycle's robot differs from the nominal model (:class:`Plant`), what a stepper is handed
(:class:`Work`) and returns (:class:`Raw`), and the divergence check."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mujoco import batch as mjbatch

from faultgen.model import robots
from faultgen.operation.conditions import CycleConditions

#: Logging periods handed to MuJoCo per ``Batch.rollout`` call (1 s of simulated time): long
#: enough that the hand-over costs little, short enough that the per-step records stay small.
CHUNK_PERIODS = 250


class SimulationDiverged(RuntimeError):
    """A cycle's state became non-finite or MuJoCo warned; the message names cycle and axis."""

    #: The command line's exit code for it (faultgen.cli.base.Command).
    exit_code = 1


def start_state(robot: robots.Robot, q0: np.ndarray, qd0: np.ndarray | None = None,
                qdd0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``qpos`` and ``qvel`` at arm angles ``q0`` (rad), at rest or, for a replayed log that starts
    moving, at velocity ``qd0`` (rad/s) and acceleration ``qdd0`` (rad/s^2), with drives on their
    set-points.

    The motors sit at ``G q0`` (turning at ``G qd0``) and each gearbox carries its load, the
    static one at rest, the arm-side torque of the motion (rigid-body inverse dynamics without the
    motor's inertia and friction) when moving: the arm lags by ``tau / K`` (thesis eq. 6.2a), and
    with backlash ``b`` it rests on the loaded flank, ``b / 2`` further, so a cycle starts in
    equilibrium. An axis without load (a vertical base axis at rest) starts in the middle of its
    dead band.
    """
    zeros = np.zeros(robot.n_axes)
    qd0 = zeros if qd0 is None else np.asarray(qd0, dtype=float)
    qdd0 = zeros if qdd0 is None else np.asarray(qdd0, dtype=float)
    qpos, qvel = robot.rigid_state(q0, qd0)
    static = robot.inverse_dynamics(q0[None], qd0[None], qdd0[None], friction=False)[0]
    static = static - robot.gear_ratio ** 2 * robot.motor_inertia * qdd0  # the rotor's share is not the gearbox's
    # a load at round-off level (gravity on a vertical axis) has no side to rest on
    side = np.sign(static) * (np.abs(static) > 1e-9 * max(float(np.abs(static).max()), 1.0))
    qpos[robot.arm_qpos] = q0 - static / robot.gearbox_stiffness
    offset = robot.arm_offset(side[None])
    if offset is not None:
        qpos[robot.arm_qpos] += offset[0]
    return qpos, qvel


@dataclass(frozen=True)
class Plant:
    """How each simulated cycle's robot differs from the nominal model: multipliers of the dry
    (Coulomb and static: wear, temperature, unit) and the viscous friction (n, N), of each link's
    mass and inertia (N,), a growing fault's parameter (n,) (None without one), and the unit's
    gearbox loss growing with the load (N,), a load-dependent friction coefficient (zeros: none)."""

    dry: np.ndarray
    viscous: np.ndarray
    link_mass: np.ndarray
    fault: np.ndarray | None = None
    gear_loss: np.ndarray | None = None  # set by of(); zeros of the robot's axes without a spread

    @classmethod
    def of(cls, wear: np.ndarray, conditions: CycleConditions | None, fault: np.ndarray | None = None) -> Plant:
        if conditions is None:
            return cls(wear, np.ones_like(wear), np.ones(wear.shape[1]), fault, np.zeros(wear.shape[1]))
        return cls(wear * conditions.dry_friction_factor, conditions.viscous_factor, conditions.link_mass_factor,
                   fault, conditions.gear_loss)

    def take(self, rows) -> Plant:
        return Plant(self.dry[rows], self.viscous[rows], self.link_mass,
                      None if self.fault is None else self.fault[rows], self.gear_loss)

    def set_fault(self, batch, fault_fields: tuple, final: float) -> None:
        """Each simulation's fault parameter (:attr:`fault`, per cycle) into the fields it moves."""
        for name, index, at_final, slope in fault_fields:
            values = batch.expand(name)
            flat = values.reshape(values.shape[0], -1)
            flat[:, index] = at_final + (self.fault[:, None] - final) * slope
            values[...] = flat.reshape(values.shape)

    def apply(self, sim, batch) -> None:
        """The viscous and link-mass changes as per-simulation model fields of ``batch`` (the dry
        friction is set by each stepper); nothing is expanded where nothing changes."""
        robot, model = sim.robot, sim.model
        if np.any(self.viscous != 1):
            sim.stepping.scale_viscous(sim, batch, self.viscous)
        if np.any(self.link_mass != 1):
            links = model.jnt_bodyid[[model.joint(n).id for n in robot.joint_names]]
            batch.expand("body_mass")[:, links] *= self.link_mass
            batch.expand("body_inertia")[:, links] *= self.link_mass[:, None]


@dataclass(frozen=True)
class Work:
    """One batch of simulations stepped together: recorded ``cycles`` (n,), their ``plant`` (wear
    and conditions), the start angles ``q0`` (N,), the drive ``inputs`` at every physics step
    (n_steps + 1, N, 3), the load disturbance ``dist`` per log period (n, n_log, N), physics steps
    per log period, MuJoCo threads, for a fault the fields it moves and its final value, and for a
    program that grips a part the steps where its mass changes (:func:`apply_grips`)."""

    cycles: np.ndarray
    plant: Plant
    q0: np.ndarray
    inputs: np.ndarray
    dist: np.ndarray
    per_log: int
    nthread: int
    fault: tuple | None = None
    grips: tuple = ()
    qd0: np.ndarray | None = None
    qdd0: np.ndarray | None = None


@dataclass
class Raw:
    """True signals at the log times, each ``(n_cycles, n_log, N)``."""

    q_a: np.ndarray
    q_m: np.ndarray
    qd_a: np.ndarray
    qd_m: np.ndarray
    tau_m: np.ndarray
    tau_f: np.ndarray


def new_batch(sim, work: Work) -> mjbatch.Batch:
    """One simulation per recorded cycle, all at the task's start state."""
    batch = mjbatch.Batch(sim.model, nsim=len(work.cycles), nthread=work.nthread)
    batch.qpos, batch.qvel = start_state(sim.robot, work.q0, work.qd0, work.qdd0)
    batch.act = 0.0
    work.plant.apply(sim, batch)
    if work.fault is not None:
        work.plant.set_fault(batch, *work.fault)
    return batch


def apply_grips(batch, grips: tuple, step: int) -> None:
    """Set the gripped body's mass and inertia at physics ``step`` where a program grips or releases
    (``grips``: ``(step, (body, mass, inertia, ipos, iquat))`` pairs); the same for every simulation."""
    for at, (body, mass, inertia, ipos, iquat) in grips:
        if at == step:
            batch.expand("body_mass")[:, body] = mass
            batch.expand("body_inertia")[:, body] = inertia
            batch.expand("body_ipos")[:, body] = ipos
            batch.expand("body_iquat")[:, body] = iquat
            # the constants MuJoCo derives from the masses (constraint weights, subtree masses) follow,
            # so an empty gripper is the same model whatever part the program grips
            batch.set_const()


def check_diverged(sim, batch, cycles: np.ndarray, velocities: np.ndarray, step: int) -> None:
    """Raise SimulationDiverged naming the first bad cycle and axis."""
    warned = np.asarray(batch.warning)
    bad = np.flatnonzero(~np.all(np.isfinite(velocities.reshape(len(cycles), -1)), axis=1)
                         | (warned.reshape(len(cycles), -1).sum(axis=1) > 0))
    if bad.size:
        i = int(bad[0])
        v = velocities[i].reshape(-1, velocities.shape[-1])
        finite = np.where(np.isfinite(v), np.abs(v), np.inf)
        axis = int(np.argmax(finite.max(axis=0)) % sim.robot.n_axes) + 1
        raise SimulationDiverged(
            f"cycle {int(cycles[i])} diverged near t = {step * sim.model.opt.timestep:.3f} s on axis {axis}"
            f" ({sim.robot.name}, {sim.friction_model} friction): the state became non-finite or MuJoCo "
            "warned; check the friction parameters and wear level of that axis"
        )
