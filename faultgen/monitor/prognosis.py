"""Remaining useful life per unit and axis: the time until an axis's wear estimate
reaches a failure wear, as a distribution, from a degradation trend fitted on the unit's wear
estimates (:mod:`faultgen.monitor.scoring`: per log and axis its own estimate ``wearI_log`` %, of the
axis's own dry friction, less the part of the learned condition slopes' error at the log's
conditions as the trend had learned it by then (the season the slopes extrapolate, which a trend
would take for wear), and its lower ``1 - alpha`` bound ``wearI_log_lower``; the estimate's
standard error is ``(wearI_log - wearI_log_lower) / z``, ``z`` the standard normal's ``1 - alpha``
quantile; not the wear filtered over the logs, ``wearI``, whose errors are not independent). Recomputed from the
unit's rows at every run, so it follows every new log; ``OUT/rul.csv`` (:func:`rul_table`).

Per axis:

1. **The logs fitted**: the unit's monitoring logs since its last maintenance (the rows of phase
   ``monitoring`` after the last ``relearning`` one: a new part starts a new trend). At least
   :data:`MIN_LOGS`; time in days since the last of them (stamps that are dates or date-times,
   :func:`faultgen.data.logfolder.parse_stamp`), or in logs (sequence-number stamps).
2. **The source axis of the unit's open alarm: four models over all of them** (the logs since
   the last maintenance, flat and then rising): the line, the exponential (3), the changepoint
   trend, flat until ``tc`` and a line after it, ``w(t) = w_now + b max(t, tc)``
   (:func:`faultgen.monitor.trends.fit_hinge`; ``tc`` among the logs from the 3rd to the 5th from
   the last, :data:`faultgen.monitor.trends.HINGE_MARGINS`, refined between its neighbours, its
   uncertainty in the covariance), and the **power-law rise**, flat and then ``c (t - t0)^p``, ``p``
   in [1, 4] (:func:`faultgen.monitor.trends.fit_power`: a rise that accelerates; ``p`` = 1 is the
   changepoint trend), and the **onset exponential**, flat and then exponential
   (:func:`faultgen.monitor.rul_forecast.fit_onset_exponential`: the power law's bounded exponent
   bends too slowly for an exponential wear, and the exponential over the whole block cannot be flat
   before the rise). When neither the changepoint trend nor the power law rises: the line and
   the exponential of the logs from the first alarm on (also the rule with ``changepoint=False``).
3. **Every other axis: the line and the exponential** (:func:`faultgen.monitor.trends.fit_models`),
   each by weighted least squares (``scipy``, weights one over each estimate's variance), written
   with the state now: ``w(t) = w0 + b t`` and ``w(t) = w0 + b (exp(k t) - 1) / k`` (Gebraeel et al.
   2005 with an offset; ``k`` >= 0, an accelerating wear; ``k`` -> 0 is the line).
   **The model average** (:func:`faultgen.monitor.trends.model_weights`): each model's **Akaike
   weight** (AICc, ``statsmodels.tools.eval_measures.aicc``, of the Gaussian likelihood with the
   variances' common scale fitted, on the same logs; ``exp(-dAICc / 2)`` normalised, Burnham &
   Anderson 2002, ch. 2.9); on the source axis (2), the average of the
   exponentials and the power law alone (the power law nests the changepoint trend and the line,
   which stay fitted to date the rise and name the model), their weights at learning rate 1/2,
   ``exp(-dAICc / 4)`` (:data:`faultgen.monitor.trends.WEIGHT_RATE`; docs/analysis.md,
   "Accelerating wear without running late"); and each model's parameters drawn in proportion to
   its weight (:func:`sample_counts`), so that the
   distribution carries the model uncertainty: where the logs cannot tell a line from an
   accelerating rise, part of the draws accelerate and the interval reaches earlier. ``model``
   in rul.csv names the simplest model within 2 of the least AICc (the rule before the average),
   ``models`` gives every weight. An axis whose named model's slope now is not above 0 at alpha has
   **no wear trend** (no number).
4. **Uncertainty**: each fit's covariance, scaled by the residuals' reduced chi-square when
   it is above one (the stated standard errors are a floor), sampled (:data:`SAMPLES` draws in all,
   multivariate normal, seeded; the exponential's ``k`` and the power law's ``p`` and ``t0`` kept in
   their bounds) into ProgPy's :class:`progpy.uncertain_data.UnweightedSamples` of the state now,
   each draw with a **scale** of the wear estimate: without friction tests log-normal, median 1,
   log standard deviation :data:`TWIN_SCALE_LOG_SD` (0.45: the twin's scale measured across friction
   laws; :func:`scale_draws`); where a test gives it, per axis, a normal of mean 1 and standard
   deviation ``scale_uncertainty``, the test's factor's relative error: the estimate is the wear times a scale
   the unit's logs cannot tell, so the wear reaches the failure wear when the estimate reaches
   the failure wear times that scale. More logs average the trend's scatter away, not the scale.
5. **Propagation**: ProgPy's :class:`progpy.predictors.MonteCarlo` runs each draw through
   :class:`WearTrend` (a :class:`progpy.PrognosticsModel` stepped by the exact solution of its
   model) up to :data:`HORIZON` days (logs), its event ``failure`` met at wear >= the failure wear
   times the draw's scale, the step ending on the crossing, so a time of event is exact.
6. **The row**: the median time of event, its 5 and 95 % quantiles (``numpy.quantile``,
   ``inverted_cdf``; a draw beyond the horizon later than any; on the source axis (2) the 5 % end,
   the service-by date, no later than that of any model of weight >= 0.01 alone,
   :func:`faultgen.monitor.rul_forecast.credible_low`, the verdict saying so), and the probability of failure
   within the horizon (one minus ProgPy's :func:`progpy.metrics.prob_success`). Below one half:
   **no end of life within the horizon**, without a number.
7. **Not yet predictable** (:func:`unpredictable`): the trend cannot yet tell the
   remaining life, and rul.csv says so in ``verdict`` with its cells empty (the draws' median and
   interval in the words), when (a) fewer than :data:`MIN_RISE_LOGS` (5) logs lie after the
   changepoint trend's changepoint, where the models that date a rise carry at least half the
   weight (a slope from 4 logs is the noise's: the monitor's persistence is 5 logs); (b) the 95 %
   end lies beyond the horizon (the trend cannot bound the life; without (a) and (c) its lower end,
   ``rul_5``, the service-by end a planner reads first, is still given; issue 90); or (c) two models of weight >=
   :data:`MIN_MODEL_WEIGHT` (0.1) have 5-95 % intervals of their own that do not overlap (the
   models disagree by more than their intervals). A wide interval alone is not "not yet
   predictable": without a friction test the estimate's scale is uncertain by a factor of about
   1.6 (one log standard deviation), and a life
   that does not know its scale says so by its width; withholding intervals wider than 3 times
   their median would withhold 4 covering, early answers at lambda on the accelerating fleets. Measured on the independent fleets: docs/analysis.md, "A remaining life
   that does not run late".

Why the fit is not ProgPy's own: ProgPy fits a model's parameters to run-to-failure data by
minimising an error (``PrognosticsModel.estimate_params``), without the parameters' covariance, and
its state estimators (Kalman and particle filters) track a model's state given its parameters; a
trend fitted to a short noisy health-indicator series with the uncertainty of its parameters is a
regression, so scipy's least squares with its covariance does that part and ProgPy the prediction,
its uncertainty types and metrics (``benchmarks/monitor_rul.py``).

The wear is in % of the axis's own dry friction (:mod:`faultgen.monitor.scoring`): in the twin's
scale, 0.5-0.7 % per % of true wear on the independent fleet, the remaining life to a 40 % estimate
runs late against the true wear (docs/analysis.md, "Remaining useful life").
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from statistics import NormalDist

import numpy as np

from faultgen.data import cells, logfolder
from faultgen.monitor import rul_forecast
from faultgen.monitor.record import Table
from faultgen.monitor.scoring import NOT_OBSERVABLE, SCALE_UNCERTAINTY
from faultgen.monitor.trends import AICC_MARGIN, MODELS, POWER_MAX, Fit, expm1_over, fit_models, model_weights

#: Default failure wear, % of the axis's own dry friction: the end of life the remaining life counts to.
FAILURE_WEAR = 40.0
#: Largest failure wear taken, %.
MAX_FAILURE_WEAR = 1000.0
#: How far ahead an end of life is looked for: days (date stamps) or logs (sequence numbers).
HORIZON = 365.0
#: Fewest logs a trend is fitted on (the monitor's default persistence: an alarm's own logs).
MIN_LOGS = 5
#: Largest relative standard uncertainty of a wear scale taken (:func:`scale_of_axis`).
MAX_SCALE_UNCERTAINTY = 10.0
#: Without a friction test (``scale_uncertainty=None``, the monitor's default): the standard
#: deviation of the natural log of the wear estimate's scale (the twin's estimate per % of true
#: wear), drawn log-normal with median 1: the spread of that scale measured on the independent
#: fleets' friction laws, the root mean square of ``ln(scale)`` over the worn units of the law where
#: it is widest (exponential hump 0.446 over 8 units; first law 0.101 over 40, Lorentzian hump 0.121
#: over 24): a new plant's law is not known, so the prior is as wide as the widest law measured
#: (docs/analysis.md, "A remaining life that knows it does not know its scale").
TWIN_SCALE_LOG_SD = 0.45
#: Draws of the fitted parameters propagated to a time of event.
SAMPLES = 1000
#: The interval given: 5 and 95 % quantiles of the time of event.
INTERVAL = (0.05, 0.95)
#: "Not yet predictable" (module docstring, 7): fewer logs than this since the rise began ...
MIN_RISE_LOGS = 5
#: ... or two models of at least this weight whose own 5-95 % intervals do not overlap.
MIN_MODEL_WEIGHT = 0.1
#: rul.csv's verdict of an axis not observable on the unit's program (no wear: :mod:`faultgen.monitor.scoring`).
UNOBSERVED = (f"{NOT_OBSERVABLE}: no wear, trend or remaining life (one log's 90 % interval of its wear is wider "
              "than faultgen.monitor.scoring.NOT_OBSERVABLE_LIMITS allows; units.csv says how wide)")
COLUMNS = ("unit", "axis", "stamp", "time_unit", "wear", "failure_wear", "model", "rul", "rul_5", "rul_95",
           "p_within_horizon", "horizon", "logs_fitted", "fitted_from", "verdict", "models")


@dataclass
class Remaining:
    """One row of ``rul.csv``: ``unit``, ``axis`` (1..N; None when the unit has no wear estimate),
    computed at ``stamp`` (the last log fitted), in ``time_unit`` ("days" or "logs"); ``wear`` the
    axis's wear at the last log, %, as wear.csv gives it (the filtered wear; the trend's wear now for
    rows without it), ``model`` (the model named, :func:`named_model`), ``rul`` the median time to
    ``failure_wear`` and ``rul_5``, ``rul_95`` its 5-95 % interval (None beyond the horizon),
    ``p_within_horizon``, ``horizon``, the ``logs_fitted`` from ``fitted_from``, ``verdict`` in
    words, ``models`` every model's weight in the average, and ``predictable`` False for "not yet
    predictable" (no median; ``rul_5`` alone where only the 95 % end is beyond the horizon; module
    docstring, 7). ``distribution``: ProgPy's time of event, from the last log (``UnweightedSamples`` with
    key ``failure``), for scoring; None without a fit."""

    unit: str
    axis: int | None
    stamp: str
    time_unit: str
    verdict: str
    failure_wear: float = FAILURE_WEAR
    horizon: float = HORIZON
    wear: float | None = None
    model: str = ""
    rul: float | None = None
    rul_5: float | None = None
    rul_95: float | None = None
    p_within_horizon: float | None = None
    logs_fitted: int = 0
    fitted_from: str = ""
    models: str = ""
    predictable: bool = True
    distribution: object = field(default=None, repr=False)

    @property
    def end_of_life(self) -> bool:
        """Whether an end of life lies within the horizon (:attr:`rul` is a number)."""
        return self.rul is not None


def import_progpy() -> None:
    """Import ProgPy with matplotlib's settings kept: ``progpy.visualize`` sets global rcParams
    (font size 14, line width 3, ...) when imported, which changed every chart drawn after it in
    the process (the monitor's charts of later units)."""
    import sys

    if "progpy" in sys.modules:
        return
    import matplotlib

    with matplotlib.rc_context():
        import progpy
        import progpy.visualize  # noqa: F401


def _wear_trend_model(failure_wear: float):
    """The ProgPy model of every trend (module docstring, 5), its event at ``failure_wear``."""
    import_progpy()
    from progpy import PrognosticsModel

    class WearTrend(PrognosticsModel):
        """``dw/dt = s``: with ``power`` 1, ``ds/dt = k s`` (a line, ``k`` = 0, or ``w0 + b (exp(k t)
        - 1) / k``); with ``power`` p > 1 (and ``k`` 0), the power-law rise ``c (age)^p`` above its
        flat level, ``s = c p age^(p-1)`` (:func:`faultgen.monitor.trends.power_curve`); stepped by
        the exact solution; the estimate's ``scale`` constant, the event at ``w`` >= the failure
        wear times it."""

        # ProgPy reads a model's names and defaults from these class attributes
        inputs = []  # noqa: RUF012
        states = ["wear", "slope", "growth", "age", "power", "scale"]  # noqa: RUF012
        outputs = ["wear"]  # noqa: RUF012
        events = ["failure"]  # noqa: RUF012
        default_parameters = {"failure_wear": failure_wear, "process_noise": 0.0,  # noqa: RUF012
                              "measurement_noise": 0.0,
                              "x0": {"wear": 0.0, "slope": 0.0, "growth": 0.0, "age": 1.0, "power": 1.0,
                                     "scale": 1.0}}

        def next_state(self, x, u, dt):
            k, s, age, p = x["growth"], x["slope"], x["age"], x["power"]
            if p > 1.0:
                wear = x["wear"] + s * ((age + dt) ** p - age**p) / (p * age ** (p - 1.0))
                slope = s * ((age + dt) / age) ** (p - 1.0)
            else:
                wear, slope = x["wear"] + s * expm1_over(k, dt), s * np.exp(k * dt)
            return self.StateContainer({"wear": wear, "slope": slope, "growth": k, "age": age + dt, "power": p,
                                        "scale": x["scale"]})

        def output(self, x):
            return self.OutputContainer({"wear": x["wear"]})

        def event_state(self, x):
            return {"failure": max(0.0, 1.0 - float(x["wear"]) / (self.parameters["failure_wear"] * x["scale"]))}

        def threshold_met(self, x):
            return {"failure": bool(x["wear"] >= self.parameters["failure_wear"] * x["scale"])}

    return WearTrend()


def sample_counts(weights, samples: int) -> np.ndarray:
    """Each model's number of draws, in proportion to its ``weights`` (summing to 1), ``samples`` in
    all (the largest remainders rounded up, ties to the first model). Shape (len(weights),)."""
    weights = np.asarray(weights, dtype=float)
    exact = weights / weights.sum() * samples
    counts = np.floor(exact).astype(int)
    order = np.argsort(-(exact - counts), kind="stable")
    counts[order[: samples - counts.sum()]] += 1
    return counts


def _states(fit: Fit, drawn: np.ndarray) -> np.ndarray:
    """A fit's drawn parameters (m, len(params)) as states (m, 5): wear, slope, growth, age, power;
    the power law's age and exponent kept within the bounds it was fitted in."""
    m = len(drawn)
    states = np.column_stack([drawn[:, 0], drawn[:, 1], np.zeros(m), np.ones(m), np.ones(m)])
    if fit.model in ("exponential", rul_forecast.ONSET):  # accelerating (fitted with k >= 0)
        states[:, 2] = np.maximum(drawn[:, 2], 0.0)
    elif fit.model == "power":
        low, high = fit.limits
        states[:, 3] = np.clip(drawn[:, 2], low[0], high[0])
        states[:, 4] = np.clip(drawn[:, 3], 1.0, POWER_MAX)
    return states


def _state_samples(fits, weights, samples: int, seed: int, scale_uncertainty: float | None):
    """The model average's draws (module docstring, 4): each fit's parameters drawn in proportion to
    its weight (:func:`sample_counts`), with a scale of the wear estimate drawn from a normal of mean
    1 and standard deviation ``scale_uncertainty`` (at least 0.05; a friction test's factor), or,
    where ``scale_uncertainty`` is None (no friction test), log-normal of median 1 and log standard
    deviation :data:`TWIN_SCALE_LOG_SD` (:func:`scale_draws`), as ProgPy's ``UnweightedSamples``
    of the state now; and each draw's model index (shape (samples,))."""
    import_progpy()
    from progpy.uncertain_data import UnweightedSamples

    rng = np.random.default_rng(seed)
    counts = sample_counts(weights, samples)
    states = np.concatenate([_states(f, rng.multivariate_normal(f.params, f.cov, size=c, method="eigh"))
                             for f, c in zip(fits, counts)])
    labels = np.repeat(np.arange(len(fits)), counts)
    scale = scale_draws(rng, samples, scale_uncertainty)
    names = ("wear", "slope", "growth", "age", "power")
    return UnweightedSamples([{**dict(zip(names, map(float, x))), "scale": float(c)}
                              for x, c in zip(states, scale)]), labels


def scale_draws(rng: np.random.Generator, samples: int, scale_uncertainty: float | None) -> np.ndarray:
    """``samples`` draws of the wear estimate's scale (shape (samples,), from ``rng``'s standard
    normals ``z``): ``max(1 + s z, 0.05)`` for a relative standard uncertainty ``s`` (a friction
    test's factor: its error is symmetric about the factor), ones for 0, and ``exp(TWIN_SCALE_LOG_SD
    z)`` for None, the twin's scale without a test: a factor 1/2 as likely as a factor 2, so that a
    wide prior widens the interval both ways and keeps its median at the scale 1 (a normal of the
    same spread would put 1 draw in 44 below 0.1, a crossing due now, and reach 1.74 at its 95 %
    where the log-normal's 5-95 % is 0.48-2.10)."""
    if scale_uncertainty is None:
        return np.exp(TWIN_SCALE_LOG_SD * rng.standard_normal(samples))
    if not scale_uncertainty:
        return np.ones(samples)
    return np.maximum(1.0 + scale_uncertainty * rng.standard_normal(samples), 0.05)


def time_of_event(fit, failure_wear: float, horizon: float = HORIZON, samples: int = SAMPLES, seed: int = 0,
                  scale_uncertainty: float | None = SCALE_UNCERTAINTY, weights=None):
    """ProgPy's Monte Carlo prediction of the time from now until the wear reaches ``failure_wear``
    under ``fit`` (a :class:`~faultgen.monitor.trends.Fit`, or a list of them drawn in proportion to
    ``weights``, the model average), the estimate's scale uncertain by ``scale_uncertainty`` (module
    docstring, 4-5; None: the twin's log-normal prior, :func:`scale_draws`): ``UnweightedSamples``
    with key ``failure`` (None beyond ``horizon``)."""
    fits = [fit] if isinstance(fit, Fit) else list(fit)
    drawn, _ = _state_samples(fits, [1.0] * len(fits) if weights is None else weights, samples, seed,
                              scale_uncertainty)
    return _propagate(drawn, failure_wear, horizon)


def _propagate(drawn, failure_wear: float, horizon: float):
    import_progpy()
    from progpy.predictors import MonteCarlo

    model = _wear_trend_model(failure_wear)

    def step(t, x):  # up to the horizon, ending on the crossing when it falls inside the step
        wear, slope, growth = float(x["wear"]), float(x["slope"]), float(x["growth"])
        age, power = float(x["age"]), float(x["power"])
        gap, left = failure_wear * float(x["scale"]) - wear, max(horizon - t, 1e-9)
        if gap <= 0:
            return 1e-9
        reach = np.inf
        if slope > 0:
            ratio = growth * gap / slope
            if power > 1.0:  # (age + T)^p = age^p + gap / c, c = slope / (p age^(p-1))
                reach = float((age**power + gap * power * age ** (power - 1.0) / slope) ** (1.0 / power) - age)
            elif abs(growth) < 1e-12:
                reach = gap / slope
            elif ratio > -1:
                reach = float(np.log1p(ratio) / growth)
        return float(min(left, max(reach * (1.0 + 1e-12), 1e-9)))

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = MonteCarlo(model).predict(drawn, dt=step, horizon=horizon, save_freq=horizon, events=["failure"])
    return result.time_of_event


def scale_of_axis(scale_uncertainty, axis: int, n_axes: int) -> float | None:
    """The relative standard uncertainty of ``axis``'s (1..``n_axes``) wear scale from
    ``scale_uncertainty``: one number for every axis, a mapping axis -> number (an axis not in it
    gets :data:`faultgen.monitor.scoring.SCALE_UNCERTAINTY`), or a sequence of ``n_axes`` numbers;
    None for None (no friction test: the twin's log-normal prior, :func:`scale_draws`).
    ValueError naming the value when a number is not in [0, :data:`MAX_SCALE_UNCERTAINTY`] or the
    sequence's length is not ``n_axes``. Above 1 is allowed: a scale read from one or two friction
    tests may be that uncertain (:mod:`faultgen.monitor.friction_tests`); each draw's scale is kept
    at 0.05 or more."""
    if scale_uncertainty is None:
        return None
    if isinstance(scale_uncertainty, Mapping):
        for key in scale_uncertainty:
            if isinstance(key, bool) or not isinstance(key, (int, np.integer)) or not 1 <= key <= n_axes:
                raise ValueError(f"scale_uncertainty axis {key!r}: expected an axis 1..{n_axes}")
        value = scale_uncertainty.get(axis, SCALE_UNCERTAINTY)
    elif isinstance(scale_uncertainty, (list, tuple, np.ndarray)):
        if len(scale_uncertainty) != n_axes:
            raise ValueError(f"scale_uncertainty = {list(scale_uncertainty)!r}: expected {n_axes} numbers, one per "
                             "axis")
        value = scale_uncertainty[axis - 1]
    else:
        value = scale_uncertainty
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)) or \
            not 0.0 <= float(value) <= MAX_SCALE_UNCERTAINTY:
        raise ValueError(f"scale_uncertainty of axis {axis} = {value!r}: expected the relative standard "
                         f"uncertainty of the wear estimate's scale, a number in [0, {MAX_SCALE_UNCERTAINTY:g}]")
    return float(value)


def remaining_life(unit: str, rows: list[dict], n_axes: int, *, alpha: float, failure_wear: float = FAILURE_WEAR,
                   keys: dict[str, float] | None = None, kind: str | None = None, since: str | None = None,
                   source_axis: int | None = None, horizon: float = HORIZON, samples: int = SAMPLES,
                   seed: int = 0, axes: list[int] | None = None, changepoint: bool = True,
                   scale_uncertainty=None) -> list[Remaining]:
    """Each axis's remaining life (:class:`Remaining`, axes 1..``n_axes``) from a unit's monitor
    rows (:class:`faultgen.monitor.record.LogRow`: ``stamp``, ``phase``, each log's own wear estimate
    ``wear.log`` and its lower bound ``wear.log_lower``, not the filtered ``wear.estimate``, whose errors are not independent from
    log to log as the trend's fit assumes) with the monitor's
    ``alpha``; ``keys`` the stamps' time keys and ``kind`` theirs
    (:func:`faultgen.data.logfolder.parse_stamp`; parsed from the stamps when None); ``since`` the
    first alarm of the open alarm, whose ``source_axis`` gets the model average with the changepoint
    trend and the power-law rise over the whole block (module docstring, 2; ``changepoint`` False:
    the line and the exponential of the logs from the alarm on) and is
    fitted from the alarm on when neither rises;
    ``scale_uncertainty`` the estimate's scale's (module docstring, 4; :func:`scale_draws`): None (no
    friction test) log-normal, :data:`TWIN_SCALE_LOG_SD`; else a test's relative one (0: none), one
    number, a mapping axis (1..N) -> number (an axis not in it: ``scoring.SCALE_UNCERTAINTY``) or
    ``n_axes`` numbers (:func:`scale_of_axis`); ``axes`` (1..N) the axes wanted, all when None. A
    unit without wear estimates (still learning, or protocol own) gets one row with axis None."""
    check_failure_wear(failure_wear)
    wanted = list(range(1, n_axes + 1)) if axes is None else list(axes)
    uncertainty = {axis: scale_of_axis(scale_uncertainty, axis, n_axes) for axis in wanted}
    stamp = rows[-1].stamp if rows else ""
    if not rows or rows[0].wear is None:
        why = "still learning: no wear estimate yet" if not rows else "no wear estimate (protocol own: no twin)"
        return [Remaining(unit, None, stamp, "", why, failure_wear, horizon)]
    block, keys, kind = monitoring_block(unit, rows, keys, kind)
    time_unit = "logs" if kind == logfolder.SEQUENCE else "days"
    per = 1.0 if kind == logfolder.SEQUENCE else 86400.0
    z = NormalDist().inv_cdf(1.0 - alpha)
    out = []

    def series(logs, axis):
        wear = np.array([r.wear.log[axis - 1] for r in logs], dtype=float)
        error = (wear - np.array([r.wear.log_lower[axis - 1] for r in logs], dtype=float)) / z
        t = np.array([keys[r.stamp] for r in logs], dtype=float)
        return (t - t[-1]) / per, wear, np.maximum(error, 1e-9)

    for axis in wanted:
        fitted, fits, now = block, [], None if rows[-1].wear is None else rows[-1].wear.estimate[axis - 1]
        if isinstance(now, float) and np.isnan(now):  # faultgen.monitor.scoring.NOT_OBSERVABLE_LIMITS
            out.append(Remaining(unit, axis, stamp, time_unit, UNOBSERVED, failure_wear, horizon))
            continue
        if since is not None and axis == source_axis:
            stamps = [r.stamp for r in block]
            if changepoint and since in stamps and len(block) >= MIN_LOGS:  # the whole block, flat then rising
                fits = rul_forecast.with_onset(fit_models(*series(block, axis), changepoint=True), *series(block, axis))
                if not any(f.changepoint is not None for f in fits):
                    fits = []
            if not fits:  # the logs from the alarm on
                fitted = block[stamps.index(since):] if since in stamps else block
        base = Remaining(unit, axis, stamp, time_unit, "", failure_wear, horizon, logs_fitted=len(fitted),
                         fitted_from=fitted[0].stamp if fitted else "", wear=None if now is None else float(now))
        if len(fitted) < MIN_LOGS:
            base.verdict = (f"too few logs for a trend: {len(fitted)} of {MIN_LOGS} since the "
                            f"{'first alarm' if fitted is not block else 'learning or the last maintenance'}")
            out.append(base)
            continue
        if not fits:
            fits = fit_models(*series(fitted, axis))
        if not fits:
            base.verdict = "no trend could be fitted"
            out.append(base)
            continue
        weights, named = model_weights(fits), named_model(fits)
        drawn, labels = _state_samples(fits, weights, samples, seed, uncertainty[axis])
        # rows without the filtered wear (a caller's own): the trend's wear now
        base.model, base.wear = named.model, base.wear if now is not None else float(np.median(drawn.key("wear")))
        base.models = ", ".join(f"{f.model} {w:.2f}" for f, w in zip(fits, weights))
        slope, slope_error = float(named.params[1]), float(np.sqrt(named.cov[1, 1]))
        if slope - z * slope_error <= 0:  # the named model's slope now, as before the model average
            base.verdict = (f"no wear trend (slope now {slope:.2g} +- {slope_error:.2g} % per {time_unit[:-1]}, not above "
                            f"0 at alpha {alpha:g}): no end of life within the horizon ({horizon:g} {time_unit})")
            out.append(base)
            continue
        row = _summarise(base, fits, weights, labels, _propagate(drawn, failure_wear, horizon), horizon,
                         series(fitted, axis)[0])
        out.append(_credible_low(row, fits, weights, labels, seed, uncertainty[axis]))
    return out


def monitoring_block(unit: str, rows: list, keys: dict[str, float] | None, kind: str | None):
    """The unit's monitoring rows since its last maintenance (the rows after the last that is not
    of phase ``monitoring``), their stamps' time ``keys`` and ``kind``
    (:func:`faultgen.data.logfolder.parse_stamp`; parsed when ``keys`` is None)."""
    block = []
    for row in reversed(rows):
        if row.phase != "monitoring":
            break
        block.append(row)
    block.reverse()
    if keys is None:
        parsed = [logfolder.parse_stamp(r.stamp, f"{unit}/{r.stamp}") for r in block]
        keys = {r.stamp: key for r, (key, _) in zip(block, parsed)}
        kind = parsed[0][1] if parsed else kind
    return block, keys, kind


def named_model(fits) -> Fit:
    """The model ``rul.csv`` names (column ``model``; the draws come from every model, column
    ``models``): the simplest (fewest parameters, in the order of
    :data:`faultgen.monitor.trends.MODELS`) whose AICc is within
    :data:`faultgen.monitor.trends.AICC_MARGIN` of the least, as the rule before the average chose."""
    least = min(f.aicc for f in fits)
    near = [f for f in fits if f.aicc <= least + AICC_MARGIN] or fits
    return min(near, key=lambda f: (len(f.params) + (f.changepoint is not None),
                                  MODELS.index(f.model) if f.model in MODELS else len(MODELS)))


def _values(toe) -> np.ndarray:
    """ProgPy's times of event as numbers (``inf`` beyond the horizon, 0 for a crossing due now)."""
    values = np.array([np.inf if v is None else float(v) for v in toe.key("failure")])
    values[values < 1e-6] = 0.0  # crossed already: the first step's length
    return values


def _credible_low(row: Remaining, fits, weights, labels, seed: int, scale_uncertainty: float | None) -> Remaining:
    """``row``, on the source axis's average (the power law among ``fits``) with a service-by end
    (``rul_5``), that end lowered to the earliest credible model's own 5 % end
    (:func:`faultgen.monitor.rul_forecast.credible_low`), the verdict saying so where it is earlier."""
    if row.rul_5 is None or not any(f.model == "power" for f in fits):
        return row

    def own(i):
        return _values(time_of_event(fits[i], row.failure_wear, row.horizon, rul_forecast.CREDIBLE_SAMPLES,
                                     seed + 1 + i, scale_uncertainty))

    low, model, weight = rul_forecast.credible_low(_values(row.distribution), labels, fits, weights, own)
    if low < row.rul_5:
        row.verdict += (f"; service by its {row.rul_5:.3g} {row.time_unit} lowered to {low:.3g} {row.time_unit}, "
                        f"the 5 % end of the {model} trend of weight {weight:.2f} alone")
        row.rul_5 = low
    return row


def _quantiles(values: np.ndarray) -> np.ndarray:
    """The 5 %, median and 95 % of times of event (``inf`` beyond the horizon; module docstring, 6)."""
    return np.quantile(values, [INTERVAL[0], 0.5, INTERVAL[1]], method="inverted_cdf")


def unpredictable(fits, weights, labels, values: np.ndarray, low: float, mid: float, high: float,
                  logs_since_rise: int | None) -> str:
    """Why the trend cannot yet tell the remaining life (module docstring, 7), or "" when it can:
    fewer than :data:`MIN_RISE_LOGS` logs since the rise (``logs_since_rise``; None: no rise
    fitted), a 5-95 % interval (``low``, ``mid`` its median, ``high``) ending beyond the horizon, or two
    models of weight >= :data:`MIN_MODEL_WEIGHT` whose own 5-95 % intervals (of their draws
    ``values[labels == i]``) do not overlap."""
    if logs_since_rise is not None and logs_since_rise < MIN_RISE_LOGS:
        return f"{logs_since_rise} logs since the rise began, {MIN_RISE_LOGS} needed"
    if not np.isfinite(high):
        return "the 95 % end of its interval beyond the horizon"
    ranges = {i: _quantiles(values[labels == i]) for i, w in enumerate(weights)
              if w >= MIN_MODEL_WEIGHT and np.sum(labels == i) >= 20}
    for i in ranges:
        for j in ranges:
            if i < j and (ranges[i][2] < ranges[j][0] or ranges[j][2] < ranges[i][0]):
                return (f"the {fits[i].model} ({ranges[i][0]:.3g}-{ranges[i][2]:.3g}) and {fits[j].model} "
                        f"({ranges[j][0]:.3g}-{ranges[j][2]:.3g}) trends' 5-95 % intervals do not overlap")
    return ""


def _summarise(row: Remaining, fits, weights, labels, toe, horizon: float, times: np.ndarray) -> Remaining:
    """The row of a propagated model average (module docstring, 6-7); ``times`` the fitted logs' times."""
    import_progpy()
    from progpy.metrics import prob_success

    values = _values(toe)
    low, mid, high = _quantiles(values)
    row.distribution = toe
    row.p_within_horizon = 1.0 - float(prob_success(toe, horizon)["failure"])
    unit = row.time_unit
    h = f"{horizon:g} {unit}"
    if row.p_within_horizon < 0.5:
        row.verdict = f"no end of life within the horizon ({h}): probability {row.p_within_horizon:.2f} within it"
        return row
    # the rise's start: the changepoint trend's changepoint (the power law's start is ill-determined
    # when its exponent is large: a steep late rise reads as a slow early one), where the models that
    # date a rise carry at least half the weight
    dated = [f for f in fits if f.changepoint is not None]
    since_rise = None
    if dated and sum(w for f, w in zip(fits, weights) if f.changepoint is not None) >= 0.5:
        hinge = next((f for f in dated if f.model == "changepoint"), dated[0])
        since_rise = int(np.sum(times > hinge.changepoint))
    upper = f"{high:.3g} {unit}" if np.isfinite(high) else f"beyond the {h} horizon"
    now = " (at or past it now)" if row.wear >= row.failure_wear else ""
    models = f"models: {row.models}"
    why = unpredictable(fits, weights, labels, values, low, mid, high, since_rise)
    if why:
        row.predictable = False
        row.verdict = (f"not yet predictable: {why} (median {mid:.3g} {unit}, 5-95 %: {low:.3g} {unit} to {upper}; "
                       f"{row.logs_fitted} logs; {models})")
        if not np.isfinite(high) and not unpredictable(fits, weights, labels, values, low, mid, mid, since_rise):
            row.rul_5 = float(low)  # only the upper end unbounded: the service-by end holds (module docstring, 7)
            row.verdict += f"; service by its 5 % end, {low:.3g} {unit}"
        return row
    row.rul, row.rul_5 = float(mid), float(low)
    row.rul_95 = float(high)
    rising = "" if since_rise is None else f", rising for the last {since_rise} logs"
    row.verdict = (f"end of life (wear {row.failure_wear:g} %){now} in {mid:.3g} {unit}, 5-95 %: {low:.3g} {unit} "
                   f"to {upper} (model average of {row.logs_fitted} logs{rising}; {models})")
    return row


def check_failure_wear(failure_wear: float) -> None:
    if not 0 < failure_wear <= MAX_FAILURE_WEAR:
        raise ValueError(f"failure_wear = {failure_wear!r} %; expected a number in (0, {MAX_FAILURE_WEAR:g}] (the wear "
                         "estimate, % of the axis's own dry friction, counted as the end of an axis's life)")


def of_monitor(unit, failure_wear: float = FAILURE_WEAR, rows: list[dict] | None = None,
               **options) -> list[Remaining]:
    """:func:`remaining_life` of a unit's record (:class:`faultgen.monitor.history.UnitHistory`): its
    rows (or ``rows``, the same put on another scale), alpha and open alarm; a unit that scored no
    log at all (not monitored, every log skipped) is said so, not "still learning"."""
    stages = unit.stages
    if not unit.rows and not stages.baseline.training:
        return [Remaining(unit.unit, None, "", "", "no log scored: no wear estimate", failure_wear,
                          options.get("horizon", HORIZON))]
    return remaining_life(unit.unit, unit.rows if rows is None else rows, stages.n_axes, alpha=stages.settings.alpha,
                          failure_wear=failure_wear, since=stages.alarm.first_alarm, source_axis=stages.alarm.source_axis,
                          **options)


def rul_table(rows: list[Remaining]) -> Table:
    """``rul.csv``: one row per unit and axis (:data:`COLUMNS`; empty cells where there is no
    number: no fit, or beyond the horizon)."""
    return Table("rul.csv", COLUMNS, [[cells.figure(getattr(row, c)) for c in COLUMNS] for row in rows])
