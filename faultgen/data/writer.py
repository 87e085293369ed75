"""Writing datasets: a run's labels and provenance as HDF5 attributes, one run written atomically
(:func:`write_run`), part files merged into one dataset (:func:`merge`).

The layout is :mod:`faultgen.data.schema`'s; a file is written under a temporary name and renamed
into place once complete (:func:`faultgen.data.atomic.hdf5_writer`), its ``complete`` attribute set
last, so no half-written file looks finished.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import asdict
from pathlib import Path

import h5py
import numpy as np

from faultgen import __version__, inputs
from faultgen.data.atomic import hdf5_writer
from faultgen.data.opening import open_file
from faultgen.data.schema import (
    ARRAYS,
    CONDITION_ARRAYS,
    COUNT_ARRAYS,
    DRIVETRAIN,
    DUTY_ARRAYS,
    FAULT_ARRAYS,
    FORMAT,
    FORMAT_VERSION,
    FRICTION_TEST,
    FRICTION_TEST_PROCESS,
    LIMITS,
    RECORD_ATTRIBUTE,
    SIGNAL_AXES,
    condition_arrays,
)
from faultgen.effects.friction import FIELDS as FRICTION_FIELDS
from faultgen.effects.friction import UNITS as FRICTION_UNITS
from faultgen.model import sources
from faultgen.operation import programs
from faultgen.simulation import resolve, sensors


def model_hash(path: Path) -> str:
    """SHA-256 of a robot's MJCF file, hex, hashed in blocks up to the loader's bound
    (:func:`faultgen.inputs.sha256_of`: a file swapped for a sparse one since the load is refused on
    its size, an InputError naming it, not read whole)."""
    return inputs.sha256_of(path, "robot MJCF", sources.MAX_DESCRIPTION_BYTES)


def drivetrain(robot) -> dict:
    """The drivetrain a run was simulated with, per axis 1..N, as plain lists: :data:`DRIVETRAIN`
    (gear ratio, motor inertia at the motor side, gearbox stiffness and damping at the arm side,
    motor torque limit) and ``friction``, the nominal motor-side friction parameters
    (:data:`faultgen.effects.friction.FIELDS`, motor side), with ``units`` naming each unit."""
    table = {name: [float(x) for x in getattr(robot, name)] for name in DRIVETRAIN}
    table["friction"] = {name: [float(x) for x in getattr(robot.friction, name)] for name in FRICTION_FIELDS}
    table["units"] = {**DRIVETRAIN, **{f"friction.{name}": FRICTION_UNITS[name] for name in FRICTION_FIELDS}}
    return table


def limits(robot, task: str | None = None) -> dict | None:
    """The robot's limits a run's histograms were binned over (:data:`LIMITS`), as plain lists:
    ``joint_range`` (N, 2) rad, ``velocity`` (N,) rad/s (the robot folder's ``tasks.toml``
    ``[limits]``, :func:`faultgen.operation.programs.robot_limits`) and ``task_velocity`` (N,) rad/s,
    the speed limit of ``task`` (a thesis task or a program file, as the run read and planned it,
    :func:`faultgen.simulation.resolve.task`; a replayed log and ``None``, a measured log, run to the
    robot's), with ``units``. None for a robot whose folder has no ``[limits]`` (an MJCF file alone,
    running a program file with its own): the run then does not store them, as files before them.

    Raises
    ------
    ValueError
        For a task that does not load (:class:`faultgen.operation.programs.ProgramError`).
    """
    try:
        velocity = programs.robot_limits(robot)[0]
    except programs.ProgramError:
        return None
    own = programs.kind(task) in (programs.THESIS, *programs.PROGRAM_KINDS)
    task_velocity = resolve.task(robot, task)[0].velocity_limit if own else velocity  # as the run planned it
    return {"joint_range": [[float(lo), float(hi)] for lo, hi in robot.joint_range],
            "velocity": [float(v) for v in velocity], "task_velocity": [float(v) for v in task_velocity],
            "units": dict(LIMITS)}


def config_key(config) -> str:
    """The run configuration as canonical JSON: equal keys mean the same simulation."""
    key = {
        "robot": config.robot, "task": str(config.task), "friction": config.friction,
        **({"program_sha256": program["sha256"]} if (program := programs.record(config.task)) else {}),
        "wear": config.wear.to_dict(), "cycles": int(config.cycles),
        "record": [int(c) for c in config.recorded_cycles], "seed": int(config.seed),
        "noise": asdict(config.noise),
    }
    # a run keeps the key it had before these options existed when it does not use them
    if program and "format" in program:  # a log read through another format than measured
        key["log_format"] = program["format"]
    if config.conditions.active:
        key["conditions"] = config.conditions.to_dict()
    if not config.signals:
        key["signals"] = False
    if config.daily:
        key["daily"] = True
    if config.fault is not None:
        key["fault"] = config.fault.to_dict()
    return json.dumps(key, sort_keys=True)


def is_friction_test(program: dict | None) -> bool:
    """Whether a run's program (:func:`faultgen.operation.programs.record`'s dict; None for a thesis
    task) is a friction test: a program file whose ``process`` is :data:`FRICTION_TEST_PROCESS`."""
    if program is None or "text" not in program:
        return False
    import tomllib

    try:
        return tomllib.loads(program["text"]).get("process") == FRICTION_TEST_PROCESS
    except tomllib.TOMLDecodeError:
        return False


def run_attributes(result, command: str = "") -> dict:
    """Labels and provenance of a run, as HDF5 attributes (strings, numbers, JSON)."""
    config = result.config
    robot = config.model
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
        **({} if (stored := limits(robot, config.task)) is None else {"limits": json.dumps(stored)}),
        "log_period": sensors.LOG_PERIOD,
        "config": config_key(config),
        "command": command,
        **({"conditions": json.dumps(config.conditions.to_dict())} if config.conditions.active else {}),
        "signals": bool(config.signals),
        "sample": "day" if config.daily else "cycle",
        **({"fault": json.dumps(config.fault.to_dict())} if config.fault is not None else {}),
        # a friction test's records, labelled so (absent on every other run, as in files before it)
        **({RECORD_ATTRIBUTE: FRICTION_TEST} if is_friction_test(program) else {}),
        # axes whose motor saturated (a wear or fault too large for the drive): validate reports them
        **({"saturated": np.asarray(result.saturated, dtype=int)} if len(getattr(result, "saturated", ())) else {}),
    }



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
        n_log = int(sim.cycle_duration(config.model, config.task) / sensors.LOG_PERIOD) + 1
        per_cycle += 7 * 4 * n_log * config.model.n_axes
    return n_cycles * per_cycle + 50_000


def write_root(f: h5py.File, n_runs: int, command: str, grid: str) -> None:
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
        write_root(f, 1, command, "")
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
                   for name in condition_arrays(conditions.to_dict() if conditions.active else None)]
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
        write_root(out, len(parts), command, grid)
        out.attrs["complete"] = False
        runs = out.create_group("runs")
        for run_id, part in parts:
            with open_file(part) as src:
                (name,) = list(src["runs"])
                src.copy(src["runs"][name], runs, name=run_id)
        out.attrs["complete"] = True
    return path
