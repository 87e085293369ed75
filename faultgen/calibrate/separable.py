"""Whether a log can tell an axis's dry (Coulomb) friction level from its viscous one
(:func:`dry_and_viscous`): the identifiability check of the joint fit that ``friction_every_axis``
makes on every moving axis (:func:`faultgen.calibrate.loop.own_friction`).

On a motion of few steady speeds the dry column ``G sign(qd)`` and the viscous column ``G^2 qd`` are
nearly parallel, and a fit trades one level for the other at little cost: on faultgen's own UR5
(a unit spread of 15 %, LuGre friction, an arc-weld program) the wrist's dry level came out at
0.3-0.4 times the plant's with a viscous level 15 times it. The check has two parts, both on the
joint fit (statsmodels' OLS, whose covariance is ``s^2 (X^T X)^-1``: Seber & Lee 2003, *Linear
Regression Analysis*, 2nd ed., sec. 3.3) on the thinned samples (every ``W``-th, ``W`` the
derivative filter's window: the residual's independent samples, as
:mod:`faultgen.calibrate.residual_tests` counts them), so that both the columns' collinearity (the
variance inflation ``1 / (1 - c^2)``, ``c`` the cosine between them) and what the model leaves
(``s``: the residual's RMS after the fit, noise and any mismatch) set it:

1. *precision*: the dry level's standard error at most :data:`SHARE` of the nominal dry level (the
   unit spread's standard deviation): the log places the level at least as well as knowing the
   type does;
2. *range*: the dry level's whole 95 % interval (``t`` quantile) inside :data:`RANGE` times the
   nominal (the unit spread's log-normal law, :data:`SIGMAS` standard deviations either way): a
   level no unit of the type has is a trade with something the model leaves, not the unit's
   friction. On the UR5 fleet the joint fit put a wrist's dry level at 1.9 times nominal (truth
   1.07) with a standard error of 4 %: the payload fitted on the same log left a torque in the
   shape of dry friction on that axis (docs/analysis.md, "The range rule"), which no interval from the noise sees.

A level that passes both is *separable* and fitted; otherwise it is held at the nominal model's
(the prior) and reported not separable on this motion, with the part that failed (``held_by``).
"""

from __future__ import annotations

import numpy as np
import statsmodels.api as sm

#: Largest standard error of the dry level in the joint fit, as a share of the nominal dry level, for
#: it to be fitted: the unit spread's standard deviation (:class:`faultgen.operation.conditions.UnitSpread`,
#: 15 %), so a level the log places less well than the type's spread does is not taken from it.
SHARE = 0.15
#: The interval's level.
LEVEL = 0.95
#: Standard deviations of the unit spread's log-normal law either way that bound a plausible level.
SIGMAS = 3.0
#: The dry levels a unit of the type can have, over the nominal: ``exp(-+SIGMAS * SHARE)`` (0.64..1.57).
RANGE = (float(np.exp(-SIGMAS * SHARE)), float(np.exp(SIGMAS * SHARE)))


def dry_and_viscous(design: np.ndarray, residual: np.ndarray, rows: np.ndarray, stride: int, nominal_dry: float,
                    model_dry: float | None = None) -> dict:
    """The identifiability of the dry and viscous levels of one axis in their joint least-squares fit.

    Parameters
    ----------
    design : ndarray (n, 2)
        The dry column (``G sign(qd)``, per N m of motor-side level) and the viscous column (``G^2 qd``,
        per N m s/rad of motor-side level).
    residual : ndarray (n,)
        What the model leaves on the axis, N m (arm side).
    rows : ndarray of bool (n,)
        The samples fitted (the axis moving).
    stride : int
        Samples between two independent ones (>= 1).
    nominal_dry : float
        The nominal model's motor-side dry level, N m (> 0: the scale of :data:`SHARE` and :data:`RANGE`).
    model_dry : float, optional
        The motor-side dry level of the model that left ``residual``, N m (default ``nominal_dry``):
        the fitted level is it plus the fit's change.

    Returns
    -------
    dict
        ``separable`` (bool), ``held_by`` (None, ``"precision"`` or ``"range"``: the part that failed),
        ``fitted_dry_Nm`` (the joint fit's motor-side dry level on every fitted sample; None: not
        fitted), ``level`` and ``interval`` (it and its 95 % interval over ``nominal_dry``),
        ``dry_half_width_Nm`` (the interval's half-width; None: unbounded, the columns parallel or
        too few samples), ``share`` (over ``nominal_dry``; None likewise), ``standard_error`` (the
        level's, over ``nominal_dry``), ``range``, ``cosine`` and ``variance_inflation`` of the two
        columns, ``samples`` (independent), ``rule``.

    Raises
    ------
    ValueError
        For ``nominal_dry`` not above 0 or ``stride`` below 1.
    """
    if not nominal_dry > 0:
        raise ValueError(f"nominal_dry {nominal_dry!r}: expected the nominal dry level, a number of N m above 0")
    if int(stride) < 1:
        raise ValueError(f"stride {stride!r}: expected a number of samples >= 1")
    model_dry = nominal_dry if model_dry is None else float(model_dry)
    x, y = design[rows][::int(stride)], residual[rows][::int(stride)]
    n = x.shape[0]
    norms = np.linalg.norm(x, axis=0)
    cosine = float(abs(x[:, 0] @ x[:, 1]) / (norms[0] * norms[1])) if np.all(norms > 0) else 1.0
    record = {"cosine": cosine, "variance_inflation": float(1 / max(1 - cosine**2, 1e-300)), "samples": int(n),
              "range": list(RANGE),
              "rule": (f"dry level's standard error (least squares, thinned samples) within {SHARE:.0%} of the "
                       f"nominal dry level, and its {LEVEL:.0%} interval inside {RANGE[0]:.2f}..{RANGE[1]:.2f} "
                       f"x nominal (the unit spread's {SIGMAS:g} standard deviations)")}
    if n <= 3 or np.linalg.cond(x.T @ x) > 1e12:
        return {**record, "separable": False, "held_by": "precision", "fitted_dry_Nm": None, "level": None,
                "interval": None, "dry_half_width_Nm": None, "share": None, "standard_error": None}
    fit = sm.OLS(y, x).fit()  # the covariance s^2 (X^T X)^-1 and the t quantile of its df_resid
    low, high = fit.conf_int(alpha=1 - LEVEL)[0]
    half = float(high - low) / 2
    fitted = model_dry + float(sm.OLS(residual[rows], design[rows]).fit().params[0])  # every sample's estimate
    level = fitted / nominal_dry
    interval = [level - half / nominal_dry, level + half / nominal_dry]
    error = float(fit.bse[0]) / nominal_dry
    held_by = ("precision" if error > SHARE else
               "range" if interval[0] < RANGE[0] or interval[1] > RANGE[1] else None)
    return {**record, "separable": held_by is None, "held_by": held_by, "fitted_dry_Nm": fitted, "level": level,
            "interval": interval, "dry_half_width_Nm": half, "share": half / nominal_dry, "standard_error": error}


def words(check: dict) -> str:
    """Why :func:`dry_and_viscous` held a dry level, in a sentence's middle: what failed and its figures."""
    if check.get("held_by") == "range":
        low, high = check["interval"]
        return (f"fitted at {check['level']:.2f} x nominal ({LEVEL:.0%} interval {low:.2f}..{high:.2f}), outside the "
                f"levels a unit of the type has ({RANGE[0]:.2f}..{RANGE[1]:.2f} x): a trade with something the "
                "model leaves")
    error = check.get("standard_error")
    return ("not separable on this motion from the viscous level (its standard error "
            + ("unbounded" if error is None else f"{100 * error:.0f} % of nominal")
            + f", accepted {100 * SHARE:.0f} %)")
