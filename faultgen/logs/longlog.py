"""A long measured log read in blocks and averaged down while it is read, so that reading it takes
memory that does not grow with its length (docs/reliability.md, docs/calibration.md "Long logs").
A log in another registered format (:mod:`faultgen.logs.formats`, ``--format NAME``) is read the
same way through its adapter's block reader (:meth:`faultgen.logs.formats.LogFormat.source`), with
the same checks and messages.

``faultgen calibrate`` works on at most ``rows`` rows: a longer log is averaged over blocks of
``k = ceil(n / rows)`` samples (:func:`faultgen.logs.blocks.block_mean`). Reading the whole log first and averaging it
after took 5.7 GB for 10^7 rows. :func:`read` gives the same result in two passes over
the file, :data:`BLOCK_ROWS` rows at a time:

1. the sample times are kept whole (8 bytes a row), every cell is checked (a non-number or
   non-finite cell refused with its data row, as :func:`faultgen.logs.measured.read` does) and,
   per column, the rows that decide the angle and torque checks (smallest, largest, largest in
   magnitude, first out of range) are kept; the time, angle and torque checks then run as for a
   short log, on those rows;
2. the derivatives are estimated block by block with a margin of one filter window on each side
   (the Savitzky-Golay filter is local: a uniformly sampled log gets the derivatives of the whole
   log, bit for bit; a log with a varying period is resampled block by block, which differs from
   the whole-log spline by far less than the filter's own error), the speed checks summed, and
   each block averaged down as it goes.

A log of at most ``rows`` rows is read whole by :func:`faultgen.logs.measured.read` (an adapter's log
by :meth:`faultgen.logs.formats.LogFormat.read`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from faultgen.logs import formats, measured
from faultgen.derivatives import SAVGOL_ORDER, is_uniform, savgol_window
from faultgen.model import robots
from faultgen.logs import blocks, jointlog
from faultgen.logs.columns import column_names

#: Rows read at a time (:data:`faultgen.logs.blocks.BLOCK_ROWS`; rounded up to a whole
#: number of averaging blocks).
BLOCK_ROWS = blocks.BLOCK_ROWS


@dataclass(frozen=True)
class Motion:
    """How much each joint moves over the whole log at its full rate: ``moving`` samples with
    |qd| at or above the rest speed asked for, ``peak`` largest |qd| (rad/s), ``rows`` in all."""

    moving: np.ndarray
    peak: np.ndarray
    rows: int


def decimation_note(n: int, k: int, m: int, rows: int) -> str:
    return f"decimated: {n} rows averaged over blocks of {k} to {m} (calibrate.MAX_ROWS = {rows})"


def motion(qd: np.ndarray, rest_speed: float) -> Motion:
    """:class:`Motion` of full-rate joint speeds ``qd`` (n, N)."""
    peak = np.max(np.abs(qd), axis=0) if len(qd) else np.zeros(qd.shape[1])
    return Motion(np.sum(np.abs(qd) >= rest_speed, axis=0), peak, len(qd))


def read(path: str | Path, robot: robots.Robot, rows: int, rest_speed: float,
         adapter: formats.LogFormat = formats.MEASURED) -> tuple[measured.MeasuredData, Motion]:
    """The log ``path`` in its format ``adapter`` (default the measured format:
    :func:`faultgen.logs.measured.read`'s format and checks), averaged down to at most ``rows`` rows when
    longer (read in blocks of :data:`BLOCK_ROWS` rows: :meth:`faultgen.logs.formats.LogFormat.source`),
    and its :class:`Motion` at the full rate.

    Returns
    -------
    (MeasuredData, Motion)
        ``t`` (m,) s, ``q``, ``qd``, ``qdd``, ``tau`` (m, N) in rad, rad/s, rad/s^2, N m, m <= ``rows``.

    Raises
    ------
    faultgen.logs.measured.MeasuredDataError
        As :func:`faultgen.logs.measured.read` (an adapter's log: as its
        :meth:`~faultgen.logs.formats.LogFormat.read`), naming the file, the column and the data row.
    """
    path = Path(path)
    fmt = adapter
    src = fmt.source(path, robot)
    if src.rows <= rows:
        data = fmt.read(path, robot)
        return data, motion(data.qd, rest_speed)
    first = blocks.scan(src, robot, size=BLOCK_ROWS)
    t, kept, kept_rows = first.t, first.kept, first.kept_rows
    n = len(t)
    if n <= rows:  # fewer rows than lines (blank lines): read whole, as a short log
        data = fmt.read(path, robot)
        return data, motion(data.qd, rest_speed)
    label = src.label
    notes = [f"ignored extra columns: {', '.join(src.extra)}"] if src.extra else []
    notes.extend(src.notes)  # what an adapter chose: first, as its whole read has them
    dt, period = jointlog.check_time(t, path, label, notes)
    index = {name: j for j, name in enumerate(src.wanted)}
    q_names, qd_names, tau_names = column_names(robot.n_axes)
    jointlog.check_angles(path, kept[:, [index[c] for c in q_names]], robot, lambda i: label(int(kept_rows[i])))
    window = savgol_window(period, n)
    uniform = is_uniform(dt, period)
    del dt
    filt = f"Savitzky-Golay, order {SAVGOL_ORDER}, window {window} samples ({window * period:.4g} s)"
    if not uniform:
        notes.append(f"sample period varies ({np.min(np.diff(t)):.6g}..{np.max(np.diff(t)):.6g} s): q resampled "
                     f"at the median period {period:.6g} s with a cubic spline for differentiation (block by block "
                     "with a margin, faultgen.logs.longlog), derivatives interpolated back")
    k = -(-n // rows)
    m = n // k
    inner = measured.velocity_rows(n, window)
    sums = _Sums(robot.n_axes, rest_speed, inner.start or 0, inner.stop if inner.stop is not None else n)
    out = blocks.averaged(src, robot.n_axes, period, window, uniform, k, m, sums.add, BLOCK_ROWS)
    estimated = qd_names[0] not in index
    if estimated:
        notes.append(f"qd and qdd estimated from q: {filt}")
    else:
        notes.append(f"qd from the file; qdd estimated from q: {filt}")
        notes.extend(measured.velocity_verdicts(path, sums.power, sums.cross, sums.size, robot.gear_ratio))
        sides = measured.speed_sides(sums.power, sums.cross, sums.size, robot.gear_ratio)
        out["qd"], sums.peak = out["qd"] / sides, sums.peak / sides  # a motor-side column to the joint side
    notes.extend(measured.torque_notes(kept[:, [index[c] for c in tau_names]], robot))
    notes.append(decimation_note(n, k, m, rows))
    data = measured.MeasuredData(t=out["t"], q=out["q"], qd=out["qd"], qdd=out["qdd"], tau=out["tau"],
                                 source=path, velocity_estimated=estimated, robot=robot.name, notes=tuple(notes))
    return data, Motion(sums.moving, sums.peak, n)


class _Sums:
    """The speed checks' sums over the rows ``inner`` (:func:`faultgen.logs.measured.velocity_verdicts`)
    and the :class:`Motion` at the full rate, block by block."""

    def __init__(self, n_axes: int, rest_speed: float, inner_lo: int, inner_hi: int):
        self.rest_speed, self.inner = rest_speed, (inner_lo, inner_hi)
        self.power, self.cross, self.size = np.zeros(n_axes), np.zeros(n_axes), 0
        self.moving, self.peak = np.zeros(n_axes, dtype=int), np.zeros(n_axes)

    def add(self, start: int, block: np.ndarray, qd_est: np.ndarray, qd: np.ndarray) -> None:
        if qd is not qd_est:  # the file's qd: compared with the derivative of q
            a, b = max(self.inner[0] - start, 0), max(min(self.inner[1] - start, len(block)), 0)
            self.power += np.einsum("ij,ij->j", qd_est[a:b], qd_est[a:b])
            self.cross += np.einsum("ij,ij->j", qd_est[a:b], qd[a:b])
            self.size += max(b - a, 0)
        self.moving += np.sum(np.abs(qd) >= self.rest_speed, axis=0)
        self.peak = np.maximum(self.peak, np.max(np.abs(qd), axis=0))
