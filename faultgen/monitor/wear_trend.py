"""Each axis's wear filtered over a unit's logs (:class:`WearTrend`): the Kalman
filter of a local linear trend, with the learned condition slopes' error as regression effects in
its state, through which :class:`faultgen.monitor.wear.WearEstimator` passes each log's wear
estimate (docs/analysis.md, "Wear in the robot's own scale")."""

from __future__ import annotations

import numpy as np

from faultgen.monitor import bounds

#: % of wear per log, per log: the standard deviation of the change of an axis's wear rate from one
#: log to the next in the local linear trend through which each log's wear estimate is filtered
#: (:class:`WearTrend`). The independent fleet's worn axes grow 0.5-1 % per log (60 % over 60-100
#: daily logs); 0.1 lets the filter follow a rate that doubles within about ten logs. Chosen on
#: seeds 0 and 1 of the independent fleet's first law (0.05-0.2 gave median errors within 0.2 point
#: of each other), checked on a held-out seed and the second law (docs/analysis.md, "Wear in the
#: robot's own scale").
WEAR_RATE_CHANGE = 0.1
#: Standard errors of the innovation (a log's estimate minus the trend's prediction) beyond which a
#: log does not move the wear's trend (:class:`WearTrend`): 5, a chance of 6e-7 for a log the trend
#: describes. On faultgen's shipped IRB 6700 fleet a healthy unit's single logs answered about 10 and 33
#: errors off (58 % and 262 % on axis 1), and without the gate its trend alarmed for a week.
OUTLIER_GATE = 5.0
#: Consecutive gated logs that restart the trend at the last (a step of wear, not outliers).
OUTLIER_RUN = 3


class WearTrend:
    """Each axis's wear filtered over the logs: a Kalman filter of a local linear trend (the wear
    and its rate per log; the rate a random walk of :data:`WEAR_RATE_CHANGE`, the wear none beyond
    it; Harvey 1989, ch. 2-3; Durbin & Koopman 2012, ch. 3), whose measurement is a log's wear
    estimate with its standard error. A log's estimate scatters by 3-4 % of wear (a log's friction
    scatter lies along the wear signature); the filtered wear by about half that, without the lag of
    a mean over the last logs, since the rate is part of the state.

    With ``n_regressors`` > 0 the state also holds the error of the unit's learned condition slopes
    (temperature, payload) along each axis's wear signature, in % of wear per unit of condition
    (regression effects in the state vector, Durbin & Koopman 2012, ch. 6.2.2): a log's estimate is
    the wear plus that error times the log's conditions ``x`` (centred on the learning logs'), so
    the error of slopes learned on the first weeks' narrow range is not extrapolated over a season
    as wear; it starts at 0 with the slopes' own covariance (:meth:`set_prior`) and is learned from
    every later log's condition that departs from the trend (a day's weather, a part), and it is
    kept across a restart of the wear (:meth:`reset`). Without a prior it stays 0 with no
    uncertainty: the local linear trend alone. What it costs: it is learned on while an axis wears,
    and where a wear begins as the season warms (a kink the trend follows only over some logs) part
    of the wear is taken for a slope error (docs/analysis.md, "Wear in the robot's own scale": on
    the second friction law the median error rose by 0.7 point).

    A log whose estimate lies more than :data:`OUTLIER_GATE` standard errors of the innovation from
    the trend's prediction does not move the trend (innovation gating, Bar-Shalom et al. 2001, ch.
    2.3: one log of a part the twin predicts badly, a log cut short, would otherwise carry the
    trend for weeks, where a single log's alarm waits for ``persistence`` logs); :data:`OUTLIER_RUN`
    such logs in a row are a step, not outliers: the trend restarts at the last of them.

    The rate's process noise is adapted to the evidence (:func:`faultgen.monitor.bounds.adapted_rate_variance`:
    covariance matching over the last :data:`faultgen.monitor.bounds.ADAPT_WINDOW` innovations not gated
    out, never below :data:`WEAR_RATE_CHANGE`), and the predicted covariance of the wear and its rate
    faded where those innovations are larger than their stated spread (:func:`faultgen.monitor.bounds.fading_factor`): where the wear grows faster than the trend predicts (3
    points a day against a filter tuned on 0.5-1), the innovations keep one sign, the rate's variance
    grows with them, the trend follows the wear within a few logs and its error (the interval) widens
    with the growth it did not foresee; with a fixed variance the estimate lagged the truth by 4-9 points
    (issue 90).

    Parameters
    ----------
    n_axes : int
    n_regressors : int
        The conditions whose slopes' error is in the state (0: none).
    adaptive : bool
        Whether the rate's process noise and the fading are adapted (False: the fixed local linear
        trend of :data:`WEAR_RATE_CHANGE`, the filter before issue 90).
    """

    def __init__(self, n_axes: int, n_regressors: int = 0, adaptive: bool = True):
        self.n_axes, self.n_regressors, self.adaptive = n_axes, n_regressors, adaptive
        self.state: np.ndarray | None = None  # (n_axes, 2 + k): wear %, rate % per log, slope errors
        self.covariance: np.ndarray | None = None  # (n_axes, 2 + k, 2 + k)
        self.gated = np.zeros(n_axes, dtype=int)  # consecutive logs gated out, per axis
        # the last innovations and their normalised squares (n_axes, 2), NaN where gated out or restarted
        self.recent: list[np.ndarray] = []
        self.rate_variance = np.full(n_axes, WEAR_RATE_CHANGE**2)  # the rate's process variance, adapted
        self.fading = np.ones(n_axes)  # the predicted covariance's fading factor, adapted
        # the slope errors' mean and covariance a new trend starts from
        self.slope_mean = np.zeros((n_axes, n_regressors))
        self.slope_covariance = np.zeros((n_axes, n_regressors, n_regressors))

    def set_prior(self, covariance: np.ndarray) -> None:
        """Start the slope errors at 0 with ``covariance`` (n_axes, k, k; % of wear per unit of
        condition, squared) and forget the trend."""
        self.slope_mean = np.zeros((self.n_axes, self.n_regressors))
        self.slope_covariance = np.array(covariance, dtype=float).reshape(self.n_axes, self.n_regressors,
                                                                          self.n_regressors)
        self.reset()

    def reset(self) -> None:
        """Forget the trend (a new learning, a repair, a gearbox change): the next log starts it.
        What the slope errors have learned is kept."""
        if self.state is not None and self.n_regressors:
            self.slope_mean = self.state[:, 2:].copy()
            self.slope_covariance = self.covariance[:, 2:, 2:].copy()
        self.state = self.covariance = None
        self.gated = np.zeros(self.n_axes, dtype=int)
        self.recent, self.rate_variance = [], np.full(self.n_axes, WEAR_RATE_CHANGE**2)
        self.fading = np.ones(self.n_axes)

    def update(self, estimate: np.ndarray, error: np.ndarray,
               conditions: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Take a log's wear ``estimate`` % and its standard ``error`` % (both (n_axes,)) at its
        centred ``conditions`` (k,; zeros when None); return the filtered wear % and its standard
        error % (both (n_axes,)). The first log after a reset (and the last of a run of
        :data:`OUTLIER_RUN` gated ones) starts the trend at its estimate less the slope errors'
        part, the rate at 0 -+ 1 % per log."""
        estimate, variance = np.asarray(estimate, dtype=float), np.asarray(error, dtype=float) ** 2
        x = np.zeros(self.n_regressors) if conditions is None else np.asarray(conditions, dtype=float)
        design = np.r_[1.0, 0.0, x]  # the measurement: wear + slope errors . x
        if self.state is None:
            self.state, self.covariance = self._start(estimate, variance, x, self.slope_mean, self.slope_covariance)
            return self.state[:, 0].copy(), np.sqrt(self.covariance[:, 0, 0])
        step = np.eye(2 + self.n_regressors)
        step[0, 1] = 1.0
        state = self.state @ step.T
        covariance = step @ self.covariance @ step.T
        covariance[:, :2, :2] *= self.fading[:, None, None]
        covariance[:, 1, 1] += self.rate_variance
        innovation = estimate - state @ design
        cross = covariance @ design  # (n_axes, 2 + k): P H'
        spread = cross @ design + variance
        gated = innovation**2 > OUTLIER_GATE**2 * spread
        gain = np.where(gated[:, None], 0.0, cross / spread[:, None])  # (n_axes, 2 + k)
        state = state + gain * innovation[:, None]
        covariance = covariance - gain[:, :, None] * cross[:, None, :]
        covariance = 0.5 * (covariance + np.swapaxes(covariance, 1, 2))  # rounding's asymmetry, which fading > 1 grows
        self.gated = np.where(gated, self.gated + 1, 0)
        restart = self.gated >= OUTLIER_RUN
        seen = np.where(gated | restart, np.nan, innovation)  # what the adaptation sees
        self.recent = [*self.recent, np.c_[seen, seen**2 / spread]][-bounds.ADAPT_WINDOW:]
        for past in self.recent[:-1]:
            past[restart] = np.nan
        recent = np.array(self.recent)  # (w, n_axes, 2): innovations and their normalised squares
        if not self.adaptive:
            recent = np.full_like(recent, np.nan)
        self.fading = bounds.fading_factor(recent[..., 1])
        self.rate_variance = np.where(self.fading > 1.0, bounds.adapted_rate_variance(
            WEAR_RATE_CHANGE**2, cross[:, 1] / spread, recent[..., 0]), WEAR_RATE_CHANGE**2)
        if restart.any():
            fresh_state, fresh_covariance = self._start(estimate, variance, x, state[:, 2:], covariance[:, 2:, 2:])
            state[restart], covariance[restart] = fresh_state[restart], fresh_covariance[restart]
            self.gated[restart] = 0
        self.state, self.covariance = state, covariance
        return self.state[:, 0].copy(), np.sqrt(self.covariance[:, 0, 0])

    def condition_part(self, conditions: np.ndarray | None) -> np.ndarray:
        """The slope errors' part (n_axes,) % of a log's estimate at its centred ``conditions``
        (k,; None: none), as the state now holds them; zeros without a trend or slope errors."""
        if self.state is None or not self.n_regressors or conditions is None:
            return np.zeros(self.n_axes)
        return self.state[:, 2:] @ np.asarray(conditions, dtype=float)

    def _start(self, estimate: np.ndarray, variance: np.ndarray, x: np.ndarray, slope_mean: np.ndarray,
               slope_covariance: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The wear at ``estimate`` less the slope errors' part at ``x`` (its variance the log's
        and theirs, correlated with them), the rate 0 -+ 1, the slope errors as given."""
        k = self.n_regressors
        covariance = np.zeros((self.n_axes, 2 + k, 2 + k))
        covariance[:, 2:, 2:] = slope_covariance
        shared = slope_covariance @ x  # (n_axes, k): Cov(slope errors, their part at x)
        covariance[:, 0, 0] = variance + shared @ x
        covariance[:, 0, 2:] = covariance[:, 2:, 0] = -shared
        covariance[:, 1, 1] = 1.0
        state = np.zeros((self.n_axes, 2 + k))
        state[:, 0], state[:, 2:] = estimate - slope_mean @ x, slope_mean
        return state, covariance
