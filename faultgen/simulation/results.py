"""What a run recorded (:class:`RunResult`): the sensors applied to the true signals, the results
of a task mix's tasks put back in cycle order, and the once-a-day remote-monitoring record."""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace

import numpy as np

from faultgen.operation.conditions import CycleConditions
from faultgen.simulation import sensors
from faultgen.simulation.batch import Raw
from faultgen.simulation.config import RunConfig
from faultgen.simulation.prepare import prepared_for
from faultgen.simulation.signals import SIGNALS


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
    q_ref : ndarray of shape (n_log, N)
        Reference arm angles at the log times, rad.
    q_a, q_m : ndarray of shape (n_cycles, n_log, N)
        Arm and motor angles as the encoders report them, rad (arm side / motor side).
    qd_a, qd_m : ndarray of shape (n_cycles, n_log, N)
        Arm and motor speeds from the encoders (backward difference), rad/s.
    tau_m : ndarray of shape (n_cycles, n_log, N)
        Motor torque (drive output), N m at the motor side.
    tau_f : ndarray of shape (n_cycles, n_log, N)
        True motor-side friction torque, N m, positive when it opposes positive motion.
    tau_dist : ndarray of shape (n_cycles, n_log, N)
        True load disturbance on the arm joints, N m at the arm side.
    friction_multiplier : ndarray of shape (n_cycles, N)
        True wear multiplier of Coulomb and static friction per cycle and axis.
    mean_friction_torque : ndarray of shape (n_cycles, N)
        Mean absolute true friction torque per cycle and axis, N m at the motor side.
    tracking_error : ndarray of shape (n_cycles, N)
        Largest absolute error of the true arm angle against the reference, rad.
    features : dict of ndarray
        Per-cycle remote-monitoring aggregates (:func:`faultgen.simulation.sensors.cycle_features`):
        ``mean_abs_torque``, ``rms_torque``, ``average_speed``, ``average_load_torque``
        (n_cycles, N) and ``angle_hist``, ``speed_hist``,
        ``torque_hist`` (n_cycles, N, 12); per recorded cycle (not in daily records) also
        ``torque_counts`` (n_cycles, N, 1200), :func:`faultgen.simulation.sensors.torque_counts`.
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
    #: Axes (1-based) whose drive torque reached its limit (:attr:`Robot.motor_torque_limit`) in some
    #: recorded cycle: the run does not follow its task there (dataset label ``saturated``).
    saturated: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int), compare=False)


def measure(sim, config, cycles, multiplier, q_ref, dist, raw: Raw, stepping_time: float,
             conditions: CycleConditions | None = None) -> RunResult:
    """Apply the sensors to the true signals and compute the per-cycle truth."""
    n_log, n_axes = raw.q_a.shape[1], raw.q_a.shape[2]
    t = np.arange(1, n_log + 1) * sensors.LOG_PERIOD
    q_a, q_m, qd_a, qd_m = [], [], [], []
    for i, cycle in enumerate(cycles):
        angles = sensors.encoder(config.seed, int(cycle), np.hstack([raw.q_a[i], raw.q_m[i]]), config.noise.encoder)
        speeds = sensors.speed(angles, np.hstack([raw.qd_a[i, 0], raw.qd_m[i, 0]]))
        q_a.append(angles[:, :n_axes])
        q_m.append(angles[:, n_axes:])
        qd_a.append(speeds[:, :n_axes])
        qd_m.append(speeds[:, n_axes:])
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


def take(conditions: CycleConditions, rows: np.ndarray) -> CycleConditions:
    """The conditions of some cycles (the unit's values are the run's)."""
    return replace(conditions, **{f.name: getattr(conditions, f.name)[rows] for f in fields(conditions)
                                  if f.name not in CycleConditions.PER_UNIT})


def merge_tasks(config: RunConfig, groups: list[np.ndarray], parts: list[RunResult]) -> RunResult:
    """One run's result from the results of its tasks' cycles (``groups``: their rows in the run's
    recorded cycles): per-cycle arrays in cycle order, no signals, the time base and reference of
    the run's own task."""
    back = np.argsort(np.concatenate(groups))

    def joined(get):
        return np.concatenate([get(r) for r in parts])[back]

    own = prepared_for(config.model, config.task, config.friction)
    n_log = (len(own.inputs) - 1) // own.per_log
    empty = np.zeros((len(back), 0, parts[0].friction_multiplier.shape[1]))
    conditions = replace(parts[0].conditions, **{f.name: joined(lambda r, n=f.name: getattr(r.conditions, n))
                                                 for f in fields(CycleConditions)
                                                 if f.name not in CycleConditions.PER_UNIT})
    return RunResult(
        config=config, t=np.arange(1, n_log + 1) * sensors.LOG_PERIOD, cycles=joined(lambda r: r.cycles),
        q_ref=own.q_ref[own.per_log::own.per_log], **dict.fromkeys(SIGNALS, empty),
        friction_multiplier=joined(lambda r: r.friction_multiplier),
        mean_friction_torque=joined(lambda r: r.mean_friction_torque),
        tracking_error=joined(lambda r: r.tracking_error),
        features={name: joined(lambda r, n=name: r.features[n]) for name in parts[0].features},
        conditions=conditions,
        fault_value=None if parts[0].fault_value is None else joined(lambda r: r.fault_value),
        saturated=np.unique(np.concatenate([r.saturated for r in parts])).astype(int),
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
        ``(n_days, 0, N)``.
    """
    per_day = result.config.conditions.cycles_per_day
    n_days = len(result.cycles) // per_day

    def days(a, reduce=np.max):
        return sensors.by_day(a, per_day, reduce)

    features = sensors.daily_features(result.features, per_day)
    conditions = result.conditions
    if conditions is not None:
        first = {name: getattr(conditions, name)[::per_day][:n_days] for name in ("day", "payload_part", "task_index")}
        conditions = replace(conditions, **first, payload_mass=days(conditions.payload_mass),
                             **{name: days(getattr(conditions, name), np.mean) for name in
                                ("hour", "ambient_temperature", "joint_temperature", "dry_friction_factor",
                                 "viscous_factor")})
    empty = np.zeros((n_days, 0, result.friction_multiplier.shape[1]))
    return replace(result, cycles=np.arange(1, n_days + 1), **dict.fromkeys(SIGNALS, empty),
                   friction_multiplier=days(result.friction_multiplier),
                   mean_friction_torque=days(result.mean_friction_torque), tracking_error=days(result.tracking_error),
                   features=features, conditions=conditions,
                   fault_value=None if result.fault_value is None else result.fault_value[per_day - 1::per_day][:n_days])
