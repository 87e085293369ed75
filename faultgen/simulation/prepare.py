"""What every run of a robot, task and friction model shares, prepared once per process: the
compiled simulation model, the task's path and the drive set-points (:class:`Prepared`), also for a
robot carrying a part or a growing fault."""

from __future__ import annotations

import functools
import json
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

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


def prepared_for(robot: str, task: str, friction_model: str, payload: dict | None = None,
              fault: Fault | None = None) -> Prepared:
    """:func:`_prepare`, renewed when the robot's model or task file changes; ``payload``: the
    :class:`faultgen.effects.payload.Payload` parameters of a part the robot carries; ``fault``:
    a growing fault to build into the simulated robot (:func:`_prepare_variant`)."""
    stamps = file_stamps(robot, task)
    if payload is None and fault is None:
        return _prepare(robot, task, friction_model, *stamps)
    key = None if fault is None else json.dumps(fault.to_dict(), sort_keys=True)
    return _prepare_variant(robot, task, friction_model, None if payload is None else tuple(sorted(payload.items())),
                            key, *stamps)


def file_stamps(robot: str, task: str) -> tuple[int, ...]:
    """Modification times of the robot's model and task files (and of a program or log file, with
    its size): what renews the cached preparations. Raises ValueError for a model file copied
    without its ``tasks.toml``."""
    model_file = robots.load(robot).path
    tasks_file = model_file.parent / "tasks.toml"
    if not tasks_file.is_file():  # a model file copied without its tasks: say so, not FileNotFoundError
        raise ValueError(f"{tasks_file}: no tasks file beside the model {model_file}; copy the robot's tasks.toml "
                         "with it (the model `faultgen calibrate` writes has one)")
    stamps = (model_file.stat().st_mtime_ns, tasks_file.stat().st_mtime_ns)
    if programs.is_file_task(task):
        stamps = (*stamps, Path(task).stat().st_mtime_ns, Path(task).stat().st_size)
    return stamps


@functools.lru_cache(maxsize=16)
def task_path(robot_name: str, task_name: str, *file_stamps: int):
    """The task (thesis task, program or replayed log) and its checked path at the robot's physics
    step, once per process (``file_stamps`` renew it on edits)."""
    robot = robots.load(robot_name)
    task = programs.load(robot, task_name)
    return task, task.trajectory(robot.model.opt.timestep)


@functools.lru_cache(maxsize=16)
def _prepare_variant(robot_name: str, task_name: str, friction_model: str, payload: tuple | None, fault: str | None,
                     *file_stamps: int) -> Prepared:
    """The :class:`Prepared` of a robot carrying a payload (``(name, value)`` pairs of the
    :class:`~faultgen.effects.payload.Payload` parameters, written as a body at the flange) and/or
    with a growing fault (a :class:`Fault` as JSON): the nominal task path; a model with the payload
    and the fault's effect in it (at its final value; :attr:`Prepared.fault_fields` move it per
    simulation), and a feedforward with the payload only (the controller knows the load it carries,
    not the fault)."""
    nominal = _prepare(robot_name, task_name, friction_model, *file_stamps)
    if nominal.grips:
        raise ValueError(f"{task_name} grips and releases a payload within the cycle; it runs without the payload "
                         "condition (--payloads) and without a growing fault")
    robot = robots.load(robot_name)
    load = None if payload is None else Payload(**dict(payload))

    def carry(spec):
        if load is not None:
            load.write(spec, robot)

    controller = robot.edited(carry) if load is not None else robot
    fields_ = ()
    if fault is None:
        sim = build(controller, friction_model, edit=carry)
    else:
        grown = Fault(**json.loads(fault))

        def model_at(value: float) -> SimModel:
            def edit(mjspec):
                carry(mjspec)
                effect = grown.at(value, controller.n_axes)
                effect.write(mjspec, controller, [grown.axis - 1])
                effect.add_to_simulation(mjspec, controller)
            return build(controller, friction_model, edit=edit)

        sim = model_at(grown.final)
        fields_ = _affine_fields(model_at, grown.start, grown.final, sim.model)
    n_steps = len(nominal.inputs) - 1
    path = nominal.path
    inputs = sim.setpoints(nominal.q_ref, *(hold_end(a, n_steps) for a in (path.qd, path.qdd)))
    inputs.setflags(write=False)
    return Prepared(sim, nominal.task, path, nominal.q_ref, inputs, fields_)


def _affine_fields(model_at, start: float, final: float, model) -> tuple:
    """The model fields a fault's parameter moves, as ``(field, flat indices, values at final,
    change per unit)``: found by comparing ``model`` (compiled at ``final``) with the model
    ``model_at(value)`` compiled half way from ``start``, and checked affine at a quarter (the
    effect's MJCF form is linear in the parameter for every schedulable effect: a dead band's spring
    lengths, a cogging amplitude, an offset's bias, a friction level).

    Raises
    ------
    ValueError
        If the models differ in structure or a field is not affine in the parameter.
    """
    value, other_value, check_value = final, start + 0.5 * (final - start), start + 0.25 * (final - start)
    other, check = model_at(other_value).model, model_at(check_value).model
    out = []
    for name in dir(model):
        a = getattr(model, name, None)
        if name.startswith("_") or not isinstance(a, np.ndarray) or a.dtype.kind != "f":
            continue
        b, c = getattr(other, name), getattr(check, name)
        if a.shape != b.shape or a.shape != c.shape:
            raise ValueError(f"the fault changes the model's structure ({name}); it cannot grow per cycle")
        changed = np.flatnonzero((a != b).ravel())
        if changed.size == 0:
            continue
        slope = (a.ravel()[changed] - b.ravel()[changed]) / (value - other_value)
        expected = a.ravel()[changed] + slope * (check_value - value)
        if not np.allclose(c.ravel()[changed], expected, rtol=1e-9, atol=1e-12):
            raise ValueError(f"the fault's parameter moves model field {name} non-linearly; it cannot grow per cycle")
        out.append((name, changed, a.ravel()[changed].copy(), slope))
    return tuple(out)


@functools.lru_cache(maxsize=8)
def _prepare(robot_name: str, task_name: str, friction_model: str, *file_stamps: int) -> Prepared:
    """The :class:`Prepared` of a robot, task and friction model, computed once per process
    (``file_stamps``, the modification times of the model and task files, renew it on edits).
    Arrays are made read-only so no run can change what the next one gets.
    """
    robot = robots.load(robot_name)
    task, path = task_path(robot_name, task_name, *file_stamps)
    loads = getattr(path, "loads", ())
    sim = build(robot, friction_model,
                edit=(lambda spec: programs.add_part(spec, robot, loads[0].params)) if loads else None)
    per_log = int(round(sensors.LOG_PERIOD / sim.model.opt.timestep))
    n_steps = _padded_steps(len(path.t) - 1, per_log)
    q_ref, qd_ref, qdd_ref = (hold_end(a, n_steps) for a in (path.q, path.qd, path.qdd))
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
    for array in (q_ref, inputs):
        array.setflags(write=False)
    return Prepared(sim, task, path, q_ref, inputs, grips=grips)


def cycle_duration(robot: str, task: str) -> float:
    """Simulated time of one cycle of ``task`` on ``robot``, s (what a run steps per cycle)."""
    prepared = prepared_for(robot, task, "stribeck")  # builds for any model file
    return (len(prepared.inputs) - 1) * prepared.sim.model.opt.timestep


def _padded_steps(n: int, per_log: int) -> int:
    return -(-n // per_log) * per_log


def hold_end(a: np.ndarray, n_steps: int) -> np.ndarray:
    """The first ``n_steps + 1`` samples of a path ``a`` (n, ...), holding its last sample when it
    is shorter (a task's path sampled at every physics step, or at every log period)."""
    if len(a) >= n_steps + 1:
        return a[: n_steps + 1]
    return np.vstack([a, np.repeat(a[-1:], n_steps + 1 - len(a), axis=0)])
