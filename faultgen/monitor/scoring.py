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
the logs through a local linear trend (:class:`WearTrend`: a log's estimate scatters by 3-4 % of
wear, the filtered wear by about half that) whose state also holds the error of the learned
condition slopes along each axis's signature, learned on from every later log (slopes learned on a
month's narrow temperature range, extrapolated over a season, moved an unworn axis's wear by up to
14 points), and the log alarms when the lower :data:`WEAR_ALARM_CONFIDENCE` (90 %)
one-sided bound of the largest filtered wear reaches ``wear_limit`` % (:class:`Settings`).
T2 and Q alarm on any change the first logs did not show (drift of the season the unit's slopes
extrapolate, a new part); the wear estimate only on a change along a wear signature, and its bound
says how much wear, so a slow wear is called at a level and not when it first leaves the noise.
Either way, a unit's alarm is persistent from the first of ``persistence`` consecutive alarming
logs (thesis ch. 3.4.1, :func:`analysis.monitoring.detect_onset`), known on the last of them
(``known`` in alarms.csv: the log on which a daily run sees it); with the twin a log whose lower
bound passes the limit by its own width alarms at once (without it, a log whose T2 or Q passes its
limit at ``alpha ** persistence``: as unlikely in normal operation as ``persistence`` independent logs
in a row past the ``alpha`` limits), and an alarm under way when a repair or
program change comes is closed by it, not forgotten. An axis the program does not excite
is :data:`NOT_OBSERVABLE` (:data:`NOT_OBSERVABLE_LIMITS`): no wear, and it does not alarm. Each log's axes are ranked: with the twin by how
closely the residual points along each axis's wear signature
(:func:`analysis.isolation.signature_scores`), without it by each axis's reconstruction-based
contribution to Q (Alcala and Qin, Automatica 45 (2009) 1593-1600: how much Q falls when the log is
reconstructed along that axis's features; each axis's share of Q, thesis eq. 3.3-3.4, smears a fault
over the axes whose features are correlated with it). The source axis of a persistent alarm is the
first of the ranking of the mean residual over the logs that made it persistent.

State is small and bounded per log (a row of scores each); a rerun on a grown folder rebuilds the
monitor by feeding it the stored inputs again (:mod:`faultgen.monitor.state`: JSON, no pickle) and
continues where the last one stopped.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from statistics import NormalDist

import numpy as np

from analysis.isolation import signature_scores
from analysis.monitoring import PCAMonitor
from faultgen.monitor import bounds, learning, record
from faultgen.monitor.wear_trend import WearTrend

PROTOCOLS = ("twin", "own")
#: The features the monitor watches per axis, in the order of a log's feature vector (by name, then
#: axis), which :mod:`faultgen.monitor.logs` computes. The RMS and average load torques: the two that
#: follow friction on an axis whose load keeps one sign (gravity), where the mean absolute torque
#: does not (friction adds on the way up what it takes on the way down: KR210 axis 2 at 40 % wear,
#: +0.01 % mean |torque|, +2 % RMS, +4.5 % average load torque); the histograms are left out (a
#: friction change of a few percent moves a 12-bin histogram by less than one bin).
#: ``friction_torque`` (:func:`faultgen.monitor.logs.friction_torque`, the monitor's own, not an
#: imported fleet's) moves by the mean |dry friction| over the motion, what the wear is stated in,
#: whatever the friction's shape: with it the second independent fleet's (a growing Stribeck hump)
#: median error fell from 4.37 to 3.90 points and the first law's three fleets' from 2.17, 1.90,
#: 2.89 to 1.92, 1.84, 2.41 (docs/analysis.md, "Wear in the robot's own scale").
FEATURES = ("rms_torque", "average_load_torque", "friction_torque")
#: The features each axis's wear (its magnitude, wear.csv) is read on; T2, Q and the ranking of the
#: axes use all :data:`FEATURES`. The friction torque alone: its change per % of an axis's dry
#: friction is the mean |dry friction| over the motion whatever the log's load, where the RMS and
#: the average load torque weigh friction by the torque it adds to, so the twin's signature
#: (simulated without a part, at the model's friction) misreads them on a log of another load or
#: friction (their response 0.64-1.08 of the signature's on the independent fleets' worn axes). Read
#: on it alone, the median error on the independent fleets fell from 1.98, 1.67, 2.39, 2.77, 2.10,
#: 2.85 to 2.40, 1.33, 1.65, 2.22, 1.96, 1.69 points (first law seeds 0, 1, 3, the second law, the
#: KR210 L150 and iiwa 14 fleets; docs/analysis.md, "The wear read on the friction torque").
WEAR_FEATURES = ("friction_torque",)
#: Share of the twin's predicted change of a feature, from the nearest condition the unit's
#: learning logs saw, that counts as the twin's own uncertainty. Measured on the independent fleet
#: (an earlier draw of it, parts of 125 and 27 kg): the twin's change of the KR210's mean |torque|
#: between the two parts was within 2-12 % of Pinocchio's on axes 1-4 and 6, 57 % off on axis 5.
MODEL_UNCERTAINTY = 0.25


#: Relative standard uncertainty of the wear signature's scale: how far the change of a unit's
#: features per % of its own dry friction may lie from its twin's, which the 90 % interval of each
#: wear estimate carries beside the noise (:meth:`UnitMonitor.wear_interval`). What it rests on
#: (docs/analysis.md, "Wear in the robot's own scale"): the signature's scale moved by 0.89-1.08
#: between the friction states of the independent fleet's units (their joints at 20-40 deg C, no
#: part or 25 kg) against the twin at the model's own friction, noise-free; and a calibrated
#: model's dry friction of the worn axis was 0.90-0.97 of the unit's own on seed 0 of that fleet
#: (the calibration fits some axes' Coulomb friction; the others stay nominal, 15 % unit spread).
#: Chosen on seeds 0 and 1 of that fleet, checked on a held-out seed and a second friction law.
SCALE_UNCERTAINTY = 0.10
#: The two-sided interval of each wear estimate in ``wear.csv``.
WEAR_INTERVAL = 0.90
#: Its two-sided normal quantile (1.645): the half-width of the interval in standard errors.
WEAR_INTERVAL_Z = NormalDist().inv_cdf(0.5 + WEAR_INTERVAL / 2)
#: One-sided confidence with which the filtered wear must have reached ``wear_limit`` for a log to
#: alarm: its lower bound is the filtered wear less this normal quantile (1.28) of its standard
#: error (``wearI_lower`` in scores.csv). Before the slope errors were in the trend's state an unworn
#: axis's filtered wear drifted with the season by up to 14 points, and the bound had to be the
#: ``1 - alpha`` one (2.33 errors at alpha 0.01) for no healthy unit to alarm, which put the alarms
#: at 10.8-29.2 % true wear for a 10 % limit. Chosen on seeds 0 and 1 of the independent fleet's
#: first law (alarms in 10-15 % true wear on 14 of 16 worn units at 0.90, 14 at 0.69, 13 at 0.84,
#: 12 at 0.95, 10 at 0.99; no healthy unit alarming at any), checked on a held-out seed, the second
#: law and the KR210 L150 and iiwa 14 fleets (docs/analysis.md, "Wear in the robot's own scale").
WEAR_ALARM_CONFIDENCE = 0.90


#: An axis is **not observable on this program** when one log's :data:`WEAR_INTERVAL` (90 %) interval of
#: its wear, from the noise at the learning logs' conditions (:meth:`UnitMonitor.wear_interval` of an
#: unworn axis: 2 x 1.645 standard errors), is wider than this many ``wear_limit``s (60 points at the
#: default 10 %). Why: the filtered wear's error is about half a log's (:class:`WearTrend`), so at that
#: width the filtered wear's own 90 % interval on an unworn axis spans -+1.5 limits: it cannot tell the
#: axis unworn from worn past the limit, and its wear, trend and remaining life would be the noise's
#: (a UR5 dispensing program's axis 2: one log's interval 258 points wide, its filtered wear
#: -36..+11 %). Such an axis gets no wear (empty cells in scores.csv and wear.csv), no remaining life
#: (rul.csv says why), and does not alarm. The independent KR210 fleet's axes (first law, seed 0) are
#: 7.8-23.3 points wide (0.8-2.3 limits): a margin of 2.6 below the rule, 4.3 above it to the UR5's.
NOT_OBSERVABLE_LIMITS = 6.0
#: What an axis that is not observable is called (rul.csv's verdict, units.csv's reason, the page).
NOT_OBSERVABLE = "not observable on this program"


#: Largest ``wear_limit`` taken, % (a friction ten times its nominal is no longer wear to monitor).
MAX_WEAR_LIMIT = 1000.0
#: The smallest significance of --protocol own's at-once limits (``alpha ** persistence``; the limits are
#: quantiles at ``1 - alpha``, which a double tells from 1 to about 1e-16): below it, no at-once rule.
FAR_ALPHA = 1e-12
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

    The default is 10 %; its alarms on two independent fleets are in
    docs/analysis.md, "Wear in the robot's own scale"."""

    protocol: str = "twin"
    train: int = 28
    alpha: float = 0.01
    variance: float = 0.85
    persistence: int = 5
    wear_limit: float = 10.0

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
    """The monitor of one unit (module docstring). ``signatures`` (n_axes, n_features): each axis's
    wear signature in feature units per % (protocol ``twin``), or None."""

    def __init__(self, unit: str, settings: Settings, n_axes: int, signatures: np.ndarray | None = None):
        self.unit, self.settings, self.n_axes = unit, settings, n_axes
        self.signatures = signatures
        self.training: list[tuple[str, np.ndarray, float]] = []
        self.pca: PCAMonitor | None = None
        self.window: deque = deque(maxlen=settings.persistence)
        self.run, self.far_ = 0, None
        self.first_alarm: str | None = None
        #: The stamp of the log on which the open alarm became known (persistent), as a daily run sees it.
        self.known: str | None = None
        #: The last maintenance or program change (what, stamp, rows before it), or None.
        self.since: tuple[str, str, int] | None = None
        #: Whether the unit learns again after a program change (its learning logs are ``relearning``).
        self.program_changed = False
        #: (n_axes,) whether each axis is observable on the program (:data:`NOT_OBSERVABLE_LIMITS`)
        #: and one log's 90 % interval width of each, points (:meth:`_fit`; all observable before it).
        self.observable_ = np.ones(n_axes, dtype=bool)
        self.width_ = np.zeros(n_axes)
        #: Rows of :attr:`rows` standing for the logs learned since a program change, not yet scored.
        self.placeholders = 0
        self.source_axis: int | None = None
        self.statistic = ""
        self.limit = float("nan")
        self.evidence = ""
        self.rows: list[record.LogRow] = []
        self.last_stamp: str | None = None
        self.learned_expectations: list[np.ndarray] = []
        #: Alarms closed by a maintenance event, oldest first (rows of alarms.csv).
        self.closed: list[dict] = []
        #: After a maintenance event: the offsets of the logs since, until :attr:`relearn_logs` (None otherwise).
        self.relearning: list[np.ndarray] | None = None
        #: (n_axes,) each axis's wear estimate's scatter on the learning logs over its stated
        #: standard error, at least 1 (:meth:`_fit`; 1 before it).
        self.dispersion_ = np.ones(n_axes)
        self.day_scatter_ = np.full(n_axes, np.nan)  # each axis's reads' day-to-day scatter, points (bounds.day_scatter)
        #: A program met after the unit learned: what it borrows of the unit's baseline
        #: (:func:`faultgen.monitor.learning.shared`), its own offset learned against it
        #: (:func:`faultgen.monitor.learning.fit_offset`); else None.
        self.borrowed_: dict | None = None
        #: Each axis's wear filtered over the logs (the wear reported and alarmed on).
        self.trend = WearTrend(n_axes)
        #: The unit's friction tests' scale (:class:`faultgen.monitor.friction_tests.Rescale`), or
        #: None: the wear in the twin's scale.
        self.tests = None

    @property
    def relearn_logs(self) -> int:
        """Logs after a repair or gearbox change from which the unit's offset is learned again:
        a quarter of ``train``, at least 5."""
        return max(5, self.settings.train // 4)

    @property
    def learning_logs(self) -> int:
        """The logs this baseline learns on: ``train``, or :attr:`relearn_logs` for a program (or torque
        source) met after the unit learned, which learns its offset alone (``borrowed_``)."""
        return self.settings.train if self.borrowed_ is None else self.relearn_logs

    # -- a new program ---------------------------------------------------------------------------
    def restart(self, stamp: str, reason: str) -> None:
        """The unit runs another program from the log ``stamp`` on (``reason`` says how it was
        found): its open alarm, if any, is closed by it, and the unit learns its normal operation
        again from this log on (``train`` logs), against the twin of the new program."""
        self._close(stamp, reason)
        self.since, self.program_changed, self.placeholders = ("program change", stamp, len(self.rows)), True, 0
        self.training, self.learned_expectations = [], []
        self.pca, self.relearning, self.run = None, None, 0
        self.window.clear()
        if self.tests is not None:
            self.tests.reset()

    # -- maintenance ----------------------------------------------------------------------------
    def maintenance(self, stamp: str, event: str, axis: int) -> None:
        """A repair or gearbox change (``event``) on ``axis`` (1..N) logged at ``stamp``, before the
        next log: the open alarm, if any, is closed by it (kept in :attr:`closed`), and the unit's
        offset (the residual's mean, every feature's) is learned again from the next
        :attr:`relearn_logs` logs, which are scored but do not alarm; its slopes, noise and PCA
        model stay. The wear estimate of every axis, the changed one's first, restarts from the new
        offset. During the first learning the learning restarts."""
        if self.tests is not None:
            self.tests.reset()
        if self.pca is None:
            self.training, self.learned_expectations, self.placeholders = [], [], 0
            return
        self._close(stamp, f"{event} of axis {axis}")
        self.since = (f"{event} of axis {axis}", stamp, len(self.rows))
        self.run = 0
        self.window.clear()
        self.relearning = []
        self.trend.reset()

    def _close(self, stamp: str, by: str) -> None:
        """Close the open alarm by ``by`` (a maintenance event or a program change) at ``stamp``; an
        alarm under way, the wear's lower bound over the limit on the last logs but fewer than
        ``persistence`` of them, is raised as it stands first and closed with it: a unit whose
        bound crossed the limit before its gearbox change does not end without an alarm."""
        if self.first_alarm is None and self.run and self.window and self.window[-1][4] is not None:
            self._raise(f"not yet persistent ({min(self.run, len(self.window))} of {self.settings.persistence} "
                        "logs) when it was closed")
        if self.first_alarm is not None:
            self.closed.append({**self._open_alarm(), "closed": stamp, "closed_by": by})
            self.first_alarm, self.known, self.source_axis, self.statistic = None, None, None, ""
            self.limit, self.evidence = float("nan"), ""

    # -- learning -------------------------------------------------------------------------------
    def _fit(self) -> None:
        """Learn the baseline on :attr:`training` (:func:`faultgen.monitor.learning.fit`)."""
        learning.fit(self, FAR_ALPHA, WEAR_INTERVAL_Z, NOT_OBSERVABLE_LIMITS)

    def _standardise(self, e: np.ndarray, conditions: np.ndarray) -> np.ndarray:
        x = np.nan_to_num(conditions[self.regressors_] - self.condition_mean_[self.regressors_])
        return (e - self.mean_ - x @ self.slope_) / self.scale_

    def prediction_factor(self, conditions: np.ndarray) -> float:
        """The prediction interval's width over the noise's for a log at ``conditions``
        (temperature deg C, payload kg): ``sqrt(1 + 1/m + x0' (X'X)^-1 x0)`` (module docstring)."""
        x = np.nan_to_num(conditions[self.regressors_] - self.condition_mean_[self.regressors_])
        return float(np.sqrt(1.0 + 1.0 / self.learned_ + x @ self.gram_inv_ @ x))

    def wear_columns(self) -> np.ndarray:
        """The positions of :data:`WEAR_FEATURES` in a feature vector of :data:`FEATURES` by name,
        then axis (``len(WEAR_FEATURES) * n_axes`` indices)."""
        n = self.n_axes
        return np.concatenate([FEATURES.index(name) * n + np.arange(n) for name in WEAR_FEATURES])

    def wear_estimate(self, residual: np.ndarray, variance: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """Each axis's wear, % of its own dry friction (n_axes,), and its standard error from the
        noise (n_axes,), from ``residual`` (n_features,: the features minus the twin's expectation,
        the unit's offset and its condition slopes) whose features have ``variance``
        (n_features,): weighted least squares of the :data:`WEAR_FEATURES` along each axis's wear
        signature (module docstring), the error times :attr:`dispersion_`. None without a twin.

        Raises ``ValueError`` when the signatures are not (n_axes, ``len(FEATURES) * n_axes``)."""
        if self.signatures is None:
            return None
        expected = (self.n_axes, len(FEATURES) * self.n_axes)
        if self.signatures.shape != expected:
            raise ValueError(f"wear signatures of shape {self.signatures.shape}; expected {expected} "
                             f"(each axis's change of {', '.join(FEATURES)} of every axis per %)")
        columns = self.wear_columns()
        signatures, residual, variance = self.signatures[:, columns], residual[columns], variance[columns]
        information = (signatures**2 / variance).sum(axis=1)
        error = self.dispersion_ / np.sqrt(information)
        return (signatures * residual / variance).sum(axis=1) / information, error

    @staticmethod
    def wear_interval(estimate: np.ndarray, error: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The :data:`WEAR_INTERVAL` (90 %) interval of wear ``estimate`` % whose noise has standard
        ``error`` %, both (n_axes,): the estimate -+ the normal quantile times ``sqrt(error^2 +
        (SCALE_UNCERTAINTY estimate)^2)``, the twin's model uncertainty (:data:`SCALE_UNCERTAINTY`,
        a share of the estimate: a scale) beside the noise. Returns (lower, upper), %."""
        return bounds.interval(estimate, bounds.standard_error(error, estimate, SCALE_UNCERTAINTY), WEAR_INTERVAL_Z)

    def _on_tests(self, stamp, estimate, error, log_estimate, log_error):
        """The filtered wear (with its error), its interval, alarm bound and the log's own estimate
        (with its error) on the unit's friction tests' scale (:mod:`faultgen.monitor.friction_tests`),
        and the row's twin-scale values, factors and scales."""
        factor, factor_error, names = self.tests.at(stamp, estimate, error)
        wear, sd = self.tests.wear(estimate, error, factor, factor_error)  # the scale's doubt in it (module bounds)
        low, high = bounds.interval(wear, sd, WEAR_INTERVAL_Z)
        lower = log_estimate - self.bound_quantile * log_error
        row = record.TestsScale(*(np.asarray(v, dtype=float) for v in (log_estimate, lower, factor, factor_error)),
                                tuple(names))
        return ((wear, factor * error), low, high, self.tests.floored(wear - self.alarm_quantile * sd),
                factor * log_estimate, factor * log_error, row)

    # -- ranking --------------------------------------------------------------------------------
    def axis_scores(self, z: np.ndarray) -> np.ndarray:
        """Each axis's isolation score for standardised residual(s) ``z`` (larger: more likely)."""
        if self.signatures is not None:
            return signature_scores(z, self.signatures / self.scale_)
        # each axis's features (by feature, then axis) reconstructed together
        axes = np.arange(self.pca.n_features_in_).reshape(-1, self.n_axes).T
        return self.pca.contributions(np.atleast_2d(z), "q", method="rbc", groups=axes).mean(axis=0)

    # -- scoring --------------------------------------------------------------------------------
    def add(self, stamp: str, residual: np.ndarray, temperature: float, payload: float,
            expected: np.ndarray | None = None) -> None:
        """Take the next log (``stamp`` later than every earlier one): its residual (n_features,),
        mean joint temperature (deg C, NaN when not logged), payload (kg) and the twin's expected
        features at its conditions (n_features,; None without a twin)."""
        self.last_stamp = stamp
        conditions = np.array([temperature, payload], dtype=float)
        if self.pca is None:
            self.training.append((stamp, np.asarray(residual, dtype=float), conditions))
            if expected is not None:
                self.learned_expectations.append(np.asarray(expected, dtype=float))
            if len(self.training) == self.learning_logs:
                self._fit()
            elif self.program_changed:  # listed at once (scored when the learning is complete)
                self.rows.append(record.listed(self.unit, stamp, self.n_axes))
                self.placeholders += 1
            return
        e = np.asarray(residual, dtype=float)
        relearned = self.relearning is not None
        if relearned:
            x = np.nan_to_num(conditions[self.regressors_] - self.condition_mean_[self.regressors_])
            self.relearning.append(e - x @ self.slope_)
            if len(self.relearning) == self.relearn_logs:
                self.mean_ = np.mean(self.relearning, axis=0)
                self.relearning = None
                self.trend.reset()  # the wear restarts from the new offset
                if self.tests is not None:
                    self.tests.reset()
        factor = self.prediction_factor(conditions)
        z = self._standardise(e, conditions) / factor
        variance = (self.scale_ * factor) ** 2
        if expected is not None and self.learned_expectations:
            # the twin's prediction of a change from every condition learned from is trusted to
            # MODEL_UNCERTAINTY of its size: that much is added to the residual's noise
            change = np.min(np.abs(np.stack(self.learned_expectations) - expected), axis=0)
            z = z / np.sqrt(1.0 + (MODEL_UNCERTAINTY * change / self.scale_) ** 2)
            variance = variance + (MODEL_UNCERTAINTY * change) ** 2
        x = np.nan_to_num(conditions[self.regressors_] - self.condition_mean_[self.regressors_])
        wear = self.wear_estimate(e - self.mean_ - x @ self.slope_, variance)
        if wear is not None:
            # the trend carries the slopes' error in its state (WearTrend): its measurement's
            # error is the noise without the prediction interval's part from the slopes
            # (the offset's share, 1/m, stays: the trend's start carries it)
            noise = variance - (self.scale_ * factor) ** 2 + self.scale_**2 * (1.0 + 1.0 / self.learned_)
            trend_error = self.wear_estimate(np.zeros_like(e), noise)[1]
            wear = (*wear, trend_error, x)
        self._score(stamp, z, phase="relearning" if relearned else "monitoring", wear=wear)

    @property
    def bound_quantile(self) -> float:
        """The standard normal's ``1 - alpha`` quantile: the lower bound of a log's own wear
        estimate (``wearI_log_lower``) is the estimate minus this many standard errors."""
        return float(NormalDist().inv_cdf(1.0 - self.settings.alpha))

    @property
    def alarm_quantile(self) -> float:
        """The standard normal's :data:`WEAR_ALARM_CONFIDENCE` quantile: the lower bound of the
        filtered wear (``wearI_lower``), which the alarm is judged on, is the filtered wear minus this
        many standard errors."""
        return float(NormalDist().inv_cdf(WEAR_ALARM_CONFIDENCE))

    def _score(self, stamp: str, z: np.ndarray, phase: str, wear=None) -> None:
        t2, q = (float(v[0]) for v in self.pca.score_samples(z[None]))
        alarm = q > self.pca.q_limit_ or t2 > self.pca.t2_limit_
        wear_row, at_once = None, False
        if wear is not None:
            log_estimate, log_error, trend_error, x = wear
            wear = estimate, error = self.trend.update(log_estimate, trend_error, x)
            # the log's own estimate less the slope errors' part at its conditions, as learned up
            # to it: the season the learned slopes extrapolate, which the remaining life's trend
            # would otherwise take for wear (docs/analysis.md, "The log's own estimate without
            # the season")
            log_estimate = log_estimate - self.trend.condition_part(x)
            bound = bounds.lower_bound(estimate, error, SCALE_UNCERTAINTY, self.alarm_quantile)  # with the scale's doubt
            # the interval keeps the log's own error: the filter averages out the scatter from log
            # to log, not the errors that stay for weeks (the learned temperature slopes
            # extrapolated over a season, the calibration's friction), which the learning logs
            # cannot tell apart (docs/analysis.md, "Wear in the robot's own scale")
            low, high = self.wear_interval(estimate, np.maximum(log_error, error))  # the filter's lag widens it
            tested = None
            if self.tests is not None:  # on the unit's friction tests' scale
                wear, low, high, bound, log_estimate, log_error, tested = self._on_tests(
                    stamp, estimate, error, log_estimate, log_error)
                estimate = wear[0]
            wear = (estimate, (estimate - bound) / self.alarm_quantile)  # the bound's error, as _raise reads it
            seen = self.observable_
            alarm = bool(np.max(np.where(seen, bound, -np.inf)) >= self.settings.wear_limit)
            # the lower bound above the limit by its own width (the filtered wear less two of its
            # quantiles): alarmed at once, persistence cannot hide it
            at_once = bool(np.max(np.where(seen, 2 * bound - estimate, -np.inf)) >= self.settings.wear_limit)
            hidden = np.where(seen, 1.0, np.nan)  # an axis not observable has no wear (NOT_OBSERVABLE_LIMITS)
            estimate, bound, low, high = estimate * hidden, bound * hidden, low * hidden, high * hidden
            log_estimate, log_error = log_estimate * hidden, log_error * hidden
            wear_row = record.AxisWear(*(np.asarray(v, dtype=float) for v in (
                estimate, bound, low, high, log_estimate, log_estimate - self.bound_quantile * log_error)), tested)
        scores = self.axis_scores(z)
        ranking = np.argsort(-scores, kind="stable") + 1
        if phase == "monitoring":
            self.run = self.run + 1 if alarm else 0
            self.window.append((stamp, z, t2, q, wear))
            if self.first_alarm is None and self.run >= self.settings.persistence:
                self._raise()
            elif self.first_alarm is None and alarm and (at_once or (self.far_ is not None and (
                    t2 > self.far_[0] or q > self.far_[1]))):
                self._raise("at once: " + ("its lower bound above the limit by more than its own width" if at_once else
                                           f"T2 or Q past its limit at alpha^{self.settings.persistence}"))
        self.rows.append(record.LogRow(self.unit, stamp, phase, q, self.pca.q_limit_, t2, self.pca.t2_limit_,
                                       int(alarm), tuple(int(a) for a in ranking), np.asarray(scores, dtype=float),
                                       wear_row))

    def _raise(self, how: str = "") -> None:
        """The alarm of the last ``run`` monitoring logs (at most ``persistence``): from the first
        of them, known on the last; ``how`` says how it was raised when not by ``persistence`` logs."""
        stamps, Z, t2, q, wear = zip(*list(self.window)[-min(self.run, len(self.window)):])
        self.first_alarm, self.known = stamps[0], stamps[-1]
        span = f"mean of {len(stamps)} logs from {stamps[0]} to {stamps[-1]}" + (f"; {how}" if how else "")
        if wear[0] is not None:  # the twin: the wear estimate alarmed
            estimate = np.mean([w[0] for w in wear], axis=0)
            bound = np.mean([w[0] - self.alarm_quantile * w[1] for w in wear], axis=0)
            order = np.argsort(-np.where(self.observable_, estimate, -np.inf), kind="stable")
            self.source_axis = int(order[0]) + 1
            self.statistic, self.limit = "wear", float(self.settings.wear_limit)
            self.evidence = (f"axis {self.source_axis} wear estimate {estimate[order[0]]:.3g} %, its lower "
                             f"{100 * WEAR_ALARM_CONFIDENCE:g} % bound {bound[order[0]]:.3g} % ({span}) >= limit "
                             f"{self.limit:g} % (% of the axis's own dry friction, weighted least squares of the friction "
                             f"torques along each axis's wear signature, filtered over the logs; the bound carries the scale's "
                             f"doubt and its reads' day-to-day scatter, {self.day_scatter_[order[0]]:.2g} points on its "
                             f"learning days); next axis {order[1] + 1}: {estimate[order[1]]:.3g} %")
            return
        mean = np.mean(Z, axis=0)
        scores = self.axis_scores(mean)
        order = np.argsort(-scores, kind="stable")
        self.source_axis = int(order[0]) + 1
        q_ratio, t2_ratio = np.mean(q) / self.pca.q_limit_, np.mean(t2) / self.pca.t2_limit_
        self.statistic = "Q" if q_ratio >= t2_ratio else "T2"
        value = float(np.mean(q) if self.statistic == "Q" else np.mean(t2))
        self.limit = float(self.pca.q_limit_ if self.statistic == "Q" else self.pca.t2_limit_)
        self.evidence = (f"{self.statistic} {value:.3g} ({span}) > limit {self.limit:.3g} at alpha "
                         f"{self.settings.alpha:g}; axis {self.source_axis} first by reconstruction-based "
                         "contribution to Q "
                         f"({scores[order[0]]:.3g}; next axis {order[1] + 1}: {scores[order[1]]:.3g})")

    def _open_alarm(self) -> dict:
        return {"unit": self.unit, "first_alarm": self.first_alarm or "", "known": self.known or "",
                "source_axis": "" if self.source_axis is None else self.source_axis,
                "statistic": self.statistic, "limit": "" if np.isnan(self.limit) else f"{self.limit:.6g}",
                "evidence": self.evidence}

    def alarm_row(self) -> dict:
        """The unit's current row of alarms.csv: its open alarm, or why there is none."""
        row = {**self._open_alarm(), "closed": "", "closed_by": ""}
        if not self.first_alarm:
            row["evidence"] = (f"no persistent alarm in {len(self.rows)} logs" if self.pca is not None else
                               f"still learning: {len(self.training)} of {self.settings.train} logs")
            if self.since is not None and self.pca is not None:  # after maintenance or a program change
                what, stamp, before = self.since
                row["evidence"] = (f"no persistent alarm since the {what} of {stamp} ({len(self.rows) - before} logs "
                                   f"since, {len(self.rows)} in all)")
            elif self.since is not None and self.program_changed:
                row["evidence"] = (f"learning again after the program change of {self.since[1]}: "
                                   f"{len(self.training)} of {self.settings.train} logs")
            if self.relearning is not None:
                row["evidence"] += (f"; learning its offset again after maintenance: {len(self.relearning)} of "
                                    f"{self.relearn_logs} logs")
        return row

    def not_observable_note(self) -> str:
        """The axes not observable on the unit's program in words (:data:`NOT_OBSERVABLE_LIMITS`), or ""."""
        axes = np.flatnonzero(~self.observable_)
        if self.pca is None or not len(axes):
            return ""
        widths = ", ".join(f"axis {k + 1}: {self.width_[k]:.3g}" for k in axes)
        return (f"axis {', '.join(str(k + 1) for k in axes)} {NOT_OBSERVABLE} (no wear, trend or remaining life): "
                f"one log's 90 % interval of the wear is wider than {NOT_OBSERVABLE_LIMITS:g} x the wear limit "
                f"({NOT_OBSERVABLE_LIMITS * self.settings.wear_limit:g} points; {widths} points), so the logs cannot "
                "tell it unworn from worn to the limit")

    def alarm_rows(self) -> list[dict]:
        """The unit's rows of alarms.csv: every alarm closed by maintenance (``closed``,
        ``closed_by``), then its current row (:meth:`alarm_row`)."""
        return [*self.closed, self.alarm_row()]
