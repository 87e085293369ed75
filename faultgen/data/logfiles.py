"""A measured log written in the measured format (:mod:`faultgen.logs.measured`, the format read
by :func:`faultgen.logs.measured.read`): CSV (through :mod:`faultgen.data.cells`) or HDF5, what a
test, a benchmark or ``calibrate``'s synthetic log writes for the readers to take."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from faultgen import axes
from faultgen.data import cells
from faultgen.logs.columns import CSV_SUFFIXES, HDF5_SUFFIXES, T_COLUMN, UNITS, column_names


def _compression(path: Path) -> str | None:
    """The compression a file written under this name gets: gzip for ``.gz``."""
    return "gzip" if path.name.lower().endswith(".gz") else None


def _table(t, q, tau, qd) -> dict[str, np.ndarray]:
    t = np.asarray(t, dtype=float)
    if t.ndim != 1:
        raise ValueError(f"t must have shape (n,), got {t.shape}")
    n_axes = np.shape(q)[1] if np.ndim(q) == 2 else 0  # the robot's N, as q gives it
    if not axes.MIN_AXES <= n_axes <= axes.MAX_AXES:
        raise ValueError(f"q must have shape ({t.shape[0]}, N), N {axes.MIN_AXES}..{axes.MAX_AXES}, got {np.shape(q)}")
    q_columns, qd_columns, tau_columns = column_names(n_axes)
    blocks = (
        [("q", q, q_columns)]
        + ([("qd", qd, qd_columns)] if qd is not None else [])
        + [("tau", tau, tau_columns)]
    )
    table = {T_COLUMN: t}
    for label, arr, names in blocks:
        arr = np.asarray(arr, dtype=float)
        if arr.shape != (t.shape[0], n_axes):
            raise ValueError(f"{label} must have shape ({t.shape[0]}, {n_axes}), got {arr.shape}")
        table.update({name: arr[:, k] for k, name in enumerate(names)})
    return table


def write_csv(
    path: str | Path, t: np.ndarray, q: np.ndarray, tau: np.ndarray, qd: np.ndarray | None = None
) -> Path:
    """Write measured data as CSV (gzip-compressed when the name ends in ``.csv.gz``).

    Columns ``t, q1..qN[, qd1..qdN], tau1..tauN`` (N the columns of ``q``) with a header row; floats are written with
    the shortest representation that reads back to the same float64. The values are not
    checked (so tests can write files that :func:`read` refuses), only the shapes.

    Parameters
    ----------
    path : str or Path
        Ending in ``.csv`` or ``.csv.gz``.
    t : array_like of shape (n,)
        Sample times in s.
    q, tau : array_like of shape (n, N)
        Arm-side joint angles (rad) and torques (N m), N = 5..7 axes.
    qd : array_like of shape (n, N), optional
        Arm-side joint velocities in rad/s; no ``qd`` columns when omitted.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    ValueError
        If the suffix is not ``.csv`` / ``.csv.gz`` or an array has the wrong shape.
    """
    path = Path(path)
    if not path.name.lower().endswith(CSV_SUFFIXES):
        raise ValueError(f"{path}: write_csv writes {' or '.join(CSV_SUFFIXES)} files")
    frame = pd.DataFrame(_table(t, q, tau, qd))
    # gzip level 6 (zlib's default) writes about as small as 9 in half the time; mtime 0 keeps
    # the file byte-identical for identical data.
    compression = {"method": "gzip", "compresslevel": 6, "mtime": 0} if _compression(path) else None
    cells.escaped(frame).to_csv(path, index=False, compression=compression)
    return path


def write_hdf5(
    path: str | Path, t: np.ndarray, q: np.ndarray, tau: np.ndarray, qd: np.ndarray | None = None
) -> Path:
    """Write measured data as HDF5: one float64 1-D dataset per column at the root, with its unit.

    Parameters and returns as :func:`write_csv`; ``path`` ends in ``.h5`` or ``.hdf5``. Each
    dataset carries a ``unit`` attribute (``s``, ``rad``, ``rad/s``, ``N m``).

    Raises
    ------
    ValueError
        If the suffix is not ``.h5`` / ``.hdf5`` or an array has the wrong shape.
    """
    path = Path(path)
    if not path.name.lower().endswith(HDF5_SUFFIXES):
        raise ValueError(f"{path}: write_hdf5 writes {' or '.join(HDF5_SUFFIXES)} files")
    table = _table(t, q, tau, qd)
    from faultgen.data.atomic import hdf5_writer

    with hdf5_writer(path) as fh:  # a full disk: OSError, never a crash nor a partial file
        for name, values in table.items():
            ds = fh.create_dataset(name, data=values)
            ds.attrs["unit"] = UNITS[name]
    return path
