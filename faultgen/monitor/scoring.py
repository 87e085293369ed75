"""One unit's monitor, fed its logs one at a time in stamp order: its :class:`Stages` in its record,
the steps over them in :mod:`faultgen.monitor.steps`.

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
stages and rows by feeding them the stored inputs again (:func:`faultgen.monitor.steps.replay`) and
continues where the last one stopped.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# the stages' constants live with their stages; named here too, as the monitor's (noqa: re-exported)
from faultgen.monitor.alarm import WEAR_ALARM_CONFIDENCE, AlarmRule  # noqa: F401
from faultgen.monitor.baseline import FEATURES, NOT_OBSERVABLE_LIMITS, WEAR_FEATURES, WEAR_INTERVAL, Baseline  # noqa: F401
from faultgen.monitor.programs import Baselines
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


@dataclass
class Stages:
    """The stage objects one unit's logs are fed through, held by its record
    (:attr:`faultgen.monitor.history.UnitHistory.stages`; the steps: :mod:`faultgen.monitor.steps`):
    the program's ``baseline`` (:class:`~faultgen.monitor.baseline.Baseline`; a later program's, of
    ``programs``, swapped in for its logs), the ``wear`` estimator
    (:class:`~faultgen.monitor.wear.WearEstimator`: its filter and friction tests' scale), the
    ``alarm`` rule (:class:`~faultgen.monitor.alarm.AlarmRule`); ``since`` the last maintenance
    (what, stamp, rows before it; :func:`faultgen.monitor.steps.maintenance`) or None; ``shared`` what the programs met later
    borrow of the first program's learned baseline (:meth:`~faultgen.monitor.baseline.Baseline.shared`),
    or None before it learned."""

    settings: Settings
    n_axes: int
    baseline: Baseline
    wear: WearEstimator
    alarm: AlarmRule
    programs: Baselines = field(default_factory=Baselines)
    since: tuple[str, str, int] | None = None
    shared: dict | None = None

    @classmethod
    def new(cls, unit: str, settings: Settings, n_axes: int, signatures: np.ndarray | None = None) -> Stages:
        """Unit ``unit``'s stages before its first log; ``signatures`` (n_axes, n_features): its first
        program's wear signatures in feature units per % (protocol ``twin``), or None."""
        return cls(settings, n_axes, Baseline(settings, n_axes, signatures), WearEstimator(settings, n_axes),
                   AlarmRule(unit, settings))
