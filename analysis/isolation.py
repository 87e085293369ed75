"""Isolation of the source axis of wear from per-cycle signals of all axes (thesis ch. 3.4.2, 6.2.2).

Every isolator is a scikit-learn estimator: ``fit(X)`` takes an ``ndarray of shape (n_cycles,
n_axes)``, one per-cycle signal per axis (typically the mean absolute motor torque of each cycle),
and sets ``scores_`` (larger = more likely the source) and ``source_axis_`` (1-based axis number,
0 when the isolator cannot decide). :data:`ISOLATORS` maps names to classes; :func:`register`
adds one and :func:`make` builds one by name.
"""

from __future__ import annotations

import numbers

import numpy as np
from scipy import signal
from sklearn.base import BaseEstimator
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_array

from analysis.monitoring import reconstruction_contributions
from faultgen import axes
from faultgen.checks import is_whole

#: Isolator classes by name, for :func:`make`; extend with :func:`register`.
ISOLATORS: dict[str, type] = {}

_MAX_STATES = 1 << 22  # cells of the (future, target past, source past) histogram per pair


def register(name: str):
    """Class decorator adding an isolator class to :data:`ISOLATORS` under ``name``.

    Raises
    ------
    ValueError
        If ``name`` is already registered to another class.
    """

    def add(cls: type) -> type:
        if ISOLATORS.get(name, cls) is not cls:
            raise ValueError(f"isolator {name!r} is already registered to {ISOLATORS[name].__name__}")
        ISOLATORS[name] = cls
        return cls

    return add


def make(name: str, **params) -> BaseEstimator:
    """Return a new isolator ``ISOLATORS[name](**params)``.

    Raises
    ------
    ValueError
        If ``name`` is not in :data:`ISOLATORS`; the message lists the known names.
    """
    if name not in ISOLATORS:
        raise ValueError(f"unknown isolator {name!r}; expected one of: {', '.join(sorted(ISOLATORS))}")
    return ISOLATORS[name](**params)


def min_rows(isolator, n_rows: int = 1_000_000) -> int | None:
    """Fewest cycles (rows of ``X``) ``isolator`` fits on: what an :class:`Isolator` needs; None for
    another estimator (a plugin), whose need is unknown until it fails. ``n_rows`` is the length
    asked about, for isolators whose need depends on it (none of the registered ones). Raises
    ValueError for invalid parameters, as ``fit`` would."""
    return int(isolator._min_rows(n_rows)) if isinstance(isolator, Isolator) else None


def _integer(owner: str, name: str, value, low: int) -> int:
    if not is_whole(value, low):
        raise ValueError(f"{owner}: {name} = {value!r}, expected an integer >= {low}")
    return int(value)


def _pick(scores: np.ndarray) -> int:
    """1-based axis of the unique largest score; 0 on a tie (to 1e-9 relative) or a NaN score."""
    if np.isnan(scores).any():
        return 0
    best = np.flatnonzero((scores == scores.max()) | np.isclose(scores, scores.max(), rtol=1e-9, atol=1e-12))
    return axes.number(best[0]) if best.size == 1 else 0


class Isolator(BaseEstimator):
    """Base class: validation of ``X`` and the choice of the source axis from ``scores_``.

    Subclasses implement ``_min_rows(n_rows)`` (after checking their parameters, raising
    ValueError naming a bad one) and ``_scores(X)`` returning an ``ndarray of shape (n_axes,)``.
    """

    def fit(self, X, y=None):
        """Score every axis as the source of a fault.

        Parameters
        ----------
        X : array-like of shape (n_cycles, n_axes)
            One per-cycle signal per axis, finite, n_axes >= 2; columns are axes 1, 2, ...
        y : None
            Ignored.

        Returns
        -------
        self

        Raises
        ------
        ValueError
            If a parameter is invalid, ``X`` is not 2-D with >= 2 columns, has a NaN or an
            infinity, or has fewer rows than the isolator needs (the message gives both).
        """
        X = check_array(X, dtype=np.float64, ensure_min_features=2, ensure_min_samples=1)
        need = self._min_rows(X.shape[0])
        if X.shape[0] < need:
            raise ValueError(
                f"{self!r}: X has n_samples = {X.shape[0]} rows (cycles), at least {need} needed"
            )
        self.n_features_in_ = X.shape[1]
        self.scores_ = np.asarray(self._scores(X), dtype=np.float64)
        self.source_axis_ = self._source_axis()
        return self

    def _source_axis(self) -> int:
        return _pick(self.scores_)


# --- transfer entropy (thesis ch. 6.2.2) ---------------------------------------------------------


def symbolise(x, bins: int) -> np.ndarray:
    """Quantile symbolisation of one series into ``bins`` symbols ``0 .. bins-1`` (thesis ch. 6.2.2).

    Bin bounds are ``q_k = np.quantile(x, k / bins, method="median_unbiased")`` for
    k = 1 .. bins-1 (R's quantile type 8, as RTransferEntropy's ``code_sample``), and
    ``np.searchsorted(q, x, side="left")`` gives symbol ``s`` to ``q_s < x <= q_{s+1}``: a value
    equal to a bound goes to the lower bin, as in the thesis's ``q_{k-1} < X <= q_k`` (its symbol
    k is our k - 1). Tied values share a symbol, so heavily tied data may leave symbols unused;
    a constant series is all 0.

    Parameters
    ----------
    x : array-like of shape (n,)
        Finite values.
    bins : int
        Number of symbols, >= 2.

    Returns
    -------
    ndarray of shape (n,), dtype intp

    Raises
    ------
    ValueError
        If ``bins`` is not an integer >= 2 or ``x`` is not 1-D and finite.
    """
    bins = _integer("symbolise", "bins", bins, 2)
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 1 or not np.isfinite(x).all():
        raise ValueError(f"symbolise: x must be a finite 1-D series, got shape {x.shape}")
    edges = np.quantile(x, np.arange(1, bins) / bins, method="median_unbiased")
    return np.searchsorted(edges, x, side="left")


def _past(s: np.ndarray, base: int, history: int) -> np.ndarray:
    """State index of ``s[t-history+1 .. t]`` for t = history-1 .. n-2, shape (..., n-history)."""
    n = s.shape[-1] - history
    state = s[..., :n].astype(np.int64)
    for h in range(1, history):
        state = state * base + s[..., h : h + n]
    return state


def _te_bits(c: np.ndarray) -> np.ndarray:
    """Eq. 6.4 summed over counts c[..., future, target past, source past], bits times samples."""
    c = c.astype(np.float64)
    c_fy = c.sum(axis=-1, keepdims=True)  # (future, target past)
    c_yx = c.sum(axis=-3, keepdims=True)  # (target past, source past)
    c_y = c_yx.sum(axis=-1, keepdims=True)  # target past
    ratio = np.ones_like(c)
    np.divide(c * c_y, c_fy * c_yx, out=ratio, where=c > 0)
    return (c * np.log2(ratio)).sum(axis=(-3, -2, -1))


def _check_states(base: int, history: int) -> int:
    n_past = base**history
    if base * n_past * n_past > _MAX_STATES:
        raise ValueError(
            f"history = {history} with {base} symbols gives {base}^{2 * history + 1} joint states, more "
            f"than {_MAX_STATES}; use fewer bins or a shorter history"
        )
    return n_past


def transfer_entropy(source, target, history: int = 1) -> float:
    """Transfer entropy T_{source -> target} in bits between two symbol sequences, thesis eq. 6.4.

    Both history lengths are ``history`` (thesis m = l; it uses 1): the sum runs over
    t = history-1 .. n-2 of the target's next symbol, the target's last ``history`` symbols
    and the source's last ``history`` symbols, with plug-in (frequency) probabilities.

    Parameters
    ----------
    source, target : array-like of int, shape (n,)
        Symbols (any integers; only equality matters), e.g. from :func:`symbolise`.
    history : int
        History length, >= 1.

    Returns
    -------
    float
        TE in bits, >= 0 up to rounding.

    Raises
    ------
    ValueError
        If the sequences are not 1-D integer sequences of the same length > ``history``, or the
        joint state space is too large to count.
    """
    history = _integer("transfer_entropy", "history", history, 1)
    source, target = np.asarray(source), np.asarray(target)
    if source.ndim != 1 or source.shape != target.shape or source.size <= history:
        raise ValueError(
            f"transfer_entropy: source and target must be 1-D of one length > history = {history}, "
            f"got shapes {source.shape} and {target.shape}"
        )
    if not (np.issubdtype(source.dtype, np.integer) and np.issubdtype(target.dtype, np.integer)):
        raise ValueError(f"transfer_entropy: symbols must be integers, got {source.dtype} and {target.dtype}")
    from analysis import te_counts  # numba: compiled loops, imported when first used

    source, target = np.ascontiguousarray(source, np.int64), np.ascontiguousarray(target, np.int64)  # one compiled form
    low, high = te_counts.value_range(source, target)
    if low >= 0 and (high + 1) ** (2 * history + 1) <= _MAX_STATES:
        src, tgt, base = source, target, int(high) + 1
    else:  # relabelling the symbols 0..b-1 changes no probability and shrinks the histogram
        _, codes = np.unique(np.concatenate([source, target]), return_inverse=True)
        src, tgt, base = codes[: source.size], codes[source.size :], int(codes.max()) + 1
    n_past = _check_states(base, history)  # the counts of _te_matrix, in one compiled pass
    counts = te_counts.joint_counts(src, tgt, base, history).reshape(1, base, n_past, n_past)
    return float(_te_bits(counts)[0] / (source.size - history))


def _te_matrix(sources: np.ndarray, targets: np.ndarray, base: int, history: int) -> np.ndarray:
    """T_{i->j} in bits from each row of ``sources`` (p_s, n) to each row of ``targets`` (p_t, n).

    Symbols are integers in 0 .. base-1. One np.bincount per target counts the joint states
    (future, target past, source past) of all sources at once, each source in its own block.
    """
    n_past = _check_states(base, history)
    cells = base * n_past * n_past
    n_src, n = sources.shape[0], sources.shape[1] - history
    source_past = _past(sources, base, history) + (np.arange(n_src, dtype=np.int64) * cells)[:, None]
    te = np.empty((n_src, targets.shape[0]))
    for j, (target, target_past) in enumerate(zip(targets, _past(targets, base, history))):
        future_past = (target[history:].astype(np.int64) * n_past + target_past) * n_past
        counts = np.bincount((source_past + future_past).ravel(), minlength=n_src * cells)
        te[:, j] = _te_bits(counts.reshape(n_src, base, n_past, n_past)) / n
    return te


@register("transfer_entropy")
class TransferEntropyIsolator(Isolator):
    """Source axis = largest summed net transfer entropy, thesis eq. 6.4-6.5 and ch. 6.4.

    Each column is symbolised with :func:`symbolise`; ``te_[i, j]`` = T_{i->j} (eq. 6.4, bits,
    both histories ``history``), ``net_te_ = te_ - te_.T`` (eq. 6.5) and
    ``scores_[i] = sum_j net_te_[i, j]``.

    Parameters
    ----------
    bins : int, default 10
        Number of quantile bins (symbols), >= 2; the thesis compares 5, 10 and 20.
    history : int, default 1
        History length m = l of source and target, >= 1.
    surrogates : int, default 0
        When > 0, effective TE (Marschinski & Kantz 2002, as RTransferEntropy): from each
        T_{i->j} subtract its mean over ``surrogates`` random permutations of the source series
        (one permutation of each column per surrogate), and compute ``p_values_``.
        RTransferEntropy draws with replacement; a permutation keeps the source's histogram exact.
    random_state : None, int or numpy.random.Generator/RandomState
        Seed of the surrogate permutations.

    Attributes
    ----------
    te_ : ndarray of shape (n_axes, n_axes)
        T_{i->j} in bits (row = source, column = target), diagonal 0.
    effective_te_ : ndarray of shape (n_axes, n_axes)
        ``te_`` minus the surrogate mean (equal to ``te_`` when ``surrogates == 0``).
    net_te_ : ndarray of shape (n_axes, n_axes)
        ``effective_te_ - effective_te_.T``, bits.
    p_values_ : ndarray of shape (n_axes, n_axes)
        ``(1 + #{surrogate TE >= T_{i->j}}) / (1 + surrogates)``, the permutation test's p-value
        (never 0); NaN when ``surrogates == 0``; diagonal NaN.
    scores_ : ndarray of shape (n_axes,)
        Summed net TE of each axis, bits.
    source_axis_ : int
        1-based axis of the largest score, 0 on a tie.
    """

    def __init__(self, bins=10, history=1, surrogates=0, random_state=None):
        self.bins = bins
        self.history = history
        self.surrogates = surrogates
        self.random_state = random_state

    def _min_rows(self, n_rows: int) -> int:
        name = type(self).__name__
        bins = _integer(name, "bins", self.bins, 2)
        history = _integer(name, "history", self.history, 1)
        _integer(name, "surrogates", self.surrogates, 0)
        _check_states(bins, history)
        return history + 2

    def _scores(self, X: np.ndarray) -> np.ndarray:
        symbols = np.stack([symbolise(column, self.bins) for column in X.T])  # (n_axes, n_cycles)
        p = X.shape[1]
        off = ~np.eye(p, dtype=bool)
        self.te_ = np.where(off, _te_matrix(symbols, symbols, self.bins, self.history), 0.0)
        self.p_values_ = np.full((p, p), np.nan)
        self.effective_te_ = self.te_.copy()
        if self.surrogates:
            rng = check_random_state(self.random_state)
            total, exceed = np.zeros((p, p)), np.zeros((p, p))
            for _ in range(self.surrogates):
                shuffled = np.stack([rng.permutation(s) for s in symbols])
                te = _te_matrix(shuffled, symbols, self.bins, self.history)
                total += te
                exceed += te >= self.te_ - 1e-12
            self.effective_te_ = self.te_ - total / self.surrogates
            self.p_values_[off] = ((1 + exceed) / (1 + self.surrogates))[off]
        np.fill_diagonal(self.effective_te_, 0.0)
        self.net_te_ = self.effective_te_ - self.effective_te_.T
        return self.net_te_.sum(axis=1)


# --- cross-correlation (thesis eq. 3.5-3.6, ch. 3.4.2) -------------------------------------------


@register("cross_correlation")
class CrossCorrelationIsolator(Isolator):
    """Source axis = the axis that leads every other axis in cross-correlation (thesis ch. 3.4.2).

    For each pair, R(dt) of thesis eq. 3.5-3.6 (cross-covariance over N with means removed,
    divided by the two population standard deviations) with ``tau^i = X[:, i]`` and
    ``tau^j = X[:, j]`` is evaluated for dt = -max_lag .. max_lag and dt* = argmax R (the signed
    maximum; among equal maxima the smallest |dt|, and 0 if +dt and -dt tie). By eq. 3.5 and the
    text below eq. 3.6, dt* > 0 means tau^j trails tau^i. Table 3.3 and ch. 6.4 instead report
    "lags" for which a leading signal is negative (MATLAB's ``xcorr(tau_i, tau_j)`` sign), so
    ``lag_[i, j] = -dt*``: negative when axis i leads axis j. Both statements say the same: the
    source leads. A constant column leads and trails nothing (its R is taken as 0).

    Parameters
    ----------
    max_lag : int or None, default None
        Largest |dt| in cycles, >= 1; None uses ``max(1, n_cycles // 4)``. Needs
        n_cycles >= max_lag + 2.
    allow_zero_lag : bool, default False
        False applies the thesis rule literally: the source has a negative lag to every other
        axis. True also accepts lag 0 to some axes as long as the axis leads at least one and
        trails none (Table 3.3's axis 1 has lag 0 to axis 5 yet is named the source).

    Attributes
    ----------
    lag_ : ndarray of shape (n_axes, n_axes), int
        Lag in cycles at maximum R, Table 3.3 sign: ``lag_[i, j] < 0`` when axis i leads axis j;
        antisymmetric, diagonal 0.
    max_lag_ : int
        The max_lag used.
    scores_ : ndarray of shape (n_axes,)
        Number of other axes each axis leads.
    source_axis_ : int
        1-based axis that leads all others (see ``allow_zero_lag``), else 0.
    """

    def __init__(self, max_lag=None, allow_zero_lag=False):
        self.max_lag = max_lag
        self.allow_zero_lag = allow_zero_lag

    def _min_rows(self, n_rows: int) -> int:
        if self.max_lag is None:
            return 3
        return _integer(type(self).__name__, "max_lag", self.max_lag, 1) + 2

    def _scores(self, X: np.ndarray) -> np.ndarray:
        n, p = X.shape
        self.max_lag_ = max(1, n // 4) if self.max_lag is None else int(self.max_lag)
        std = X.std(axis=0)
        Z = np.divide(X - X.mean(axis=0), std, out=np.zeros_like(X), where=std > 0)
        lags = signal.correlation_lags(n, n)
        keep = np.abs(lags) <= self.max_lag_
        lags = lags[keep]
        self.lag_ = np.zeros((p, p), dtype=int)
        for i in range(p):
            for j in range(i + 1, p):
                # correlate(b, a)[dt] = sum_t a_t b_{t+dt}: eq. 3.5 with tau^i = a, tau^j = b
                r = signal.correlate(Z[:, j], Z[:, i])[keep] / n
                best = lags[r >= r.max() - 1e-12]
                best = best[np.abs(best) == np.abs(best).min()]
                dt = int(best[0]) if best.size == 1 else 0  # +dt and -dt tie: no lead
                self.lag_[i, j], self.lag_[j, i] = -dt, dt
        return (self.lag_ < 0).sum(axis=1).astype(np.float64)

    def _source_axis(self) -> int:
        return source_from_lags(self.lag_, self.allow_zero_lag)


def source_from_lags(lag, allow_zero_lag: bool = False) -> int:
    """1-based axis with all negative lags (thesis ch. 3.4.2), 0 if none or several qualify.

    ``lag`` is an ``ndarray of shape (n_axes, n_axes)`` in Table 3.3's sign (``lag[i, j] < 0``:
    axis i leads axis j), e.g. ``CrossCorrelationIsolator.lag_``; the diagonal is ignored. With
    ``allow_zero_lag``, lag 0 is accepted too if the axis leads at least one other.
    """
    lag = np.asarray(lag)
    off = ~np.eye(lag.shape[0], dtype=bool)
    ok = ((lag < 0) | ~off).all(axis=1)
    if allow_zero_lag:
        ok = ((lag <= 0) | ~off).all(axis=1) & ((lag < 0) & off).any(axis=1)
    return axes.number(np.flatnonzero(ok)[0]) if ok.sum() == 1 else 0


# --- baselines an expert would compare against ---------------------------------------------------


@register("granger")
class GrangerIsolator(Isolator):
    """Source axis = largest summed net pairwise Granger F statistic (Granger 1969).

    ``f_[i, j]`` is statsmodels' ``ssr_ftest`` F statistic of "axis i Granger-causes axis j"
    (lags 1 .. maxlag of both series, with a constant); a pair with a constant column gets 0.
    ``scores_[i] = sum_j (f_[i, j] - f_[j, i])``, summed like net TE (thesis eq. 6.5).

    Parameters
    ----------
    maxlag : int, default 1
        Number of lags, >= 1; needs n_cycles >= 3 * maxlag + 2 (statsmodels' limit).

    Attributes
    ----------
    f_ : ndarray of shape (n_axes, n_axes)
        F statistics, row = cause, column = effect, diagonal 0.
    scores_ : ndarray of shape (n_axes,)
    source_axis_ : int
    """

    def __init__(self, maxlag=1):
        self.maxlag = maxlag

    def _min_rows(self, n_rows: int) -> int:
        return 3 * _integer(type(self).__name__, "maxlag", self.maxlag, 1) + 2

    def _scores(self, X: np.ndarray) -> np.ndarray:
        from statsmodels.tsa.stattools import grangercausalitytests

        p = X.shape[1]
        varies = np.ptp(X, axis=0) > 0
        self.f_ = np.zeros((p, p))
        for i in range(p):
            for j in range(p):
                if i != j and varies[i] and varies[j]:
                    result = grangercausalitytests(X[:, [j, i]], maxlag=[self.maxlag])
                    self.f_[i, j] = result[self.maxlag][0]["ssr_ftest"][0]
        return (self.f_ - self.f_.T).sum(axis=1)


@register("trend")
class TrendIsolator(Isolator):
    """Source axis = the axis whose signal drifts most against its own noise.

    Wear raises the worn axis's friction torque (thesis eq. 6.6), so its per-cycle signal should
    trend most. For each axis, ``scores_ = |b| / s``: b is the slope of an ordinary least-squares
    line over the cycle index 0 .. n-1 and s the standard deviation of its residuals (n - 2
    degrees of freedom), so the score is free of the axis's torque scale. A perfect line gives
    inf, a constant column 0. Needs n_cycles >= 3.

    Attributes
    ----------
    slope_ : ndarray of shape (n_axes,)
        OLS slope b, signal units per cycle.
    scores_ : ndarray of shape (n_axes,)
        |b| / s, 1 / cycle.
    source_axis_ : int
    """

    def _min_rows(self, n_rows: int) -> int:
        return 3

    def _scores(self, X: np.ndarray) -> np.ndarray:
        n = X.shape[0]
        t = np.arange(n) - (n - 1) / 2
        self.slope_ = t @ (X - X.mean(axis=0)) / (t @ t)
        residual = X - X.mean(axis=0) - np.outer(t, self.slope_)
        s = np.sqrt((residual**2).sum(axis=0) / (n - 2))
        s[s <= 1e-12 * np.abs(X).max(axis=0)] = 0.0  # residual of a straight line is rounding error
        return np.divide(np.abs(self.slope_), s, out=np.where(self.slope_ != 0, np.inf, 0.0), where=s > 0)


@register("pca_contribution")
class PCAContributionIsolator(Isolator):
    """Source axis = largest reconstruction-based contribution to the PCA residual Q (thesis eq.
    3.3-3.4; Alcala and Qin, Automatica 45 (2009) 1593-1600).

    The first ``n_reference`` cycles (normal operation) are standardised (their mean and
    standard deviation; a constant column is scaled by 1) and decomposed by SVD; the first m
    components explaining >= ``variance`` of their variance are kept, m at most n_axes - 2
    (:func:`kept_components`), so that a residual space of at least two directions remains. For
    the later cycles, E = Z (I - P_m P_m^T) and ``scores_[i] = mean over
    cycles of E[:, i]**2 / (1 - sum_j P[j, i]**2)``: how much Q falls when axis i is
    reconstructed (:func:`analysis.monitoring.reconstruction_contributions`). Axis i's share of Q,
    ``E[:, i]**2`` alone, smears a fault over the axes correlated with it. With one residual
    direction every axis's score would be the whole Q, a tie by construction: on six weakly
    correlated per-cycle signals 90 % of the variance needs five components, and before the cap
    (issue 88) the isolator named no axis on any run of the first-look preset.

    Parameters
    ----------
    n_reference : int, default 20
        Reference cycles, >= 2; needs n_cycles >= n_reference + 1.
    variance : float, default 0.9
        Fraction of reference variance to keep, in (0, 1]; the thesis uses 0.75 in ch. 3.2.2.

    Attributes
    ----------
    mean_, scale_ : ndarray of shape (n_axes,)
        Reference mean and standard deviation used to standardise.
    components_ : ndarray of shape (n_components_, n_axes)
        Principal directions P_m^T.
    n_components_ : int
    scores_ : ndarray of shape (n_axes,)
        Mean reconstruction-based contribution to Q per axis over cycles n_reference+1 .. n.
    source_axis_ : int
    """

    def __init__(self, n_reference=20, variance=0.9):
        self.n_reference = n_reference
        self.variance = variance

    def _min_rows(self, n_rows: int) -> int:
        name = type(self).__name__
        if not (isinstance(self.variance, numbers.Real) and 0 < self.variance <= 1):
            raise ValueError(f"{name}: variance = {self.variance!r}, expected a fraction in (0, 1]")
        return _integer(name, "n_reference", self.n_reference, 2) + 1

    def _scores(self, X: np.ndarray) -> np.ndarray:
        reference = X[: self.n_reference]
        self.mean_ = reference.mean(axis=0)
        std = reference.std(axis=0, ddof=1)
        self.scale_ = np.where(std > 0, std, 1.0)
        _, sv, vt = np.linalg.svd((reference - self.mean_) / self.scale_, full_matrices=False)
        self.n_components_ = kept_components(sv, self.variance, X.shape[1])
        self.components_ = vt[: self.n_components_]
        Z = (X[self.n_reference :] - self.mean_) / self.scale_
        residual_projector = np.eye(X.shape[1]) - self.components_.T @ self.components_
        return reconstruction_contributions(Z, residual_projector).mean(axis=0)


def kept_components(singular_values, variance: float, n_axes: int) -> int:
    """Principal components a PCA-contribution isolator keeps: the fewest whose share of the
    variance (``singular_values`` squared) reaches ``variance``, at most ``n_axes - 2`` (none for
    two axes). Reconstruction-based contributions to Q need a residual space of two directions or
    more to rank axes: in one, every axis's contribution is the whole Q (a tie)."""
    power = np.asarray(singular_values, dtype=float) ** 2
    explained = np.cumsum(power) / max(power.sum(), np.finfo(float).tiny)
    return min(int(np.searchsorted(explained, variance - 1e-12) + 1), max(n_axes - 2, 0))


def signature_scores(residual, signatures) -> np.ndarray:
    """Match a residual against each axis's fault signature (directional residuals: Gertler,
    *Fault Detection and Diagnosis in Engineering Systems*, 1998, ch. 8): axis i scores the
    projection of the residual on its signature's unit vector, ``r . s_i / |s_i|``, so a fault of
    axis i of any size scores highest on axis i when the signatures differ in direction. A fault
    raising the signature's features scores positive, one lowering them negative.

    Parameters
    ----------
    residual : array-like of shape (n_features,) or (n_samples, n_features)
        Standardised residuals (the features minus their expectation, over their noise).
    signatures : array-like of shape (n_axes, n_features)
        How each axis's fault moves the features (same units as ``residual``, per unit of fault).

    Returns
    -------
    ndarray of shape (n_axes,) or (n_samples, n_axes)

    Raises
    ------
    ValueError
        If the numbers of features differ, or a signature is zero or not finite (naming the axis).
    """
    r = np.asarray(residual, dtype=float)
    s = np.asarray(signatures, dtype=float)
    if s.ndim != 2 or r.shape[-1] != s.shape[1]:
        raise ValueError(f"residual has {r.shape[-1]} features, signatures shape {s.shape}; expected (n_axes, "
                         f"{r.shape[-1]})")
    norm = np.linalg.norm(s, axis=1)
    bad = np.flatnonzero(~np.isfinite(norm) | (norm == 0))
    if bad.size:
        raise ValueError(f"the signature of axis {int(bad[0]) + 1} is zero or not finite: the fault does not move "
                         "the features, so it cannot be isolated from them")
    return r @ (s / norm[:, None]).T
