"""Stepping: one robot repeating one task for many cycles while chosen axes wear.

Only the cycles that are recorded are simulated. Each starts from the task's start state (at
rest, gearboxes deflected by the static load, drives on their set-points) with its own wear
level, so cycles are independent: they are stepped together as the runs of one batch, one per
cycle, with the wear as per-run model fields. A run without wear can instead step its cycles
back to back in one simulation (``back_to_back``), each cycle starting from the state the
previous one ended in, as a robot's own log runs on: the hidden-effect logs of the calibration do
(:mod:`faultgen.calibrate.synth`).

A stepper steps the runs (:mod:`faultgen.simulation.backends`: ``mujoco.batch`` by
default) with the friction model in the MuJoCo model (:mod:`faultgen.simulation.friction_models`:
``lugre`` inside MuJoCo, ``stribeck`` set from Python before every step). This module runs a
configuration; its parts are modules by job: :mod:`~faultgen.simulation.config`
(:class:`RunConfig`), :mod:`~faultgen.simulation.model` (the compiled :class:`SimModel`),
:mod:`~faultgen.simulation.prepare` (what runs of a robot and task share, cached),
:mod:`~faultgen.simulation.batch` (cycles stepped together), :mod:`~faultgen.simulation.results`
(:class:`RunResult`, task mixes, daily records) and :mod:`~faultgen.simulation.signals` (the
signal set). Their public names are importable from here too."""

from __future__ import annotations

import time
from dataclasses import fields, replace

import numpy as np
from tqdm.auto import tqdm

from faultgen.operation import faults
from faultgen.operation.conditions import CycleConditions
from faultgen.simulation import backends, batch, sensors
from faultgen.simulation.batch import CHUNK_PERIODS, Plant, Raw, SimulationDiverged, Work, start_state
from faultgen.simulation.config import RunConfig
from faultgen.simulation.model import SimModel, applied_drive_torque, build
from faultgen.simulation.prepare import Prepared, _prepare, _prepare_variant, cycle_duration, hold_end, prepared_for
from faultgen.simulation.results import RunResult, daily_record, measure, merge_tasks, take
from faultgen.simulation.signals import SIGNALS, TRUE_SIGNALS, TRUTHS

__all__ = ["BATCH_CYCLES", "CHUNK_PERIODS", "Prepared", "RunConfig", "RunResult", "SimModel", "SimulationDiverged",
           "applied_drive_torque", "build", "cycle_duration", "daily_record", "hold_end", "simulate", "start_state"]

#: Most cycles stepped together in one batch: bounds the step buffers (about 1 MB per cycle
#: and second of chunk) when a run records many cycles (the c2 preset records 1200).
BATCH_CYCLES = 100

#: Share of an axis's motor torque limit at which its drive counts as saturated (the drive's
#: control range clips the torque at the limit itself).
SATURATION = 0.999

#: Cycles of a daily-record run (a fleet's robot) stepped and reduced to their days before the next
#: ones are stepped (rounded down to whole days, at least one): bounds a run's memory, whatever its days.
DAILY_BLOCK_CYCLES = 20

#: Earlier private names, for scripts that reach them (benchmarks/setup_time.py clears the cache).
_prepared = prepared_for
_ = _prepare, _prepare_variant


def simulate(config: RunConfig, progress: bool = True, stepper: backends.Stepper | None = None,
             dry_multipliers: np.ndarray | None = None) -> RunResult:
    """Run ``config``: simulate its recorded cycles and return what the monitoring recorded.

    ``stepper`` steps the cycles (a :class:`faultgen.simulation.backends.Stepper`: ``BatchStepper()``,
    MuJoCo's threaded C stepping, the default when None, or ``LoopStepper()``, a plain Python loop of
    ``mj_step`` for checking it); every stepper gives the same results to float tolerance.

    ``dry_multipliers``: ndarray of shape (n_recorded, N), each recorded cycle's multiplier of
    every axis's dry (Coulomb and static) friction, given instead of friction wear (no wear plan,
    no fault on the dry friction): cycles that no wear schedule relates, such as one healthy and one per worn axis
    (:class:`faultgen.monitor.twin.Twin`'s signatures), stepped together as one batch. A cycle's
    result is the same, bit for bit, as the one-cycle run whose wear plan gives that row
    (tests/test_twin_batch.py).

    With a task mix (:class:`faultgen.operation.conditions.TaskMix`) the cycles of each task are
    simulated together on that task's path, and the per-cycle results are put back in cycle order
    (no signals: cycles of different tasks differ in length).

    Raises
    ------
    SimulationDiverged
        If a cycle's state becomes non-finite or MuJoCo raises a warning; names cycle and axis.
    ValueError
        For a run its robot refuses (:meth:`RunConfig.check`), a ``stepper`` that is not a Stepper
        object; ``dry_multipliers`` not of that shape, not finite and positive, beside friction wear
        or with daily records.
    """
    stepper = backends.DEFAULT_STEPPER if stepper is None else backends.checked(stepper)
    if config.resolved is None:  # not from resolve (which checked it): built from a name, or unpickled
        config.check(config.model)
    cycles = config.recorded_cycles
    n_axes = config.model.n_axes
    if dry_multipliers is not None:
        dry_multipliers = _checked_multipliers(config, dry_multipliers, cycles, n_axes)
    conditions = config.conditions.evaluate(config.seed, cycles, n_axes) if config.conditions.active else None
    if not config.daily:
        return _simulate_cycles(config, cycles, conditions, progress, stepper, dry_multipliers)
    # daily records: a block of whole days at a time, each reduced to its days before the next is
    # stepped, so that a run's memory does not grow with its days (cycles are independent: the
    # same arrays as all at once, tests/test_fleet.py)
    size = max(1, DAILY_BLOCK_CYCLES // config.conditions.cycles_per_day) * config.conditions.cycles_per_day
    blocks = [np.arange(i, min(i + size, len(cycles))) for i in range(0, len(cycles), size)]
    return _join_days([daily_record(_simulate_cycles(
        config, cycles[rows], None if conditions is None else take(conditions, rows), progress, stepper))
        for rows in blocks])


def _checked_multipliers(config: RunConfig, values, cycles: np.ndarray, n_axes: int) -> np.ndarray:
    """:func:`simulate`'s ``dry_multipliers`` for the recorded ``cycles``, checked (its Raises)."""
    values = np.asarray(values, dtype=float)
    if values.shape != (len(cycles), n_axes) or not np.all(np.isfinite(values) & (values > 0)):
        raise ValueError(f"dry_multipliers of shape {values.shape}: expected finite numbers > 0 of shape "
                         f"({len(cycles)}, {n_axes}), one row per recorded cycle and a column per axis")
    worn = bool(np.any(faults.dry_multipliers(config.faults, cycles, n_axes) != 1.0))
    if worn or config.daily:
        raise ValueError("dry_multipliers are given instead of a wear plan and without daily records; this run "
                         f"has {'friction wear (a wear plan or a fault)' if worn else 'daily records'}")
    return values


def _simulate_cycles(config: RunConfig, cycles: np.ndarray, conditions: CycleConditions | None,
                     progress: bool, stepper: backends.Stepper = backends.DEFAULT_STEPPER,
                     dry_multipliers: np.ndarray | None = None) -> RunResult:
    """The recorded ``cycles`` of ``config`` with their ``conditions``, every cycle kept (``dry_multipliers``:
    :func:`simulate`'s, checked)."""
    mix = config.conditions.task_mix
    if mix is None:
        return _simulate_task(config, config.task, cycles, conditions, progress, stepper, dry_multipliers)
    task_of = conditions.tasks(mix)
    groups = [np.flatnonzero(task_of == task) for task in dict.fromkeys(task_of)]
    return merge_tasks(config, groups, [
        _simulate_task(config, task_of[g[0]], cycles[g], take(conditions, g), progress, stepper,
                       None if dry_multipliers is None else dry_multipliers[g]) for g in groups])


def _join_days(blocks: list[RunResult]) -> RunResult:
    """One daily record from the daily records of consecutive blocks of whole days."""
    if len(blocks) == 1:
        return blocks[0]
    first = blocks[0]

    def joined(get):
        return np.concatenate([get(block) for block in blocks])

    conditions = first.conditions
    if conditions is not None:
        conditions = replace(conditions, **{f.name: joined(lambda b, n=f.name: getattr(b.conditions, n))
                                            for f in fields(CycleConditions) if f.name not in CycleConditions.PER_UNIT})
    signals = {name: joined(lambda b, n=name: getattr(b, n)) for name in SIGNALS + TRUTHS}
    return replace(first, cycles=np.arange(1, sum(len(b.cycles) for b in blocks) + 1), **signals,
                   features={name: joined(lambda b, n=name: b.features[n]) for name in first.features},
                   conditions=conditions,
                   fault_value=None if first.fault_value is None else joined(lambda b: b.fault_value),
                   saturated=np.unique(joined(lambda b: b.saturated)).astype(int),
                   stepping_time=sum(b.stepping_time for b in blocks))


def _simulate_task(config: RunConfig, task_name: str, cycles: np.ndarray, conditions: CycleConditions | None,
                   progress: bool, stepper: backends.Stepper = backends.DEFAULT_STEPPER,
                   dry_multipliers: np.ndarray | None = None) -> RunResult:
    """The recorded ``cycles`` of ``config`` that run ``task_name``, with their ``conditions``:
    stepped, measured, their per-cycle features (and torque counts unless daily) computed; each
    cycle's dry friction multipliers ``dry_multipliers`` when given, else the wear plan's."""
    payloads = conditions is not None and bool(np.any(conditions.payload_part >= 0))
    # a fault run without payloads steps the faulted model only: no nominal model is compiled for it
    # (its set-points, the disturbance's scale, are the nominal ones: the controller knows no fault)
    # a fault the plant carries (a growing load-dependent friction) is no model variant
    in_model = config.fault if config.fault is not None and not config.fault.in_plant else None
    prepared = prepared_for(config.model, task_name, config.friction,
                            fault=in_model if in_model is not None and not payloads else None)
    sim, task, path, q_ref, inputs = prepared.sim, prepared.task, prepared.path, prepared.q_ref, prepared.inputs
    robot = sim.robot
    per_log = prepared.per_log
    n_steps = len(inputs) - 1

    # friction wear is a fault: the relative faults on the motor friction scale each cycle's dry friction
    multiplier = (faults.dry_multipliers(config.faults, cycles, robot.n_axes) if dry_multipliers is None
                  else dry_multipliers)
    n_log = n_steps // per_log
    feedforward_arm = inputs[:, :, 2] * robot.gear_ratio
    sigma = config.noise.disturbance * np.mean(np.abs(feedforward_arm), axis=0)
    dist = np.stack([sensors.disturbance(config.seed, int(c), n_log, sigma) for c in cycles])
    plant = Plant.of(multiplier, conditions, None if config.fault is None else config.fault.values(cycles))
    if config.fault is not None and config.fault.in_plant:
        plant = plant.with_fault_in_gear_loss(config.fault.axis - 1)

    with tqdm(total=len(cycles) * n_steps * sim.model.opt.timestep, unit="sim s", disable=not progress,
              desc=f"{robot.name} {task_name}", bar_format="{l_bar}{bar}| {n:.0f}/{total:.0f} sim s "
              "[{elapsed}<{remaining}]") as bar:
        started = time.perf_counter()
        if config.back_to_back:  # one simulation over the cycles' set-points one after the other
            chained = np.concatenate([inputs[:-1]] * len(cycles) + [inputs[-1:]])
            if prepared.grips:
                raise ValueError(f"{task_name} grips and releases a payload within the cycle; back_to_back runs "
                                 "do not switch it")
            if not np.array_equal(path.q[0], path.q[-1]):
                raise ValueError(f"{task_name} ends {np.max(np.abs(path.q[-1] - path.q[0])):.4g} rad away from where it "
                                 "starts; back_to_back runs need a cycle that returns to its start")
            one = batch.step(sim, Work(cycles[:1], plant.take([0]), path.q[0], chained,
                                     dist.reshape(1, -1, dist.shape[-1]), per_log, config.nthread,
                                     qd0=path.qd[0], qdd0=path.qdd[0], stepper=stepper), bar)
            raw = Raw(**{name: getattr(one, name).reshape(len(cycles), -1, robot.n_axes) for name in TRUE_SIGNALS})
        else:  # the cycles of each payload (its own model and feedforward) in batches of BATCH_CYCLES
            parts = conditions.payload_part if conditions is not None else np.full(len(cycles), -1)
            order, raws = [], []
            for part in np.unique(parts):
                carrying = np.flatnonzero(parts == part)
                payload = None if part < 0 else config.conditions.payloads.parameters(int(part))
                variant = prepared if payload is None and in_model is None else prepared_for(
                    config.model, task_name, config.friction, payload, in_model)
                for i in range(0, len(carrying), BATCH_CYCLES):
                    g = carrying[i:i + BATCH_CYCLES]
                    fault = None if in_model is None else (variant.fault_fields, in_model.final)
                    raws.append(batch.step(variant.sim, Work(cycles[g], plant.take(g), path.q[0], variant.inputs,
                                                              dist[g], per_log, config.nthread, fault, variant.grips,
                                                              path.qd[0], path.qdd[0], stepper), bar))
                    order.append(g)
            back = np.argsort(np.concatenate(order))  # to the order of the cycles
            raw = Raw(**{name: np.concatenate([getattr(r, name) for r in raws])[back] for name in TRUE_SIGNALS})
        stepping_time = time.perf_counter() - started
    result = measure(sim, config, cycles, multiplier, q_ref[per_log::per_log], dist, raw, stepping_time, conditions)
    if plant.fault is not None:
        result = replace(result, fault_value=plant.fault)
    if result.tau_m.size:
        peak = np.max(np.abs(result.tau_m), axis=(0, 1))
        result = replace(result, saturated=np.flatnonzero(peak >= SATURATION * robot.motor_torque_limit) + 1)
    result.features.update(sensors.cycle_features(result.q_a, result.qd_a, result.tau_m, robot.joint_range,
                                                  task.velocity_limit, robot.motor_torque_limit))
    if not config.daily:
        result.features["torque_counts"] = sensors.torque_counts(result.tau_m, robot.motor_torque_limit)
    return result
