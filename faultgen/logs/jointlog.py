"""A joint log: one implementation of reading, checking and differentiating the logs faultgen takes
from a robot (the calibration's measured logs, :mod:`faultgen.logs.measured`; a replayed log,
:mod:`faultgen.operation.replay`, which needs no torque columns).

The format (columns, units, CSV and HDF5 layouts, row numbers in messages) is documented in
:mod:`faultgen.logs.measured`. Every refusal is a :class:`LogError` (a ValueError) naming the file
and the column and/or data row (1-based, header not counted).

Derivatives: :func:`derivatives` (the Savitzky-Golay estimator of :mod:`faultgen.derivatives` at
the median sample period), so a replayed log and the same log calibrated see one motion.
"""

from __future__ import annotations

import io
import math
import zlib
from collections import Counter
from contextlib import contextmanager
from pathlib import Path

import h5py
import numpy as np
import pandas as pd

from faultgen import inputs
from faultgen.derivatives import derivatives as _savgol
from faultgen.derivatives import is_uniform, savgol_window
from faultgen.model import robots
from faultgen.logs.columns import (
    CHUNK_CELLS,
    CSV_SUFFIXES,
    CYCLE_COLUMN,
    FULL_TURN_MARGIN,
    HDF5_SUFFIXES,
    JOINT_RANGE_TOLERANCE,
    MAX_GAP,
    MAX_ROWS,
    MIN_DURATION,
    MIN_RATE,
    PAYLOAD_COLUMN,
    T_COLUMN,
    UNITS,
    VALUE_BOUNDS,
    WHOLE_MAX_BYTES,
    LogBoundError,
    LogError,
    column_names,
    required,
    temperature_columns,
)


def whole_rows(n_columns: int, bytes_per_cell: int = 8) -> int:
    """Most rows a log read whole may have when ``n_columns`` columns of ``bytes_per_cell`` bytes are
    kept (:data:`WHOLE_MAX_BYTES`)."""
    return WHOLE_MAX_BYTES // (max(bytes_per_cell, 8) * max(n_columns, 1))


def check_whole_rows(path: Path, rows: int, n_columns: int, bytes_per_cell: int = 8, what: str = "a log") -> None:
    """Refuse ``rows`` rows of ``n_columns`` columns read whole above :func:`whole_rows`."""
    most = whole_rows(n_columns, bytes_per_cell)
    if rows > most:
        raise LogBoundError(f"{path}: {rows} rows of {n_columns} columns; {what} read whole has at most {most} "
                            f"({WHOLE_MAX_BYTES // 2**20} MiB of {max(bytes_per_cell, 8)}-byte cells, WHOLE_MAX_BYTES)")


def csv_rows(path: Path, n_columns: int, what: str = "a log", label: str = "joint log") -> None:
    """Refuse a CSV log (plain or gzip-compressed) of more data rows than :func:`whole_rows` allows for
    ``n_columns`` columns, counted before it is parsed: from its size when that already bounds them
    (a row takes at least a byte), else by a streaming line count (:func:`faultgen.inputs.count_lines`)."""
    try:
        if not inputs.is_gzip(path) and inputs.size_of(path) <= whole_rows(n_columns):
            return
        lines = inputs.count_lines(path, label, inputs.CSV_ROW_MAX_BYTES)
    except inputs.InputError as err:
        raise LogError(str(err)) from None
    check_whole_rows(path, max(lines - 1, 0), n_columns, what=what)


def header(path: Path, what: str = "joint log") -> list[str]:
    """The names in the CSV log's header, bounded (:func:`faultgen.inputs.csv_header`), stripped;
    refuse a name given twice."""
    try:
        raw, _ = inputs.csv_header(path, what)
    except inputs.InputError as err:
        raise LogBoundError(str(err)) from None
    except (OSError, UnicodeDecodeError, EOFError, zlib.error) as err:
        raise LogError(f"{path}: cannot read the file as CSV: {err}") from err
    names = [h.strip() for h in raw]
    duplicated = sorted(n for n, count in Counter(names).items() if count > 1)
    if duplicated:
        raise LogError(f"{path}: column(s) {', '.join(duplicated)} appear more than once in the header")
    return names


def kind(path: Path) -> str:
    name = path.name.lower()
    if name.endswith(CSV_SUFFIXES):
        return "csv"
    if name.endswith(HDF5_SUFFIXES):
        return "hdf5"
    accepted = ", ".join(CSV_SUFFIXES + HDF5_SUFFIXES)
    suffixes = "".join(inputs.path_of(path).suffixes)
    raise LogError(
        f"{path}: unknown file type {suffixes or '(no suffix)'!r}; expected {accepted}"
    )


def regular(path: Path) -> None:
    """Refuse a missing file, a folder, a device or a FIFO (faultgen.inputs), as LogError."""
    try:
        inputs.regular_file(path, "joint log")
    except inputs.InputError as err:
        raise LogError(str(err)) from None


def csv_label(i: int) -> str:
    return f"data row {i + 1} (line {i + 2})"


def index_label(i: int) -> str:
    return f"data row {i + 1} (index {i})"


def read_csv(path: Path, n_axes: int, motion_only: bool = False) -> tuple[dict[str, np.ndarray], list[str], object]:
    """Columns of a CSV file as float arrays, the ignored extra column names, the row labeller.

    A gzip-compressed file is recognised by its content, so a compressed log named ``.csv``
    reads like one named ``.csv.gz``. The header is bounded (:func:`header`) and the rows
    (:func:`csv_rows`) before a row is parsed; only the wanted columns are converted and kept.
    """
    names = header(path)
    if not names:
        raise LogError(
            f"{path}: the file is empty; expected a header row with the columns t, q1..q{n_axes}, tau1..tau{n_axes}"
        )
    wanted, extra = select_columns(path, names, n_axes, motion_only)
    csv_rows(path, len(wanted))
    fast = _arrow_columns(path, names, wanted)
    if fast is not None:
        return fast, extra, csv_label
    # pandas (a gzip-compressed log, or one pyarrow refused), in chunks of rows: every column is
    # tokenized, so a row with too many or too few fields is refused by the parser with its line
    # number instead of being silently cut, but only a chunk's extra cells are held at a time.
    read_kw = {
        "header": 0,
        "names": names,
        "index_col": False,
        "skip_blank_lines": False,
        "chunksize": max(1_000, CHUNK_CELLS // len(names)),
    }
    try:
        try:
            # Numbers throughout. Anything else is diagnosed from the text below.
            dtypes = {name: (float if name in wanted else str) for name in names}
            parts = {name: [] for name in wanted}
            with inputs.open_text(path, "joint log") as fh:
                for frame in pd.read_csv(fh, dtype=dtypes, **read_kw):
                    for name in wanted:
                        parts[name].append(frame[name].to_numpy(dtype=float))
            columns = {name: joined(parts[name]) for name in wanted}
            clean = all(bool(np.isfinite(column).all()) for column in columns.values())
        except inputs.InputError:
            raise
        except (ValueError, TypeError):
            clean = False
        if not clean:
            columns = _numbers_from_text(path, read_kw, wanted)
    except inputs.InputError as err:
        raise LogError(str(err)) from None
    except (OSError, EOFError, UnicodeDecodeError, pd.errors.ParserError, pd.errors.EmptyDataError) as err:
        raise LogError(f"{path}: cannot read the file as CSV: {err}") from err
    return columns, extra, csv_label


def joined(parts: list[np.ndarray]) -> np.ndarray:
    """One contiguous float column from its chunks (the one chunk itself: no copy)."""
    if len(parts) == 1:
        return np.ascontiguousarray(parts[0], dtype=float)
    return np.ascontiguousarray(np.concatenate(parts) if parts else np.empty(0), dtype=float)


def _arrow_columns(path: Path, names: list[str], wanted: list[str]) -> dict[str, np.ndarray] | None:
    """The wanted columns of a clean, uncompressed CSV log as float arrays, parsed by pyarrow's
    multi-threaded reader (the import's largest cost with pandas); None for anything
    else (a gzip-compressed file, a ragged row, a blank line, an empty, non-numeric or
    non-finite cell, text that is not UTF-8), which :func:`read_csv` then reads or refuses
    through pandas with the row named, as before. Same numbers as pandas's parser, bit for bit
    (tests/test_measured.py)."""
    import pyarrow as pa
    from pyarrow import csv as pacsv

    try:
        if inputs.is_gzip(path):
            return None
        types = {name: pa.float64() for name in wanted}
        with inputs.open_bytes(path, "joint log") as fh:
            # only the wanted columns converted and kept; every row's fields still counted by the parser
            table = pacsv.read_csv(
                fh,
                read_options=pacsv.ReadOptions(column_names=names, skip_rows=1),
                parse_options=pacsv.ParseOptions(ignore_empty_lines=False),
                convert_options=pacsv.ConvertOptions(column_types=types, strings_can_be_null=False,
                                                     include_columns=wanted),
            )
    except inputs.InputError as err:
        raise LogError(str(err)) from None
    except (pa.ArrowException, OSError, ValueError):
        return None
    columns = {}
    for name in wanted:
        chunked = table.column(name)
        if chunked.null_count:
            return None
        column = chunked.to_numpy()
        if not np.isfinite(column).all():
            return None
        columns[name] = np.ascontiguousarray(column, dtype=float)
    return columns if table.num_rows else None


def _numbers_from_text(path: Path, read_kw: dict, wanted: list[str]) -> dict[str, np.ndarray]:
    """The wanted columns from the text, chunk by chunk: trailing blank rows dropped, refused at the
    first empty / NaN / non-numeric cell before them (the first data row, then the first wanted
    column). A bad cell in a blank row counts only when a row that is not blank follows it."""
    parts = {name: [] for name in wanted}
    first: tuple[int, int, str, str] | None = None  # (row, column order, column, raw text)
    last_filled, start = -1, 0
    with inputs.open_text(path, "joint log") as fh:
        for text in pd.read_csv(fh, dtype=str, keep_default_na=False, na_filter=False, **read_kw):
            blank = (text.apply(lambda col: col.str.strip()) == "").all(axis=1).to_numpy()
            filled = np.flatnonzero(~blank)
            if filled.size:
                last_filled = start + int(filled[-1])
            for order, name in enumerate(wanted):
                raw = text[name].str.strip()
                values = pd.to_numeric(raw, errors="coerce").to_numpy(dtype=float)
                bad = np.flatnonzero(~np.isfinite(values))
                if first is None or first[0] >= start:  # the earliest bad cell: earlier chunks win
                    if bad.size and (first is None or start + bad[0] < first[0]):
                        first = (start + int(bad[0]), order, name, str(raw.iloc[bad[0]]))
                parts[name].append(values)
            start += len(text)
    if first is not None and first[0] <= last_filled:
        row, _, name, raw = first
        raise LogError(f"{path}: {csv_label(row)}, column {name}: {describe_bad_cell(raw)}")
    return {name: joined(parts[name])[: last_filled + 1] for name in wanted}


#: Characters of a bad cell quoted in a refusal; a longer one is cut, its length said (a sparse
#: log's hole read as one cell of NUL bytes put 256 MiB of them into one message).
CELL_SHOWN = 40


def shown_cell(raw: str) -> str:
    """``repr`` of a cell, cut at :data:`CELL_SHOWN` characters (its length then said)."""
    return repr(raw) if len(raw) <= CELL_SHOWN else f"{raw[:CELL_SHOWN]!r}... ({len(raw)} characters)"


def describe_bad_cell(raw: str) -> str:
    if len(raw) > CELL_SHOWN:
        return f"value {shown_cell(raw)} is not a number"
    if raw == "":
        return "empty cell; expected a number"
    if raw.lower() in ("nan", "-nan", "+nan", "na", "n/a", "null", "none", "#n/a"):
        return f"value {raw!r} (NaN); expected a number"
    try:
        value = float(raw)
    except ValueError:
        return f"value {raw!r} is not a number"
    return f"value {raw!r} is not finite" if not math.isfinite(value) else f"value {raw!r} not understood"


def select_columns(path: Path, names: list[str], n_axes: int, motion_only: bool = False) -> tuple[list[str], list[str]]:
    """Columns to read (required, plus all qd when present) and the extra ones; refuse missing.
    ``motion_only``: ``t`` and ``q1..qN`` alone (a replayed log: no torque), the rest extra."""
    present = set(names)
    n = n_axes
    qd_columns = column_names(n)[1]
    needed = required(n)[: n + 1] if motion_only else required(n)
    missing = [c for c in needed if c not in present]
    if missing:
        shown = names if len(names) <= 40 else [*names[:40], f"... ({len(names)} in all)"]
        hint = ""
        if len(names) == 1 and ";" in names[0]:
            hint = "; the header seems to use ';' as separator, expected ','"
        elif len(names) == 1 and "\t" in names[0]:
            hint = "; the header seems to use tabs as separator, expected ','"
        raise LogError(
            f"{path}: missing column(s) {', '.join(missing)}; found columns: {', '.join(shown) or '(none)'}"
            + (f"; required: t, q1..q{n} (rad)" if motion_only else
               f"; required: t, q1..q{n}, tau1..tau{n} (qd1..qd{n} optional)") + hint
        )
    if motion_only:
        return list(needed), [c for c in names if c not in needed]
    qd_present = [c for c in qd_columns if c in present]
    if qd_present and len(qd_present) != n:
        qd_missing = [c for c in qd_columns if c not in present]
        raise LogError(
            f"{path}: velocity columns {', '.join(qd_present)} present but {', '.join(qd_missing)} missing; "
            f"give all of qd1..qd{n} or none (then they are estimated from q)"
        )
    wanted = [*required(n), *qd_present]
    if all(c in present for c in temperature_columns(n)):  # some of them only: ignored, named as extra
        wanted += temperature_columns(n)
    wanted += [c for c in (PAYLOAD_COLUMN, CYCLE_COLUMN) if c in present]
    extra = [n for n in names if n not in wanted]
    return wanted, extra


def hdf5_rows(fh, path: Path, wanted: list[str]) -> int:
    """The rows of the HDF5 log's columns ``wanted``, from their declared metadata only, after checking
    each: a 1-D dataset of numbers (text or a compound refused, never converted), of its column's
    unit when it names one, of at most :data:`MAX_ROWS` rows, all of one length. What the whole read
    (:func:`read_hdf5`) and the block reader (:class:`faultgen.logs.blocks`) both check. ``fh``: the
    open ``h5py.File``, or a mapping of (at least) the names ``wanted`` to its datasets.

    Raises
    ------
    LogError
        Naming the file, the dataset and what was expected.
    """
    length = None
    for name in wanted:
        ds = fh[name]
        if ds.ndim != 1:
            raise LogError(f"{path}: dataset {name} has shape {ds.shape}; expected a 1-D dataset (n,)")
        if ds.dtype.kind not in "fiu":
            raise LogError(f"{path}: dataset {name} has dtype {ds.dtype}; expected numbers")
        attrs = ds.attrs  # a membership test, not a failed look-up (h5py's error path) per column
        unit = attrs["unit"] if "unit" in attrs else attrs["units"] if "units" in attrs else None
        if unit is not None:
            unit = unit.decode() if isinstance(unit, bytes) else str(unit)
            if _unit_key(unit) != _unit_key(UNITS[name]):
                raise LogError(f"{path}: dataset {name} has unit {unit!r}; expected {UNITS[name]!r}")
        if ds.shape[0] > MAX_ROWS:
            raise LogError(f"{path}: dataset {name} declares {ds.shape[0]} rows; a log has at most "
                           f"{MAX_ROWS} (MAX_ROWS: a day at 1 kHz)")
        if length is None:
            length = ds.shape[0]
        elif ds.shape[0] != length:
            raise LogError(f"{path}: dataset {name} has {ds.shape[0]} rows but {wanted[0]} has {length}; "
                           "all columns must have the same length")
    return length or 0


def read_hdf5(path: Path, n_axes: int, motion_only: bool = False) -> tuple[dict[str, np.ndarray], list[str], object]:
    with open_hdf5(path) as fh:
        wanted, extra = hdf5_columns(fh, path, n_axes, motion_only)
        datasets = {name: fh[name] for name in wanted}  # each looked up once
        columns = {}
        length = hdf5_rows(datasets, path, wanted)
        # from the declared shapes and element sizes, before any row is read
        cell = max(ds.dtype.itemsize for ds in datasets.values()) if wanted else 8
        check_whole_rows(path, length, len(wanted), cell)
        for name in wanted:
            columns[name] = np.asarray(datasets[name][()], dtype=float)
    refuse_non_finite(path, columns, wanted, index_label)
    return columns, extra, index_label


def hdf5_columns(fh: h5py.File, path: Path, n_axes: int, motion_only: bool = False) -> tuple[list[str], list[str]]:
    """The root datasets to read (required, plus all qd when present) and the extra ones (groups
    among them, marked); refuse missing columns, naming the groups at the root that hold none."""
    objects = {n: fh[n] for n in fh.keys()}  # each looked up once
    datasets = [n for n, obj in objects.items() if isinstance(obj, h5py.Dataset)]
    groups = [n for n, obj in objects.items() if isinstance(obj, h5py.Group)]
    try:
        wanted, extra = select_columns(path, datasets, n_axes, motion_only)
    except LogError as err:
        if groups:
            raise LogError(
                f"{err}; groups at the root: {', '.join(groups)} (columns must be 1-D datasets at the file root)"
            ) from None
        raise
    return wanted, extra + [f"{g}/ (group)" for g in groups]


@contextmanager
def open_hdf5(path: Path):
    """The HDF5 log, opened read-only after faultgen.inputs refused links and virtual datasets that
    reach other files (LogError naming the link)."""
    try:
        fh = h5py.File(io.BytesIO(path.data) if isinstance(path, inputs.Held) else path, "r")
    except OSError as err:
        raise LogError(f"{path}: cannot read the file as HDF5: {err}") from err
    with fh:
        try:
            inputs.check_hdf5_links(fh, path)
        except inputs.InputError as err:
            raise LogError(str(err)) from None
        yield fh


def _unit_key(unit: str) -> str:
    return "".join(ch for ch in unit.lower() if ch not in " *.·")



def check_values(where: Path, columns: dict[str, np.ndarray], label) -> None:
    """Refuse the first row whose value lies outside :data:`VALUE_BOUNDS` (naming the file, the
    column, the data row, the value and the bound)."""
    first = None
    for name, values in columns.items():
        stem = name.rstrip("0123456789")
        key = name if name in (T_COLUMN, PAYLOAD_COLUMN) else stem if stem != name else None
        if key not in VALUE_BOUNDS:
            continue
        low, high, _, _ = VALUE_BOUNDS[key]
        bad = np.flatnonzero((values < low) | (values > high))
        if bad.size and (first is None or bad[0] < first[0]):
            first = (int(bad[0]), name, key)
    if first is not None:
        row, name, key = first
        low, high, unit, hint = VALUE_BOUNDS[key]
        raise LogError(f"{where}: {label(row)}, column {name}: value {float(columns[name][row]):.6g} {unit}; expected "
                       f"{low:g} .. {high:g} {unit} ({hint})")


def refuse_non_finite(where: Path, columns: dict[str, np.ndarray], order: list[str], label) -> None:
    first = None
    for name in order:
        bad = np.flatnonzero(~np.isfinite(columns[name]))
        if bad.size and (first is None or bad[0] < first[0]):
            first = (int(bad[0]), name)
    if first is not None:
        row, name = first
        value = columns[name][row]
        what = "NaN" if np.isnan(value) else f"{value} (not finite)"
        raise LogError(
            f"{where}: {label(row)}, column {name}: value {what}; expected a finite number"
        )



# --------------------------------------------------------------------------------------------
# Checks and derivatives


def check_time(t: np.ndarray, where: Path, label, notes: list[str], min_duration: float = MIN_DURATION,
               min_rate: float = MIN_RATE) -> tuple[np.ndarray, float]:
    """Refuse sample times that do not increase, a median period above 1 / ``min_rate`` (default
    :data:`MIN_RATE`), a gap above :data:`MAX_GAP` or a span below ``min_duration`` (default
    :data:`MIN_DURATION`); note long gaps in ``notes``. Returns the intervals and the median period, s."""
    n = t.shape[0]
    if n < 2:
        raise LogError(
            f"{where}: {n} data row(s); expected at least {min_duration:g} s of data at >= {min_rate:g} Hz"
        )
    dt = np.diff(t)
    back = np.flatnonzero(dt <= 0)
    if back.size:
        i = int(back[0]) + 1
        how = "repeats" if dt[i - 1] == 0 else "goes back"
        raise LogError(
            f"{where}: column t {how} at {label(i)}: t = {float(t[i])!r} s after t = {float(t[i - 1])!r} s at "
            f"{label(i - 1)}; expected strictly increasing times"
        )
    period = float(np.median(dt))
    if period > (1.0 / min_rate) * (1 + 1e-9):
        raise LogError(
            f"{where}: column t has a median sample period of {period:.6g} s ({1 / period:.4g} Hz); "
            f"expected at most {1 / min_rate:g} s (a sample rate of at least {min_rate:g} Hz)"
        )
    gap = int(np.argmax(dt))
    if dt[gap] > MAX_GAP * (1 + 1e-9):
        raise LogError(
            f"{where}: column t jumps by {dt[gap]:.6g} s from {label(gap)} to {label(gap + 1)}; "
            f"expected no interval longer than {MAX_GAP:g} s (the derivative filter window)"
        )
    duration = float(t[-1] - t[0])
    if duration < min_duration:
        raise LogError(
            f"{where}: the data covers {duration:.6g} s ({n} data rows); expected at least {min_duration:g} s"
        )
    long_gaps = np.flatnonzero(dt > 2 * period)
    if long_gaps.size:
        notes.append(
            f"{long_gaps.size} sampling interval(s) longer than twice the median period {period:.6g} s, "
            f"the longest {dt[gap]:.6g} s before {label(gap + 1)}"
        )
    return dt, period


def check_angles(where: Path, q: np.ndarray, robot: robots.Robot, label,
                 tolerance: float = JOINT_RANGE_TOLERANCE) -> None:
    """Refuse angle columns in degrees or outside the joint range plus ``tolerance`` (rad)."""
    tol = tolerance
    for k, name in enumerate(column_names(robot.n_axes)[0]):
        lo, hi = robot.joint_range[k]
        col = q[:, k]
        outside = np.flatnonzero((col < lo - tol) | (col > hi + tol))
        if not outside.size:
            continue
        as_rad = np.deg2rad(col)
        fits_as_degrees = bool(np.all((as_rad >= lo - tol) & (as_rad <= hi + tol)))
        peak = int(np.argmax(np.abs(col)))
        beyond_turn = abs(col[peak]) > 2 * math.pi + FULL_TURN_MARGIN
        too_wide = np.ptp(col) > (hi - lo) + 2 * tol
        if fits_as_degrees and (beyond_turn or too_wide):
            extreme = "max" if col[peak] >= 0 else "min"
            raise LogError(
                f"{where}: column {name} looks like degrees ({extreme} {col[peak]:.6g} at {label(peak)}, "
                f"span {np.ptp(col):.4g}); expected rad within the joint range [{lo:.4g}, {hi:.4g}] rad"
            )
        i = int(outside[0])
        hint = " (if the column is in degrees, convert it to rad)" if fits_as_degrees else ""
        raise LogError(
            f"{where}: column {name} at {label(i)} is {col[i]:.6g} rad, outside the joint range "
            f"[{lo:.4g}, {hi:.4g}] rad of {robot.name} (tolerance {tol:g} rad){hint}"
        )


def read_columns(path: Path | inputs.Held, n_axes: int, motion_only: bool = False
                 ) -> tuple[dict[str, np.ndarray], list[str], object]:
    """The columns of the log ``path`` (:func:`select_columns`), every cell a finite number, the
    ignored extra column names and the row labeller (:func:`csv_label` or :func:`index_label`).
    ``path`` may be the log's bytes read once (:class:`faultgen.inputs.Held`): parsed from them,
    the file not opened again.

    Raises
    ------
    LogError
        For an unknown suffix, a file that is not a regular one or not readable as its type, a
        missing column, a cell that is not a finite number (file, data row and column named).
    """
    path = path if isinstance(path, inputs.Held) else Path(path)
    reader = read_csv if kind(path) == "csv" else read_hdf5
    regular(path)
    return reader(path, n_axes, motion_only)


def derivatives(t: np.ndarray, q: np.ndarray, dt: np.ndarray, period: float, orders=(1, 2)):
    """The Savitzky-Golay window (samples), whether the sampling is uniform, and the derivatives of
    ``q`` (n, N) of each order in ``orders`` at the times ``t`` (:mod:`faultgen.derivatives`), from
    the intervals ``dt`` and median period ``period`` of :func:`check_time`."""
    window = savgol_window(period, len(t))
    uniform = is_uniform(dt, period)
    return window, uniform, _savgol(t, q, period, window, uniform, orders=orders)


def motion(columns: dict[str, np.ndarray], robot: robots.Robot, where: Path, label, notes: list[str], *,
           min_duration: float = MIN_DURATION, min_rate: float = MIN_RATE,
           tolerance: float = JOINT_RANGE_TOLERANCE, orders=(1, 2)) -> dict:
    """The checked motion of a log's ``columns`` (:func:`read_columns`): its times (:func:`check_time`),
    angles (:func:`check_angles`) and their derivatives (:func:`derivatives`).

    Returns
    -------
    dict
        ``t`` (n,) s, ``q`` (n, N) rad, ``dt`` (n - 1,) s, ``period`` s, ``window`` samples,
        ``uniform`` bool and ``derivatives``, a tuple of (n, N) arrays, one per order.

    Raises
    ------
    LogError
        As :func:`check_values`, :func:`check_time` and :func:`check_angles`, naming the file, the
        column and the row.
    """
    check_values(where, columns, label)
    t = columns[T_COLUMN]
    dt, period = check_time(t, where, label, notes, min_duration, min_rate)
    q = np.column_stack([columns[c] for c in column_names(robot.n_axes)[0]])
    check_angles(where, q, robot, label, tolerance)
    window, uniform, found = derivatives(t, q, dt, period, orders)
    return {"t": t, "q": q, "dt": dt, "period": period, "window": window, "uniform": uniform, "derivatives": found}
