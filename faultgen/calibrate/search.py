"""Model selection: which effect explains the torque residual, on which axes, with what size.

One step (:func:`best_step`), for the current model and its residual ``r = tau_measured -
tau_model`` (arm side, N m):

1. Every effect of the library is fitted to the residual of the **fitting part** (the first
   :data:`FIT_FRACTION` of the record), each axis on its own (the payload on all axes at once),
   by linear least squares in its linear parameters and a grid search over its nonlinear one
   (the optimisers :class:`AxisLeastSquares` and :class:`RobotLeastSquares`; an effect not linear
   in its parameter brings its own, :meth:`faultgen.effects.Effect.search`).
2. Each fit is judged on the **held-out part** (the rest of the record, never used to fit): the
   gain of an axis is how much its normalised RMS error (RMSE over the RMS of the measured
   torque of that axis) drops. This is the guard against over-fitting: a term that fits noise
   or a coincidence of the fitting part does not carry over.
3. An axis is *significant* for an effect when its held-out gain is at least
   :data:`MIN_GAIN` (absolute, in nrmse) **and** at least :data:`MIN_RELATIVE_GAIN` of that
   axis's held-out nrmse before the step (a significance threshold on the effect size that noise
   and the rigid-model mismatch stay under; docs/calibration.md gives the null-case figures), and
   the fit is physical: within the effect's bounds and the motor's torque limit.
4. The candidates with significant axes are compared by an information criterion on the
   held-out part (:func:`held_out_aic`): Akaike's criterion of the Gaussian held-out likelihood,
   each axis with its own noise variance and its *effective* number of samples (the held-out
   count over the residual's integrated autocorrelation time, so that a smooth, correlated
   residual does not count as thousands of independent samples), penalised by twice the
   parameters fitted. Candidates within :data:`SEPARABLE` of the best (Burnham & Anderson 2002,
   *Model Selection and Multimodel Inference*, 2nd ed., sec. 2.6: a difference of at most 2 means
   substantial support for both) are **not separable on this log**: the simplest of them (earliest
   in :data:`faultgen.effects.EFFECTS`) is fitted and the step's evidence lists them all with
   their AIC differences, Akaike weights and evidence ratios (:func:`compare`).

The criterion and the gap record live in :mod:`faultgen.calibrate.criterion` (this module fits,
that one judges); their names are importable from here too.

The workflow (:func:`faultgen.calibrate.calibrate`) adds the winner to the model on its
significant axes, recomputes the residual with the augmented model and repeats until no
effect is significant on any axis.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar
from tqdm.auto import tqdm

from faultgen.calibrate.criterion import SEPARABLE as SEPARABLE
from faultgen.calibrate.criterion import compare, effective_samples, noise_floor
from faultgen.calibrate.criterion import gap as gap
from faultgen.calibrate.criterion import held_out_aic as held_out_aic
from faultgen.calibrate.criterion import rms as _rms
from faultgen.effects import EFFECTS, REST_SPEED, Effect, Motion

#: Share of the record (by time, from the start) used for fitting; the rest is held out.
FIT_FRACTION = 0.7
#: Smallest held-out nrmse drop of an axis that counts (1 % of that axis's torque RMS).
MIN_GAIN = 0.01
#: Smallest held-out nrmse drop of an axis relative to its nrmse before the step.
MIN_RELATIVE_GAIN = 0.2
#: Held-out AIC gain an effect already in the model must give on an axis still above its noise
#: floor to be added there (:func:`reopen`; Burnham & Anderson 2002, sec. 2.6: above 10 the model
#: without it has essentially no support).
REOPEN_EVIDENCE = 10.0
#: An axis is still open when its held-out nrmse is above this multiple of its noise floor
#: (:func:`noise_floor`).
ABOVE_FLOOR = 1.2
#: Share of an open axis's held-out nrmse above its noise floor that a re-searched effect must
#: close (:func:`reopen`): a model mismatch the effect fits a little of is not the effect.
REOPEN_SHARE = 0.5
#: Blocks of the fitting part for the jackknife standard errors (:func:`standard_errors`).
JACKKNIFE_BLOCKS = 10
#: Rounds of a nested fit whose unfitted parameters follow from the fitted ones (:func:`_nested`).
COMPLETE_ITERATIONS = 4



@dataclass(frozen=True)
class Split:
    """Per-axis boolean masks ``(n, 6)``: ``fit`` (first part of the record) and ``held_out``
    (the rest). Both leave out the first and last :data:`EDGE` seconds, where the derivative
    filter is weakest, and the samples where the axis is at rest (:data:`REST_SPEED`)."""

    fit: np.ndarray
    held_out: np.ndarray

    EDGE = 0.1

    @classmethod
    def of(cls, t: np.ndarray, qd: np.ndarray) -> Split:
        t = np.asarray(t, dtype=float) - float(t[0])
        inner = (t >= cls.EDGE) & (t <= t[-1] - cls.EDGE)
        cut = FIT_FRACTION * t[-1]
        moving = np.abs(np.asarray(qd)) >= REST_SPEED
        return cls(moving & (inner & (t < cut))[:, None], moving & (inner & (t >= cut))[:, None])


@dataclass
class Candidate:
    """One effect fitted to the current residual.

    Attributes
    ----------
    effect : Effect
        The fitted effect: the current model's values of it with the fitted parameters on every
        axis (robot-wide: the fitted ones), significant or not, absolute, in SI units.
    axes : list of int
        Significant axes, 0-based (all six for a robot-wide effect that is significant; none when
        the effect explains nothing). Only these are written into the model.
    gain : ndarray of shape (6,)
        Held-out nrmse drop per axis (all axes, significant or not).
    relative_gain : ndarray of shape (6,)
        ``gain`` over the held-out nrmse before.
    contribution : ndarray of shape (n, 6)
        Fitted torque of the effect, N m (zero on axes that are not significant).
    fitted_torque : ndarray of shape (n, 6)
        Fitted torque on every axis, significant or not, N m (:func:`reopen` tries the others).
    physical : ndarray of shape (6,)
        Whether the fit of each axis may be written (:func:`_physical`).
    parameters : int
        Parameters fitted per axis (once when robot-wide), for the information criterion.
    """

    effect: Effect
    axes: list[int]
    gain: np.ndarray
    relative_gain: np.ndarray
    contribution: np.ndarray
    fitted_torque: np.ndarray | None = None
    physical: np.ndarray | None = None
    parameters: int = 1

    @property
    def fitted_parameters(self) -> int:
        """Parameters the step would add: per significant axis, or once when robot-wide."""
        if not self.axes:
            return 0
        return self.parameters * (len(self.axes) if self.effect.per_axis else 1)

    @property
    def score(self) -> float:
        """Drop of the held-out ``total_nrmse`` over the significant axes."""
        return float(np.sum(self.gain[self.axes]) / len(self.gain))


def _lstsq(phi: np.ndarray, y: np.ndarray) -> np.ndarray:
    if not np.any(phi):
        return np.zeros(phi.shape[1])
    return np.linalg.lstsq(phi, y, rcond=None)[0]


def _nested(design: np.ndarray, target: np.ndarray, levels: tuple[int, ...] | None, admissible,
            complete=None) -> np.ndarray:
    """Least squares of ``target`` (m,) on the leading ``level`` columns of ``design`` (m, k) at
    each of ``levels`` (simplest first; None: all columns at once), keeping the most detailed level
    whose fit is ``admissible(theta)`` and lowers the Bayesian information criterion
    ``m ln(SSE / m) + level ln(m)``: a parameter the data do not support stays at zero, or at what
    ``complete(theta, level)`` (:meth:`Effect.complete`) makes of it, fitted again with the
    completed columns held (:data:`COMPLETE_ITERATIONS` rounds)."""
    best, best_bic = None, np.inf
    k = design.shape[-1]
    if target.size == 0:  # an axis that never moves faster than the rest speed: nothing to fit
        return np.zeros(k)
    for level in levels or (k,):
        theta = np.zeros(k)
        for _ in range(COMPLETE_ITERATIONS if complete is not None and level < k else 1):
            theta[:level] = _lstsq(design[:, :level], target - design[:, level:] @ theta[level:])
            if complete is not None:
                theta = complete(theta, level)
        sse = max(float(np.sum((target - design @ theta) ** 2)), 1e-300)
        bic = target.size * np.log(sse / target.size) + level * np.log(target.size)
        if best is None or (bic < best_bic and admissible(theta)):
            best, best_bic = theta, bic
    return best


class AxisLeastSquares:
    """The default optimiser of a per-axis effect (the PySINDy split: the effect gives the
    regressors, the optimiser fits them): per axis, linear least squares in the linear parameters
    at every value of the effect's :meth:`~faultgen.effects.Effect.grid` (at each of its nested
    :attr:`~faultgen.effects.Effect.levels`, as :class:`RobotLeastSquares` does), the best refined
    between its grid neighbours (bounded scalar search in log) when the grid samples a continuous
    parameter."""

    def fit(self, effect: Effect, motion: Motion, residual: np.ndarray, rows: np.ndarray,
            scale: np.ndarray) -> list[tuple]:
        """Per axis ``(h, theta, predicted torque (n,))`` fitted to ``residual`` (n, 6) on ``rows``."""
        return [self._axis(effect, motion, residual[:, a], rows[:, a], a)[1:] for a in range(residual.shape[1])]

    @staticmethod
    def _axis(effect: Effect, motion: Motion, residual: np.ndarray, rows: np.ndarray, axis: int):
        def trial(h):
            phi, offset = effect.columns(motion, axis, h)
            theta = _nested(phi[rows], residual[rows] - offset[rows], effect.levels,
                            lambda th: effect.admissible(motion, axis, effect.params(motion, axis, th, h)),
                            lambda th, level: effect.complete(motion, axis, th, level))
            predicted = phi @ theta + offset
            return float(np.sum((residual[rows] - predicted[rows]) ** 2)), h, theta, predicted

        grid = effect.grid(motion, axis)
        results = [trial(h) for h in grid]
        k = min(range(len(results)), key=lambda i: results[i][0])
        best = results[k]
        if effect.continuous and len(grid) > 2:  # refine between the grid neighbours, in log
            bounds = (np.log(grid[max(k - 1, 0)]), np.log(grid[min(k + 1, len(grid) - 1)]))
            found = minimize_scalar(lambda x: trial(float(np.exp(x)))[0], bounds=bounds, method="bounded",
                                    options={"xatol": 1e-3})
            best = min(best, trial(float(np.exp(found.x))), key=lambda r: r[0])
        return best


class RobotLeastSquares:
    """The optimiser of a robot-wide effect (payload): one least squares over the fitted samples of
    all axes at once, each axis weighted by ``1 / scale`` so that it counts by its nrmse. An effect
    with nested :attr:`~faultgen.effects.Effect.levels` is fitted at each (its leading columns
    only), and the most detailed level is kept whose fit is admissible and lowers the Bayesian
    information criterion ``N ln(SSE / N) + k ln(N)`` (N weighted residuals, k parameters) on the
    fitting part: a parameter the motion does not excite is left at its current value."""

    def fit(self, effect: Effect, motion: Motion, residual: np.ndarray, rows: np.ndarray,
            scale: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(theta, predicted torque (n, 6))`` fitted to ``residual`` (n, 6) on ``rows``."""
        phi, offset = effect.columns(motion, None, None)  # (n, 6, k), (n, 6)
        weights = 1.0 / scale
        design, target = (phi * weights[:, None])[rows], ((residual - offset) * weights)[rows]
        best = _nested(design, target, effect.levels,
                       lambda th: effect.admissible(motion, None, effect.params(motion, None, th, None)),
                       lambda th, level: effect.complete(motion, None, th, level))
        return best, phi @ best + offset


def fit_effect(effect: Effect, motion: Motion, residual: np.ndarray, tau: np.ndarray, split: Split) -> Candidate:
    """Fit ``effect`` to ``residual`` (n, 6) on the fitting part; judge it on the held-out part."""
    held, fit = split.held_out, split.fit
    scale = _rms(tau, held)
    scale = np.where(scale > 0, scale, 1.0)
    before = _rms(residual, held) / scale
    params, contribution = _fit(effect, motion, residual, fit, scale)
    fitted = effect.fitted(motion.robot, params)
    after = _rms(residual - contribution, held) / scale
    gain = before - after
    relative = gain / np.where(before > 0, before, 1.0)
    significant = (gain >= MIN_GAIN) & (relative >= MIN_RELATIVE_GAIN)
    physical = np.ones(residual.shape[1], dtype=bool)
    if effect.per_axis:
        physical = np.array([_physical(effect, motion, a, params[a]) for a in range(residual.shape[1])])
        significant &= physical
        axes = [int(a) for a in np.flatnonzero(significant)]
    else:
        # robot-wide: significant as a whole when the mean gain passes both thresholds
        total_before = float(np.mean(before))
        total_gain = float(np.mean(gain))
        whole = (total_gain >= MIN_GAIN and total_gain >= MIN_RELATIVE_GAIN * total_before
                 and effect.admissible(motion, None, params[None]))
        axes = list(range(residual.shape[1])) if whole else []
    mask = np.zeros(residual.shape[1], dtype=bool)
    mask[axes] = True
    return Candidate(fitted, axes, gain, relative, np.where(mask, contribution, 0.0), contribution, physical,
                     parameter_count(effect))


def parameter_count(effect: Effect) -> int:
    """Parameters an effect fits per axis (once when robot-wide): its linear ones plus one for a
    nonlinear parameter chosen from a grid or by its own search (a Stribeck velocity, a
    load-friction form, a backlash width)."""
    nonlinear = effect.per_axis and (effect.continuous or type(effect).grid is not Effect.grid
                                     or type(effect).search is not Effect.search)
    return int(effect.n_parameters) + int(nonlinear)


def _fit(effect: Effect, motion: Motion, residual: np.ndarray, rows: np.ndarray, scale: np.ndarray,
         near: list[int] | None = None) -> tuple[dict, np.ndarray]:
    """``effect`` fitted to ``residual`` (n, 6) on the samples of ``rows`` by its optimiser: the
    parameters keyed by axis (0-based; None when robot-wide) and the fitted torque (n, 6).
    ``near``: ``effect`` is a fit and this a jackknife replicate of it on these axes
    (:meth:`Effect.replicate`)."""
    if not effect.per_axis:
        theta, contribution = RobotLeastSquares().fit(effect, motion, residual, rows, scale)
        return {None: effect.params(motion, None, theta, None)}, contribution
    # the effect's own search (backlash), else the default optimiser
    fits = ((near is not None and effect.replicate(motion, residual, rows, scale, near))
            or effect.search(motion, residual, rows, scale)
            or AxisLeastSquares().fit(effect, motion, residual, rows, scale))
    contribution = np.zeros_like(residual)
    params = {}
    for axis, (h, theta, predicted) in enumerate(fits):
        contribution[:, axis] = predicted
        params[axis] = effect.params(motion, axis, theta, h)
    return params, contribution


@dataclass(frozen=True)
class JointFit:
    """An effect fitted on one axis together with changes of the level effects already there
    (:func:`fit_jointly`): absolute parameters of each, and the held-out nrmse gain that the
    effect adds beyond re-fitting those levels alone."""

    params: dict[str, float]
    others: list[dict[str, float]]
    gain: float
    relative_gain: float
    #: Jackknife standard errors (as :func:`standard_errors`): the effect's, then each other's.
    standard_errors: list[dict[str, float]]


def fit_jointly(effect: Effect, others: list[Effect], motion: Motion, residual: np.ndarray, tau: np.ndarray,
                split: Split, axis: int) -> JointFit | None:
    """``effect`` on ``axis`` (0-based) fitted to ``residual`` (n, 6) on the fitting part at every
    value of its grid, together with a change of each of ``others``: effects the model already
    holds on that axis whose parameters are linear (grid ``[None]``: a torque offset, a Coulomb
    or viscous level), re-opened because an earlier fit of them, made while ``effect`` was
    missing, took up part of it (a Coulomb level fitted during a warm-up takes up its early excess).
    The gain counted is the held-out nrmse drop beyond what re-fitting ``others`` alone gives, so
    ``effect`` earns it. None when that gain is not significant (:data:`MIN_GAIN`,
    :data:`MIN_RELATIVE_GAIN`) or a fit is not physical."""
    held, rows = split.held_out[:, axis], split.fit[:, axis]
    r = residual[:, axis]
    scale = _rms(tau, split.held_out)[axis] or 1.0
    before = float(np.sqrt(np.mean(r[held] ** 2)) / scale) if held.any() else 0.0
    parts = [other.columns(motion, axis, None) for other in others]
    known = np.column_stack([phi for phi, _ in parts])
    known_offset = np.sum([offset for _, offset in parts], axis=0)
    sizes = np.cumsum([0] + [phi.shape[1] for phi, _ in parts])

    def after(design, offset, theta):
        return float(np.sqrt(np.mean((r[held] - design[held] @ theta - offset[held]) ** 2)) / scale)

    alone = _lstsq(known[rows], (r - known_offset)[rows])
    reopened = after(known, known_offset, alone)
    grid = []  # (h, design, known part) per grid value
    for h in effect.grid(motion, axis):
        phi, offset = effect.columns(motion, axis, h)
        grid.append((h, np.column_stack([known, phi]), known_offset + offset))

    def fit(keep):  # the best grid value on the samples of keep: (h, theta, design, known part)
        fits = [(h, _lstsq(design[keep], (r - total)[keep]), design, total) for h, design, total in grid]
        return min(fits, key=lambda f: float(np.sum((r[keep] - f[2][keep] @ f[1] - f[3][keep]) ** 2)))

    def named(h, theta):
        return [effect.params(motion, axis, theta[sizes[-1]:], h)] + [
            other.params(motion, axis, theta[a:b], None) for other, a, b in zip(others, sizes, sizes[1:])]

    h, theta, design, total = fit(rows)
    error = after(design, total, theta)
    fitted = named(h, theta)
    gain = reopened - error
    relative = gain / before if before > 0 else 0.0
    physical = _physical(effect, motion, axis, fitted[0]) and all(
        other.admissible(motion, axis, p) for other, p in zip(others, fitted[1:], strict=True))
    if gain < MIN_GAIN or relative < MIN_RELATIVE_GAIN or not physical:
        return None
    # delete-one-block jackknife over the fitting part, the grid value chosen again in each
    replicates = []
    for block in np.array_split(np.flatnonzero(rows), JACKKNIFE_BLOCKS):
        keep = rows.copy()
        keep[block] = False
        replicate = fit(keep)
        replicates.append(named(replicate[0], replicate[1]))
    errors = [_jackknife([rep[k] for rep in replicates]) for k in range(len(fitted))]
    return JointFit(fitted[0], fitted[1:], gain, relative, errors)


def standard_errors(effect: Effect, motion: Motion, residual: np.ndarray, tau: np.ndarray, split: Split,
                    axes: list[int], blocks: int = JACKKNIFE_BLOCKS) -> dict:
    """Standard errors of ``effect``'s fitted parameters on ``axes`` (0-based), by the delete-one-
    block jackknife over time (Kunsch 1989): the fitting part is cut into ``blocks`` contiguous
    blocks, the effect is fitted again with each left out (near its fit where it
    can, :meth:`Effect.replicate`), and the spread of the ``blocks`` fits
    gives ``se = sqrt((B - 1) / B * sum (p_b - mean p)^2)``. Blocks of time keep the residual's
    correlation in time (drift, ringing), which a least-squares covariance would take for
    independent samples. A parameter chosen from a grid (pole count) has 0 when no block moves it.

    Returns
    -------
    dict
        Keyed like the fit's parameters (axis, 0-based; None when robot-wide): parameter name ->
        standard error, in the parameter's unit.
    """
    scale = _rms(tau, split.held_out)
    scale = np.where(scale > 0, scale, 1.0)
    fitting = np.flatnonzero(split.fit.any(axis=1))
    edges = np.linspace(fitting[0], fitting[-1] + 1, blocks + 1).round().astype(int)
    replicates = []
    for low, high in itertools.pairwise(edges):
        rows = split.fit.copy()
        rows[low:high] = False
        replicates.append(_fit(effect, motion, residual, rows, scale, near=axes)[0])
    keys = [None] if not effect.per_axis else axes
    return {key: _jackknife([r[key] for r in replicates]) for key in keys}


def _jackknife(replicates: list[dict[str, float]]) -> dict[str, float]:
    """Delete-one-block jackknife standard error of each parameter from its B replicate values:
    ``sqrt((B - 1) / B * sum (p_b - mean p)^2)``."""
    names = list(replicates[0])
    values = np.array([[r[name] for name in names] for r in replicates], dtype=float)
    b = len(replicates)
    spread = np.sqrt((b - 1) / b * np.sum((values - values.mean(axis=0)) ** 2, axis=0))
    return {name: float(v) for name, v in zip(names, spread, strict=True)}


def _physical(effect: Effect, motion: Motion, axis: int, params: dict[str, float]) -> bool:
    """Whether a per-axis fit may be written: the effect's own bounds (:meth:`Effect.admissible`)
    and a torque the motor can give (:meth:`Effect.motor_torque` within the motor's torque limit,
    e.g. no offset above the axis's rated torque)."""
    limit = motion.robot.motor_torque_limit[axis]
    return bool(effect.admissible(motion, axis, params) and effect.motor_torque(motion, axis, params) <= limit)


def rank(motion: Motion, residual: np.ndarray, tau: np.ndarray, split: Split, progress: bool = False,
         label: str = "fitting effects") -> list[Candidate]:
    """All effects fitted, best first per the selection rule of this module's docstring
    (``progress``: a progress bar over the effects, labelled ``label``): first the effect fitted
    (the simplest of those not separable from the best by held-out AIC), then the others with
    significant axes by AIC, then the rest by score."""
    effects = tqdm(EFFECTS.values(), desc=label, unit="effect", disable=not progress, leave=False)
    candidates = [fit_effect(e, motion, residual, tau, split) for e in effects]
    return order(candidates, residual, split)


def order(candidates: list[Candidate], residual: np.ndarray, split: Split) -> list[Candidate]:
    """``candidates`` (fitted to ``residual``) in the order :func:`rank` gives."""
    place = {e.id: k for k, e in enumerate(EFFECTS.values())}
    evidence = compare(candidates, residual, split)
    if not evidence:
        return sorted(candidates, key=lambda c: (-c.score, place.get(c.effect.id, len(place))))
    tied = [c for c in candidates if c.effect.id in evidence and not evidence[c.effect.id]["separable"]]
    chosen = min(tied, key=lambda c: place.get(c.effect.id, len(place)))

    def key(c: Candidate):
        if c is chosen:
            return (0, 0.0)
        if c.effect.id in evidence:
            return (1, evidence[c.effect.id]["delta_aic"])
        return (2, -c.score)

    return sorted(candidates, key=key)


def reopen(effect: Effect, motion: Motion, residual: np.ndarray, tau: np.ndarray, split: Split,
           axes: list[int], floor: np.ndarray | None = None) -> tuple[Candidate, dict[int, float]]:
    """``effect`` (already in the model on other axes) fitted again to ``residual`` (n, N) and
    judged on each of ``axes`` (0-based; those still above their noise floor) by its held-out
    evidence alone (fitted as :meth:`Effect.reopened` gives it: a Stribeck hump with a wider
    velocity grid): the AIC gain ``n_eff ln(SSE_before / SSE_after) - 2 k`` of that axis
    (:func:`held_out_aic`) must be at least :data:`REOPEN_EVIDENCE`, the held-out nrmse must drop
    by at least :data:`REOPEN_SHARE` of its excess over ``floor`` (N,; default
    :func:`noise_floor` of ``tau``), and the fit be physical. The absolute gain threshold :data:`MIN_GAIN` does not apply: an
    effect a first search found on some axes may be smaller than 1 % of the torque on another
    (a large payload added first leaves a hump there that is small beside the axis's torque).

    Returns
    -------
    (Candidate, dict)
        The fit (``axes`` the axes that pass, ``contribution`` on them only) and the AIC gain of
        every axis tried.
    """
    effect = effect.reopened()
    fit = fit_effect(effect, motion, residual, tau, split)
    held = split.held_out
    k = parameter_count(effect)
    n_eff = effective_samples(residual - fit.fitted_torque, held)
    count = np.maximum(held.sum(axis=0), 1)
    before = np.sum(np.where(held, residual, 0.0) ** 2, axis=0) / count
    after = np.sum(np.where(held, residual - fit.fitted_torque, 0.0) ** 2, axis=0) / count
    gains = {}
    for a in axes:
        if not held[:, a].any() or after[a] <= 0 or before[a] <= 0:
            continue
        gains[a] = float(n_eff[a] * np.log(before[a] / after[a]) - 2 * k)
    floor = noise_floor(tau, held) if floor is None else np.asarray(floor)
    scale = _rms(tau, held)
    excess = np.sqrt(before) / np.where(scale > 0, scale, 1.0) - floor  # held-out nrmse above the floor
    passing = sorted(a for a, g in gains.items() if g >= REOPEN_EVIDENCE and fit.physical[a]
                     and fit.gain[a] > 0 and fit.gain[a] >= REOPEN_SHARE * excess[a])
    mask = np.zeros(residual.shape[1], dtype=bool)
    mask[passing] = True
    found = Candidate(fit.effect, passing, fit.gain, fit.relative_gain, np.where(mask, fit.fitted_torque, 0.0),
                      fit.fitted_torque, fit.physical, k)
    return found, gains
