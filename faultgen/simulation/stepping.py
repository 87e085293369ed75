"""Stepping: one robot repeating one task for many cycles while chosen axes wear.

Only the cycles that are recorded are simulated. Each starts from the task's start state (at
rest, gearboxes deflected by the static load, drives on their set-points) with its own wear
level, so cycles are independent: they are stepped together as the simulations of one
``mujoco.batch.Batch``, one per cycle, with the wear as per-simulation model fields. A run
without wear can instead step its cycles back to back in one simulation (``back_to_back``), each
cycle starting from the state the previous one ended in, as a robot's own log runs on: the
hidden-effect logs of the calibration do (:mod:`faultgen.calibrate.synth`).

With the ``lugre`` friction model everything that runs at the physics rate (the PID drives,
LuGre friction, the gearboxes) runs inside MuJoCo, and Python only hands over pre-computed
set-points and disturbance torques a chunk at a time (``Batch.rollout``). The static
``stribeck`` model needs its friction level set before every physics step from the rotor speed,
so it steps from Python and is slower (docs/performance.md gives both figures).
"""

from __future__ import annotations

import functools
import json
import time
from collections.abc import Callable
from dataclasses import dataclass, field, fields, replace

import mujoco
import numpy as np
from mujoco import batch as mjbatch
from tqdm.auto import tqdm

from faultgen.checks import is_whole
from faultgen.effects import friction
from faultgen.effects.base import Effect
from faultgen.effects.load_dependent_friction import LoadDependentFriction
from faultgen.effects.payload import Payload
from faultgen.model import robots
from faultgen.operation import tasks
from faultgen.operation.conditions import Conditions, CycleConditions
from faultgen.operation.faults import Fault
from faultgen.operation.wear import WearPlan
from faultgen.simulation import control, sensors

#: Most cycles stepped together in one ``Batch``: bounds the step buffers (about 1 MB per cycle
#: and second of chunk) when a run records many cycles (the c2 preset records 1200).
BATCH_CYCLES = 100

#: Logging periods handed to MuJoCo per ``Batch.rollout`` call (1 s of simulated time): long
#: enough that the hand-over costs little, short enough that the per-step records stay small.
CHUNK_PERIODS = 250


class SimulationDiverged(RuntimeError):
    """A cycle's state became non-finite or MuJoCo warned; the message names cycle and axis."""

    #: The command line's exit code for it (faultgen.cli.base.Command).
    exit_code = 1


@dataclass(frozen=True)
class RunConfig:
    """One run: a robot repeating a task for ``cycles`` cycles while the axes of ``wear`` wear.

    Attributes
    ----------
    robot : str
        Robot name (``faultgen robots``) or MJCF path.
    task : str
        One of :data:`faultgen.tasks.TASKS`.
    friction : str
        Friction model, one of :data:`faultgen.friction.MODELS`.
    wear : WearPlan
        Worn axes and their schedules; empty for no wear.
    cycles : int
        Number of cycles of the run (cycle indices 1..cycles); >= 1.
    record : tuple of int, optional
        The cycles to simulate and record; all of them when omitted.
    seed : int
        Seed of the disturbance and encoder noise; >= 0.
    noise : NoiseConfig
        Disturbance and encoder noise levels.
    nthread : int
        Threads for stepping (0: all CPUs).
    back_to_back : bool
        Step the cycles one after the other in one simulation, each starting where the previous
        one ended (gearbox deflections, backlash flanks, drive integrators carry over), instead of
        each from the start state. Only without wear and with every cycle recorded.
    conditions : Conditions
        Operating conditions over the cycles (joint temperature, payloads, task mix, unit spread;
        :mod:`faultgen.operation.conditions`); none by default.
    signals : bool
        Keep the 250 Hz signals in the dataset (False: the per-cycle features and truth only).
    fault : Fault or None
        A fault other than friction wear: an effect's parameter growing over the cycles
        (:mod:`faultgen.operation.faults`); the controller does not know it.
    daily : bool
        Record one remote-monitoring sample per day of ``conditions.cycles_per_day`` cycles, the
        day's maximum (thesis ch. 5.3.2; :func:`daily_record`), instead of every cycle; every
        cycle is simulated, no signals are kept.

    Raises
    ------
    ValueError
        On construction, for an unknown robot or an invalid robot file (e.g. a negative friction
        parameter), an unknown task or friction model, cycles < 1, a recorded cycle outside
        1..cycles, a negative seed or nthread, ``back_to_back`` with wear, operating conditions,
        a fault or a ``record`` subset, ``daily`` with a ``record`` subset, signals, or cycles that
        are not whole days, a fault whose last cycle is not the run's or whose effect the robot
        already carries, a task mix without the run's task or with signals, or a unit spread with a
        gear loss under the ``lugre`` friction model; the message names the value.
    """

    robot: str
    task: str
    friction: str = "lugre"
    wear: WearPlan = field(default_factory=lambda: WearPlan({}))
    cycles: int = 100
    record: tuple[int, ...] | None = None
    seed: int = 0
    noise: sensors.NoiseConfig = field(default_factory=sensors.NoiseConfig)
    nthread: int = 0
    back_to_back: bool = False
    conditions: Conditions = field(default_factory=Conditions)
    signals: bool = True
    daily: bool = False
    fault: Fault | None = None

    def __post_init__(self) -> None:
        robots.load(self.robot)  # UnknownRobotError / ModelError (ValueErrors) name the problem
        if self.task not in tasks.TASKS:
            raise ValueError(f"unknown task {self.task!r}; expected one of: {', '.join(tasks.TASKS)}")
        friction.check_model(self.friction)
        if not is_whole(self.cycles, 1):
            raise ValueError(f"cycles = {self.cycles!r}; expected a whole number >= 1")
        if self.record is not None:
            record = tuple(int(c) for c in self.record)
            if not record:
                raise ValueError("record is empty; give at least one cycle, or omit it to record all")
            bad = [c for c in record if not 1 <= c <= self.cycles]
            if bad:
                raise ValueError(f"recorded cycle {bad[0]} is out of range 1..{self.cycles}")
            object.__setattr__(self, "record", tuple(sorted(set(record))))
        if not is_whole(self.seed, 0):
            raise ValueError(f"seed = {self.seed!r}; expected a whole number >= 0")
        if self.nthread < 0:
            raise ValueError(f"nthread = {self.nthread!r}; expected >= 0 (0 uses all CPUs)")
        if not isinstance(self.conditions, Conditions):
            raise TypeError(f"conditions: expected a Conditions, got {type(self.conditions).__name__}")
        if self.fault is not None:
            if not isinstance(self.fault, Fault):
                raise TypeError(f"fault: expected a Fault, got {type(self.fault).__name__}")
            if self.fault.last_cycle != self.cycles:
                raise ValueError(f"fault last_cycle {self.fault.last_cycle} differs from the run's {self.cycles} cycles")
            if self.fault.effect in robots.load(self.robot).effects and np.any(
                    robots.load(self.robot).effects[self.fault.effect].active()):
                raise ValueError(f"{self.robot} already carries {self.fault.effect}; a growing {self.fault.effect} fault "
                                 "needs a robot without it")
            if self.back_to_back:
                raise ValueError("a fault grows from cycle to cycle: run the cycles independently (no back_to_back)")
        if self.back_to_back and (self.wear.schedules or self.conditions.active
                                  or self.record not in (None, tuple(range(1, self.cycles + 1)))):
            raise ValueError("back_to_back runs step every cycle in one simulation without wear or operating "
                             f"conditions; got wear on axes {list(self.wear.schedules)}, conditions "
                             f"{'on' if self.conditions.active else 'off'} and record = {self.record!r}: drop "
                             "them, or run the cycles independently")
        mix = self.conditions.task_mix
        if mix is not None and self.task not in mix.tasks:
            raise ValueError(f"task {self.task!r} is not in the task mix ({', '.join(mix.tasks)}); a run's own task "
                             "must be one of the tasks its cycles run")
        if mix is not None and self.signals:
            raise ValueError(f"a task mix ({', '.join(mix.tasks)}) keeps no signals: cycles of different tasks differ "
                             "in length; record features only (--features-only, signals=False)")
        spread = self.conditions.spread
        if spread is not None and spread.gear_loss > 0 and self.friction == "lugre":
            raise ValueError(f"unit spread gear_loss = {spread.gear_loss!r} needs the static friction model "
                             "(friction='stribeck', --friction stribeck): friction growing with the load is "
                             "updated every step from Python, and the lugre model runs inside MuJoCo")
        if self.daily:
            per_day = self.conditions.cycles_per_day
            if self.record is not None or self.signals or self.cycles % per_day:
                raise ValueError(f"daily records need every cycle recorded, no signals and whole days: got record = "
                                 f"{self.record!r}, signals = {self.signals}, {self.cycles} cycles at {per_day} a day")

    @property
    def recorded_cycles(self) -> np.ndarray:
        """Indices of the simulated cycles, ``ndarray of shape (n_recorded,)``."""
        if self.record is None:
            return np.arange(1, self.cycles + 1)
        return np.array(self.record)


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
    drive_ctrl : ndarray of shape (6, 3)
        ``ctrl`` indices of each drive's (pos, vel, ff) inputs.
    drive_ids : ndarray of shape (6,)
        Actuator ids of the drives ``motor{i}``.
    lugre_ids : ndarray of shape (6,)
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
    def implicit_position(self) -> bool:
        """Whether the step is implicit in position too (MuJoCo's ``discrete`` integrator)."""
        return self.model.opt.integrator == mujoco.mjtIntegrator.mjINT_DISCRETE

    def setpoints(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """:func:`faultgen.control.setpoints` of a path sampled at this model's physics step, for its
        integrator (the drives' position gains when it is implicit in position), ``(n, 6, 3)``."""
        return control.setpoints(self.robot, q, qd, qdd, self.model.opt.timestep,
                                 self.gains.kp if self.implicit_position else None)

    def applied_force(self, force: np.ndarray, v_m: np.ndarray, v_m_before: np.ndarray) -> np.ndarray:
        """:func:`applied_drive_torque` for this model's drives, on ``actuator_force`` rows.

        Parameters
        ----------
        force : ndarray of shape (..., n_actuators)
            ``actuator_force`` of a step, N m at the motor side.
        v_m, v_m_before : ndarray of shape (..., 6)
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
    """Compile ``robot`` with PID drives (:mod:`faultgen.control`) and a friction model;
    ``edit(spec)``, when given, is applied to the MJCF first (as :meth:`Robot.edited` made ``robot``).

    Raises
    ------
    ValueError
        For an unknown friction model, or friction parameters the model cannot represent.
    """
    friction.check_model(friction_model)
    spec = mujoco.MjSpec.from_file(str(robot.path))
    if edit is not None:
        edit(spec)
    gains = control.ServoGains.for_robot(robot)
    control.add_drives(spec, robot, gains)
    if friction_model == "lugre":
        stepped = _stepped(robot)
        if stepped:
            raise ValueError(
                f"{robot.path}: {' and '.join(e.summary for e in stepped)} ({', '.join(e.id for e in stepped)}) "
                "act through the friction level Python sets every step; simulate this model with --friction stribeck"
            )
        friction.check_lugre_step(robot.friction, spec.option.timestep, gains.kd)
        friction.add_lugre(spec, robot)
    else:
        friction.add_stribeck(spec, robot)
    _add_effect_forces(spec, robot)
    model = spec.compile()
    drive_ids = np.array([model.actuator(n).id for n in robot.actuator_names])
    drive_ctrl = model.actuator_ctrladr[drive_ids][:, None] + np.arange(len(control.INPUTS))
    lugre_ids = np.array(
        [model.actuator(f"lugre{k + 1}").id for k in range(6)] if friction_model == "lugre" else [], dtype=int
    )
    return SimModel(robot, friction_model, gains, model, drive_ctrl, drive_ids, lugre_ids)


def _add_effect_forces(spec, robot: robots.Robot) -> None:
    """The MuJoCo elements of the robot's effects (:meth:`faultgen.effects.Effect.add_to_simulation`:
    cogging, a torque offset), in place."""
    for effect in robot.effects.values():
        if np.any(effect.active()):
            effect.add_to_simulation(spec, robot)


def _stepped(robot: robots.Robot) -> list:
    """The robot's effects that act through a per-step update of the rotors' dry friction."""
    return [e for e in robot.effects.values() if e.stepped and np.any(e.active())]


@dataclass(frozen=True)
class RunResult:
    """Everything a run recorded. Arrays over recorded cycles come first, then log samples.

    Attributes
    ----------
    config : RunConfig
    t : ndarray of shape (n_log,)
        Log times within a cycle, s (every 4 ms, first sample 4 ms after the start).
    cycles : ndarray of shape (n_cycles,)
        Recorded cycle indices (1-based).
    q_ref : ndarray of shape (n_log, 6)
        Reference arm angles at the log times, rad.
    q_a, q_m : ndarray of shape (n_cycles, n_log, 6)
        Arm and motor angles as the encoders report them, rad (arm side / motor side).
    qd_a, qd_m : ndarray of shape (n_cycles, n_log, 6)
        Arm and motor speeds from the encoders (backward difference), rad/s.
    tau_m : ndarray of shape (n_cycles, n_log, 6)
        Motor torque (drive output), N m at the motor side.
    tau_f : ndarray of shape (n_cycles, n_log, 6)
        True motor-side friction torque, N m, positive when it opposes positive motion.
    tau_dist : ndarray of shape (n_cycles, n_log, 6)
        True load disturbance on the arm joints, N m at the arm side.
    friction_multiplier : ndarray of shape (n_cycles, 6)
        True wear multiplier of Coulomb and static friction per cycle and axis.
    mean_friction_torque : ndarray of shape (n_cycles, 6)
        Mean absolute true friction torque per cycle and axis, N m at the motor side.
    tracking_error : ndarray of shape (n_cycles, 6)
        Largest absolute error of the true arm angle against the reference, rad.
    features : dict of ndarray
        Per-cycle remote-monitoring aggregates (:func:`faultgen.sensors.cycle_features`):
        ``mean_abs_torque``, ``rms_torque``, ``average_speed``, ``average_load_torque``
        (n_cycles, 6) and ``angle_hist``, ``speed_hist``,
        ``torque_hist`` (n_cycles, 6, 12); per recorded cycle (not in daily records) also
        ``torque_counts`` (n_cycles, 6, 1200), :func:`faultgen.sensors.torque_counts`.
    conditions : CycleConditions or None
        The operating conditions of each recorded cycle (None when the run has none).
    fault_value : ndarray of shape (n_cycles,) or None
        The growing fault's parameter at each recorded cycle (None without a fault).
    stepping_time : float
        Wall time spent stepping the physics, s (not part of the recorded data).
    """

    config: RunConfig
    t: np.ndarray
    cycles: np.ndarray
    q_ref: np.ndarray
    q_a: np.ndarray
    q_m: np.ndarray
    qd_a: np.ndarray
    qd_m: np.ndarray
    tau_m: np.ndarray
    tau_f: np.ndarray
    tau_dist: np.ndarray
    friction_multiplier: np.ndarray
    mean_friction_torque: np.ndarray
    tracking_error: np.ndarray
    features: dict[str, np.ndarray] = field(default_factory=dict)
    conditions: CycleConditions | None = None
    fault_value: np.ndarray | None = None
    stepping_time: float = field(default=0.0, compare=False)


def start_state(robot: robots.Robot, q0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``qpos`` and ``qvel`` at rest at arm angles ``q0`` with drives on their set-points.

    The motors sit at ``G q0`` and each gearbox carries the static load: the arm sags by
    ``tau_static / K`` (thesis eq. 6.2a), and with backlash ``b`` it rests on the loaded flank,
    ``b / 2`` further, so a cycle starts in equilibrium. An axis without static load (a vertical
    base axis) starts in the middle of its dead band.
    """
    qpos, qvel = robot.rigid_state(q0)
    zeros = np.zeros((1, 6))
    static = robot.inverse_dynamics(q0[None], zeros, zeros, friction=False)[0]
    # a load at round-off level (gravity on a vertical axis) has no side to rest on
    side = np.sign(static) * (np.abs(static) > 1e-9 * max(float(np.abs(static).max()), 1.0))
    qpos[robot.arm_qpos] = q0 - static / robot.gearbox_stiffness
    offset = robot.arm_offset(side[None])
    if offset is not None:
        qpos[robot.arm_qpos] += offset[0]
    return qpos, qvel


def simulate(config: RunConfig, progress: bool = True) -> RunResult:
    """Run ``config``: simulate its recorded cycles and return what the monitoring recorded.

    With a task mix (:class:`faultgen.operation.conditions.TaskMix`) the cycles of each task are
    simulated together on that task's path, and the per-cycle results are put back in cycle order
    (no signals: cycles of different tasks differ in length).

    Raises
    ------
    SimulationDiverged
        If a cycle's state becomes non-finite or MuJoCo raises a warning; names cycle and axis.
    """
    cycles = config.recorded_cycles
    conditions = config.conditions.evaluate(config.seed, cycles) if config.conditions.active else None
    mix = config.conditions.task_mix
    if mix is None:
        result = _simulate_task(config, config.task, cycles, conditions, progress)
    else:
        task_of = conditions.tasks(mix)
        groups = [np.flatnonzero(task_of == task) for task in dict.fromkeys(task_of)]
        result = _merge_tasks(config, groups, [
            _simulate_task(config, task_of[g[0]], cycles[g], _take(conditions, g), progress) for g in groups])
    return daily_record(result) if config.daily else result


def _simulate_task(config: RunConfig, task_name: str, cycles: np.ndarray, conditions: CycleConditions | None,
                   progress: bool) -> RunResult:
    """The recorded ``cycles`` of ``config`` that run ``task_name``, with their ``conditions``:
    stepped, measured, their per-cycle features (and torque counts unless daily) computed."""
    prepared = _prepared(config.robot, task_name, config.friction)
    sim, task, path, q_ref, inputs = prepared.sim, prepared.task, prepared.path, prepared.q_ref, prepared.inputs
    robot = sim.robot
    per_log = prepared.per_log
    n_steps = len(inputs) - 1

    multiplier = config.wear.multipliers(cycles)
    n_log = n_steps // per_log
    feedforward_arm = inputs[:, :, 2] * robot.gear_ratio
    sigma = config.noise.disturbance * np.mean(np.abs(feedforward_arm), axis=0)
    dist = np.stack([sensors.disturbance(config.seed, int(c), n_log, sigma) for c in cycles])
    plant = _Plant.of(multiplier, conditions, None if config.fault is None else config.fault.values(cycles))

    stepper = _step_lugre if config.friction == "lugre" else _step_stribeck
    with tqdm(total=len(cycles) * n_steps * sim.model.opt.timestep, unit="sim s", disable=not progress,
              desc=f"{robot.name} {task_name}", bar_format="{l_bar}{bar}| {n:.0f}/{total:.0f} sim s "
              "[{elapsed}<{remaining}]") as bar:
        started = time.perf_counter()
        if config.back_to_back:  # one simulation over the cycles' set-points one after the other
            chained = np.concatenate([inputs[:-1]] * len(cycles) + [inputs[-1:]])
            one = stepper(sim, _Work(cycles[:1], plant.take([0]), path.q[0], chained,
                                     dist.reshape(1, -1, dist.shape[-1]), per_log, config.nthread), bar)
            raw = _Raw(**{f.name: getattr(one, f.name).reshape(len(cycles), -1, 6) for f in fields(_Raw)})
        else:  # the cycles of each payload (its own model and feedforward) in batches of BATCH_CYCLES
            parts = conditions.payload_part if conditions is not None else np.full(len(cycles), -1)
            order, raws = [], []
            for part in np.unique(parts):
                carrying = np.flatnonzero(parts == part)
                payload = None if part < 0 else config.conditions.payloads.parameters(int(part))
                variant = prepared if payload is None and config.fault is None else _prepared(
                    config.robot, task_name, config.friction, payload, config.fault)
                for i in range(0, len(carrying), BATCH_CYCLES):
                    g = carrying[i:i + BATCH_CYCLES]
                    fault = None if config.fault is None else (variant.fault_fields, config.fault.final)
                    raws.append(stepper(variant.sim, _Work(cycles[g], plant.take(g), path.q[0], variant.inputs,
                                                           dist[g], per_log, config.nthread, fault), bar))
                    order.append(g)
            back = np.argsort(np.concatenate(order))  # to the order of the cycles
            raw = _Raw(**{f.name: np.concatenate([getattr(r, f.name) for r in raws])[back] for f in fields(_Raw)})
        stepping_time = time.perf_counter() - started
    result = _measure(sim, config, cycles, multiplier, q_ref[per_log::per_log], dist, raw, stepping_time, conditions)
    if plant.fault is not None:
        result = replace(result, fault_value=plant.fault)
    result.features.update(sensors.cycle_features(result.q_a, result.qd_a, result.tau_m, robot.joint_range,
                                                  task.velocity_limit, robot.motor_torque_limit))
    if not config.daily:
        result.features["torque_counts"] = sensors.torque_counts(result.tau_m, robot.motor_torque_limit)
    return result


def _take(conditions: CycleConditions, rows: np.ndarray) -> CycleConditions:
    """The conditions of some cycles (the unit's values are the run's)."""
    return replace(conditions, **{f.name: getattr(conditions, f.name)[rows] for f in fields(conditions)
                                  if f.name not in CycleConditions.PER_UNIT})


def _merge_tasks(config: RunConfig, groups: list[np.ndarray], parts: list[RunResult]) -> RunResult:
    """One run's result from the results of its tasks' cycles (``groups``: their rows in the run's
    recorded cycles): per-cycle arrays in cycle order, no signals, the time base and reference of
    the run's own task."""
    back = np.argsort(np.concatenate(groups))

    def joined(get):
        return np.concatenate([get(r) for r in parts])[back]

    own = _prepared(config.robot, config.task, config.friction)
    n_log = (len(own.inputs) - 1) // own.per_log
    empty = np.zeros((len(back), 0, 6))
    conditions = replace(parts[0].conditions, **{f.name: joined(lambda r, n=f.name: getattr(r.conditions, n))
                                                 for f in fields(CycleConditions)
                                                 if f.name not in CycleConditions.PER_UNIT})
    return RunResult(
        config=config, t=np.arange(1, n_log + 1) * sensors.LOG_PERIOD, cycles=joined(lambda r: r.cycles),
        q_ref=own.q_ref[own.per_log::own.per_log], q_a=empty, q_m=empty, qd_a=empty, qd_m=empty, tau_m=empty,
        tau_f=empty, tau_dist=empty, friction_multiplier=joined(lambda r: r.friction_multiplier),
        mean_friction_torque=joined(lambda r: r.mean_friction_torque),
        tracking_error=joined(lambda r: r.tracking_error),
        features={name: joined(lambda r, n=name: r.features[n]) for name in parts[0].features},
        conditions=conditions,
        fault_value=None if parts[0].fault_value is None else joined(lambda r: r.fault_value),
        stepping_time=sum(r.stepping_time for r in parts))


def daily_record(result: RunResult) -> RunResult:
    """The remote-monitoring record of ``result`` once a day (thesis ch. 5.3.2): of each day's
    ``cycles_per_day`` cycles the largest value of every per-cycle feature and truth (histogram
    bins too, each histogram then scaled back to a sum of 1; the wear and fault of the day's last cycle), the
    operating conditions' mean (temperatures, friction factors) or largest value (payload mass),
    the day's first part and task. ``cycles`` becomes the day number (1-based); no signals are kept.

    Returns
    -------
    RunResult
        With ``(n_days, ...)`` arrays where ``result`` had ``(n_cycles, ...)`` and signals of shape
        ``(n_days, 0, 6)``.
    """
    per_day = result.config.conditions.cycles_per_day
    n_days = len(result.cycles) // per_day

    def days(a, reduce=np.max):
        return reduce(np.asarray(a)[: n_days * per_day].reshape(n_days, per_day, *np.shape(a)[1:]), axis=1)

    features = {name: days(v) for name, v in result.features.items()}
    for name in sensors.HISTOGRAMS:
        features[name] = features[name] / features[name].sum(axis=-1, keepdims=True)
    conditions = result.conditions
    if conditions is not None:
        first = {name: getattr(conditions, name)[::per_day][:n_days] for name in ("day", "payload_part", "task_index")}
        conditions = replace(conditions, **first, payload_mass=days(conditions.payload_mass),
                             **{name: days(getattr(conditions, name), np.mean) for name in
                                ("hour", "ambient_temperature", "joint_temperature", "dry_friction_factor",
                                 "viscous_factor")})
    empty = np.zeros((n_days, 0, 6))
    return replace(result, cycles=np.arange(1, n_days + 1), q_a=empty, q_m=empty, qd_a=empty, qd_m=empty,
                   tau_m=empty, tau_f=empty, tau_dist=empty, friction_multiplier=days(result.friction_multiplier),
                   mean_friction_torque=days(result.mean_friction_torque), tracking_error=days(result.tracking_error),
                   features=features, conditions=conditions,
                   fault_value=None if result.fault_value is None else result.fault_value[per_day - 1::per_day][:n_days])


@dataclass(frozen=True)
class Prepared:
    """What every run of a robot, task and friction model shares (read-only arrays).

    Attributes
    ----------
    sim : SimModel
        The compiled simulation model (``Batch`` works on copies of it).
    task : faultgen.tasks.Task
    path : faultgen.tasks.JointPath
        The task's path sampled at every physics step.
    q_ref : ndarray of shape (n_steps + 1, 6)
        Reference arm angles at every physics step, rad (held at the end to a whole log period).
    inputs : ndarray of shape (n_steps + 1, 6, 3)
        Drive set-points (angle, speed, feedforward) at every physics step, motor side.
    fault_fields : tuple
        For a model with a growing fault: the fields its parameter moves (:func:`_affine_fields`),
        set per simulation from each cycle's value.
    """

    sim: SimModel
    task: tasks.Task
    path: tasks.JointPath
    q_ref: np.ndarray
    inputs: np.ndarray
    fault_fields: tuple = ()

    @property
    def per_log(self) -> int:
        """Physics steps per log period."""
        return int(round(sensors.LOG_PERIOD / self.sim.model.opt.timestep))


@dataclass(frozen=True)
class _Plant:
    """How each simulated cycle's robot differs from the nominal model: multipliers of the dry
    (Coulomb and static: wear, temperature, unit) and the viscous friction (n, 6), of each link's
    mass and inertia (6,), a growing fault's parameter (n,) (None without one), and the unit's
    gearbox loss growing with the load (6,), a load-dependent friction coefficient (zeros: none)."""

    dry: np.ndarray
    viscous: np.ndarray
    link_mass: np.ndarray
    fault: np.ndarray | None = None
    gear_loss: np.ndarray = field(default_factory=lambda: np.zeros(6))

    @classmethod
    def of(cls, wear: np.ndarray, conditions: CycleConditions | None, fault: np.ndarray | None = None) -> _Plant:
        if conditions is None:
            return cls(wear, np.ones_like(wear), np.ones(wear.shape[1]), fault)
        return cls(wear * conditions.dry_friction_factor, conditions.viscous_factor, conditions.link_mass_factor,
                   fault, conditions.gear_loss)

    def take(self, rows) -> _Plant:
        return _Plant(self.dry[rows], self.viscous[rows], self.link_mass,
                      None if self.fault is None else self.fault[rows], self.gear_loss)

    def set_fault(self, batch, fault_fields: tuple, final: float) -> None:
        """Each simulation's fault parameter (:attr:`fault`, per cycle) into the fields it moves."""
        for name, index, at_final, slope in fault_fields:
            values = batch.expand(name)
            flat = values.reshape(values.shape[0], -1)
            flat[:, index] = at_final + (self.fault[:, None] - final) * slope
            values[...] = flat.reshape(values.shape)

    def apply(self, sim: SimModel, batch) -> None:
        """The viscous and link-mass changes as per-simulation model fields of ``batch`` (the dry
        friction is set by each stepper); nothing is expanded where nothing changes."""
        robot, model = sim.robot, sim.model
        if np.any(self.viscous != 1):
            if sim.friction_model == "lugre":
                batch.expand("actuator_damping")[:, sim.lugre_ids] *= self.viscous
            else:
                batch.expand("dof_damping")[:, robot.rotor_dof] *= self.viscous
        if np.any(self.link_mass != 1):
            links = model.jnt_bodyid[[model.joint(n).id for n in robot.joint_names]]
            batch.expand("body_mass")[:, links] *= self.link_mass
            batch.expand("body_inertia")[:, links] *= self.link_mass[:, None]


@dataclass(frozen=True)
class _Work:
    """One batch of simulations stepped together: recorded ``cycles`` (n,), their ``plant`` (wear
    and conditions), the start angles ``q0`` (6,), the drive ``inputs`` at every physics step
    (n_steps + 1, 6, 3), the load disturbance ``dist`` per log period (n, n_log, 6), physics steps
    per log period, MuJoCo threads, and for a fault the fields it moves and its final value."""

    cycles: np.ndarray
    plant: _Plant
    q0: np.ndarray
    inputs: np.ndarray
    dist: np.ndarray
    per_log: int
    nthread: int
    fault: tuple | None = None


def _prepared(robot: str, task: str, friction_model: str, payload: dict | None = None,
              fault: Fault | None = None) -> Prepared:
    """:func:`_prepare`, renewed when the robot's model or task file changes; ``payload``: the
    :class:`faultgen.effects.payload.Payload` parameters of a part the robot carries; ``fault``:
    a growing fault to build into the simulated robot (:func:`_prepare_variant`)."""
    model_file = robots.load(robot).path
    stamps = (model_file.stat().st_mtime_ns, (model_file.parent / "tasks.toml").stat().st_mtime_ns)
    if payload is None and fault is None:
        return _prepare(robot, task, friction_model, *stamps)
    key = None if fault is None else json.dumps(fault.to_dict(), sort_keys=True)
    return _prepare_variant(robot, task, friction_model, None if payload is None else tuple(sorted(payload.items())),
                            key, *stamps)


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
                effect = grown.at(value)
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
    sim = build(robot, friction_model)
    task = tasks.load(robot, task_name)
    path = task.trajectory(sim.model.opt.timestep)
    per_log = int(round(sensors.LOG_PERIOD / sim.model.opt.timestep))
    n_steps = _padded_steps(len(path.t) - 1, per_log)
    q_ref, qd_ref, qdd_ref = (hold_end(a, n_steps) for a in (path.q, path.qd, path.qdd))
    inputs = sim.setpoints(q_ref, qd_ref, qdd_ref)  # (n_steps + 1, 6, 3)
    for array in (q_ref, inputs):
        array.setflags(write=False)
    return Prepared(sim, task, path, q_ref, inputs)


def cycle_duration(robot: str, task: str) -> float:
    """Simulated time of one cycle of ``task`` on ``robot``, s (what a run steps per cycle)."""
    prepared = _prepared(robot, task, "stribeck")  # builds for any model file
    return (len(prepared.inputs) - 1) * prepared.sim.model.opt.timestep


def _padded_steps(n: int, per_log: int) -> int:
    return -(-n // per_log) * per_log


def hold_end(a: np.ndarray, n_steps: int) -> np.ndarray:
    """The first ``n_steps + 1`` samples of a path ``a`` (n, ...), holding its last sample when it
    is shorter (a task's path sampled at every physics step, or at every log period)."""
    if len(a) >= n_steps + 1:
        return a[: n_steps + 1]
    return np.vstack([a, np.repeat(a[-1:], n_steps + 1 - len(a), axis=0)])


@dataclass
class _Raw:
    """True signals at the log times, each ``(n_cycles, n_log, 6)``."""

    q_a: np.ndarray
    q_m: np.ndarray
    qd_a: np.ndarray
    qd_m: np.ndarray
    tau_m: np.ndarray
    tau_f: np.ndarray


def _new_batch(sim: SimModel, work: _Work) -> mjbatch.Batch:
    """One simulation per recorded cycle, all at the task's start state."""
    batch = mjbatch.Batch(sim.model, nsim=len(work.cycles), nthread=work.nthread)
    batch.qpos, batch.qvel = start_state(sim.robot, work.q0)
    batch.act = 0.0
    work.plant.apply(sim, batch)
    if work.fault is not None:
        work.plant.set_fault(batch, *work.fault)
    return batch


def _step_lugre(sim: SimModel, work: _Work, bar) -> _Raw:
    """All physics in MuJoCo: set-points and disturbances handed over one chunk at a time."""
    robot, model = sim.robot, sim.model
    cycles, dry, inputs, dist, per_log = work.cycles, work.plant.dry, work.inputs, work.dist, work.per_log
    viscous = robot.friction.viscous * work.plant.viscous[:, None, :]
    batch = _new_batch(sim, work)
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
    logs = {f.name: np.empty((n_sim, n_steps // per_log, 6)) for f in fields(_Raw)}
    arm_dist = model.nu + robot.arm_dof
    last_qvel = batch.qvel.copy()
    for start in range(0, n_steps, chunk):
        stop = min(start + chunk, n_steps)
        size = stop - start
        control_in[:, :size, : model.nu][:, :, sim.drive_ctrl] = inputs[start:stop]
        control_in[:, :size, arm_dist] = np.repeat(dist[:, start // per_log : stop // per_log], per_log, axis=1)
        out = records if size == chunk else {k: np.empty((n_sim, size, v.shape[2])) for k, v in records.items()}
        batch.rollout(size, control=control_in[:, :size], control_spec=spec, record=tuple(out), out=out)
        _check(sim, batch, cycles, out["qvel"], start)
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
    return _Raw(**logs)


def _step_stribeck(sim: SimModel, work: _Work, bar) -> _Raw:
    """Static friction: the friction-loss level follows the rotor speed before every step."""
    robot, model = sim.robot, sim.model
    cycles, dry, inputs, dist, per_log = work.cycles, work.plant.dry, work.inputs, work.dist, work.per_log
    viscous = robot.friction.viscous * work.plant.viscous
    batch = _new_batch(sim, work)
    frictionloss = batch.expand("dof_frictionloss")
    qvel, qpos = batch.bind("qvel"), batch.bind("qpos")
    ctrl, applied = batch.bind("ctrl"), batch.bind("qfrc_applied")
    force, constraint = batch.bind("actuator_force"), batch.bind("qfrc_constraint")
    n_steps = len(inputs) - 1
    n_log = n_steps // per_log
    logs = {f.name: np.empty((len(cycles), n_log, 6)) for f in fields(_Raw)}
    rotor, arm = robot.rotor_dof, robot.arm_dof
    G = robot.gear_ratio
    dt = model.opt.timestep
    run_start = (cycles[:, None] - 1) * n_steps * dt  # a drift with time runs over the whole run
    # the stepped effects that scale the dry friction and those that add to it, sorted once
    factors = [e for e in _stepped(robot) if type(e).dry_friction_factor is not Effect.dry_friction_factor]
    extras = [e for e in _stepped(robot) if type(e).dry_friction_extra is not Effect.dry_friction_extra]
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
                _check(sim, batch, cycles, logs["qd_m"][:, : j + 1], step)
    return _Raw(**logs)


def _check(sim: SimModel, batch, cycles: np.ndarray, velocities: np.ndarray, step: int) -> None:
    """Raise SimulationDiverged naming the first bad cycle and axis."""
    warned = np.asarray(batch.warning)
    bad = np.flatnonzero(~np.all(np.isfinite(velocities.reshape(len(cycles), -1)), axis=1)
                         | (warned.reshape(len(cycles), -1).sum(axis=1) > 0))
    if bad.size:
        i = int(bad[0])
        v = velocities[i].reshape(-1, velocities.shape[-1])
        finite = np.where(np.isfinite(v), np.abs(v), np.inf)
        axis = int(np.argmax(finite.max(axis=0)) % 6) + 1
        raise SimulationDiverged(
            f"cycle {int(cycles[i])} diverged near t = {step * sim.model.opt.timestep:.3f} s on axis {axis}"
            f" ({sim.robot.name}, {sim.friction_model} friction): the state became non-finite or MuJoCo "
            "warned; check the friction parameters and wear level of that axis"
        )


def _measure(sim, config, cycles, multiplier, q_ref, dist, raw: _Raw, stepping_time: float,
             conditions: CycleConditions | None = None) -> RunResult:
    """Apply the sensors to the true signals and compute the per-cycle truth."""
    n_log = raw.q_a.shape[1]
    t = np.arange(1, n_log + 1) * sensors.LOG_PERIOD
    q_a, q_m, qd_a, qd_m = [], [], [], []
    for i, cycle in enumerate(cycles):
        angles = sensors.encoder(config.seed, int(cycle), np.hstack([raw.q_a[i], raw.q_m[i]]), config.noise.encoder)
        speeds = sensors.speed(angles, np.hstack([raw.qd_a[i, 0], raw.qd_m[i, 0]]))
        q_a.append(angles[:, :6])
        q_m.append(angles[:, 6:])
        qd_a.append(speeds[:, :6])
        qd_m.append(speeds[:, 6:])
    return RunResult(
        config=config,
        t=t,
        cycles=cycles,
        q_ref=q_ref,
        q_a=np.stack(q_a),
        q_m=np.stack(q_m),
        qd_a=np.stack(qd_a),
        qd_m=np.stack(qd_m),
        tau_m=raw.tau_m,
        tau_f=raw.tau_f,
        tau_dist=dist,
        friction_multiplier=multiplier,
        mean_friction_torque=np.mean(np.abs(raw.tau_f), axis=1),
        tracking_error=np.max(np.abs(raw.q_a - q_ref), axis=1),
        conditions=conditions,
        stepping_time=stepping_time,
    )
