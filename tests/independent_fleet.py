"""A "real" fleet's measured logs made by a simulator that is not faultgen (issue 46, item 5): the
generator lives in the package as the sim-to-real track's test split,
:mod:`faultgen.bench.independent` (what is independent and what is ours is said there); this module
adds the robot folder (the KR210 as :func:`pinocchio_log.add_kr210` adds it, or :func:`add_robot`:
rtb-data's KR210 L150 or LBR iiwa 14 R820 with a given rated payload) and the monitor's evaluation
against the truth. Used by ``tests/test_monitor.py``, ``tests/test_monitor_independent.py`` and
``benchmarks/monitor_loop.py``.
"""

from __future__ import annotations

import csv
import warnings
from pathlib import Path

import numpy as np

import pinocchio_log
from faultgen.bench.independent import (  # noqa: F401  (the generator's names, for the tests and benchmarks)
    FleetSpec,
    motor_friction,
    read_changes,
    read_truth,
    stamps,
    unit_names,
    wear_percent,
)
from faultgen.bench import independent
from faultgen.model import importers
from faultgen.model.folder import add as add_folder
from faultgen.operation import taskgen

#: The arms an independent fleet may be made of: rtb-data's URDF and the ROS package its meshes name
#: (the folder two levels above the URDF), and the datasheet's rated payload, kg (KUKA: KR210 L150
#: 150 kg, LBR iiwa 14 R820 14 kg).
ARMS = {
    "kr210": (pinocchio_log.KR210_URDF, "kuka_kr210_support", 150.0),
    "iiwa14": (pinocchio_log.KR210_URDF.parents[2] / "kuka_lbr_iiwa/urdf/lbr_iiwa_14_r820.urdf",
               "kuka_lbr_iiwa_support", 14.0),
}


def add_robot(out: Path, name: str = "kr210", payload: float | None = None) -> Path:
    """``faultgen robots add NAME --from <rtb-data's URDF> --package PKG=<its folder> [--payload KG] -o
    out`` as the library call (the generated tasks, as the command makes them), for ``name`` in
    :data:`ARMS`. Returns the folder."""
    if name not in ARMS:
        raise ValueError(f"arm {name!r}; expected one of {', '.join(ARMS)}")
    urdf, package, _ = ARMS[name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", importers.GeometryDropped)
        add_folder(name, urdf, Path(out), tasks=taskgen.generate, packages={package: urdf.parents[1]},
                   payload=payload)
    return Path(out)


def write_fleet(root: Path, spec: FleetSpec = FleetSpec(), robot: Path | None = None) -> tuple[Path, Path, Path]:
    """Write the fleet under ``root``: ``root/kr210`` (the robot folder, unless ``robot`` is given),
    ``root/logs/<unit>/<stamp>.csv`` and ``root/truth.csv``. Returns (robot folder, logs, truth)."""
    root = Path(root)
    folder = Path(robot) if robot is not None else pinocchio_log.add_kr210(root / "kr210")
    logs, truth = independent.write_fleet(root, spec, folder)
    return folder, logs, truth


def evaluate(truth_path: Path, alarms_path: Path) -> dict[str, dict]:
    """Each unit's outcome from ``truth.csv`` and a monitor's ``alarms.csv``: ``axis`` (worn, 0
    healthy), ``alarm`` (the unit's first first_alarm stamp, closed or open, or ""), ``day`` of the
    alarm (1-based) and ``wear`` at it (%), ``day10`` / ``day40`` (first day with wear >= 10 / 40 %), ``known`` (the stamp the alarm became
    known on, "" before alarms.csv had it) and ``known_wear`` (the true wear then, % or None),
    ``delay`` (alarm day - day10), ``source`` (the alarm's axis or 0), ``in_window`` (10 % <= wear at
    alarm < 40 %); ``alarms``: every alarm row of the unit (closed ones first, as alarms.csv has them,
    rows without an alarm left out)."""
    truth = read_truth(truth_path)
    out = {}
    rows: dict[str, list[dict]] = {}
    with open(alarms_path, newline="") as f:
        for row in csv.DictReader(f):
            if row["first_alarm"]:
                rows.setdefault(row["unit"], []).append(row)
    for unit, t in truth.items():
        row = rows.get(unit, [{}])[0]
        stamp = row.get("first_alarm", "")
        day = t["stamps"].index(stamp) + 1 if stamp else None
        wear = t["wear"]
        day10 = int(np.argmax(wear >= 10)) + 1 if np.any(wear >= 10) else None
        day40 = int(np.argmax(wear >= 40)) + 1 if np.any(wear >= 40) else None
        at = float(wear[day - 1]) if day else None
        known = row.get("known") or ""  # the log the alarm became known on (issue 72; absent before it)
        known_wear = float(wear[t["stamps"].index(known)]) if known else None
        out[unit] = {"axis": t["axis"], "alarm": stamp, "day": day, "wear": at, "day10": day10, "day40": day40,
                     "known": known, "known_wear": known_wear,
                     "delay": (day - day10) if day and day10 else None,
                     "source": int(row["source_axis"]) if row.get("source_axis") else 0,
                     "in_window": at is not None and 10.0 <= at < 40.0, "alarms": rows.get(unit, [])}
    return out
