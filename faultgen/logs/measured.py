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
``mode="interp"``): a cubic (:data:`~faultgen.derivatives.SAVGOL_ORDER`) least-squares fit over a
window of :data:`~faultgen.derivatives.SAVGOL_WINDOW` = 0.05 s, i.e. ``2 round(0.025 / dt) + 1``
samples at the median sample period ``dt`` (5 samples at 100 Hz, 13 at 250 Hz, 51 at 1 kHz). Its
pass band reaches about 25-35 Hz (Schafer 2011, "What is a Savitzky-Golay filter?"), well above
the joint motion of an industrial arm, while encoder noise at hundreds of Hz is rejected. Near both
ends the polynomial of the first / last window is used, so the first and last ~0.025 s are less
accurate.

The filter coefficients assume equally spaced samples. When the sample period varies by more
than :data:`~faultgen.derivatives.UNIFORM_TOLERANCE` (relative), ``q`` is first interpolated with
a cubic spline (:class:`scipy.interpolate.CubicSpline`, C2, so it adds no kinks to the second derivative)
onto a uniform grid at the median period, differentiated there, and the derivatives are
interpolated back onto the original sample times with a cubic spline. Applying the uniform
coefficients to jittered samples instead would bias the derivatives in proportion to the
timing error. Given ``qd`` columns are used as they are (not filtered); ``qdd`` is always
taken from ``q``. Torque is used as it is.

Given ``qd`` columns are checked against the derivative of ``q`` (their least-squares ratio over the
log, :func:`velocity_verdicts`): about 57.3 (deg/s) is refused; about the axis's gear ratio G
(within :data:`MOTOR_SIDE_TOLERANCE`) is the motor's speed, a controller's motor-side export: the
column is divided by G to the joint side and the note says so (``column qdK is motor-side: ...``,
:func:`motor_side_speeds`); a ratio that could be either is refused; any other ratio outside
0.8..1.25 is noted ("check its sign and unit") and used as it is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from faultgen import inputs
from faultgen.derivatives import SAVGOL_ORDER
from faultgen.derivatives import derivatives as _derivatives
from faultgen.derivatives import is_uniform as _is_uniform
from faultgen.derivatives import savgol_window as _savgol_window
from faultgen.model import robots
from faultgen.logs import jointlog
from faultgen.logs.columns import (
    CYCLE_COLUMN, MAX_CYCLE, MIN_CYCLE_TIME, PAYLOAD_COLUMN, T_COLUMN, LogError, column_names,
    temperature_columns,
)

#: Raised for a measured-data file that cannot be used: the joint log's one error type
#: (:class:`faultgen.logs.columns.LogError`, a ValueError naming the file, column and data row).
MeasuredDataError = LogError


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
        used, resampling, sampling gaps, suspicious torque magnitudes; one on a speed or torque
        column a :class:`ColumnNote` (its axis and kind as fields).

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


def read(path: str | Path | inputs.Held, robot: robots.Robot, accelerations: bool = True) -> MeasuredData:
    """Read, check and complete a measured-data file (format in the module docstring).

    Parameters
    ----------
    path : str, Path or faultgen.inputs.Held
        A ``.csv``, ``.csv.gz``, ``.h5`` or ``.hdf5`` file (suffix case-insensitive), or its bytes
        read once (:func:`faultgen.inputs.hold`: parsed from them, :attr:`MeasuredData.source` its path).
    robot : robots.Robot
        The robot the data was recorded on, resolved once by the caller
        (:func:`faultgen.model.robots.load`). Its joint range is used to recognise
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
    TypeError
        For a robot that is not a :class:`~faultgen.model.robots.Robot` (a name: resolve it once).
    MeasuredDataError
        When the file is missing, unreadable or has an unknown suffix; a column is missing
        (the message lists the missing and the present columns) or only some ``qd`` columns
        are present; a cell is empty, NaN, infinite or not a number (first such data row and
        column); ``t`` does not strictly increase (the data row where it repeats or goes
        back); the median sample period exceeds 0.01 s (< 100 Hz) or one interval exceeds
        :data:`~faultgen.logs.columns.MAX_GAP`; the data spans less than 2 s; a ``q`` column looks
        like degrees ("column q3 looks like degrees (max 170.2); expected rad") or leaves the robot's
        joint range by more than :data:`~faultgen.logs.columns.JOINT_RANGE_TOLERANCE` (column, row,
        value, range); a ``qd`` column looks like deg/s.

    Notes
    -----
    Degrees are recognised only where the values cannot be radians within the joint range:
    beyond a full turn, or spreading wider than the joint range, while the same numbers read
    as degrees fit. A joint that stays within a few degrees of zero looks the same in both
    units and is accepted. Smaller excursions out of range are refused as out of range, with
    a hint to convert when the values would fit as degrees.
    """
    robot = robots.require(robot, "measured.read")
    columns, extra, row_label = jointlog.read_columns(path, robot.n_axes)
    notes = [f"ignored extra columns: {', '.join(extra)}"] if extra else []
    return _build(columns, robot, inputs.path_of(path), row_label, notes, accelerations)


def from_arrays(
    t: np.ndarray,
    q: np.ndarray,
    tau: np.ndarray,
    robot: robots.Robot,
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
    robot : robots.Robot
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
    robot = robots.require(robot, "measured.from_arrays")
    where = Path(source) if source is not None else Path("<arrays>")
    columns = _columns_from_arrays(where, t, q, tau, qd, robot.n_axes)
    return _build(columns, robot, where, jointlog.index_label, [])


def from_columns(columns: dict[str, np.ndarray], robot: robots.Robot, source: str | Path,
                 label=None, accelerations: bool = True, notes: tuple[str, ...] = ()) -> MeasuredData:
    """Check and complete the columns of a log in another layout, mapped onto this format's names
    (``t``, ``q1..qN``, ``tau1..tauN``, optional ``qd1..qdN``, ``temperature1..N``, ``payload``,
    ``cycle``; :mod:`faultgen.logs.formats`), exactly as :func:`read` checks a file.

    Parameters
    ----------
    columns : dict of ndarray of shape (n,)
    robot : robots.Robot
    source : str or Path
        The file they came from, named in messages.
    label : callable, optional
        Data row index -> its description in messages (default: 1-based row and 0-based index).
    notes : tuple of str
        What the adapter chose (its torque source), first in :attr:`MeasuredData.notes`.

    Raises
    ------
    MeasuredDataError
        As :func:`read`: a missing column, a non-finite value, times, rates, angles out of range.
    """
    robot = robots.require(robot, "measured.from_columns")
    where = Path(source)
    label = label or jointlog.index_label
    names = list(columns)
    wanted, _ = jointlog.select_columns(where, names, robot.n_axes)
    lengths = {len(np.asarray(columns[name])) for name in wanted}
    if len(lengths) > 1:
        raise MeasuredDataError(f"{where}: columns of different lengths {sorted(lengths)}")
    values = {name: np.asarray(columns[name], dtype=float) for name in wanted}
    jointlog.refuse_non_finite(where, values, wanted, label)
    return _build(values, robot, where, label, list(notes), accelerations)


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
    jointlog.refuse_non_finite(where, columns, list(columns), jointlog.index_label)
    return columns


def _build(
    columns: dict[str, np.ndarray], robot: robots.Robot, where: Path, label, notes: list[str],
    accelerations: bool = True,
) -> MeasuredData:
    # a reader that needs no qdd (an imported fleet's features) saves its filter
    motion = jointlog.motion(columns, robot, where, label, notes, orders=(1, 2) if accelerations else (1,))
    t, q, dt, period, window, uniform = (motion[k] for k in ("t", "q", "dt", "period", "window", "uniform"))
    qd_est, qdd = motion["derivatives"] if accelerations else (*motion["derivatives"], np.full_like(q, np.nan))
    _, qd_columns, tau_columns = column_names(robot.n_axes)
    tau = np.column_stack([columns[c] for c in tau_columns])
    if not accelerations:
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
        verdicts, sides = _check_velocities(where, qd, qd_est, window, robot.gear_ratio)
        notes.extend(verdicts)
        qd = qd / sides  # a motor-side column to the joint side
    notes.extend(torque_notes(tau, robot))
    temperature = (np.column_stack([columns[c] for c in temperature_columns(robot.n_axes)])
                   if temperature_columns(robot.n_axes)[0] in columns else None)
    cycle = _cycles(where, columns[CYCLE_COLUMN], label, t) if CYCLE_COLUMN in columns else None

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


def _cycles(where: Path, values: np.ndarray, label, t: np.ndarray) -> np.ndarray:
    """The ``cycle`` column as whole numbers 0..:data:`~faultgen.logs.columns.MAX_CYCLE` that
    never decrease, each cycle but the log's first and last spanning at least
    :data:`~faultgen.logs.columns.MIN_CYCLE_TIME` s, or refused at the first row that is not."""
    fractional = np.flatnonzero((values != np.round(values)) | (values < 0) | (values > MAX_CYCLE))
    if fractional.size:
        i = int(fractional[0])
        raise MeasuredDataError(f"{where}: {label(i)}, column {CYCLE_COLUMN}: value {values[i]:.6g}; expected a whole "
                                f"cycle number 0 .. {MAX_CYCLE:g}")
    back = np.flatnonzero(np.diff(values) < 0)
    if back.size:
        i = int(back[0]) + 1
        raise MeasuredDataError(f"{where}: column {CYCLE_COLUMN} goes back at {label(i)}: {values[i]:g} after "
                                f"{values[i - 1]:g}; expected the samples of each cycle together, cycles in order")
    starts = np.flatnonzero(np.diff(values)) + 1  # the first row of each cycle but the first
    spans = t[starts[1:] - 1] - t[starts[:-1]]  # first to last sample of each cycle between the first and last
    short = np.flatnonzero(spans < MIN_CYCLE_TIME)
    if short.size:
        i = int(starts[short[0]])
        raise MeasuredDataError(f"{where}: column {CYCLE_COLUMN}: cycle {values[i]:g} from {label(i)} spans "
                                f"{spans[short[0]]:.6g} s; expected cycles of at least {MIN_CYCLE_TIME:g} s "
                                "(but the log's first and last)")
    return values.astype(np.int64)


def cycle_slices(cycle: np.ndarray) -> list[slice]:
    """The rows of each cycle of a checked ``cycle`` column (n,) (:func:`_cycles`): one slice per run
    of equal values, in order."""
    edges = [0, *(np.flatnonzero(np.diff(cycle)) + 1).tolist(), len(cycle)]
    return [slice(a, b) for a, b in zip(edges, edges[1:])]


def velocity_rows(n: int, window: int) -> slice:
    """The rows over which given velocities are compared with the derivative of q (away from the ends)."""
    return slice(window, n - window) if n > 4 * window else slice(None)


def _check_velocities(where: Path, qd: np.ndarray, qd_est: np.ndarray, window: int,
                      gear_ratio: np.ndarray) -> tuple[list[str], np.ndarray]:
    """Refuse qd columns in deg/s; note columns that disagree with the derivative of q; find the
    motor-side ones (:func:`velocity_verdicts`)."""
    inner = velocity_rows(qd.shape[0], window)
    given, est = qd[inner], qd_est[inner]
    power, cross = np.einsum("ij,ij->j", est, est), np.einsum("ij,ij->j", est, given)
    return (velocity_verdicts(where, power, cross, len(est), gear_ratio),
            speed_sides(power, cross, len(est), gear_ratio))


#: How near a ``qd`` column's ratio to the derivative of its ``q`` must come to the axis's gear
#: ratio G (relative) to be read as the motor's speed, ``G qd`` (:func:`speed_sides`); the ratio is
#: a least-squares slope over the log, within 1 % of G on a motor-side column of any log the reader
#: takes (tests/test_life_motor_side.py).
MOTOR_SIDE_TOLERANCE = 0.05
#: The ratio of deg/s to rad/s.
DEG_PER_RAD = 180.0 / np.pi
#: The kinds of a reader's :class:`ColumnNote`: a ``qd`` column read as the motor's speed (divided by the
#: gear ratio), one of another ratio to ``q``'s derivative (kept), a ``tau`` column above 1.5 x the arm's limit.
MOTOR_SIDE_SPEED, SPEED_RATIO, TORQUE_ABOVE_LIMIT = "motor-side speed", "speed ratio", "torque above limit"
COLUMN_KINDS = (MOTOR_SIDE_SPEED, SPEED_RATIO, TORQUE_ABOVE_LIMIT)


class ColumnNote(str):
    """A reader's note on a column of axis ``axis`` (1-based; :attr:`MeasuredData.notes`), as written,
    with its ``kind`` (:data:`COLUMN_KINDS`): what it is about is read from these, never from its text."""

    def __new__(cls, text: str, axis: int = 0, kind: str = ""):  # the defaults: unpickled, set after
        note = super().__new__(cls, text)
        note.axis, note.kind = axis, kind
        return note


def _slopes(power: np.ndarray, cross: np.ndarray, size: int) -> np.ndarray:
    """Per axis the given speed's least-squares ratio to the derivative of q; NaN where the axis
    moves too little to judge (RMS below 1e-3 rad/s)."""
    power = np.asarray(power, dtype=float)
    moving = power / max(size, 1) >= 1e-6
    return np.where(moving, np.asarray(cross, dtype=float) / np.where(moving, power, 1.0), np.nan)


def _motor_side(slopes: np.ndarray, gear_ratio: np.ndarray | None) -> np.ndarray:
    """Per axis, whether its ``qd`` column is the motor's speed: ``|slope|`` within
    :data:`MOTOR_SIDE_TOLERANCE` of a gear ratio that is no ratio of the joint's own (0.8..1.25)."""
    if gear_ratio is None:
        return np.zeros(len(slopes), dtype=bool)
    g = np.asarray(gear_ratio, dtype=float)
    with np.errstate(invalid="ignore"):
        return (np.abs(np.abs(slopes) / g - 1.0) <= MOTOR_SIDE_TOLERANCE) & ((g < 0.8) | (g > 1.25))


def speed_sides(power: np.ndarray, cross: np.ndarray, size: int, gear_ratio: np.ndarray) -> np.ndarray:
    """What each given ``qd`` column is divided by to be the joint's speed, shape (N,): the axis's
    gear ratio where the column is the motor's speed (:func:`velocity_verdicts` notes it), else 1.
    Sums as :func:`velocity_verdicts`."""
    g = np.asarray(gear_ratio, dtype=float)
    return np.where(_motor_side(_slopes(power, cross, size), g), g, 1.0)


def velocity_verdicts(where: Path, power: np.ndarray, cross: np.ndarray, size: int,
                      gear_ratio: np.ndarray | None = None) -> list[str]:
    """:func:`_check_velocities` from the sums over its rows: per axis, ``power`` = sum of the
    estimated speed squared, ``cross`` = sum of estimated times given speed, over ``size`` rows.
    With the robot's ``gear_ratio`` (N,), a column about G times the derivative of q
    (:data:`MOTOR_SIDE_TOLERANCE`) is noted motor-side (a :class:`ColumnNote` of kind :data:`MOTOR_SIDE_SPEED`;
    the reader divides it by G: :func:`speed_sides`), and one that could be motor-side or deg/s alike is refused."""
    notes = []
    q_columns, qd_columns, _ = column_names(len(power))
    slopes = _slopes(power, cross, size)
    motor = _motor_side(slopes, gear_ratio)
    for k, name in enumerate(qd_columns):
        slope = float(slopes[k])
        if not math.isfinite(slope):  # too little motion to judge
            continue
        degrees = 40.0 <= slope <= 80.0
        if motor[k] and abs(slope / DEG_PER_RAD - 1.0) <= MOTOR_SIDE_TOLERANCE:
            raise MeasuredDataError(
                f"{where}: column {name} is {slope:.4g} times the derivative of {q_columns[k]}: deg/s or "
                f"the motor's speed (axis {k + 1}'s gear ratio {gear_ratio[k]:.4g}) alike; expected rad/s at "
                "the joint")
        if motor[k]:
            notes.append(ColumnNote(f"column {name} is motor-side: {slope:.4g} times the derivative of {q_columns[k]}, "
                                    f"axis {k + 1}'s gear ratio {gear_ratio[k]:.4g}; divided by it to the joint side "
                                    "(rad/s)", k + 1, MOTOR_SIDE_SPEED))
            continue
        if degrees:
            raise MeasuredDataError(
                f"{where}: column {name} looks like deg/s (it is {slope:.4g} times the derivative of "
                f"{q_columns[k]}); expected rad/s"
            )
        if not 0.8 <= slope <= 1.25:
            notes.append(ColumnNote(f"column {name} is {slope:.3g} times the derivative of {q_columns[k]}; check its "
                                    "sign and unit", k + 1, SPEED_RATIO))
    return notes


def motor_side_speeds(notes) -> tuple[int, ...]:
    """The axes (1-based) whose ``qd`` column a log's reader found motor-side and divided by the
    gear ratio, from its ``notes`` (their :class:`ColumnNote` of kind :data:`MOTOR_SIDE_SPEED`)."""
    return tuple(sorted({n.axis for n in notes if isinstance(n, ColumnNote) and n.kind == MOTOR_SIDE_SPEED}))


def torque_notes(tau: np.ndarray, robot: robots.Robot) -> list[str]:
    limit = robot.gear_ratio * robot.motor_torque_limit
    notes = []
    for k, name in enumerate(column_names(robot.n_axes)[2]):
        peak = float(np.max(np.abs(tau[:, k])))
        if peak > 1.5 * limit[k]:
            notes.append(ColumnNote(f"column {name} reaches {peak:.4g} N m, above 1.5 x the arm-side torque limit "
                                    f"{limit[k]:.4g} N m (gear ratio x motor limit); check its unit and side",
                                    k + 1, TORQUE_ABOVE_LIMIT))
    return notes


def acceleration(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Second time derivative of ``x`` by the same Savitzky-Golay filter :func:`read` estimates
    ``qdd`` with (window :data:`~faultgen.derivatives.SAVGOL_WINDOW` at the median period, resampled
    when the period varies): a model signal seen through it can be compared with one made of measured ``qdd``.

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
