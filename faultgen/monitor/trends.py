"""The degradation trends :mod:`faultgen.monitor.prognosis` fits to an axis's wear estimates (issues
59 and 75), each by weighted least squares with its parameters' covariance, written with the state now
(``t`` <= 0 the logs' times, 0 the last log; ``params[0]`` the wear now, %, ``params[1]`` its slope
now, % per day or log): a line, an exponential, the changepoint trend, flat and then a line
(:func:`fit_hinge`), and the power-law rise, flat and then a power of the time since the rise
(:func:`fit_power`); each with its AICc, from which :func:`akaike_weights` gives the model average's
weights (:func:`fit_models`). The remaining life propagates them with ProgPy
(:mod:`faultgen.monitor.prognosis`, whose module docstring gives the rules and what they rest on).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

#: Models, the simpler first; "changepoint" (the hinge: flat, then a line) and "power" (flat, then
#: a power >= 1 of the time since the rise) only for the open alarm's source axis
#: (faultgen.monitor.prognosis, module docstring, 2).
MODELS = ("linear", "exponential", "changepoint", "power")
#: The power law's exponent is looked for in [1, POWER_MAX] (1: the changepoint trend; 2: a wear
#: rate growing in proportion to the time since the rise; above 4 the rise is a step the logs would
#: show as such).
POWER_MAX = 4.0
#: The exponents of the power law's starting grid (refined by least squares).
POWER_GRID = (1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0)
#: The power law's rise may have begun before the first log fitted (while the unit learned, its wear
#: then read as its baseline): a second fit looks for its start also this many times the logs' span
#: before the last log, at most twice that span, and the fit of lower AICc is kept (a quadratic rise
#: from day 25 of a unit fitted from day 33 was held to a later start and a flatter power, and its
#: service-by date came a day after the failure: docs/analysis.md, "a rise begun before the first log
#: fitted").
BEFORE_FIRST = np.array([1.1, 1.25, 1.5, 2.0])
#: The hinge's changepoint is looked for between the logs this far from either end of the block
#: (the 3rd log and the 5th from the last: a flat stretch and a rise of at least a few logs each).
HINGE_MARGINS = (2, 4)
#: The learning rate of the model average's weights (:func:`model_weights`): each model's weight
#: ``exp(-WEIGHT_RATE dAICc / 2)`` normalised, the Akaike weights at 1. One half, as the generalised
#: ("safe") Bayesian updates take it for models that are all wrong (Grunwald & van Ommen 2017,
#: "Inconsistency of Bayesian inference for misspecified linear models, and a proposal for repairing
#: it", Bayesian Analysis 12(4); Bissiri, Holmes & Walker 2016): every trend here is wrong about
#: the estimate (its scale bends with the plant's friction law: on accelerating wear the estimate
#: rose less steeply than the true wear), and at 1 the power law and the exponential, which
#: extrapolate 5-10 days apart there, split the draws by AICc differences of a few units that are
#: the friction law's as much as the wear's. Applied to the source axis's average only
#: (:func:`model_weights`; docs/analysis.md, "Accelerating wear without running late").
WEIGHT_RATE = 0.5
#: How much smaller the exponential's AICc must be for it to be taken over the line (Burnham &
#: Anderson 2002, ch. 2.6: models within 2 of the best have substantial support; the simpler is kept).
AICC_MARGIN = 2.0


def expm1_over(k, t):
    """``(exp(k t) - 1) / k``, ``t`` where ``k t`` is too small for the quotient."""
    k, t = np.asarray(k, dtype=float), np.asarray(t, dtype=float)
    small = np.abs(k * t) < 1e-8
    return np.where(small, t * (1.0 + 0.5 * k * t), np.expm1(k * t) / np.where(small, 1.0, k))


def _linear(t, w0, b):
    return w0 + b * t


def _exponential(t, w0, b, k):
    return w0 + b * expm1_over(k, t)


@dataclass(frozen=True)
class Fit:
    """A fitted trend: ``model`` name, parameters ``params`` (w0, b[, k] for the line and the
    exponential, w_now, b for the changepoint trend, w_now, b, age, p for the power law: the wear
    now, %, and its slope now first), their covariance ``cov`` (scaled by the reduced chi-square when
    above one: :mod:`faultgen.monitor.prognosis`, 4), its ``aicc`` (:func:`information_criterion`,
    on the logs it was fitted on) and ``changepoint`` the time the rise began (the hinge's ``tc``,
    the power law's -age; None for the other models)."""

    model: str
    params: np.ndarray
    cov: np.ndarray
    aicc: float = float("nan")
    changepoint: float | None = None
    limits: tuple | None = None


#: Singular values of a fit's Jacobian at or below this share of its largest count as zero in the
#: fit's covariance (:func:`gauss_newton_cov`): scipy's ``least_squares`` differentiates by forward
#: differences, good to about the square root of the machine epsilon of the Jacobian's scale, so a
#: direction the logs fix no better than that is one they do not fix. The power law whose exponent
#: sits at 1 with its rise begun before the first log is such a fit: its start moves nothing, and
#: the plain inverse put 6.8e8 days of standard deviation on it, a negative eigenvalue from rounding
#: beside it, and an exponent drawn over -0.9 to 2.9 (docs/analysis.md, "a fit's covariance where
#: the logs do not fix a parameter").
JACOBIAN_RTOL = float(np.sqrt(np.finfo(float).eps))


def gauss_newton_cov(jacobian: np.ndarray) -> np.ndarray:
    """The Gauss-Newton covariance ``(J^T J)^+`` of a least-squares fit's parameters from its
    Jacobian ``J`` (n, k) of the residuals divided by their standard errors: ``J^+ (J^+)^T`` with
    ``J``'s pseudo-inverse through its singular value decomposition (``scipy.linalg.pinv``, the way
    ``scipy.optimize.curve_fit`` computes its ``pcov``), singular values at or below
    :data:`JACOBIAN_RTOL` of the largest taken as zero: a direction the data do not fix gets no
    variance instead of an unbounded one. Shape (k, k), symmetric positive semi-definite."""
    from scipy.linalg import pinv

    inverse = pinv(np.asarray(jacobian, dtype=float), atol=0.0, rtol=JACOBIAN_RTOL)
    return inverse @ inverse.T


def _widened(cov: np.ndarray, chi2: float, dof: int) -> np.ndarray:
    """``cov`` scaled by the reduced chi-square ``chi2 / dof`` when it is above one (the scatter
    about the trend larger than the stated errors; :mod:`faultgen.monitor.prognosis`, 4); as given
    without degrees of freedom."""
    return cov * max(1.0, chi2 / dof) if dof > 0 else cov


def _hinge_design(t: np.ndarray, tc) -> np.ndarray:
    """The hinge's design matrices at changepoints ``tc`` (shape (m,)): (m, n, 2), columns 1 and ``max(t, tc)``."""
    tc = np.atleast_1d(np.asarray(tc, dtype=float))
    x = np.maximum(t[None, :], tc[:, None])
    return np.stack([np.ones_like(x), x], axis=-1)


def _hinge_wls(t, wear, weight, tc):
    """Weighted least squares of the hinge's (w_now, b) at each changepoint ``tc``: parameters (m, 2)
    and chi-square (m,); NaN where the design is singular."""
    return _wls(_hinge_design(t, tc), wear, weight)


def fit_hinge(t: np.ndarray, wear: np.ndarray, error: np.ndarray) -> Fit | None:
    """The two-phase (changepoint) trend fitted to the wear estimates ``wear`` (%) at times ``t``
    (<= 0, the last 0) with standard errors ``error``: flat until ``tc``, then a line,
    ``w(t) = w_now + b max(t, tc)`` (:mod:`faultgen.monitor.prognosis`, 2): weighted least squares of
    (``w_now``, ``b``) at each candidate ``tc`` (the logs' times, :data:`HINGE_MARGINS` from either
    end), the least chi-square's ``tc`` refined between its neighbours (``scipy.optimize.minimize_scalar``);
    the covariance of (``w_now``, ``b``) the Gauss-Newton one of the three parameters there (as
    ``curve_fit`` with ``absolute_sigma`` gives it), marginalised, scaled by the reduced
    chi-square when above one. :class:`Fit` with ``params`` (w_now, b) and ``changepoint`` ``tc``;
    None when it cannot be fitted (fewer than ``sum(HINGE_MARGINS) + 1`` logs, a singular design or a
    covariance that is not finite)."""
    from scipy.optimize import minimize_scalar

    t, wear, error = (np.asarray(v, dtype=float) for v in (t, wear, error))
    n = len(t)
    first, last = HINGE_MARGINS[0], n - 1 - HINGE_MARGINS[1]
    if last < first:
        return None
    weight = 1.0 / error**2
    grid = t[first: last + 1]
    chi2 = _hinge_wls(t, wear, weight, grid)[1]
    if not np.any(np.isfinite(chi2)):
        return None
    best = int(np.nanargmin(chi2))
    # the profile's minimum between the grid's neighbours of its best log (chi2 is smooth between logs)
    low, high = grid[max(best - 1, 0)], grid[min(best + 1, len(grid) - 1)]
    tc = float(grid[best])
    if high > low:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            found = minimize_scalar(lambda c: float(_hinge_wls(t, wear, weight, c)[1][0]), bounds=(low, high),
                                    method="bounded", options={"xatol": 1e-6 * max(high - low, 1e-9)})
        if np.isfinite(found.fun) and found.fun < chi2[best]:
            tc = float(found.x)
    params, chi2_tc = _hinge_wls(t, wear, weight, tc)
    (w_now, b), chi2_tc = params[0], float(chi2_tc[0])
    if not np.all(np.isfinite(params)):
        return None
    # covariance of (w_now, b, tc): the Gauss-Newton one at the optimum, the model's derivative in tc
    # being b before tc and 0 after it
    jacobian = np.column_stack([np.ones(n), np.maximum(t, tc), np.where(t < tc, b, 0.0)])
    try:
        cov = gauss_newton_cov(jacobian * np.sqrt(weight)[:, None])
    except (ValueError, np.linalg.LinAlgError):
        return None
    cov = _widened(cov, chi2_tc, n - 3)
    if not (np.all(np.isfinite(cov)) and np.all(np.diag(cov) >= 0)):
        return None
    residual = wear - (w_now + b * np.maximum(t, tc))
    return Fit("changepoint", np.array([w_now, b]), cov[:2, :2], information_criterion(residual, error, 3),
               changepoint=tc)


def information_criterion(residual: np.ndarray, error: np.ndarray, n_params: int) -> float:
    """AICc (``statsmodels.tools.eval_measures.aicc``; Burnham & Anderson 2002) of a trend with
    ``n_params`` parameters whose ``residual`` (%, shape (n,)) have the stated standard errors
    ``error`` (%): the Gaussian likelihood with the variances' common scale at its maximum (one
    parameter more); infinite where the sample is too small for the correction."""
    from scipy import stats
    from statsmodels.tools.eval_measures import aicc

    n = len(residual)
    if n - n_params - 2 <= 0:
        return float("inf")
    chi2 = float(np.sum((residual / error) ** 2))
    scale = np.sqrt(chi2 / n) if chi2 > 0 else 1e-12
    llf = float(np.sum(stats.norm.logpdf(residual, scale=error * scale)))
    return float(aicc(llf, n, n_params + 1))


def power_curve(t, w_now, b, age, p):
    """The power-law rise at times ``t`` (<= 0): ``w_now + b ((age + t)_+^p - age^p) / (p age^(p-1))``,
    flat until ``-age`` and then ``c (t + age)^p`` above that level, ``c = b / (p age^(p-1))``: the wear
    ``w_now`` and slope ``b`` now, ``age`` (> 0) the time since the rise began, ``p`` >= 1 (1: the
    changepoint trend)."""
    t = np.asarray(t, dtype=float)
    return w_now + b * (np.maximum(age + t, 0.0) ** p - age**p) / (p * age ** (p - 1.0))


def fit_power(t: np.ndarray, wear: np.ndarray, error: np.ndarray) -> Fit | None:
    """The power-law rise (:func:`power_curve`; ``w = a + c (t - t0)_+^p``, ``p`` in [1,
    :data:`POWER_MAX`]) fitted to ``wear`` (%) at times ``t`` (<= 0, the last 0) with standard errors
    ``error``, its start ``t0`` = -age among the logs the changepoint trend looks at
    (:data:`HINGE_MARGINS`) and, a second fit, also before the first log (:data:`BEFORE_FIRST`): the
    one of lower AICc (the first on a tie; either where the other cannot be fitted). Each: weighted
    least squares of (``w_now``, ``b``) on a grid of the ages and :data:`POWER_GRID`, the best refined
    over all four parameters within those bounds (``scipy.optimize.least_squares``), the covariance
    the Gauss-Newton one there, scaled by the reduced chi-square when above one. :class:`Fit`
    ``power`` with ``params`` (w_now, b, age, p) and ``changepoint`` -age; None when neither fits."""
    t, wear, error = (np.asarray(v, dtype=float) for v in (t, wear, error))
    n = len(t)
    first, last = HINGE_MARGINS[0], n - 1 - HINGE_MARGINS[1]
    if last < first or n < 7:
        return None
    ages = -t[first: last + 1]
    ages = ages[ages > 0]
    if not ages.size:
        return None
    within = _power_over(t, wear, error, ages)
    before = _power_over(t, wear, error, np.r_[ages, -t[0] * BEFORE_FIRST])
    if before is None or (within is not None and not before.aicc < within.aicc):
        return within
    return before


def _power_over(t: np.ndarray, wear: np.ndarray, error: np.ndarray, ages: np.ndarray) -> Fit | None:
    """:func:`fit_power` with the rise's start looked for at ``ages`` (> 0) and refined between them."""
    from scipy.optimize import least_squares

    weight = 1.0 / error**2
    grid = [(a, p) for a in ages for p in POWER_GRID]
    basis = np.stack([(np.maximum(a + t, 0.0) ** p - a**p) / (p * a ** (p - 1.0)) for a, p in grid])
    x = np.stack([np.ones_like(basis), basis], axis=-1)
    params, chi2 = _wls(x, wear, weight)
    if not np.any(np.isfinite(chi2)):
        return None
    best = int(np.nanargmin(chi2))
    start = np.array([*params[best], *grid[best]])
    low = np.array([-np.inf, -np.inf, float(ages.min()), 1.0])
    high = np.array([np.inf, np.inf, float(ages.max()), POWER_MAX])
    if not high[2] > low[2]:
        high[2] = low[2] * (1 + 1e-9) + 1e-12
    start = np.clip(start, low, high)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            found = least_squares(lambda q: (power_curve(t, *q) - wear) / error, start, bounds=(low, high),
                                  x_scale="jac", method="trf")
        cov = gauss_newton_cov(found.jac)
    except (ValueError, np.linalg.LinAlgError):
        return None
    cov = _widened(cov, float(np.sum(found.fun**2)), len(t) - 4)
    if not (np.all(np.isfinite(found.x)) and np.all(np.isfinite(cov)) and np.all(np.diag(cov) >= 0)):
        return None
    residual = wear - power_curve(t, *found.x)
    return Fit("power", found.x, cov, information_criterion(residual, error, 4), changepoint=-float(found.x[2]),
               limits=(low[2:], high[2:]))


def _wls(x: np.ndarray, wear: np.ndarray, weight: np.ndarray):
    """Weighted least squares of ``wear`` (n,) on each design ``x`` (m, n, 2): parameters (m, 2) and
    chi-square (m,); NaN where the design is singular."""
    a = np.einsum("mni,n,mnj->mij", x, weight, x)
    rhs = np.einsum("mni,n,n->mi", x, weight, wear)
    det = np.linalg.det(a)
    ok = det > 1e-12 * np.maximum(a[:, 0, 0] * a[:, 1, 1], 1e-300)
    params = np.full(rhs.shape, np.nan)
    params[ok] = np.linalg.solve(a[ok], rhs[ok][..., None])[..., 0]
    residual = wear[None, :] - np.einsum("mni,mi->mn", x, params)
    return params, np.einsum("mn,n->m", residual**2, weight)


def akaike_weights(fits: list[Fit], rate: float = 1.0) -> np.ndarray:
    """The Akaike weights of ``fits`` (Burnham & Anderson 2002, ch. 2.9): ``exp(-rate dAICc / 2)``
    normalised (``scipy.special.softmax``; ``rate`` 1 the Akaike weights, below 1 a tempered
    likelihood, :data:`WEIGHT_RATE`), a fit of infinite AICc weight 0; all equal when none is
    finite. Shape (len(fits),). ValueError for a ``rate`` not in (0, 1]."""
    from scipy.special import softmax

    if not 0.0 < rate <= 1.0:
        raise ValueError(f"rate = {rate!r}: expected the weights' learning rate in (0, 1] (1: the Akaike weights)")
    aicc = np.array([f.aicc for f in fits], dtype=float)
    finite = np.isfinite(aicc)
    if not finite.any():
        return np.full(len(fits), 1.0 / len(fits))
    weights = np.zeros(len(fits))
    weights[finite] = softmax(-0.5 * rate * (aicc[finite] - aicc[finite].min()))
    return weights


def model_weights(fits: list[Fit], rate: float = WEIGHT_RATE) -> np.ndarray:
    """The model average's weights of ``fits`` (:mod:`faultgen.monitor.prognosis`, 3). Where the
    power-law rise is among them (an open alarm's source axis), the models it nests get none (the
    changepoint trend is its ``p`` = 1; the line over the block nearly a rise from its start, ``p`` =
    1 at the largest age), so the average is the exponential's and the power law's, whose exponent
    carries the line's and the hinge's shapes with its uncertainty instead of an Occam bonus for a
    rise that cannot accelerate, and their weights are :func:`akaike_weights` at ``rate``
    (:data:`WEIGHT_RATE`); the nested models are still fitted: the hinge dates the rise, and
    ``model`` names the simplest within 2 of the least AICc
    (:func:`faultgen.monitor.prognosis.named_model`). Otherwise (the line and the exponential of
    every other axis) the Akaike weights, as before. Shape (len(fits),)."""
    if not any(f.model == "power" for f in fits):
        return akaike_weights(fits)
    kept = [i for i, f in enumerate(fits) if f.model not in ("linear", "changepoint")]
    out = np.zeros(len(fits))
    out[kept] = akaike_weights([fits[i] for i in kept], rate)
    return out


def fit_models(t: np.ndarray, wear: np.ndarray, error: np.ndarray, changepoint: bool = False) -> list[Fit]:
    """Every model that fits (:data:`MODELS`; the changepoint trend and the power-law rise only with
    ``changepoint``): the line, the exponential, and with ``changepoint`` the hinge and the power
    law, each with its AICc on the same logs (the model average's weights, :func:`akaike_weights`).
    A hinge or power law whose slope now is not positive is left out (a trend that has stopped
    rising is the line's or the exponential's), and so is an exponential whose time constant ``1/k``
    is shorter than the logs' median spacing (a step at the last log: its ``b`` and ``k`` trade off,
    their variance unbounded, and its AICc took the average from the line)."""
    fits = list(_fit_line_and_exponential(t, wear, error))
    if changepoint:
        for fit in (fit_hinge(t, wear, error), fit_power(t, wear, error)):
            if fit is not None and fit.params[1] > 0:
                fits.append(fit)
    return fits


def _fit_line_and_exponential(t, wear, error):
    """The line and the exponential fitted to ``wear`` (:func:`fit_trend`), each with its AICc."""
    from scipy.optimize import curve_fit

    t, wear, error = (np.asarray(v, dtype=float) for v in (t, wear, error))
    linear = None
    for name, f in (("linear", _linear), ("exponential", _exponential)):
        n_params = 2 if name == "linear" else 3
        if len(t) < n_params + 1:
            continue
        if name == "linear":
            p0 = [wear[-1], 0.0]
        else:
            if linear is None:
                continue
            span = max(float(-t[0]), 1e-9)
            p0 = [linear.params[0], linear.params[1], 0.1 / span]
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                bounds = ([-np.inf, -np.inf], [np.inf, np.inf]) if name == "linear" else \
                    ([-np.inf, -np.inf, 0.0], [np.inf, np.inf, np.inf])  # an accelerating exponential
                params, cov = curve_fit(f, t, wear, p0=p0, sigma=error, absolute_sigma=True, bounds=bounds,
                                        **({"maxfev": 5000} if name == "linear" else {"max_nfev": 5000}))
        except (RuntimeError, ValueError, np.linalg.LinAlgError):
            continue
        residual = wear - f(t, *params)
        chi2 = float(np.sum((residual / error) ** 2))
        cov = _widened(cov, chi2, len(t) - n_params)
        if not (np.all(np.isfinite(params)) and np.all(np.isfinite(cov))):
            continue
        if name == "exponential" and params[2] * float(np.median(np.diff(t))) > 1.0:
            continue  # a time constant shorter than the logs' spacing: a step at the last log, b and k unidentified
        found = Fit(name, params, cov, information_criterion(residual, error, n_params))
        if name == "linear":
            linear = found
        yield found


def fit_trend(t: np.ndarray, wear: np.ndarray, error: np.ndarray) -> Fit | None:
    """Both models fitted to the wear estimates ``wear`` (%) at times ``t`` (<= 0, the last 0) with
    standard errors ``error``; the one of smaller AICc by :data:`AICC_MARGIN` (a choice of one model,
    not the model average), None when neither fits."""
    fits = list(_fit_line_and_exponential(t, wear, error))
    if not fits:
        return None
    if len(fits) == 2 and fits[1].aicc < fits[0].aicc - AICC_MARGIN:
        return fits[1]
    return fits[0]
