"""What the remainder follows: a sparse regression of an axis's remainder (measured minus model
torque, N m) on a generic candidate library that no effect class holds, its terms named in words
with their share of the remaining gap and an interval (:func:`explain`); and the single generic
terms a library effect is weighed against before it is written (:func:`best_single`, the rule
"no forced fit" of :mod:`faultgen.calibrate.guard`).

The candidate library of an axis ``a`` (:func:`groups`; a *group* is one form, one to three
columns fitted together):

* ``arm_periodic`` ``k``: ``sin(k q_a)``, ``cos(k q_a)``, k = 1..:data:`ARM_HARMONICS` (a ripple
  periodic in the arm angle: a gear's eccentricity, a cable);
* ``motor_periodic`` ``k``: the same in the motor angle ``G q_a``, k = 1..:data:`MOTOR_HARMONICS`;
* ``speed``, ``dry``, ``speed_squared``, ``speed_cubed``: ``qd_a``, ``sign(qd_a)``,
  ``qd_a |qd_a|``, ``qd_a^3`` (powers and signs of the speed);
* ``position_friction`` ``k``: ``sign(qd_a)`` times ``1``, ``sin(k q_a)``, ``cos(k q_a)``, k = 1, 2
  (friction that changes with the arm angle);
* ``channel_delay``: the model's torque shifted in time, ``tau_model(t - d) - tau_model(t)``, with
  the shift ``d`` (up to :data:`MAX_DELAY` either way) that fits the remainder best on the fitting
  part (a time shift of the torque channels; the first-order term ``-d tau_model'`` fails where the
  friction steps at a speed reversal);
* ``speed_drift``, ``dry_drift``: ``qd_a t``, ``sign(qd_a) t`` (t in hours from the log's start: a
  viscous or dry friction drifting in time, as with the oil's temperature);
* ``acceleration``: ``qdd_a`` (a time shift of the motion's second derivative; an inertia the model lacks);
* ``gain``: the measured torque ``tau_a`` (a gain ``g``: ``tau = g tau_model`` leaves
  ``tau - tau_model = (1 - 1/g) tau``);
* ``cross_speed`` / ``cross_acceleration`` of every other axis ``b``: ``qd_b``, ``qdd_b`` (cross-axis
  coupling).

Every fit has an intercept. The regression (:func:`explain`): scikit-learn's ``LassoCV`` (Tibshirani
1996; coordinate descent, the penalty chosen by 5-fold cross-validation over contiguous blocks of
time on the fitting part, columns standardised) selects the groups; the selected groups are then
ordered by forward selection on the held-out part (each refitted by least squares on the fitting
part, the relaxed lasso of Meinshausen 2007), a group kept while it closes at least
:data:`MIN_SHARE` of the held-out mean square remainder. Each named term gets its share of the
remaining gap (the held-out mean square it closes, in the order added) with a 95 % interval from a
block bootstrap of the held-out part (:data:`BOOTSTRAP` resamples of :data:`HELD_BLOCKS` contiguous
blocks; Kunsch 1989), and its size (amplitude, coefficient, delay, gain) with a 95 % interval from
the delete-one-block jackknife over the fitting part (10 blocks, t with 9 degrees of freedom), as
the effects' standard errors are (:func:`faultgen.calibrate.search.standard_errors`).
"""

from __future__ import annotations

from dataclasses import dataclass

import warnings

import numpy as np
from scipy.stats import t as student_t
from sklearn.exceptions import ConvergenceWarning
from sklearn.linear_model import LassoCV
from sklearn.model_selection import KFold

from faultgen import axes as axis_numbers
from faultgen.calibrate.delay import peak

#: Harmonics per arm revolution tried (``arm_periodic``, ``position_friction`` up to 2).
ARM_HARMONICS = 6
#: Harmonics per motor revolution tried (``motor_periodic``; the library's cogging has 1..24 poles).
MOTOR_HARMONICS = 3
#: Harmonics of the position-dependent friction.
FRICTION_HARMONICS = 2
#: Smallest share of the held-out mean square remainder a group must close to be named.
MIN_SHARE = 0.05
#: Most groups named per axis.
MAX_TERMS = 4
#: Most fitting-part rows the lasso sees (evenly thinned beyond it).
LASSO_ROWS = 6000
#: Blocks of the held-out part for the bootstrap of the shares, and resamples.
HELD_BLOCKS = 20
BOOTSTRAP = 400
#: Blocks of the fitting part for the jackknife intervals of the sizes.
JACKKNIFE_BLOCKS = 10
#: Largest time shift of the torque searched (``channel_delay``), s.
MAX_DELAY = 0.1


@dataclass(frozen=True)
class Group:
    """One generic form on one axis: ``form`` (its id), ``axis`` (0-based, the variable's axis),
    ``order`` (harmonic; 0 when none), ``columns`` (n, k) and ``shift`` (``channel_delay``: the
    delay, s)."""

    form: str
    axis: int
    order: int
    columns: np.ndarray
    shift: float = 0.0

    @property
    def key(self) -> str:
        """A short label, e.g. ``arm_periodic(q2, 3)``."""
        return f"{self.form}({axis_numbers.number(self.axis)}{', ' + str(self.order) if self.order else ''})"


def groups(t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, tau: np.ndarray, model: np.ndarray,
           gear_ratio: np.ndarray, axis: int, fit: np.ndarray, drift: bool = True) -> list[Group]:
    """The generic candidate library of ``axis`` (0-based): module docstring. Arrays (n, N):
    angles rad, speeds rad/s, accelerations rad/s^2, measured and model torque N m; ``t`` (n,) s;
    ``gear_ratio`` (N,); ``fit`` (n,) bool: the samples the delay is searched on; ``drift``: with the
    drifts in time (False: the library the search's guard weighs effects against, whose warm-up
    effect is a drift in time itself)."""
    a = axis
    x, v = q[:, a], qd[:, a]
    s = np.sign(v)
    found = [Group("arm_periodic", a, k, np.column_stack([np.sin(k * x), np.cos(k * x)]))
             for k in range(1, ARM_HARMONICS + 1)]
    motor = gear_ratio[a] * x
    found += [Group("motor_periodic", a, k, np.column_stack([np.sin(k * motor), np.cos(k * motor)]))
              for k in range(1, MOTOR_HARMONICS + 1)]
    found += [Group("speed", a, 0, v[:, None]), Group("dry", a, 0, s[:, None]),
              Group("speed_squared", a, 0, (v * np.abs(v))[:, None]), Group("speed_cubed", a, 0, (v**3)[:, None])]
    found += [Group("position_friction", a, k, np.column_stack([s, s * np.sin(k * x), s * np.cos(k * x)]))
              for k in range(1, FRICTION_HARMONICS + 1)]
    if drift:
        hours = (t - t[0]) / 3600.0
        found += [Group("speed_drift", a, 0, (v * hours)[:, None]), Group("dry_drift", a, 0, (s * hours)[:, None])]
    m, y = model[:, a], tau[:, a] - model[:, a]
    d = delay(t, m, y, fit)
    found += [Group("channel_delay", a, 0, (np.interp(t - d, t, m) - m)[:, None], d),
              Group("acceleration", a, 0, qdd[:, a][:, None]), Group("gain", a, 0, tau[:, a][:, None])]
    for b in range(q.shape[1]):
        if b != a:
            found += [Group("cross_speed", b, 0, qd[:, b][:, None]), Group("cross_acceleration", b, 0, qdd[:, b][:, None])]
    return found


def delay(t: np.ndarray, model: np.ndarray, y: np.ndarray, rows: np.ndarray) -> float:
    """The shift ``d`` (s, within :data:`MAX_DELAY`) for which ``model(t - d) - model(t)`` (with an
    intercept, at unit gain: a free gain trades against the shift where the first-order term holds)
    fits ``y`` best on ``rows``: whole samples, then a parabola through the best and its neighbours
    (Jacovitti & Scarano 1993; :func:`faultgen.calibrate.delay.peak`)."""
    dt = float(np.median(np.diff(t)))
    most = max(1, min(int(round(MAX_DELAY / dt)), int(rows.sum()) // 4))
    index = np.flatnonzero(rows)
    index = index[(index >= most) & (index < len(t) - most)]
    if index.size < 10:
        return 0.0
    target = y[index] - y[index].mean()
    sse = []
    for k in range(-most, most + 1):
        c = model[index - k] - model[index]
        sse.append(float(np.sum((target - (c - c.mean())) ** 2)))
    return peak(-np.array(sse)) * dt  # the least squared error, between samples


def _ols(design: np.ndarray, y: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Least squares with an intercept (its coefficient last)."""
    full = np.column_stack([design[rows], np.ones(int(rows.sum()))])
    return np.linalg.lstsq(full, y[rows], rcond=None)[0]


def _predict(design: np.ndarray, theta: np.ndarray) -> np.ndarray:
    return design @ theta[:-1] + theta[-1]


def best_single(candidates: list[Group], y: np.ndarray, fit: np.ndarray, held: np.ndarray, scale: float
                ) -> tuple[Group | None, float, np.ndarray | None]:
    """The generic group that alone (no intercept: a constant is the library's torque offset, and
    an intercept in every generic fit would let any group take an offset's share too; fitted on
    ``fit``) lowers the held-out nrmse of the remainder ``y`` (n,) most, that drop (nrmse: RMS over
    ``scale``, the axis's measured torque RMS, N m) and its coefficients. (None, 0.0, None) when no
    group lowers it."""
    if not held.any() or not fit.any():
        return None, 0.0, None
    before = float(np.sqrt(np.mean(y[held] ** 2)))
    best, best_gain, best_theta = None, 0.0, None
    for g in candidates:
        theta = np.linalg.lstsq(g.columns[fit], y[fit], rcond=None)[0]
        after = float(np.sqrt(np.mean((y[held] - g.columns[held] @ theta) ** 2)))
        gain = (before - after) / scale
        if gain > best_gain:
            best, best_gain, best_theta = g, gain, theta
    return best, best_gain, best_theta


def _thinned(rows: np.ndarray, most: int) -> np.ndarray:
    index = np.flatnonzero(rows)
    return index[:: max(1, -(-index.size // most))]


def _lasso_groups(candidates: list[Group], y: np.ndarray, fit: np.ndarray) -> list[int]:
    """The groups with a nonzero lasso coefficient (LassoCV, blocked 5-fold CV on the fitting part)."""
    design = np.column_stack([g.columns for g in candidates])
    owner = np.concatenate([[k] * g.columns.shape[1] for k, g in enumerate(candidates)])
    rows = _thinned(fit, LASSO_ROWS)
    x = design[rows]
    spread = x.std(axis=0)
    usable = spread > 0
    x = (x[:, usable] - x[:, usable].mean(axis=0)) / spread[usable]
    with warnings.catch_warnings():  # a path's smallest penalties may stop short: the CV picks a larger one
        warnings.simplefilter("ignore", ConvergenceWarning)
        lasso = LassoCV(cv=KFold(5, shuffle=False), alphas=30, max_iter=3000).fit(x, y[rows])
    chosen = owner[usable][np.abs(lasso.coef_) > 0]
    return sorted(set(int(k) for k in chosen))


def _forward(candidates: list[Group], pool: list[int], y: np.ndarray, fit: np.ndarray, held: np.ndarray,
             start: list[int] = ()) -> list[int]:
    """Forward selection over the groups of ``pool`` by held-out mean square (least squares on the
    fitting part), while each closes :data:`MIN_SHARE` of the held-out mean square remainder,
    after the groups of ``start`` (taken first, whatever they close)."""
    total = float(np.mean(y[held] ** 2))
    chosen = list(start)
    current = total
    if chosen:
        design = np.column_stack([candidates[j].columns for j in chosen])
        current = float(np.mean((y[held] - _predict(design[held], _ols(design, y, fit))) ** 2))
    while pool and len(chosen) < MAX_TERMS:
        trials = []
        for k in pool:
            design = np.column_stack([candidates[j].columns for j in (*chosen, k)])
            theta = _ols(design, y, fit)
            trials.append((float(np.mean((y[held] - _predict(design[held], theta)) ** 2)), k))
        after, k = min(trials)
        if current - after < MIN_SHARE * total:
            break
        chosen.append(k)
        pool = [j for j in pool if j != k]
        current = after
    return chosen


def explain(t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, tau: np.ndarray, model: np.ndarray,
            gear_ratio: np.ndarray, fit: np.ndarray, held: np.ndarray, axis: int,
            log_delay: tuple[float, list[float]] | None = None) -> dict:
    """What the remainder ``tau - model`` of ``axis`` (0-based) follows (module docstring).

    Parameters
    ----------
    t : ndarray (n,), s; q, qd, qdd, tau, model : ndarray (n, N)
        The log (rad, rad/s, rad/s^2, measured torque N m) and the model's torque (N m).
    gear_ratio : ndarray (N,)
    fit, held : ndarray of bool (n, N)
        The fitting and held-out samples (:class:`faultgen.calibrate.search.Split`).
    log_delay : (float, [float, float]) or None
        A delay of the log's torque channels, s, and its interval (:func:`faultgen.calibrate.delay.shown`):
        the ``channel_delay`` term at that shift is the first term, whatever its share (a property of
        the log's channels, not of this axis), with the log's value and interval.

    Returns
    -------
    dict
        ``axis`` (1..N), ``terms`` (in the order added, each: ``form``, ``variable_axis``, ``order``,
        ``words``, ``share`` and ``share_interval`` of the held-out mean square remainder it closes,
        ``value``, ``interval`` and ``unit`` of its size), ``explained_share`` (all named terms
        together, with ``explained_interval``), ``nrmse_before`` and ``nrmse_after`` (held out), and
        ``method``.
    """
    fit, held = fit[:, axis], held[:, axis]
    y = tau[:, axis] - model[:, axis]
    candidates = groups(t, q, qd, qdd, tau, model, gear_ratio, axis, fit)
    scale = float(np.sqrt(np.mean(tau[held, axis] ** 2))) if held.any() else 1.0
    record = {"axis": axis_numbers.number(axis), "terms": [], "explained_share": 0.0,
              "explained_interval": [0.0, 0.0], "method": (
                  "LassoCV (scikit-learn; blocked 5-fold CV) over the generic library, then forward selection "
                  f"on the held-out part (each term closing >= {MIN_SHARE:.0%}); shares: block bootstrap of the "
                  "held-out part, 95 %; sizes: delete-one-block jackknife, 95 %")}
    if fit.sum() < 50 or held.sum() < 50:
        return record
    candidates, start = _with_delay(candidates, t, model[:, axis], axis, log_delay)
    selected = _lasso_groups(candidates, y, fit)
    # a selected form brings its other harmonics: the lasso picks among collinear harmonics poorly
    forms = {(candidates[k].form, candidates[k].axis) for k in selected}
    pool = [k for k, g in enumerate(candidates)
            if k not in start and (k in selected or ((g.form, g.axis) in forms and g.order))]
    chosen = _forward(candidates, pool, y, fit, held, start)
    design = np.column_stack([candidates[k].columns for k in chosen]) if chosen else np.zeros((len(y), 0))
    widths = np.cumsum([0] + [candidates[k].columns.shape[1] for k in chosen])
    theta = _ols(design, y, fit)
    shares, intervals, total_interval = _shares(candidates, chosen, y, fit, held)
    replicates = _jackknife(design, y, fit)
    factor = float(student_t.ppf(0.975, JACKKNIFE_BLOCKS - 1))
    for j, k in enumerate(chosen):
        g = candidates[k]
        value, unit = size(g, theta[widths[j]: widths[j + 1]])
        if k in start:  # the log's delay: its own interval
            interval = [float(v) for v in log_delay[1]]
        else:
            if g.form == "channel_delay":  # the shift searched again on each replicate's samples
                spread = [delay(t, model[:, axis], y, keep) for keep in _blocks_left_out(fit)]
            else:
                spread = [size(g, r[widths[j]: widths[j + 1]])[0] for r in replicates]
            se = float(np.sqrt((len(spread) - 1) / len(spread) * np.sum((np.array(spread) - np.mean(spread)) ** 2)))
            interval = [value - factor * se, value + factor * se]
        resolved = _resolved(candidates, chosen, j, y, fit, held)
        text = words(g, axis, value, interval, unit)
        if not resolved:  # the period is not told apart by the log: the size as an RMS, the range said
            part = design[held][:, widths[j]: widths[j + 1]] @ theta[widths[j]: widths[j + 1]]
            spread = float(np.ptp(q[fit | held, g.axis]))
            text = (f"{FORM_WORDS[g.form]} of axis {axis_numbers.number(g.axis)}, period not resolved: the log covers "
                    f"{spread:.2f} rad of it ({g.order} per revolution fits best, others alike), "
                    f"{float(np.sqrt(np.mean(part**2))):.3g} N m RMS")
        record["terms"].append({"form": g.form, "variable_axis": axis_numbers.number(g.axis), "order": g.order,
                                "order_resolved": resolved, "words": text, "share": shares[j],
                                "share_interval": intervals[j], "value": value, "interval": interval, "unit": unit})
    after = y[held] - _predict(design[held], theta)
    record.update(explained_share=float(sum(shares)), explained_interval=total_interval,
                  nrmse_before=float(np.sqrt(np.mean(y[held] ** 2)) / scale),
                  nrmse_after=float(np.sqrt(np.mean(after**2)) / scale))
    return record


def _with_delay(candidates: list[Group], t: np.ndarray, model: np.ndarray, axis: int, found) -> tuple[list[Group], list[int]]:
    """``candidates`` with the log's channel delay ``found`` ((s, interval) or None) in place of the
    shift searched on this axis alone (``model`` (n,): the axis's model torque, N m), and the index
    of that group, to be taken first (empty when ``found`` is None)."""
    if found is None:
        return candidates, []
    kept = [g for g in candidates if g.form != "channel_delay"]
    kept.append(Group("channel_delay", axis, 0, (np.interp(t - found[0], t, model) - model)[:, None], found[0]))
    return kept, [len(kept) - 1]


#: The periodic forms, in words, for a period the log does not resolve.
FORM_WORDS = {"arm_periodic": "periodic in the arm angle", "motor_periodic": "periodic in the motor angle",
              "position_friction": "friction varying with the arm angle"}
#: A harmonic is resolved when every other harmonic of its form, in its place, closes less than
#: this share of what it closes on the held-out part.
RESOLVED = 0.9


def _resolved(candidates, chosen, j, y, fit, held) -> bool:
    """Whether the harmonic of the ``j``-th chosen group is told apart from its form's others
    (:data:`RESOLVED`); True for a form without harmonics."""
    g = candidates[chosen[j]]
    if not g.order:
        return True

    def closes(k):
        design = np.column_stack([candidates[i].columns for i in (*chosen[:j], k)])
        theta = _ols(design, y, fit)
        base = np.column_stack([candidates[i].columns for i in chosen[:j]]) if j else np.zeros((len(y), 0))
        before = y[held] - _predict(base[held], _ols(base, y, fit))
        return float(np.mean(before**2) - np.mean((y[held] - _predict(design[held], theta)) ** 2))

    own = closes(chosen[j])
    others = [closes(k) for k, h in enumerate(candidates)
              if h.form == g.form and h.axis == g.axis and h.order and k != chosen[j]]
    return not others or max(others) < RESOLVED * own


def _shares(candidates, chosen, y, fit, held):
    """Each chosen group's share of the held-out mean square remainder (in the order added), its
    95 % block-bootstrap interval, and the interval of all of them together."""
    index = np.flatnonzero(held)
    blocks = np.array_split(np.arange(index.size), min(HELD_BLOCKS, index.size))
    sse = np.zeros((len(chosen) + 1, len(blocks)))  # per stage (none, first, first two, ...) per block
    sse[0] = [np.sum(y[index[b]] ** 2) for b in blocks]
    for stage in range(1, len(chosen) + 1):
        design = np.column_stack([candidates[k].columns for k in chosen[:stage]])
        theta = _ols(design, y, fit)
        r = y[index] - _predict(design[index], theta)
        sse[stage] = [np.sum(r[b] ** 2) for b in blocks]
    point = (sse[:-1].sum(axis=1) - sse[1:].sum(axis=1)) / sse[0].sum()
    rng = np.random.default_rng(0)  # the same log gives the same intervals
    draws = rng.integers(0, len(blocks), size=(BOOTSTRAP, len(blocks)))
    resampled = sse[:, draws].sum(axis=2)  # (stages, draws)
    parts = (resampled[:-1] - resampled[1:]) / resampled[0]
    together = (resampled[0] - resampled[-1]) / resampled[0]
    intervals = [[float(v) for v in np.percentile(p, [2.5, 97.5])] for p in parts]
    return [float(p) for p in point], intervals, [float(v) for v in np.percentile(together, [2.5, 97.5])]


def _blocks_left_out(fit: np.ndarray) -> list[np.ndarray]:
    """The fitting samples with each of :data:`JACKKNIFE_BLOCKS` contiguous blocks left out in turn."""
    kept = []
    for block in np.array_split(np.flatnonzero(fit), JACKKNIFE_BLOCKS):
        keep = fit.copy()
        keep[block] = False
        kept.append(keep)
    return kept


def _jackknife(design: np.ndarray, y: np.ndarray, fit: np.ndarray) -> list[np.ndarray]:
    return [_ols(design, y, keep) for keep in _blocks_left_out(fit)]


def size(group: Group, theta: np.ndarray) -> tuple[float, str]:
    """A group's size from its fitted coefficients ``theta`` and its unit: the amplitude of a
    periodic term (N m), a coefficient, the delay (s, positive: the torque logged late) or the gain
    (measured over model torque, 1)."""
    if group.form in ("arm_periodic", "motor_periodic"):
        return float(np.hypot(*theta)), "N m"
    if group.form == "position_friction":
        return float(np.hypot(*theta[1:])), "N m"
    if group.form == "channel_delay":
        return float(group.shift), "s"
    if group.form == "gain":
        return float(1.0 / (1.0 - theta[0])) if theta[0] < 1 else float("inf"), "1"
    units = {"speed": "N m s/rad", "dry": "N m", "speed_squared": "N m s^2/rad^2", "speed_cubed": "N m s^3/rad^3",
             "acceleration": "kg m^2", "cross_speed": "N m s/rad", "cross_acceleration": "kg m^2",
             "speed_drift": "N m s/rad per h", "dry_drift": "N m per h"}
    return float(theta[0]), units[group.form]


def words(group: Group, axis: int, value: float, interval: list[float] | None, unit: str) -> str:
    """The term in words a user can act on, e.g. ``periodic in the arm angle of axis 2, 3 per
    revolution, 1.9 N m (1.7 .. 2.1)`` (``interval``: its 95 % interval, or None)."""
    a, b = axis_numbers.number(axis), axis_numbers.number(group.axis)
    interval = interval or [value, value]
    span = f"({interval[0]:.3g} .. {interval[1]:.3g})" if interval[0] != interval[1] else ""
    form = group.form
    if form == "arm_periodic":
        text = f"periodic in the arm angle of axis {b}, {group.order} per revolution, {value:.3g} N m"
    elif form == "motor_periodic":
        text = f"periodic in the motor angle of axis {b}, {group.order} per motor revolution, {value:.3g} N m"
    elif form == "position_friction":
        text = f"friction of axis {b} varying with its arm angle, {group.order} per revolution, +-{value:.3g} N m"
    elif form == "channel_delay":
        text = f"the torque {'lags' if value >= 0 else 'leads'} the motion by {1e3 * abs(value):.1f} ms"
        span = f"({1e3 * interval[0]:+.1f} .. {1e3 * interval[1]:+.1f} ms)" if span else ""
    elif form == "gain":
        text = (f"axis {a}'s torque {100 * abs(value - 1):.1f} % {'above' if value >= 1 else 'below'} the model at "
                f"every load, gain {value:.4g}")
        span = f"({interval[0]:.4g} .. {interval[1]:.4g})" if span else ""
    else:
        text = {"speed": f"proportional to the speed of axis {b}", "dry": f"a step with the direction of axis {b}",
                "speed_squared": f"grows with the speed squared on axis {b}",
                "speed_cubed": f"grows with the speed cubed on axis {b}",
                "speed_drift": f"viscous friction of axis {b} drifting in time (as with the oil's temperature)",
                "dry_drift": f"dry friction of axis {b} drifting in time (as with the oil's temperature)",
                "acceleration": f"follows the acceleration of axis {b} (an inertia the model lacks)",
                "cross_speed": f"follows the speed of axis {b} (cross-axis coupling)",
                "cross_acceleration": f"follows the acceleration of axis {b} (cross-axis coupling)"}[form]
        text += f", {value:.3g} {unit}"
    return f"{text} {span}".rstrip()


def line(found: dict) -> str:
    """One console line for the terms :func:`explain` named on an unexplained axis."""
    terms = found.get("terms") or []
    if not terms:
        return f"   axis {found['axis']}: no term of the generic library explains it"
    parts = [f"{t['words']}: {100 * t['share']:.0f} % of the remaining gap ({100 * t['share_interval'][0]:.0f} .. "
             f"{100 * t['share_interval'][1]:.0f} %)" for t in terms]
    return f"   axis {found['axis']} follows: " + "; ".join(parts)
