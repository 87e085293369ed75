"""What the monitor says of one log, typed (issue 84 item 1): the statistics, the axis ranking and
scores, and with the twin each axis's wear as arrays (n_axes,), instead of rows keyed by formatted
column names. The output tables' columns (``scoreI``, ``wearI_lower``, ...) are made from these only
where a table is made (:mod:`faultgen.monitor.report`) or read back (:mod:`faultgen.monitor.tables`).

A run's output tables are held as :class:`Table` (issue 84 item 4): each CSV is written from it and
the page drawn from its rows as a reader gets them back (:meth:`Table.records`), so no run reads its
own outputs; only ``faultgen report OUT`` parses the files."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from faultgen.data import cells


@dataclass(frozen=True)
class TestsScale:
    """A log's wear on its unit's friction tests' scale (:mod:`faultgen.monitor.friction_tests`),
    per axis (n_axes,): the twin-scale own estimate and its lower bound, %, the factor onto the
    tests' scale with its error, and each axis's scale's name."""

    twin_log: np.ndarray
    twin_log_lower: np.ndarray
    factor: np.ndarray
    factor_error: np.ndarray
    scale: tuple[str, ...]


@dataclass(frozen=True)
class AxisWear:
    """A log's wear per axis (n_axes,), % of the axis's own dry friction: filtered (``estimate``)
    with the lower bound the alarm is judged on (``lower``) and its 90 % interval (``p5``,
    ``p95``); the log's own estimate (``log``) and its lower ``1 - alpha`` bound (``log_lower``);
    ``tests`` where the unit has friction tests. NaN for an axis not observable."""

    estimate: np.ndarray
    lower: np.ndarray
    p5: np.ndarray
    p95: np.ndarray
    log: np.ndarray
    log_lower: np.ndarray
    tests: TestsScale | None = None

    def with_log(self, log: np.ndarray, log_lower: np.ndarray) -> AxisWear:
        """A copy with the log's own estimate and its bound replaced."""
        return dataclasses.replace(self, log=np.asarray(log, dtype=float), log_lower=np.asarray(log_lower, dtype=float))


@dataclass(frozen=True)
class LogRow:
    """One scored (or listed) log of a unit: ``phase`` training, monitoring or relearning; T2 and Q
    with their limits (NaN when not scored); ``alarm`` 1 when the log alarms; ``ranking`` the axes
    (1-based) most likely first; ``scores`` each axis's isolation score (n_axes,); ``wear`` with the
    twin, else None."""

    unit: str
    stamp: str
    phase: str
    Q: float
    Q_limit: float
    T2: float
    T2_limit: float
    alarm: int
    ranking: tuple[int, ...]
    scores: np.ndarray
    wear: AxisWear | None = None

    def wear_at(self, axis: int, name: str = "estimate") -> float:
        """Field ``name`` of :attr:`wear` at ``axis`` (1-based), %; NaN without the twin or that axis."""
        values = getattr(self.wear, name, ())
        return float(values[axis - 1]) if 1 <= axis <= len(values) else np.nan

    def tabled(self) -> LogRow:
        """This row at the output tables' 6 significant digits (:mod:`faultgen.monitor.report`), its
        unit and stamp as read back (:func:`as_read`): the page drawn from a run's rows is the one
        ``faultgen report OUT`` draws from its scores.csv."""
        six = lambda values: np.array([float(f"{v:.6g}") for v in np.ravel(values)])  # noqa: E731
        wear = self.wear and dataclasses.replace(self.wear, **{f.name: six(getattr(self.wear, f.name)) for f in
                                                               dataclasses.fields(self.wear) if f.name != "tests"})
        return dataclasses.replace(self, unit=as_read(self.unit), stamp=as_read(self.stamp), scores=six(self.scores),
                                   wear=wear, **{
            k: float(f"{getattr(self, k):.6g}") for k in ("Q", "Q_limit", "T2", "T2_limit")})


def listed(unit: str, stamp: str, n_axes: int) -> LogRow:
    """A log listed while its unit learns again after a program change (scored when the learning
    is complete): no statistic, no score."""
    nan = float("nan")
    return LogRow(unit, stamp, "relearning", nan, nan, nan, nan, 0, (), np.full(n_axes, np.nan))


def unescaped(cell: str) -> str:
    """A text cell as it was before the CSV writer's formula escape (:mod:`faultgen.data.cells`)."""
    return cell[1:] if cell.startswith("'") and cell[1:].startswith(cells.FORMULA) else cell


def as_read(value) -> str:
    """The text a reader of a CSV file gets back (:func:`unescaped`) from a cell written as ``value``
    by :func:`faultgen.data.cells.writer`: None empty, a float as :mod:`csv` writes it (``repr``),
    anything else ``str``; text on one line, its formula escape undone."""
    text = "" if value is None else value if isinstance(value, str) else repr(value) if isinstance(value, float) \
        else str(value)
    return unescaped(cells.text(text))


@dataclass(frozen=True)
class Table:
    """One output table of a monitor run in memory: the file's ``name`` in OUT, its ``columns``
    and ``rows`` (each a list of cells as :func:`faultgen.data.cells.writer` takes them: text,
    numbers; a row shorter than the header is padded with empty cells when read)."""

    name: str
    columns: tuple[str, ...]
    rows: list[list]

    def write(self, folder: Path) -> Path:
        """Write ``folder/name`` (header and rows through :func:`faultgen.data.cells.writer`)."""
        path = Path(folder) / self.name
        with open(path, "w", newline="") as f:
            writer = cells.writer(f)
            writer.writerow(self.columns)
            writer.writerows(self.rows)
        return path

    def records(self) -> list[dict[str, str]]:
        """The rows as :func:`faultgen.monitor.tables.read` reads them back from the file: text cells
        by column name (:func:`as_read`), a short row's missing cells empty."""
        return [{c: as_read(v) for c, v in zip(self.columns, row)} | dict.fromkeys(self.columns[len(row):], "")
                for row in self.rows]
