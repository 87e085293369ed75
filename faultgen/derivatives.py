"""Velocity and acceleration of sampled joint angles by a Savitzky-Golay filter: one estimator for
the calibration's measured logs (:mod:`faultgen.logs.measured`) and for replayed logs
(:mod:`faultgen.operation.replay`), so both see a log's motion alike.

A cubic (:data:`SAVGOL_ORDER`) least-squares fit over a window of :data:`SAVGOL_WINDOW` = 0.05 s
(:func:`scipy.signal.savgol_filter`, ``mode="interp"``); when the sample period varies by more than
:data:`UNIFORM_TOLERANCE`, the signal is first put on a uniform grid at the median period with a
cubic spline and the derivatives interpolated back (docs in :mod:`faultgen.logs.measured`).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.signal import savgol_filter

#: Savitzky-Golay window in s (rounded to an odd number of samples) and polynomial order.
SAVGOL_WINDOW = 0.05
SAVGOL_ORDER = 3
#: Sampling counts as uniform when every period is within this fraction of the median.
UNIFORM_TOLERANCE = 1e-3


def is_uniform(dt: np.ndarray, period: float) -> bool:
    """True when every sample interval is within :data:`UNIFORM_TOLERANCE` of the median ``period``."""
    return bool(np.max(np.abs(dt - period)) <= UNIFORM_TOLERANCE * period)


def savgol_window(period: float, n: int) -> int:
    """Odd window length closest to :data:`SAVGOL_WINDOW` s, at least order + 2, at most n."""
    window = 2 * round(SAVGOL_WINDOW / (2 * period)) + 1
    shortest = SAVGOL_ORDER + 2 if SAVGOL_ORDER % 2 else SAVGOL_ORDER + 3  # odd, > order + 1
    window = max(window, shortest)
    largest = n if n % 2 else n - 1
    return min(window, largest)


def derivatives(
    t: np.ndarray, q: np.ndarray, period: float, window: int, uniform: bool, orders: tuple[int, ...] = (1, 2)
) -> tuple[np.ndarray, ...]:
    """Derivatives of ``q`` (n, k) sampled at ``t`` (n,) s, of the given ``orders``, by Savitzky-Golay
    (``window`` samples at ``period`` s), resampling on a uniform grid first when not ``uniform``."""
    if uniform:
        return tuple(savgol_filter(q, window, SAVGOL_ORDER, deriv=d, delta=period, axis=0, mode="interp")
                     for d in orders)
    s = t - t[0]  # relative time: keeps the spline well conditioned for absolute time stamps
    grid = np.arange(math.floor(s[-1] / period) + 1) * period
    if grid[-1] < s[-1]:
        grid = np.append(grid, grid[-1] + period)  # cover the last sample (spline extrapolates a bit)
    q_grid = CubicSpline(s, q, axis=0)(grid)
    return tuple(
        CubicSpline(grid, savgol_filter(q_grid, window, SAVGOL_ORDER, deriv=d, delta=period, axis=0, mode="interp"),
                    axis=0)(s)
        for d in orders)


def smoothed(t: np.ndarray, q: np.ndarray, window: float = SAVGOL_WINDOW) -> np.ndarray:
    """``q`` (n, k) sampled at ``t`` (n,) s through the Savitzky-Golay filter of its derivatives
    (cubic, order 0) over ``window`` s, shape (n, k). On a smooth motion it changes the angles by
    far less than an encoder's noise; on a noisy log it removes what a drive tracking the log as its
    reference would amplify."""
    dt = np.diff(t)
    period = float(np.median(dt))
    samples = max(SAVGOL_ORDER + 2, 2 * round(window / (2 * period)) + 1)
    samples = min(samples, len(t) if len(t) % 2 else len(t) - 1)
    return derivatives(t, q, period, samples, is_uniform(dt, period), orders=(0,))[0]
