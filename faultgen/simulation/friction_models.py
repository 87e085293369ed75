"""The friction models of a simulation as strategies: how each puts the robot's motor-side
friction into the MuJoCo model and steps a batch of cycles with it (:data:`MODELS`, by the name
``RunConfig.friction`` and the dataset's ``friction_model`` label give).

``lugre``: everything that runs at the physics rate (the PID drives, LuGre friction, the
gearboxes) runs inside MuJoCo, and Python only hands over pre-computed set-points and disturbance
torques a chunk at a time (``Batch.rollout``). ``stribeck``: the static model needs its friction
level set before every physics step from the rotor speed, so it steps from Python and is slower
(docs/performance.md gives both figures).
"""

from __future__ import annotations

from dataclasses import fields

import mujoco
import numpy as np

from faultgen.effects import friction
from faultgen.effects.base import Effect
from faultgen.effects.load_dependent_friction import LoadDependentFriction
from faultgen.model import robots
from faultgen.simulation.batch import CHUNK_PERIODS, Raw, Work, check_diverged, new_batch


def stepped_effects(robot: robots.Robot) -> list:
    """The robot's effects that act through a per-step update of the rotors' dry friction."""
    return [e for e in robot.effects.values() if e.stepped and np.any(e.active())]


class FrictionModel:
    """A friction model of the simulation. Subclasses say how it enters the MJCF, which actuators
    carry it, how a cycle's viscous friction is scaled and how a batch of cycles is stepped."""

    #: The model's name (:data:`faultgen.effects.friction.MODELS`).
    name: str
    #: Whether Python sets the friction level before every physics step (what friction growing
    #: with the load, the unit's gear loss, needs).
    per_step: bool

    def add(self, spec: mujoco.MjSpec, robot: robots.Robot, gains) -> None:
        """Put the robot's motor-side friction into ``spec`` (after the drives, ``gains``)."""
        raise NotImplementedError

    def actuator_ids(self, model: mujoco.MjModel, robot: robots.Robot) -> np.ndarray:
        """Ids of the actuators that carry the friction, one per axis (empty: none)."""
        return np.array([], dtype=int)

    def scale_viscous(self, sim, batch, factor: np.ndarray) -> None:
        """Multiply each simulation's viscous friction by ``factor`` (n_sim, N)."""
        raise NotImplementedError

    def step(self, sim, work: Work, bar) -> Raw:
        """Step the cycles of ``work`` on ``sim``; the true signals at the log times."""
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class LuGre(FrictionModel):
    """LuGre friction in MuJoCo's ``dcmotor`` actuators ``lugre{i}`` (bristle state as activation)."""

    name = "lugre"
    per_step = False

    def add(self, spec, robot, gains):
        stepped = stepped_effects(robot)
        if stepped:
            raise ValueError(
                f"{robot.path}: {' and '.join(e.summary for e in stepped)} ({', '.join(e.id for e in stepped)}) "
                "act through the friction level Python sets every step; simulate this model with --friction stribeck"
            )
        friction.check_lugre_step(robot.friction, spec.option.timestep, gains.kd)
        friction.add_lugre(spec, robot)

    def actuator_ids(self, model, robot):
        return np.array([model.actuator(f"lugre{k + 1}").id for k in range(robot.n_axes)], dtype=int)

    def scale_viscous(self, sim, batch, factor):
        batch.expand("actuator_damping")[:, sim.lugre_ids] *= factor

    def step(self, sim, work, bar):
        """All physics in MuJoCo: set-points and disturbances handed over one chunk at a time."""
        robot, model = sim.robot, sim.model
        cycles, dry, inputs, dist, per_log = work.cycles, work.plant.dry, work.inputs, work.dist, work.per_log
        viscous = robot.friction.viscous * work.plant.viscous[:, None, :]
        batch = new_batch(sim, work)
        bias = batch.expand("actuator_biasprm")
        bias[:, sim.lugre_ids, 3] *= dry  # Coulomb level F_c
        bias[:, sim.lugre_ids, 4] *= dry  # breakaway level F_s
        n_sim, n_steps = len(cycles), len(inputs) - 1
        spec = mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_QFRC_APPLIED
        chunk = min(CHUNK_PERIODS * per_log, n_steps)
        # buffers reused by every chunk: rollout inputs and per-substep records
        control_in = np.zeros((n_sim, chunk, model.nu + model.nv))
        records = {name: np.empty((n_sim, chunk, size)) for name, size in
                   (("qpos", model.nq), ("qvel", model.nv), ("actuator_force", model.actuator_trnid.shape[0]))}
        logs = {f.name: np.empty((n_sim, n_steps // per_log, robot.n_axes)) for f in fields(Raw)}
        arm_dist = model.nu + robot.arm_dof
        last_qvel = batch.qvel.copy()
        for start in range(0, n_steps, chunk):
            stop = min(start + chunk, n_steps)
            size = stop - start
            control_in[:, :size, : model.nu][:, :, sim.drive_ctrl] = inputs[start:stop]
            control_in[:, :size, arm_dist] = np.repeat(dist[:, start // per_log : stop // per_log], per_log, axis=1)
            out = records if size == chunk else {k: np.empty((n_sim, size, v.shape[2])) for k, v in records.items()}
            batch.rollout(size, control=control_in[:, :size], control_spec=spec, record=tuple(out), out=out)
            check_diverged(sim, batch, cycles, out["qvel"], start)
            logged = slice(start // per_log, stop // per_log)
            qpos, qvel, force = (out[k][:, per_log - 1 :: per_log] for k in ("qpos", "qvel", "actuator_force"))
            v_m = qvel[:, :, robot.rotor_dof]
            # rotor speeds one step before each logged one (the last of the previous chunk for a 4 ms step)
            before = out["qvel"][:, per_log - 2 :: per_log] if per_log > 1 else np.concatenate(
                [last_qvel[:, None], out["qvel"][:, :-1]], axis=1)
            last_qvel = out["qvel"][:, -1].copy()
            applied = sim.applied_force(force, v_m, before[:, :, robot.rotor_dof])
            logs["q_a"][:, logged] = qpos[:, :, robot.arm_qpos]
            logs["q_m"][:, logged] = qpos[:, :, robot.rotor_qpos]
            logs["qd_a"][:, logged] = qvel[:, :, robot.arm_dof]
            logs["qd_m"][:, logged] = v_m
            logs["tau_m"][:, logged] = applied[:, :, sim.drive_ids]
            # friction opposes motion: minus the LuGre actuator's force, plus the viscous term
            logs["tau_f"][:, logged] = -force[:, :, sim.lugre_ids] + viscous * v_m
            bar.update(n_sim * size * model.opt.timestep)
        return Raw(**logs)


class Stribeck(FrictionModel):
    """Static friction (thesis eq. 6.3) as the rotors' friction loss, set from Python every step."""

    name = "stribeck"
    per_step = True

    def add(self, spec, robot, gains):
        friction.add_stribeck(spec, robot)

    def scale_viscous(self, sim, batch, factor):
        batch.expand("dof_damping")[:, sim.robot.rotor_dof] *= factor

    def step(self, sim, work, bar):
        """Static friction: the friction-loss level follows the rotor speed before every step."""
        robot, model = sim.robot, sim.model
        cycles, dry, inputs, dist, per_log = work.cycles, work.plant.dry, work.inputs, work.dist, work.per_log
        viscous = robot.friction.viscous * work.plant.viscous
        batch = new_batch(sim, work)
        frictionloss = batch.expand("dof_frictionloss")
        qvel, qpos = batch.bind("qvel"), batch.bind("qpos")
        ctrl, applied = batch.bind("ctrl"), batch.bind("qfrc_applied")
        force, constraint = batch.bind("actuator_force"), batch.bind("qfrc_constraint")
        n_steps = len(inputs) - 1
        n_log = n_steps // per_log
        logs = {f.name: np.empty((len(cycles), n_log, robot.n_axes)) for f in fields(Raw)}
        rotor, arm = robot.rotor_dof, robot.arm_dof
        G = robot.gear_ratio
        dt = model.opt.timestep
        run_start = (cycles[:, None] - 1) * n_steps * dt  # a drift with time runs over the whole run
        # the stepped effects that scale the dry friction and those that add to it, sorted once
        factors = [e for e in stepped_effects(robot) if type(e).dry_friction_factor is not Effect.dry_friction_factor]
        extras = [e for e in stepped_effects(robot) if type(e).dry_friction_extra is not Effect.dry_friction_extra]
        if np.any(work.plant.gear_loss):  # the unit's gearbox loss: the same effect, on top of the model's
            extras.append(LoadDependentFriction(coefficient=work.plant.gear_loss))
        if extras:  # the static load from the last step's kinematics, for those that ask for it
            kinematics = [batch.bind(name) for name in ("subtree_com", "xanchor", "xaxis")]
            batch.forward()  # the start state's, for the first step

            def static_load() -> np.ndarray:
                return robot.static_load_of(*kinematics, qpos)

        for step in range(n_steps):
            level = dry
            for effect in factors:
                level = level * effect.dry_friction_factor(run_start + step * dt)
            frictionloss[:, rotor] = robot.friction.stribeck_level(qvel[:, rotor], level)
            if extras:  # the gearbox deflection (eq. 6.2a) carries the load
                deflection = qpos[:, robot.rotor_qpos] / G - qpos[:, robot.arm_qpos]
                for effect in extras:
                    frictionloss[:, rotor] += effect.dry_friction_extra(robot, deflection, static_load)
            ctrl[:, sim.drive_ctrl] = inputs[step]
            applied[:, arm] = dist[:, step // per_log]
            logged = (step + 1) % per_log == 0
            if logged:
                v_before = qvel[:, rotor].copy()
            batch.step()
            if logged:
                j = (step + 1) // per_log - 1
                v_m = qvel[:, rotor]
                logs["q_a"][:, j] = qpos[:, robot.arm_qpos]
                logs["q_m"][:, j] = qpos[:, robot.rotor_qpos]
                logs["qd_a"][:, j] = qvel[:, arm]
                logs["qd_m"][:, j] = v_m
                logs["tau_m"][:, j] = sim.applied_force(force, v_m, v_before)[:, sim.drive_ids]
                logs["tau_f"][:, j] = -constraint[:, rotor] + viscous * v_m
                bar.update(len(cycles) * per_log * model.opt.timestep)
                if (j + 1) % CHUNK_PERIODS == 0 or j == n_log - 1:
                    check_diverged(sim, batch, cycles, logs["qd_m"][:, : j + 1], step)
        return Raw(**logs)


#: The friction models by name.
MODELS = {model.name: model for model in (LuGre(), Stribeck())}


def get(name: str) -> FrictionModel:
    """The friction model ``name``; raises ValueError naming it and the known ones
    (:func:`faultgen.effects.friction.check_model`)."""
    friction.check_model(name)
    return MODELS[name]
