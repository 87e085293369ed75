"""The degradation trends :mod:`faultgen.monitor.prognosis` fits to an axis's wear estimates (issue
59), each by weighted least squares with its parameters' covariance, written with the state now
(``t`` <= 0 the logs' times, 0 the last log): a line, an exponential (:func:`fit_trend`, chosen by
AICc) and the changepoint trend, flat and then a line (:func:`fit_hinge`). The remaining life
propagates them with ProgPy (:mod:`faultgen.monitor.prognosis`, whose module docstring gives the
rules and what they rest on).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

#: Models, the simpler first; "changepoint" (the hinge: flat, then a line) only for the open
#: alarm's source axis (faultgen.monitor.prognosis, module docstring, 2).
MODELS = ("linear", "exponential", "changepoint")
#: The hinge's changepoint is looked for between the logs this far from either end of the block
#: (the 3rd log and the 5th from the last: a flat stretch and a rise of at least a few logs each).
HINGE_MARGINS = (2, 4)
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
    """A fitted trend: ``model`` name, parameters ``params`` (w0, b[, k]), their covariance
    ``cov`` (scaled by the reduced chi-square when above one: :mod:`faultgen.monitor.prognosis`, 4),
    its ``aicc`` (the line's and the exponential's, which :func:`fit_trend` compares by it; NaN for
    the changepoint trend, compared with nothing) and ``changepoint`` the hinge's ``tc`` (None for
    the other models)."""

    model: str
    params: np.ndarray
    cov: np.ndarray
    aicc: float = float("nan")
    changepoint: float | None = None


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
    x = _hinge_design(t, tc)
    a = np.einsum("mni,n,mnj->mij", x, weight, x)
    rhs = np.einsum("mni,n,n->mi", x, weight, wear)
    det = np.linalg.det(a)
    ok = det > 1e-12 * np.maximum(a[:, 0, 0] * a[:, 1, 1], 1e-300)
    params = np.full(rhs.shape, np.nan)
    params[ok] = np.linalg.solve(a[ok], rhs[ok][..., None])[..., 0]
    residual = wear[None, :] - np.einsum("mni,mi->mn", x, params)
    return params, np.einsum("mn,n->m", residual**2, weight)


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
        cov = np.linalg.inv(jacobian.T @ (jacobian * weight[:, None]))
    except np.linalg.LinAlgError:
        return None
    cov = _widened(cov, chi2_tc, n - 3)
    if not (np.all(np.isfinite(cov)) and np.all(np.diag(cov) >= 0)):
        return None
    return Fit("changepoint", np.array([w_now, b]), cov[:2, :2], changepoint=tc)


def fit_trend(t: np.ndarray, wear: np.ndarray, error: np.ndarray) -> Fit | None:
    """Both models fitted to the wear estimates ``wear`` (%) at times ``t`` (<= 0, the last 0) with
    standard errors ``error``; the one of smaller AICc (:mod:`faultgen.monitor.prognosis`, 3-4), None
    when neither fits."""
    from scipy import stats
    from scipy.optimize import curve_fit
    from statsmodels.tools.eval_measures import aicc

    t, wear, error = (np.asarray(v, dtype=float) for v in (t, wear, error))
    fits = []
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
                params, cov = curve_fit(f, t, wear, p0=p0, sigma=error, absolute_sigma=True, maxfev=5000)
        except (RuntimeError, ValueError, np.linalg.LinAlgError):
            continue
        residual = wear - f(t, *params)
        chi2 = float(np.sum((residual / error) ** 2))
        cov = _widened(cov, chi2, len(t) - n_params)
        if not (np.all(np.isfinite(params)) and np.all(np.isfinite(cov))):
            continue
        # Gaussian likelihood, the variances' common scale at its maximum (one parameter more)
        scale = np.sqrt(chi2 / len(t)) if chi2 > 0 else 1e-12
        llf = float(np.sum(stats.norm.logpdf(residual, scale=error * scale)))
        found = Fit(name, params, cov, float(aicc(llf, len(t), n_params + 1)))
        if name == "linear":
            linear = found
        fits.append(found)
    if not fits:
        return None
    if len(fits) == 2 and fits[1].aicc < fits[0].aicc - AICC_MARGIN:
        return fits[1]
    return fits[0]
