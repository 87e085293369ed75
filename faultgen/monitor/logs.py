"""A fleet's measured logs, one at a time, as the monitor reads them: the folder layout, each log's
per-cycle features and its operating conditions.

Layout (issue 46): ``LOGS/<unit>/<stamp>.<csv|csv.gz|h5>``, ``<stamp>`` an ISO date or date-time
or a sequence number; the measured format of :mod:`faultgen.data.measured` (``t``, ``q1..qN`` rad,
``tau1..tauN`` N m arm side) with the optional conditions ``temperature1..N`` (deg C, the joints')
and ``payload`` (kg, the part carried, as the program's load data declares it).
"""

from __future__ import annotations

import datetime
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from faultgen.data import measured
from faultgen.model.robots import Robot
from faultgen.operation import programs
from faultgen.simulation import sensors

SUFFIXES = (".csv", ".csv.gz", ".h5", ".hdf5")
#: The features the monitor watches, per axis (the remote-monitoring aggregates of
#: :func:`faultgen.simulation.sensors.cycle_features`; the histograms are left out: a friction
#: change of a few percent moves a 12-bin histogram of |torque| by less than one sample's share).
FEATURES = ("mean_abs_torque", "rms_torque", "average_load_torque")


@dataclass(frozen=True)
class Log:
    """One measured log: ``unit``, ``stamp`` (as in its file name), ``path``."""

    unit: str
    stamp: str
    path: Path


def stamp_of(path: Path) -> str:
    name = path.name
    for suffix in SUFFIXES:
        if name.lower().endswith(suffix):
            return name[: -len(suffix)]
    return path.stem


def _order(stamp: str, path: Path) -> tuple:
    """Sort key of a stamp: a sequence number, else an ISO date or date-time (refused otherwise)."""
    if stamp.isdigit():
        return (0, int(stamp), "")
    try:
        return (1, 0, datetime.datetime.fromisoformat(stamp).isoformat())
    except ValueError:
        raise ValueError(f"{path}: the file name {stamp!r} is not a stamp; expected an ISO date (2026-03-01), "
                         "date-time (2026-03-01T06:00) or a sequence number") from None


def fleet(logs_dir: str | Path) -> dict[str, list[Log]]:
    """The units of a fleet folder (sorted by name) and each unit's logs in stamp order.

    Raises
    ------
    ValueError
        If the folder does not exist, holds no unit folder with a log, or a file name is no stamp.
    """
    root = Path(logs_dir)
    if not root.is_dir():
        raise ValueError(f"{root}: no such folder; expected LOGS/<unit>/<stamp>.csv")
    units: dict[str, list[Log]] = {}
    for folder in sorted(p for p in root.iterdir() if p.is_dir() and not p.name.startswith(".")):
        files = [p for p in folder.iterdir() if p.is_file() and p.name.lower().endswith(SUFFIXES)]
        logs = sorted((Log(folder.name, stamp_of(p), p) for p in files), key=lambda g: _order(g.stamp, g.path))
        if logs:
            units[folder.name] = logs
    if not units:
        raise ValueError(f"{root}: no unit folder with a log; expected LOGS/<unit>/<stamp>.csv "
                         f"(suffixes {', '.join(SUFFIXES)})")
    return units


@dataclass(frozen=True)
class Reading:
    """A log's features (``vector``, per :data:`FEATURES` name then axis), mean joint temperature
    (deg C, NaN when not logged) and payload (kg, 0 when not logged)."""

    vector: np.ndarray
    temperature: float
    payload: float


def feature_vector(features: dict[str, np.ndarray]) -> np.ndarray:
    """:data:`FEATURES` of one cycle (each shape (1, N) or (N,)) as one vector (len(FEATURES) * N)."""
    return np.concatenate([np.ravel(features[name]) for name in FEATURES])


def features_of(robot: Robot, data: measured.MeasuredData) -> dict[str, np.ndarray]:
    """The per-cycle features of a measured log, as a simulated cycle's
    (:func:`faultgen.simulation.sensors.cycle_features` on the log's angles, speeds and the motor
    torque, arm-side torque over the gear ratio)."""
    velocity, _, _ = programs._limits({}, robot, str(robot.path))
    tau_m = np.asarray(data.tau) / robot.gear_ratio
    return sensors.cycle_features(np.asarray(data.q)[None], np.asarray(data.qd)[None], tau_m[None],
                                  robot.joint_range, velocity, robot.motor_torque_limit)


def read(robot: Robot, log: Log) -> Reading:
    """Read and check one log (:func:`faultgen.data.measured.read`) and its conditions."""
    data = measured.read(log.path, robot)
    vector = feature_vector(features_of(robot, data))
    temperature, payload = float("nan"), 0.0
    if log.path.name.lower().endswith((".csv", ".csv.gz")):
        names = [f"temperature{i}" for i in range(1, robot.n_axes + 1)] + ["payload"]
        header = pd.read_csv(log.path, nrows=0).columns
        present = [n for n in names if n in header]
        if present:
            table = pd.read_csv(log.path, usecols=present)
            temps = [n for n in present if n.startswith("temperature")]
            if temps:
                temperature = float(np.nanmean(table[temps].to_numpy()))
            if "payload" in present:
                payload = float(np.nanmean(table["payload"].to_numpy()))
    if not (np.isnan(temperature) or -50 < temperature < 150):
        raise ValueError(f"{log.path}: temperature columns average {temperature:g}; expected deg C in -50..150")
    if not (np.isfinite(payload) and payload >= 0):
        raise ValueError(f"{log.path}: payload {payload!r}; expected a mass >= 0 kg")
    return Reading(vector, temperature, payload)
