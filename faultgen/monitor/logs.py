"""A fleet's measured logs, one at a time, as the monitor reads them: the folder
(:func:`faultgen.data.logfolder.scan`), each log's record by the import's code
(:func:`faultgen.data.fleetlogs.log_record`: the per-cycle features of a simulated fleet's daily
records) and its logged conditions (joint temperature, payload; :mod:`faultgen.data.measured`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from faultgen.data import fleetlogs, logfolder, measured
from faultgen.model.robots import Robot
from faultgen.operation import programs

#: The features the monitor watches, per axis (of :func:`faultgen.simulation.sensors.cycle_features`):
#: the two that follow friction on an axis whose load keeps one sign (gravity), where the mean
#: absolute torque does not (friction adds on the way up what it takes on the way down: KR210 axis
#: 2 at 40 % wear, +0.01 % mean |torque|, +2 % RMS, +4.5 % average load torque). The histograms are
#: left out: a friction change of a few percent moves a 12-bin histogram by less than one bin.
FEATURES = ("rms_torque", "average_load_torque")

Log = logfolder.LogFile


#: A log reader: (path, robot) -> the checked log (:func:`faultgen.data.measured.read`, or an
#: adapter's, :mod:`faultgen.data.adapters`).
Reader = Callable[[Path, Robot], measured.MeasuredData]


def reader_of(adapter=None) -> tuple[Reader, tuple[str, ...]]:
    """The reader and the file suffixes of a log format: the measured format's without ``adapter``,
    else the adapter's (:class:`faultgen.data.adapters.Adapter`, accelerations not estimated: the
    import's reading of the same files)."""
    if adapter is None:
        return measured.read, fleetlogs.SUFFIXES
    return (lambda path, robot: adapter.read(path, robot, accelerations=False)), adapter.suffixes


def fleet(logs_dir: str | Path, suffixes: tuple[str, ...] = fleetlogs.SUFFIXES) -> dict[str, list[Log]]:
    """The units of a fleet folder and each unit's logs (files ending in one of ``suffixes``) in
    stamp order.

    Raises
    ------
    ValueError
        As :func:`faultgen.data.logfolder.scan`, or for a file in a unit folder that is not a log
        (named, with what was expected).
    """
    units, bad = logfolder.scan(Path(logs_dir), suffixes)
    if bad:
        name, reason = bad[0]
        more = f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""
        raise ValueError(f"{Path(logs_dir) / name}: {reason}{more}")
    return {unit: logs for unit, logs in units.items() if logs}


@dataclass(frozen=True)
class Reading:
    """A log's features (``vector``, :data:`FEATURES` by name then axis), mean joint temperature
    (deg C, NaN when not logged), payload (kg, 0 when not logged) and the reader's ``notes``."""

    vector: np.ndarray
    temperature: float
    payload: float
    notes: tuple[str, ...] = ()
    q: np.ndarray | None = None  # (n, N) rad: the log's angles, which tell a program change


def feature_vector(record: dict[str, np.ndarray]) -> np.ndarray:
    """:data:`FEATURES` of one record (each (1, N)) as one vector of ``len(FEATURES) * N``."""
    return np.concatenate([np.ravel(record[name]) for name in FEATURES])


@lru_cache(maxsize=8)
def _speed_limit(robot: Robot) -> np.ndarray:
    return programs.robot_limits(robot)[0]


def features_of(robot: Robot, data: measured.MeasuredData) -> np.ndarray:
    """The feature vector of a measured (or simulated, as arrays) log: the import's record."""
    return feature_vector(fleetlogs.log_record(data, robot, _speed_limit(robot)))


def read(robot: Robot, log: Log, reader: Reader = measured.read) -> Reading:
    """Read and check one log (``reader``: :func:`faultgen.data.measured.read` by default; errors
    name the file and row)."""
    data = reader(log.path, robot)
    temperature = float(np.mean(data.joint_temperature)) if data.joint_temperature is not None else float("nan")
    payload = float(np.max(data.payload_mass)) if data.payload_mass is not None else 0.0
    return Reading(features_of(robot, data), temperature, payload, tuple(data.notes), np.asarray(data.q))
