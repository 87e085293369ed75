"""A folder of synthetic measured logs of a small fleet, for the import's tests and benchmark:
LOGS/<unit>/<stamp>.csv, each log a few cycles of a sinusoidal motion within the joint range, its
arm-side torque gravity-like plus Coulomb and viscous friction, one unit's axis wearing (its
Coulomb friction growing) from a given day. Not a simulation: a layout and signals the reader takes."""

from __future__ import annotations

from datetime import date, timedelta  # noqa: F401 (date: the tests start fleets on other days)
from pathlib import Path

import h5py
import numpy as np
import pandas as pd

from faultgen.logs import measured
from faultgen.data import logfiles

RATE = 250.0  # Hz


def log_signals(robot, day: int, seed: int, wear: np.ndarray, cycles: int = 2, cycle_time: float = 1.5,
                model: bool = False):
    """(t, q, qd, tau, cycle) of one log: ``cycles`` cycles of ``cycle_time`` s; ``wear`` (N,) the
    relative Coulomb friction increase of each axis. ``model``: the torque the robot's rigid model
    needs along the motion (its inverse dynamics) in place of the gravity-like term, a log the
    calibration's plausibility check takes as the robot's (the monitor's twin refuses any other
    since issue 88)."""
    rng = np.random.default_rng([seed, day])
    n = int(cycles * cycle_time * RATE)
    t = np.arange(n) / RATE
    low, high = robot.joint_range.T
    middle, half = (low + high) / 2, 0.3 * (high - low) / 2
    phase = np.arange(robot.n_axes)
    w = 2 * np.pi / cycle_time
    q = middle + half * np.sin(w * t[:, None] + phase)
    qd = half * w * np.cos(w * t[:, None] + phase)
    limit = robot.gear_ratio * robot.motor_torque_limit
    coulomb = 0.05 * limit * (1 + wear)
    if model:
        qdd = -half * w**2 * np.sin(w * t[:, None] + phase)
        rigid = robot.inverse_dynamics(q, qd, qdd, friction=False)
    else:
        rigid = 0.2 * limit * np.cos(q)
    tau = rigid + coulomb * np.tanh(qd / 0.05) + 0.02 * limit * qd
    tau = tau + 0.002 * limit * rng.standard_normal(tau.shape)
    cycle = (t // cycle_time).astype(int) + 1
    return t, q, qd, tau, cycle


def write_log(path: Path, robot, day: int, seed: int, wear: np.ndarray, **kw) -> Path:
    """One log at ``path`` (.csv, .csv.gz or .h5) with a ``cycle`` column."""
    t, q, qd, tau, cycle = log_signals(robot, day, seed, wear, **kw)
    if path.name.endswith((".h5", ".hdf5")):
        logfiles.write_hdf5(path, t, q, tau, qd)
        with h5py.File(path, "a") as fh:
            fh["cycle"] = cycle
        return path
    q_names, qd_names, tau_names = measured.column_names(robot.n_axes)
    frame = pd.DataFrame({"t": t, **dict(zip(q_names, q.T)), **dict(zip(qd_names, qd.T)),
                          **dict(zip(tau_names, tau.T)), "cycle": cycle})
    frame.to_csv(path, index=False, compression="gzip" if path.name.endswith(".gz") else None)
    return path


def write_fleet(folder: Path, robot, units: int = 3, days: int = 12, worn: dict | None = None,
                start: date = date(2026, 3, 1), suffix: str = ".csv", model: bool = False) -> Path:
    """``units`` units x ``days`` daily logs under ``folder``; ``worn`` maps a unit index to
    (axis 1..N, onset day index, wear per day); units are named ``u1``, ``u2``, ...; ``model``: the
    torque of the robot's model (:func:`log_signals`), for the twin."""
    worn = worn or {}
    for u in range(units):
        unit = folder / f"u{u + 1}"
        unit.mkdir(parents=True, exist_ok=True)
        for d in range(days):
            wear = np.zeros(robot.n_axes)
            if u in worn:
                axis, onset, rate = worn[u]
                wear[axis - 1] = max(0.0, d - onset) * rate
            write_log(unit / f"{(start + timedelta(days=d)).isoformat()}{suffix}", robot, d, u, wear, model=model)
    return folder
