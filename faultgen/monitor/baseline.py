"""The baseline stage (:class:`Baseline`): one program's normal operation learned on its first logs
(what it learns: :mod:`faultgen.monitor.scoring`'s docstring), how a later log is standardised
against it and each axis's wear read from it; and how a unit's programs share it (issue 90, item
3's "every unit monitored by its 40th day").

- **One program.** Its first ``train`` logs: offset, condition slopes, noise, PCA model
  (:meth:`Baseline.fit_shared`), the wear reads' dispersion, day-to-day scatter and observability
  on the program's wear signatures (:meth:`Baseline.fit_signatures`).
- **Programs met while the unit learns** pool into that learning (:func:`faultgen.monitor.programs.pool`):
  the unit is learned once it has ``train`` logs in all, not ``train`` of each program. The twin's
  residual makes the programs comparable up to an offset: each program its own offset, the slopes
  and noise learned within programs (the fixed-effects estimator: each program's mean taken out of
  the residuals and conditions before the least squares; the noise's degrees of freedom less one
  per program), one PCA model on the pooled standardised residuals; each its own signatures.
- **A program met after** (or with fewer than a relearning's logs in the pooled window) learns only
  its offset, on :attr:`Baseline.relearn_logs` logs of its own (:meth:`Baseline.fit_offset`, as a
  unit after maintenance does: :meth:`Baseline.learn_offset`), and borrows the rest
  (:data:`SHARED`) of the unit's learned baseline; its dispersion and scatter are read on the
  unit's pooled learning residuals along its own signatures.
"""

from __future__ import annotations

from statistics import NormalDist

import numpy as np

from analysis import registry
from analysis.isolation import signature_scores
from faultgen.monitor import bounds

#: The features the monitor watches per axis, in the order of a log's feature vector (by name, then
#: axis), which :mod:`faultgen.monitor.logs` computes. The RMS and average load torques: the two that
#: follow friction on an axis whose load keeps one sign (gravity), where the mean absolute torque
#: does not (friction adds on the way up what it takes on the way down: KR210 axis 2 at 40 % wear,
#: +0.01 % mean |torque|, +2 % RMS, +4.5 % average load torque); the histograms are left out (a
#: friction change of a few percent moves a 12-bin histogram by less than one bin).
#: ``friction_torque`` (:func:`faultgen.monitor.logs.friction_torque`, the monitor's own, not an
#: imported fleet's) moves by the mean |dry friction| over the motion, what the wear is stated in,
#: whatever the friction's shape: with it the second independent fleet's (a growing Stribeck hump)
#: median error fell from 4.37 to 3.90 points and the first law's three fleets' from 2.17, 1.90,
#: 2.89 to 1.92, 1.84, 2.41 (docs/analysis.md, "Wear in the robot's own scale").
FEATURES = ("rms_torque", "average_load_torque", "friction_torque")
#: The features each axis's wear (its magnitude, wear.csv) is read on; T2, Q and the ranking of the
#: axes use all :data:`FEATURES`. The friction torque alone: its change per % of an axis's dry
#: friction is the mean |dry friction| over the motion whatever the log's load, where the RMS and
#: the average load torque weigh friction by the torque it adds to, so the twin's signature
#: (simulated without a part, at the model's friction) misreads them on a log of another load or
#: friction (their response 0.64-1.08 of the signature's on the independent fleets' worn axes). Read
#: on it alone, the median error on the independent fleets fell from 1.98, 1.67, 2.39, 2.77, 2.10,
#: 2.85 to 2.40, 1.33, 1.65, 2.22, 1.96, 1.69 points (first law seeds 0, 1, 3, the second law, the
#: KR210 L150 and iiwa 14 fleets; docs/analysis.md, "The wear read on the friction torque").
WEAR_FEATURES = ("friction_torque",)

#: The two-sided interval of each wear estimate in ``wear.csv``.
WEAR_INTERVAL = 0.90
#: Its two-sided normal quantile (1.645): the half-width of the interval in standard errors.
WEAR_INTERVAL_Z = NormalDist().inv_cdf(0.5 + WEAR_INTERVAL / 2)

#: An axis is **not observable on this program** when one log's :data:`WEAR_INTERVAL` (90 %) interval of
#: its wear, from the noise at the learning logs' conditions (:meth:`~faultgen.monitor.wear.WearEstimator.wear_interval` of an
#: unworn axis: 2 x 1.645 standard errors), is wider than this many ``wear_limit``s (48 points at the
#: default 8 %). Why: the filtered wear's error is about half a log's (:class:`~faultgen.monitor.wear_trend.WearTrend`), so at that
#: width the filtered wear's own 90 % interval on an unworn axis spans -+1.5 limits: it cannot tell the
#: axis unworn from worn past the limit, and its wear, trend and remaining life would be the noise's
#: (a UR5 dispensing program's axis 2: one log's interval 258 points wide, its filtered wear
#: -36..+11 %). Such an axis gets no wear (empty cells in scores.csv and wear.csv), no remaining life
#: (rul.csv says why), and does not alarm. The independent KR210 fleet's axes (first law, seed 0) are
#: 7.8-23.3 points wide (1.0-2.9 limits of 8 %): a margin of 2.1 below the rule, 5.4 above it to the
#: UR5's (at the earlier default of 10 %: 0.8-2.3 limits, margins 2.6 and 4.3).
NOT_OBSERVABLE_LIMITS = 6.0

#: The smallest significance of --protocol own's at-once limits (``alpha ** persistence``; the limits are
#: quantiles at ``1 - alpha``, which a double tells from 1 to about 1e-16): below it, no at-once rule.
FAR_ALPHA = 1e-12


#: What a unit's programs share of its baseline, learned once (:meth:`Baseline.fit_shared`): the
#: condition slopes, noise and PCA model; each program has its own offset and wear signatures.
SHARED = ("pca", "far_", "condition_mean_", "regressors_", "slope_", "gram_inv_", "scale_")


class Baseline:
    """One program's baseline (module docstring): learned on :attr:`training` (stamp, residual
    (n_features,), conditions (2,): temperature deg C, payload kg) by :meth:`fit`; ``signatures``
    (n_axes, n_features): each axis's wear signature in feature units per % (protocol ``twin``), or
    None; ``borrowed``: what it borrows of the unit's learned baseline (:meth:`shared`), or None."""

    def __init__(self, settings, n_axes: int, signatures: np.ndarray | None = None, borrowed: dict | None = None):
        self.settings, self.n_axes, self.signatures = settings, n_axes, signatures
        self.training: list[tuple[str, np.ndarray, np.ndarray]] = []
        #: The twin's expected features of each learning log (with the twin).
        self.learned_expectations: list[np.ndarray] = []
        self.pca = self.far_ = self.mean_ = self.condition_mean_ = self.regressors_ = None
        self.slope_ = self.gram_inv_ = self.learned_ = self.scale_ = None
        #: (n_axes,) whether each axis is observable on the program (:data:`NOT_OBSERVABLE_LIMITS`)
        #: and one log's 90 % interval width of each, points (:meth:`fit_signatures`; all observable before it).
        self.observable_ = np.ones(n_axes, dtype=bool)
        self.width_ = np.zeros(n_axes)
        #: (n_axes,) each axis's wear estimate's scatter on the learning logs over its stated
        #: standard error, at least 1 (:meth:`fit_signatures`; 1 before it).
        self.dispersion_ = np.ones(n_axes)
        self.day_scatter_ = np.full(n_axes, np.nan)  # each axis's reads' day-to-day scatter, points (bounds.day_scatter)
        #: After a maintenance event: the (residual, conditions) of the logs since, until
        #: :attr:`relearn_logs` (None otherwise).
        self.relearning: list[tuple[np.ndarray, np.ndarray]] | None = None
        #: Whether it learns again after a program change (its learning logs are ``relearning``).
        self.program_changed = False
        #: Rows standing for the logs learned since a program change, not yet scored.
        self.placeholders = 0
        #: A program met after the unit learned: what it borrows of the unit's baseline (:meth:`shared`),
        #: its own offset learned against it (:meth:`fit_offset`); else None.
        self.borrowed_ = borrowed

    @property
    def relearn_logs(self) -> int:
        """Logs after a repair or gearbox change from which the offset is learned again: a quarter
        of ``train``, at least 5."""
        return max(5, self.settings.train // 4)

    @property
    def learning_logs(self) -> int:
        """The logs this baseline learns on: ``train``, or :attr:`relearn_logs` for a program (or torque
        source) met after the unit learned, which learns its offset alone (``borrowed_``)."""
        return self.settings.train if self.borrowed_ is None else self.relearn_logs

    # -- a later log ----------------------------------------------------------------------------
    def centred(self, conditions: np.ndarray) -> np.ndarray:
        """The learned regressors of ``conditions`` (..., 2) less their learning mean (NaN: 0)."""
        return np.nan_to_num(conditions[..., self.regressors_] - self.condition_mean_[self.regressors_])

    def learn_offset(self, E: np.ndarray, C: np.ndarray) -> None:
        """The offset learned again on residuals ``E`` (m, n_features) at conditions ``C`` (m, 2): their
        mean less the slopes' part (a program met later, a unit after maintenance)."""
        self.mean_ = (E - self.centred(C) @ self.slope_).mean(axis=0)

    def standardise(self, e: np.ndarray, conditions: np.ndarray) -> np.ndarray:
        """Residual ``e`` (n_features,) at ``conditions`` less the offset and slopes, over the noise."""
        return (e - self.mean_ - self.centred(conditions) @ self.slope_) / self.scale_

    def prediction_factor(self, conditions: np.ndarray) -> float:
        """The prediction interval's width over the noise's for a log at ``conditions``
        (temperature deg C, payload kg): ``sqrt(1 + 1/m + x0' (X'X)^-1 x0)`` (scoring's docstring)."""
        x = self.centred(conditions)
        return float(np.sqrt(1.0 + 1.0 / self.learned_ + x @ self.gram_inv_ @ x))

    def wear_columns(self) -> np.ndarray:
        """The positions of :data:`WEAR_FEATURES` in a feature vector of :data:`FEATURES` by name,
        then axis (``len(WEAR_FEATURES) * n_axes`` indices)."""
        n = self.n_axes
        return np.concatenate([FEATURES.index(name) * n + np.arange(n) for name in WEAR_FEATURES])

    def wear_estimate(self, residual: np.ndarray, variance: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """Each axis's wear, % of its own dry friction (n_axes,), and its standard error from the
        noise (n_axes,), from ``residual`` (n_features,: the features minus the twin's expectation,
        the unit's offset and its condition slopes) whose features have ``variance``
        (n_features,): weighted least squares of the :data:`WEAR_FEATURES` along each axis's wear
        signature (scoring's docstring), the error times :attr:`dispersion_`. None without a twin.

        Raises ``ValueError`` when the signatures are not (n_axes, ``len(FEATURES) * n_axes``)."""
        if self.signatures is None:
            return None
        expected = (self.n_axes, len(FEATURES) * self.n_axes)
        if self.signatures.shape != expected:
            raise ValueError(f"wear signatures of shape {self.signatures.shape}; expected {expected} "
                             f"(each axis's change of {', '.join(FEATURES)} of every axis per %)")
        columns = self.wear_columns()
        signatures, residual, variance = self.signatures[:, columns], residual[columns], variance[columns]
        information = (signatures**2 / variance).sum(axis=1)
        error = self.dispersion_ / np.sqrt(information)
        return (signatures * residual / variance).sum(axis=1) / information, error

    def axis_scores(self, z: np.ndarray) -> np.ndarray:
        """Each axis's isolation score for standardised residual(s) ``z`` (larger: more likely)."""
        if self.signatures is not None:
            return signature_scores(z, self.signatures / self.scale_)
        # each axis's features (by feature, then axis) reconstructed together
        axes = np.arange(self.pca.n_features_in_).reshape(-1, self.n_axes).T
        return self.pca.contributions(np.atleast_2d(z), "q", method="rbc", groups=axes).mean(axis=0)

    # -- learning -------------------------------------------------------------------------------
    def fit(self) -> tuple[list[str], np.ndarray, np.ndarray | None, dict | None]:
        """Learn on :attr:`training`: all of it (:meth:`fit_shared`), or for a program met after the
        unit learned (``borrowed_``) its offset alone (:meth:`fit_offset`); then its signatures'
        parts (:meth:`fit_signatures`). Returns the learning logs' stamps and residuals less offset
        and slopes (m, n_features), an unworn axis's standard error (n_axes,; None without a twin)
        and, when it learned all of it, what the unit's later programs borrow (:meth:`shared`)."""
        stamps = [s for s, _, _ in self.training]
        if self.borrowed_ is not None:
            R, pooled, dof = self.fit_offset(), self.borrowed_["R"], self.borrowed_["dof"]
        else:
            R, _ = self.fit_shared()
            pooled, dof = R, len(R) - 1 - len(self.regressors_)
        self.training = []
        error = None if self.signatures is None else self.fit_signatures(pooled, dof)
        return stamps, R, error, self.shared(pooled, dof) if self.borrowed_ is None else None

    def shared(self, R: np.ndarray, dof: int) -> dict:
        """What a program met later borrows of this learned baseline (:data:`SHARED`), with the
        learning residuals ``R`` (m, n_features) and their degrees of freedom ``dof``."""
        return {name: getattr(self, name) for name in SHARED} | {"R": R, "dof": dof}

    def borrow(self, common: dict) -> None:
        """Take the unit's :data:`SHARED` parts from ``common`` (:meth:`shared`)."""
        for name in SHARED:
            setattr(self, name, common[name])

    def fit_shared(self, groups: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The offset, condition slopes, noise and PCA model learned on :attr:`training` (scoring's
        docstring); ``groups`` (m,) the program of each learning log (0..G-1; None: one program): each
        its own offset, the slopes and noise within programs (module docstring). Returns the learning
        logs' residuals less their offset and slopes (m, n_features) and the offsets (G, n_features)."""
        E = np.stack([e for _, e, _ in self.training])
        C = np.array([c for _, _, c in self.training])  # (m, 2): temperature, payload
        self.mean_ = E.mean(axis=0)
        # the conditions that vary over the learning logs (and are logged) become regressors
        finite = np.all(np.isfinite(C), axis=0)
        self.condition_mean_ = np.where(finite, np.nanmean(np.where(np.isfinite(C), C, 0.0), axis=0), 0.0)
        self.regressors_ = np.flatnonzero(finite & (np.ptp(np.where(np.isfinite(C), C, 0.0), axis=0) > 0))
        X = C[:, self.regressors_] - self.condition_mean_[self.regressors_]
        offsets, within = self.mean_[None], X
        if groups is not None:  # each program's mean taken out of the residuals and the conditions
            n = E.shape[1]
            means = np.stack([np.bincount(groups, weights=column) for column in np.column_stack([E, X]).T], axis=1)
            means = means / np.bincount(groups)[:, None]
            within = X - means[groups, n:]
            self.slope_ = np.linalg.lstsq(within, E - means[groups, :n], rcond=None)[0]
            offsets = means[:, :n] - means[:, n:] @ self.slope_
            self.mean_ = offsets[0]
            R = E - offsets[groups] - X @ self.slope_
        else:
            self.slope_ = (np.linalg.lstsq(X, E - self.mean_, rcond=None)[0] if X.shape[1]
                           else np.zeros((0, E.shape[1])))
            R = E - self.mean_ - X @ self.slope_
        # (X'X)^-1 of the centred conditions: a later log's leverage (the prediction interval)
        self.gram_inv_ = np.linalg.pinv(within.T @ within) if X.shape[1] else np.zeros((0, 0))
        self.learned_ = len(E)
        scale = np.sqrt((R**2).sum(axis=0) / (len(R) - len(offsets) - X.shape[1]))
        self.scale_ = np.where(scale > 0, scale, 1.0)
        # the registry's monitor model (analysis.registry: the one detect and training-source build)
        settings = self.settings
        self.pca = registry.make("pca_monitor", variance=settings.variance, alpha=settings.alpha, cv=5)[1].fit(
            R / self.scale_)
        # --protocol own's at-once limits (T2, Q) from the same fitted model; none past FAR_ALPHA
        far = settings.alpha**settings.persistence
        self.far_ = None if self.signatures is not None or far < FAR_ALPHA else self.pca.limits(far)
        return R, offsets

    def fit_offset(self) -> np.ndarray:
        """A program met after the unit learned (``borrowed_``): the unit's :data:`SHARED` slopes,
        noise and PCA model, and the program's own offset (:meth:`learn_offset`). Returns its
        learning logs' residuals less both (m, n_features)."""
        self.borrow(self.borrowed_)
        E = np.stack([e for _, e, _ in self.training])
        C = np.array([c for _, _, c in self.training])
        self.learn_offset(E, C)
        self.learned_ = len(E)
        return E - self.mean_ - self.centred(C) @ self.slope_

    def learn_with(self, common: dict, offset: np.ndarray, count: int) -> None:
        """Learned with the unit's first program (:func:`faultgen.monitor.programs.pool`): the unit's
        ``common`` parts (:meth:`shared`), its own ``offset`` (n_features,) from its ``count`` learning
        logs, and its signatures' parts on the pooled residuals."""
        self.borrow(common)
        self.mean_, self.learned_, self.training = offset, count, []
        self.program_changed, self.placeholders = False, 0
        if self.signatures is not None:
            self.fit_signatures(common["R"], common["dof"])

    def fit_signatures(self, R: np.ndarray, dof: int) -> np.ndarray:
        """Each axis's wear read's dispersion, day-to-day scatter, one log's interval width (``2``
        :data:`WEAR_INTERVAL_Z` standard errors) and observability (that width at most
        :data:`NOT_OBSERVABLE_LIMITS` wear limits) from learning residuals ``R`` (m, n_features;
        ``dof`` degrees of freedom left). Returns an unworn axis's standard error (n_axes,)."""
        # the learning logs are unworn: their wear estimates' scatter over the stated standard
        # error (a feature's noise is not independent of the others': a log's friction scatter
        # moves an axis's features together, along its signature) widens every later error
        self.dispersion_ = np.ones(self.n_axes)
        z = np.stack([w / e for w, e in (self.wear_estimate(r, self.scale_**2) for r in R)])
        self.day_scatter_ = bounds.day_scatter(z * self.wear_estimate(R[0], self.scale_**2)[1])  # points
        self.dispersion_ = np.maximum(1.0, np.sqrt((z**2).sum(axis=0) / dof))
        # the learned slopes' error along each axis's wear signature (% of wear per unit of
        # condition): the estimate is linear in the residual, so its covariance is the wear
        # estimate's squared error times (X'X)^-1; the wear filter learns it on from later logs
        error = self.wear_estimate(np.zeros_like(self.scale_), self.scale_**2)[1]
        self.width_ = 2.0 * WEAR_INTERVAL_Z * error  # one log's 90 % interval of an unworn axis, from the noise
        self.observable_ = self.width_ <= NOT_OBSERVABLE_LIMITS * self.settings.wear_limit
        return error
