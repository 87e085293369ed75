"""HDF5 datasets of simulated runs: schema, atomic writer, reader, validator, summary.

One file holds any number of runs. Layout (h5py; every array carries ``units``, ``axes`` and
``description`` attributes; docs/dataset.md explains each field)::

    /                         attrs: format = "faultgen", format_version, faultgen_version,
                                     n_runs, command, grid (JSON, sweeps only),
                                     complete (written last: True only for a finished file)
    /runs/<run id>/           attrs: labels (robot, task, friction_model, cycles, seed, worn_axes,
                                     wear JSON, noise JSON) and provenance (faultgen_version,
                                     model_sha256, log_period, config JSON, command)
        t, cycles, q_ref                       time base, recorded cycles, reference
        q_a, q_m, qd_a, qd_m, tau_m            (n_cycles, n_log, 6) logged signals, 250 Hz
        tau_f, tau_dist                        (n_cycles, n_log, 6) truth
        friction_multiplier, mean_friction_torque, tracking_error        (n_cycles, 6) truth
        mean_abs_torque, rms_torque                                       (n_cycles, 6) features
        average_speed, average_load_torque     (n_cycles, 6) each axis's duty (DUTY_ARRAYS; runs
                                               simulated since it exists)
        angle_hist, speed_hist, torque_hist                               (n_cycles, 6, 12) features
        torque_counts          (n_cycles, 6, 1200) samples per fine |tau_m| bin, what detection
                               bins from (COUNT_ARRAYS; runs recorded per cycle since it exists)
        day, hour, joint_temperature, ...      operating conditions per cycle, truth (only runs
                                               with conditions: CONDITION_ARRAYS; attr conditions)

A file is written under a temporary name in its target folder and renamed into place once
complete, so a crash or kill never leaves a file at the target path that looks finished; a
reader refuses a file whose ``complete`` attribute is not set, and :func:`validate` reports
truncated or corrupted files instead of letting them be read.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Iterable
from contextlib import contextmanager
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING

import h5py
import numpy as np

if TYPE_CHECKING:
    import pandas as pd

from faultgen import __version__
from faultgen.data.atomic import atomic_path
from faultgen.model import robots
from faultgen.simulation import sensors

FORMAT = "faultgen"
FORMAT_VERSION = 1
SIGNAL_AXES = "cycle, sample, axis"

#: name -> (units, axes, description) of every array of a run group.
ARRAYS = {
    "t": ("s", "sample", "log time within a cycle (250 Hz)"),
    "cycles": ("1", "cycle", "1-based index of each recorded cycle"),
    "q_ref": ("rad", "sample, axis", "reference arm angle"),
    "q_a": ("rad", SIGNAL_AXES, "arm angle from the encoder"),
    "q_m": ("rad", SIGNAL_AXES, "motor angle from the encoder (motor side)"),
    "qd_a": ("rad/s", SIGNAL_AXES, "arm speed, backward difference of q_a"),
    "qd_m": ("rad/s", SIGNAL_AXES, "motor speed, backward difference of q_m (motor side)"),
    "tau_m": ("N m", SIGNAL_AXES, "motor torque (drive output, motor side)"),
    "tau_f": ("N m", SIGNAL_AXES, "true friction torque, motor side, positive opposing positive motion"),
    "tau_dist": ("N m", SIGNAL_AXES, "true load disturbance on the arm joint (arm side)"),
    "friction_multiplier": ("1", "cycle, axis", "true wear multiplier of Coulomb and static friction"),
    "mean_friction_torque": ("N m", "cycle, axis", "mean absolute true friction torque per cycle (motor side)"),
    "tracking_error": ("rad", "cycle, axis", "largest absolute error of the true arm angle against q_ref"),
    "mean_abs_torque": ("N m", "cycle, axis", "mean absolute motor torque per cycle (motor side)"),
    "rms_torque": ("N m", "cycle, axis", "RMS motor torque per cycle (motor side)"),
    "angle_hist": ("1", "cycle, axis, bin", "fraction of the cycle in each twelfth of the joint range"),
    "speed_hist": ("1", "cycle, axis, bin", "fraction of the cycle in each twelfth of 0..max arm speed"),
    "torque_hist": ("1", "cycle, axis, bin", "fraction of the cycle in each twelfth of 0..peak motor torque"),
}

#: name -> (units, axes, description) of the per-cycle sample counts of every run recorded per
#: cycle (not daily records; files written before they existed lack them, and stay valid).
COUNT_AXES = "cycle, axis, fine bin"
COUNT_ARRAYS = {
    "torque_counts": ("1", COUNT_AXES, (f"samples of the cycle in each 1/{sensors.TORQUE_COUNT_BINS} of 0..peak "
                                        "motor torque (|tau_m| as stored, larger in the last bin)")),
}

#: name -> (units, axes, description) of each axis's duty per cycle (:func:`faultgen.simulation.sensors.duty`),
#: what the speed and torque indicators are made from; files written before it existed lack it,
#: and stay valid.
DUTY_ARRAYS = {
    "average_speed": ("rad/s", "cycle, axis", "mean |qd_a| per cycle, the gearbox's average output speed"),
    "average_load_torque": ("N m", "cycle, axis", (f"(mean(|qd_a| |tau_m|^p) / mean |qd_a|)^(1/p) per cycle, "
                                                   f"p = {sensors.LOAD_EXPONENT:.4g} (motor side)")),
}

#: name -> (units, axes, description, condition that writes it) of the operating-condition
#: arrays (:mod:`faultgen.operation.conditions`), written for a run that has conditions: the
#: calendar and the friction factors always, the rest when their condition is on
#: (``condition.setting``: when that setting of the condition is on, not 0).
CONDITION_ARRAYS = {
    "day": ("d", "cycle", "day of the year of the cycle (counts on past 365)", None),
    "hour": ("h", "cycle", "time of day of the cycle", None),
    "dry_friction_factor": ("1", "cycle, axis", ("multiplier of Coulomb and static friction from temperature and "
                                                 "unit spread (wear not included)"), None),
    "viscous_factor": ("1", "cycle, axis", "multiplier of viscous friction from temperature and unit spread", None),
    "ambient_temperature": ("degC", "cycle", "air temperature", "thermal"),
    "joint_temperature": ("degC", "cycle, axis", "joint temperature", "thermal"),
    "payload_part": ("1", "cycle", "index of the part carried (into the conditions' payload masses)", "payloads"),
    "payload_mass": ("kg", "cycle", "mass of the part carried", "payloads"),
    "link_mass_factor": ("1", "axis", "multiplier of each link's mass and inertia (this unit's)", "spread"),
    "task_index": ("1", "cycle", "index of the task the cycle ran (into the conditions' task_mix tasks)", "task_mix"),
    "gear_loss": ("1", "axis", ("load-dependent friction coefficient this unit's gearbox adds (share of the "
                                "transmitted torque lost as Coulomb friction)"), "spread.gear_loss"),
}

#: The array of a run whose fault is not friction wear (attribute ``fault``): its units are the
#: fault parameter's, named by the effect (``faultgen.effects``), so the array says where to look.
FAULT_ARRAYS = {
    "fault_value": ("of the fault parameter", "cycle", "the growing fault's parameter at each cycle (attr fault)"),
}

#: Attributes every run group carries.
RUN_ATTRIBUTES = ("robot", "task", "friction_model", "cycles", "seed", "worn_axes", "wear", "noise",
                  "faultgen_version", "model_sha256", "log_period", "config", "command")


class DatasetError(ValueError):
    """A file is not a finished, valid faultgen dataset; the message says what is wrong."""

    #: The command line's exit code for it (faultgen.cli.base.Command): the file, not the input, is bad.
    exit_code = 1


def model_hash(path: Path) -> str:
    """SHA-256 of a robot's MJCF file, hex."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def config_key(config) -> str:
    """The run configuration as canonical JSON: equal keys mean the same simulation."""
    key = {
        "robot": config.robot, "task": config.task, "friction": config.friction,
        "wear": config.wear.to_dict(), "cycles": int(config.cycles),
        "record": [int(c) for c in config.recorded_cycles], "seed": int(config.seed),
        "noise": asdict(config.noise),
    }
    # a run keeps the key it had before these options existed when it does not use them
    if config.conditions.active:
        key["conditions"] = config.conditions.to_dict()
    if not config.signals:
        key["signals"] = False
    if config.daily:
        key["daily"] = True
    if config.fault is not None:
        key["fault"] = config.fault.to_dict()
    return json.dumps(key, sort_keys=True)


def run_attributes(result, command: str = "") -> dict:
    """Labels and provenance of a run, as HDF5 attributes (strings, numbers, JSON)."""
    config = result.config
    robot = robots.load(config.robot)
    return {
        "robot": robot.name,
        "task": config.task,
        "friction_model": config.friction,
        "cycles": int(config.cycles),
        "seed": int(config.seed),
        "worn_axes": np.array(sorted({*config.wear.worn_axes, *([config.fault.axis] if config.fault else [])}),
                              dtype=int),
        "wear": json.dumps(config.wear.to_dict()),
        "noise": json.dumps(asdict(config.noise)),
        "faultgen_version": __version__,
        "model_sha256": model_hash(robot.path),
        "log_period": sensors.LOG_PERIOD,
        "config": config_key(config),
        "command": command,
        **({"conditions": json.dumps(config.conditions.to_dict())} if config.conditions.active else {}),
        "signals": bool(config.signals),
        "sample": "day" if config.daily else "cycle",
        **({"fault": json.dumps(config.fault.to_dict())} if config.fault is not None else {}),
    }


def _condition_arrays(conditions: dict | None) -> list[str]:
    """The :data:`CONDITION_ARRAYS` a run with ``conditions`` (its JSON labels; None: none) has."""
    if not conditions:
        return []

    def on(condition: str | None) -> bool:
        if condition is None:
            return True
        name, _, setting = condition.partition(".")
        table = conditions.get(name)
        return table is not None and (not setting or bool(table.get(setting)))

    return [name for name, (*_, condition) in CONDITION_ARRAYS.items() if on(condition)]


def _write_root(f: h5py.File, n_runs: int, command: str, grid: str) -> None:
    f.attrs["format"] = FORMAT
    f.attrs["format_version"] = FORMAT_VERSION
    f.attrs["faultgen_version"] = __version__
    f.attrs["n_runs"] = n_runs
    f.attrs["command"] = command
    f.attrs["grid"] = grid


def write_run(path: str | Path, result, run_id: str = "run", command: str = "") -> Path:
    """Write one run to a new HDF5 file at ``path``, atomically.

    Raises
    ------
    OSError
        If the folder does not exist or cannot be written, or the disk is full; nothing is left
        at ``path`` and no temporary file remains.
    """
    path = Path(path)
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as f:
        _write_root(f, 1, command, "")
        f.attrs["complete"] = False
        group = f.create_group(f"runs/{run_id}")
        for key, value in run_attributes(result, command).items():
            group.attrs[key] = value
        values = {name: getattr(result, name, None) for name in ARRAYS}
        values.update(result.features)
        arrays = [(name, values[name], spec) for name, spec in ARRAYS.items()
                  if spec[1] != SIGNAL_AXES or result.config.signals]  # features only: no signals
        conditions = result.config.conditions
        arrays += [(name, getattr(result.conditions, name), CONDITION_ARRAYS[name][:3])
                   for name in _condition_arrays(conditions.to_dict() if conditions.active else None)]
        if result.fault_value is not None:
            arrays.append(("fault_value", result.fault_value, FAULT_ARRAYS["fault_value"]))
        arrays += [(name, values[name], spec) for name, spec in {**DUTY_ARRAYS, **COUNT_ARRAYS}.items()
                   if name in values]
        for name, value, (units, axes, description) in arrays:
            data = np.asarray(value)
            if axes == SIGNAL_AXES:
                # 250 Hz signals: float32 (7 digits, finer than the 1e-4 rad encoder noise), one chunk
                # per cycle, uncompressed: gzip saves only 24 % on these noisy signals at 4.6 times the
                # write time (docs/dataset.md)
                ds = group.create_dataset(name, data=data.astype(np.float32), chunks=(1, *data.shape[1:]))
            else:
                ds = group.create_dataset(name, data=data, compression="gzip", compression_opts=4, shuffle=True)
            ds.attrs["units"] = units
            ds.attrs["axes"] = axes
            ds.attrs["description"] = description
        f.attrs["complete"] = True
    return path


def merge(parts: Iterable[tuple[str, Path]], path: str | Path, command: str = "", grid: str = "") -> Path:
    """Copy the run of each part file (``(run id, part path)``) into one new dataset, atomically.

    Chunks are copied as stored (no recompression). Raises :class:`DatasetError` if a part is not
    a finished faultgen file.
    """
    path = Path(path)
    parts = list(parts)
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as out:
        _write_root(out, len(parts), command, grid)
        out.attrs["complete"] = False
        runs = out.create_group("runs")
        for run_id, part in parts:
            with _open(part) as src:
                (name,) = list(src["runs"])
                src.copy(src["runs"][name], runs, name=run_id)
        out.attrs["complete"] = True
    return path


@contextmanager
def _open(path: str | Path):
    """Open a finished faultgen file for reading, or raise DatasetError saying why not."""
    try:
        f = h5py.File(path, "r")
    except FileNotFoundError:
        raise DatasetError(f"{path}: no such file") from None
    except OSError as err:
        raise DatasetError(f"{path}: cannot be opened as HDF5 (truncated or not HDF5): {err}") from None
    try:
        if f.attrs.get("format") != FORMAT:
            raise DatasetError(f"{path} is not a faultgen file (format attribute {f.attrs.get('format')!r})")
        if not f.attrs.get("complete", False):
            raise DatasetError(f"{path} is incomplete: its writer did not finish")
        if "runs" not in f:
            raise DatasetError(f"{path} has no /runs group")
        yield f
    finally:
        f.close()


def list_runs(path: str | Path) -> list[str]:
    """Run ids of a dataset, in file order."""
    with _open(path) as f:
        return list(f["runs"])


def runs_with(path: str | Path, names: Iterable[str]) -> list[str]:
    """Run ids of a dataset, in file order, that hold every array of ``names`` (e.g. the
    :data:`DUTY_ARRAYS`, which runs simulated before they existed lack)."""
    names = list(names)
    with _open(path) as f:
        return [run_id for run_id in f["runs"] if all(name in f["runs"][run_id] for name in names)]


def read_run(path: str | Path, run_id: str | None = None,
             names: Iterable[str] | None = None) -> tuple[dict[str, np.ndarray], dict]:
    """Read one run: its arrays by name and its attributes (labels and provenance).

    ``run_id`` may be omitted for a file with one run; ``names`` limits the arrays read (default:
    all, see :data:`ARRAYS`). Raises :class:`DatasetError` if the file is not a finished faultgen
    file, has no such run, or the run has no such array.
    """
    with _open(path) as f:
        ids = list(f["runs"])
        if run_id is None:
            if len(ids) != 1:
                raise DatasetError(f"{path} has {len(ids)} runs; name one: {', '.join(ids[:10])}")
            run_id = ids[0]
        if run_id not in f["runs"]:
            raise DatasetError(f"{path} has no run {run_id!r}; runs: {', '.join(ids[:10])}")
        group = f["runs"][run_id]
        wanted = list(group) if names is None else list(names)
        missing = [name for name in wanted if name not in group]
        if missing:
            why = ""
            if not group.attrs.get("signals", True) and ARRAYS.get(missing[0], ("", ""))[1] == SIGNAL_AXES:
                why = ("; it was recorded without signals (features only): simulate it again with signals "
                       "(`faultgen sweep` without --features-only) to use this command")
            raise DatasetError(f"{path}: run {run_id!r} has no array {missing[0]!r}{why}")
        arrays = {name: group[name][()] for name in wanted}
        attrs = {key: _attr(group.attrs[key]) for key in group.attrs}
    return arrays, attrs


#: Labels of a run repeated on every row of :func:`features`.
FEATURE_LABELS = ("robot", "task", "friction_model", "seed")
#: Formats :func:`export_features` writes, by file-name ending.
EXPORT_SUFFIXES = (".csv", ".csv.gz", ".parquet")


def features(path: str | Path) -> pd.DataFrame:
    """Every per-cycle quantity of a dataset as one tidy table, for tools that do not read HDF5.

    One row per (run, recorded cycle, axis); columns: ``run``, the run's labels
    (:data:`FEATURE_LABELS`), ``worn_axes`` (the run's worn axes as text, "2" or "2 5"; "" for
    none), ``cycle`` (1-based), ``axis`` (1..6), ``worn`` (this axis wears in this run),
    ``wear_pct`` (true wear of this axis at this cycle, ``(friction_multiplier - 1) * 100``),
    then every array of :data:`ARRAYS` with axes "cycle, axis" and of :data:`DUTY_ARRAYS` (empty for
    runs without) under its own name and every
    histogram ("cycle, axis, bin") as one column per bin, ``torque_hist_1`` .. ``torque_hist_12``,
    and, for runs with operating conditions, each of their :data:`CONDITION_ARRAYS` (a per-cycle
    value on each of the cycle's rows, a per-axis one on each axis's; empty for runs without).
    Values are the stored ones, in the units of :data:`ARRAYS`; ``DataFrame.attrs["units"]`` maps
    each column to its unit.

    Raises
    ------
    DatasetError
        If ``path`` is not a finished faultgen dataset.
    """
    import pandas as pd

    per_cycle = [name for name, (_, axes, _) in ARRAYS.items() if axes == "cycle, axis"]
    histograms = [name for name, (_, axes, _) in ARRAYS.items() if axes == "cycle, axis, bin"]
    frames = []
    with_duty = runs_with(path, DUTY_ARRAYS)
    for run_id in list_runs(path):
        duty = list(DUTY_ARRAYS) if run_id in with_duty else []
        arrays, attrs = read_run(path, run_id, names=("cycles", *per_cycle, *duty, *histograms))
        n_cycles, n_axes = arrays["friction_multiplier"].shape
        present = _condition_arrays(json.loads(attrs["conditions"]) if "conditions" in attrs else None)
        conditions = read_run(path, run_id, names=present)[0] if present else {}
        worn = {int(a) for a in attrs["worn_axes"]}
        columns = {"run": run_id, **{key: attrs[key] for key in FEATURE_LABELS},
                   "worn_axes": " ".join(str(a) for a in sorted(worn)),
                   "cycle": np.repeat(arrays["cycles"], n_axes), "axis": np.tile(np.arange(1, n_axes + 1), n_cycles),
                   "worn": np.tile([a in worn for a in range(1, n_axes + 1)], n_cycles),
                   "wear_pct": ((arrays["friction_multiplier"] - 1.0) * 100.0).ravel()}
        columns.update({name: arrays[name].ravel() for name in (*per_cycle, *duty)})
        for name, values in conditions.items():  # per cycle, per axis or per unit, to rows
            axes = CONDITION_ARRAYS[name][1]
            columns[name] = (values.ravel() if axes == "cycle, axis" else np.repeat(values, n_axes)
                             if axes == "cycle" else np.tile(values, n_cycles))
        for name in histograms:
            bins = arrays[name].reshape(n_cycles * n_axes, -1)
            columns.update({f"{name}_{k + 1}": bins[:, k] for k in range(bins.shape[1])})
        frames.append(pd.DataFrame(columns))
    table = pd.concat(frames, ignore_index=True)
    table.attrs["units"] = {"wear_pct": "%", **{name: ARRAYS[name][0] for name in per_cycle},
                            **{name: DUTY_ARRAYS[name][0] for name in DUTY_ARRAYS if name in table},
                            **{name: CONDITION_ARRAYS[name][0] for name in CONDITION_ARRAYS if name in table},
                            **{c: ARRAYS[c.rsplit("_", 1)[0]][0] for c in table.columns
                               if c.rsplit("_", 1)[0] in histograms}}
    return table


def export_features(path: str | Path, out: str | Path) -> Path:
    """Write :func:`features` of ``path`` to ``out`` (CSV, gzip-compressed CSV or Parquet by its
    ending, :data:`EXPORT_SUFFIXES`), atomically.

    Raises
    ------
    ValueError
        If ``out`` has another ending (the message lists the accepted ones).
    DatasetError
        If ``path`` is not a finished faultgen dataset.
    """
    out = Path(out)
    if not out.name.lower().endswith(EXPORT_SUFFIXES):
        raise ValueError(f"cannot export to {out}: expected a name ending in {', '.join(EXPORT_SUFFIXES)}")
    table = features(path)
    with atomic_path(out) as tmp:
        if out.name.lower().endswith(".parquet"):
            table.to_parquet(tmp, index=False)
        else:
            table.to_csv(tmp, index=False, compression="gzip" if out.name.lower().endswith(".gz") else None)
    return out


def labels(path: str | Path) -> list[dict]:
    """The labels of every run, one dict per run (with its ``run`` id), in file order."""
    with _open(path) as f:
        return [{"run": run_id, **{k: _attr(v) for k, v in f["runs"][run_id].attrs.items()}} for run_id in f["runs"]]


def _attr(value):
    return value.decode() if isinstance(value, bytes) else value


def validate(path: str | Path) -> list[str]:
    """Check a file against the schema; return the problems found (an empty list: valid).

    Opens every array (so corrupted chunks surface), and checks units, shapes, finiteness, that
    histograms sum to 1, that recorded cycles lie in 1..cycles, and that the run count matches.
    """
    problems: list[str] = []
    try:
        with _open(path) as f:
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


def _validate_run(group: h5py.Group) -> list[str]:
    problems = [f"missing attribute {a!r}" for a in RUN_ATTRIBUTES if a not in group.attrs]
    try:
        conditions = json.loads(_attr(group.attrs["conditions"])) if "conditions" in group.attrs else None
    except ValueError:
        return [*problems, "conditions attribute is not JSON"]
    signals = bool(group.attrs.get("signals", True))
    schema = {**{name: value for name, value in ARRAYS.items() if signals or value[1] != SIGNAL_AXES},
              **{name: CONDITION_ARRAYS[name][:3] for name in _condition_arrays(conditions)}}
    if "fault" in group.attrs:
        schema.update(FAULT_ARRAYS)
    schema.update({name: spec for name, spec in {**DUTY_ARRAYS, **COUNT_ARRAYS}.items() if name in group})
    if sum(name in group for name in DUTY_ARRAYS) == 1:
        problems.append(f"has one of the duty arrays {', '.join(DUTY_ARRAYS)} but not the other")
    missing = [name for name in schema if name not in group]
    problems += [f"missing array {name!r}" for name in missing]
    if missing:
        return problems
    data = {}
    for name, (units, axes, _) in schema.items():
        ds = group[name]
        if _attr(ds.attrs.get("units")) != units or _attr(ds.attrs.get("axes")) != axes:
            problems.append(f"{name}: units/axes attributes {ds.attrs.get('units')!r}/{ds.attrs.get('axes')!r}, "
                            f"expected {units!r}/{axes!r}")
        try:
            data[name] = ds[()]
        except (OSError, RuntimeError) as err:
            problems.append(f"{name}: cannot be read ({err}); the file is corrupted")
            return problems
        if not np.all(np.isfinite(data[name])):
            problems.append(f"{name}: holds non-finite values")
    n_cycles, n_log = len(data["cycles"]), len(data["t"])
    for name, (_, axes, _) in schema.items():
        expected = {SIGNAL_AXES: (n_cycles, n_log, 6), "cycle, axis": (n_cycles, 6),
                    "cycle, axis, bin": (n_cycles, 6, sensors.HISTOGRAM_BINS), "sample, axis": (n_log, 6),
                    COUNT_AXES: (n_cycles, 6, sensors.TORQUE_COUNT_BINS),
                    "sample": (n_log,), "cycle": (n_cycles,), "axis": (6,)}[axes]
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
                                                                            conditions, _attr(group.attrs.get("task")))):
            problems.append(f"{name}: not counts of the {n_log} samples of each cycle")
    for name in ("friction_multiplier", "dry_friction_factor", "viscous_factor", "link_mass_factor"):
        if name in data and np.any(data[name] <= 0):
            problems.append(f"{name}: not positive")
    for name in (*DUTY_ARRAYS, "gear_loss"):
        if name in data and np.any(data[name] < 0):
            problems.append(f"{name}: negative")
    return problems


def _counts_fit(totals: np.ndarray, n_log: int, data: dict, conditions: dict | None, task: str) -> bool:
    """Whether per-cycle sample counts ``totals`` (n_cycles, 6) count each cycle's samples: ``n_log``
    (the run's task's) for every cycle, or with a task mix for the cycles of the run's own task,
    and one number for all axes and cycles of each other task (its path, not stored, sets it)."""
    mix = (conditions or {}).get("task_mix")
    if mix is None:
        return bool(np.all(totals == n_log))
    tasks = np.array(mix["tasks"], dtype=object)[data["task_index"]]
    return all(np.all(totals[tasks == name] == (n_log if name == task else totals[tasks == name][0, 0]))
               for name in set(tasks))


def summary(path: str | Path) -> str:
    """A few lines describing a dataset: runs, robots, tasks, wear, cycles, size, provenance."""
    with _open(path) as f:
        runs = f["runs"]
        rows = [{k: _attr(v) for k, v in runs[r].attrs.items()} for r in runs]
        n_cycles = [runs[r]["cycles"].shape[0] for r in runs]
        n_log = [runs[r]["t"].shape[0] for r in runs]
        version, command = _attr(f.attrs.get("faultgen_version")), _attr(f.attrs.get("command", ""))
    worn = sorted({tuple(int(a) for a in row["worn_axes"]) for row in rows})
    daily = any(row.get("sample") == "day" for row in rows)
    signals = all(row.get("signals", True) for row in rows)
    lines = [
        f"{path}: {len(rows)} run(s), {Path(path).stat().st_size / 1e6:.1f} MB, written by faultgen {version}",
        f"  robots:        {', '.join(sorted({r['robot'] for r in rows}))}",
        f"  tasks:         {', '.join(sorted({r['task'] for r in rows}))}",
        f"  friction:      {', '.join(sorted({r['friction_model'] for r in rows}))}",
        f"  worn axes:     {', '.join('none' if not w else '+'.join(map(str, w)) for w in worn)}",
        f"  seeds:         {', '.join(map(str, sorted({int(r['seed']) for r in rows})))}",
        f"  {'days' if daily else 'cycles'}:{' ' * (14 - (4 if daily else 6))}{min(n_cycles)}-{max(n_cycles)} "
        f"{'daily records' if daily else 'recorded'} per run, {sum(n_cycles)} in all; "
        + (f"{min(n_log)}-{max(n_log)} samples per cycle at {1 / sensors.LOG_PERIOD:.0f} Hz" if signals
           else "features and truth only (no 250 Hz signals)"),
    ]
    if any("conditions" in row for row in rows):
        lines.append(f"  conditions:    {sum('conditions' in row for row in rows)} run(s) with operating conditions "
                     "(temperature, payloads, task mix, unit spread: CONDITION_ARRAYS)")
    if command:
        lines.append(f"  command:       {command}")
    return "\n".join(lines)
