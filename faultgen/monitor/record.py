"""What the monitor says of one log, typed (issue 84 item 1): the statistics, the axis ranking and
scores, and with the twin each axis's wear as arrays (n_axes,), instead of rows keyed by formatted
column names. The output tables' columns (``scoreI``, ``wearI_lower``, ...) are made from these only
where a table is written (:mod:`faultgen.monitor.report`) or read back (:mod:`faultgen.monitor.tables`)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np


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
        """This row at the output tables' 6 significant digits (:mod:`faultgen.monitor.report`): the
        page drawn from a run's rows is the one ``faultgen report OUT`` draws from its scores.csv."""
        six = lambda values: np.array([float(f"{v:.6g}") for v in np.ravel(values)])  # noqa: E731
        wear = self.wear and dataclasses.replace(self.wear, **{f.name: six(getattr(self.wear, f.name)) for f in
                                                               dataclasses.fields(self.wear) if f.name != "tests"})
        return dataclasses.replace(self, scores=six(self.scores), wear=wear, **{
            k: float(f"{getattr(self, k):.6g}") for k in ("Q", "Q_limit", "T2", "T2_limit")})


def listed(unit: str, stamp: str, n_axes: int) -> LogRow:
    """A log listed while its unit learns again after a program change (scored when the learning
    is complete): no statistic, no score."""
    nan = float("nan")
    return LogRow(unit, stamp, "relearning", nan, nan, nan, nan, 0, (), np.full(n_axes, np.nan))
