"""The monitor's tables read back (``units.csv``, ``alarms.csv``, ``scores.csv``, ``rul.csv``,
``life.csv``, ``wear.csv``, ``tests.csv`` of a monitor output folder): by one bounded, checked reader
(:func:`read`), for ``faultgen report OUT`` only (:func:`faultgen.monitor.page.read`; a monitor run
draws its page from the tables it holds, :class:`faultgen.monitor.record.Table`). A table is a
stranger's file when ``faultgen report`` is given a folder: its size is checked before it is read,
every cell's length and the number of axes as it is parsed; each refusal names the file and the row
or column."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from faultgen import inputs
from faultgen.axes import MAX_AXES
from faultgen.monitor import record, report
from faultgen.monitor.record import unescaped

#: Size bound of each table the page is read from (units.csv, alarms.csv, scores.csv, rul.csv,
#: life.csv, wear.csv, tests.csv), bytes, checked before it is read: scores.csv has a row of about
#: 0.4 kB per scored log (six axes, the twin's wear columns), so 80 000 logs, wear.csv six rows of
#: about 80 B, so 70 000; the page of so many is already too large for a browser.
CSV_MAX_BYTES = 32 * 2**20
#: Longest text cell read, characters: what the monitor writes (:data:`faultgen.monitor.report.CELL_MAX_CHARS`)
#: and the ``'`` of a formula escape.
CELL_MAX_CHARS = report.CELL_MAX_CHARS + 1
#: Columns holding a unit's or a log's name (a folder's or a file's: at most 255 bytes), and their
#: longest cell read, characters (with a formula escape): the page repeats a log's stamp in each trace
#: of its unit's chart.
NAME_COLUMNS = ("unit", "stamp", "first_alarm", "known", "last_log")
NAME_MAX_CHARS = 256


def read(folder: Path, name: str, required: tuple[str, ...],
         max_bytes: int | None = CSV_MAX_BYTES) -> tuple[list[str], list[dict]]:
    """The header and rows of ``folder/name``, text cells unescaped, read whole after checking its
    size (``max_bytes``; None: no bound),
    then parsed with every cell's length checked (:data:`CELL_MAX_CHARS`,
    :data:`NAME_MAX_CHARS` for :data:`NAME_COLUMNS`) and at most :data:`faultgen.axes.MAX_AXES`
    ``scoreI`` columns.

    Raises
    ------
    ValueError
        (:class:`faultgen.inputs.InputError` for the content) Naming the file, and the row or
        column at fault: missing, a link out of ``folder``, above its size bound, not UTF-8, a
        malformed row or a cell too long, too many axes, or without one of the ``required`` columns.
    """
    path = folder / name
    if not (path.exists() or path.is_symlink()):
        raise ValueError(f"{folder}: no {name}; give a `faultgen monitor` output folder")
    if not inputs.inside(path, folder) or not path.is_file():
        raise ValueError(f"{path}: not a file inside {folder} (a link out of the folder is not read)")
    what = "monitor output table"
    bound = path.stat().st_size if max_bytes is None else max_bytes
    reader = csv.reader(io.StringIO(inputs.read_text(path, what, bound), newline=""))
    try:
        columns = next(reader, [])
        missing = [c for c in required if c not in columns]
        if missing:
            raise inputs.InputError(f"{path}: no column {missing[0]}; is it a `faultgen monitor` output?")
        if len(columns) > inputs.CSV_MAX_COLUMNS:
            raise inputs.InputError(f"{path}: the header names {len(columns)} columns; the monitor writes at most "
                                    f"{inputs.CSV_MAX_COLUMNS}")
        axes_ = sum(1 for c in columns if c.startswith("score") and c[5:].isdigit())
        if axes_ > MAX_AXES:
            raise inputs.InputError(f"{path}: {axes_} score columns; a robot has at most {MAX_AXES} axes")
        limits = [NAME_MAX_CHARS if c in NAME_COLUMNS else CELL_MAX_CHARS for c in columns]
        rows = []
        for cells_ in reader:
            if not cells_:
                continue  # a blank line
            for cell, limit, column in zip(cells_, limits, columns):
                if len(cell) > limit:
                    raise inputs.InputError(f"{path}: row {reader.line_num}, column {column}: a cell of {len(cell)} "
                                            f"characters; the monitor writes at most {limit}")
            rows.append({k: unescaped(v) for k, v in zip(columns, cells_)} | dict.fromkeys(columns[len(cells_):], ""))
    except csv.Error as err:
        raise inputs.InputError(f"{path}: row {reader.line_num}: not a CSV row the monitor writes ({err})") from None
    return columns, rows


def _axis_values(row: dict, end: str, n_axes: int) -> np.ndarray:
    return np.array([_number(row.get(f"wear{k}{end}")) for k in range(1, n_axes + 1)], dtype=float)


def _number(value) -> float:  # a cell that is no number (empty, or planted text): NaN, as the page reads it
    try:
        return float(value)
    except (TypeError, ValueError):
        return float("nan")


def log_row(row: dict) -> record.LogRow:
    """A :class:`faultgen.monitor.record.LogRow` from a row of scores.csv's columns (read back, or
    written so by a benchmark or test): ``stamp``, ``phase``, optional ``unit``, ``Q``, ``T2`` and
    limits, ``alarm``, ``ranking``, ``scoreI``, and the twin's ``wearI``, ``wearI_lower``, ``wearI_5``,
    ``wearI_95``, ``wearI_log``, ``wearI_log_lower`` (with friction tests also ``wearI_twin_log``,
    ``wearI_twin_log_lower``, ``wearI_factor``, ``wearI_factor_error``, ``wearI_scale``); a missing
    number is NaN."""
    axes = [int(a) for k in row if k.startswith("wear") and (a := k[4:].split("_")[0]).isdigit()]
    scores = [int(k[5:]) for k in row if k.startswith("score") and k[5:].isdigit()]
    n_axes = max(axes + scores, default=0)
    wear = None
    if any(row.get(f"wear{k}{end}") not in (None, "") for k in axes for end in ("", "_log")):
        tests = None
        if "wear1_twin_log" in row:
            tests = record.TestsScale(*(_axis_values(row, end, n_axes) for end in (
                "_twin_log", "_twin_log_lower", "_factor", "_factor_error")),
                tuple(row.get(f"wear{k}_scale", "") for k in range(1, n_axes + 1)))
        wear = record.AxisWear(*(_axis_values(row, end, n_axes) for end in ("", "_lower", "_5", "_95", "_log",
                                                                             "_log_lower")), tests)
    ranking = tuple(int(a) for a in str(row.get("ranking", "")).split() if a.isdigit())
    return record.LogRow(row.get("unit", ""), row["stamp"], row["phase"],
                         *(_number(row.get(c)) for c in ("Q", "Q_limit", "T2", "T2_limit")),
                         int(a) if np.isfinite(a := _number(row.get("alarm"))) else 0, ranking,
                         np.array([_number(row.get(f"score{k}")) for k in range(1, n_axes + 1)]), wear)


def log_rows(rows: list[dict]) -> list[record.LogRow]:
    """:func:`log_row` of each row."""
    return [log_row(r) for r in rows]
