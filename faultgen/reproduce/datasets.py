"""Data shared between tables: two sweeps of the same grid with other seeds combined into one
dataset (so that j2's seed-0 runs serve both Table 6.2 and the three-seed detection study), and
thesis Table 6.1 read off j2's last cycle instead of simulated again."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd


def combine(files: Sequence[str | Path], out: str | Path) -> Path:
    """Copy the runs of ``files`` (faultgen datasets) into one new dataset ``out``, atomically.

    The root attributes are those of the first file, with ``n_runs`` and ``command`` updated; run
    groups are copied as stored. Raises ValueError if a run id appears in two files or a file is
    not a complete faultgen dataset (validation names the problem).
    """
    import h5py

    from faultgen.data import atomic, dataset

    files = [Path(f) for f in files]
    for path in files:
        problems = dataset.validate(path)
        if problems:
            raise ValueError(f"{path} fails validation (run `faultgen validate {path}`): {problems[0]}")
    seen: dict[str, Path] = {}
    for path in files:
        for run_id in dataset.list_runs(path):
            if run_id in seen:
                raise ValueError(f"run {run_id!r} is in both {seen[run_id]} and {path}; combine datasets of other seeds")
            seen[run_id] = path
    out = Path(out)
    with atomic.hdf5_writer(out) as dst:
        with h5py.File(files[0], "r") as first:
            for key, value in first.attrs.items():
                dst.attrs[key] = value
        dst.attrs["n_runs"] = len(seen)
        dst.attrs["command"] = "combined by faultgen reproduce from " + ", ".join(f.name for f in files)
        runs = dst.create_group("runs")
        for path in files:
            with h5py.File(path, "r") as src:
                for run_id in src["runs"]:
                    src.copy(src["runs"][run_id], runs, name=run_id)
    return out


def last_cycle_torque(path: str | Path) -> pd.DataFrame:
    """Thesis Table 6.1's layout from a sweep with signals: per task and worn axis (0: no wear),
    the mean and standard deviation of |motor torque| (N m) of every axis in each run's last
    recorded cycle, and the worn axis's rise of the mean against the run without wear of its task
    and seed.

    Returns a DataFrame: task, seed, worn_axis, cycle, then ``mean_K`` and ``std_K`` per axis K
    (1-based), and ``rise`` (N m; NaN for the runs without wear). Raises ValueError if the
    dataset holds no signals (a ``--features-only`` sweep).
    """
    import faultgen

    rows = []
    with faultgen.open(path) as data:
        for run in data.runs:
            if not run.has("tau_m"):
                raise ValueError(f"{path}: run {run.id} holds no signals; Table 6.1 needs a sweep with signals")
            torque = np.abs(run.signal("tau_m")[-1])
            axes = run.worn_axes
            row = {"task": run.task, "seed": run.seed, "worn_axis": axes[0] if axes else 0,
                   "cycle": int(run.recorded[-1])}
            for k in range(torque.shape[1]):
                row[f"mean_{k + 1}"] = float(torque[:, k].mean())
                row[f"std_{k + 1}"] = float(torque[:, k].std())
            rows.append(row)
    table = pd.DataFrame(rows).sort_values(["task", "seed", "worn_axis"]).reset_index(drop=True)
    base = table[table["worn_axis"] == 0].set_index(["task", "seed"])
    table["rise"] = [row[f"mean_{row['worn_axis']}"] - base.loc[(row["task"], row["seed"]), f"mean_{row['worn_axis']}"]
                     if row["worn_axis"] and (row["task"], row["seed"]) in base.index else np.nan
                     for _, row in table.iterrows()]
    return table
