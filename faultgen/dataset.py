"""HDF5 files of simulated runs: writer (atomic) and reader.

Layout of a file (h5py; every array carries ``units``, ``axes`` and ``description`` attributes)::

    /                         attrs: format = "faultgen", format_version, faultgen_version,
                                     complete (written last: True only for a finished file)
    /runs/<run id>/           attrs: robot, task, friction_model, cycles, seed, wear (JSON),
                                     noise (JSON), worn_axes, model_sha256, log_period, command
        t                     (n_log,)               s, log times within a cycle
        cycles                (n_cycles,)            1-based indices of the recorded cycles
        q_ref                 (n_log, 6)             rad, reference arm angles
        q_a, q_m              (n_cycles, n_log, 6)   rad, encoder angles, arm / motor side
        qd_a, qd_m            (n_cycles, n_log, 6)   rad/s, encoder speeds, arm / motor side
        tau_m                 (n_cycles, n_log, 6)   N m, motor torque (motor side)
        tau_f                 (n_cycles, n_log, 6)   N m, true friction torque (motor side)
        tau_dist              (n_cycles, n_log, 6)   N m, true load disturbance (arm side)
        friction_multiplier   (n_cycles, 6)          1, true wear multiplier
        mean_friction_torque  (n_cycles, 6)          N m, mean |tau_f| per cycle (motor side)
        tracking_error        (n_cycles, 6)          rad, largest |q_a - q_ref| per cycle

A file is written under a temporary name in the target folder and renamed into place once
complete, so a crash or kill never leaves a file at the target path that looks finished.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from dataclasses import asdict
from pathlib import Path

import h5py
import numpy as np

from faultgen import __version__, robots, sensors
from faultgen.sim import RunResult

FORMAT = "faultgen"
FORMAT_VERSION = 1

#: name -> (units, axes, description) of every array of a run group.
ARRAYS = {
    "t": ("s", "sample", "log time within a cycle"),
    "cycles": ("1", "cycle", "1-based index of each recorded cycle"),
    "q_ref": ("rad", "sample, axis", "reference arm angle"),
    "q_a": ("rad", "cycle, sample, axis", "arm angle from the encoder"),
    "q_m": ("rad", "cycle, sample, axis", "motor angle from the encoder (motor side)"),
    "qd_a": ("rad/s", "cycle, sample, axis", "arm speed, backward difference of q_a"),
    "qd_m": ("rad/s", "cycle, sample, axis", "motor speed, backward difference of q_m (motor side)"),
    "tau_m": ("N m", "cycle, sample, axis", "motor torque (drive output, motor side)"),
    "tau_f": ("N m", "cycle, sample, axis", "true friction torque, motor side, positive opposing positive motion"),
    "tau_dist": ("N m", "cycle, sample, axis", "true load disturbance on the arm joint (arm side)"),
    "friction_multiplier": ("1", "cycle, axis", "true wear multiplier of Coulomb and static friction"),
    "mean_friction_torque": ("N m", "cycle, axis", "mean absolute true friction torque per cycle (motor side)"),
    "tracking_error": ("rad", "cycle, axis", "largest absolute error of the true arm angle against q_ref"),
}


def model_hash(path: Path) -> str:
    """SHA-256 of a robot's MJCF file, hex."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def run_attributes(result: RunResult, command: str = "") -> dict:
    """Labels and provenance of a run, as HDF5 attributes (strings, numbers, JSON)."""
    config = result.config
    robot = robots.load(config.robot)
    return {
        "robot": robot.name,
        "task": config.task,
        "friction_model": config.friction,
        "cycles": int(config.cycles),
        "seed": int(config.seed),
        "worn_axes": np.array(config.wear.worn_axes, dtype=int),
        "wear": json.dumps(config.wear.to_dict()),
        "noise": json.dumps(asdict(config.noise)),
        "model_sha256": model_hash(robot.path),
        "log_period": sensors.LOG_PERIOD,
        "faultgen_version": __version__,
        "command": command,
    }


def write_run(path: str | Path, result: RunResult, run_id: str = "run", command: str = "") -> Path:
    """Write one run to a new HDF5 file at ``path``, atomically.

    Raises
    ------
    OSError
        If the folder cannot be written (the message names it); nothing is left at ``path``.
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise OSError(f"cannot write {path}: folder {folder} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=folder)
    os.close(fd)
    try:
        with h5py.File(tmp, "w") as f:
            f.attrs["format"] = FORMAT
            f.attrs["format_version"] = FORMAT_VERSION
            f.attrs["faultgen_version"] = __version__
            f.attrs["complete"] = False
            group = f.create_group(f"runs/{run_id}")
            for key, value in run_attributes(result, command).items():
                group.attrs[key] = value
            for name, (units, axes, description) in ARRAYS.items():
                data = np.asarray(getattr(result, name))
                chunked = data.ndim == 3
                ds = group.create_dataset(
                    name, data=data, compression="gzip" if chunked else None,
                    chunks=(1, data.shape[1], 6) if chunked else None, shuffle=chunked,
                )
                ds.attrs["units"] = units
                ds.attrs["axes"] = axes
                ds.attrs["description"] = description
            f.attrs["complete"] = True
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the file normal permissions
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def read_run(path: str | Path, run_id: str = "run") -> tuple[dict[str, np.ndarray], dict]:
    """Read one run: its arrays by name and its attributes.

    Raises
    ------
    ValueError
        If the file is not a finished faultgen file or has no such run (the message says which).
    """
    with h5py.File(path, "r") as f:
        if f.attrs.get("format") != FORMAT:
            raise ValueError(f"{path} is not a faultgen file (format attribute {f.attrs.get('format')!r})")
        if not f.attrs.get("complete", False):
            raise ValueError(f"{path} is incomplete: its writer did not finish")
        if f"runs/{run_id}" not in f:
            raise ValueError(f"{path} has no run {run_id!r}; runs: {', '.join(f['runs'])}")
        group = f[f"runs/{run_id}"]
        arrays = {name: group[name][()] for name in group}
        attrs = {key: group.attrs[key] for key in group.attrs}
    return arrays, attrs
