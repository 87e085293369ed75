"""A joint log (:mod:`faultgen.logs.jointlog`) read in blocks of rows and averaged down while
it is read, so that reading a long log takes memory that does not grow with its length
(docs/reliability.md; docs/calibration.md "Long logs").

Two passes over the file, :data:`BLOCK_ROWS` rows at a time:

1. :func:`scan`: every cell checked (a non-number or non-finite cell refused with its data row, as
   the whole-file reader does); per column the rows that decide the angle and torque checks
   (smallest, largest, largest in magnitude, first out of range) kept; the sample times either
   kept whole (8 bytes a row: the calibration, whose time checks then run as for a short log) or
   checked as they stream by (:class:`TimeScan`: increasing, gaps, span, the median period of
   each block; a replayed log, whose memory must not grow with its rows at all);
2. :func:`averaged`: the derivatives estimated block by block with a margin of one filter window
   on each side (the Savitzky-Golay filter is local: a uniformly sampled log gets the derivatives
   of the whole log, bit for bit; a log with a varying period is resampled block by block, which
   differs from the whole-log spline by far less than the filter's own error), each block averaged
   over ``k`` consecutive rows (:func:`block_mean`) as it goes: the calibration; or
2. :func:`thinned`: every ``k``-th row kept, the rest dropped as it goes: a replay, whose reference
   is sampled at the physics step and must pass through the log's own samples.

The passes read a *block source*: ``path``; ``wanted``, the measured format's columns read (the
order of a block's columns); ``extra``, the file's columns ignored; ``notes``, what the reading
chose; ``rows``, an upper bound of the data rows, known before they are parsed; ``label``, data
row index -> its name in messages; and ``blocks(size)``, yielding ``(start, block)``: the index of
the block's first data row and a float array of shape (size, len(wanted)) (the last block shorter),
every cell refused unless finite (a :class:`~faultgen.logs.columns.LogError` naming the file,
the data row and the column). :func:`source` gives the measured format's (:class:`Csv`,
:class:`Hdf5`); every log format has one (:meth:`faultgen.logs.formats.LogFormat.source`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from faultgen import inputs
from faultgen.derivatives import derivatives as _derivatives
from faultgen.model import robots
from faultgen.logs import jointlog
from faultgen.logs.columns import JOINT_RANGE_TOLERANCE, MAX_GAP, MAX_ROWS, T_COLUMN, LogError, column_names

#: Rows read at a time (rounded up to a whole number of averaging blocks).
BLOCK_ROWS = 200_000


def block_mean(a: np.ndarray, k: int, m: int) -> np.ndarray:
    """The first ``m * k`` rows of ``a`` averaged over consecutive blocks of ``k``: ``m`` rows."""
    return a[: m * k].reshape(m, k, *a.shape[1:]).mean(axis=1)


def source(path: Path, n_axes: int, motion_only: bool = False):
    """The log ``path`` as blocks of its wanted columns (:class:`Csv` or :class:`Hdf5`), its header or
    datasets checked (:func:`faultgen.logs.jointlog.select_columns`)."""
    kind = jointlog.kind(path)
    jointlog.regular(path)
    return Csv(path, n_axes, motion_only) if kind == "csv" else Hdf5(path, n_axes, motion_only)


class Csv:
    """A CSV log's wanted columns in blocks of rows (as float arrays, in the order ``wanted``);
    ``rows`` an upper bound of its data rows (blank lines count)."""

    label = staticmethod(jointlog.csv_label)
    notes: tuple[str, ...] = ()

    def __init__(self, path: Path, n_axes: int, motion_only: bool = False):
        self.path = path
        header = jointlog.header(path)  # bounded: CSV_MAX_COLUMNS, CSV_HEADER_MAX_BYTES
        try:
            lines = inputs.count_lines(path, "joint log", inputs.CSV_ROW_MAX_BYTES)
        except inputs.InputError as err:
            raise LogError(str(err)) from None
        except (OSError, UnicodeDecodeError, EOFError) as err:
            raise LogError(f"{path}: cannot read the file as CSV: {err}") from err
        self.names = header
        self.wanted, self.extra = (jointlog.select_columns(path, self.names, n_axes, motion_only) if header
                                   else ([], []))
        self.rows = max(lines - 1, 0) if self.wanted else 0  # an upper bound: blank lines count here
        if self.rows > MAX_ROWS:
            raise LogError(f"{path}: {self.rows} data rows; a log has at most {MAX_ROWS} "
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
            with inputs.open_text(self.path, "joint log") as fh:
                for frame in pd.read_csv(fh, dtype=dtype, **kw):
                    yield frame[self.wanted]
        except inputs.InputError as err:
            raise LogError(str(err)) from None
        except LogError:
            raise
        except (OSError, EOFError, UnicodeDecodeError, pd.errors.ParserError, pd.errors.EmptyDataError) as err:
            raise LogError(f"{self.path}: cannot read the file as CSV: {err}") from err
        except (ValueError, TypeError):  # a cell that is not a number: found and named from the text
            if dtype is str:
                raise
            self._refuse(size)

    def _refuse(self, size: int):
        """Find the first cell that is not a finite number (from the text) and refuse it by row."""
        start = 0
        for text in self._frames(size, str):
            first = None
            for name in self.wanted:
                raw = text[name].str.strip()
                bad = np.flatnonzero(~np.isfinite(pd.to_numeric(raw, errors="coerce").to_numpy(dtype=float)))
                if bad.size and (first is None or bad[0] < first[0]):
                    first = (int(bad[0]), name, str(raw.iloc[bad[0]]))
            if first is not None:
                row, name, raw = first
                raise LogError(f"{self.path}: {self.label(start + row)}, column {name}: "
                               f"{jointlog.describe_bad_cell(raw)}")
            start += len(text)
        raise LogError(f"{self.path}: cannot read the file as CSV: a cell is not a number")


class Hdf5:
    """An HDF5 log's wanted root datasets in blocks of rows, each checked from its metadata first
    (:func:`faultgen.logs.jointlog.hdf5_rows`: a dataset not 1-D, of text, of another length or
    above MAX_ROWS refused, named)."""

    label = staticmethod(jointlog.index_label)
    notes: tuple[str, ...] = ()

    def __init__(self, path: Path, n_axes: int, motion_only: bool = False):
        self.path = path
        with jointlog.open_hdf5(path) as fh:
            self.wanted, self.extra = jointlog.hdf5_columns(fh, path, n_axes, motion_only)
            self.rows = jointlog.hdf5_rows(fh, path, self.wanted)

    def blocks(self, size: int) -> Iterator[tuple[int, np.ndarray]]:
        with jointlog.open_hdf5(self.path) as fh:
            for start in range(0, self.rows, size):
                block = np.column_stack([np.asarray(fh[name][start:start + size], dtype=float)
                                         for name in self.wanted])
                columns = {name: block[:, j] for j, name in enumerate(self.wanted)}
                jointlog.refuse_non_finite(self.path, columns, self.wanted, lambda i, s=start: self.label(s + i))
                yield start, block


@dataclass
class TimeScan:
    """The sample times checked as they stream by, none of them kept: strictly increasing, no
    interval above :data:`faultgen.logs.columns.MAX_GAP`; ``limit(first, last, rows)`` may
    refuse the log as soon as a block shows it too long. The sample rate checked is that of the
    median of the blocks' median intervals (the exact median would need every interval at once)."""

    path: Path
    label: Callable[[int], str]
    limit: Callable[[float, float, int], None] = lambda first, last, rows: None
    rows: int = 0
    first: float = math.nan
    last: float = math.nan
    high: float = 0.0
    gap_row: int = 0
    medians: list = field(default_factory=list)

    def add(self, start: int, t: np.ndarray) -> None:
        dt = np.diff(np.concatenate([[self.last], t]) if self.rows else t)
        offset = start if self.rows else start + 1  # the data row each interval ends at
        back = np.flatnonzero(dt <= 0)
        if back.size:
            i = offset + int(back[0])
            how = "repeats" if dt[back[0]] == 0 else "goes back"
            raise LogError(f"{self.path}: column t {how} at {self.label(i)}: t = {float(t[i - start])!r} s after "
                           f"t = {float(self.last if i == start else t[i - start - 1])!r} s at {self.label(i - 1)}; "
                           "expected strictly increasing times")
        self.first = t[0] if not self.rows else self.first
        self.rows, self.last = start + len(t), t[-1]
        if len(dt):
            self.medians.append(float(np.median(dt)))
            if dt.max() > self.high:
                self.high, self.gap_row = float(dt.max()), offset + int(np.argmax(dt))
        self.limit(self.first, self.last, self.rows)

    def check(self, min_duration: float, min_rate: float) -> None:
        """Refuse what :func:`faultgen.logs.jointlog.check_time` refuses on the whole times."""
        if self.rows < 2:
            raise LogError(f"{self.path}: {self.rows} data row(s); expected at least {min_duration:g} s of data at "
                           f">= {min_rate:g} Hz")
        period = float(np.median(self.medians))
        if period > (1.0 / min_rate) * (1 + 1e-9):
            raise LogError(f"{self.path}: column t has a median sample period of {period:.6g} s; expected at most "
                           f"{1 / min_rate:g} s (a sample rate of at least {min_rate:g} Hz)")
        if self.high > MAX_GAP * (1 + 1e-9):
            raise LogError(f"{self.path}: column t jumps by {self.high:.6g} s from {self.label(self.gap_row - 1)} to "
                           f"{self.label(self.gap_row)}; expected no interval longer than {MAX_GAP:g} s "
                           "(the derivative filter window)")
        if self.last - self.first < min_duration:
            raise LogError(f"{self.path}: the data covers {self.last - self.first:.6g} s ({self.rows} data rows); "
                           f"expected at least {min_duration:g} s")


@dataclass
class Scan:
    """What :func:`scan` keeps of a log: its times (whole, or None when streamed through ``times``),
    and the rows that decide the angle and torque checks (``kept`` values, ``kept_rows`` their data
    rows, sorted)."""

    t: np.ndarray | None
    kept: np.ndarray
    kept_rows: np.ndarray
    times: TimeScan | None


def scan(src, robot: robots.Robot, times: TimeScan | None = None, size: int | None = None) -> Scan:
    """The first pass over ``src`` (module docstring), in blocks of ``size`` rows (default
    :data:`BLOCK_ROWS`): the whole times when ``times`` is None, else checked as they stream by
    through it."""
    kept = {}
    if not src.wanted:  # an empty file: the whole-file reader says what is missing
        return Scan(np.empty(0) if times is None else None, np.empty((0, 0)), np.empty(0, dtype=int), times)
    index = {name: j for j, name in enumerate(src.wanted)}
    names = column_names(robot.n_axes)
    q_cols, tau_cols = [index[c] for c in names[0]], [index[c] for c in names[2] if c in index]
    t_col = index[T_COLUMN]
    low, high = robot.joint_range[:, 0], robot.joint_range[:, 1]
    tol = JOINT_RANGE_TOLERANCE
    # the whole times in one array of the declared rows (no list of blocks joined: half the memory),
    # checked as they stream by too, so a log whose times repeat or go back (an HDF5 file declaring
    # 10^8 rows it does not hold reads as zeros) is refused at its first block, not after all of it
    whole = np.empty(src.rows) if times is None else None
    early = TimeScan(src.path, src.label) if times is None else times
    end = 0
    for start, block in src.blocks(size or BLOCK_ROWS):
        if times is None:
            if start + len(block) > len(whole):  # more rows than counted (cannot happen): grow
                whole = np.concatenate([whole, np.empty(start + len(block) - len(whole))])
            whole[start:start + len(block)] = block[:, t_col]
            end = start + len(block)
        early.add(start, block[:, t_col])
        q = block[:, q_cols]
        rows = [np.argmin(q, axis=0), np.argmax(q, axis=0), np.argmax(np.abs(q), axis=0)]
        if tau_cols:
            rows.append(np.argmax(np.abs(block[:, tau_cols]), axis=0))
        outside = (q < low - tol) | (q > high + tol)
        rows.append(np.argmax(outside, axis=0)[outside.any(axis=0)])
        for i in np.unique(np.concatenate(rows)):
            kept[start + int(i)] = block[i].copy()  # a copy: a view would keep the whole block
    order = sorted(kept)
    t = whole[:end] if times is None else None
    if not order:
        return Scan(t, np.empty((0, len(src.wanted))), np.empty(0, dtype=int), times)
    return Scan(t, np.array([kept[i] for i in order]), np.array(order), times)


def thinned(src, k: int, size: int | None = None) -> dict[str, np.ndarray]:
    """Every ``k``-th row of ``src`` from the first, per column (its ``wanted``), read in blocks of
    about ``size`` rows (default :data:`BLOCK_ROWS`)."""
    size = k * math.ceil((size or BLOCK_ROWS) / k)  # blocks start on a kept row
    parts = [block[::k].copy() for _, block in src.blocks(size)]  # copies: a view would keep the block
    values = np.concatenate(parts) if parts else np.empty((0, len(src.wanted)))
    return {name: np.ascontiguousarray(values[:, j]) for j, name in enumerate(src.wanted)}


def averaged(src, n_axes: int, period: float, window: int, uniform: bool, k: int, m: int, on_block=None,
             size: int | None = None) -> dict:
    """The second pass over ``src`` (module docstring) in blocks of about ``size`` rows (default
    :data:`BLOCK_ROWS`): ``t``, ``q``, ``qd``, ``qdd`` (and ``tau`` when read) averaged over blocks
    of ``k`` rows, ``m`` rows each; ``qd`` is the file's when it has ``qd`` columns.
    ``on_block(start, block, qd_est, qd)`` sees each block at the full rate."""
    index = {name: j for j, name in enumerate(src.wanted)}
    q_names, qd_names, tau_names = column_names(n_axes)
    cols = {"t": [index[T_COLUMN]], "q": [index[c] for c in q_names]}
    if tau_names[0] in index:
        cols["tau"] = [index[c] for c in tau_names]
    qd_cols = [index[c] for c in qd_names] if qd_names[0] in index else None
    margin = window if uniform else max(window, 200)
    out = {name: [] for name in ("t", "q", "qd", "qdd", *(["tau"] if "tau" in cols else []))}
    size = k * math.ceil((size or BLOCK_ROWS) / k)  # blocks start on a whole averaging block
    left = np.empty((0, len(src.wanted)))
    pending = None

    def emit(start, block, right):
        rows = np.concatenate([left, block, right])
        qd_est, qdd = (d[len(left): len(left) + len(block)]
                       for d in _derivatives(rows[:, cols["t"][0]], rows[:, cols["q"]], period, window, uniform))
        qd = qd_est if qd_cols is None else np.ascontiguousarray(block[:, qd_cols])
        if on_block is not None:
            on_block(start, block, qd_est, qd)
        whole = max(min(m * k - start, len(block)), 0) // k  # averaging blocks within this block
        # contiguous, as the whole-log reader's columns: the same sums in the same order, bit for bit
        values = {name: np.ascontiguousarray(block[:, c]) for name, c in cols.items()}
        values["t"] = values["t"][:, 0]
        values.update(qd=qd, qdd=qdd)
        for name, kept in out.items():
            kept.append(block_mean(values[name], k, whole))

    for start, block in src.blocks(size):
        if pending is not None:
            emit(*pending, block[:margin])
            left = np.concatenate([left, pending[1]])[-margin:]
        pending = (start, block)
    emit(*pending, np.empty((0, left.shape[1])))
    return {name: np.concatenate(values) for name, values in out.items()}
