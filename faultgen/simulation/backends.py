"""Stepping backends: what steps a batch of simulations (one per recorded cycle) of one compiled model.

A backend makes the ``runs`` of a batch (:meth:`Backend.new`); the stepping loops of
:mod:`faultgen.simulation.batch` and the friction models (:mod:`faultgen.simulation.friction_models`)
use only the methods of :class:`Runs`, the part of ``mujoco.batch.Batch``'s interface faultgen needs:

- ``bind(name)``: an MjData field of every run, ``(n, ...)``; state fields (``qpos``, ``qvel``,
  ``act``, ``ctrl``, ``qfrc_applied``) are written through, the others are read after a call
  (``mujoco.batch`` fills the fields bound before the call);
- ``expand(name)``: a model field given per-run values, ``(n, ...)``, written through;
- ``step()``: one physics step (``mj_step``) of every run;
- ``rollout(nstep, control, control_spec, record, out)``: ``nstep`` steps, setting the state
  components of ``control_spec`` from ``control`` ``(n, nstep, size)`` before each and recording
  the MjData fields ``record`` after each into ``out[name]`` ``(n, nstep, ...)``; a run whose
  warning counters rise stops stepping and repeats its last records. A backend with
  :attr:`Backend.applies_friction_update` also takes ``update``, a
  :class:`faultgen.simulation.friction_update.FrictionUpdate` of the ``nstep`` steps, and writes its
  friction loss (:func:`faultgen.simulation.friction_update.apply`) before each step, before the
  controls;
- ``forward()``: ``mj_forward`` of every run; ``set_const()``: ``mj_setConst`` of every run, keeping
  its MjData (its state and the last step's kinematics);
- ``warning``: each run's warning counters, ``(n, mjNWARNING, 2)``.

:data:`BACKENDS` by name (:func:`register` adds one): ``batch`` (``mujoco.batch.Batch``: C threads,
the default) and ``loop`` (a Python loop of ``mujoco.mj_step`` over one ``MjData`` and one
``MjModel`` copy per run, deliberately plain: the reference the tests hold ``batch`` to;
docs/architecture.md, "Stepping backends", says what a GPU backend implements).
"""

from __future__ import annotations

import copy
from typing import Protocol

import mujoco
import numpy as np
from mujoco import batch as mjbatch

from faultgen.simulation import friction_update

#: MjData fields a caller writes (inputs and state); the others are outputs of a call.
STATE_FIELDS = ("qpos", "qvel", "act", "ctrl", "qfrc_applied", "qacc_warmstart")
#: The state components ``rollout``'s ``control`` may set, in MuJoCo's state order.
_CONTROL_ORDER = ((mujoco.mjtState.mjSTATE_CTRL, "ctrl"), (mujoco.mjtState.mjSTATE_QFRC_APPLIED, "qfrc_applied"))


class Runs(Protocol):
    """The simulations of one batch (the methods the module docstring lists)."""

    warning: np.ndarray

    def bind(self, name: str) -> np.ndarray: ...

    def expand(self, name: str) -> np.ndarray: ...

    def step(self) -> None: ...

    def forward(self) -> None: ...

    def set_const(self) -> None: ...

    def rollout(self, nstep: int, control: np.ndarray, control_spec: int, record: tuple,
                out: dict, update=None) -> dict: ...


class Backend:
    """A way to step a batch of simulations of one model."""

    #: The backend's name (:data:`BACKENDS`).
    name: str
    #: Whether its runs' ``rollout`` takes a friction ``update`` and applies it before every step
    #: (the static friction model's level); False: the stepping loop steps such a run one step at a
    #: time, applying the update from Python before each (:func:`faultgen.simulation.batch.step`).
    applies_friction_update: bool = False

    def new(self, model: mujoco.MjModel, nsim: int, nthread: int) -> Runs:
        """``nsim`` simulations of ``model`` at its default state, on ``nthread`` threads where
        the backend uses threads."""
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class BatchBackend(Backend):
    """``mujoco.batch.Batch``: every run stepped in C, on ``nthread`` threads (0: all CPUs)."""

    name = "batch"

    def new(self, model, nsim, nthread):
        return mjbatch.Batch(model, nsim=nsim, nthread=nthread)


class LoopBackend(Backend):
    """A Python loop of ``mujoco.mj_step``, one ``MjData`` and one ``MjModel`` copy per run (one
    thread, slow: for checking the other backends, not for runs)."""

    name = "loop"
    applies_friction_update = True

    def new(self, model, nsim, nthread):
        return LoopRuns(model, nsim)


class LoopRuns:
    """:class:`Runs` as plain MuJoCo objects: the ``(n, ...)`` arrays :meth:`bind` and
    :meth:`expand` give are copied into every run's ``MjData`` / ``MjModel`` before each call and
    the data copied back after it."""

    def __init__(self, model: mujoco.MjModel, nsim: int):
        self.models = [copy.copy(model) for _ in range(nsim)]
        self.datas = [mujoco.MjData(m) for m in self.models]
        self._bound: dict[str, np.ndarray] = {}
        self._expanded: dict[str, np.ndarray] = {}
        self.warning = np.zeros((nsim, len(self.datas[0].warning), 2))

    def bind(self, name: str) -> np.ndarray:
        if name not in self._bound:
            self._bound[name] = np.stack([np.array(getattr(d, name), dtype=float) for d in self.datas])
        return self._bound[name]

    def expand(self, name: str) -> np.ndarray:
        if name not in self._expanded:
            self._expanded[name] = np.stack([getattr(m, name).copy() for m in self.models])
        return self._expanded[name]

    def _put(self, i: int) -> None:
        for name, values in self._expanded.items():
            getattr(self.models[i], name)[...] = values[i]
        for name in STATE_FIELDS:
            if name in self._bound:
                getattr(self.datas[i], name)[...] = self._bound[name][i]

    def _get(self, i: int) -> None:
        data = self.datas[i]
        for name, values in self._bound.items():
            values[i] = getattr(data, name)
        self.warning[i] = [(w.number, w.lastinfo) for w in data.warning]

    def _each(self, call) -> None:
        for i, (model, data) in enumerate(zip(self.models, self.datas)):
            self._put(i)
            call(model, data)
            self._get(i)

    def step(self) -> None:
        self._each(mujoco.mj_step)

    def forward(self) -> None:
        self._each(mujoco.mj_forward)

    def set_const(self) -> None:
        self._each(_set_const)

    def rollout(self, nstep, control, control_spec, record, out, update=None):
        inputs, at = [], 0
        for bit, name in _CONTROL_ORDER:
            if control_spec & bit:
                size = getattr(self.datas[0], name).size
                inputs.append((name, at, size))
                at += size
        if update is not None:
            frictionloss = self.expand("dof_frictionloss")
        for i, (model, data) in enumerate(zip(self.models, self.datas)):
            self._put(i)
            warned = sum(w.number for w in data.warning)
            stopped = False
            world = None if update is None else update.take([i])
            for k in range(nstep):
                if not stopped:
                    if world is not None:  # the friction loss from the run's state, before the controls
                        kinematics = tuple(getattr(data, f)[None] for f in friction_update.KINEMATICS)
                        model.dof_frictionloss[world.rotor_dof] = friction_update.apply(
                            world, k, data.qvel[None], data.qpos[None], kinematics)[0]
                    for name, start, size in inputs:
                        getattr(data, name)[:] = control[i, k, start:start + size]
                    mujoco.mj_step(model, data)
                    stopped = sum(w.number for w in data.warning) > warned
                for name in record:
                    out[name][i, k] = getattr(data, name)
            self._get(i)
            if update is not None:
                frictionloss[i] = model.dof_frictionloss
        return out


def _set_const(model: mujoco.MjModel, data: mujoco.MjData) -> None:
    """``mj_setConst``, keeping the run's data (it poses ``data`` at ``qpos0`` to compute): its
    state and the last step's kinematics, as ``mujoco.batch.Batch.set_const`` does."""
    kept = mujoco.MjData(model)
    mujoco.mj_copyData(kept, model, data)
    mujoco.mj_setConst(model, data)
    mujoco.mj_copyData(data, model, kept)


#: The stepping backends by name (:func:`register` adds one).
BACKENDS: dict[str, Backend] = {}


def register(backend: Backend) -> Backend:
    """Add ``backend`` (an instance of a :class:`Backend` subclass) to :data:`BACKENDS` under its
    ``name`` and return it: from then on sweeps, fleets, the cluster's workers and the monitor's twin
    reach it by that name (a process that has not registered it, a fresh worker process or a Dask
    worker, does not know it). Registering the same instance again changes nothing.

    Raises
    ------
    ValueError
        If ``backend`` is not a :class:`Backend`, its ``name`` is not a non-empty string, or the
        name is registered to another backend.
    """
    if not isinstance(backend, Backend):
        raise ValueError(f"{backend!r} is not a stepping backend (an instance of a Backend subclass)")
    name = getattr(backend, "name", None)
    if not isinstance(name, str) or not name:
        raise ValueError(f"stepping backend {backend!r} has no name (a class attribute name = '...')")
    if BACKENDS.get(name, backend) is not backend:
        raise ValueError(f"stepping backend {name!r} is already registered to {BACKENDS[name]!r}")
    BACKENDS[name] = backend
    return backend


register(BatchBackend())
register(LoopBackend())

#: The backend runs use unless told otherwise.
DEFAULT = "batch"


def get(name: str) -> Backend:
    """The stepping backend ``name``; raises ValueError naming it and the known ones."""
    if name not in BACKENDS:
        raise ValueError(f"unknown stepping backend {name!r}; expected one of {', '.join(BACKENDS)}")
    return BACKENDS[name]
