"""The benchmark's files: ``train.h5`` and ``test.h5`` (what a method may read) and ``test_labels.csv``.

Both HDF5 files hold *units* (``/units/<id>``: one robot doing its program), each with attributes
``robot``, ``task`` and ``sample`` (what a record is: "cycle") and one array per observable
quantity of :data:`OBSERVABLES` it has, in the units of faultgen's dataset schema (docs/dataset.md):
what a robot's controller could log. Never the simulated truth (friction, wear, fault parameter).
A train unit also carries its labels: ``fault_level`` (per record, %: the worn axis's friction wear,
or the share of a fault's final change), and attributes ``worn_axis`` (1..N, 0 none) and ``fault``
("none", "friction_wear", or the effect of another fault). A test unit carries none of them; its
labels are in ``test_labels.csv`` (one row per unit and record: unit, cycle, fault_level_pct,
worn_axis, fault), which scoring reads and a method is never given. Test unit ids are in a seeded
random order (``test-000``, ...), so that neither the id nor the order tells the fault.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from faultgen.data import atomic

#: name -> unit of every per-record array a method may read (faultgen's dataset schema): the
#: per-axis features ("record, axis"), the histograms ("record, axis, bin") and, for a run with
#: operating conditions, what a plant logs beside them.
OBSERVABLES = {
    "cycles": "1", "mean_abs_torque": "N m", "rms_torque": "N m", "average_speed": "rad/s",
    "average_load_torque": "N m", "angle_hist": "1", "speed_hist": "1", "torque_hist": "1",
    "day": "d", "hour": "h", "ambient_temperature": "degC", "joint_temperature": "degC", "payload_mass": "kg",
    "task_index": "1",
}
#: The per-axis scalar features a detector sees by default (columns of :meth:`Unit.features`).
FEATURES = ("mean_abs_torque", "rms_torque", "average_speed", "average_load_torque")
FORMAT = "faultgen-bench/1"
LABEL_COLUMNS = ("unit", "cycle", "fault_level_pct", "worn_axis", "fault")


@dataclass
class Unit:
    """One unit of a benchmark file.

    Attributes
    ----------
    id, robot, task, sample : str
    arrays : dict of str to ndarray
        The observables it has (:data:`OBSERVABLES`), first axis the records.
    fault_level : ndarray of shape (n_records,) or None
        % (train units only; None in a test file).
    worn_axis : int or None
        1..N, 0 without a fault; None in a test file.
    fault : str or None
        "none", "friction_wear" or an effect id; None in a test file.
    """

    id: str
    robot: str
    task: str
    sample: str
    arrays: dict[str, np.ndarray]
    fault_level: np.ndarray | None = None
    worn_axis: int | None = None
    fault: str | None = None

    @property
    def n_axes(self) -> int:
        return self.arrays["mean_abs_torque"].shape[1]

    def features(self, names: tuple[str, ...] = FEATURES) -> np.ndarray:
        """Per record, the per-axis features ``names`` side by side: ndarray of shape
        (n_records, len(names) * N), feature-major (all axes of the first feature, then the next)."""
        return np.concatenate([self.arrays[name] for name in names if name in self.arrays], axis=1)


def write(path: Path, units: list[Unit], attrs: dict) -> None:
    """Write ``units`` to the benchmark file ``path`` (atomically), with file attributes ``attrs``."""
    with atomic.hdf5_writer(path) as f:
        f.attrs["format"] = FORMAT
        for key, value in attrs.items():
            f.attrs[key] = value
        group = f.create_group("units")
        for unit in units:
            g = group.create_group(unit.id)
            g.attrs.update(robot=unit.robot, task=unit.task, sample=unit.sample)
            for name, values in unit.arrays.items():
                g.create_dataset(name, data=values)
                g[name].attrs["units"] = OBSERVABLES[name]
            if unit.fault_level is not None:
                g.create_dataset("fault_level", data=unit.fault_level)
                g["fault_level"].attrs["units"] = "%"
                g.attrs.update(worn_axis=int(unit.worn_axis), fault=str(unit.fault))


def read(path: str | Path) -> list[Unit]:
    """The units of a benchmark file, in file order (labels only in a train file).

    Raises
    ------
    ValueError
        If ``path`` does not exist or is not a benchmark file (naming it and what was expected).
    """
    import h5py

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path} does not exist; make it with `faultgen bench make TRACK -o {path.parent}`")
    try:
        f = h5py.File(path, "r")
    except OSError:
        raise ValueError(f"{path} is not an HDF5 file; expected a benchmark file of `faultgen bench make`") from None
    with f:
        if f.attrs.get("format") != FORMAT:
            raise ValueError(f"{path} is not a benchmark file (format {f.attrs.get('format')!r}, expected {FORMAT!r})")
        units = []
        for uid in f["units"]:
            g = f["units"][uid]
            arrays = {name: g[name][()] for name in OBSERVABLES if name in g}
            labelled = "fault_level" in g
            units.append(Unit(id=uid, robot=str(g.attrs["robot"]), task=str(g.attrs["task"]),
                              sample=str(g.attrs["sample"]), arrays=arrays,
                              fault_level=g["fault_level"][()] if labelled else None,
                              worn_axis=int(g.attrs["worn_axis"]) if labelled else None,
                              fault=str(g.attrs["fault"]) if labelled else None))
    return units


def write_labels(path: Path, units: list[Unit]) -> None:
    """``test_labels.csv``: one row per unit and record (:data:`LABEL_COLUMNS`), atomically."""
    rows = [",".join(LABEL_COLUMNS)]
    for unit in units:
        for cycle, level in zip(unit.arrays["cycles"], unit.fault_level):
            rows.append(f"{unit.id},{int(cycle)},{float(level)!r},{unit.worn_axis},{unit.fault}")
    atomic.write_text(path, "\n".join(rows) + "\n")


def attach_labels(units: list[Unit], path: str | Path) -> list[Unit]:
    """``units`` of a test file with their labels from ``test_labels.csv`` (scoring only).

    Raises
    ------
    ValueError
        If the file is missing, a unit has no rows, or its cycles differ from the unit's (naming them).
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path} does not exist: the test labels are written by `faultgen bench make`")
    rows: dict[str, list] = {}
    with path.open(newline="") as f:
        reader = csv.DictReader(f)
        if tuple(reader.fieldnames or ()) != LABEL_COLUMNS:
            raise ValueError(f"{path}: columns {reader.fieldnames}, expected {', '.join(LABEL_COLUMNS)}")
        for line, row in enumerate(reader, start=2):
            try:
                rows.setdefault(row["unit"], []).append((int(row["cycle"]), float(row["fault_level_pct"]),
                                                         int(row["worn_axis"]), row["fault"]))
            except ValueError:
                raise ValueError(f"{path}, row {line}: {row}: expected a whole cycle, a number and a whole axis") from None
    out = []
    for unit in units:
        got = rows.get(unit.id)
        if not got or [c for c, *_ in got] != [int(c) for c in unit.arrays["cycles"]]:
            raise ValueError(f"{path}: the labels of unit {unit.id} do not match its records in the test file")
        out.append(Unit(id=unit.id, robot=unit.robot, task=unit.task, sample=unit.sample, arrays=unit.arrays,
                        fault_level=np.array([level for _, level, *_ in got]), worn_axis=got[0][2], fault=got[0][3]))
    return out
