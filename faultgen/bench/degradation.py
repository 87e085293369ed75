"""The degradation baselines of the prognostics track (``faultgen bench score prognostics --baseline
linear|exponential``): a trend fitted on a health indicator and extrapolated to the train split's
end-of-life level.

**Health indicator.** Per axis, the per-record mean absolute motor torque (``mean_abs_torque``,
N m) less what the operating conditions explain: ordinary least squares (``statsmodels`` OLS) of it
on a constant, the payload mass (kg) and the axis's joint temperature (deg C), where the unit logs
them and they vary, and a trend in time ``t`` (records since the first): linear ``b t``, or
exponential ``a (exp(k t) - 1) / k`` (the exponential degradation model of Gebraeel et al. 2005,
written by its slope ``a`` at the first record and its growth rate ``k``; ``scipy.optimize.curve_fit``
from the linear fit). The indicator is the trend over the unit's conditions-corrected level at its
first record (the fitted torque with no part and the joint at 20 deg C, the same reference whatever
records are fitted): the relative rise of the axis's torque, 1 = 100 %.

**End-of-life level.** Learnt from the train split: for each run-to-failure train unit, the
indicator of its worn axis at its end of life by the baseline's own trend (fitted on its records up
to it; the exponential's, where it converges, else the line's); per axis the mean
over the units wearing it, and the mean over all units for an axis no train unit wears.

**Prediction.** At each time of prediction, on the unit's records so far: the axis whose linear
trend is the most significant (largest ``b / se(b)``) is taken as the wearing one; its trend's
parameters are drawn :data:`SAMPLES` times from their fitted normal distribution (the OLS or
curve_fit covariance, seeded), and each draw's crossing of the end-of-life level solved in closed
form: the end-of-life time's distribution (a draw that never crosses: ``inf``). A trend whose fit
fails gives no prediction (the exponential falls back to the linear trend, said in its docstring).

Why not ``faultgen.monitor.prognosis``: the bench and the monitor are sibling layers that do not
import each other (pyproject's import-linter contract); the monitor's trend is fitted on the twin's
wear estimates, this one on a feature of the records, which a benchmark method may read.
"""

from __future__ import annotations

import warnings

import numpy as np

from faultgen.bench import files
from faultgen.bench.prognosers import end_of_life, prefix

#: Draws of a trend's parameters per prediction.
SAMPLES = 1000
#: Fewest residual degrees of freedom a trend is fitted with.
MIN_DOF = 3


def _conditions(unit: files.Unit, axis: int) -> np.ndarray:
    """Columns of the conditions regressors of ``axis`` (0-based): a constant, the payload mass (kg) and
    the axis's joint temperature less 20 deg C where logged and varying; shape (n_records, 1..3)."""
    n = len(unit.arrays["cycles"])
    columns = [np.ones(n)]
    for name in ("payload_mass", "joint_temperature"):
        if name in unit.arrays:
            values = np.asarray(unit.arrays[name], dtype=float)
            values = values[:, axis] if values.ndim == 2 else values
            if np.ptp(values) > 1e-9:  # the level: no part, a joint at 20 deg C (the same reference in every prefix)
                columns.append(values - (20.0 if name == "joint_temperature" else 0.0))
    return np.column_stack(columns)


def linear_fit(unit: files.Unit, axis: int):
    """OLS of ``axis``'s (0-based) mean absolute torque on the conditions and a line in time:
    (slope b per record, its standard error, level L N m, t0) or None when there are too few records."""
    import statsmodels.api as sm

    y = np.asarray(unit.arrays["mean_abs_torque"][:, axis], dtype=float)
    cycles = np.asarray(unit.arrays["cycles"], dtype=float)
    Z = _conditions(unit, axis)
    X = np.column_stack([Z, cycles - cycles[0]])
    if len(y) - X.shape[1] < MIN_DOF:
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = sm.OLS(y, X).fit()
    b, se = float(fit.params[-1]), float(np.sqrt(fit.cov_params()[-1, -1]))
    level = float(fit.params[0])
    if not (np.isfinite(b) and np.isfinite(se) and level > 0):
        return None
    return b, max(se, 1e-12), level, float(cycles[0])


def _expm1_over(k, t):
    k, t = np.asarray(k, dtype=float), np.asarray(t, dtype=float)
    small = np.abs(k * t) < 1e-8
    return np.where(small, t * (1.0 + 0.5 * k * t), np.expm1(k * t) / np.where(small, 1.0, k))


def _exponential_fit(unit: files.Unit, axis: int, slope: float):
    """curve_fit of the exponential trend with the conditions: ((a, k), their 2x2 covariance, level)
    or None when it does not converge."""
    from scipy.optimize import curve_fit

    y = np.asarray(unit.arrays["mean_abs_torque"][:, axis], dtype=float)
    cycles = np.asarray(unit.arrays["cycles"], dtype=float)
    t = cycles - cycles[0]
    Z = _conditions(unit, axis)
    m = Z.shape[1]
    if len(y) - m - 2 < MIN_DOF:
        return None

    def model(_, *p):
        return Z @ np.asarray(p[:m]) + p[m] * _expm1_over(p[m + 1], t)

    c0 = np.linalg.lstsq(Z, y - slope * t, rcond=None)[0]
    span = max(float(t[-1]), 1.0)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            params, cov = curve_fit(model, t, y, p0=[*c0, slope, 0.1 / span], maxfev=5000)
    except (RuntimeError, ValueError, np.linalg.LinAlgError):
        return None
    if not (np.all(np.isfinite(params)) and np.all(np.isfinite(cov))):
        return None
    level = float(params[0])
    return params[m:], cov[m:, m:], level


class _Degradation:
    """Shared by both baselines: the end-of-life levels from the train split, the axis choice."""

    model = "linear"

    def __init__(self, seed: int = 0):
        self.seed = seed

    def fit(self, units: list[files.Unit], failure_wear: float):
        levels: dict[int, list[float]] = {}
        for unit in units:
            life = end_of_life(unit, failure_wear) if unit.fault_level is not None and unit.worn_axis else None
            if life is None:
                continue
            n = int(np.searchsorted(unit.arrays["cycles"], life, side="right"))
            rise = self._rise_at_end(prefix(unit, n), unit.worn_axis - 1, life)
            if rise is not None:
                levels.setdefault(unit.worn_axis, []).append(rise)
        if not levels:
            raise ValueError(f"{self.model} degradation: no train unit reaches the failure wear {failure_wear:g} % "
                             "with enough records for a trend")
        self.levels_ = {axis: float(np.mean(v)) for axis, v in levels.items()}
        self.pooled_ = float(np.mean([x for v in levels.values() for x in v]))
        return self

    def _rise_at_end(self, unit: files.Unit, axis: int, life: float) -> float | None:
        """The indicator (relative rise) of ``axis`` (0-based) at ``life``, by this baseline's trend
        fitted on ``unit``'s records."""
        found = linear_fit(unit, axis)
        if found is None:
            return None
        b, _, level, t0 = found
        return b * (life - t0) / level

    def _axis(self, unit: files.Unit):
        """(0-based axis, its linear fit) of the most significant rising trend; None without one."""
        best = None
        for axis in range(unit.n_axes):
            found = linear_fit(unit, axis)
            if found is not None and (best is None or found[0] / found[1] > best[1][0] / best[1][1]):
                best = (axis, found)
        return best

    def _rng(self, unit: files.Unit) -> np.random.Generator:
        return np.random.default_rng([self.seed, len(unit.arrays["cycles"])])

    def predict(self, unit: files.Unit):
        chosen = self._axis(unit)
        if chosen is None:
            return None
        axis, (b, se, level, t0) = chosen
        rise = self.levels_.get(axis + 1, self.pooled_) * level  # N m above the level at end of life
        now = float(unit.arrays["cycles"][-1])
        toe = self._crossing(unit, axis, b, se, level, rise, t0)
        return np.maximum(toe, now)

    def _crossing(self, unit, axis, b, se, level, rise, t0) -> np.ndarray:
        slopes = self._rng(unit).normal(b, se, SAMPLES)
        with np.errstate(divide="ignore"):
            return np.where(slopes > 0, t0 + rise / np.where(slopes > 0, slopes, 1.0), np.inf)


class LinearDegradation(_Degradation):
    """Linear degradation on the health indicator (module docstring).

    Parameters
    ----------
    seed : int, default=0
        Seeds the draws of the trend's parameters (the same records, the same draws).
    """

    model = "linear"


class ExponentialDegradation(_Degradation):
    """Exponential degradation ``a (exp(k t) - 1) / k`` on the health indicator (module docstring);
    where its fit does not converge, the linear trend's prediction.

    Parameters
    ----------
    seed : int, default=0
    """

    model = "exponential"

    def _rise_at_end(self, unit: files.Unit, axis: int, life: float) -> float | None:
        linear = linear_fit(unit, axis)
        found = None if linear is None else _exponential_fit(unit, axis, linear[0])
        if found is None:
            return super()._rise_at_end(unit, axis, life)
        (a, k), _, level = found
        return float(a * _expm1_over(k, life - linear[3])) / level

    def _crossing(self, unit, axis, b, se, level, rise, t0) -> np.ndarray:
        found = _exponential_fit(unit, axis, b)
        if found is None:
            return super()._crossing(unit, axis, b, se, level, rise, t0)
        params, cov, _ = found
        drawn = self._rng(unit).multivariate_normal(params, cov, size=SAMPLES, method="eigh")
        a, k = drawn[:, 0], drawn[:, 1]
        out = np.full(SAMPLES, np.inf)
        flat = np.abs(k) < 1e-12
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = k * rise / np.where(a != 0, a, 1.0)
            s = np.where(flat, rise / np.where(a != 0, a, 1.0), np.log1p(np.maximum(ratio, -1 + 1e-15)) /
                         np.where(flat, 1.0, k))
        ok = (a > 0) & (flat | (ratio > -1)) & np.isfinite(s) & (s >= 0)
        out[ok] = t0 + s[ok]
        return out

