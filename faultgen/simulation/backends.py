"""Steppers (stepping backends): what steps a batch of simulations (one per recorded cycle) of one compiled model.

A stepper is an object (frozen, picklable: it travels to worker processes and Dask workers as it
is): :class:`BatchStepper` or :class:`LoopStepper`, or one of a user's. It makes the ``runs`` of a
batch (:meth:`Stepper.new`); the stepping loops of
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
  :attr:`Stepper.applies_friction_update` also takes ``update``, a
  :class:`faultgen.simulation.friction_update.FrictionUpdate` of the ``nstep`` steps, and writes its
  friction loss (:func:`faultgen.simulation.friction_update.apply`) before each step, before the
  controls;
- ``forward()``: ``mj_forward`` of every run; ``set_const()``: ``mj_setConst`` of every run, keeping
  its MjData (its state and the last step's kinematics);
- ``warning``: each run's warning counters, ``(n, mjNWARNING, 2)``.

:data:`STEPPERS`, the stepper classes by name, is for resolving a name given by a user (the CLI's
``--backend``) once, at the CLI boundary (:func:`get`; :func:`register` adds a class): ``batch``
(:class:`BatchStepper`, ``mujoco.batch.Batch``: C threads, the default) and ``loop`` (:class:`LoopStepper`, (a Python loop of ``mujoco.mj_step`` over one ``MjData`` and one
``MjModel`` copy per run, deliberately plain: the reference the tests hold ``batch`` to;
docs/architecture.md, "Stepping backends", says what a GPU backend implements).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import ClassVar, Protocol

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


@dataclass(frozen=True)
class Stepper:
    """A way to step a batch of simulations of one model (frozen, picklable: compared by value)."""

    #: The stepper's name (:data:`STEPPERS`; the CLI's ``--backend``).
    name: ClassVar[str]
    #: Whether its runs' ``rollout`` takes a friction ``update`` and applies it before every step
    #: (the static friction model's level); False: the stepping loop steps such a run one step at a
    #: time, applying the update from Python before each (:func:`faultgen.simulation.batch.step`).
    applies_friction_update: ClassVar[bool] = False

    def new(self, model: mujoco.MjModel, nsim: int, nthread: int) -> Runs:
        """``nsim`` simulations of ``model`` at its default state, on ``nthread`` threads where
        the stepper uses threads (the run's ``nthread``)."""
        raise NotImplementedError


@dataclass(frozen=True)
class BatchStepper(Stepper):
    """``mujoco.batch.Batch``: every run stepped in C, on ``nthread`` threads (0: all CPUs; None, the
    default: the run's own ``nthread``)."""

    name: ClassVar[str] = "batch"
    nthread: int | None = None

    def new(self, model, nsim, nthread):
        return mjbatch.Batch(model, nsim=nsim, nthread=nthread if self.nthread is None else self.nthread)


@dataclass(frozen=True)
class LoopStepper(Stepper):
    """A Python loop of ``mujoco.mj_step``, one ``MjData`` and one ``MjModel`` copy per run (one
    thread, slow: for checking the other steppers, not for runs)."""

    name: ClassVar[str] = "loop"
    applies_friction_update: ClassVar[bool] = True

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


#: The stepper classes by name (:func:`register` adds one), for resolving a user's name once.
STEPPERS: dict[str, type[Stepper]] = {}


def register(stepper: type[Stepper]) -> type[Stepper]:
    """Add the stepper class ``stepper`` (a :class:`Stepper` subclass, made with no arguments) to
    :data:`STEPPERS` under its ``name`` and return it (a class decorator): from then on the CLI's
    ``--backend`` reaches it by that name. Sweeps, fleets, the cluster's workers and the monitor's
    twin receive the stepper object itself (a worker process unpickles it: its class must be
    importable there). Registering the same class again changes nothing.

    Raises
    ------
    ValueError
        If ``stepper`` is not a :class:`Stepper` subclass, its ``name`` is not a non-empty string, or
        the name is registered to another class.
    """
    if not (isinstance(stepper, type) and issubclass(stepper, Stepper)):
        raise ValueError(f"{stepper!r} is not a stepping backend (a subclass of Stepper)")
    name = getattr(stepper, "name", None)
    if not isinstance(name, str) or not name:
        raise ValueError(f"stepping backend {stepper!r} has no name (a class attribute name = '...')")
    if STEPPERS.get(name, stepper) is not stepper:
        raise ValueError(f"stepping backend {name!r} is already registered to {STEPPERS[name]!r}")
    STEPPERS[name] = stepper
    return stepper


register(BatchStepper)
register(LoopStepper)

#: The name of the stepper runs use unless told otherwise.
DEFAULT = "batch"
#: The stepper runs use unless told otherwise.
DEFAULT_STEPPER = BatchStepper()


def get(name: str) -> Stepper:
    """A stepper of the class registered as ``name`` (made with no arguments); raises ValueError
    naming it and the known ones."""
    if name not in STEPPERS:
        raise ValueError(f"unknown stepping backend {name!r}; expected one of {', '.join(STEPPERS)}")
    return STEPPERS[name]()


def key_text(stepper: Stepper) -> str:
    """What a run key (a Dask task's) records of ``stepper``: nothing for the default, ``backend=NAME``
    for a stepper made with no arguments (the text keys had when steppers travelled as names), and
    its repr after that for one made with others."""
    if stepper == DEFAULT_STEPPER:
        return ""
    try:
        plain = stepper == type(stepper)()
    except TypeError:  # a stepper class that needs arguments
        plain = False
    return f"backend={stepper.name}" + ("" if plain else f" {stepper!r}")


def checked(stepper: Stepper) -> Stepper:
    """``stepper`` when it is a :class:`Stepper`; raises ValueError naming it otherwise (a name: use
    :func:`get`)."""
    if not isinstance(stepper, Stepper):
        raise ValueError(f"{stepper!r} is not a stepper (a Stepper object such as BatchStepper(); a name is "
                         f"resolved by faultgen.simulation.backends.get, one of {', '.join(STEPPERS)})")
    return stepper
