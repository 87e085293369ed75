"""The joint-log format as data: the columns of a robot of N axes (``t``, ``q1..qN``, ``qd1..qdN``,
``tau1..tauN``, the optional operating conditions) and their units, the file suffixes, the bounds a
log is held to (rows, memory, sample rate, gaps, duration, values, cycles), and :class:`LogError`.
Every reader (:mod:`faultgen.logs.jointlog`, :mod:`faultgen.logs.blocks`, the formats) and writer
imports them from here; the format is documented in :mod:`faultgen.logs.measured`."""

from __future__ import annotations

from faultgen import axes, inputs
from faultgen.effects.payload import Payload
from faultgen.effects.temperature import Temperature

#: Column names of the format: ``t`` and, for a robot of N axes, :func:`column_names`.
T_COLUMN = "t"


def column_names(n_axes: int) -> tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]]:
    """The angle, velocity and torque columns of a robot of ``n_axes`` axes: ``q1..qN``,
    ``qd1..qdN``, ``tau1..tauN``."""
    numbers = range(1, n_axes + 1)
    return tuple(f"q{i}" for i in numbers), tuple(f"qd{i}" for i in numbers), tuple(f"tau{i}" for i in numbers)


def required(n_axes: int) -> tuple[str, ...]:
    """The columns every log of a robot of ``n_axes`` axes has: ``t``, ``q1..qN``, ``tau1..tauN``."""
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
#: Memory a log read whole (:func:`read_columns`: a log the calibration does not average down, an
#: imported fleet's log, the monitor's, an adapter's) may give the columns it reads, bytes (each
#: column as float64): its rows are bounded by this divided by 8 bytes times the columns read
#: (:func:`whole_rows`; 5.2 million rows of a 6-axis log's 13, 86 min at 1 kHz), checked before any
#: row is read, so a small file declaring or holding more (an 8 kB HDF5 log declaring 10^8 rows was
#: a MemoryError in ``logs import``) is refused. The checks and derivatives of a log read whole take
#: about three times its columns more (docs/reliability.md); a longer log is for the calibration's
#: streaming reader (:mod:`faultgen.logs.longlog`) or a replay's (:mod:`faultgen.operation.replay`).
WHOLE_MAX_BYTES = 512 * 2**20
#: Largest log file any reader takes, bytes on disk (its ``st_size``, checked before the file is
#: read, hashed or copied: a sparse file's apparent size costs nothing to make, ``truncate -s 2T``,
#: and was read whole before it was refused). A log read whole keeps at most :data:`WHOLE_MAX_BYTES`
#: of its columns; its text, with columns faultgen does not read, may be a few times that.
LOG_MAX_BYTES = 4 * 2**30
#: Cells of a CSV log parsed at a time when pandas reads it (a compressed log, or one pyarrow refused).
CHUNK_CELLS = 4_000_000

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
#: The values a log may hold, per column (prefix) -> (low, high, unit, what it is likely to be when
#: outside): no robot comes near them, and past them the features and fits overflow (a torque of
#: 1e300 squared) instead of naming the row. Angles are bounded by the robot's joint range
#: (:func:`check_angles`), cycle numbers by :data:`MAX_CYCLE`.
VALUE_BOUNDS = {
    T_COLUMN: (-1e10, 1e10, "s", "seconds since 1970 reach 2e9"),
    "qd": (-1e5, 1e5, "rad/s", "the fastest wrists turn 20 rad/s"),
    "tau": (-1e7, 1e7, "N m", "the largest arms' axes carry 1e5 N m"),
    TEMPERATURE_PREFIX: (-60.0, 250.0, "degC", "in deg C, not K or deg F"),
    PAYLOAD_COLUMN: (0.0, 1e4, "kg", "the largest arms carry 2.3 t"),
}
#: Largest cycle number of a log (a cycle a second for 30 years); cycle numbers are >= 0.
MAX_CYCLE = 10**9
#: Shortest cycle, s, but a log's first and last (which its ends may cut): a ``cycle`` column that
#: starts a new cycle every few samples is refused (each cycle's features are computed apart).
MIN_CYCLE_TIME = 0.1


class LogError(ValueError):
    """Raised for a joint log that cannot be used.

    The message starts with the file (or ``<arrays>``) and names the offending column and/or
    data row (1-based, header not counted) and what was expected.
    """


class LogBoundError(LogError, inputs.InputError):
    """A log refused before its rows are read, by a bound on the work or memory its reading would
    take (:data:`WHOLE_MAX_BYTES`, :data:`faultgen.inputs.CSV_MAX_COLUMNS`): both a :class:`LogError`
    and a :class:`faultgen.inputs.InputError`; the message names the file, the count and the bound."""
