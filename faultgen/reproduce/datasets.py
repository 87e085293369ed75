"""Data shared between tables: thesis Table 6.1 read off j2's last cycle instead of simulated again.
(Two sweeps of one grid with other seeds are combined into one dataset by
:func:`faultgen.data.dataset.combine`, so that j2's seed-0 runs serve both Table 6.2 and the
three-seed detection study.)"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd


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
