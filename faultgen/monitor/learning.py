"""A unit's baseline learned (:func:`fit`, for :class:`faultgen.monitor.scoring.UnitMonitor`; what it
learns: that module's docstring), and how a unit's programs share it (issue 90, item 3's "every unit
monitored by its 40th day").

- **One program.** Its first ``train`` logs: offset, condition slopes, noise, PCA model
  (:func:`fit_shared`), the wear reads' dispersion, day-to-day scatter and observability on the
  program's wear signatures (:func:`fit_signatures`), and the learning logs' rows
  (:func:`score_learning`).
- **Programs met while the unit learns** pool into that learning (:func:`faultgen.monitor.programs.pool`):
  the unit is learned once it has ``train`` logs in all, not ``train`` of each program. The twin's
  residual makes the programs comparable up to an offset: each program its own offset, the slopes
  and noise learned within programs (the fixed-effects estimator: each program's mean taken out of
  the residuals and conditions before the least squares; the noise's degrees of freedom less one
  per program), one PCA model on the pooled standardised residuals; each its own signatures.
- **A program met after** (or with fewer than a relearning's logs in the pooled window) learns only
  its offset, on :attr:`~faultgen.monitor.scoring.UnitMonitor.relearn_logs` logs of its own
  (:func:`fit_offset`, as a unit after maintenance does), and borrows the rest (:data:`SHARED`) of
  the unit's learned baseline; its dispersion and scatter are read on the unit's pooled learning
  residuals along its own signatures.
"""

from __future__ import annotations

import numpy as np

from analysis import registry
from faultgen.monitor import bounds
from faultgen.monitor.wear_trend import WearTrend

#: What a unit's programs share of its baseline, learned once (:func:`fit_shared`): the condition
#: slopes, noise and PCA model; each program has its own offset and wear signatures.
SHARED = ("pca", "far_", "condition_mean_", "regressors_", "slope_", "gram_inv_", "scale_")


def fit(monitor, far_alpha: float, interval_z: float, limits: float) -> None:
    """Learn ``monitor``'s baseline on its ``training`` logs: all of it (:func:`fit_shared`), or for
    a program met after the unit learned (its ``borrowed_``) its offset alone (:func:`fit_offset`);
    then its signatures' parts (:func:`fit_signatures`: ``interval_z``, ``limits`` as there) and
    the learning logs' rows (:func:`score_learning`). ``far_alpha``: :func:`fit_shared`'s."""
    stamps = [s for s, _, _ in monitor.training]
    if monitor.borrowed_ is not None:
        R, (pooled, dof) = fit_offset(monitor), (monitor.borrowed_["R"], monitor.borrowed_["dof"])
    else:
        R, _ = fit_shared(monitor, far_alpha)
        pooled, dof = R, len(R) - 1 - len(monitor.regressors_)
        monitor.trend = WearTrend(monitor.n_axes, len(monitor.regressors_))
    monitor.training = []
    if monitor.signatures is not None:
        error = fit_signatures(monitor, pooled, dof, interval_z, limits)
        if monitor.borrowed_ is None:  # the learned slopes' error, in the unit's filter (scoring's docstring)
            monitor.trend.set_prior(error[:, None, None] ** 2 * monitor.gram_inv_[None])
    if monitor.borrowed_ is None:  # what the unit's programs met later borrow
        monitor.shared_ = shared(monitor, pooled, dof)
    score_learning(monitor, stamps, R)


def shared(monitor, R: np.ndarray, dof: int) -> dict:
    """What a program met later borrows of ``monitor``'s learned baseline (:data:`SHARED`), with the
    learning residuals ``R`` (m, n_features) and their degrees of freedom ``dof``."""
    return {name: getattr(monitor, name) for name in SHARED} | {"R": R, "dof": dof}


def fit_shared(monitor, far_alpha: float, groups: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The offset, condition slopes, noise and PCA model learned on ``monitor.training`` (scoring's
    docstring); ``groups`` (m,) the program of each learning log (0..G-1; None: one program): each
    its own offset, the slopes and noise within programs (module docstring); ``far_alpha``: the
    smallest significance of ``--protocol own``'s at-once limits. Returns the learning logs'
    residuals less their offset and slopes (m, n_features) and the offsets (G, n_features)."""
    E = np.stack([e for _, e, _ in monitor.training])
    C = np.array([c for _, _, c in monitor.training])  # (m, 2): temperature, payload
    monitor.mean_ = E.mean(axis=0)
    # the conditions that vary over the learning logs (and are logged) become regressors
    finite = np.all(np.isfinite(C), axis=0)
    monitor.condition_mean_ = np.where(finite, np.nanmean(np.where(np.isfinite(C), C, 0.0), axis=0), 0.0)
    monitor.regressors_ = np.flatnonzero(finite & (np.ptp(np.where(np.isfinite(C), C, 0.0), axis=0) > 0))
    X = C[:, monitor.regressors_] - monitor.condition_mean_[monitor.regressors_]
    offsets, within = monitor.mean_[None], X
    if groups is not None:  # each program's mean taken out of the residuals and the conditions
        n = E.shape[1]
        means = np.stack([np.bincount(groups, weights=column) for column in np.column_stack([E, X]).T], axis=1)
        means = means / np.bincount(groups)[:, None]
        within = X - means[groups, n:]
        monitor.slope_ = np.linalg.lstsq(within, E - means[groups, :n], rcond=None)[0]
        offsets = means[:, :n] - means[:, n:] @ monitor.slope_
        monitor.mean_ = offsets[0]
        R = E - offsets[groups] - X @ monitor.slope_
    else:
        monitor.slope_ = (np.linalg.lstsq(X, E - monitor.mean_, rcond=None)[0] if X.shape[1]
                          else np.zeros((0, E.shape[1])))
        R = E - monitor.mean_ - X @ monitor.slope_
    # (X'X)^-1 of the centred conditions: a later log's leverage (the prediction interval)
    monitor.gram_inv_ = np.linalg.pinv(within.T @ within) if X.shape[1] else np.zeros((0, 0))
    monitor.learned_ = len(E)
    scale = np.sqrt((R**2).sum(axis=0) / (len(R) - len(offsets) - X.shape[1]))
    monitor.scale_ = np.where(scale > 0, scale, 1.0)
    # the registry's monitor model (analysis.registry: the one detect and training-source build)
    settings = monitor.settings
    monitor.pca = registry.make("pca_monitor", variance=settings.variance, alpha=settings.alpha, cv=5)[1].fit(
        R / monitor.scale_)
    # --protocol own's at-once limits (T2, Q) from the same fitted model; none past far_alpha
    far = settings.alpha**settings.persistence
    monitor.far_ = None if monitor.signatures is not None or far < far_alpha else monitor.pca.limits(far)
    return R, offsets


def fit_offset(monitor) -> np.ndarray:
    """A program met after the unit learned (``monitor.borrowed_``): the unit's :data:`SHARED`
    slopes, noise and PCA model, and the program's own offset, the mean of its learning logs less
    the slopes' part. Returns those logs' residuals less both (m, n_features)."""
    for name in SHARED:
        setattr(monitor, name, monitor.borrowed_[name])
    E = np.stack([e for _, e, _ in monitor.training])
    C = np.array([c for _, _, c in monitor.training])
    X = np.nan_to_num(C[:, monitor.regressors_] - monitor.condition_mean_[monitor.regressors_])
    monitor.mean_ = (E - X @ monitor.slope_).mean(axis=0)
    monitor.learned_ = len(E)
    return E - monitor.mean_ - X @ monitor.slope_


def fit_signatures(monitor, R: np.ndarray, dof: int, interval_z: float, limits: float) -> np.ndarray:
    """Each axis's wear read's dispersion, day-to-day scatter, one log's interval width (``2
    interval_z`` standard errors) and observability (that width at most ``limits`` wear limits)
    from learning residuals ``R`` (m, n_features; ``dof`` degrees of freedom left), on
    ``monitor``'s signatures. Returns an unworn axis's standard error (n_axes,)."""
    # the learning logs are unworn: their wear estimates' scatter over the stated standard
    # error (a feature's noise is not independent of the others': a log's friction scatter
    # moves an axis's features together, along its signature) widens every later error
    monitor.dispersion_ = np.ones(monitor.n_axes)
    z = np.stack([w / e for w, e in (monitor.wear_estimate(r, monitor.scale_**2) for r in R)])
    monitor.day_scatter_ = bounds.day_scatter(z * monitor.wear_estimate(R[0], monitor.scale_**2)[1])  # points
    monitor.dispersion_ = np.maximum(1.0, np.sqrt((z**2).sum(axis=0) / dof))
    # the learned slopes' error along each axis's wear signature (% of wear per unit of
    # condition): the estimate is linear in the residual, so its covariance is the wear
    # estimate's squared error times (X'X)^-1; the trend learns it on from later logs
    error = monitor.wear_estimate(np.zeros_like(monitor.scale_), monitor.scale_**2)[1]
    # one log's 90 % interval of an unworn axis, from the noise: the rule of scoring's NOT_OBSERVABLE_LIMITS
    monitor.width_ = 2.0 * interval_z * error
    monitor.observable_ = monitor.width_ <= limits * monitor.settings.wear_limit
    return error


def score_learning(monitor, stamps: list[str], R: np.ndarray, phase: str | None = None) -> None:
    """The rows of the learning logs ``stamps`` (residuals ``R`` less offset and slopes), in place of
    those listed for them since a program change; ``phase`` "relearning" after a program change,
    else "training" (None: as ``monitor.program_changed`` says)."""
    if monitor.placeholders:  # the rows standing for these logs since a program change (by stamp: another
        learned = set(stamps)  # program's logs may lie between them, faultgen.monitor.programs)
        monitor.rows[:] = [row for row in monitor.rows if row.stamp not in learned]
        monitor.placeholders = 0
    phase = phase or ("relearning" if monitor.program_changed else "training")
    monitor.program_changed = False
    for stamp, r in zip(stamps, R):
        wear = monitor.wear_estimate(r, monitor.scale_**2)
        monitor._score(stamp, r / monitor.scale_, phase=phase, wear=None if wear is None else (*wear, wear[1], None))
