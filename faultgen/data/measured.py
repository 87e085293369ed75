"""Read and check measured joint data: the input of the sim-vs-measured calibration workflow.

The format is fixed by the design document, section "Measured data (input of the discrepancy
workflow)": one column per signal,

=============  =======  ==================================================================
column         unit     meaning
=============  =======  ==================================================================
``t``          s        sample time, strictly increasing, constant or varying rate >= 100 Hz
``q1..qN``     rad      arm-side joint angles (N the robot's axes, 5..7)
``tau1..tauN`` N m      arm-side joint torque (motor torque referred through the gear ratio)
``qd1..qdN``   rad/s    optional: joint velocities; estimated from ``q`` when absent
``temperature1..N``  degC  optional: joint temperatures (all N or none; read, not used by the
                       calibration: an imported fleet stores them, :mod:`faultgen.data.fleetlogs`)
``payload``    kg       optional: mass of the part carried
``cycle``      1        optional: the cycle each sample belongs to (whole numbers, never
                       decreasing): a log of several cycles (:mod:`faultgen.data.fleetlogs`)
=============  =======  ==================================================================

stored as

* a CSV file (``.csv``, or gzip-compressed ``.csv.gz``; compression is recognised by the
  content, so a compressed file named ``.csv`` reads too) with a header row holding the column
  names, comma-separated, one sample per row;
* an HDF5 file (``.h5`` or ``.hdf5``) with **one 1-D dataset per column at the file root**,
  named as above and all of the same length. A dataset may carry a ``unit`` (or ``units``)
  attribute; when it does, it must be the unit of the table (``deg`` on ``q3`` is refused).
  Columns inside a group are not looked for: export them to the root.

Other columns (CSV) or root datasets (HDF5) are allowed and ignored; their names are listed in
:attr:`MeasuredData.notes`. The ``qd`` columns are all N or none.

Row numbers in messages
-----------------------
Every message naming a row uses **1-based data rows**: the first sample is data row 1, the
header is not counted. For a CSV file the message adds the file line (data row + 1, which is
also the row number a spreadsheet shows, since the header is its row 1); for HDF5 and arrays
it adds the 0-based index.

Derivative estimation
---------------------
``qdd`` (always) and ``qd`` (when the file has no ``qd`` columns) are estimated from ``q`` with
a Savitzky-Golay filter (:func:`scipy.signal.savgol_filter`, ``deriv=1`` / ``deriv=2``,
``mode="interp"``): a cubic (:data:`SAVGOL_ORDER`) least-squares fit over a window of
:data:`SAVGOL_WINDOW` = 0.05 s, i.e. ``2 round(0.025 / dt) + 1`` samples at the median sample
period ``dt`` (5 samples at 100 Hz, 13 at 250 Hz, 51 at 1 kHz). Its pass band reaches about
25-35 Hz (Schafer 2011, "What is a Savitzky-Golay filter?"), well above the joint motion of
an industrial arm, while encoder noise at hundreds of Hz is rejected. Near both ends the
polynomial of the first / last window is used, so the first and last ~0.025 s are less
accurate.

The filter coefficients assume equally spaced samples. When the sample period varies by more
than :data:`UNIFORM_TOLERANCE` (relative), ``q`` is first interpolated with a cubic spline
(:class:`scipy.interpolate.CubicSpline`, C2, so it adds no kinks to the second derivative)
onto a uniform grid at the median period, differentiated there, and the derivatives are
interpolated back onto the original sample times with a cubic spline. Applying the uniform
coefficients to jittered samples instead would bias the derivatives in proportion to the
timing error. Given ``qd`` columns are used as they are (not filtered); ``qdd`` is always
taken from ``q``. Torque is used as it is.
"""

from __future__ import annotations

import csv
import math
import zlib
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np
import pandas as pd

from faultgen import axes, inputs
from faultgen.derivatives import SAVGOL_ORDER, SAVGOL_WINDOW, UNIFORM_TOLERANCE  # noqa: F401 (re-exported)
from faultgen.derivatives import derivatives as _derivatives
from faultgen.derivatives import is_uniform as _is_uniform
from faultgen.derivatives import savgol_window as _savgol_window
from faultgen.effects.payload import Payload
from faultgen.effects.temperature import Temperature
from faultgen.model import robots

#: Column names of the format: ``t`` and, for a robot of N axes, :func:`column_names`.
T_COLUMN = "t"


def column_names(n_axes: int) -> tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]]:
    """The angle, velocity and torque columns of a robot of ``n_axes`` axes: ``q1..qN``,
    ``qd1..qdN``, ``tau1..tauN``."""
    numbers = range(1, n_axes + 1)
    return tuple(f"q{i}" for i in numbers), tuple(f"qd{i}" for i in numbers), tuple(f"tau{i}" for i in numbers)


def _required(n_axes: int) -> tuple[str, ...]:
    q, _, tau = column_names(n_axes)
    return (T_COLUMN, *q, *tau)


#: Unit of each column of any robot (written as the ``unit`` attribute of HDF5 datasets).
UNITS = {T_COLUMN: "s"}
for _q, _qd, _tau in zip(*column_names(axes.MAX_AXES), strict=True):
    UNITS.update({_q: "rad", _qd: "rad/s", _tau: "N m"})
#: The optional columns of operating conditions are named as the effects that model them
#: (:mod:`faultgen.effects`): ``temperature1..N`` (all N or none), the joint temperatures, and
#: ``payload``, the payload mass; ``cycle`` is the cycle number of each sample.
TEMPERATURE_PREFIX, PAYLOAD_COLUMN, CYCLE_COLUMN = Temperature.id, Payload.id, "cycle"


def temperature_columns(n_axes: int) -> tuple[str, ...]:
    """The joint-temperature columns of a robot of ``n_axes`` axes: ``temperature1..N``."""
    return tuple(TEMPERATURE_PREFIX + str(i) for i in range(1, n_axes + 1))


UNITS.update({name: "degC" for name in temperature_columns(axes.MAX_AXES)})
UNITS.update({PAYLOAD_COLUMN: "kg", CYCLE_COLUMN: "1"})

#: File suffixes read by :func:`read`, lower case.
CSV_SUFFIXES = (".csv", ".csv.gz")
#: Most rows a log may have (a day at 1 kHz); a longer one, or an HDF5 log declaring more, is refused.
MAX_ROWS = 100_000_000
HDF5_SUFFIXES = (".h5", ".hdf5")

#: Lowest accepted sample rate in Hz (applied to the median sample period).
MIN_RATE = 100.0
#: Longest accepted single interval between samples in s: the derivative filter window.
MAX_GAP = 0.05
#: Shortest accepted recording in s (last minus first sample time).
MIN_DURATION = 2.0
# SAVGOL_WINDOW, SAVGOL_ORDER, UNIFORM_TOLERANCE: the Savitzky-Golay estimator's settings, imported
# from faultgen.derivatives (shared with replayed task logs, faultgen.operation.replay)
#: Joint angles may exceed the robot's joint range by this much (rad) before being refused.
JOINT_RANGE_TOLERANCE = 0.05
#: Angles beyond a full turn plus this margin (rad) cannot be radians of a revolute arm joint.
FULL_TURN_MARGIN = 0.1


class MeasuredDataError(ValueError):
    """Raised for a measured-data file that cannot be used.

    The message starts with the file (or ``<arrays>``) and names the offending column and/or
    data row (1-based, header not counted; see the module docstring) and what was expected.
    """


@dataclass(frozen=True, eq=False)
class MeasuredData:
    """Measured joint data of one robot, checked, with velocities and accelerations.

    Attributes
    ----------
    t : ndarray of shape (n,)
        Sample times in s as in the file, strictly increasing.
    q : ndarray of shape (n, N)
        Arm-side joint angles in rad (N the robot's axes).
    qd : ndarray of shape (n, N)
        Arm-side joint velocities in rad/s: the file's ``qd`` columns, or estimated from ``q``
        (see :attr:`velocity_estimated`).
    qdd : ndarray of shape (n, N)
        Arm-side joint accelerations in rad/s^2, estimated from ``q`` (NaN when read with
        ``accelerations=False``).
    tau : ndarray of shape (n, N)
        Arm-side joint torques in N m.
    source : Path
        The file read (``Path("<arrays>")`` for :func:`from_arrays` without a source).
    velocity_estimated : bool
        True when ``qd`` was estimated from ``q`` (the file had no ``qd`` columns).
    robot : str
        Name of the robot the data was checked against.
    joint_temperature : ndarray of shape (n, N) or None
        Joint temperatures in degC (the file's ``temperature1..N`` columns), None without.
    payload_mass : ndarray of shape (n,) or None
        Payload mass in kg (the ``payload`` column), None without.
    cycle : ndarray of int of shape (n,) or None
        The cycle of each sample (the ``cycle`` column: whole, never decreasing), None without.
    notes : tuple of str
        Remarks that did not refuse the data: ignored extra columns, the derivative filter
        used, resampling, sampling gaps, suspicious torque magnitudes.

    All arrays are read-only.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    source: Path
    velocity_estimated: bool
    robot: str = ""
    notes: tuple[str, ...] = field(default=())
    joint_temperature: np.ndarray | None = None
    payload_mass: np.ndarray | None = None
    cycle: np.ndarray | None = None

    def __post_init__(self) -> None:
        t = np.array(self.t, dtype=float)
        if t.ndim != 1:
            raise ValueError(f"t must have shape (n,), got {t.shape}")
        t.setflags(write=False)
        object.__setattr__(self, "t", t)
        n_axes = np.shape(self.q)[1] if np.ndim(self.q) == 2 else None
        for name in ("q", "qd", "qdd", "tau"):
            arr = np.array(getattr(self, name), dtype=float)
            if n_axes is None or arr.shape != (t.shape[0], n_axes):
                raise ValueError(f"{name} must have shape ({t.shape[0]}, N) alike, got {arr.shape}")
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        for name, shape, dtype in (("joint_temperature", (t.shape[0], n_axes), float),
                                   ("payload_mass", (t.shape[0],), float),
                                   ("cycle", (t.shape[0],), np.int64)):
            if getattr(self, name) is not None:
                arr = np.array(getattr(self, name), dtype=dtype)
                if arr.shape != shape:
                    raise ValueError(f"{name} must have shape {shape}, got {arr.shape}")
                arr.setflags(write=False)
                object.__setattr__(self, name, arr)
        object.__setattr__(self, "source", Path(self.source))
        object.__setattr__(self, "notes", tuple(self.notes))

    @property
    def duration(self) -> float:
        """Recorded time span in s: last minus first sample time."""
        return float(self.t[-1] - self.t[0]) if self.t.size else 0.0

    @property
    def sample_period(self) -> float:
        """Median sample period in s."""
        return float(np.median(np.diff(self.t))) if self.t.size > 1 else math.nan

    def __len__(self) -> int:
        return int(self.t.shape[0])


# --------------------------------------------------------------------------------------------
# Reading


def read(path: str | Path, robot: str | Path | robots.Robot, accelerations: bool = True) -> MeasuredData:
    """Read, check and complete a measured-data file (format in the module docstring).

    Parameters
    ----------
    path : str or Path
        A ``.csv``, ``.csv.gz``, ``.h5`` or ``.hdf5`` file (suffix case-insensitive).
    robot : str, Path or robots.Robot
        The robot the data was recorded on: a name for :func:`faultgen.model.robots.load` (checked
        before the file is opened) or a loaded robot. Its joint range is used to recognise
        angles in degrees and angles out of range.
    accelerations : bool, default True
        Estimate ``qdd``; False leaves it NaN and saves its filter (a reader that needs no
        accelerations: an imported fleet's features, :mod:`faultgen.data.fleetlogs`).

    Returns
    -------
    MeasuredData
        With ``qd`` (when absent) and ``qdd`` estimated as described in the module docstring.

    Raises
    ------
    robots.UnknownRobotError
        For an unknown robot name; the message lists the known robots.
    MeasuredDataError
        When the file is missing, unreadable or has an unknown suffix; a column is missing
        (the message lists the missing and the present columns) or only some ``qd`` columns
        are present; a cell is empty, NaN, infinite or not a number (first such data row and
        column); ``t`` does not strictly increase (the data row where it repeats or goes
        back); the median sample period exceeds 0.01 s (< 100 Hz) or one interval exceeds
        :data:`MAX_GAP`; the data spans less than 2 s; a ``q`` column looks like degrees
        ("column q3 looks like degrees (max 170.2); expected rad") or leaves the robot's
        joint range by more than :data:`JOINT_RANGE_TOLERANCE` (column, row, value, range);
        a ``qd`` column looks like deg/s.

    Notes
    -----
    Degrees are recognised only where the values cannot be radians within the joint range:
    beyond a full turn, or spreading wider than the joint range, while the same numbers read
    as degrees fit. A joint that stays within a few degrees of zero looks the same in both
    units and is accepted. Smaller excursions out of range are refused as out of range, with
    a hint to convert when the values would fit as degrees.
    """
    robot = robot if isinstance(robot, robots.Robot) else robots.load(robot)
    path = Path(path)
    kind = _kind(path)
    _regular(path)
    if kind == "csv":
        columns, extra, row_label = _read_csv(path, robot.n_axes)
    else:
        columns, extra, row_label = _read_hdf5(path, robot.n_axes)
    notes = [f"ignored extra columns: {', '.join(extra)}"] if extra else []
    return _build(columns, robot, path, row_label, notes, accelerations)


def from_arrays(
    t: np.ndarray,
    q: np.ndarray,
    tau: np.ndarray,
    robot: str | Path | robots.Robot,
    qd: np.ndarray | None = None,
    source: str | Path | None = None,
) -> MeasuredData:
    """Check and complete arrays exactly as :func:`read` checks a file.

    Parameters
    ----------
    t : array_like of shape (n,)
        Sample times in s.
    q, tau : array_like of shape (n, N)
        Arm-side joint angles (rad) and torques (N m), N the robot's axes.
    robot : str, Path or robots.Robot
        As for :func:`read`.
    qd : array_like of shape (n, N), optional
        Arm-side joint velocities in rad/s; estimated from ``q`` when omitted.
    source : str or Path, optional
        Recorded as :attr:`MeasuredData.source` and used in messages; ``<arrays>`` by default.

    Returns
    -------
    MeasuredData

    Raises
    ------
    robots.UnknownRobotError, MeasuredDataError
        As for :func:`read`; rows are 1-based data rows with the 0-based index added.
    """
    robot = robot if isinstance(robot, robots.Robot) else robots.load(robot)
    where = Path(source) if source is not None else Path("<arrays>")
    columns = _columns_from_arrays(where, t, q, tau, qd, robot.n_axes)
    return _build(columns, robot, where, _index_label, [])


def from_columns(columns: dict[str, np.ndarray], robot: str | Path | robots.Robot, source: str | Path,
                 label=None, accelerations: bool = True) -> MeasuredData:
    """Check and complete the columns of a log in another layout, mapped onto this format's names
    (``t``, ``q1..qN``, ``tau1..tauN``, optional ``qd1..qdN``, ``temperature1..N``, ``payload``,
    ``cycle``; :mod:`faultgen.data.adapters`), exactly as :func:`read` checks a file.

    Parameters
    ----------
    columns : dict of ndarray of shape (n,)
    robot : str, Path or robots.Robot
    source : str or Path
        The file they came from, named in messages.
    label : callable, optional
        Data row index -> its description in messages (default: 1-based row and 0-based index).

    Raises
    ------
    MeasuredDataError
        As :func:`read`: a missing column, a non-finite value, times, rates, angles out of range.
    """
    robot = robot if isinstance(robot, robots.Robot) else robots.load(robot)
    where = Path(source)
    label = label or _index_label
    names = list(columns)
    wanted, _ = _select_columns(where, names, robot.n_axes)
    lengths = {len(np.asarray(columns[name])) for name in wanted}
    if len(lengths) > 1:
        raise MeasuredDataError(f"{where}: columns of different lengths {sorted(lengths)}")
    values = {name: np.asarray(columns[name], dtype=float) for name in wanted}
    _refuse_non_finite(where, values, wanted, label)
    return _build(values, robot, where, label, [], accelerations)


def _kind(path: Path) -> str:
    name = path.name.lower()
    if name.endswith(CSV_SUFFIXES):
        return "csv"
    if name.endswith(HDF5_SUFFIXES):
        return "hdf5"
    accepted = ", ".join(CSV_SUFFIXES + HDF5_SUFFIXES)
    raise MeasuredDataError(
        f"{path}: unknown file type {''.join(path.suffixes) or '(no suffix)'!r}; expected {accepted}"
    )


def _regular(path: Path) -> None:
    """Refuse a missing file, a folder, a device or a FIFO (faultgen.inputs), as MeasuredDataError."""
    try:
        inputs.regular_file(path, "measured log")
    except inputs.InputError as err:
        raise MeasuredDataError(str(err)) from None


def _csv_label(i: int) -> str:
    return f"data row {i + 1} (line {i + 2})"


def _index_label(i: int) -> str:
    return f"data row {i + 1} (index {i})"


def _compression(path: Path) -> str | None:
    """The compression a file written under this name gets: gzip for ``.gz``."""
    return "gzip" if path.name.lower().endswith(".gz") else None


def _read_csv(path: Path, n_axes: int) -> tuple[dict[str, np.ndarray], list[str], object]:
    """Columns of a CSV file as float arrays, the ignored extra column names, the row labeller.

    A gzip-compressed file is recognised by its content, so a compressed log named ``.csv``
    reads like one named ``.csv.gz``.
    """
    try:
        with inputs.open_text(path, "measured log") as fh:
            header = next(csv.reader(fh), None)
    except inputs.InputError as err:
        raise MeasuredDataError(str(err)) from None
    except (OSError, UnicodeDecodeError, EOFError, zlib.error, csv.Error) as err:
        raise MeasuredDataError(f"{path}: cannot read the file as CSV: {err}") from err
    if not header:
        raise MeasuredDataError(
            f"{path}: the file is empty; expected a header row with the columns t, q1..q{n_axes}, tau1..tau{n_axes}"
        )
    names = [h.strip() for h in header]
    duplicated = sorted({n for n in names if names.count(n) > 1})
    if duplicated:
        raise MeasuredDataError(
            f"{path}: column(s) {', '.join(duplicated)} appear more than once in the header"
        )
    wanted, extra = _select_columns(path, names, n_axes)

    # All columns are parsed (extra ones as text) so that a row with too many or too few
    # fields is refused by the parser with its line number instead of being silently cut.
    read_kw = {
        "header": 0,
        "names": names,
        "index_col": False,
        "skip_blank_lines": False,
    }
    try:
        try:
            # Fast path: numbers throughout. Anything else is diagnosed from the text below.
            dtypes = {name: (float if name in wanted else str) for name in names}
            with inputs.open_text(path, "measured log") as fh:
                frame = pd.read_csv(fh, dtype=dtypes, **read_kw)
            # every column wanted (the common case): no reindexed copy of the frame
            values = (frame if list(frame.columns) == wanted else frame[wanted]).to_numpy(dtype=float)
            clean = bool(np.isfinite(values).all())
        except inputs.InputError:
            raise
        except (ValueError, TypeError):
            clean = False
        if not clean:
            with inputs.open_text(path, "measured log") as fh:
                text = pd.read_csv(fh, dtype=str, keep_default_na=False, na_filter=False, **read_kw)
            text = _drop_trailing_blank_rows(text)
            frame = _numbers_from_text(path, text, wanted)
    except inputs.InputError as err:
        raise MeasuredDataError(str(err)) from None
    except (OSError, EOFError, UnicodeDecodeError, pd.errors.ParserError, pd.errors.EmptyDataError) as err:
        raise MeasuredDataError(f"{path}: cannot read the file as CSV: {err}") from err
    if clean:  # the fast path's values, column by column
        columns = {name: values[:, k] for k, name in enumerate(wanted)}
    else:
        columns = {name: frame[name].to_numpy(dtype=float) for name in wanted}
    return columns, extra, _csv_label


def _drop_trailing_blank_rows(text: pd.DataFrame) -> pd.DataFrame:
    blank = (text.apply(lambda col: col.str.strip()) == "").all(axis=1).to_numpy()
    n = len(blank)
    while n and blank[n - 1]:
        n -= 1
    return text.iloc[:n]


def _numbers_from_text(path: Path, text: pd.DataFrame, wanted: list[str]) -> pd.DataFrame:
    """Convert text columns to floats; refuse at the first empty / NaN / non-numeric cell."""
    out = {}
    first: tuple[int, int, str, str] | None = None  # (row, column order, column, raw text)
    for order, name in enumerate(wanted):
        raw = text[name].str.strip()
        values = pd.to_numeric(raw, errors="coerce").to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size and (first is None or bad[0] < first[0]):
            first = (int(bad[0]), order, name, str(raw.iloc[bad[0]]))
        out[name] = values
    if first is not None:
        row, _, name, raw = first
        raise MeasuredDataError(f"{path}: {_csv_label(row)}, column {name}: {_describe_bad_cell(raw)}")
    return pd.DataFrame(out)


def _describe_bad_cell(raw: str) -> str:
    if raw == "":
        return "empty cell; expected a number"
    if raw.lower() in ("nan", "-nan", "+nan", "na", "n/a", "null", "none", "#n/a"):
        return f"value {raw!r} (NaN); expected a number"
    try:
        value = float(raw)
    except ValueError:
        return f"value {raw!r} is not a number"
    return f"value {raw!r} is not finite" if not math.isfinite(value) else f"value {raw!r} not understood"


def _select_columns(path: Path, names: list[str], n_axes: int) -> tuple[list[str], list[str]]:
    """Columns to read (required, plus all qd when present) and the extra ones; refuse missing."""
    present = set(names)
    n = n_axes
    qd_columns = column_names(n)[1]
    missing = [c for c in _required(n) if c not in present]
    if missing:
        shown = names if len(names) <= 40 else [*names[:40], f"... ({len(names)} in all)"]
        hint = ""
        if len(names) == 1 and ";" in names[0]:
            hint = "; the header seems to use ';' as separator, expected ','"
        elif len(names) == 1 and "\t" in names[0]:
            hint = "; the header seems to use tabs as separator, expected ','"
        raise MeasuredDataError(
            f"{path}: missing column(s) {', '.join(missing)}; found columns: {', '.join(shown) or '(none)'}"
            f"; required: t, q1..q{n}, tau1..tau{n} (qd1..qd{n} optional){hint}"
        )
    qd_present = [c for c in qd_columns if c in present]
    if qd_present and len(qd_present) != n:
        qd_missing = [c for c in qd_columns if c not in present]
        raise MeasuredDataError(
            f"{path}: velocity columns {', '.join(qd_present)} present but {', '.join(qd_missing)} missing; "
            f"give all of qd1..qd{n} or none (then they are estimated from q)"
        )
    wanted = [*_required(n), *qd_present]
    if all(c in present for c in temperature_columns(n)):  # some of them only: ignored, named as extra
        wanted += temperature_columns(n)
    wanted += [c for c in (PAYLOAD_COLUMN, CYCLE_COLUMN) if c in present]
    extra = [n for n in names if n not in wanted]
    return wanted, extra


def _read_hdf5(path: Path, n_axes: int) -> tuple[dict[str, np.ndarray], list[str], object]:
    with _open_hdf5(path) as fh:
        wanted, extra = hdf5_columns(fh, path, n_axes)
        columns = {}
        length = None
        for name in wanted:
            ds = fh[name]
            if ds.ndim != 1:
                raise MeasuredDataError(
                    f"{path}: dataset {name} has shape {ds.shape}; expected a 1-D dataset (n,)"
                )
            if ds.dtype.kind not in "fiu":
                raise MeasuredDataError(f"{path}: dataset {name} has dtype {ds.dtype}; expected numbers")
            unit = ds.attrs.get("unit", ds.attrs.get("units"))
            if unit is not None:
                unit = unit.decode() if isinstance(unit, bytes) else str(unit)
                if _unit_key(unit) != _unit_key(UNITS[name]):
                    raise MeasuredDataError(
                        f"{path}: dataset {name} has unit {unit!r}; expected {UNITS[name]!r}"
                    )
            if ds.shape[0] > MAX_ROWS:
                raise MeasuredDataError(f"{path}: dataset {name} declares {ds.shape[0]} rows; a log has at most "
                                        f"{MAX_ROWS} (MAX_ROWS: a day at 1 kHz)")
            if length is None:
                length = ds.shape[0]
            elif ds.shape[0] != length:
                raise MeasuredDataError(
                    f"{path}: dataset {name} has {ds.shape[0]} rows but {wanted[0]} has {length}; "
                    "all columns must have the same length"
                )
            columns[name] = np.asarray(ds[()], dtype=float)
    _refuse_non_finite(path, columns, wanted, _index_label)
    return columns, extra, _index_label


def hdf5_columns(fh: h5py.File, path: Path, n_axes: int) -> tuple[list[str], list[str]]:
    """The root datasets to read (required, plus all qd when present) and the extra ones (groups
    among them, marked); refuse missing columns, naming the groups at the root that hold none."""
    names = list(fh.keys())
    datasets = [n for n in names if isinstance(fh[n], h5py.Dataset)]
    groups = [n for n in names if isinstance(fh[n], h5py.Group)]
    try:
        wanted, extra = _select_columns(path, datasets, n_axes)
    except MeasuredDataError as err:
        if groups:
            raise MeasuredDataError(
                f"{err}; groups at the root: {', '.join(groups)} (columns must be 1-D datasets at the file root)"
            ) from None
        raise
    return wanted, extra + [f"{g}/ (group)" for g in groups]


@contextmanager
def _open_hdf5(path: Path):
    """The HDF5 log, opened read-only after faultgen.inputs refused links and virtual datasets that
    reach other files (MeasuredDataError naming the link)."""
    try:
        fh = h5py.File(path, "r")
    except OSError as err:
        raise MeasuredDataError(f"{path}: cannot read the file as HDF5: {err}") from err
    with fh:
        try:
            inputs.check_hdf5_links(fh, path)
        except inputs.InputError as err:
            raise MeasuredDataError(str(err)) from None
        yield fh


def _unit_key(unit: str) -> str:
    return "".join(ch for ch in unit.lower() if ch not in " *.·")


def _columns_from_arrays(where: Path, t, q, tau, qd, n_axes: int) -> dict[str, np.ndarray]:
    t = np.asarray(t, dtype=float)
    if t.ndim != 1:
        raise MeasuredDataError(f"{where}: t must have shape (n,), got {t.shape}")
    q_columns, qd_columns, tau_columns = column_names(n_axes)
    blocks = {"q": (q, q_columns), "tau": (tau, tau_columns)}
    if qd is not None:
        blocks["qd"] = (qd, qd_columns)
    columns = {T_COLUMN: t}
    for label, (arr, names) in blocks.items():
        arr = np.asarray(arr, dtype=float)
        if arr.shape != (t.shape[0], n_axes):
            raise MeasuredDataError(
                f"{where}: {label} must have shape ({t.shape[0]}, {n_axes}), got {arr.shape}"
            )
        columns.update({name: arr[:, k] for k, name in enumerate(names)})
    _refuse_non_finite(where, columns, list(columns), _index_label)
    return columns


def _refuse_non_finite(where: Path, columns: dict[str, np.ndarray], order: list[str], label) -> None:
    first = None
    for name in order:
        bad = np.flatnonzero(~np.isfinite(columns[name]))
        if bad.size and (first is None or bad[0] < first[0]):
            first = (int(bad[0]), name)
    if first is not None:
        row, name = first
        value = columns[name][row]
        what = "NaN" if np.isnan(value) else f"{value} (not finite)"
        raise MeasuredDataError(
            f"{where}: {label(row)}, column {name}: value {what}; expected a finite number"
        )


# --------------------------------------------------------------------------------------------
# Checks and derivatives


def check_time(t: np.ndarray, where: Path, label, notes: list[str]) -> tuple[np.ndarray, float]:
    """Refuse sample times that do not increase, a median period above 1 / :data:`MIN_RATE`, a gap
    above :data:`MAX_GAP` or a span below :data:`MIN_DURATION`; note long gaps in ``notes``. Returns
    the intervals and the median period, s."""
    n = t.shape[0]
    if n < 2:
        raise MeasuredDataError(
            f"{where}: {n} data row(s); expected at least {MIN_DURATION:g} s of data at >= {MIN_RATE:g} Hz"
        )
    dt = np.diff(t)
    back = np.flatnonzero(dt <= 0)
    if back.size:
        i = int(back[0]) + 1
        how = "repeats" if dt[i - 1] == 0 else "goes back"
        raise MeasuredDataError(
            f"{where}: column t {how} at {label(i)}: t = {float(t[i])!r} s after t = {float(t[i - 1])!r} s at "
            f"{label(i - 1)}; expected strictly increasing times"
        )
    period = float(np.median(dt))
    if period > (1.0 / MIN_RATE) * (1 + 1e-9):
        raise MeasuredDataError(
            f"{where}: column t has a median sample period of {period:.6g} s ({1 / period:.4g} Hz); "
            f"expected at most {1 / MIN_RATE:g} s (a sample rate of at least {MIN_RATE:g} Hz)"
        )
    gap = int(np.argmax(dt))
    if dt[gap] > MAX_GAP * (1 + 1e-9):
        raise MeasuredDataError(
            f"{where}: column t jumps by {dt[gap]:.6g} s from {label(gap)} to {label(gap + 1)}; "
            f"expected no interval longer than {MAX_GAP:g} s (the derivative filter window)"
        )
    duration = float(t[-1] - t[0])
    if duration < MIN_DURATION:
        raise MeasuredDataError(
            f"{where}: the data covers {duration:.6g} s ({n} data rows); expected at least {MIN_DURATION:g} s"
        )
    long_gaps = np.flatnonzero(dt > 2 * period)
    if long_gaps.size:
        notes.append(
            f"{long_gaps.size} sampling interval(s) longer than twice the median period {period:.6g} s, "
            f"the longest {dt[gap]:.6g} s before {label(gap + 1)}"
        )
    return dt, period


def _build(
    columns: dict[str, np.ndarray], robot: robots.Robot, where: Path, label, notes: list[str],
    accelerations: bool = True,
) -> MeasuredData:
    t = columns[T_COLUMN]
    n = t.shape[0]
    dt, period = check_time(t, where, label, notes)

    q_columns, qd_columns, tau_columns = column_names(robot.n_axes)
    q = np.column_stack([columns[c] for c in q_columns])
    tau = np.column_stack([columns[c] for c in tau_columns])
    _check_angles(where, q, robot, label)

    window = _savgol_window(period, n)
    uniform = _is_uniform(dt, period)
    if accelerations:
        qd_est, qdd = _derivatives(t, q, period, window, uniform)
    else:  # a reader that needs no qdd (an imported fleet's features) saves its filter
        (qd_est,) = _derivatives(t, q, period, window, uniform, orders=(1,))
        qdd = np.full_like(q, np.nan)
        notes.append("qdd not estimated (accelerations=False): NaN")
    filt = f"Savitzky-Golay, order {SAVGOL_ORDER}, window {window} samples ({window * period:.4g} s)"
    if not uniform:
        notes.append(
            f"sample period varies ({dt.min():.6g}..{dt.max():.6g} s): q resampled at the median period "
            f"{period:.6g} s with a cubic spline for differentiation, derivatives interpolated back"
        )
    estimated = qd_columns[0] not in columns
    if estimated:
        qd = qd_est
        notes.append(f"qd and qdd estimated from q: {filt}")
    else:
        qd = np.column_stack([columns[c] for c in qd_columns])
        notes.append(f"qd from the file; qdd estimated from q: {filt}")
        notes.extend(_check_velocities(where, qd, qd_est, window))
    notes.extend(_torque_notes(tau, robot))
    temperature = (np.column_stack([columns[c] for c in temperature_columns(robot.n_axes)])
                   if temperature_columns(robot.n_axes)[0] in columns else None)
    cycle = _cycles(where, columns[CYCLE_COLUMN], label) if CYCLE_COLUMN in columns else None

    return MeasuredData(
        t=t,
        q=q,
        qd=qd,
        qdd=qdd,
        tau=tau,
        source=where,
        velocity_estimated=estimated,
        robot=robot.name,
        notes=tuple(notes),
        joint_temperature=temperature,
        payload_mass=columns.get(PAYLOAD_COLUMN),
        cycle=cycle,
    )


def _cycles(where: Path, values: np.ndarray, label) -> np.ndarray:
    """The ``cycle`` column as whole numbers that never decrease, or refused at the first row that is not."""
    fractional = np.flatnonzero(values != np.round(values))
    if fractional.size:
        i = int(fractional[0])
        raise MeasuredDataError(f"{where}: {label(i)}, column {CYCLE_COLUMN}: value {values[i]!r}; expected a whole "
                                "cycle number")
    back = np.flatnonzero(np.diff(values) < 0)
    if back.size:
        i = int(back[0]) + 1
        raise MeasuredDataError(f"{where}: column {CYCLE_COLUMN} goes back at {label(i)}: {values[i]:g} after "
                                f"{values[i - 1]:g}; expected the samples of each cycle together, cycles in order")
    return values.astype(np.int64)


def _check_angles(where: Path, q: np.ndarray, robot: robots.Robot, label) -> None:
    """Refuse angle columns in degrees or outside the joint range (plus tolerance)."""
    tol = JOINT_RANGE_TOLERANCE
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
            raise MeasuredDataError(
                f"{where}: column {name} looks like degrees ({extreme} {col[peak]:.6g} at {label(peak)}, "
                f"span {np.ptp(col):.4g}); expected rad within the joint range [{lo:.4g}, {hi:.4g}] rad"
            )
        i = int(outside[0])
        hint = " (if the column is in degrees, convert it to rad)" if fits_as_degrees else ""
        raise MeasuredDataError(
            f"{where}: column {name} at {label(i)} is {col[i]:.6g} rad, outside the joint range "
            f"[{lo:.4g}, {hi:.4g}] rad of {robot.name} (tolerance {tol:g} rad){hint}"
        )


def velocity_rows(n: int, window: int) -> slice:
    """The rows over which given velocities are compared with the derivative of q (away from the ends)."""
    return slice(window, n - window) if n > 4 * window else slice(None)


def _check_velocities(where: Path, qd: np.ndarray, qd_est: np.ndarray, window: int) -> list[str]:
    """Refuse qd columns in deg/s; note columns that disagree with the derivative of q."""
    inner = velocity_rows(qd.shape[0], window)
    given, est = qd[inner], qd_est[inner]
    return velocity_verdicts(where, np.einsum("ij,ij->j", est, est), np.einsum("ij,ij->j", est, given), len(est))


def velocity_verdicts(where: Path, power: np.ndarray, cross: np.ndarray, size: int) -> list[str]:
    """:func:`_check_velocities` from the sums over its rows: per axis, ``power`` = sum of the
    estimated speed squared, ``cross`` = sum of estimated times given speed, over ``size`` rows."""
    notes = []
    q_columns, qd_columns, _ = column_names(len(power))
    for k, name in enumerate(qd_columns):
        power_k = float(power[k])
        if power_k / max(size, 1) < 1e-6:  # RMS below 1e-3 rad/s: too little motion to judge
            continue
        slope = float(cross[k] / power_k)
        if 40.0 <= slope <= 80.0:
            raise MeasuredDataError(
                f"{where}: column {name} looks like deg/s (it is {slope:.4g} times the derivative of "
                f"{q_columns[k]}); expected rad/s"
            )
        if not 0.8 <= slope <= 1.25:
            notes.append(
                f"column {name} is {slope:.3g} times the derivative of {q_columns[k]}; check its sign and unit"
            )
    return notes


def _torque_notes(tau: np.ndarray, robot: robots.Robot) -> list[str]:
    limit = robot.gear_ratio * robot.motor_torque_limit
    notes = []
    for k, name in enumerate(column_names(robot.n_axes)[2]):
        peak = float(np.max(np.abs(tau[:, k])))
        if peak > 1.5 * limit[k]:
            notes.append(
                f"column {name} reaches {peak:.4g} N m, above 1.5 x the arm-side torque limit "
                f"{limit[k]:.4g} N m (gear ratio x motor limit); check its unit and side"
            )
    return notes


def acceleration(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Second time derivative of ``x`` by the same Savitzky-Golay filter :func:`read` estimates
    ``qdd`` with (window :data:`SAVGOL_WINDOW` at the median period, resampled when the period
    varies): a model signal seen through it can be compared with one made of measured ``qdd``.

    Parameters
    ----------
    t : ndarray of shape (n,)
        Sample times, s, strictly increasing (as :func:`read` checked them).
    x : ndarray of shape (n, k)
        Signal per column.

    Returns
    -------
    ndarray of shape (n, k)
        Its filtered second derivative, unit of ``x`` per s^2.
    """
    t = np.asarray(t, dtype=float)
    dt = np.diff(t)
    period = float(np.median(dt))
    (xdd,) = _derivatives(t, np.asarray(x, dtype=float), period, _savgol_window(period, len(t)),
                          _is_uniform(dt, period), orders=(2,))
    return xdd


# --------------------------------------------------------------------------------------------
# Writing


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
    frame.to_csv(path, index=False, compression=compression)
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
