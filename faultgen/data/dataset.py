"""HDF5 datasets of simulated runs: schema, atomic writer, reader, validator, summary.

One file holds any number of runs. Layout (h5py; every array carries ``units``, ``axes`` and
``description`` attributes; docs/dataset.md explains each field)::

    /                         attrs: format = "faultgen", format_version, faultgen_version,
                                     n_runs, command, grid (JSON, sweeps only),
                                     complete (written last: True only for a finished file)
    /runs/<run id>/           attrs: labels (robot, task, friction_model, cycles, seed, worn_axes,
                                     program_sha256: what the program is (PROGRAM_ATTRIBUTE;
                                     older files lack it),
                                     a program file's or log's program: name, file, sha256, program_text;
                                     wear JSON, noise JSON) and provenance (faultgen_version,
                                     model_sha256, log_period, config JSON, command; since robots
                                     of 5-7 axes: n_axes, drivetrain JSON)
        t, cycles, q_ref                       time base, recorded cycles, reference
        q_a, q_m, qd_a, qd_m, tau_m            (n_cycles, n_log, N) logged signals, 250 Hz, N the
                                               robot's axes (attr n_axes; 6 in files before it)
        tau_f, tau_dist                        (n_cycles, n_log, N) truth
        friction_multiplier, mean_friction_torque, tracking_error        (n_cycles, N) truth
        mean_abs_torque, rms_torque                                       (n_cycles, N) features
        average_speed, average_load_torque     (n_cycles, N) each axis's duty (DUTY_ARRAYS; runs
                                               simulated since it exists)
        angle_hist, speed_hist, torque_hist                               (n_cycles, N, 12) features
        torque_counts          (n_cycles, N, 1200) samples per fine |tau_m| bin, what detection
                               bins from (COUNT_ARRAYS; runs recorded per cycle since it exists)
        day, hour, joint_temperature, ...      operating conditions per cycle, truth (only runs
                                               with conditions: CONDITION_ARRAYS; attr conditions)

A file is written under a temporary name in its target folder and renamed into place once
complete, so a crash or kill never leaves a file at the target path that looks finished; a
reader refuses a file whose ``complete`` attribute is not set, and :func:`validate` reports
truncated or corrupted files instead of letting them be read.
"""

from __future__ import annotations

import errno
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
from faultgen import axes as axis_numbers
from faultgen import inputs
from faultgen.data import structure
from faultgen.data.atomic import atomic_path, hdf5_writer
from faultgen.effects.friction import FIELDS as FRICTION_FIELDS
from faultgen.effects.friction import UNITS as FRICTION_UNITS
from faultgen.model import robots
from faultgen.operation import programs
from faultgen.operation.faults import Fault
from faultgen.simulation import sensors
from faultgen.simulation.signals import ARRAYS, SIGNAL_AXES  # the signal set, defined once (re-exported)

FORMAT = "faultgen"
FORMAT_VERSION = 1

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

#: name -> (units, axes, description) of what a run imported from measured logs holds beside the
#: features (attribute ``source = "measured"``, :mod:`faultgen.data.fleetlogs`): a record is a log;
#: ``joint_temperature`` and ``payload_mass`` only when every log of the unit has them. Such a run has
#: no simulated truth (``mean_friction_torque``, ``tracking_error``); its ``friction_multiplier`` holds
#: the labels (2 on worn logs, 1 elsewhere, ``faultgen.data.fleetlogs.WORN_MARK``).
MEASURED_ARRAYS = {
    "label": ("1", "cycle, axis", "per log and axis: 1 worn, 0 healthy, -1 unknown (from the logs' events.csv)"),
    "stamp": ("", "cycle", "the log's stamp, as in its file name (ISO date or date-time, or a sequence number)"),
    "stamp_key": ("s since 1970-01-01 UTC, or 1 for sequence numbers", "cycle", "the stamp as a number, increasing"),
    "log_file": ("", "cycle", "the log's file, <unit>/<name>, relative to the logs folder"),
    "log_cycles": ("1", "cycle", "cycles in the log, reduced to its record as a simulated day's are"),
    "log_duration": ("s", "cycle", "recorded time span of the log"),
    "joint_temperature": ("degC", "cycle, axis", "the log's mean joint temperature"),
    "payload_mass": ("kg", "cycle", "the largest payload mass in the log"),
}
#: The :data:`MEASURED_ARRAYS` an imported run holds only when its logs have them.
MEASURED_OPTIONAL = ("joint_temperature", "payload_mass")
#: The simulated truths a measured run lacks.
SIMULATED_TRUTH = ("mean_friction_torque", "tracking_error")
#: The ``source`` attribute of a run imported from measured logs (absent: simulated).
MEASURED = "measured"
#: The arrays that hold text (variable-length UTF-8 strings), not numbers.
TEXT_ARRAYS = ("stamp", "log_file")


def kinds(name: str) -> str:
    """The NumPy type kinds an array of a run may hold (:func:`faultgen.inputs.bounded_dataset`):
    text for :data:`TEXT_ARRAYS`, numbers (and booleans) for the others."""
    return "SOU" if name in TEXT_ARRAYS else "fiub"

#: name -> axes of every array a run may hold, and the lengths of the axes that are not cycles,
#: samples or axes: the declared shapes :func:`faultgen.data.structure.check_runs` checks at opening.
SHAPES = {name: spec[1] for table in (ARRAYS, COUNT_ARRAYS, DUTY_ARRAYS, CONDITION_ARRAYS, FAULT_ARRAYS,
                                                        MEASURED_ARRAYS)
          for name, spec in table.items()}
BINS = {"bin": sensors.HISTOGRAM_BINS, "fine bin": sensors.TORQUE_COUNT_BINS}

#: Attributes every run group carries.
RUN_ATTRIBUTES = ("robot", "task", "friction_model", "cycles", "seed", "worn_axes", "wear", "noise",
                  "faultgen_version", "model_sha256", "log_period", "config", "command")


#: The attribute that says what a run's program is (:func:`faultgen.operation.programs.identity`):
#: the SHA-256 of its text, hex. Runs written before it lack it; readers then fall back to the
#: ``task`` label (:attr:`faultgen.data.reader.Run.program`) and analyses say so.
PROGRAM_ATTRIBUTE = "program_sha256"

#: Attributes of a run written since robots of 5 to 7 axes exist (files before them lack them and
#: stay valid: their robots had six axes): ``n_axes`` (int) and ``drivetrain`` (JSON,
#: :func:`drivetrain`).
ROBOT_ATTRIBUTES = ("n_axes", "drivetrain")

#: The drivetrain numbers a run records (:func:`drivetrain`): Robot attribute -> SI unit.
DRIVETRAIN = {"gear_ratio": "1", "motor_inertia": "kg m^2", "gearbox_stiffness": "N m/rad",
              "gearbox_damping": "N m s/rad", "motor_torque_limit": "N m"}


class DatasetError(ValueError):
    """A file is not a finished, valid faultgen dataset; the message says what is wrong."""

    #: The command line's exit code for it (faultgen.cli.base.Command): the file, not the input, is bad.
    exit_code = 1


def model_hash(path: Path) -> str:
    """SHA-256 of a robot's MJCF file, hex."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def drivetrain(robot) -> dict:
    """The drivetrain a run was simulated with, per axis 1..N, as plain lists: :data:`DRIVETRAIN`
    (gear ratio, motor inertia at the motor side, gearbox stiffness and damping at the arm side,
    motor torque limit) and ``friction``, the nominal motor-side friction parameters
    (:data:`faultgen.effects.friction.FIELDS`, motor side), with ``units`` naming each unit."""
    table = {name: [float(x) for x in getattr(robot, name)] for name in DRIVETRAIN}
    table["friction"] = {name: [float(x) for x in getattr(robot.friction, name)] for name in FRICTION_FIELDS}
    table["units"] = {**DRIVETRAIN, **{f"friction.{name}": FRICTION_UNITS[name] for name in FRICTION_FIELDS}}
    return table


def config_key(config) -> str:
    """The run configuration as canonical JSON: equal keys mean the same simulation."""
    key = {
        "robot": config.robot, "task": config.task, "friction": config.friction,
        **({"program_sha256": program["sha256"]} if (program := programs.record(config.task)) else {}),
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
    program = programs.record(config.task)  # a program file or a replayed log: what makes it again
    label, digest = programs.identity(robot, config.task)
    return {
        "robot": robot.name,
        "task": label,
        "program_sha256": digest,
        **({} if program is None else {
            "program": json.dumps({k: v for k, v in program.items() if k != "text"}),
            **({"program_text": program["text"]} if "text" in program else {})}),
        "friction_model": config.friction,
        "cycles": int(config.cycles),
        "seed": int(config.seed),
        "worn_axes": np.array(sorted({*config.wear.worn_axes, *([config.fault.axis] if config.fault else [])}),
                              dtype=int),
        "wear": json.dumps(config.wear.to_dict()),
        "noise": json.dumps(asdict(config.noise)),
        "faultgen_version": __version__,
        "model_sha256": model_hash(robot.path),
        "n_axes": int(robot.n_axes),
        "drivetrain": json.dumps(drivetrain(robot)),
        "log_period": sensors.LOG_PERIOD,
        "config": config_key(config),
        "command": command,
        **({"conditions": json.dumps(config.conditions.to_dict())} if config.conditions.active else {}),
        "signals": bool(config.signals),
        "sample": "day" if config.daily else "cycle",
        **({"fault": json.dumps(config.fault.to_dict())} if config.fault is not None else {}),
        # axes whose motor saturated (a wear or fault too large for the drive): validate reports them
        **({"saturated": np.asarray(result.saturated, dtype=int)} if len(getattr(result, "saturated", ())) else {}),
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


def estimated_size(config) -> int:
    """Bytes the file of a run of ``config`` (:class:`faultgen.simulation.stepping.RunConfig`)
    takes, about: its signals as float32 (seven arrays of (recorded cycles, samples, axes)) when
    kept, and 20 kB of features per recorded cycle (measured: 2 cycles of pick_place on the
    IRB-6700-like arm with signals, 721 kB; this estimate 666 kB). What the commands check is free
    before they start (:func:`faultgen.data.atomic.check_writable`)."""
    from faultgen.simulation import stepping as sim

    n_cycles = len(config.recorded_cycles)
    per_cycle = 20_000
    if config.signals:
        n_log = int(sim.cycle_duration(config.robot, config.task) / sensors.LOG_PERIOD) + 1
        per_cycle += 7 * 4 * n_log * robots.load(config.robot).n_axes
    return n_cycles * per_cycle + 50_000


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
    with hdf5_writer(path) as f:
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
    with hdf5_writer(path) as out:
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
    writer = _writer_of(Path(path))
    if writer is not None:
        raise DatasetError(f"{path} is in use: process {writer} is writing it (the finished file appears under "
                           "its own name when it is done)")
    if Path(path).exists() and not Path(path).is_dir():
        inputs.regular_file(path, "dataset")  # /dev/zero, a FIFO: refused before h5py waits on it
    try:
        f = h5py.File(path, "r")
    except FileNotFoundError:
        raise DatasetError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise DatasetError(f"{path} is a folder, not a dataset file") from None
    except OSError as err:
        if err.errno == errno.EAGAIN or "unable to lock file" in str(err).lower():
            raise DatasetError(f"{path} is in use: another process has it open for writing; wait for it to "
                               "finish") from None
        raise DatasetError(f"{path}: cannot be opened as HDF5 (truncated or not HDF5): {err}") from None
    try:
        inputs.check_hdf5_links(f, path)  # before anything is read through a link to another file
        if f.attrs.get("format") != FORMAT:
            raise DatasetError(f"{path} is not a faultgen file (format attribute {f.attrs.get('format')!r})")
        if not f.attrs.get("complete", False):
            raise DatasetError(f"{path} is incomplete: its writer did not finish")
        if "runs" not in f:
            raise DatasetError(f"{path} has no /runs group")
        if f.attrs.get("format_version") != FORMAT_VERSION:
            raise DatasetError(f"{path} has format_version {_attr(f.attrs.get('format_version')).item() if hasattr(f.attrs.get('format_version'), 'item') else f.attrs.get('format_version')!r}; this faultgen "
                               f"reads version {FORMAT_VERSION}")
        if len(f["runs"]) == 0:
            raise DatasetError(f"{path} has no runs (its /runs group is empty)")
        structure.check_runs(f, path, SHAPES, BINS, kinds)
        yield f
    finally:
        f.close()


def _writer_of(path: Path) -> int | None:
    """The pid of the running process writing ``path``, if it is the temporary file of an atomic
    write (``.<name>.<pid>@<host>.<random>.part``, :func:`faultgen.data.atomic.atomic_path`) of a
    process that still runs on this host; else None."""
    import re

    from faultgen.data import atomic

    match = re.fullmatch(r"\.(.+)\.(\d+)@(.+)\.[^.]+\.part", path.name)
    if match is None or match[3] != atomic._host() or not atomic._running(int(match[2])):
        return None
    return int(match[2])


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
        problems = _attribute_problems(group)
        if problems:
            raise DatasetError(f"{path}: run {run_id!r}: {problems[0]} (faultgen validate {path} lists every problem)")
        arrays = {name: inputs.bounded_dataset(group, name, path, kinds=kinds(name))[()] for name in wanted}
        for name, value in arrays.items():
            if value.dtype.kind == "f" and not np.all(np.isfinite(value)):
                raise DatasetError(f"{path}: run {run_id!r}: {name} holds non-finite values; the file is corrupted "
                                   f"(faultgen validate {path})")
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
    none), ``cycle`` (1-based), ``axis`` (1..N), ``worn`` (this axis wears in this run),
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
    from faultgen.data import reader  # the typed reader builds the table, with the file opened once

    with reader.open(path) as data:
        return data.features()


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
        for run_id in f["runs"]:
            problems = _attribute_problems(f["runs"][run_id])
            if problems:
                raise DatasetError(f"{path}: run {run_id!r}: {problems[0]} (faultgen validate {path} lists every "
                                   "problem)")
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
    with _open(path) as f:
        for run_id, group in f["runs"].items():
            axes = [int(a) for a in np.atleast_1d(group.attrs.get("saturated", []))]
            if axes:
                out.append(f"run {run_id}: axes {', '.join(map(str, axes))}: the motor saturated (the drive torque "
                           "reached its limit): the run does not follow its task there")
    return out


def _attribute_problems(group: h5py.Group) -> list[str]:
    """What is wrong with the attributes of a run group: each present attribute must parse into
    its type and range (a whole number of cycles >= 1, worn axes as axis numbers, JSON tables, a
    known friction model, a positive log period, ...); the missing ones are listed by
    :func:`_validate_run`."""
    from faultgen.effects import friction

    problems = []
    attrs = {key: _attr(group.attrs[key]) for key in group.attrs}

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
    for key in ("wear", "noise", "config", "conditions", "fault"):
        if key in attrs:
            try:
                table = json.loads(attrs[key])
            except (TypeError, ValueError):
                problems.append(f"attribute {key!r} is not JSON: {str(attrs[key])[:40]!r}")
                continue
            if not isinstance(table, dict):
                problems.append(f"attribute {key!r} is {str(attrs[key])[:40]!r}, expected a JSON table")
    return problems


def _program_problems(attrs) -> list[str]:
    """A run of a program file or replayed log (attribute ``program``: JSON name, file, sha256; a
    program's text in ``program_text``): the JSON reads, and the stored text is the one hashed."""
    if "program" not in attrs:
        return ["program_text without a program attribute"] if "program_text" in attrs else []
    try:
        program = json.loads(_attr(attrs["program"]))
        digest = program["sha256"]
    except (ValueError, KeyError, TypeError):
        return ["program attribute is not JSON with a sha256"]
    if PROGRAM_ATTRIBUTE in attrs and _attr(attrs[PROGRAM_ATTRIBUTE]) != digest:
        return [f"{PROGRAM_ATTRIBUTE} {str(_attr(attrs[PROGRAM_ATTRIBUTE]))[:12]}... is not the program's sha256 "
                f"{digest[:12]}..."]
    if "program_text" in attrs:
        text = _attr(attrs["program_text"])
        if hashlib.sha256(text.encode()).hexdigest() != digest:
            return [f"program_text does not hash to the program's sha256 {digest[:12]}..."]
    return []


def _validate_run(group: h5py.Group) -> list[str]:
    problems = [f"missing attribute {a!r}" for a in RUN_ATTRIBUTES if a not in group.attrs]
    problems += _attribute_problems(group)
    try:
        conditions = json.loads(_attr(group.attrs["conditions"])) if "conditions" in group.attrs else None
    except ValueError:
        return [*problems, "conditions attribute is not JSON"]
    problems += _program_problems(group.attrs)
    if problems:
        return problems
    signals = bool(group.attrs.get("signals", True))
    schema = {**{name: value for name, value in ARRAYS.items() if signals or value[1] != SIGNAL_AXES},
              **{name: CONDITION_ARRAYS[name][:3] for name in _condition_arrays(conditions)}}
    if "fault" in group.attrs:
        schema.update(FAULT_ARRAYS)
    schema.update({name: spec for name, spec in {**DUTY_ARRAYS, **COUNT_ARRAYS}.items() if name in group})
    if _attr(group.attrs.get("source")) == MEASURED:
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
        if _attr(ds.attrs.get("units")) != units or _attr(ds.attrs.get("axes")) != axes:
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
                                                                            conditions, _attr(group.attrs.get("task")))):
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
    with every :data:`DRIVETRAIN` entry and friction parameter a list of N finite numbers.
    """
    problems = []
    if "n_axes" in group.attrs:
        n_axes = group.attrs["n_axes"]
        if not (np.ndim(n_axes) == 0 and np.issubdtype(np.asarray(n_axes).dtype, np.integer)
                and axis_numbers.MIN_AXES <= int(n_axes) <= axis_numbers.MAX_AXES):
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
            table = json.loads(_attr(group.attrs["drivetrain"]))
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
    return n_axes, problems


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


def summary(path: str | Path) -> str:
    """A few lines describing a dataset: runs, robots, tasks, wear, cycles, size, provenance."""
    with _open(path) as f:
        runs = f["runs"]
        for run_id in runs:
            problems = [f"missing attribute {a!r}" for a in ("robot", "task", "friction_model", "seed", "worn_axes")
                        if a not in runs[run_id].attrs] + _attribute_problems(runs[run_id])
            problems += [f"missing array {a!r}" for a in ("cycles", "t") if a not in runs[run_id]]
            if problems:
                raise DatasetError(f"{path}: run {run_id!r}: {problems[0]} (faultgen validate {path} lists every "
                                   "problem)")
        rows = [{k: _attr(v) for k, v in runs[r].attrs.items()} for r in runs]
        n_cycles = [runs[r]["cycles"].shape[0] for r in runs]
        n_log = [runs[r]["t"].shape[0] for r in runs]
        version, command = _attr(f.attrs.get("faultgen_version")), _attr(f.attrs.get("command", ""))
    worn = sorted({tuple(int(a) for a in row["worn_axes"]) for row in rows})
    daily = any(row.get("sample") in ("day", "log") for row in rows)
    logs = any(row.get("sample") == "log" for row in rows)
    what, record = ("logs", "log records") if logs else ("days", "daily records") if daily else ("cycles", "recorded")
    signals = all(row.get("signals", True) for row in rows)
    lines = [
        f"{path}: {len(rows)} run(s), {Path(path).stat().st_size / 1e6:.1f} MB, written by faultgen {version}",
        f"  robots:        {', '.join(sorted({r['robot'] for r in rows}))}",
        f"  tasks:         {', '.join(sorted({r['task'] for r in rows}))}",
        f"  friction:      {', '.join(sorted({r['friction_model'] for r in rows}))}",
        f"  worn axes:     {', '.join('none' if not w else '+'.join(map(str, w)) for w in worn)}",
        f"  seeds:         {', '.join(map(str, sorted({int(r['seed']) for r in rows})))}",
        f"  {what}:{' ' * (14 - len(what))}{min(n_cycles)}-{max(n_cycles)} "
        f"{record} per run, {sum(n_cycles)} in all; "
        + (f"{min(n_log)}-{max(n_log)} samples per cycle at {1 / sensors.LOG_PERIOD:.0f} Hz" if signals
           else "features and truth only (no 250 Hz signals)"),
    ]
    if any("conditions" in row for row in rows):
        tables = [json.loads(row["conditions"]) for row in rows if "conditions" in row]
        kinds = sorted({key for table in tables for key, value in table.items()
                        if key in ("thermal", "payloads", "spread", "task_mix") and value})
        lines.append(f"  conditions:    {sum('conditions' in row for row in rows)} run(s) with operating conditions: "
                     f"{', '.join(kinds)} (their per-cycle arrays: `faultgen info FILE --card`, docs/dataset.md)")
    with_fault = [Fault(**json.loads(row["fault"])).text() for row in rows if "fault" in row]
    if with_fault:
        counts = {text: with_fault.count(text) for text in dict.fromkeys(with_fault)}
        lines.append("  faults:        " + ", ".join(f"{text} ({n} run{'s' * (n > 1)})" for text, n in counts.items())
                     + " (EFFECT:AXIS:PARAMETER:FINAL, other than friction wear)")
    saturated = [row for row in rows if len(row.get("saturated", ()))]
    if saturated:
        lines.append(f"  saturated:     {len(saturated)} run(s) whose motors reached their torque limit (they do not "
                     "follow their task; `faultgen validate` lists them)")
    measured = [row for row in rows if row.get("source") == MEASURED]
    if measured:
        lines.append(f"  measured:      {len(measured)} unit(s) imported from logs (`faultgen logs import`): labels from "
                     "their events, no simulated truth")
    if command:
        lines.append(f"  command:       {command}")
    return "\n".join(lines)
