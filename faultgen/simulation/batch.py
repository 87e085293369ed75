"""Cycles stepped together as the simulations (runs) of one batch: their start state, how each
cycle's robot differs from the nominal model (:class:`Plant`), what the stepping is handed
(:class:`Work`) and returns (:class:`Raw`), the stepping loop (:func:`step`: a stepping backend,
:mod:`faultgen.simulation.backends`, steps the runs; the friction model,
:mod:`faultgen.simulation.friction_models`, says how friction enters them) and the divergence check."""

from __future__ import annotations

from dataclasses import dataclass, make_dataclass, replace

import mujoco
import numpy as np

from faultgen.model import robots
from faultgen.operation.conditions import CycleConditions
from faultgen.simulation import backends, friction_update
from faultgen.simulation.signals import TRUE_SIGNALS

#: Logging periods handed to MuJoCo per ``rollout`` call of the backend (1 s of simulated time): long
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
    gearbox loss growing with the load, a load-dependent friction coefficient (zeros: none), (N,)
    or per cycle (n, N) with a growing load-dependent friction fault (:meth:`with_fault_in_gear_loss`)."""

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
                      None if self.fault is None else self.fault[rows],
                      self.gear_loss[rows] if np.ndim(self.gear_loss) == 2 else self.gear_loss)

    def with_fault_in_gear_loss(self, axis: int) -> Plant:
        """This plant with each cycle's fault value (:attr:`fault`, a load-dependent friction
        coefficient) added to the gear loss of ``axis`` (0-based): gear loss (n, N)."""
        loss = np.tile(self.gear_loss, (len(self.fault), 1))
        loss[:, axis] += self.fault
        return replace(self, gear_loss=loss)

    def set_fault(self, runs, fault_fields: tuple, final: float) -> None:
        """Each simulation's fault parameter (:attr:`fault`, per cycle) into the fields it moves."""
        for name, index, at_final, slope in fault_fields:
            values = runs.expand(name)
            flat = values.reshape(values.shape[0], -1)
            flat[:, index] = at_final + (self.fault[:, None] - final) * slope
            values[...] = flat.reshape(values.shape)

    def apply(self, sim, runs) -> None:
        """The viscous and link-mass changes as per-simulation model fields of ``runs`` (the dry
        friction is set by the friction model); nothing is expanded where nothing changes."""
        robot, model = sim.robot, sim.model
        if np.any(self.viscous != 1):
            sim.stepping.scale_viscous(sim, runs, self.viscous)
        if np.any(self.link_mass != 1):
            links = model.jnt_bodyid[[model.joint(n).id for n in robot.joint_names]]
            runs.expand("body_mass")[:, links] *= self.link_mass
            runs.expand("body_inertia")[:, links] *= self.link_mass[:, None]


@dataclass(frozen=True)
class Work:
    """One batch of simulations stepped together: recorded ``cycles`` (n,), their ``plant`` (wear
    and conditions), the start angles ``q0`` (N,), the drive ``inputs`` at every physics step
    (n_steps + 1, N, 3), the load disturbance ``dist`` per log period (n, n_log, N), physics steps
    per log period, MuJoCo threads, for a fault the fields it moves and its final value, and for a
    program that grips a part the steps where its mass changes (:func:`apply_grips`), and the
    stepper (:class:`faultgen.simulation.backends.Stepper`)."""

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
    stepper: backends.Stepper = backends.DEFAULT_STEPPER


#: True signals at the log times (:data:`faultgen.simulation.signals.TRUE_SIGNALS`), each
#: ``(n_cycles, n_log, N)``.
Raw = make_dataclass("Raw", [(name, np.ndarray) for name in TRUE_SIGNALS])
Raw.__doc__ = "True signals at the log times, each ``(n_cycles, n_log, N)``: " + ", ".join(TRUE_SIGNALS) + "."


#: Runs per thread below which a batch stepped one step at a time from Python (:func:`_step_each`)
#: on all CPUs (``nthread`` 0, the default) takes fewer threads: handing a few runs' single step to a thread pool
#: costs more than the step. On the shared 2-core machine (2026-11-27, loaded) the static friction
#: model's 4 / 16 / 48 PUMA 560 runs on 2 threads took 2.7 / 1.6 / 1.2 times the CPU time of one
#: thread, and longer wall time. MuJoCo's batch gives the same bits at any thread count.
STEP_RUNS_PER_THREAD = 16


def step_threads(nthread: int, n_sim: int) -> int:
    """Threads for ``n_sim`` runs stepped one step at a time, for a run's ``nthread``: for 0 (all
    CPUs) one per :data:`STEP_RUNS_PER_THREAD` runs, at least one; a number the user chose is kept."""
    return max(1, n_sim // STEP_RUNS_PER_THREAD) if nthread == 0 else nthread


def new_runs(sim, work: Work, nthread: int | None = None) -> backends.Runs:
    """One simulation per recorded cycle on the stepper of ``work`` (on ``nthread`` threads; the
    run's ``nthread`` by default), all at the task's start state, with each cycle's plant, fault
    and dry friction."""
    runs = work.stepper.new(sim.model, len(work.cycles), work.nthread if nthread is None else nthread)
    runs.bind("qpos")[...], runs.bind("qvel")[...] = start_state(sim.robot, work.q0, work.qd0, work.qdd0)
    runs.bind("act")[...] = 0.0
    work.plant.apply(sim, runs)
    if work.fault is not None:
        work.plant.set_fault(runs, *work.fault)
    sim.stepping.scale_dry(sim, runs, work.plant.dry)
    return runs


#: Inputs a step takes from Python: the drives' set-points (ctrl) and the load disturbance (qfrc_applied).
CONTROL_SPEC = mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_QFRC_APPLIED


def step(sim, work: Work, bar) -> Raw:
    """Step the cycles of ``work`` on ``sim`` and return the true signals at the log times.

    The set-points and disturbances are handed over a chunk (:data:`CHUNK_PERIODS` log periods)
    at a time to the backend's ``rollout``, and chunks also break where a program grips or releases
    a payload. A friction model whose level is set before every step (``per_step``) hands its update
    for the chunk (:class:`faultgen.simulation.friction_update.FrictionUpdate`) to ``rollout`` too
    when the backend applies it (``applies_friction_update``); otherwise (and for a plug-in effect
    whose extra friction is not in the update's arrays) each chunk is stepped one step at a time with
    the update applied from Python before each. ``bar`` (tqdm) advances by the simulated seconds.
    """
    robot, model, friction = sim.robot, sim.model, sim.stepping
    cycles, inputs, dist, per_log = work.cycles, work.inputs, work.dist, work.per_log
    viscous = robot.friction.viscous * work.plant.viscous[:, None, :]
    schedule = friction.schedule(sim, work)
    applies = work.stepper.applies_friction_update
    in_rollout = schedule is None or (schedule.in_arrays and applies)
    n_sim, n_steps = len(cycles), len(inputs) - 1
    runs = new_runs(sim, work, work.nthread if in_rollout else step_threads(work.nthread, n_sim))
    if schedule is not None and schedule.reads_start_state:
        for name in friction_update.KINEMATICS:  # bound before the call that fills them
            runs.bind(name)
        runs.forward()  # the start state's kinematics, for the first step's load-dependent friction
    chunk = min(CHUNK_PERIODS * per_log, n_steps)
    # buffers reused by every chunk: rollout inputs and per-substep records
    control_in = np.zeros((n_sim, chunk, model.nu + model.nv))
    sizes = {"qpos": model.nq, "qvel": model.nv, "actuator_force": model.actuator_trnid.shape[0], "qfrc_constraint": model.nv}
    records = {name: np.empty((n_sim, chunk, sizes[name])) for name in
               dict.fromkeys(("qpos", "qvel", "actuator_force", friction.force_field))}
    logs = {name: np.empty((n_sim, n_steps // per_log, robot.n_axes)) for name in TRUE_SIGNALS}
    arm_dist = model.nu + robot.arm_dof
    last_qvel = runs.bind("qvel").copy()
    starts = sorted({*range(0, n_steps, chunk), *(at for at, _ in work.grips if 0 < at < n_steps)})
    for start, stop in zip(starts, [*starts[1:], n_steps]):
        size = stop - start
        out = records if size == chunk else {k: np.empty((n_sim, size, v.shape[2])) for k, v in records.items()}
        update = None if schedule is None else schedule.chunk(start, stop)
        if in_rollout:
            apply_grips(runs, work.grips, start)
            control_in[:, :size, : model.nu][:, :, sim.drive_ctrl] = inputs[start:stop]
            control_in[:, :size, arm_dist] = np.repeat(dist[:, start // per_log : stop // per_log], per_log, axis=1)
            runs.rollout(size, control=control_in[:, :size], control_spec=CONTROL_SPEC, record=tuple(out), out=out,
                         **({} if update is None else {"update": update}))
        else:
            _step_each(sim, work, runs, schedule.setter(runs, update), start, stop, out)
        check_diverged(sim, runs, cycles, out["qvel"], start)
        logged = slice(start // per_log, stop // per_log)
        qpos, qvel, force = (out[k][:, per_log - 1 :: per_log] for k in ("qpos", "qvel", "actuator_force"))
        v_m = qvel[:, :, robot.rotor_dof]
        # rotor speeds one step before each logged one (the last of the previous chunk for a 4 ms step)
        before = out["qvel"][:, per_log - 2 :: per_log] if per_log > 1 else np.concatenate(
            [last_qvel[:, None], out["qvel"][:, :-1]], axis=1)
        last_qvel = out["qvel"][:, -1].copy()
        logs["q_a"][:, logged] = qpos[:, :, robot.arm_qpos]
        logs["q_m"][:, logged] = qpos[:, :, robot.rotor_qpos]
        logs["qd_a"][:, logged] = qvel[:, :, robot.arm_dof]
        logs["qd_m"][:, logged] = v_m
        logs["tau_m"][:, logged] = sim.applied_force(force, v_m, before[:, :, robot.rotor_dof])[:, :, sim.drive_ids]
        logs["tau_f"][:, logged] = friction.friction_torque(sim, out[friction.force_field][:, per_log - 1 :: per_log],
                                                            v_m, viscous)
        bar.update(n_sim * size * model.opt.timestep)
    return Raw(**logs)


def _step_each(sim, work: Work, runs, write, start: int, stop: int, out: dict) -> None:
    """Steps ``start`` to ``stop`` one at a time, recorded into ``out``. Before each MuJoCo step
    one compiled call (:func:`faultgen.simulation.friction_kernel.before_step`) records the last
    step's ``qvel`` (the divergence check and the applied torque read it after every step), writes
    the friction loss (the compiled update of ``write``, a :class:`friction_update.Writer`, ``k``
    from 0 at ``start``), the set-points and, where a log period starts, the disturbance (constant
    over the period; MuJoCo keeps ``qfrc_applied`` from step to step); then Python adds what
    ``write`` leaves to it (``write.rest``; ``write(k)`` itself where it is a plain function) and a
    grip. The other fields are recorded after the last step of each log period, the rows
    :func:`step` reads (the others keep what the buffers held)."""
    from faultgen.simulation import friction_kernel
    robot, per_log, inputs, dist = sim.robot, work.per_log, work.inputs, work.dist
    drive_ctrl, arm_dof = np.asarray(sim.drive_ctrl, np.int64), np.asarray(robot.arm_dof, np.int64)
    _check_inputs(inputs, dist, drive_ctrl, (len(work.cycles), (stop - 1) // per_log + 1, len(arm_dof)), stop)
    grip_steps = {at for at, _ in work.grips}
    velocity, qvel = out["qvel"], runs.bind("qvel")
    logged = [(out[name], runs.bind(name)) for name in out if name != "qvel"]
    # a plain set_level(k) (a friction model's own schedule) runs from Python, after the compiled call
    ours = isinstance(write, friction_update.Writer)
    update, rest = (write.arrays, write.rest) if ours else (friction_kernel.NO_UPDATE, write)
    args = (per_log, ours and write.compiled, runs.bind("ctrl"), drive_ctrl, inputs, runs.bind("qfrc_applied"),
            arm_dof, dist, qvel, velocity, *update)
    before, step_all = friction_kernel.before_step, runs.step
    for k, at in enumerate(range(start, stop)):
        before(k, at, *args)
        if rest is not None:
            rest(k)
        if at in grip_steps:
            apply_grips(runs, work.grips, at)
        step_all()
        if k % per_log == per_log - 1:
            for record, values in logged:
                record[:, k] = values
    velocity[:, stop - start - 1] = qvel


def _check_inputs(inputs: np.ndarray, dist: np.ndarray, drive_ctrl: np.ndarray, periods: tuple, stop: int) -> None:
    """Refuse set-points ``inputs`` of fewer than ``stop`` steps or not of ``drive_ctrl``'s shape,
    and disturbances ``dist`` of other runs or axes than ``periods`` or fewer periods (the compiled
    call does not check its indices)."""
    if len(inputs) < stop or inputs.shape[1:] != drive_ctrl.shape or dist.shape[0] != periods[0] or \
            dist.shape[1] < periods[1] or dist.shape[2] != periods[2]:
        raise ValueError(f"steps up to {stop} need ({stop}, {', '.join(map(str, drive_ctrl.shape))}) set-points "
                         f"and {periods} disturbances (runs, log periods, axes); got {inputs.shape} and {dist.shape}")


def apply_grips(runs, grips: tuple, step: int) -> None:
    """Set the gripped body's mass and inertia at physics ``step`` where a program grips or releases
    (``grips``: ``(step, (body, mass, inertia, ipos, iquat))`` pairs); the same for every simulation."""
    for at, (body, mass, inertia, ipos, iquat) in grips:
        if at == step:
            runs.expand("body_mass")[:, body] = mass
            runs.expand("body_inertia")[:, body] = inertia
            runs.expand("body_ipos")[:, body] = ipos
            runs.expand("body_iquat")[:, body] = iquat
            # the constants MuJoCo derives from the masses (constraint weights, subtree masses) follow,
            # so an empty gripper is the same model whatever part the program grips
            runs.set_const()


def check_diverged(sim, runs, cycles: np.ndarray, velocities: np.ndarray, step: int) -> None:
    """Raise SimulationDiverged naming the first bad cycle and axis."""
    warned = np.asarray(runs.warning)
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
