"""Two guards of the remaining life's model average (:mod:`faultgen.monitor.prognosis`) so that the
dates a planner reads do not run late (issue 90: "a late prediction is worse than an early one"):

1. **The exponential rise after a flat stretch** (:func:`fit_onset_exponential`): on an open
   alarm's source axis a fifth model joins the average, flat until the rise began and exponential
   after it, weighed by its AICc as the others. Over the whole block an exponential cannot be flat
   before the rise: on precise logs the AICc counts that misfit of the flat stretch against it, the
   power-law rise (its exponent
   bounded by :data:`faultgen.monitor.trends.POWER_MAX`) took every weight and, bending too slowly,
   ran late on an exponential wear (the clean fleet's unit04: median 13 days for a true 10, its 5 %
   end 12). Measured on the independent fleets: docs/analysis.md, "Issue 90: service-by dates that
   are not late".
2. **The credible end** (:func:`credible_low`): the service-by end of the interval (``rul_5``) is no
   later than the 5 % end of any model of weight >= :data:`CREDIBLE_WEIGHT` taken alone, each from
   at least :data:`CREDIBLE_SAMPLES` of its own draws: the weights are not calibrated probabilities
   (every trend is wrong about the estimate), so the early end of a model the logs still admit is
   not averaged away by a later one.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable

import numpy as np

from faultgen.monitor.trends import Fit, expm1_over, gauss_newton_cov, information_criterion

#: The name of the exponential rise after a flat stretch (:func:`fit_onset_exponential`).
ONSET = "onset exponential"
#: The service-by end is no later than the 5 % end of any model of at least this weight ...
CREDIBLE_WEIGHT = 0.01
#: ... each model's own end from at least this many of its draws.
CREDIBLE_SAMPLES = 200


def onset_curve(t, w_now, b, k, age):
    """Flat until ``-age``, then an exponential rise: ``w_now + b (exp(k max(t, -age)) - 1) / k`` at
    times ``t`` (<= 0, the last log 0): the wear ``w_now`` and its slope ``b`` now, the rate ``k``
    (>= 0), ``age`` the time since the rise began."""
    return w_now + b * expm1_over(k, np.maximum(np.asarray(t, dtype=float), -age))


def fit_onset_exponential(t: np.ndarray, wear: np.ndarray, error: np.ndarray, ages: np.ndarray) -> Fit | None:
    """The exponential rise after a flat stretch (:func:`onset_curve`) fitted to ``wear`` (%) at times
    ``t`` (<= 0) with standard errors ``error`` by least squares (``scipy.optimize.least_squares``)
    from each start age of ``ages`` (the power law's and the hinge's), the best kept: :class:`Fit`
    :data:`ONSET` with ``params`` (w_now, b, k) and their covariance (the Gauss-Newton one of all
    four, scaled by the reduced chi-square when above one), its AICc over every log with 4
    parameters, ``changepoint`` -age. The exponential over the whole block cannot be flat before
    the rise, and the AICc then counts that misfit of the flat stretch against it (module docstring,
    1). None when it cannot be fitted."""
    from scipy.optimize import least_squares

    t, wear, error = (np.asarray(v, dtype=float) for v in (t, wear, error))
    best = None
    for age in ages:
        start = np.array([wear[-1], max((wear[-1] - wear[-3]) / max(t[-1] - t[-3], 1e-9), 1e-3), 0.02, age])
        low, high = np.array([-np.inf, -np.inf, 0.0, 1e-6]), np.array([np.inf, np.inf, 5.0, -t[0]])
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                found = least_squares(lambda q: (onset_curve(t, *q) - wear) / error, np.clip(start, low, high),
                                      bounds=(low, high), x_scale="jac", method="trf")
        except ValueError:
            continue
        if best is None or found.cost < best.cost:
            best = found
    if best is None:
        return None
    try:
        cov = gauss_newton_cov(best.jac) * max(1.0, 2.0 * best.cost / max(len(t) - 4, 1))
    except (ValueError, np.linalg.LinAlgError):
        return None
    if not (np.all(np.isfinite(best.x)) and np.all(np.isfinite(cov)) and np.all(np.diag(cov) >= 0)):
        return None
    residual = wear - onset_curve(t, *best.x)
    return Fit(ONSET, best.x[:3], cov[:3, :3], information_criterion(residual, error, 4),
               changepoint=-float(best.x[3]))


def credible_low(values: np.ndarray, labels: np.ndarray, fits: list[Fit], weights,
                 own: Callable[[int], np.ndarray]) -> tuple[float, str, float]:
    """The earliest 5 % end (``numpy.quantile``, ``inverted_cdf``) of a model of weight >=
    :data:`CREDIBLE_WEIGHT` (module docstring, 2), its model and weight: each model's draws
    ``values[labels == i]`` of the average, or ``own(i)`` (at least :data:`CREDIBLE_SAMPLES` times of
    event of model ``i`` alone) where the average gave it fewer; ``(inf, "", 0)`` when none."""
    ends = []
    for i, (fit, weight) in enumerate(zip(fits, weights)):
        if weight < CREDIBLE_WEIGHT:
            continue
        mine = values[labels == i]
        if mine.size < CREDIBLE_SAMPLES:
            mine = own(i)
        ends.append((float(np.quantile(mine, 0.05, method="inverted_cdf")), fit.model, float(weight)))
    return min(ends, default=(np.inf, "", 0.0))


def with_onset(fits: list[Fit], t: np.ndarray, wear: np.ndarray, error: np.ndarray) -> list[Fit]:
    """``fits`` (:func:`faultgen.monitor.trends.fit_models` with ``changepoint``) and, after them,
    :func:`fit_onset_exponential` (its start ages the fits' changepoints; module docstring, 1), which
    the model average weighs by its AICc as the others; unchanged without a dated rise, an
    exponential, or where it cannot be fitted."""
    ages = np.array([-f.changepoint for f in fits if f.changepoint is not None and f.changepoint < 0])
    names = [f.model for f in fits]
    if not ages.size or "exponential" not in names:
        return fits
    onset = fit_onset_exponential(t, wear, error, ages)
    if onset is None:
        return fits
    return [*fits, onset]
