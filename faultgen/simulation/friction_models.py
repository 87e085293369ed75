"""The friction models of a simulation as strategies: how each puts the robot's motor-side
friction into the MuJoCo model (:data:`MODELS`, by the name ``RunConfig.friction`` and the dataset's
``friction_model`` label give). They do not step: a stepping backend does
(:mod:`faultgen.simulation.backends`), driven by the loops of :mod:`faultgen.simulation.batch`.

``lugre``: everything that runs at the physics rate (the PID drives, LuGre friction, the
gearboxes) runs inside MuJoCo, and Python only hands over pre-computed set-points and disturbance
torques a chunk at a time (``rollout``). ``stribeck``: the static model's friction level is set
before every physics step from the rotor speed; that update is data
(:class:`faultgen.simulation.friction_update.FrictionUpdate`, made chunk by chunk by
:meth:`FrictionModel.schedule`), handed over a chunk at a time like the set-points to a backend
that applies it itself, and applied one step at a time from Python on the others
(docs/performance.md gives both models' speed).
"""

from __future__ import annotations

import mujoco
import numpy as np

from faultgen.effects import friction
from faultgen.model import robots
from faultgen.simulation.friction_update import Schedule


def stepped_effects(robot: robots.Robot) -> list:
    """The robot's effects that act through a per-step update of the rotors' dry friction."""
    return [e for e in robot.effects.values() if e.stepped and np.any(e.active())]


class FrictionModel:
    """A friction model of the simulation. Subclasses say how it enters the MJCF, which actuators
    carry it, how each run's dry and viscous friction are scaled, what sets its level before every
    step (a model with :attr:`per_step`: its :meth:`schedule`) and where the logged friction torque
    is read."""

    #: The model's name (:data:`faultgen.effects.friction.MODELS`).
    name: str
    #: Whether the friction level is set before every physics step (what friction growing with
    #: the load, the unit's gear loss, needs): by the update :meth:`schedule` makes.
    per_step: bool
    #: The MjData field the friction torque is read from after a step (:meth:`friction_torque`).
    force_field: str

    def add(self, spec: mujoco.MjSpec, robot: robots.Robot, gains) -> None:
        """Put the robot's motor-side friction into ``spec`` (after the drives, ``gains``)."""
        raise NotImplementedError

    def actuator_ids(self, model: mujoco.MjModel, robot: robots.Robot) -> np.ndarray:
        """Ids of the actuators that carry the friction, one per axis (empty: none)."""
        return np.array([], dtype=int)

    def scale_viscous(self, sim, runs, factor: np.ndarray) -> None:
        """Multiply each run's viscous friction by ``factor`` (n_sim, N)."""
        raise NotImplementedError

    def scale_dry(self, sim, runs, dry: np.ndarray) -> None:
        """Multiply each run's dry (Coulomb and static) friction by ``dry`` (n_sim, N), once before
        stepping (a :attr:`per_step` model scales it in its :meth:`schedule` instead)."""

    def schedule(self, sim, work) -> Schedule | None:
        """For a :attr:`per_step` model, the friction updates of the batch ``work``
        (:class:`faultgen.simulation.batch.Work`) chunk by chunk; None: the level stays what the
        model holds."""

    def friction_torque(self, sim, force: np.ndarray, v_m: np.ndarray, viscous: np.ndarray) -> np.ndarray:
        """The motor-side friction torque, N m, positive opposing positive motion, ``(..., N)``,
        from the :attr:`force_field` rows ``force`` ``(..., size)`` of a step, the rotor speeds
        after it ``v_m`` (rad/s) and the viscous coefficients ``viscous`` (N m s/rad)."""
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class LuGre(FrictionModel):
    """LuGre friction in MuJoCo's ``dcmotor`` actuators ``lugre{i}`` (bristle state as activation)."""

    name = "lugre"
    per_step = False
    force_field = "actuator_force"

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

    def scale_viscous(self, sim, runs, factor):
        runs.expand("actuator_damping")[:, sim.lugre_ids] *= factor

    def scale_dry(self, sim, runs, dry):
        bias = runs.expand("actuator_biasprm")
        bias[:, sim.lugre_ids, 3] *= dry  # Coulomb level F_c
        bias[:, sim.lugre_ids, 4] *= dry  # breakaway level F_s

    def friction_torque(self, sim, force, v_m, viscous):
        # friction opposes motion: minus the LuGre actuator's force, plus the viscous term
        return -force[..., sim.lugre_ids] + viscous * v_m


class Stribeck(FrictionModel):
    """Static friction (thesis eq. 6.3) as the rotors' friction loss, set before every step."""

    name = "stribeck"
    per_step = True
    force_field = "qfrc_constraint"

    def add(self, spec, robot, gains):
        friction.add_stribeck(spec, robot)

    def scale_viscous(self, sim, runs, factor):
        runs.expand("dof_damping")[:, sim.robot.rotor_dof] *= factor

    def schedule(self, sim, work):
        """The friction-loss level from the rotor speed (eq. 6.3), scaled by the stepped effects and
        added to by those that grow with the load (the unit's gear loss among them)."""
        return Schedule(sim, work, stepped_effects(sim.robot))

    def friction_torque(self, sim, force, v_m, viscous):
        # the friction loss acts as a constraint force on the rotor, plus the viscous term
        return -force[..., sim.robot.rotor_dof] + viscous * v_m


#: The friction models by name.
MODELS = {model.name: model for model in (LuGre(), Stribeck())}


def get(name: str) -> FrictionModel:
    """The friction model ``name``; raises ValueError naming it and the known ones
    (:func:`faultgen.effects.friction.check_model`)."""
    friction.check_model(name)
    return MODELS[name]
