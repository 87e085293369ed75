"""Adapters: logs in the layouts robots and datasets really have, read into the measured format.

Each adapter maps a foreign file's columns onto the measured format's (``t``, ``q1..qN``,
``tau1..tauN`` arm side, optional ``qd1..qdN`` and ``cycle``) and hands them to
:func:`faultgen.data.measured.from_columns`, which checks them as it checks a measured log (the
same refusals, by data row). Registered by name (:func:`register`, :data:`ADAPTERS`), chosen with
``faultgen logs import --format NAME``; docs/dataset.md, "Adapters", gives each layout.

- ``ur-rtde``: Universal Robots' RTDE recorder CSV (comma- or space-separated; ``.csv`` or
  ``.csv.gz``): ``timestamp`` (s), ``actual_q_0..5`` (rad), optional ``actual_qd_0..5`` (rad/s) and
  ``joint_temperatures_0..5`` (deg C, all or none), and the joint torque: with ``torque_constants``
  given (N m/A at the joint, one per axis), the measured ``actual_current_0..5`` (A) times them;
  without, the commanded ``target_moment_0..5`` (N m). Which one was taken is the log's note.
- ``voraus``: the voraus-AD dataset's Parquet layout (Brockmann et al. 2023, CC BY-NC-SA 4.0: never
  shipped with faultgen; read from your copy): ``time`` (s), ``joint_position_1..6`` (rad),
  ``joint_velocity_1..6`` (rad/s) and ``motor_torque_1..6`` (N m at the motor, referred to the
  arm by the robot's gear ratio), 100 Hz; its ``sample`` column (one recording) becomes the cycle.
"""

from __future__ import annotations

import dataclasses
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from faultgen import inputs
from faultgen.data import measured
from faultgen.model import robots
from faultgen.operation import jointlog

#: name -> adapter class.
ADAPTERS: dict[str, type[Adapter]] = {}
#: Largest foreign log read, bytes on disk.
MAX_BYTES = 4 * 2**30
#: N m/A: the torque constants at the joint a ``ur-rtde`` log may be read with (a UR joint's is
#: about 10: the motor's 0.1 times the gear ratio 101).
MIN_TORQUE_CONSTANT, MAX_TORQUE_CONSTANT = 1e-3, 1e4


def register(name: str):
    """Class decorator: register an :class:`Adapter` under ``name`` (its ``--format``)."""
    def decorate(cls):
        cls.name = name
        ADAPTERS[name] = cls
        return cls
    return decorate


@dataclass(frozen=True)
class Adapter:
    """Base: ``suffixes`` (lower case) of the files it reads, and :meth:`columns` (the foreign file's
    columns as the measured format's, and the data-row labeller of its messages).

    ``reads_held``: :meth:`columns` takes the file's bytes read once (:class:`faultgen.inputs.Held`)
    for its path, reading through :mod:`faultgen.inputs` (``open_bytes``, ``open_text``,
    ``csv_header``) or from ``held.data``, so ``faultgen monitor`` opens each log once. False (the
    default, a plug-in written against a path): :meth:`read` hands it the held file's path, which
    it then opens again."""

    name = ""
    reads_held = False
    suffixes: tuple[str, ...] = ()

    def columns(self, path: Path, robot: robots.Robot) -> tuple:
        """``(columns, label)`` or ``(columns, label, notes)``: the file's columns under the
        measured format's names, the data-row labeller of messages, and what the reading chose
        (which torque source, say), kept in :attr:`faultgen.data.measured.MeasuredData.notes`."""
        raise NotImplementedError

    def read(self, path: Path, robot: robots.Robot, accelerations: bool = True) -> measured.MeasuredData:
        """Read and check one log (:func:`faultgen.data.measured.from_columns`; ``accelerations``
        as :func:`faultgen.data.measured.read`); ``path`` may be held (:attr:`reads_held`)."""
        given = path if self.reads_held and isinstance(path, inputs.Held) else inputs.path_of(path)
        columns, label, *notes = self.columns(given, robot)
        return measured.from_columns(columns, robot, inputs.path_of(path), label, accelerations,
                                     notes=notes[0] if notes else ())


def make(name: str, **options) -> Adapter:
    """The adapter ``name`` with its options.

    Raises
    ------
    ValueError
        For an unknown name (the message lists the known ones) or a bad option.
    """
    if name not in ADAPTERS:
        raise ValueError(f"unknown log format {name!r}; expected measured (the default) or one of "
                         f"{', '.join(ADAPTERS)}")
    cls = ADAPTERS[name]
    known = [f.name for f in dataclasses.fields(cls) if f.name != "suffixes"]
    unknown = [key for key in options if key not in known]
    if unknown:
        raise ValueError(f"log format {name} takes no option {', '.join(unknown)}"
                         + (f"; its options: {', '.join(known)}" if known else ""))
    return cls(**options)


def _require(path: Path, names: list[str], wanted: list[str], what: str) -> None:
    missing = [c for c in wanted if c not in names]
    if missing:
        raise measured.MeasuredDataError(f"{path}: missing column(s) {', '.join(missing)} of the {what} layout; found "
                                         f"{', '.join(names[:40]) or '(none)'}")


def _numbers(path: Path, frame: pd.DataFrame, wanted: list[str], label) -> dict[str, np.ndarray]:
    """The ``wanted`` columns as floats, refused at the first cell that is not a finite number."""
    out = {}
    for name in wanted:
        values = pd.to_numeric(frame[name], errors="coerce").to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise measured.MeasuredDataError(f"{path}: {label(int(bad[0]))}, column {name}: value "
                                             f"{frame[name].iloc[bad[0]]!r}; expected a finite number")
        out[name] = values
    return out


@register("ur-rtde")
@dataclass(frozen=True)
class URRTDE(Adapter):
    """Universal Robots' RTDE recorder CSV (module docstring).

    Parameters
    ----------
    torque_constants : tuple of float, optional
        N m/A at the joint, per axis: read the torque as ``actual_current_i`` times them when the
        file has no ``target_moment`` columns.
    """

    reads_held = True
    suffixes: tuple[str, ...] = (".csv", ".csv.gz")
    torque_constants: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        if self.torque_constants is not None:
            try:
                constants = np.asarray(self.torque_constants, dtype=float)
            except (TypeError, ValueError):
                constants = np.full(0, np.nan)
            if constants.ndim != 1 or not constants.size or not np.all(
                    (constants >= MIN_TORQUE_CONSTANT) & (constants <= MAX_TORQUE_CONSTANT)):
                raise ValueError(f"torque constants {self.torque_constants!r}: expected one number in "
                                 f"{MIN_TORQUE_CONSTANT:g} .. {MAX_TORQUE_CONSTANT:g} N m/A per axis")

    def columns(self, path: Path, robot: robots.Robot):
        n_axes = robot.n_axes
        inputs.regular_file(path, "RTDE log", MAX_BYTES)
        try:
            names, separator = inputs.csv_header(path, "RTDE log", separator=None)
        except inputs.InputError as err:
            raise jointlog.LogBoundError(str(err)) from None
        except (OSError, UnicodeDecodeError, EOFError) as err:
            raise measured.MeasuredDataError(f"{path}: cannot read the file as CSV: {err}") from err
        twice = sorted(name for name, count in Counter(names).items() if count > 1)
        if twice:
            raise measured.MeasuredDataError(f"{path}: column(s) {', '.join(twice[:10])} appear more than once in the "
                                             "header")
        label = jointlog.csv_label
        axes = range(n_axes)
        q = [f"actual_q_{k}" for k in axes]
        qd = [f"actual_qd_{k}" for k in axes]
        moment = [f"target_moment_{k}" for k in axes]
        current = [f"actual_current_{k}" for k in axes]
        temperature = [f"joint_temperatures_{k}" for k in axes]
        if self.torque_constants is not None and all(c in names for c in current):
            if len(self.torque_constants) != n_axes:
                raise ValueError(f"{len(self.torque_constants)} torque constants for a robot of {n_axes} axes")
            torque, scale = current, np.asarray(self.torque_constants, dtype=float)
            source = "torque from actual_current_i x the torque constants given (measured)"
        elif all(c in names for c in moment):
            torque, scale = moment, np.ones(n_axes)
            source = ("torque from target_moment_i (the controller's commanded moment, not a measurement; "
                      "--torque-constants K1,...,KN reads the measured actual_current_i instead)"
                      + (" (the file has actual_current_i)" if all(c in names for c in current) else ""))
        else:
            raise measured.MeasuredDataError(
                f"{path}: no joint torque: expected target_moment_0..{n_axes - 1} (N m), or actual_current_0.."
                f"{n_axes - 1} (A) with the torque constants given (--torque-constants)")
        with_temperature = all(c in names for c in temperature)
        wanted = ["timestamp", *q, *torque, *([c for c in qd] if all(c in names for c in qd) else []),
                  *(temperature if with_temperature else [])]
        _require(path, names, wanted, "RTDE recorder")
        jointlog.csv_rows(path, len(wanted), "an RTDE log", "RTDE log")
        values = _rtde_numbers(path, names, separator, wanted, label)
        q_names, qd_names, tau_names = measured.column_names(n_axes)
        out = {measured.T_COLUMN: values["timestamp"]}
        out.update({q_names[k]: values[q[k]] for k in axes})
        out.update({tau_names[k]: values[torque[k]] * scale[k] for k in axes})
        if qd[0] in values:
            out.update({qd_names[k]: values[qd[k]] for k in axes})
        if with_temperature:
            out.update({name: values[temperature[k]] for k, name in enumerate(jointlog.temperature_columns(n_axes))})
        return out, label, (source,)


def _rtde_numbers(path: Path, names: list[str], separator: str, wanted: list[str], label) -> dict[str, np.ndarray]:
    """The ``wanted`` columns of an RTDE log parsed as numbers (only they converted and kept: memory
    in proportion to the numbers, where reading every cell as text took 7 times the file), refused
    at the first cell that is not a finite number, found from the text in chunks of rows (every
    column of a row is tokenized, kept or not: a chunk's rows are bounded by all the columns)."""
    kw = {"sep": separator, "header": None, "names": names, "usecols": wanted, "skipinitialspace": True,
          "skiprows": 1, "chunksize": max(1_000, jointlog.CHUNK_CELLS // len(names))}
    parts = {name: [] for name in wanted}
    try:
        with inputs.open_text(path, "RTDE log", MAX_BYTES) as fh:
            for frame in pd.read_csv(fh, dtype=float, **kw):
                for name in wanted:
                    parts[name].append(frame[name].to_numpy(dtype=float))
        out = {name: jointlog.joined(parts[name]) for name in wanted}
        if all(bool(np.isfinite(column).all()) for column in out.values()):
            return out
    except inputs.InputError:
        raise
    except (ValueError, TypeError):  # a cell that is not a number: found from the text below
        pass
    del parts
    start = 0
    try:
        with inputs.open_text(path, "RTDE log", MAX_BYTES) as fh:
            for frame in pd.read_csv(fh, dtype=str, keep_default_na=False, **kw):
                _numbers(path, frame, wanted, lambda i, s=start: label(s + i))
                start += len(frame)
    except (inputs.InputError, measured.MeasuredDataError):
        raise
    except (ValueError, OSError, EOFError) as err:  # pandas's ParserError (an unbalanced quote) is a ValueError
        raise measured.MeasuredDataError(f"{path}: cannot read the file as an RTDE recorder CSV: "
                                         f"{' '.join(str(err).split())}") from None
    raise measured.MeasuredDataError(f"{path}: cannot read the file as CSV: a cell is not a number")


@register("voraus")
@dataclass(frozen=True)
class Voraus(Adapter):
    """The voraus-AD dataset's Parquet layout (module docstring)."""

    reads_held = True
    suffixes: tuple[str, ...] = (".parquet",)

    def columns(self, path: Path | inputs.Held, robot: robots.Robot):
        import pyarrow as pa
        import pyarrow.parquet as pq

        n_axes = robot.n_axes
        inputs.regular_file(path, "voraus-AD log", MAX_BYTES)
        source = pa.BufferReader(path.data) if isinstance(path, inputs.Held) else path  # held: not reopened
        names = pq.read_schema(source).names
        axes = range(1, n_axes + 1)
        position = [f"joint_position_{k}" for k in axes]
        velocity = [f"joint_velocity_{k}" for k in axes]
        torque = [f"motor_torque_{k}" for k in axes]
        wanted = ["time", *position, *torque, *(velocity if all(c in names for c in velocity) else [])]
        _require(path, names, wanted, "voraus-AD")
        sample = ["sample"] if "sample" in names else []
        # the rows from the file's metadata, before any is read: a few MB of constant columns may hold 10^8
        rows = pq.ParquetFile(source).metadata.num_rows
        jointlog.check_whole_rows(path, rows, len(wanted + sample), what="a voraus-AD log")
        frame = pq.read_table(source, columns=wanted + sample).to_pandas()
        label = jointlog.index_label
        values = _numbers(path, frame, wanted + sample, label)
        q_names, qd_names, tau_names = measured.column_names(n_axes)
        out = {measured.T_COLUMN: values["time"]}
        for k in range(n_axes):
            out[q_names[k]] = values[position[k]]
            out[tau_names[k]] = values[torque[k]] * robot.gear_ratio[k]  # motor side -> arm side
            if velocity[k] in values:
                out[qd_names[k]] = values[velocity[k]]
        if sample:
            out[measured.CYCLE_COLUMN] = values["sample"]
        return out, label
