"""Checking a dataset against its schema (``faultgen validate``): every attribute parsed into its
type and range, every array read (so corrupted chunks surface) and checked for units, shape,
finiteness and its own rules (histograms summing to 1, counts counting the samples, ...).

:func:`attribute_problems` is the part every reader runs at opening (a run's labels must parse
before a typed run is built from them); :func:`validate` runs all of it.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import h5py
import numpy as np

from faultgen import axes as axis_numbers
from faultgen import inputs
from faultgen.data.opening import attr, open_file
from faultgen.data.schema import (
    ARRAYS,
    CONDITION_ARRAYS,
    COUNT_ARRAYS,
    COUNT_AXES,
    DRIVETRAIN,
    DUTY_ARRAYS,
    FAULT_ARRAYS,
    FORMAT_VERSION,
    FRICTION_TEST,
    LIMITS,
    MEASURED,
    MEASURED_ARRAYS,
    MEASURED_OPTIONAL,
    PROGRAM_ATTRIBUTE,
    RECORD_ATTRIBUTE,
    RUN_ATTRIBUTES,
    SIGNAL_AXES,
    SIMULATED_TRUTH,
    DatasetError,
    condition_arrays,
    kinds,
)
from faultgen.effects.friction import FIELDS as FRICTION_FIELDS
from faultgen.simulation import sensors


def validate(path: str | Path) -> list[str]:
    """Check a file against the schema; return the problems found (an empty list: valid).

    Opens every array (so corrupted chunks surface), and checks units, shapes, finiteness, that
    histograms sum to 1, that recorded cycles lie in 1..cycles, and that the run count matches.
    """
    problems: list[str] = []
    try:
        with open_file(path) as f:
            runs = f["runs"]
            if f.attrs.get("format_version") != FORMAT_VERSION:
                problems.append(f"format_version {f.attrs.get('format_version')!r}, expected {FORMAT_VERSION}")
            if f.attrs.get("n_runs") != len(runs):
                problems.append(f"n_runs attribute {f.attrs.get('n_runs')!r} but {len(runs)} run groups")
            if len(runs) == 0:
                problems.append("no runs")
            for run_id in runs:
                problems += [f"run {run_id}: {p}" for p in _validate_run(runs[run_id])]
    except DatasetError as err:
        return [str(err)]
    except (OSError, RuntimeError, KeyError) as err:
        problems.append(f"cannot read {path}: {err} (corrupted file?)")
    return problems


def saturation_warnings(path: str | Path) -> list[str]:
    """The runs whose motors reached their torque limit (label ``saturated``), one line each.

    The file is valid, and a fleet's hardest moves may touch a limit for a moment; but where a drive
    is at its limit the run does not follow its task (a wear or fault beyond what the drive can
    carry), so ``faultgen validate`` and ``info`` name them.

    Raises
    ------
    DatasetError
        If ``path`` is not a faultgen dataset.
    """
    out = []
    with open_file(path) as f:
        for run_id, group in f["runs"].items():
            axes = [int(a) for a in np.atleast_1d(group.attrs.get("saturated", []))]
            if axes:
                out.append(f"run {run_id}: axes {', '.join(map(str, axes))}: the motor saturated (the drive torque "
                           "reached its limit): the run does not follow its task there")
    return out


def attribute_problems(group: h5py.Group) -> list[str]:
    """What is wrong with the attributes of a run group: each present attribute must parse into
    its type and range (a whole number of cycles >= 1, worn axes as axis numbers, JSON tables, a
    known friction model, a positive log period, ...); the missing ones are listed by
    :func:`_validate_run`."""
    from faultgen.effects import friction

    problems = []
    attrs = {key: attr(group.attrs[key]) for key in group.attrs}

    def whole(value) -> bool:
        return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))

    checks = {
        "robot": (lambda v: isinstance(v, str) and bool(v), "a robot name"),
        "task": (lambda v: isinstance(v, str) and bool(v), "a task name"),
        "friction_model": (lambda v: v in friction.MODELS or (v == MEASURED and attrs.get("source") == MEASURED),
                           f"one of {', '.join(friction.MODELS)}"),
        "cycles": (lambda v: whole(v) and v >= 1, "a whole number >= 1"),
        "seed": (lambda v: whole(v) and v >= 0, "a whole number >= 0"),
        "worn_axes": (lambda v: isinstance(v, np.ndarray) and v.ndim == 1 and v.dtype.kind in "iu"
                      and bool(np.all(v >= 1)), "a list of axis numbers"),  # within the run's N: _validate_run
        "log_period": (lambda v: isinstance(v, (float, np.floating)) and np.isfinite(v) and v > 0,
                       "a positive number of seconds"),
        "signals": (lambda v: isinstance(v, (bool, np.bool_)), "true or false"),
        "sample": (lambda v: v in ("cycle", "day", "log"), "'cycle', 'day' or 'log'"),
        PROGRAM_ATTRIBUTE: (lambda v: isinstance(v, str) and len(v) == 64
                            and all(c in "0123456789abcdef" for c in v), "64 hex digits (a SHA-256)"),
        "source": (lambda v: v == MEASURED, f"{MEASURED!r} (absent for a simulated run)"),
        RECORD_ATTRIBUTE: (lambda v: v == FRICTION_TEST, f"{FRICTION_TEST!r} (absent for production records)"),
        "saturated": (lambda v: isinstance(v, np.ndarray) and v.ndim == 1 and v.dtype.kind in "iu",
                      "a list of axes"),
    }
    for key, (ok, expected) in checks.items():
        if key in attrs:
            try:
                good = bool(ok(attrs[key]))
            except (TypeError, ValueError):
                good = False
            if not good:
                value = attrs[key]
                shown = value.tolist() if isinstance(value, (np.ndarray, np.generic)) else value
                problems.append(f"attribute {key!r} is {shown!r}, expected {expected}")
    if "n_axes" in attrs and not _axis_count(attrs["n_axes"]):  # every reader sizes its arrays with it
        problems.append(f"n_axes attribute {attrs['n_axes']}, expected a whole number "
                        f"{axis_numbers.MIN_AXES}..{axis_numbers.MAX_AXES}")
    for key in ("wear", "noise", "config", "conditions", "fault", "limits"):
        if key in attrs:
            try:
                table = json.loads(attrs[key])
            except (TypeError, ValueError):
                problems.append(f"attribute {key!r} is not JSON: {str(attrs[key])[:40]!r}")
                continue
            if not isinstance(table, dict):
                problems.append(f"attribute {key!r} is {str(attrs[key])[:40]!r}, expected a JSON table")
    return problems


def _axis_count(value) -> bool:
    """Whether an ``n_axes`` attribute is a whole number of axes MIN_AXES..MAX_AXES."""
    return bool(np.ndim(value) == 0 and np.issubdtype(np.asarray(value).dtype, np.integer)
                and axis_numbers.MIN_AXES <= int(value) <= axis_numbers.MAX_AXES)


def _program_problems(attrs) -> list[str]:
    """A run of a program file or replayed log (attribute ``program``: JSON name, file, sha256; a
    program's text in ``program_text``): the JSON reads, and the stored text is the one hashed."""
    if "program" not in attrs:
        return ["program_text without a program attribute"] if "program_text" in attrs else []
    try:
        program = json.loads(attr(attrs["program"]))
        digest = program["sha256"]
    except (ValueError, KeyError, TypeError):
        return ["program attribute is not JSON with a sha256"]
    if PROGRAM_ATTRIBUTE in attrs and attr(attrs[PROGRAM_ATTRIBUTE]) != digest:
        return [f"{PROGRAM_ATTRIBUTE} {str(attr(attrs[PROGRAM_ATTRIBUTE]))[:12]}... is not the program's sha256 "
                f"{digest[:12]}..."]
    if "program_text" in attrs:
        text = attr(attrs["program_text"])
        if hashlib.sha256(text.encode()).hexdigest() != digest:
            return [f"program_text does not hash to the program's sha256 {digest[:12]}..."]
    return []


def _validate_run(group: h5py.Group) -> list[str]:
    problems = [f"missing attribute {a!r}" for a in RUN_ATTRIBUTES if a not in group.attrs]
    problems += attribute_problems(group)
    try:
        conditions = json.loads(attr(group.attrs["conditions"])) if "conditions" in group.attrs else None
    except ValueError:
        return [*problems, "conditions attribute is not JSON"]
    problems += _program_problems(group.attrs)
    if problems:
        return problems
    signals = bool(group.attrs.get("signals", True))
    schema = {**{name: value for name, value in ARRAYS.items() if signals or value[1] != SIGNAL_AXES},
              **{name: CONDITION_ARRAYS[name][:3] for name in condition_arrays(conditions)}}
    if "fault" in group.attrs:
        schema.update(FAULT_ARRAYS)
    schema.update({name: spec for name, spec in {**DUTY_ARRAYS, **COUNT_ARRAYS}.items() if name in group})
    if attr(group.attrs.get("source")) == MEASURED:
        for name in SIMULATED_TRUTH:
            del schema[name]
        schema.update({name: spec for name, spec in MEASURED_ARRAYS.items()
                       if name not in MEASURED_OPTIONAL or name in group})
    if sum(name in group for name in DUTY_ARRAYS) == 1:
        problems.append(f"has one of the duty arrays {', '.join(DUTY_ARRAYS)} but not the other")
    missing = [name for name in schema if name not in group]
    problems += [f"missing array {name!r}" for name in missing]
    if missing:
        return problems
    data = {}
    for name, (units, axes, _) in schema.items():
        ds = group[name]
        if attr(ds.attrs.get("units")) != units or attr(ds.attrs.get("axes")) != axes:
            problems.append(f"{name}: units/axes attributes {ds.attrs.get('units')!r}/{ds.attrs.get('axes')!r}, "
                            f"expected {units!r}/{axes!r}")
        try:
            data[name] = inputs.bounded_dataset(group, name, group.file.filename, kinds=kinds(name))[()]
        except (OSError, RuntimeError) as err:
            problems.append(f"{name}: cannot be read ({err}); the file is corrupted")
            return problems
        if data[name].dtype.kind in "fiu" and not np.all(np.isfinite(data[name])):
            problems.append(f"{name}: holds non-finite values")
    n_cycles, n_log = len(data["cycles"]), len(data["t"])
    n_axes, robot_problems = _robot_attributes(group, data)
    if robot_problems:
        return [*problems, *robot_problems]
    for name, (_, axes, _) in schema.items():
        expected = {SIGNAL_AXES: (n_cycles, n_log, n_axes), "cycle, axis": (n_cycles, n_axes),
                    "cycle, axis, bin": (n_cycles, n_axes, sensors.HISTOGRAM_BINS), "sample, axis": (n_log, n_axes),
                    COUNT_AXES: (n_cycles, n_axes, sensors.TORQUE_COUNT_BINS),
                    "sample": (n_log,), "cycle": (n_cycles,), "axis": (n_axes,)}[axes]
        if data[name].shape != expected:
            problems.append(f"{name}: shape {data[name].shape}, expected {expected}")
    if problems:
        return problems
    cycles = int(group.attrs["cycles"])
    if np.any(data["cycles"] < 1) or np.any(data["cycles"] > cycles) or np.any(np.diff(data["cycles"]) <= 0):
        problems.append(f"cycles must increase within 1..{cycles}")
    for name in ("angle_hist", "speed_hist", "torque_hist"):
        if not np.allclose(data[name].sum(axis=-1), 1.0):
            problems.append(f"{name}: a histogram does not sum to 1")
    mix = (conditions or {}).get("task_mix")
    if mix is not None and np.any((data["task_index"] < 0) | (data["task_index"] >= len(mix["tasks"]))):
        return [*problems, f"task_index: outside 0..{len(mix['tasks']) - 1} (the task mix's tasks)"]
    for name in COUNT_ARRAYS:
        if name in data and (data[name].dtype.kind != "u" or not _counts_fit(data[name].sum(axis=-1), n_log, data,
                                                                            conditions, attr(group.attrs.get("task")))):
            problems.append(f"{name}: not counts of the {n_log} samples of each cycle")
    if "label" in data and not np.all(np.isin(data["label"], (-1, 0, 1))):
        problems.append("label: not -1 (unknown), 0 (healthy) or 1 (worn)")
    if "stamp_key" in data and np.any(np.diff(data["stamp_key"]) <= 0):
        problems.append("stamp_key: the logs are not in increasing stamp order")
    for name in ("friction_multiplier", "dry_friction_factor", "viscous_factor", "link_mass_factor"):
        if name in data and np.any(data[name] <= 0):
            problems.append(f"{name}: not positive")
    for name in (*DUTY_ARRAYS, "gear_loss"):
        if name in data and np.any(data[name] < 0):
            problems.append(f"{name}: negative")
    return problems


def _robot_attributes(group: h5py.Group, data: dict) -> tuple[int, list[str]]:
    """The run's number of axes N and what is wrong with its :data:`ROBOT_ATTRIBUTES` and worn axes.

    N is the ``n_axes`` attribute (5..7); a run written before it existed has the axes of its
    ``friction_multiplier`` (six, the only robots then). ``drivetrain``, when present, must be JSON
    with every :data:`DRIVETRAIN` entry and friction parameter a list of N finite numbers; ``limits``,
    when present, the limits of N axes (:func:`limits_problems`).
    """
    problems = []
    if "n_axes" in group.attrs:
        n_axes = group.attrs["n_axes"]
        if not _axis_count(n_axes):
            return 0, [f"n_axes attribute {n_axes}, expected a whole number "
                       f"{axis_numbers.MIN_AXES}..{axis_numbers.MAX_AXES}"]
        n_axes = int(n_axes)
    else:
        shape = np.shape(data["friction_multiplier"])
        n_axes = shape[1] if len(shape) == 2 else 0
    worn = [int(a) for a in np.atleast_1d(group.attrs.get("worn_axes", []))]
    bad = [a for a in worn if not 1 <= a <= n_axes]
    if bad:
        problems.append(f"worn_axes: axis {bad[0]} is out of range 1..{n_axes}")
    if "drivetrain" in group.attrs:
        try:
            table = json.loads(attr(group.attrs["drivetrain"]))
            entries = {**{name: table[name] for name in DRIVETRAIN},
                       **{f"friction.{name}": table["friction"][name] for name in FRICTION_FIELDS}}
        except (ValueError, KeyError, TypeError) as err:
            return n_axes, [*problems, f"drivetrain attribute is not the drivetrain JSON (missing or bad {err})"]
        for name, values in entries.items():
            ok = isinstance(values, list) and len(values) == n_axes and all(
                isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) for x in values)
            if not ok:
                problems.append(f"drivetrain {name}: expected {n_axes} finite numbers, got {values!r}")
                break
    elif "n_axes" in group.attrs:
        problems.append("has the n_axes attribute but not drivetrain")
    if "limits" in group.attrs:
        problems += limits_problems(attr(group.attrs["limits"]), n_axes)
    return n_axes, problems


def limits_problems(text, n_axes: int) -> list[str]:
    """What is wrong with a run's ``limits`` attribute (:data:`LIMITS`, JSON) for a robot of
    ``n_axes`` axes: ``joint_range`` must be N pairs of finite numbers, low below high, ``velocity``
    and ``task_velocity`` N finite positive numbers (rad, rad/s); [] when it is right."""
    try:
        table = json.loads(text)
        entries = {name: table[name] for name in LIMITS}
    except (ValueError, KeyError, TypeError) as err:
        return [f"limits attribute is not the limits JSON (missing or bad {err})"]

    def numbers(values, size) -> bool:
        return isinstance(values, list) and len(values) == size and all(
            isinstance(x, (int, float)) and not isinstance(x, bool) and np.isfinite(x) for x in values)

    pairs = entries["joint_range"]
    if not (isinstance(pairs, list) and len(pairs) == n_axes and all(numbers(p, 2) and p[0] < p[1] for p in pairs)):
        return [f"limits joint_range: expected {n_axes} pairs of finite numbers, low below high, got {pairs!r}"]
    for name in ("velocity", "task_velocity"):
        if not (numbers(entries[name], n_axes) and all(v > 0 for v in entries[name])):
            return [f"limits {name}: expected {n_axes} finite positive numbers, got {entries[name]!r}"]
    return []


def _counts_fit(totals: np.ndarray, n_log: int, data: dict, conditions: dict | None, task: str) -> bool:
    """Whether per-cycle sample counts ``totals`` (n_cycles, N) count each cycle's samples: ``n_log``
    (the run's task's) for every cycle, or with a task mix for the cycles of the run's own task,
    and one number for all axes and cycles of each other task (its path, not stored, sets it)."""
    mix = (conditions or {}).get("task_mix")
    if mix is None:
        return bool(np.all(totals == n_log))
    tasks = np.array(mix["tasks"], dtype=object)[data["task_index"]]
    return all(np.all(totals[tasks == name] == (n_log if name == task else totals[tasks == name][0, 0]))
               for name in set(tasks))

