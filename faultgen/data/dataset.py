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
    "SIMULATED_TRUTH", "TEXT_ARRAYS", "DatasetError", "config_key", "drivetrain", "estimated_size",
    "export_features", "features", "kinds", "labels", "limits", "list_runs", "merge", "model_hash", "read_run",
    "run_attributes", "runs_with", "saturation_warnings", "summary", "validate", "write_run",
]
