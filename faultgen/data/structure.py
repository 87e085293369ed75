"""A dataset's runs checked from their metadata alone, before any array is read.

A stranger's file can declare an array of (10^10, 6) float64 in a 76 MB file (447 GiB on read),
store text where numbers belong, put a group where an array belongs, leave a run group without its
labels or claim ``cycles = 1e15``. :func:`check_runs` refuses each of these when the file is opened
(:func:`faultgen.data.opening.open_file`), from the declared shapes, types and attributes, so no
command and no ``faultgen.open`` reads such an array or crashes on a missing label. The schema
checks that need the values (units, finiteness, histograms summing to 1) stay with
``faultgen validate``.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from faultgen import axes as axis_numbers
from faultgen import checks, inputs

#: Labels every run group must carry for any command to read it (the reader builds each run from them).
LABELS = ("robot", "task", "friction_model", "cycles", "seed", "worn_axes")
#: Most cycles a run may claim (a cycle a second for 30 years): a larger ``cycles`` attribute is refused.
MAX_CYCLES = 10**9
#: Most log samples per cycle (an hour at 250 Hz, the longest cycle a program may run).
MAX_LOG_SAMPLES = 900_000


def _dims(axes: str, n_cycles: int, n_log: int, n_axes: int | None, bins: dict[str, int]) -> tuple:
    """The expected shape of an array with the named ``axes`` ("cycle, axis, bin"); None: any length."""
    sizes = {"cycle": n_cycles, "sample": n_log, "axis": n_axes, **bins}
    return tuple(sizes[name.strip()] for name in axes.split(","))


def check_runs(f: h5py.File, path: str | Path, schema: dict[str, str], bins: dict[str, int],
               kinds=lambda name: "fiub") -> None:
    """Refuse a dataset whose ``/runs`` holds anything but run groups carrying :data:`LABELS`, a
    ``cycles`` attribute above :data:`MAX_CYCLES` (one that is not a whole number >= 1 is for
    ``faultgen validate`` to report, exit 1), or an array of ``schema`` (name -> axes,
    e.g. "cycle, axis") that is not a numeric dataset of the shape its run's ``cycles`` and ``t``
    arrays and ``n_axes`` attribute imply (``bins``: the lengths of the other axes, e.g. bin -> 12);
    ``kinds(name)``: the NumPy type kinds the array may hold (text for an imported fleet's stamps).

    Raises
    ------
    faultgen.inputs.InputError
        Naming the file, the run, and the attribute or array at fault and what was expected.
    """
    runs = f["runs"]
    if not isinstance(runs, h5py.Group):
        raise inputs.InputError(f"{path}: /runs is a {type(runs).__name__.lower()}; a group of runs is expected")
    for run_id in runs:
        group = runs.get(run_id)
        where = f"{path}: run {run_id!r}"
        if not isinstance(group, h5py.Group):
            raise inputs.InputError(f"{where} is a {type(group).__name__.lower()}; each run is a group")
        missing = [name for name in LABELS if name not in group.attrs]
        if missing:
            raise inputs.InputError(f"{where}: no attribute {missing[0]!r}; every run carries {', '.join(LABELS)}")
        cycles = group.attrs["cycles"]
        if checks.is_number(cycles) and cycles > MAX_CYCLES:  # not a whole number >= 1: validate says so
            raise inputs.InputError(f"{where}: attribute 'cycles' is {np.asarray(cycles).tolist()!r}; a whole "
                                    f"number 1..{MAX_CYCLES} is expected")
        cycles = int(cycles) if checks.is_whole(cycles, 1) else MAX_CYCLES
        n_axes = group.attrs.get("n_axes")
        n_axes = int(n_axes) if checks.is_whole(n_axes, axis_numbers.MIN_AXES) and n_axes <= axis_numbers.MAX_AXES \
            else None
        n_cycles = _length(group, "cycles", path, cycles, "the run's cycles attribute")
        n_log = _length(group, "t", path, MAX_LOG_SAMPLES, "an hour at 250 Hz")
        for name, axes in schema.items():
            if name not in group:
                continue
            shape = _dims(axes, n_cycles, n_log, n_axes, bins)
            ds = inputs.bounded_dataset(group, name, path, shape, kinds=kinds(name))
            if n_axes is None and "axis" in axes:
                found = ds.shape[[a.strip() for a in axes.split(",")].index("axis")]
                if not axis_numbers.MIN_AXES <= found <= axis_numbers.MAX_AXES:
                    raise inputs.InputError(f"{where}: {name} has {found} axes; "
                                            f"{axis_numbers.MIN_AXES}..{axis_numbers.MAX_AXES} are expected")


def _length(group: h5py.Group, name: str, path, most: int, why: str) -> int | None:
    """The declared length of the run's 1-D array ``name`` (at most ``most``), None if it has none."""
    if name not in group:
        return None
    ds = inputs.bounded_dataset(group, name, path, (None,))
    if ds.shape[0] > most:
        raise inputs.InputError(f"{path}: {ds.name} declares {ds.shape[0]} entries; at most {most} are expected "
                                f"({why})")
    return ds.shape[0]
