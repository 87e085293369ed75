"""A "real" fleet's measured logs made by a simulator that is not faultgen (issue 46, item 5): the
generator lives in the package as the sim-to-real track's test split,
:mod:`faultgen.bench.independent` (what is independent and what is ours is said there); this module
adds the KR210 robot folder (:func:`pinocchio_log.add_kr210`) and the monitor's evaluation against the
truth. Used by ``tests/test_monitor.py`` and ``benchmarks/monitor_loop.py``.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

import pinocchio_log
from faultgen.bench.independent import (  # noqa: F401  (the generator's names, for the tests and benchmarks)
    FleetSpec,
    motor_friction,
    read_truth,
    stamps,
    unit_names,
    wear_percent,
)
from faultgen.bench import independent


def write_fleet(root: Path, spec: FleetSpec = FleetSpec(), robot: Path | None = None) -> tuple[Path, Path, Path]:
    """Write the fleet under ``root``: ``root/kr210`` (the robot folder, unless ``robot`` is given),
    ``root/logs/<unit>/<stamp>.csv`` and ``root/truth.csv``. Returns (robot folder, logs, truth)."""
    root = Path(root)
    folder = Path(robot) if robot is not None else pinocchio_log.add_kr210(root / "kr210")
    logs, truth = independent.write_fleet(root, spec, folder)
    return folder, logs, truth


def evaluate(truth_path: Path, alarms_path: Path) -> dict[str, dict]:
    """Each unit's outcome from ``truth.csv`` and a monitor's ``alarms.csv``: ``axis`` (worn, 0
    healthy), ``alarm`` (first_alarm stamp or ""), ``day`` of the alarm (1-based) and ``wear`` at it
    (%), ``day10`` / ``day40`` (first day with wear >= 10 / 40 %), ``delay`` (alarm day - day10),
    ``source`` (the alarm's axis or 0), ``in_window`` (10 % <= wear at alarm < 40 %)."""
    truth = read_truth(truth_path)
    out = {}
    with open(alarms_path, newline="") as f:
        alarms = {row["unit"]: row for row in csv.DictReader(f)}
    for unit, t in truth.items():
        row = alarms.get(unit, {})
        stamp = row.get("first_alarm", "")
        day = t["stamps"].index(stamp) + 1 if stamp else None
        wear = t["wear"]
        day10 = int(np.argmax(wear >= 10)) + 1 if np.any(wear >= 10) else None
        day40 = int(np.argmax(wear >= 40)) + 1 if np.any(wear >= 40) else None
        at = float(wear[day - 1]) if day else None
        out[unit] = {"axis": t["axis"], "alarm": stamp, "day": day, "wear": at, "day10": day10, "day40": day40,
                     "delay": (day - day10) if day and day10 else None,
                     "source": int(row["source_axis"]) if row.get("source_axis") else 0,
                     "in_window": at is not None and 10.0 <= at < 40.0}
    return out
