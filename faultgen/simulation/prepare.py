"""What every run of a robot, task and friction model shares, prepared once per process: the
compiled simulation model, the task's path and the drive set-points (:class:`Prepared`), also for a
robot carrying a part or a growing fault."""

from __future__ import annotations

import functools
import hashlib
import json
from dataclasses import dataclass, replace

import numpy as np

from faultgen import effects, inputs
from faultgen.effects.payload import Payload
from faultgen.model import robots
from faultgen.operation import programs, tasks
from faultgen.operation.faults import Fault
from faultgen.simulation import sensors
from faultgen.simulation.model import SimModel, build


@dataclass(frozen=True)
class Prepared:
    """What every run of a robot, task and friction model shares (read-only arrays).

    Attributes
    ----------
    sim : SimModel
        The compiled simulation model (a stepping backend works on copies of it).
    task : faultgen.operation.tasks.Task
    path : faultgen.operation.tasks.JointPath
        The task's path sampled at every physics step.
    q_ref : ndarray of shape (n_steps + 1, N)
        Reference arm angles at every physics step, rad (held at the end to a whole log period).
    inputs : ndarray of shape (n_steps + 1, N, 3)
        Drive set-points (angle, speed, feedforward) at every physics step, motor side.
    fault_fields : tuple
        For a model with a growing fault: the fields its parameter moves (:func:`_affine_fields`),
        set per simulation from each cycle's value.
    grips : tuple
        For a program that grips and releases a payload: ``(physics step, gripped body's values)``
        where its mass changes (:func:`faultgen.simulation.batch.apply_grips`).
    """

    sim: SimModel
    task: tasks.Task
    path: tasks.JointPath
    q_ref: np.ndarray
    inputs: np.ndarray
    fault_fields: tuple = ()
    grips: tuple = ()

    @property
    def per_log(self) -> int:
        """Physics steps per log period."""
        return int(round(sensors.LOG_PERIOD / self.sim.model.opt.timestep))


def prepared_for(robot: robots.Robot, task: str, friction_model: str, payload: dict | None = None,
                 fault: Fault | None = None) -> Prepared:
    """:func:`_prepare` of the resolved ``robot`` (a name is resolved once, at the boundary:
    :func:`faultgen.model.robots.load`; TypeError for anything but a :class:`Robot`), renewed when
    its task file's content changes (:func:`digests`); ``payload``: the :class:`faultgen.effects.payload.Payload` parameters of a
    part the robot carries; ``fault``: a growing fault to build into the simulated robot
    (:func:`_prepare_variant`)."""
    robots.require(robot, "prepared_for")
    keys = digests(robot, task)
    if payload is None and fault is None:
        return _prepare(robot, task, friction_model, *keys)
    key = None if fault is None else json.dumps(fault.to_dict(), sort_keys=True)
    return _prepare_variant(robot, task, friction_model, None if payload is None else tuple(sorted(payload.items())),
                            key, *keys)


def digests(robot: robots.Robot, task) -> tuple[str, ...]:
    """SHA-256 of the robot folder's task file (and of a program or log file's bytes): what keys the
    cached preparations besides the task as given, so that an edited file is planned again and an
    unchanged one is not, whatever its modification time (the robot's own model is the
    :class:`Robot` object they are keyed by, one per file content; a program's text and a motion in
    memory are keyed by their content already). Raises ValueError for a model file copied without
    its ``tasks.toml``."""
    model_file = robot.path
    tasks_file = model_file.parent / "tasks.toml"
    if not tasks_file.is_file():  # a model file copied without its tasks: say so, not FileNotFoundError
        raise ValueError(f"{tasks_file}: no tasks file beside the model {model_file}; copy the robot's tasks.toml "
                         "with it (the model `faultgen calibrate` writes has one)")
    # through faultgen.inputs, each size checked before the read (a sparse 20 GiB tasks.toml or
    # program file was read whole here: a MemoryError)
    found = (hashlib.sha256(inputs.read_bytes(tasks_file, "tasks file", inputs.TOML_MAX_BYTES)).hexdigest(),)
    if programs.kind(task) in programs.FILE_KINDS:
        found = (*found, programs.file_sha256(task))
    return found


@functools.lru_cache(maxsize=16)
def task_path(robot: robots.Robot, task_name: str, *digests: str):
    """The task (thesis task, program or replayed log) and its checked path at the robot's physics
    step, once per process, robot and content (``digests``: :func:`digests`)."""
    task = programs.load(robot, task_name)
    return task, task.trajectory(robot.model.opt.timestep)


@functools.lru_cache(maxsize=16)
def _reference(robot: robots.Robot, task_name: str, *digests: str) -> tuple:
    """``(task, path, q_ref, qd_ref, qdd_ref)``: the task's path held to a whole number of log
    periods at the robot's physics step, what every friction model and variant of the robot
    shares (read-only; no simulation model is compiled for it)."""
    task, path = task_path(robot, task_name, *digests)
    per_log = int(round(sensors.LOG_PERIOD / robot.model.opt.timestep))
    n_steps = _padded_steps(len(path.t) - 1, per_log)
    arrays = tuple(hold_end(a, n_steps) for a in (path.q, path.qd, path.qdd))
    for array in arrays:
        array.setflags(write=False)
    return (task, path, *arrays)


@functools.lru_cache(maxsize=16)
def _prepare_variant(robot: robots.Robot, task_name: str, friction_model: str, payload: tuple | None,
                     fault: str | None, *digests: str) -> Prepared:
    """The :class:`Prepared` of a robot carrying a payload (``(name, value)`` pairs of the
    :class:`~faultgen.effects.payload.Payload` parameters, written as a body at the flange) and/or
    with a growing fault (a :class:`Fault` as JSON): the nominal task path; a model with the payload
    and the fault's effect in it (at its final value; :attr:`Prepared.fault_fields` move it per
    simulation), and a feedforward with the payload only (the controller knows the load it carries,
    not the fault). No nominal simulation model is compiled for it."""
    task, path, q_ref, qd_ref, qdd_ref = _reference(robot, task_name, *digests)
    if getattr(path, "loads", ()):
        raise ValueError(f"{task_name} grips and releases a payload within the cycle; it runs without the payload "
                         "condition (--payloads) and without a growing fault")
    load = None if payload is None else Payload(**dict(payload))
    # the controller's robot: the nominal one carrying the payload, derived from its spec in memory
    controller = robot.edited(lambda spec: load.write(spec, robot)) if load is not None else robot
    fields_ = ()
    if fault is None:
        sim = build(controller, friction_model)
    else:
        grown = Fault(**json.loads(fault))
        model_at = fault_model(controller, friction_model, grown)
        sim = model_at(grown.final)
        fields_ = _affine_fields(model_at, grown.start, grown.final, sim.model,
                                 checked=not type(effects.get(grown.effect)).affine_mjcf)
    inputs = sim.setpoints(q_ref, qd_ref, qdd_ref)
    inputs.setflags(write=False)
    return Prepared(sim, task, path, q_ref, inputs, fields_)


def fault_model(robot: robots.Robot, friction_model: str, fault: Fault):
    """``model_at(value)``: the simulation model of ``robot`` with ``fault``'s effect at ``value``
    of its parameter, derived from the robot's spec (:func:`faultgen.simulation.model.build`)."""
    def model_at(value: float) -> SimModel:
        def edit(mjspec):
            effect = fault.at(value, robot.n_axes)
            effect.write(mjspec, robot, [fault.axis - 1])
            effect.add_to_simulation(mjspec, robot)
        return build(robot, friction_model, edit=edit)
    return model_at


def _affine_fields(model_at, start: float, final: float, model, checked: bool = True) -> tuple:
    """The model fields a fault's parameter moves, as ``(field, flat indices, values at final,
    change per unit)``: found by comparing ``model`` (compiled at ``final``) with the model
    ``model_at(value)`` compiled half way from ``start``, and, with ``checked``, checked affine at a
    quarter (a third compile). The effect's MJCF form is linear in the parameter for every built-in
    schedulable effect (a dead band's spring lengths, a cogging amplitude, an offset's bias); those
    say so (:attr:`faultgen.effects.Effect.affine_mjcf`, proved by tests/test_compile_count.py) and
    skip the check; an effect that does not (a plug-in's) is checked.

    Raises
    ------
    ValueError
        If the models differ in structure or a field is not affine in the parameter.
    """
    value, other_value, check_value = final, start + 0.5 * (final - start), start + 0.25 * (final - start)
    other = model_at(other_value).model
    check = model_at(check_value).model if checked else None
    out = []
    for name in dir(model):
        a = getattr(model, name, None)
        if name.startswith("_") or not isinstance(a, np.ndarray) or a.dtype.kind != "f":
            continue
        b = getattr(other, name)
        c = b if check is None else getattr(check, name)
        if a.shape != b.shape or a.shape != c.shape:
            raise ValueError(f"the fault changes the model's structure ({name}); it cannot grow per cycle")
        changed = np.flatnonzero((a != b).ravel())
        if changed.size == 0:
            continue
        slope = (a.ravel()[changed] - b.ravel()[changed]) / (value - other_value)
        expected = a.ravel()[changed] + slope * (check_value - value)
        if check is not None and not np.allclose(c.ravel()[changed], expected, rtol=1e-9, atol=1e-12):
            raise ValueError(f"the fault's parameter moves model field {name} non-linearly; it cannot grow per cycle")
        out.append((name, changed, a.ravel()[changed].copy(), slope))
    return tuple(out)


@functools.lru_cache(maxsize=8)
def _prepare(robot: robots.Robot, task_name: str, friction_model: str, *digests: str) -> Prepared:
    """The :class:`Prepared` of a robot, task and friction model, computed once per process, robot
    object and content of the task files (``digests``: :func:`digests`).
    Arrays are made read-only so no run can change what the next one gets.
    """
    task, path, q_ref, qd_ref, qdd_ref = _reference(robot, task_name, *digests)
    loads = getattr(path, "loads", ())
    sim = build(robot, friction_model,
                edit=(lambda spec: programs.add_part(spec, robot, loads[0].params)) if loads else None)
    inputs = sim.setpoints(q_ref, qd_ref, qdd_ref)  # (n_steps + 1, N, 3)
    grips = ()
    if loads:  # the drives know the part they carry: its feedforward where the program grips it
        body = sim.model.body(programs.GRIP_BODY).id
        events = {0: (body, 0.0, np.zeros(3), np.zeros(3), np.array([1.0, 0, 0, 0]))}
        for load in loads:
            carrying = robot.edited(lambda spec, p=load.params: programs.add_part(spec, robot, p))
            with_load = replace(sim, robot=carrying).setpoints(q_ref, qd_ref, qdd_ref)
            inputs[load.first:load.last] = with_load[load.first:load.last]
            grip = carrying.model.body(programs.GRIP_BODY)
            events[load.first] = (body, float(grip.mass[0]), grip.inertia.copy(), grip.ipos.copy(), grip.iquat.copy())
            events[load.last] = events[0]
        grips = tuple(sorted(events.items()))
    inputs.setflags(write=False)
    return Prepared(sim, task, path, q_ref, inputs, grips=grips)


def cycle_duration(robot: robots.Robot, task: str) -> float:
    """Simulated time of one cycle of ``task`` on the resolved ``robot``, s (what a run steps per
    cycle): the task's path held to whole log periods, no simulation model compiled for it.
    TypeError for anything but a :class:`~faultgen.model.robot.Robot`."""
    robots.require(robot, "cycle_duration")
    q_ref = _reference(robot, task, *digests(robot, task))[2]
    return (len(q_ref) - 1) * robot.model.opt.timestep


def _padded_steps(n: int, per_log: int) -> int:
    return -(-n // per_log) * per_log


def hold_end(a: np.ndarray, n_steps: int) -> np.ndarray:
    """The first ``n_steps + 1`` samples of a path ``a`` (n, ...), holding its last sample when it
    is shorter (a task's path sampled at every physics step, or at every log period)."""
    if len(a) >= n_steps + 1:
        return a[: n_steps + 1]
    return np.vstack([a, np.repeat(a[-1:], n_steps + 1 - len(a), axis=0)])
