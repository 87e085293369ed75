"""A stepping backend of the tests' own that applies the static friction model's per-step update
from its arrays alone, as a batched (GPU) backend would: the proof that
:class:`faultgen.simulation.friction_update.FrictionUpdate` holds everything the update reads.

``kernel`` steps ``mujoco.batch.Batch`` one step at a time over all runs, and before each step
writes the rotors' friction loss of every run from the update's fields with its own NumPy kernel
(:func:`friction_loss`, written from the formula in the class's docstring): it calls no faultgen
effect, no ``friction_update.apply`` and no robot method. Importing this module registers it;
tests/test_backends.py holds it to ``loop`` as every registered backend.
"""

from __future__ import annotations

import numpy as np
from mujoco import batch as mjbatch

from faultgen.simulation import backends


def friction_loss(u, k: int, qvel: np.ndarray, qpos: np.ndarray, subtree_com, xanchor, xaxis) -> np.ndarray:
    """The rotors' friction loss ``(nsim, N)`` before step ``k`` of the chunk, every run at once,
    from the fields of the update ``u`` and the runs' state (the kinematics of the last step)."""
    v = qvel[:, u.rotor_dof]
    coulomb = np.where(v > 0, u.coulomb_pos,
                       np.where(v < 0, u.coulomb_neg, np.maximum(u.coulomb_pos, u.coulomb_neg)))
    loss = (coulomb + u.static_friction * np.exp(-np.abs(v / u.stribeck_velocity) ** u.stribeck_exponent)) \
        * u.level[:, k]
    if u.load_static.shape[0] == 0:
        return loss
    transmitted = u.stiffness * (qpos[:, u.rotor_qpos] / u.gear_ratio - qpos[:, u.arm_qpos])
    joints, bodies, mass, gravity, spring, rest = u.static_terms
    moment = np.sum((xaxis[:, joints] @ gravity) * (subtree_com[:, bodies] - xanchor[:, joints]), axis=-1)
    static = mass * moment + spring * (qpos[:, u.arm_qpos] - rest)
    for t in range(u.load_static.shape[0]):
        load = np.where(u.load_static[t], static, transmitted)
        loss = loss + u.load_outer[:, t] * (u.load_inner[:, t] * np.abs(load) / u.gear_ratio)
    return loss


class KernelRuns:
    """``mujoco.batch.Batch``'s runs with a ``rollout`` that takes a friction ``update`` (stepping
    every run one step at a time from Python: a run whose warnings rise is not stopped, as the
    tests' runs do not diverge)."""

    def __init__(self, model, nsim: int, nthread: int) -> None:
        self.batch = mjbatch.Batch(model, nsim=nsim, nthread=nthread)
        self.nu = model.nu

    def __getattr__(self, name):  # bind, expand, step, forward, set_const, warning
        return getattr(self.batch, name)

    def rollout(self, nstep, control, control_spec, record, out, update=None):
        if update is None:
            return self.batch.rollout(nstep, control=control, control_spec=control_spec, record=record, out=out)
        b = self.batch
        assert control_spec == (mjbatch.mujoco.mjtState.mjSTATE_CTRL | mjbatch.mujoco.mjtState.mjSTATE_QFRC_APPLIED)
        frictionloss, ctrl, applied = b.expand("dof_frictionloss"), b.bind("ctrl"), b.bind("qfrc_applied")
        state = [b.bind(name) for name in ("qvel", "qpos", "subtree_com", "xanchor", "xaxis")]
        bound = {name: b.bind(name) for name in record}
        for k in range(nstep):
            frictionloss[:, update.rotor_dof] = friction_loss(update, k, *state)
            ctrl[...] = control[:, k, : self.nu]
            applied[...] = control[:, k, self.nu :]
            b.step()
            for name, values in bound.items():
                out[name][:, k] = values
        return out


@backends.register
class KernelBackend(backends.Stepper):
    """:class:`KernelRuns`: the friction update applied from its arrays inside ``rollout``."""

    name = "kernel"
    applies_friction_update = True

    def new(self, model, nsim, nthread):
        return KernelRuns(model, nsim, nthread)


#: An instance of it.
KERNEL = KernelBackend()
