"""A long measured log read in blocks and averaged down while it is read, so that reading it takes
memory that does not grow with its length (docs/reliability.md, docs/calibration.md "Long logs").

``faultgen calibrate`` works on at most ``rows`` rows: a longer log is averaged over blocks of
``k = ceil(n / rows)`` samples (:func:`block_mean`). Reading the whole log first and averaging it
after took 5.7 GB for 10^7 rows (issue 50). :func:`read` gives the same result in two passes over
the file, :data:`BLOCK_ROWS` rows at a time:

1. the sample times are kept whole (8 bytes a row), every cell is checked (a non-number or
   non-finite cell refused with its data row, as :func:`faultgen.data.measured.read` does) and,
   per column, the rows that decide the angle and torque checks (smallest, largest, largest in
   magnitude, first out of range) are kept; the time, angle and torque checks then run as for a
   short log, on those rows;
2. the derivatives are estimated block by block with a margin of one filter window on each side
   (the Savitzky-Golay filter is local: a uniformly sampled log gets the derivatives of the whole
   log, bit for bit; a log with a varying period is resampled block by block, which differs from
   the whole-log spline by far less than the filter's own error), the speed checks summed, and
   each block averaged down as it goes.

A log of at most ``rows`` rows is read whole by :func:`faultgen.data.measured.read`.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from faultgen import inputs
from faultgen.data import measured
from faultgen.derivatives import SAVGOL_ORDER
from faultgen.derivatives import derivatives as _derivatives
from faultgen.derivatives import is_uniform as _is_uniform
from faultgen.derivatives import savgol_window as _savgol_window
from faultgen.model import robots

#: Rows read at a time (rounded up to a whole number of averaging blocks).
BLOCK_ROWS = 200_000


@dataclass(frozen=True)
class Motion:
    """How much each joint moves over the whole log at its full rate: ``moving`` samples with
    |qd| at or above the rest speed asked for, ``peak`` largest |qd| (rad/s), ``rows`` in all."""

    moving: np.ndarray
    peak: np.ndarray
    rows: int


def block_mean(a: np.ndarray, k: int, m: int) -> np.ndarray:
    """The first ``m * k`` rows of ``a`` averaged over consecutive blocks of ``k``: ``m`` rows."""
    return a[: m * k].reshape(m, k, *a.shape[1:]).mean(axis=1)


def decimation_note(n: int, k: int, m: int, rows: int) -> str:
    return f"decimated: {n} rows averaged over blocks of {k} to {m} (calibrate.MAX_ROWS = {rows})"


def motion(qd: np.ndarray, rest_speed: float) -> Motion:
    """:class:`Motion` of full-rate joint speeds ``qd`` (n, N)."""
    peak = np.max(np.abs(qd), axis=0) if len(qd) else np.zeros(qd.shape[1])
    return Motion(np.sum(np.abs(qd) >= rest_speed, axis=0), peak, len(qd))


def read(path: str | Path, robot: robots.Robot, rows: int, rest_speed: float) -> tuple[measured.MeasuredData, Motion]:
    """The measured log ``path`` (:func:`faultgen.data.measured.read`'s format and checks), averaged
    down to at most ``rows`` rows when longer, and its :class:`Motion` at the full rate.

    Raises
    ------
    faultgen.data.measured.MeasuredDataError
        As :func:`faultgen.data.measured.read`, naming the file, the column and the data row.
    """
    path = Path(path)
    kind = measured._kind(path)
    measured._regular(path)
    source = _Csv(path, robot.n_axes) if kind == "csv" else _Hdf5(path, robot.n_axes)
    if source.rows <= rows:
        data = measured.read(path, robot)
        return data, motion(data.qd, rest_speed)
    return _Reader(source, robot, rows, rest_speed).read()


class _Csv:
    """A CSV log's wanted columns in blocks of rows (as float arrays, in the order ``wanted``)."""

    label = staticmethod(measured._csv_label)

    def __init__(self, path: Path, n_axes: int):
        self.path = path
        try:
            with inputs.open_text(path, "measured log") as fh:
                header = next(csv.reader(fh), None)
            lines = inputs.count_lines(path, "measured log")
        except inputs.InputError as err:
            raise measured.MeasuredDataError(str(err)) from None
        except (OSError, UnicodeDecodeError, EOFError, csv.Error) as err:
            raise measured.MeasuredDataError(f"{path}: cannot read the file as CSV: {err}") from err
        self.names = [h.strip() for h in header or []]
        self.wanted, self.extra = (measured._select_columns(path, self.names, n_axes) if header
                                   else ([], []))
        self.rows = max(lines - 1, 0) if self.wanted else 0  # an upper bound: blank lines count here
        if self.rows > measured.MAX_ROWS:
            raise measured.MeasuredDataError(f"{path}: {self.rows} data rows; a log has at most {measured.MAX_ROWS} "
                                             "(MAX_ROWS: a day at 1 kHz)")

    def blocks(self, size: int) -> Iterator[tuple[int, np.ndarray]]:
        start = 0
        for frame in self._frames(size, float):
            block = frame.to_numpy(dtype=float)
            if not len(block):
                continue
            if not np.isfinite(block).all():
                self._refuse(size)
            yield start, block
            start += len(block)

    def _frames(self, size: int, dtype) -> Iterator[pd.DataFrame]:
        kw = {"header": 0, "names": self.names, "index_col": False, "usecols": self.wanted, "chunksize": size}
        if dtype is str:
            kw.update(keep_default_na=False, na_filter=False)
        try:
            with inputs.open_text(self.path, "measured log") as fh:
                for frame in pd.read_csv(fh, dtype=dtype, **kw):
                    yield frame[self.wanted]
        except inputs.InputError as err:
            raise measured.MeasuredDataError(str(err)) from None
        except measured.MeasuredDataError:
            raise
        except (OSError, EOFError, UnicodeDecodeError, pd.errors.ParserError, pd.errors.EmptyDataError) as err:
            raise measured.MeasuredDataError(f"{self.path}: cannot read the file as CSV: {err}") from err
        except (ValueError, TypeError):  # a cell that is not a number: found and named from the text
            if dtype is str:
                raise
            self._refuse(size)

    def _refuse(self, size: int):
        """Find the first cell that is not a finite number (from the text) and refuse it by row."""
        start = 0
        for text in self._frames(size, str):
            first = None
            for order, name in enumerate(self.wanted):
                raw = text[name].str.strip()
                bad = np.flatnonzero(~np.isfinite(pd.to_numeric(raw, errors="coerce").to_numpy(dtype=float)))
                if bad.size and (first is None or bad[0] < first[0]):
                    first = (int(bad[0]), name, str(raw.iloc[bad[0]]))
            if first is not None:
                row, name, raw = first
                raise measured.MeasuredDataError(f"{self.path}: {self.label(start + row)}, column {name}: "
                                                 f"{measured._describe_bad_cell(raw)}")
            start += len(text)
        raise measured.MeasuredDataError(f"{self.path}: cannot read the file as CSV: a cell is not a number")


class _Hdf5:
    """An HDF5 log's wanted root datasets in blocks of rows."""

    label = staticmethod(measured._index_label)

    def __init__(self, path: Path, n_axes: int):
        self.path = path
        with measured._open_hdf5(path) as fh:
            self.wanted, self.extra = measured.hdf5_columns(fh, path, n_axes)
            lengths = {name: fh[name].shape for name in self.wanted}
        shapes = set(lengths.values())
        if len(shapes) != 1 or len(next(iter(shapes))) != 1:
            # irregular shapes: the whole-file reader names the dataset at fault
            self.rows = 0
            return
        self.rows = next(iter(shapes))[0]
        if self.rows > measured.MAX_ROWS:
            raise measured.MeasuredDataError(f"{path}: {self.rows} rows; a log has at most {measured.MAX_ROWS} "
                                             "(MAX_ROWS: a day at 1 kHz)")

    def blocks(self, size: int) -> Iterator[tuple[int, np.ndarray]]:
        with measured._open_hdf5(self.path) as fh:
            for start in range(0, self.rows, size):
                block = np.column_stack([np.asarray(fh[name][start:start + size], dtype=float)
                                         for name in self.wanted])
                columns = {name: block[:, j] for j, name in enumerate(self.wanted)}
                measured._refuse_non_finite(self.path, columns, self.wanted,
                                            lambda i, s=start: self.label(s + i))
                yield start, block


class _Reader:
    def __init__(self, source, robot: robots.Robot, rows: int, rest_speed: float):
        self.source, self.robot, self.rows, self.rest_speed = source, robot, rows, rest_speed
        self.path = source.path
        n = robot.n_axes
        q_names, qd_names, tau_names = measured.column_names(n)
        index = {name: j for j, name in enumerate(source.wanted)}
        self.t_col = index[measured.T_COLUMN]
        self.q_cols = [index[c] for c in q_names]
        self.tau_cols = [index[c] for c in tau_names]
        self.qd_cols = [index[c] for c in qd_names] if qd_names[0] in index else None

    def _first_pass(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The whole sample times, and the rows that decide the angle and torque checks (their
        values, and their data rows, sorted)."""
        times, kept = [], {}
        low, high = self.robot.joint_range[:, 0], self.robot.joint_range[:, 1]
        tol = measured.JOINT_RANGE_TOLERANCE
        for start, block in self.source.blocks(BLOCK_ROWS):
            times.append(block[:, self.t_col].copy())
            q, tau = block[:, self.q_cols], block[:, self.tau_cols]
            rows = [np.argmin(q, axis=0), np.argmax(q, axis=0), np.argmax(np.abs(q), axis=0),
                    np.argmax(np.abs(tau), axis=0)]
            outside = (q < low - tol) | (q > high + tol)
            rows.append(np.argmax(outside, axis=0)[outside.any(axis=0)])
            for i in np.unique(np.concatenate(rows)):
                kept[start + int(i)] = block[i]
        order = sorted(kept)
        if not order:
            return np.empty(0), np.empty((0, len(self.source.wanted))), np.empty(0, dtype=int)
        return np.concatenate(times), np.array([kept[i] for i in order]), np.array(order)

    def read(self) -> tuple[measured.MeasuredData, Motion]:
        path, label = self.path, self.source.label
        t, kept, kept_rows = self._first_pass()
        n = len(t)
        if n <= self.rows:  # fewer rows than lines (blank lines): read whole, as a short log
            data = measured.read(path, self.robot)
            return data, motion(data.qd, self.rest_speed)
        notes = [f"ignored extra columns: {', '.join(self.source.extra)}"] if self.source.extra else []
        dt, period = measured.check_time(t, path, label, notes)
        measured._check_angles(path, kept[:, self.q_cols], self.robot, lambda i: label(int(kept_rows[i])))
        window = _savgol_window(period, n)
        uniform = _is_uniform(dt, period)
        del dt
        filt = f"Savitzky-Golay, order {SAVGOL_ORDER}, window {window} samples ({window * period:.4g} s)"
        if not uniform:
            notes.append(f"sample period varies ({np.min(np.diff(t)):.6g}..{np.max(np.diff(t)):.6g} s): q resampled "
                         f"at the median period {period:.6g} s with a cubic spline for differentiation (block by block "
                         "with a margin, faultgen.data.longlog), derivatives interpolated back")
        k = -(-n // self.rows)
        m = n // k
        out = self._second_pass(t, period, window, uniform, k, m)
        estimated = self.qd_cols is None
        if estimated:
            notes.append(f"qd and qdd estimated from q: {filt}")
        else:
            notes.append(f"qd from the file; qdd estimated from q: {filt}")
            notes.extend(measured.velocity_verdicts(path, out["power"], out["cross"], out["size"]))
        notes.extend(measured._torque_notes(kept[:, self.tau_cols], self.robot))
        notes.append(decimation_note(n, k, m, self.rows))
        data = measured.MeasuredData(t=block_mean(t, k, m), q=out["q"], qd=out["qd"], qdd=out["qdd"], tau=out["tau"],
                                     source=path, velocity_estimated=estimated, robot=self.robot.name,
                                     notes=tuple(notes))
        return data, Motion(out["moving"], out["peak"], n)

    def _second_pass(self, t: np.ndarray, period: float, window: int, uniform: bool, k: int, m: int) -> dict:
        n_axes = self.robot.n_axes
        margin = window if uniform else max(window, 200)
        inner = measured.velocity_rows(len(t), window)
        inner_lo, inner_hi = inner.start or 0, inner.stop if inner.stop is not None else len(t)
        acc = {"q": [], "qd": [], "qdd": [], "tau": [], "power": np.zeros(n_axes), "cross": np.zeros(n_axes),
               "size": 0, "moving": np.zeros(n_axes, dtype=int), "peak": np.zeros(n_axes)}
        size = k * math.ceil(BLOCK_ROWS / k)  # blocks start on a whole averaging block
        left = np.empty((0, len(self.source.wanted)))
        pending = None
        for start, block in self.source.blocks(size):
            if pending is not None:
                self._emit(acc, t, pending, left, block[:margin], period, window, uniform, k, m,
                           (inner_lo, inner_hi))
                left = np.concatenate([left, pending[1]])[-margin:]
            pending = (start, block)
        self._emit(acc, t, pending, left, np.empty((0, left.shape[1])), period, window, uniform, k, m,
                   (inner_lo, inner_hi))
        for name in ("q", "qd", "qdd", "tau"):
            acc[name] = np.concatenate(acc[name])
        return acc

    def _emit(self, acc: dict, t: np.ndarray, pending, left, right, period, window, uniform, k, m, inner) -> None:
        start, block = pending
        rows = np.concatenate([left, block, right])
        lo = start - len(left)
        q = rows[:, self.q_cols]
        qd_est, qdd = (d[len(left): len(left) + len(block)]
                       for d in _derivatives(t[lo: lo + len(rows)], q, period, window, uniform))
        qd = qd_est if self.qd_cols is None else np.ascontiguousarray(block[:, self.qd_cols])
        if self.qd_cols is not None:
            a, b = max(inner[0] - start, 0), max(min(inner[1] - start, len(block)), 0)
            acc["power"] += np.einsum("ij,ij->j", qd_est[a:b], qd_est[a:b])
            acc["cross"] += np.einsum("ij,ij->j", qd_est[a:b], qd[a:b])
            acc["size"] += max(b - a, 0)
        acc["moving"] += np.sum(np.abs(qd) >= self.rest_speed, axis=0)
        acc["peak"] = np.maximum(acc["peak"], np.max(np.abs(qd), axis=0))
        whole = max(min(m * k - start, len(block)), 0) // k  # averaging blocks within this block
        # contiguous, as the whole-log reader's columns: the same sums in the same order, bit for bit
        q, tau = (np.ascontiguousarray(block[:, cols]) for cols in (self.q_cols, self.tau_cols))
        for name, values in (("q", q), ("qd", qd), ("qdd", qdd), ("tau", tau)):
            acc[name].append(block_mean(values, k, whole))
