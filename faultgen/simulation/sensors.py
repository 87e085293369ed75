"""What the robot's monitoring records: sampling, sensor noise and load disturbance.

- Logging at 250 Hz (4 ms), as the thesis's data (ch. 6.3.2).
- Load disturbance: a zero-mean Gaussian torque on each arm joint, held for one logging period,
  with a standard deviation of 1 % of that axis's mean absolute torque (thesis ch. 3.3.2).
- Encoder noise: zero-mean Gaussian, 1e-4 rad standard deviation on every logged angle
  (thesis ch. 3.3.2, "the average accuracy of the encoder"). Logged speeds are the backward
  difference of the logged angles, as a drive computes speed from its encoder.

Every random draw comes from a generator seeded by (run seed, cycle index, stream), so a cycle's
noise does not depend on which other cycles a run records, and the same seed gives bit-identical
output.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

LOG_PERIOD = 0.004  # s (250 Hz)

_DISTURBANCE_STREAM = 0
_ENCODER_STREAM = 1


@dataclass(frozen=True)
class NoiseConfig:
    """Sensor noise and disturbance settings.

    Attributes
    ----------
    disturbance : float
        Standard deviation of the load disturbance as a fraction of each axis's mean absolute
        arm-side torque (0.01 = 1 %). 0 switches it off.
    encoder : float
        Standard deviation of the encoder noise in rad. 0 switches it off.

    Raises
    ------
    ValueError
        If a value is negative or not finite.
    """

    disturbance: float = 0.01
    encoder: float = 1e-4

    def __post_init__(self) -> None:
        for name in ("disturbance", "encoder"):
            value = getattr(self, name)
            if not np.isfinite(value) or value < 0:
                raise ValueError(f"{name} noise {value!r} must be a finite value >= 0")


def cycle_rng(seed: int, cycle: int, stream: int) -> np.random.Generator:
    """The random generator of one stream of one cycle of a run."""
    return np.random.default_rng([seed, cycle, stream])


def disturbance(seed: int, cycle: int, n_periods: int, sigma: np.ndarray) -> np.ndarray:
    """Load disturbance torque, ``ndarray of shape (n_periods, N)`` in N m at the arm side.

    ``sigma`` is the per-axis standard deviation, ``ndarray of shape (N,)`` in N m.
    """
    return cycle_rng(seed, cycle, _DISTURBANCE_STREAM).standard_normal((n_periods, sigma.size)) * sigma


def encoder(seed: int, cycle: int, angles: np.ndarray, sigma: float) -> np.ndarray:
    """Angles as the encoders report them: ``angles`` plus Gaussian noise of ``sigma`` rad.

    ``angles`` is an ``ndarray of shape (n, k)``; all channels share the cycle's encoder stream.
    """
    return angles + sigma * cycle_rng(seed, cycle, _ENCODER_STREAM).standard_normal(angles.shape)


def speed(angles: np.ndarray, first: np.ndarray, period: float = LOG_PERIOD) -> np.ndarray:
    """Backward-difference speed of logged angles, ``ndarray of shape (n, k)`` in rad/s.

    ``first`` (shape (k,)) is the speed reported for the first sample, which has no predecessor.
    """
    out = np.empty_like(angles)
    out[0] = first
    out[1:] = np.diff(angles, axis=0) / period
    return out


#: Bins of the remote-monitoring histograms (thesis ch. 5.3.1: 12 values per measurement).
HISTOGRAM_BINS = 12
#: The per-cycle histograms of :func:`cycle_features`.
HISTOGRAMS = ("angle_hist", "speed_hist", "torque_hist")


def histogram(values: np.ndarray, low: np.ndarray, high: np.ndarray, bins: int = HISTOGRAM_BINS) -> np.ndarray:
    """Fraction of samples in each of ``bins`` equal ranges of [low, high], per cycle and axis.

    Parameters
    ----------
    values : ndarray of shape (n_cycles, n_samples, N)
    low, high : ndarray of shape (N,)
        Range per axis; values outside it count in the first or last bin.

    Returns
    -------
    ndarray of shape (n_cycles, N, bins)
        Each row sums to 1.
    """
    fraction = (values - low) / (high - low)
    index = np.clip((fraction * bins).astype(int), 0, bins - 1)
    return _bin_counts(index, bins) / values.shape[1]


def _bin_counts(index: np.ndarray, bins: int) -> np.ndarray:
    """Samples per bin of each cycle and axis, (n_cycles, n_axes, bins), from bin indices
    (n_cycles, n_samples, n_axes) within 0 .. bins - 1."""
    n_cycles, _, n_axes = index.shape
    offset = (np.arange(n_cycles)[:, None, None] * n_axes + np.arange(n_axes)) * bins
    counts = np.bincount((index + offset).ravel(), minlength=n_cycles * n_axes * bins)
    return counts.reshape(n_cycles, n_axes, bins)


#: Fine bins of the per-cycle torque counts (:func:`torque_counts`), each 1/1200 of the peak motor
#: torque: 12 per percent of it, so that 12 equal bins over 0 .. any whole percent of the peak
#: torque are whole groups of them (the detection's binning, ``analysis.benchmark.detection_table``).
TORQUE_COUNT_BINS = 1200


def torque_counts(tau_m: np.ndarray, torque_limit: np.ndarray) -> np.ndarray:
    """Samples of each cycle per fine bin of |motor torque|, the record detection bins from.

    |tau_m| is taken as a dataset stores it (float32), so the counts of a run recorded without
    signals equal those computed again from a stored run's signals, bit for bit.

    Parameters
    ----------
    tau_m : ndarray of shape (n_cycles, n_samples, N)
        Logged motor torque, N m at the motor side.
    torque_limit : ndarray of shape (N,)
        Peak motor torque, N m: the range 0 .. peak is cut into :data:`TORQUE_COUNT_BINS` equal
        bins; larger values count in the last.

    Returns
    -------
    ndarray of shape (n_cycles, N, TORQUE_COUNT_BINS)
        Unsigned integer counts (the smallest type holding ``n_samples``); each row sums to
        ``n_samples``.
    """
    magnitude = np.abs(np.asarray(tau_m, dtype=np.float32)).astype(np.float64)
    scale = TORQUE_COUNT_BINS / np.asarray(torque_limit, dtype=np.float64)
    index = np.minimum((magnitude * scale).astype(np.int64), TORQUE_COUNT_BINS - 1)
    return _bin_counts(index, TORQUE_COUNT_BINS).astype(np.min_scalar_type(index.shape[1]))


def cycle_features(q_a: np.ndarray, qd_a: np.ndarray, tau_m: np.ndarray, joint_range: np.ndarray,
                   speed_limit: np.ndarray, torque_limit: np.ndarray) -> dict[str, np.ndarray]:
    """Per-cycle aggregates of a run, as a robot's remote monitoring reports them.

    Parameters
    ----------
    q_a, qd_a : ndarray of shape (n_cycles, n_samples, N)
        Logged arm angles (rad) and speeds (rad/s).
    tau_m : ndarray of shape (n_cycles, n_samples, N)
        Logged motor torque, N m at the motor side.
    joint_range : ndarray of shape (N, 2)
        Joint limits, rad: the design range of the angle histogram.
    speed_limit : ndarray of shape (N,)
        Largest arm speed, rad/s: the design maximum of the speed histogram.
    torque_limit : ndarray of shape (N,)
        Peak motor torque, N m: the design maximum of the torque histogram.

    Returns
    -------
    dict of ndarray
        ``mean_abs_torque``, ``rms_torque`` (n_cycles, N) in N m (thesis ch. 6.3.2: the mean of
        absolute torque per cycle); ``average_speed`` (rad/s) and ``average_load_torque`` (N m),
        (n_cycles, N), :func:`duty`; ``angle_hist``, ``speed_hist``, ``torque_hist``
        (n_cycles, N, 12): fraction of the cycle's samples in each twelfth of the design range
        (angle from its lower to its upper limit; |speed| and |torque| from 0 to their design
        maximum, larger values in the last bin; thesis ch. 5.3.1).
    """
    zeros = np.zeros(len(joint_range))
    return {
        "mean_abs_torque": np.mean(np.abs(tau_m), axis=1),
        "rms_torque": np.sqrt(np.mean(tau_m**2, axis=1)),
        "angle_hist": histogram(q_a, joint_range[:, 0], joint_range[:, 1]),
        "speed_hist": histogram(np.abs(qd_a), zeros, speed_limit),
        "torque_hist": histogram(np.abs(tau_m), zeros, torque_limit),
        **duty(qd_a, tau_m),
    }


def daily_features(features: dict[str, np.ndarray], per_day: int) -> dict[str, np.ndarray]:
    """The remote-monitoring record of each day from its cycles' :func:`cycle_features` (thesis
    ch. 5.3.2): of each ``per_day`` consecutive cycles the largest value of every feature, histogram
    bins too, each histogram then scaled back to a sum of 1. A simulated fleet's daily records
    (:func:`faultgen.simulation.results.daily_record`) and an imported log's record
    (:mod:`faultgen.data.fleetlogs`, a log's cycles as one day) both come from here.

    Parameters
    ----------
    features : dict of ndarray
        Per-cycle features, each of shape (n_cycles, ...).
    per_day : int
        Cycles per day; trailing cycles that do not fill a day are dropped.

    Returns
    -------
    dict of ndarray
        The same names, each of shape (n_cycles // per_day, ...).
    """
    out = {name: by_day(value, per_day) for name, value in features.items()}
    for name in HISTOGRAMS:
        if name in out:
            out[name] = out[name] / out[name].sum(axis=-1, keepdims=True)
    return out


def by_day(values: np.ndarray, per_day: int, reduce=np.max) -> np.ndarray:
    """``reduce`` (default the largest value) over each ``per_day`` consecutive rows of ``values``
    (n_cycles, ...) -> (n_cycles // per_day, ...); trailing rows that do not fill a day are dropped."""
    n_days = len(values) // per_day
    return reduce(np.asarray(values)[: n_days * per_day].reshape(n_days, per_day, *np.shape(values)[1:]), axis=1)


#: Life exponent ``p`` of the average load torque: 10/3, that of roller bearings (ISO 281), the
#: cross-roller output bearings of robot reducers (Harmonic Drive SHG manual, table 42.4).
LOAD_EXPONENT = 10.0 / 3.0
#: The per-cycle duty of each axis that :func:`duty` computes, what the speed and torque
#: indicators of thesis ch. 5.3.1 are made from (``analysis.features.duty_indicators``).
DUTY = ("average_speed", "average_load_torque")


def duty(qd_a: np.ndarray, tau_m: np.ndarray, exponent: float = LOAD_EXPONENT) -> dict[str, np.ndarray]:
    """Average speed and average load torque of each cycle and axis, the duty a gearbox is sized by.

    The thesis's speed and torque indicators are undisclosed "invertible functions of actual speed,
    actual torque, production time and production time difference" (ch. 5.3.1, Table 5.1).
    faultgen records the two quantities by which reducer and bearing makers rate life under a
    varying duty: the average output speed ``n_av = mean |qd_a|`` (Harmonic Drive SHG manual,
    eq. 42.2) and the average load torque ``T_av = (mean(|qd_a| |tau_m|^p) / n_av)^(1/p)``, the
    speed-weighted mean load of ISO 281 with ``p`` = :data:`LOAD_EXPONENT`. A worn axis needs more
    torque at the same speeds, so ``T_av`` rises with its friction, more at its loaded moments
    than ``mean |tau_m|`` does.

    Parameters
    ----------
    qd_a : ndarray of shape (n_cycles, n_samples, N)
        Logged arm speed, rad/s (the gearbox's output).
    tau_m : ndarray of shape (n_cycles, n_samples, N)
        Logged motor torque, N m at the motor side.
    exponent : float, default=LOAD_EXPONENT

    Returns
    -------
    dict of ndarray of shape (n_cycles, N)
        ``average_speed`` in rad/s and ``average_load_torque`` in N m at the motor side. An axis
        that does not move in a cycle has ``average_speed`` 0 and a time-weighted mean load.
    """
    speed, load = np.abs(qd_a), np.abs(tau_m) ** exponent
    average_speed = speed.mean(axis=1)
    weighted = (speed * load).mean(axis=1)
    mean_load = np.divide(weighted, average_speed, out=load.mean(axis=1), where=average_speed > 0)
    return {"average_speed": average_speed, "average_load_torque": mean_load ** (1.0 / exponent)}
