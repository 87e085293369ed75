"""One unit's monitor, fed its logs one at a time in stamp order (:class:`UnitMonitor`).

A log arrives as its residual: the features minus the twin's expectation at the log's payload
(protocol ``twin``), or the features themselves (protocol ``own``). The first ``train`` logs are
the unit's own normal operation. On them, per feature, the monitor learns

- the unit's offset (the residual's mean: what neither the model nor the calibration explains,
  and the unit-to-unit spread: the per-unit normalisation of thesis ch. 4),
- the residual's slopes with the logged conditions that vary over those logs, joint temperature
  and payload (least squares; linear extrapolation beyond them: the seasonal change of friction,
  which the first weeks see only a little of, and the part of a payload's effect the twin gets
  wrong, or without the twin all of it),
- its noise (the standard deviation left, ``ddof`` = 1 + the slopes).

A later log's residual is the regression's prediction error at its conditions, so it is
standardised by the prediction interval's width, not by the noise alone: the noise times
``sqrt(1 + 1/m + x0' (X'X)^-1 x0)`` (``m`` learning logs, ``x0`` the log's conditions and ``X``
the learning logs', both centred on the learning mean: a least-squares regression's prediction
interval for a new observation, Montgomery & Runger, thesis ref. [66], ch. 11-12). Inside the learned range the factor is close to
1; a log 8 K warmer than learning logs that spanned 4 K is trusted to its slopes' standard error
times that distance, which a narrow first month learns only roughly,

and fits :class:`analysis.monitoring.PCAMonitor`, made by the registry (``pca_monitor`` of
:mod:`analysis.registry`) (Hotelling's T2 and Q, thesis eq. 2.3-2.6; the
Q limit out-of-fold, ``cv = 5``) on the standardised residuals. Every later log is standardised
the same way (with the twin, a feature's noise is widened by :data:`MODEL_UNCERTAINTY` of the
change the twin predicts from the nearest condition learned from: a new part is predicted, not
known) and scored. Without a twin (protocol ``own``) a log alarms when T2 or Q is above its
``1 - alpha`` limit. With the twin, T2 and Q are scored and charted the same way, but a log alarms
on the wear itself: each axis's wear is estimated from the residual's friction torques
(:data:`WEAR_FEATURES`) by weighted least squares along that axis's wear signature (the twin's
change of those features per % wear; the weights one
over each feature's variance: its noise times the prediction factor, squared, plus the twin's own
uncertainty of :data:`MODEL_UNCERTAINTY` of its predicted change; the estimate's standard error is
one over the root of the summed weights: the fault-magnitude estimate of a known fault direction,
Gertler 1998 ch. 8; Basseville & Nikiforov 1993 ch. 7), each axis's estimates are filtered over
the logs through a local linear trend (:class:`~faultgen.monitor.wear_trend.WearTrend`: a log's estimate scatters by 3-4 % of
wear, the filtered wear by about half that) whose state also holds the error of the learned
condition slopes along each axis's signature, learned on from every later log (slopes learned on a
month's narrow temperature range, extrapolated over a season, moved an unworn axis's wear by up to
14 points), and the log alarms when the lower :data:`WEAR_ALARM_CONFIDENCE` (90 %)
one-sided bound of the largest filtered wear reaches ``wear_limit`` % (:class:`Settings`).
T2 and Q alarm on any change the first logs did not show (drift of the season the unit's slopes
extrapolate, a new part); the wear estimate only on a change along a wear signature, and its bound
says how much wear, so a slow wear is called at a level and not when it first leaves the noise.
Either way the alarm rule (:mod:`faultgen.monitor.alarm`) makes the unit's alarm of its alarming
logs. An axis the program does not excite is :data:`NOT_OBSERVABLE` (:data:`NOT_OBSERVABLE_LIMITS`):
no wear, and it does not alarm. Each log's axes are ranked: with the twin by how closely the
residual points along each axis's wear signature (:func:`analysis.isolation.signature_scores`),
without it by each axis's reconstruction-based contribution to Q (Alcala and Qin, Automatica 45
(2009) 1593-1600: how much Q falls when the log is reconstructed along that axis's features; each
axis's share of Q, thesis eq. 3.3-3.4, smears a fault over the axes whose features are correlated
with it).

State is small and bounded per log (a row of scores each); a rerun on a grown folder rebuilds the
monitor by feeding it the stored inputs again (:mod:`faultgen.monitor.state`: JSON, no pickle) and
continues where the last one stopped.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from faultgen.monitor import record
# the stages' constants live with their stages; named here too, as the monitor's (noqa: re-exported)
from faultgen.monitor.alarm import WEAR_ALARM_CONFIDENCE, AlarmRule  # noqa: F401
from faultgen.monitor.baseline import FEATURES, NOT_OBSERVABLE_LIMITS, WEAR_FEATURES, WEAR_INTERVAL, Baseline  # noqa: F401
from faultgen.monitor.wear import SCALE_UNCERTAINTY, WearEstimator  # noqa: F401

PROTOCOLS = ("twin", "own")
#: Share of the twin's predicted change of a feature, from the nearest condition the unit's
#: learning logs saw, that counts as the twin's own uncertainty. Measured on the independent fleet
#: (an earlier draw of it, parts of 125 and 27 kg): the twin's change of the KR210's mean |torque|
#: between the two parts was within 2-12 % of Pinocchio's on axes 1-4 and 6, 57 % off on axis 5.
MODEL_UNCERTAINTY = 0.25


#: What an axis that is not observable is called (rul.csv's verdict, units.csv's reason, the page).
NOT_OBSERVABLE = "not observable on this program"


#: Largest ``wear_limit`` taken, % (a friction ten times its nominal is no longer wear to monitor).
MAX_WEAR_LIMIT = 1000.0
#: The fewest logs a unit is learned from (``train``), and the most logs ``train`` and ``persistence``
#: may name (years of a log an hour: beyond any fleet's record).
MIN_TRAIN, MAX_LOGS = 10, 100_000


@dataclass(frozen=True)
class Settings:
    """``protocol`` (:data:`PROTOCOLS`), ``train`` logs of normal operation, ``alpha``, PCA
    ``variance``, ``persistence`` (consecutive alarming logs) and, with the twin, ``wear_limit``:
    the wear, % increase of an axis's dry friction (Coulomb and Stribeck, thesis eq. 6.6) in % of
    the unit's own (its model's: calibrated on its first log, or nominal), that the lower
    one-sided :data:`WEAR_ALARM_CONFIDENCE` (90 %) bound of the wear filtered up to a log (its
    noise) must reach for the log to alarm; ``alpha`` is the significance of the T2
    and Q limits and of each log's own bound (``wearI_log_lower``).

    The default is 8 %, the lower edge of the 8-15 % true wear a first alarm should come in: the bound
    lies below the true wear (on >= 95 % of alarms), so an alarm comes at the limit or later. Its alarms
    on the real-cell fleets are in docs/analysis.md, "Issue 90: 8 % the default" (10 % before: "Wear in
    the robot's own scale")."""

    protocol: str = "twin"
    train: int = 28
    alpha: float = 0.01
    variance: float = 0.85
    persistence: int = 5
    wear_limit: float = 8.0

    def __post_init__(self) -> None:
        if self.protocol not in PROTOCOLS:
            raise ValueError(f"protocol = {self.protocol!r}; expected one of {', '.join(PROTOCOLS)}")
        if not (isinstance(self.train, int) and self.train >= MIN_TRAIN):
            raise ValueError(f"train = {self.train!r} logs; expected a whole number >= 10 (the unit's normal "
                             "operation, from which its offset, temperature slope and noise are learned)")
        if not 0 < self.alpha < 0.5:
            raise ValueError(f"alpha = {self.alpha!r}; expected a significance level in (0, 0.5)")
        if not (isinstance(self.persistence, int) and self.persistence >= 1):
            raise ValueError(f"persistence = {self.persistence!r}; expected a whole number of logs >= 1")
        if not 0 < self.wear_limit <= MAX_WEAR_LIMIT:
            raise ValueError(f"wear_limit = {self.wear_limit!r} %; expected a number in (0, {MAX_WEAR_LIMIT:g}] (the "
                             "wear, % of the axis's own dry friction, the estimate must be sure of before a log alarms)")


class UnitMonitor:
    """The monitor of one unit (module docstring), as stages over its :attr:`rows`: the program's
    :attr:`baseline` (:class:`faultgen.monitor.baseline.Baseline`; a later program's is swapped in
    for its logs by :class:`faultgen.monitor.programs.Baselines`), the :attr:`wear`
    (:class:`faultgen.monitor.wear.WearEstimator`: its filter and friction tests' scale), and the :attr:`alarm` rule
    (:class:`faultgen.monitor.alarm.AlarmRule`). ``signatures`` (n_axes, n_features): the first
    program's wear signatures in feature units per % (protocol ``twin``), or None."""

    def __init__(self, unit: str, settings: Settings, n_axes: int, signatures: np.ndarray | None = None):
        self.unit, self.settings, self.n_axes = unit, settings, n_axes
        self.baseline = Baseline(settings, n_axes, signatures)
        self.alarm = AlarmRule(unit, settings)
        #: The last maintenance or program change (what, stamp, rows before it), or None.
        self.since: tuple[str, str, int] | None = None
        self.rows: list[record.LogRow] = []
        self.last_stamp: str | None = None
        #: What the unit's programs met later borrow of its first program's learned baseline
        #: (:meth:`faultgen.monitor.baseline.Baseline.shared`), or None before it learned.
        self.shared_: dict | None = None
        self.wear = WearEstimator(settings, n_axes)

    # -- a new program ---------------------------------------------------------------------------
    def restart(self, stamp: str, reason: str) -> None:
        """The unit runs another program from the log ``stamp`` on (``reason`` says how it was
        found): its open alarm, if any, is closed by it, and the unit learns its normal operation
        again from this log on (``train`` logs), against the twin of the new program."""
        b = self.baseline
        self.alarm.close(b, stamp, reason)
        self.since, b.program_changed, b.placeholders = ("program change", stamp, len(self.rows)), True, 0
        b.training, b.learned_expectations = [], []
        b.pca, b.relearning = None, None
        self.alarm.reset()
        if self.wear.tests is not None:
            self.wear.tests.reset()

    # -- maintenance ----------------------------------------------------------------------------
    def maintenance(self, stamp: str, event: str, axis: int) -> None:
        """A repair or gearbox change (``event``) on ``axis`` (1..N) logged at ``stamp``, before the
        next log: the open alarm, if any, is closed by it (kept in the alarm's ``closed``), and the
        unit's offset (the residual's mean, every feature's) is learned again from the next
        ``relearn_logs`` logs, which are scored but do not alarm; its slopes, noise and PCA
        model stay. The wear estimate of every axis, the changed one's first, restarts from the new
        offset. During the first learning the learning restarts."""
        if self.wear.tests is not None:
            self.wear.tests.reset()
        b = self.baseline
        if b.pca is None:
            b.training, b.learned_expectations, b.placeholders = [], [], 0
            return
        self.alarm.close(b, stamp, f"{event} of axis {axis}")
        self.since = (f"{event} of axis {axis}", stamp, len(self.rows))
        self.alarm.reset()
        b.relearning = []
        self.wear.trend.reset()

    # -- learning -------------------------------------------------------------------------------
    def _fit(self) -> None:
        """Learn the baseline on its training logs (:meth:`faultgen.monitor.baseline.Baseline.fit`) and
        score them; the unit's first program's also starts the wear filter (:meth:`WearEstimator.start`) and
        keeps what the programs met later borrow (:attr:`shared_`)."""
        stamps, R, error, common = self.baseline.fit()
        if common is not None:
            self.shared_ = common
            self.wear.start(len(self.baseline.regressors_), error, self.baseline.gram_inv_)
        self.score_learning(stamps, R)

    def score_learning(self, stamps: list[str], R: np.ndarray, phase: str | None = None) -> None:
        """The rows of the learning logs ``stamps`` (residuals ``R`` less offset and slopes), in place of
        those listed for them since a program change; ``phase`` "relearning" after a program change,
        else "training" (None: as the baseline's ``program_changed`` says)."""
        b = self.baseline
        if b.placeholders:  # the rows standing for these logs since a program change (by stamp: another
            learned = set(stamps)  # program's logs may lie between them, faultgen.monitor.programs)
            self.rows[:] = [row for row in self.rows if row.stamp not in learned]
            b.placeholders = 0
        phase = phase or ("relearning" if b.program_changed else "training")
        b.program_changed = False
        for stamp, r in zip(stamps, R):
            wear = b.wear_estimate(r, b.scale_**2)
            self._score(stamp, r / b.scale_, phase=phase, wear=None if wear is None else (*wear, wear[1], None))

    # -- scoring --------------------------------------------------------------------------------
    def add(self, stamp: str, residual: np.ndarray, temperature: float, payload: float,
            expected: np.ndarray | None = None) -> None:
        """Take the next log (``stamp`` later than every earlier one): its residual (n_features,),
        mean joint temperature (deg C, NaN when not logged), payload (kg) and the twin's expected
        features at its conditions (n_features,; None without a twin)."""
        self.last_stamp = stamp
        b = self.baseline
        conditions = np.array([temperature, payload], dtype=float)
        if b.pca is None:
            b.training.append((stamp, np.asarray(residual, dtype=float), conditions))
            if expected is not None:
                b.learned_expectations.append(np.asarray(expected, dtype=float))
            if len(b.training) == b.learning_logs:
                self._fit()
            elif b.program_changed:  # listed at once (scored when the learning is complete)
                self.rows.append(record.listed(self.unit, stamp, self.n_axes))
                b.placeholders += 1
            return
        e = np.asarray(residual, dtype=float)
        relearned = b.relearning is not None
        if relearned:
            b.relearning.append((e, conditions))
            if len(b.relearning) == b.relearn_logs:
                b.learn_offset(*(np.stack(logs) for logs in zip(*b.relearning)))
                b.relearning = None
                self.wear.trend.reset()  # the wear restarts from the new offset
                if self.wear.tests is not None:
                    self.wear.tests.reset()
        factor = b.prediction_factor(conditions)
        z = b.standardise(e, conditions) / factor
        variance = (b.scale_ * factor) ** 2
        if expected is not None and b.learned_expectations:
            # the twin's prediction of a change from every condition learned from is trusted to
            # MODEL_UNCERTAINTY of its size: that much is added to the residual's noise
            change = np.min(np.abs(np.stack(b.learned_expectations) - expected), axis=0)
            z = z / np.sqrt(1.0 + (MODEL_UNCERTAINTY * change / b.scale_) ** 2)
            variance = variance + (MODEL_UNCERTAINTY * change) ** 2
        x = b.centred(conditions)
        wear = b.wear_estimate(e - b.mean_ - x @ b.slope_, variance)
        if wear is not None:
            # the trend carries the slopes' error in its state (WearTrend): its measurement's
            # error is the noise without the prediction interval's part from the slopes
            # (the offset's share, 1/m, stays: the trend's start carries it)
            noise = variance - (b.scale_ * factor) ** 2 + b.scale_**2 * (1.0 + 1.0 / b.learned_)
            trend_error = b.wear_estimate(np.zeros_like(e), noise)[1]
            wear = (*wear, trend_error, x)
        self._score(stamp, z, phase="relearning" if relearned else "monitoring", wear=wear)

    def _score(self, stamp: str, z: np.ndarray, phase: str, wear=None) -> None:
        b = self.baseline
        t2, q = (float(v[0]) for v in b.pca.score_samples(z[None]))
        alarm = q > b.pca.q_limit_ or t2 > b.pca.t2_limit_
        wear_row, at_once = None, False
        if wear is not None:
            wear, alarm, at_once, wear_row = self.wear.read(stamp, wear, b.observable_)
        scores = b.axis_scores(z)
        ranking = np.argsort(-scores, kind="stable") + 1
        if phase == "monitoring":
            self.alarm.step(b, stamp, z, t2, q, wear, alarm, at_once)
        self.rows.append(record.LogRow(self.unit, stamp, phase, q, b.pca.q_limit_, t2, b.pca.t2_limit_,
                                       int(alarm), tuple(int(a) for a in ranking), np.asarray(scores, dtype=float),
                                       wear_row))

    def alarm_row(self) -> dict:
        """The unit's current row of alarms.csv: its open alarm, or why there is none."""
        b = self.baseline
        row = {**self.alarm.open_alarm(), "closed": "", "closed_by": ""}
        if not self.alarm.first_alarm:
            row["evidence"] = (f"no persistent alarm in {len(self.rows)} logs" if b.pca is not None else
                               f"still learning: {len(b.training)} of {self.settings.train} logs")
            if self.since is not None and b.pca is not None:  # after maintenance or a program change
                what, stamp, before = self.since
                row["evidence"] = (f"no persistent alarm since the {what} of {stamp} ({len(self.rows) - before} logs "
                                   f"since, {len(self.rows)} in all)")
            elif self.since is not None and b.program_changed:
                row["evidence"] = (f"learning again after the program change of {self.since[1]}: "
                                   f"{len(b.training)} of {self.settings.train} logs")
            if b.relearning is not None:
                row["evidence"] += (f"; learning its offset again after maintenance: {len(b.relearning)} of "
                                    f"{b.relearn_logs} logs")
        return row

    def not_observable_note(self) -> str:
        """The axes not observable on the unit's program in words (:data:`NOT_OBSERVABLE_LIMITS`), or ""."""
        axes = np.flatnonzero(~self.baseline.observable_)
        if self.baseline.pca is None or not len(axes):
            return ""
        widths = ", ".join(f"axis {k + 1}: {self.baseline.width_[k]:.3g}" for k in axes)
        return (f"axis {', '.join(str(k + 1) for k in axes)} {NOT_OBSERVABLE} (no wear, trend or remaining life): "
                f"one log's 90 % interval of the wear is wider than {NOT_OBSERVABLE_LIMITS:g} x the wear limit "
                f"({NOT_OBSERVABLE_LIMITS * self.settings.wear_limit:g} points; {widths} points), so the logs cannot "
                "tell it unworn from worn to the limit")

    def alarm_rows(self) -> list[dict]:
        """The unit's rows of alarms.csv: every alarm closed by maintenance (``closed``,
        ``closed_by``), then its current row (:meth:`alarm_row`)."""
        return [*self.alarm.closed, self.alarm_row()]
