"""Whether a log can tell an axis's dry (Coulomb) friction level from its viscous one
(:func:`dry_and_viscous`): the identifiability check of the joint fit that ``friction_every_axis``
makes on every moving axis (:func:`faultgen.calibrate.loop.own_friction`).

On a motion of few steady speeds the dry column ``G sign(qd)`` and the viscous column ``G^2 qd`` are
nearly parallel, and a fit trades one level for the other at little cost: on faultgen's own UR5
(a unit spread of 15 %, LuGre friction, an arc-weld program) the wrist's dry level came out at
0.3-0.4 times the plant's with a viscous level 15 times it. The check is the
standard error of the dry level in the joint fit, from the least-squares covariance
``s^2 (X^T X)^-1`` (Seber & Lee 2003, *Linear Regression Analysis*, 2nd ed., sec. 3.3) on the
thinned samples (every ``W``-th, ``W`` the derivative filter's window: the residual's
independent samples, as :mod:`faultgen.calibrate.residual_tests` counts them), so that both the
columns' collinearity (the variance inflation ``1 / (1 - c^2)``, ``c`` the cosine between them)
and what the model leaves (``s``: the residual's RMS after the fit, noise and any mismatch) set it.
The dry level is *separable* when its 95 % interval (``t`` quantile) is within :data:`SHARE` of
the nominal model's dry level either way; otherwise it is held at the nominal model's
(the prior) and reported not separable on this motion.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import t as student_t

#: Largest half-width of the dry level's 95 % interval, as a share of the nominal dry level, for it to
#: be fitted: the unit spread's standard deviation (:class:`faultgen.operation.conditions.UnitSpread`,
#: 15 %), so a level the log cannot place within a unit's spread of the type's is not taken from it.
SHARE = 0.15
#: The interval's level.
LEVEL = 0.95


def dry_and_viscous(design: np.ndarray, residual: np.ndarray, rows: np.ndarray, stride: int, nominal_dry: float
                    ) -> dict:
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
        The nominal model's motor-side dry level, N m (the scale of :data:`SHARE`).

    Returns
    -------
    dict
        ``separable`` (bool), ``dry_half_width_Nm`` (the 95 % interval's half-width of the motor-side
        dry level; None: unbounded, the columns parallel or too few samples), ``share`` (over
        ``nominal_dry``; None likewise), ``cosine`` and ``variance_inflation`` of the two
        columns, ``samples`` (independent), ``rule``.
    """
    x, y = design[rows][::max(1, int(stride))], residual[rows][::max(1, int(stride))]
    n = x.shape[0]
    norms = np.linalg.norm(x, axis=0)
    cosine = float(abs(x[:, 0] @ x[:, 1]) / (norms[0] * norms[1])) if np.all(norms > 0) else 1.0
    record = {"cosine": cosine, "variance_inflation": float(1 / max(1 - cosine**2, 1e-300)), "samples": int(n),
              "rule": (f"dry level's {LEVEL:.0%} interval (least squares, thinned samples) within "
                       f"{SHARE:.0%} of the nominal dry level either way")}
    gram = x.T @ x
    if n <= 3 or np.linalg.cond(gram) > 1e12:
        return {**record, "separable": False, "dry_half_width_Nm": None, "share": None}
    theta = np.linalg.solve(gram, x.T @ y)
    s2 = float(np.sum((y - x @ theta) ** 2) / (n - 2))
    half = float(student_t.ppf((1 + LEVEL) / 2, n - 2) * np.sqrt(s2 * np.linalg.inv(gram)[0, 0]))
    share = half / nominal_dry if nominal_dry > 0 else None
    return {**record, "separable": share is not None and bool(share <= SHARE), "dry_half_width_Nm": half,
            "share": share}
