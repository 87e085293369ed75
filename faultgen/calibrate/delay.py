"""The delay between a log's motion channels and its torque channels (:func:`estimate`), checked on
every log before the effect search, and the log with its torque columns moved by a delay
(:func:`shift`, ``faultgen calibrate --delay auto|SECONDS``).

A controller that samples the torque (or the motor current) later than the encoders logs
``tau_logged(t) = tau(t - d)``. The model's torque along the logged motion is ``tau(t)``, so the
cross-correlation of the measured torque's rate of change with the model's peaks at the lag ``d``
(the rates, not the torques: a torque held against gravity says nothing about when it was
sampled, and it would flatten the peak; on pick-and-place logs with long rests the torques' own
interval reached 40 ms where the rates' is 3 ms wide). The lag is taken
to a fraction of a sample by a parabola through the peak and its two neighbours (Jacovitti &
Scarano 1993, "Discrete time techniques for time delay estimation", IEEE Trans. Signal Process.
41(2), eq. 19), its interval by a block bootstrap of the time axis (Carlstein 1986, non-overlapping
blocks; Efron & Tibshirani 1993, ch. 13, the percentile interval). Nothing the effect search adds
moves the peak: a missing friction or payload changes the torque's size, not when it happens.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from faultgen.calibrate import criterion
from faultgen.calibrate.search import Split
from faultgen.logs import measured as measured_io

#: Largest delay searched, s, either way (a controller's channels are a few cycles apart).
MAX_DELAY = 0.1
#: Level of the delay's interval.
LEVEL = 0.95
#: Bootstrap replicates; fixed seed, so the same log gives the same interval.
REPLICATES = 1000
SEED = 0
#: Length of a bootstrap block, s, and the fewest blocks (a short log gets shorter blocks).
BLOCK = 2.0
MIN_BLOCKS = 10
#: What the interval is widened by on both sides, in sample periods: the bias the bootstrap does not
#: see, the parabola's own (up to 0.08 sample on roboticstoolbox logs shifted by a known delay) and
#: that of effects not yet in the model; docs/calibration.md, "Channel delay".
ALLOWANCE = 0.15


@dataclass(frozen=True)
class Delay:
    """A delay of the torque channels behind the motion channels, s (positive: the torque logged
    late), with its interval.

    Attributes
    ----------
    seconds : float
        The estimate: the cross-correlation's peak, parabolic sub-sample interpolation.
    low, high : float
        The :data:`LEVEL` percentile interval of the block bootstrap, s.
    period : float
        The log's median sample period, s.
    level : float
        The interval's level (:data:`LEVEL` unless asked otherwise).
    """

    seconds: float
    low: float
    high: float
    period: float
    level: float = LEVEL

    @property
    def covers_zero(self) -> bool:
        return bool(self.low <= 0.0 <= self.high)

    def record(self) -> dict:
        """For ``report.json``: the estimate and interval in s, the level and the method."""
        return {"seconds": self.seconds, "interval_s": [self.low, self.high], "level": self.level,
                "sample_period_s": self.period, "covers_zero": self.covers_zero,
                "method": ("peak of the cross-correlation of the measured with the model's torque rate (all "
                           "axes, each standardised), parabolic sub-sample interpolation (Jacovitti & Scarano "
                           "1993); interval: "
                           f"percentile, block bootstrap ({REPLICATES} replicates, blocks of up to {BLOCK:g} s, "
                           f"Carlstein 1986), widened by {ALLOWANCE:g} sample period either side")}

    def line(self, checked: dict | None = None) -> str:
        """One console line: the estimate, its interval and whether it differs from zero; with
        ``checked`` (:func:`verify`), the correction advised only where it lowers the held-out gap."""
        if self.covers_zero:
            verdict = "its interval covers 0: no delay shown"
        elif checked is not None and not checked["lowers"]:
            verdict = (f"its interval leaves out 0, but moving the torque by it raises the nominal model's held-out "
                       f"gap ({checked['gap_before']:.4f} -> {checked['gap_after']:.4f}): not taken for a channel "
                       "delay, no correction advised (a torque term the model lacks can move the peak)")
        else:
            verdict = "the torque is logged off the motion: `faultgen calibrate --delay auto` corrects it"
            if checked is not None:
                verdict += (f" (the nominal model's held-out gap {checked['gap_before']:.4f} -> "
                            f"{checked['gap_after']:.4f} with it)")
        return (f"channel delay: torque behind motion {1e3 * self.seconds:+.1f} ms ({self.level:.0%} interval "
                f"{1e3 * self.low:+.1f} .. {1e3 * self.high:+.1f} ms, sample period {1e3 * self.period:.1f} ms); "
                f"{verdict}")


def estimate(t: np.ndarray, tau: np.ndarray, predicted: np.ndarray, max_delay: float = MAX_DELAY,
             level: float = LEVEL) -> Delay:
    """The delay of the measured torque behind the model's torque along the same logged motion.

    Parameters
    ----------
    t : ndarray of shape (n,)
        Sample times, s (about uniform: the median period is the lag unit).
    tau, predicted : ndarray of shape (n, N)
        Measured torque and the model's torque along the logged motion, N m.
    max_delay : float
        Largest delay searched either way, s.
    level : float
        The interval's level (the same bootstrap replicates at any level: a wider level's interval
        holds a narrower one's).

    Returns
    -------
    Delay
        Estimate and ``level`` interval, s.

    Raises
    ------
    ValueError
        If the log is shorter than :data:`MIN_BLOCKS` times twice the lags searched, or the shapes
        differ.
    """
    t = np.asarray(t, dtype=float)
    tau, predicted = np.asarray(tau, dtype=float), np.asarray(predicted, dtype=float)
    if tau.shape != predicted.shape or tau.shape[0] != t.shape[0]:
        raise ValueError(f"tau {tau.shape} and predicted {predicted.shape} must both have shape ({t.shape[0]}, N)")
    period = float(np.median(np.diff(t)))
    k = max(1, int(np.ceil(max_delay / period)))
    n = t.shape[0]
    if n < 2 * k * MIN_BLOCKS:
        raise ValueError(f"a log of {n} samples is too short to estimate a delay of up to {max_delay:g} s; "
                         f"expected at least {2 * k * MIN_BLOCKS} samples")
    rate, model_rate = np.gradient(tau, t, axis=0), np.gradient(predicted, t, axis=0)
    products = _products(_standardised(rate), _standardised(model_rate), k)  # (n - 2k, 2k + 1)
    rows = products.shape[0]
    size = max(1, min(int(round(BLOCK / period)), rows // MIN_BLOCKS))
    blocks = rows // size
    sums = products[: blocks * size].reshape(blocks, size, -1).sum(axis=1)  # (blocks, 2k + 1)
    rng = np.random.default_rng(SEED)
    counts = rng.multinomial(blocks, np.full(blocks, 1.0 / blocks), size=REPLICATES)
    boot = np.array([peak(c) for c in counts @ sums]) * period
    low, high = np.quantile(boot, [(1 - level) / 2, (1 + level) / 2]) + np.array([-1, 1]) * ALLOWANCE * period
    return Delay(seconds=float(peak(sums.sum(axis=0)) * period), low=float(low), high=float(high), period=period,
                 level=level)


#: Level of the rule that names a channel delay unexplained on an axis (:func:`shown`): the residual
#: tests' (:data:`faultgen.calibrate.residual_tests.LEVEL`, MATLAB ``resid``'s 99 %).
SHOWN_LEVEL = 0.99


def shown(t: np.ndarray, tau: np.ndarray, predicted: np.ndarray, moving: np.ndarray) -> dict | None:
    """Whether the log's torque channels are logged off its motion, and on which axes that shows:
    the rule by which a channel delay the calibration does not correct is reported unexplained.

    The rule, at :data:`SHOWN_LEVEL`: (1) the log's delay (:func:`estimate`, all axes) has an
    interval that leaves out 0; (2) moving the torque by it lowers the model's error (the sum over
    the axes of the RMS of measured minus model torque over the axis's measured torque RMS, on the
    moving samples): an effect the model lacks can move the cross-correlation's peak (faultgen's
    own PUMA 560 simulation, an inertia the model lacks: +3.5 .. +4.3 ms), but moving the torque by
    it then makes the model's error larger; (3) an axis shows it when its own estimate (its torque
    alone), over an axis with at least as many moving samples as a log needs for an estimate, has
    an interval on the same side of 0.

    Parameters
    ----------
    t : ndarray (n,), s; tau, predicted : ndarray (n, N), N m
        The log's times, measured torque and the model's torque along the logged motion.
    moving : ndarray of bool (n, N)
        The samples where each axis moves.

    Returns
    -------
    dict or None
        None when the log is too short for an estimate or (1) fails; else ``seconds``,
        ``interval_s``, ``level``, ``error_before`` and ``error_after`` (the correction's), ``channel``
        (bool: (2) holds), ``axes`` (numbered 1..N: (3) holds, empty unless ``channel``),
        ``per_axis`` (by axis number: ``seconds``, ``interval_s``; axes that move enough) and ``rule``.
    """
    t, tau, predicted = np.asarray(t, dtype=float), np.asarray(tau, dtype=float), np.asarray(predicted, dtype=float)
    moving = np.asarray(moving, dtype=bool)
    try:
        found = estimate(t, tau, predicted, level=SHOWN_LEVEL)
    except ValueError:
        return None
    if found.covers_zero:
        return None
    keep, moved = moved_torque(t, tau, found.seconds)
    rows = moving[keep]
    scale = np.sqrt(np.mean(tau**2, axis=0))
    scale = np.where(scale > 0, scale, 1.0)

    def error(measured):
        return float(sum(np.sqrt(np.mean((measured[rows[:, a], a] - predicted[keep][rows[:, a], a]) ** 2)) / scale[a]
                         for a in range(tau.shape[1]) if rows[:, a].any()))

    before, after = error(tau[keep]), error(moved)
    need = 2 * max(1, int(np.ceil(MAX_DELAY / found.period))) * MIN_BLOCKS
    per_axis = {}
    for a in np.flatnonzero(moving.sum(axis=0) >= need):
        own = estimate(t, tau[:, [a]], predicted[:, [a]], level=SHOWN_LEVEL)
        per_axis[int(a) + 1] = {"seconds": own.seconds, "interval_s": [own.low, own.high]}
    sign = np.sign(found.seconds)
    axes = [a for a, v in per_axis.items() if sign * v["interval_s"][0] > 0 and sign * v["interval_s"][1] > 0]
    channel = after < before
    return {"seconds": found.seconds, "interval_s": [found.low, found.high], "level": SHOWN_LEVEL,
            "error_before": before, "error_after": after, "channel": channel, "axes": axes if channel else [],
            "per_axis": per_axis,
            "rule": (f"the log's delay interval at {SHOWN_LEVEL:.0%} leaves out 0, moving the torque by it lowers the "
                     f"model's error, and the axis's own delay interval (its torque alone) at {SHOWN_LEVEL:.0%} "
                     "leaves out 0 on the same side")}


def verify(t: np.ndarray, tau: np.ndarray, predicted: np.ndarray, qd: np.ndarray, seconds: float) -> dict:
    """Whether moving the torque ``seconds`` earlier (:func:`shift`) lowers the model's held-out gap:
    the check a delay passes before its correction is advised (issue 88: on faultgen's own null
    PUMA 560 log an inertia the model lacks moved the peak to +3.7 ms, and `--delay auto` raised
    the held-out gap 0.0126 -> 0.0180).

    Parameters
    ----------
    t : ndarray (n,), s; tau, predicted : ndarray (n, N), N m; qd : ndarray (n, N), rad/s
        The log's times, measured torque, the model's torque and the speeds along the logged motion.
    seconds : float
        The delay, s (positive: the torque logged late).

    Returns
    -------
    dict
        ``seconds``, ``gap_before`` and ``gap_after`` (held-out total nrmse,
        :func:`faultgen.calibrate.criterion.gap`, both on the rows the moved log keeps and their
        :class:`~faultgen.calibrate.search.Split`: the model's torque on a row depends on the motion
        only, which the move keeps) and ``lowers`` (``gap_after < gap_before``).
    """
    t, tau, predicted = np.asarray(t, dtype=float), np.asarray(tau, dtype=float), np.asarray(predicted, dtype=float)
    keep, moved = moved_torque(t, tau, float(seconds))
    held_out = Split.of(t[keep], np.asarray(qd)[keep]).held_out
    before = criterion.gap(tau[keep], predicted[keep], held_out)["total_nrmse"]
    after = criterion.gap(moved, predicted[keep], held_out)["total_nrmse"]
    return {"seconds": float(seconds), "gap_before": before, "gap_after": after, "lowers": bool(after < before)}


def moved_torque(t: np.ndarray, tau: np.ndarray, seconds: float) -> tuple[np.ndarray, np.ndarray]:
    """The torque ``tau`` (n, N) sampled at ``t`` (n,) s moved ``seconds`` earlier (``tau(t + seconds)``,
    linear interpolation): the rows kept (n,) bool, those whose moved torque lies inside the log, and
    the moved torque on them (k, N)."""
    keep = (t + seconds >= t[0]) & (t + seconds <= t[-1])
    return keep, np.column_stack([np.interp(t[keep] + seconds, t, tau[:, a]) for a in range(tau.shape[1])])


def shift(data: measured_io.MeasuredData, seconds: float) -> measured_io.MeasuredData:
    """``data`` with its torque columns moved ``seconds`` earlier (``tau(t) <- tau_logged(t + seconds)``,
    linear interpolation: the correction of a torque logged ``seconds`` after the motion; negative:
    moved later). The rows whose corrected torque would lie outside the log are dropped; the
    motion, its derivatives and the other columns are kept as they are on the rows kept.

    Raises
    ------
    ValueError
        If ``seconds`` is not finite or leaves fewer than half of the log's rows.
    """
    seconds = float(seconds)
    t = np.asarray(data.t)
    span = float(t[-1] - t[0])
    if not np.isfinite(seconds) or abs(seconds) > span / 2:
        raise ValueError(f"--delay {seconds!r} s: expected a finite delay of at most half the log's {span:.3g} s")
    keep, tau = moved_torque(t, data.tau, seconds)

    def rows(a):
        return None if a is None else np.asarray(a)[keep]

    note = f"torque columns moved {1e3 * seconds:+.1f} ms (--delay); {int((~keep).sum())} rows at the end dropped"
    return replace(data, t=t[keep], q=rows(data.q), qd=rows(data.qd), qdd=rows(data.qdd), tau=tau,
                   joint_temperature=rows(data.joint_temperature), payload_mass=rows(data.payload_mass),
                   cycle=rows(data.cycle), notes=(*data.notes, note))


def _standardised(x: np.ndarray) -> np.ndarray:
    """Each column less its mean, over its standard deviation (a still column: zero)."""
    x = x - x.mean(axis=0)
    scale = x.std(axis=0)
    return np.where(scale > 0, x / np.where(scale > 0, scale, 1.0), 0.0)


def _products(a: np.ndarray, b: np.ndarray, k: int) -> np.ndarray:
    """Row ``i`` (times ``k .. n - k``), column ``j`` (lag ``j - k``): ``sum_axes a[i] b[i - lag]``."""
    n = a.shape[0]
    return np.column_stack([np.einsum("ij,ij->i", a[k:n - k], b[k - lag:n - k - lag]) for lag in range(-k, k + 1)])


def peak(c: np.ndarray) -> float:
    """The lag (samples, from ``-k``) of the largest of ``c`` (2k + 1,), to a fraction of a sample
    by the parabola through it and its neighbours (an end of the range: that end)."""
    k = (c.size - 1) // 2
    j = int(np.argmax(c))
    if 0 < j < c.size - 1:
        below, top, above = c[j - 1], c[j], c[j + 1]
        curvature = below - 2 * top + above
        if curvature < 0:
            return j - k + 0.5 * (below - above) / curvature
    return float(j - k)
