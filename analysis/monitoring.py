"""PCA monitoring with Hotelling's T2 and the Q statistic (SPE), thesis ch. 2.3.3, 3.2.2, 3.4.1.

:class:`PCAMonitor` learns normal operation from features (one row per sample, e.g. the KL
divergences of :class:`analysis.features.HistogramKL`), and flags samples whose T2 or Q exceeds
its ``1 - alpha`` limit; :func:`detect_onset` turns the alarms into the onset of a fault.

Notation: ``m`` training samples, ``n_features`` variables, ``k`` retained components. The thesis
uses ``m`` for both the number of samples (eq. 2.4) and the number of variables (eq. 2.6).
"""

from __future__ import annotations

import numpy as np
from scipy import stats
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted, validate_data

from faultgen.checks import is_whole

STATISTICS = ("q", "t2", "either")


class PCAMonitor(BaseEstimator):
    """PCA model of normal operation with T2 and Q control limits.

    Fit standardises each feature with the training mean and sample standard deviation
    (``ddof=1``), so the model is the eigen-decomposition of the training correlation matrix:
    features in different units (N m, bits) weigh equally. The first ``k`` components are kept,
    the fewest whose cumulative share of the variance is >= ``variance`` (thesis: 75 % in
    ch. 3.2.2, 85 % in ch. 2.3.3, 90 % in ch. 4.3.3 and 5.3.2), unless ``n_components`` is given.

    For a standardised sample ``z`` (row vector) with scores ``t = z P_k``:

    - ``T2 = t Lambda_k^-1 t^T`` (eq. 2.3), limit ``T2_alpha = k (m - 1) / (m - k)
      F_(1-alpha)(k, m - k)`` (Jackson 1991; MacGregor & Kourti 1995). The thesis prints eq. 2.4
      with ``F(k, m - 1; alpha)``; the prefactor ``k (m - 1) / (m - k)`` belongs to an F
      distribution with ``m - k`` denominator degrees of freedom, which is used here. The printed
      ``m - 1`` gives a lower limit (more false alarms) for small ``m``, e.g. m = 30, k = 5,
      alpha = 0.05: 14.76 instead of 15.10 (equal to 4 digits for m in the thousands). The exact limit for a
      new sample has a further factor ``(m + 1) / m`` (Tracy, Young & Mason 1992), < 1 % for
      m > 100, left out as in the thesis.
    - ``Q = ||z - z P_k P_k^T||^2`` (eq. 2.5), limit of Jackson & Mudholkar (1979), eq. 2.6:
      ``Q_alpha = theta_1 [c_alpha h_0 sqrt(2 theta_2) / theta_1 + 1 + theta_2 h_0 (h_0 - 1) /
      theta_1^2]^(1 / h_0)`` with ``theta_i = sum_(j > k) lambda_j^i`` over the residual
      eigenvalues, ``h_0 = 1 - 2 theta_1 theta_3 / (3 theta_2^2)`` and ``c_alpha`` the standard
      normal quantile at ``1 - alpha``.

    Parameters
    ----------
    variance : float, default=0.85
        Share of the variance the kept components must explain, in (0, 1].
    alpha : float, default=0.05
        Significance level: the limits are the ``1 - alpha`` quantiles under normal operation.
    n_components : int or None, default=None
        Number of components ``k``, 1 <= k < n_features; overrides ``variance``.
    statistic : {"either", "q", "t2"}, default="either"
        What :meth:`predict` alarms on. With ``"either"`` the false-alarm rate is up to
        ``2 alpha`` (about ``2 alpha - alpha^2`` as T2 and Q are independent for Gaussian data).
    cv : int or None, default=None
        Folds for an out-of-sample Q limit. None: eq. 2.6 on the training eigenvalues (the
        thesis's). An integer ``f`` (2 <= f <= m): the training samples are cut into ``f``
        contiguous blocks (``sklearn.model_selection.KFold`` without shuffling); each block is
        projected on the model (same ``k``, own mean and scale) fitted on the other blocks, and
        ``theta_i`` of eq. 2.6 are the power sums of the eigenvalues of the covariance of those
        out-of-block residuals. The smallest eigenvalues of a sample covariance matrix
        underestimate the population's, so the in-sample limit alarms more often than ``alpha``
        on normal data the model did not learn: j2 with three seeds, each healthy run judged by
        a monitor fitted on the other two (6 features, k = 5, m = 200): 9.0 % alarms at alpha
        = 5 % in-sample, 6.7 / 6.6 / 6.2 / 5.9 % with 5 / 10 / 20 / 200 folds (docs/analysis.md).
        T2's limit is unchanged.

    Attributes
    ----------
    mean_, scale_ : ndarray of shape (n_features,)
        Training mean and standard deviation (``ddof=1``) of each feature, in its unit.
    eigenvalues_ : ndarray of shape (n_features,)
        All eigenvalues of the training correlation matrix, descending; the first
        ``n_components_`` are the model's, the rest the residual ones of eq. 2.6.
    components_ : ndarray of shape (n_components_, n_features)
        Kept eigenvectors ``P_k^T`` (rows), each with its largest loading positive.
    explained_variance_ratio_ : ndarray of shape (n_features,)
        ``eigenvalues_ / sum(eigenvalues_)``.
    n_components_ : int
        Components kept, ``k``.
    n_samples_fit_ : int
        Training samples, ``m``.
    t2_limit_, q_limit_ : float
        Control limits of T2 (eq. 2.4, F with ``m - k`` degrees of freedom) and Q (eq. 2.6).
    n_features_in_ : int
        Features seen in fit.

    Raises
    ------
    ValueError
        From :meth:`fit`: invalid parameters (naming the value), fewer than 2 samples or
        features, non-finite values, a constant feature (naming its index), ``variance`` that
        needs all components (no residual space for Q), ``k >= m``, or residual eigenvalues
        that are all zero. From the scoring methods: a number of features other than in fit.
    """

    def __init__(self, variance: float = 0.85, alpha: float = 0.05, n_components: int | None = None,
                 statistic: str = "either", cv: int | None = None):
        self.variance = variance
        self.alpha = alpha
        self.n_components = n_components
        self.statistic = statistic
        self.cv = cv

    def _check_params(self) -> None:
        if not 0 < self.variance <= 1:
            raise ValueError(f"variance = {self.variance!r}; expected a share in (0, 1]")
        if not 0 < self.alpha < 1:
            raise ValueError(f"alpha = {self.alpha!r}; expected a significance level in (0, 1)")
        if self.statistic not in STATISTICS:
            raise ValueError(f"statistic = {self.statistic!r}; expected one of {', '.join(STATISTICS)}")
        k = self.n_components
        if k is not None and not is_whole(k, 1):
            raise ValueError(f"n_components = {k!r}; expected None or an integer >= 1")
        f = self.cv
        if f is not None and not is_whole(f, 2):
            raise ValueError(f"cv = {f!r}; expected None (in-sample Q limit) or a number of folds >= 2")

    def fit(self, X, y=None):
        """Fit the model and limits on normal operation.

        Parameters
        ----------
        X : array-like of shape (m, n_features)
            Features under normal operation, one row per sample, m >= 2, n_features >= 2.
        y : ignored

        Returns
        -------
        self
        """
        self._check_params()
        X = validate_data(self, X, dtype=float, ensure_min_samples=2, ensure_min_features=2)
        m, n = X.shape
        mean, scale = X.mean(axis=0), X.std(axis=0, ddof=1)
        # A constant column has std 0 up to rounding of the mean (~1e-16 |mean|).
        constant = np.flatnonzero(scale <= 1e-10 * np.abs(mean))
        if constant.size:
            j = int(constant[0])
            raise ValueError(f"feature {j} is constant in the training data (mean {float(mean[j])!r}, std "
                             f"{float(scale[j])!r}) and cannot be standardised; drop it")
        Z = (X - mean) / scale
        eigenvalues, vectors = np.linalg.eigh(Z.T @ Z / (m - 1))
        eigenvalues, vectors = np.clip(eigenvalues[::-1], 0.0, None), vectors[:, ::-1]
        vectors *= np.where(vectors[np.abs(vectors).argmax(axis=0), range(n)] < 0, -1.0, 1.0)
        ratio = eigenvalues / eigenvalues.sum()
        if self.n_components is None:
            k = int(np.argmax(np.cumsum(ratio) >= self.variance - 1e-12)) + 1
            if k >= n:
                raise ValueError(f"variance = {self.variance!r} needs all {n} components, leaving no "
                                 "residual space for Q; lower it or set n_components")
        else:
            k = int(self.n_components)
            if k >= n:
                raise ValueError(f"n_components = {k} must be below n_features = {n} "
                                 "(Q needs a residual space)")
        if k >= m:
            raise ValueError(f"{k} components need more than {k} training samples, got {m}")
        residual = eigenvalues[k:] if self.cv is None else _out_of_fold_eigenvalues(X, k, self.cv)
        theta1, theta2, theta3 = (np.sum(residual**i) for i in (1, 2, 3))
        if theta2 <= 0:
            raise ValueError(f"the residual eigenvalues beyond component {k} are all zero (features exactly "
                             "collinear); the Q limit is undefined: use fewer components or features")
        self.mean_, self.scale_ = mean, scale
        self.eigenvalues_, self.explained_variance_ratio_ = eigenvalues, ratio
        self.components_, self.n_components_, self.n_samples_fit_ = vectors[:, :k].T.copy(), k, m
        self.residual_eigenvalues_ = residual
        self.t2_limit_, self.q_limit_ = self.limits(self.alpha)
        return self

    def limits(self, alpha: float) -> tuple[float, float]:
        """The T2 and Q limits (eqs. 2.4 and 2.6, as :meth:`fit` sets ``t2_limit_`` and ``q_limit_``)
        of the fitted model at another significance ``alpha``: the same components and residual
        eigenvalues, no second fit. ValueError for ``alpha`` outside (0, 1), or where the
        Jackson-Mudholkar approximation is undefined."""
        check_is_fitted(self, "residual_eigenvalues_")
        if not 0 < alpha < 1:
            raise ValueError(f"alpha = {alpha!r}; expected a significance level in (0, 1)")
        k, m = self.n_components_, self.n_samples_fit_
        theta1, theta2, theta3 = (np.sum(self.residual_eigenvalues_**i) for i in (1, 2, 3))
        return (float(k * (m - 1) / (m - k) * stats.f.ppf(1 - alpha, k, m - k)),
                _jackson_mudholkar(theta1, theta2, theta3, alpha))

    def _project(self, X) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Standardised X, scores and residuals of X of shape (n_samples, n_features)."""
        check_is_fitted(self, "q_limit_")
        X = validate_data(self, X, dtype=float, reset=False)
        Z = (X - self.mean_) / self.scale_
        T = Z @ self.components_.T
        return Z, T, Z - T @ self.components_

    def score_samples(self, X) -> tuple[np.ndarray, np.ndarray]:
        """T2 (eq. 2.3) and Q (eq. 2.5) of each sample.

        Parameters
        ----------
        X : array-like of shape (n_samples, n_features)

        Returns
        -------
        t2, q : ndarray of shape (n_samples,)
            Dimensionless (standardised features); compare with ``t2_limit_`` and ``q_limit_``.
            Unlike scikit-learn's outlier detectors, larger means more abnormal.
        """
        _, T, E = self._project(X)
        return np.sum(T**2 / self.eigenvalues_[: self.n_components_], axis=1), np.sum(E**2, axis=1)

    def predict(self, X) -> np.ndarray:
        """Alarms, ``ndarray of shape (n_samples,)`` of bool: the chosen ``statistic`` above its limit."""
        t2, q = self.score_samples(X)
        alarm = {"q": q > self.q_limit_, "t2": t2 > self.t2_limit_}
        return alarm[self.statistic] if self.statistic in alarm else alarm["q"] | alarm["t2"]

    def index_matrix(self, statistic: str = "q") -> np.ndarray:
        """The matrix ``M`` of the statistic as a quadratic form of the standardised sample ``z``,
        ``index = z M z^T``, ndarray of shape (n_features, n_features): for ``"q"`` the residual
        projector ``C~ = I - P_k P_k^T`` (eq. 2.5), for ``"t2"`` ``D = P_k Lambda_k^-1 P_k^T``
        (eq. 2.3); Alcala and Qin, Automatica 45 (2009) 1593-1600.

        Raises ``ValueError`` for another ``statistic``."""
        check_is_fitted(self, "q_limit_")
        if statistic not in ("q", "t2"):
            raise ValueError(f"statistic = {statistic!r}; expected 'q' or 't2'")
        P = self.components_.T
        if statistic == "q":
            return np.eye(P.shape[0]) - P @ P.T
        return (P / self.eigenvalues_[: self.n_components_]) @ P.T

    def _rbc_terms(self, statistic: str, groups) -> tuple:
        """``(M, groups, inverses)`` of :func:`reconstruction_contributions` for this fit: the index
        matrix and each group's ``(Xi^T M Xi)^+``, computed once per fit, statistic and groups (a
        monitor scoring one log at a time asked for the same pseudo-inverses on every log)."""
        key = (statistic, None if groups is None else tuple(tuple(g.tolist()) for g in groups))
        cache = self.__dict__.get("_rbc_cache")
        if cache is None or cache[0] is not self.components_:  # a new fit: new components
            cache = self.__dict__["_rbc_cache"] = (self.components_, {})
        if key not in cache[1]:
            M = self.index_matrix(statistic)
            cache[1][key] = (M, groups, None if groups is None else group_inverses(M, groups))
        return cache[1][key]

    def contributions(self, X, statistic: str = "q", method: str = "complete", groups=None) -> np.ndarray:
        """Contribution of each feature (or group of features) to Q or T2, for isolating the feature
        behind an alarm.

        ``method="complete"`` (complete decomposition, the thesis's): ``"q"`` the squared residuals
        ``e_j^2`` of the standardised sample, which sum to Q (the thesis's Q contribution plots show
        the residuals ``e_j`` with their sign); ``"t2"`` ``z P_k Lambda_k^(-1/2) P_k^T``, thesis eq.
        8 (ch. 2.3.3.2), signed; the sum of their squares is T2. Eq. 8 is printed with
        ``lambda^(1/2)``; the inverse square root is the form whose squares add up to T2
        (PLS_Toolbox ``tcon``, Wise & Gallagher 1996). A fault along one feature spreads into the
        residuals of the features correlated with it, so the largest complete contribution can be
        another feature's ("smearing").

        ``method="rbc"``: reconstruction-based contributions (Alcala and Qin, Automatica 45 (2009)
        1593-1600): the amount by which the statistic falls when the sample is
        reconstructed along feature ``i``, ``RBC_i = (xi_i^T M z)^2 / (xi_i^T M xi_i)`` with ``M``
        of :meth:`index_matrix` and ``xi_i`` the i-th unit vector; a fault of large enough size
        along one feature has its largest RBC on that feature. Non-negative; they do not sum to the
        statistic. A feature whose direction the statistic cannot see (``xi_i^T M xi_i`` below
        1e-12 of the largest diagonal entry) has RBC 0.

        Parameters
        ----------
        X : array-like of shape (n_samples, n_features)
        statistic : {"q", "t2"}, default="q"
        method : {"complete", "rbc"}, default="complete"
        groups : sequence of n_groups index sequences, or None
            Contributions of sets of features (e.g. one robot axis's features) instead of single
            ones. With ``"rbc"`` a group is reconstructed along all its features at once,
            ``z M Xi (Xi^T M Xi)^+ Xi^T M z^T`` (Alcala and Qin 2009, multidimensional
            faults; ``^+`` the pseudo-inverse); with ``"complete"`` the group's squared
            contributions are summed (``"t2"`` then also unsigned).

        Returns
        -------
        ndarray of shape (n_samples, n_features), or (n_samples, n_groups) with ``groups``

        Raises
        ------
        ValueError
            For another ``statistic`` or ``method``, a group that is empty or names a feature out of
            range, or a number of features other than in fit.
        """
        if statistic not in ("q", "t2"):
            raise ValueError(f"statistic = {statistic!r}; expected 'q' or 't2'")
        if method not in ("complete", "rbc"):
            raise ValueError(f"method = {method!r}; expected 'complete' or 'rbc'")
        Z, T, E = self._project(X)
        groups = None if groups is None else _check_groups(groups, Z.shape[1])
        if method == "rbc":
            return reconstruction_contributions(Z, *self._rbc_terms(statistic, groups))
        if statistic == "q":
            complete = E**2
        else:
            complete = (T / np.sqrt(self.eigenvalues_[: self.n_components_])) @ self.components_
        if groups is None:
            return complete
        squared = complete if statistic == "q" else complete**2
        return np.stack([squared[:, g].sum(axis=1) for g in groups], axis=1)


def group_inverses(M, groups) -> list[np.ndarray]:
    """Each group's ``(Xi^T M Xi)^+`` (:func:`reconstruction_contributions`), in the order of
    ``groups`` (index sequences, checked)."""
    M = np.asarray(M, dtype=float)
    return [np.linalg.pinv(M[np.ix_(g, g)], rcond=1e-12, hermitian=True)
            for g in _check_groups(groups, M.shape[0])]


def reconstruction_contributions(Z, M, groups=None, inverses=None) -> np.ndarray:
    """Reconstruction-based contributions (RBC) of each variable, or group of variables, to the
    fault detection index ``z M z^T`` (Alcala and Qin, Automatica 45 (2009) 1593-1600):
    ``RBC_i = (xi_i^T M z)^2 / (xi_i^T M xi_i)`` for variable ``i``, and ``z M Xi (Xi^T M
    Xi)^+ Xi^T M z^T`` for a group whose unit vectors are the columns of ``Xi``: the largest fall of
    the index along that direction (its minimum over ``f`` of ``(z - Xi f) M (z - Xi f)^T`` taken
    from the index). A direction the index cannot see (``xi_i^T M xi_i`` below 1e-12 of the
    largest diagonal entry of ``M``) contributes 0.

    Parameters
    ----------
    Z : array-like of shape (n_samples, n_variables)
        Samples in the variables of ``M`` (for :class:`PCAMonitor`, standardised).
    M : array-like of shape (n_variables, n_variables)
        Symmetric positive semi-definite matrix of the index (:meth:`PCAMonitor.index_matrix`).
    groups : sequence of index sequences, or None
        Sets of variables reconstructed together; None: each variable alone.
    inverses : list of ndarray, or None
        With ``groups``: each group's ``(Xi^T M Xi)^+`` as :func:`group_inverses` gives them
        (computed here when None).

    Returns
    -------
    ndarray of shape (n_samples, n_variables), or (n_samples, n_groups) with ``groups``

    Raises
    ------
    ValueError
        If ``M`` is not square with the samples' number of variables, or a group is empty or out
        of range.
    """
    Z = np.atleast_2d(np.asarray(Z, dtype=float))
    M = np.asarray(M, dtype=float)
    n = Z.shape[1]
    if M.shape != (n, n):
        raise ValueError(f"M has shape {M.shape}; expected ({n}, {n}) for samples of {n} variables")
    MZ = Z @ M  # row j: (M z_j)^T, M symmetric
    tol = 1e-12 * max(float(np.abs(np.diag(M)).max()), np.finfo(float).tiny)
    if groups is None:
        diagonal = np.diag(M)
        seen = diagonal > tol
        return np.where(seen, MZ**2 / np.where(seen, diagonal, 1.0), 0.0)
    out = np.empty((Z.shape[0], len(groups)))
    groups = _check_groups(groups, n)
    inverses = group_inverses(M, groups) if inverses is None else inverses  # (Xi^T M Xi)^+
    for column, (g, inverse) in enumerate(zip(groups, inverses, strict=True)):
        A = MZ[:, g]  # Xi^T M z per sample
        out[:, column] = np.einsum("si,ij,sj->s", A, inverse, A)
    return np.clip(out, 0.0, None)


def _check_groups(groups, n: int) -> list[np.ndarray]:
    """``groups`` as integer index arrays, each non-empty and within ``0..n-1``."""
    checked = []
    for k, g in enumerate(groups):
        g = np.asarray(g)
        if g.ndim != 1 or g.size == 0 or not np.issubdtype(g.dtype, np.integer) or g.min() < 0 or g.max() >= n:
            raise ValueError(f"group {k} = {g.tolist()!r}; expected a non-empty list of feature indices "
                             f"in 0..{n - 1}")
        checked.append(g)
    return checked


def fit_q_monitor(X, monitor: PCAMonitor) -> PCAMonitor:
    """``monitor``, an unfitted :class:`PCAMonitor` alarming on Q (the registry's: ``analysis.registry
    .make("pca_monitor", variance=..., alpha=..., statistic="q", cv=...)``), fitted on ``X`` (m,
    n_features). Where its ``variance`` would need every component (no residual space for Q, as
    with a few weakly correlated features), it keeps ``min(n_features - 1, m - 3)`` components
    instead: one feature's worth of residual, and room for a fold of ``cv`` to fit them.

    Raises
    ------
    ValueError
        If it cannot be fitted with that many components either (too few samples).
    """
    try:
        return monitor.fit(X)
    except ValueError:
        m, n = np.shape(X)
        return monitor.set_params(n_components=min(n - 1, m - 3)).fit(X)


def varying_columns(X) -> np.ndarray:
    """Indices of the columns of ``X`` (n_samples, n_features) that vary beyond rounding: sample
    standard deviation above 1e-9 of the column's largest magnitude and above 1e-12 in its unit.
    A KL divergence that is zero up to rounding (an axis whose torque never leaves the first bin)
    has a standard deviation of ~1e-16; standardised, that noise would be a feature."""
    X = np.asarray(X, dtype=float)
    spread = X.std(axis=0)
    return np.flatnonzero(spread > np.maximum(1e-9 * np.abs(X).max(axis=0), 1e-12))


def _out_of_fold_eigenvalues(X: np.ndarray, k: int, folds: int) -> np.ndarray:
    """Eigenvalues of the covariance of the Q residuals of ``X`` (m, n) when each of ``folds``
    contiguous blocks is projected on the ``k``-component model of the other blocks. Each fold
    standardises with its own mean and standard deviation (``ddof=1``); a feature constant within
    a fold (it varies only in the held-out block) takes the whole training set's deviation."""
    from sklearn.model_selection import KFold

    m = len(X)
    if folds > m:
        raise ValueError(f"cv = {folds} folds need at least {folds} training samples, got {m}")
    overall = X.std(axis=0, ddof=1)
    residuals = []
    for fit_rows, held_rows in KFold(n_splits=folds).split(X):
        if len(fit_rows) <= k + 1:
            raise ValueError(f"cv = {folds}: a fold leaves {len(fit_rows)} samples to fit {k} components; "
                             "use fewer folds or more training samples")
        part = X[fit_rows]
        mean, scale = part.mean(axis=0), part.std(axis=0, ddof=1)
        scale = np.where(scale > 1e-10 * np.abs(mean), scale, overall)
        Z = (part - mean) / scale
        vectors = np.linalg.eigh(Z.T @ Z / (len(part) - 1))[1][:, ::-1][:, :k]
        held = (X[held_rows] - mean) / scale
        residuals.append(held - held @ vectors @ vectors.T)
    E = np.vstack(residuals)
    return np.clip(np.linalg.eigvalsh(E.T @ E / (m - 1))[::-1], 0.0, None)


def _jackson_mudholkar(theta1: float, theta2: float, theta3: float, alpha: float) -> float:
    """Q limit of eq. 2.6 (Jackson & Mudholkar 1979) from the residual eigenvalue sums."""
    h0 = 1 - 2 * theta1 * theta3 / (3 * theta2**2)
    c = stats.norm.ppf(1 - alpha)
    # (Q / theta1)^h0 is approximately normal; for h0 < 0 the same expression still holds, as the
    # upper quantile of Q maps to the lower quantile of the decreasing transform.
    base = c * h0 * np.sqrt(2 * theta2) / theta1 + 1 + theta2 * h0 * (h0 - 1) / theta1**2
    if h0 == 0 or base <= 0:
        raise ValueError(f"the Jackson-Mudholkar approximation is undefined for these residual "
                         f"eigenvalues (h0 = {float(h0)!r}, bracket = {float(base)!r}); choose another "
                         "number of components")
    return float(theta1 * base ** (1 / h0))


def detect_onset(alarms, persistence: int = 1) -> int | None:
    """First index from which ``persistence`` consecutive samples are alarms (thesis ch. 3.4.1).

    Parameters
    ----------
    alarms : array-like of shape (n_samples,)
        Alarms in time order, e.g. :meth:`PCAMonitor.predict`; truthy means above the limit.
    persistence : int, default=1
        Consecutive alarms needed; the onset is the first sample of the first such run (it is
        confirmed ``persistence - 1`` samples later).

    Returns
    -------
    int or None
        0-based index of the onset, or None if no run of ``persistence`` alarms occurs.

    Raises
    ------
    ValueError
        If ``alarms`` is not 1-D or ``persistence`` is not an integer >= 1.
    """
    a = np.asarray(alarms)
    if a.ndim != 1:
        raise ValueError(f"alarms must be 1-D (n_samples,), got shape {a.shape}")
    if not is_whole(persistence, 1):
        raise ValueError(f"persistence = {persistence!r}; expected an integer >= 1")
    if a.size < persistence:
        return None
    runs = np.convolve(a.astype(bool).astype(int), np.ones(persistence, dtype=int), mode="valid")
    hits = np.flatnonzero(runs == persistence)
    return int(hits[0]) if hits.size else None
