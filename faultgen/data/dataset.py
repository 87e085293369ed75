"""HDF5 datasets of simulated runs: the public face of the modules that do each job.

This module holds no code. It names, in one place, what the commands, the sweeps, the tests and
users import to work with a dataset file; each name lives in the module of its job, and data
flows one way between them (docs/architecture.md)::

    schema      the format as data: array tables (names, units, axes, dtypes, shapes), run
                attributes, format version, DatasetError
    opening     the one gate every read passes (a finished faultgen file, or DatasetError)
    writer      labels and provenance of a run, atomic write of a run, merge of part files
    validator   every value checked against the schema (`faultgen validate`)
    robot_record  what a run stored of its robot (drivetrain, limits), read by the typed runs
    reader      typed reading (`faultgen.open`) and plain reads (read_run, labels, list_runs)
    summary     `faultgen info`'s text and the tidy features table (`faultgen export`)

The layout of a file is described in :mod:`faultgen.data.schema` and docs/dataset.md.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from faultgen.data import atomic, opening
from faultgen.data.reader import labels, list_runs, read_run, runs_with
from faultgen.data.schema import (
    ARRAYS,
    BINS,
    CONDITION_ARRAYS,
    COUNT_ARRAYS,
    COUNT_AXES,
    DRIVETRAIN,
    DUTY_ARRAYS,
    FAULT_ARRAYS,
    FORMAT,
    FORMAT_VERSION,
    LIMITS,
    MEASURED,
    MEASURED_ARRAYS,
    MEASURED_OPTIONAL,
    PROGRAM_ATTRIBUTE,
    ROBOT_ATTRIBUTES,
    RUN_ATTRIBUTES,
    SHAPES,
    SIGNAL_AXES,
    SIMULATED_TRUTH,
    TEXT_ARRAYS,
    DatasetError,
    kinds,
)
from faultgen.data.summary import EXPORT_SUFFIXES, FEATURE_LABELS, export_features, features, summary
from faultgen.data.validator import saturation_warnings, validate
from faultgen.data.writer import (
    config_key,
    drivetrain,
    estimated_size,
    limits,
    merge,
    model_hash,
    run_attributes,
    write_run,
)

__all__ = [
    "ARRAYS", "BINS", "CONDITION_ARRAYS", "COUNT_ARRAYS", "COUNT_AXES", "DRIVETRAIN", "DUTY_ARRAYS",
    "EXPORT_SUFFIXES", "FAULT_ARRAYS", "FEATURE_LABELS", "FORMAT", "FORMAT_VERSION", "LIMITS", "MEASURED", "MEASURED_ARRAYS",
    "MEASURED_OPTIONAL", "PROGRAM_ATTRIBUTE", "ROBOT_ATTRIBUTES", "RUN_ATTRIBUTES", "SHAPES", "SIGNAL_AXES",
    "SIMULATED_TRUTH", "TEXT_ARRAYS", "DatasetError", "combine", "config_key", "drivetrain", "estimated_size",
    "export_features", "features", "kinds", "labels", "limits", "list_runs", "merge", "model_hash", "read_run",
    "run_attributes", "runs_with", "saturation_warnings", "summary", "validate", "write_run",
]


def combine(files: Iterable[str | Path], path: str | Path, command: str = "") -> Path:
    """Copy every run of ``files`` (complete faultgen datasets, e.g. two sweeps of one grid with
    other seeds) into one new dataset ``path``, atomically, chunks as stored.

    The root attributes are those of the first file, with ``n_runs`` and ``command`` updated
    (``command`` by default names the files). Raises ValueError if a file fails validation (naming
    its first problem) or a run id appears in two files.
    """
    files, path = [Path(f) for f in files], Path(path)
    for source in files:
        problems = validate(source)
        if problems:
            raise ValueError(f"{source} fails validation (run `faultgen validate {source}`): {problems[0]}")
    seen: dict[str, Path] = {}
    for source in files:
        for run_id in list_runs(source):
            if run_id in seen:
                raise ValueError(f"run {run_id!r} is in both {seen[run_id]} and {source}; combine datasets of other seeds")
            seen[run_id] = source
    with atomic.hdf5_writer(path) as out:
        with opening.open_file(files[0]) as first:
            for key, value in first.attrs.items():
                out.attrs[key] = value
        out.attrs["n_runs"] = len(seen)
        out.attrs["command"] = command or "combined from " + ", ".join(f.name for f in files)
        runs = out.create_group("runs")
        for source in files:
            with opening.open_file(source) as src:
                for run_id in src["runs"]:
                    src.copy(src["runs"][run_id], runs, name=run_id)
    return path
