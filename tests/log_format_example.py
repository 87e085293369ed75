"""A log format added in one file (issue 57: "adding a log format touches 1 file"): a controller
export with time in milliseconds, angles in degrees and torques in N m, tab-separated, ``.tsv``.

Importing this module registers it (:func:`faultgen.logs.formats.register`); from then on
``--format deg-ms`` reads it in ``faultgen logs import``, ``faultgen calibrate``, ``faultgen
monitor`` and ``faultgen simulate --task LOG`` (the replay), with the measured format's checks
(:func:`faultgen.logs.measured.from_columns`; the replay's, :func:`faultgen.operation.replay.from_columns`). A format
shipped with faultgen is the same class in ``faultgen/logs/formats.py``. tests/test_log_formats.py
uses it.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from faultgen.logs import formats, measured


@formats.register("deg-ms")
@dataclass(frozen=True)
class DegreesMilliseconds(formats.LogFormat):
    """``time_ms`` (ms), ``angle_deg_1..N`` (deg), ``torque_Nm_1..N`` (N m at the arm), tab-separated.

    The column mapping and units alone (:meth:`convert` of one block of the file, read as
    tab-separated text by the base class): the base reads the file whole or in blocks with it."""

    suffixes: tuple[str, ...] = (".tsv",)
    separator = "\t"

    def convert(self, frame, robot):
        n_axes = robot.n_axes
        q_names, _, tau_names = measured.column_names(n_axes)
        out = {measured.T_COLUMN: frame["time_ms"].to_numpy(float) / 1000.0}
        for k in range(n_axes):
            out[q_names[k]] = np.radians(frame[f"angle_deg_{k + 1}"].to_numpy(float))
            out[tau_names[k]] = frame[f"torque_Nm_{k + 1}"].to_numpy(float)
        return out


def write(source: Path, path: Path) -> Path:
    """The measured-format log ``source`` (CSV) written at ``path`` in this layout (its q and tau
    columns only)."""
    frame = pd.read_csv(source)
    n_axes = sum(1 for c in frame.columns if c.startswith("tau"))
    table = {"time_ms": frame["t"] * 1000.0}
    for k in range(1, n_axes + 1):
        table[f"angle_deg_{k}"] = np.degrees(frame[f"q{k}"])
    for k in range(1, n_axes + 1):
        table[f"torque_Nm_{k}"] = frame[f"tau{k}"]
    pd.DataFrame(table).to_csv(path, sep="\t", index=False, float_format="%.17g")
    return path


def measured_copy(path: Path, robot, out: Path) -> Path:
    """The numbers this adapter reads from ``path``, written at ``out`` in the measured format
    (``t, q1..qN, tau1..tauN``, 17 digits: read back bit for bit), for comparing a command's
    outputs on both."""
    columns = DegreesMilliseconds().columns(path, robot)[0]
    pd.DataFrame(columns).to_csv(out, index=False, float_format="%.17g")
    return out
