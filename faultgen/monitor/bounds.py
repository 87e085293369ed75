"""The doubts a log's wear carries, put together (issue 90, "Daily scatter, honest bounds"): the
arithmetic of the wear's 90 % interval and of the lower bound an alarm is judged on
(:class:`faultgen.monitor.wear.WearEstimator`), the plant's day-to-day scatter an axis shows, and
the filter's adapted process noise (:class:`faultgen.monitor.wear_trend.WearTrend`).

**The sources** (each a standard deviation in points of wear, % of the axis's own dry friction):

- the **noise** of the wear read: the filtered wear's own error (the filter's: the logs' scatter
  averaged over the logs, widened where the filter's process noise was adapted to a fast wear,
  :func:`adapted_rate_variance`), or the log's own where the errors that stay for weeks count
  (the twin's scale: a month's learned slopes extrapolated over a season, the calibration);
- the **scale**: the wear read is the robot's wear times a factor the logs cannot tell, ``f``, known
  to a relative standard error ``s``: before a friction test that tells it (an informative test,
  one that sees the wear) the prior's (:data:`faultgen.monitor.friction_tests.SCALE_PRIOR` with
  tests, :data:`faultgen.monitor.scoring.SCALE_UNCERTAINTY` without), after it the fitted factor's
  (:class:`faultgen.monitor.friction_tests.Rescale`). It is a share of the wear: ``s x`` points at a
  read of ``x`` (:func:`standard_error`);
- the **plant's day-to-day scatter**: a day's friction scatters about its level (the lubricant film,
  the warm-up), which moves a log's read and a test's alike; it is in the noise the unit learns on
  its healthy learning days (each log's read scatters by it), stated per axis by
  :func:`day_scatter` (logs) and by the tests' scatter about the unit's temperature law
  (``scatter_percent`` in ``tests.csv``).

**The interval** is the read -+ ``z`` times the root of the sum of their squares (independent
sources; :func:`interval`), ``z`` the 90 % two-sided normal quantile; **the lower bound** an alarm is
judged on is the read less the one-sided quantile times the same root with the filter's noise
(:func:`lower_bound`): the scale's doubt included, so a read 1.5 times the truth before the first
informative test does not give a bound above the truth (issue 90: "wear estimate 12.2 %, its lower 90 %
bound 11.8 %" at 8.0 % true wear, the bound without the scale).
"""

from __future__ import annotations

import math

import numpy as np

#: The smallest level ``1 + b/100`` of a reference test over its axis's true level taken
#: (:func:`reference_factor`; a reference read 10 times too high, no test reads).
LEVEL_MIN = 0.1
#: Logs over which the filter's innovations are averaged to adapt its rate's process noise
#: (:func:`adapted_rate_variance`).
ADAPT_WINDOW = 3
#: The mean normalised squared innovation over :data:`ADAPT_WINDOW` logs past which the trend is
#: adapted (:func:`fading_factor`, and the rate's process noise by :func:`adapted_rate_variance`):
#: the chi-square's 99 % quantile with 3 degrees of freedom over 3 (11.345 / 3), so a trend that
#: describes its logs is adapted on 1 log in 100. On synthetic ramps (/tmp script of 2026-11-27, in
#: tests/test_monitor_bounds.py): a wear of 0.5-1 point a log read to 3-4 points, RMS error 1.50
#: against the fixed trend's 1.47 (at the 95 % quantile 1.59); 3 points a log read to 1.5 points,
#: the 90 % interval covering 88 % of the logs at 10-40 % (fixed: 19 %), the mean lag 0.2 point
#: (fixed: 3.0); read to 3.5 points, 70 % and 2.1 (fixed: 1 % and 6.5).
FADING_THRESHOLD = 11.345 / 3
#: The confidence of the upper limit by which a fit whose residuals scatter less than their stated
#: errors narrows them (:func:`upper_ratio`): the 90 % the monitor states its intervals and bound at.
RATIO_LEVEL = 0.90


def standard_error(noise: np.ndarray, estimate: np.ndarray, scale: np.ndarray | float) -> np.ndarray:
    """The wear read's standard error, points (n_axes,): ``sqrt(noise^2 + (scale estimate)^2)``,
    ``noise`` points, ``estimate`` % and ``scale`` the scale's relative standard error (a number or
    (n_axes,)). NaN where any input is."""
    noise, estimate = np.asarray(noise, dtype=float), np.asarray(estimate, dtype=float)
    return np.sqrt(noise**2 + (np.asarray(scale, dtype=float) * estimate) ** 2)


def interval(estimate: np.ndarray, error: np.ndarray, z: float) -> tuple[np.ndarray, np.ndarray]:
    """``(estimate - z error, estimate + z error)``, % (module docstring)."""
    estimate, error = np.asarray(estimate, dtype=float), np.asarray(error, dtype=float)
    return estimate - z * error, estimate + z * error


def lower_bound(estimate: np.ndarray, noise: np.ndarray, scale: np.ndarray | float, z: float) -> np.ndarray:
    """The lower one-sided bound an alarm is judged on: ``estimate - z`` :func:`standard_error`
    (``noise`` the filtered wear's own error, ``scale`` the scale's relative standard error), %."""
    return np.asarray(estimate, dtype=float) - z * standard_error(noise, estimate, scale)


def day_scatter(reads: np.ndarray) -> np.ndarray:
    """Each axis's day-to-day scatter of its wear read on the unit's healthy learning days, points
    (n_axes,): the sample standard deviation of ``reads`` (m logs, n_axes), the logs' wear reads
    about the learned offset and slopes (their mean and conditions' part taken out: ddof 1). It is
    the plant's scatter of dry friction from one day to the next (a 1.5 % scatter reads about 1.5
    points at no wear) with the read's own noise in it (on a plant without scatter it is that noise
    alone). NaN with fewer than 2 logs."""
    reads = np.asarray(reads, dtype=float)
    if reads.ndim != 2 or len(reads) < 2:
        return np.full(reads.shape[-1] if reads.ndim == 2 else 0, np.nan)
    return np.std(reads, axis=0, ddof=1)


def upper_ratio(residual: np.ndarray, variance: np.ndarray, dof: float, level: float = RATIO_LEVEL) -> float:
    """The factor (<= 1) by which a fit's stated ``variance`` (n,) is narrowed where its ``residual`` (n,)
    scatters less than it states: the upper ``level`` confidence limit of their ratio, ``dof chi2 / q``
    (``chi2`` the reduced chi-square ``sum(residual^2 / variance) / dof``, ``q`` the chi-square's ``1 -
    level`` quantile on ``dof`` degrees of freedom, ``scipy.stats.chi2.ppf``: the confidence limit of a
    normal sample's variance, e.g. Montgomery & Runger 2014, ch. 8.3), where it is below one, else 1 (and
    where ``dof`` < 1 or any value is not finite; ``dof`` may be fractional: a fit with priors). The
    variances are narrowed only as far as the residuals show at that confidence: with 1 degree of freedom
    only where ``chi2`` is below 0.016; a residual that also carries what ``variance`` leaves out (a drift)
    only makes the limit larger."""
    from scipy import stats

    residual, variance = np.asarray(residual, dtype=float), np.asarray(variance, dtype=float)
    chi2 = float(np.sum(residual**2 / np.maximum(variance, 1e-12)) / dof) if dof >= 1 else math.nan
    if not np.isfinite(chi2):
        return 1.0
    return float(min(1.0, dof * chi2 / stats.chi2.ppf(1.0 - level, dof)))


def adapted_rate_variance(floor: float, gains: np.ndarray, innovations: np.ndarray) -> np.ndarray:
    """The rate's process variance for the next log, per axis (n_axes,), by covariance matching
    (Mohamed & Schwarz 1999, "Adaptive Kalman filtering for INS/GPS", J. Geodesy 73, eq. 28:
    ``Q = K C K'``, ``C`` the innovations' covariance over a window): the rate's gain squared times
    the mean squared innovation of the last logs, at least ``floor`` (the filter's fixed variance,
    :data:`faultgen.monitor.wear_trend.WEAR_RATE_CHANGE` squared). ``gains`` (n_axes,): the rate's
    gain at the last log (whether or not it was gated out); ``innovations`` (w, n_axes): the last
    ``w`` innovations, points (NaN: left out, as a log gated out). Where the wear grows faster than the trend predicts, the innovations
    keep one sign and grow, the rate's process noise with them, and the trend follows the wear
    within a few logs; where the trend describes the logs the variance stays at its floor."""
    innovations = np.asarray(innovations, dtype=float).reshape(-1, np.size(gains))
    seen = np.isfinite(innovations)
    count = seen.sum(axis=0)
    mean = np.where(seen, innovations, 0.0) ** 2
    mean = mean.sum(axis=0) / np.maximum(count, 1)
    matched = np.where(count > 0, np.asarray(gains, dtype=float) ** 2 * mean, floor)
    return np.maximum(floor, np.nan_to_num(matched, nan=floor))


def fading_factor(normalised: np.ndarray) -> np.ndarray:
    """The factor (n_axes,) >= 1 by which the wear's and its rate's predicted covariance is
    multiplied at the next log (a fading-memory filter, Sorenson & Sacks 1971; the factor from the
    innovations, Xia et al. 1994, "Adaptive fading Kalman filter with an application", Automatica
    30): the mean of the last logs' normalised squared innovations (``normalised`` (w, n_axes): each
    innovation squared over its stated variance; NaN left out) where it passes
    :data:`FADING_THRESHOLD`, else 1. A lagging trend's innovations are several of their stated
    standard deviations; fading its covariance lets the next logs move it, and its stated error
    carries the lag."""
    normalised = np.asarray(normalised, dtype=float)
    seen = np.isfinite(normalised)
    count = seen.sum(axis=0)
    mean = np.where(seen, normalised, 0.0).sum(axis=0) / np.maximum(count, 1)
    return np.where((count > 0) & (mean > FADING_THRESHOLD), mean, 1.0)


def test_read(scale: tuple, twin: tuple, test: tuple, same_log: bool) -> tuple[np.ndarray, np.ndarray]:
    """An axis's wear on the tests' scale with its last friction test read into it at once (issue
    90: "a test read at once"), % and its standard error, points: the best linear unbiased
    combination of two correlated reads of the wear now (Aitken 1935; e.g. Bar-Shalom et al. 2001,
    ch. 1.4), the logs' ``A = f x`` and the test's carried to now by the logs' growth since it,
    ``B = y + f (x - x_t)``.

    ``scale`` ``(f, s_f)``: the factor onto the tests' scale and its standard error as known before
    the test; ``twin`` ``(x, e)``: the filtered twin-scale wear now and its error; ``test``
    ``(y, s_y, x_t, e_t)``: the test's wear and its error (the reference test's included), the
    filtered twin-scale wear it was paired with and that one's error; ``same_log``: ``x`` is that
    same filtered wear (the test's own log: the filter's error is common to ``A`` and ``B`` and
    cancels from ``B``), else the filter's errors now and then are taken as independent (``B``
    carries both). The factor's error is common to both (``s_f x`` and ``s_f (x - x_t)``): their
    covariance ``s_f^2 x (x - x_t) + f^2 (e^2 - c)``, ``c`` the filter's errors' covariance
    (``e_t^2`` on the same log, else 0). Where the twin's scale is barely known (``s_f`` 0.3 before an
    informative test) and the test sees the wear, the result is the test's read, to its own error,
    not the logs' read to 30 %: a fast wear is caught at the test. All (n_axes,) arrays or numbers;
    NaN in the test: ``A`` and its error alone."""
    f, sf = (np.asarray(v, dtype=float) for v in scale)
    x, e = (np.asarray(v, dtype=float) for v in twin)
    y, sy, xt, et = (np.asarray(v, dtype=float) for v in test)
    c = et**2 if same_log else 0.0
    va = (sf * x) ** 2 + (f * e) ** 2
    vb = sy**2 + (sf * (x - xt)) ** 2 + f**2 * (e**2 + et**2 - 2 * c)
    cov = sf**2 * x * (x - xt) + f**2 * (e**2 - c)
    d = va + vb - 2 * cov  # the variance of A - B: (sf xt)^2 + f^2 (et^2 ...) + sy^2
    with np.errstate(divide="ignore", invalid="ignore"):
        w = (vb - cov) / d
        fused, variance = w * f * x + (1 - w) * (y + f * (x - xt)), (va * vb - cov**2) / d
    ok = np.isfinite(fused) & np.isfinite(variance) & (d > 0)
    return np.where(ok, fused, f * x), np.sqrt(np.where(ok, np.maximum(variance, 0.0), va))


def reference_level(offset: float) -> float:
    """``1 + b/100``: the reference test's dry level over the axis's own, at least :data:`LEVEL_MIN`,
    from the offset ``b`` (points) its later tests all share (:func:`reference_factor`)."""
    return max(1.0 + float(offset) / 100.0, LEVEL_MIN)


def reference_factor(params, cov, least: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """``((f, s_f), (b, s_b))`` from the tests' line ``y = b + F x`` (``params`` ``(b, F)``, ``cov``
    their 2 x 2 covariance): the reference test's error is a factor on every later test's dry level,
    ``1 + y/100 = (1 + b/100) (1 + f x/100)``, so the line's slope is ``F = f (1 + b/100)`` and the
    wear's factor ``f = F / (1 + b/100)`` (at least ``least``), its error by the delta method. Taken as
    the factor, ``F`` carried the reference's error into every wear (issue 90, seed 1's unit06: a
    reference 2.5 scatters low read its wear 4-8 % high)."""
    b, slope = (float(v) for v in params)
    level = reference_level(b)
    gradient = np.array([-slope / (100.0 * level**2), 1.0 / level])
    variance = float(gradient @ np.asarray(cov, dtype=float) @ gradient)
    return (max(slope / level, least), math.sqrt(variance)), (b, math.sqrt(float(np.asarray(cov)[0, 0])))


def less_reference(wear: float, error: float, offset: float, offset_error: float) -> tuple[float, float]:
    """A test's wear ``wear`` -+ ``error`` % less the reference's ``offset`` -+ ``offset_error`` points
    (:func:`reference_factor`): ``(y - b) / (1 + b/100)`` and its standard error (the two independent)."""
    level = reference_level(offset)
    spread = float(np.hypot(error, offset_error * (1.0 + wear / 100.0) / level))
    return (wear - offset) / level, spread / level
