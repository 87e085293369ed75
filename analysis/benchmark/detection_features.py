"""What detection sees of a run (thesis ch. 3.4): its per-cycle |motor torque| counts, binned into 12
histogram bins over the training data's range, grouped into samples (a cycle or a period of cycles),
and their KL divergence against a reference histogram."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from faultgen.data import reader
from faultgen.simulation import sensors


def group_cycles(cycles: np.ndarray, period: int | None) -> np.ndarray:
    """Group index of each recorded cycle: ``(cycle - 1) // period`` (e.g. the hour, for period 60
    one-minute cycles), or one group per recorded cycle when ``period`` is None."""
    return np.arange(len(cycles)) if period is None else (cycles - 1) // period


def torque_record(run: reader.Run) -> np.ndarray | StoredHistograms:
    """What detection bins a run's |motor torque| from: its per-cycle counts in fine bins of
    0 .. peak motor torque (``torque_counts``, (n_cycles, 6, 1200),
    :func:`faultgen.simulation.sensors.torque_counts`), read as stored, or computed from the
    stored signals for a file written before the counts existed, over the peak motor torque the run
    stored (:attr:`faultgen.data.reader.Run.drivetrain`); the two are equal bit for bit for the same
    run. A run that has neither (a daily record, or an old file without signals)
    gives its 12-bin ``torque_hist`` (:class:`StoredHistograms`).

    Raises
    ------
    faultgen.data.dataset.DatasetError
        If the run has no counts and lacks ``tau_m`` though it says it has signals, or lacks
        ``torque_hist``.
    """
    if run.has("torque_counts"):  # the stored counts: a small array, where the signals are the largest part
        return run.array("torque_counts")
    if run.has_signals:
        tau_m = run.signal("tau_m")
        run.forget("tau_m")  # the largest array of a file: not kept
        return sensors.torque_counts(tau_m, run.drivetrain.motor_torque_limit)
    return StoredHistograms(run.array("torque_hist"))


def detection_scale(counts: list[np.ndarray]) -> np.ndarray:
    """The range of detection's 12 torque bins per axis, as fine bins of :func:`torque_record`
    per detection bin: the training data's largest |motor torque| rounded up to the next whole
    percent of the peak motor torque (thesis ch. 3.4 normalises by the largest torque; rounded so
    that a run's stored counts give the same bins as its signals).

    Parameters
    ----------
    counts : list of ndarray of shape (n_cycles, 6, 1200)
        The training runs' torque counts.

    Returns
    -------
    ndarray of int, shape (6,)
        Fine bins per detection bin, 1 .. 100 (the scale in percent of peak torque).
    """
    occupied = np.any(np.concatenate(counts) > 0, axis=0)  # (6, 1200)
    highest = sensors.TORQUE_COUNT_BINS - 1 - np.argmax(occupied[:, ::-1], axis=1)
    return highest // sensors.HISTOGRAM_BINS + 1


def binned_torque(counts: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """12-bin |torque| histograms per cycle, (n_cycles, 6, 12), from fine counts (n_cycles, 6,
    1200) and ``scale`` fine bins per bin (:func:`detection_scale`); larger values in the last."""
    counts = counts.astype(np.int64)
    hist = np.stack([np.add.reduceat(counts[:, axis], np.arange(sensors.HISTOGRAM_BINS) * step, axis=-1)
                     for axis, step in enumerate(scale)], axis=1)
    return hist / counts.sum(axis=-1, keepdims=True)


@dataclass(frozen=True)
class StoredHistograms:
    """The per-cycle torque histograms a run recorded without signals or counts (``torque_hist``,
    (n, 6, 12), binned over 0 .. the motor's peak torque), standing in for its counts in detection."""

    hist: np.ndarray

    def __getitem__(self, rows) -> StoredHistograms:
        """The histograms of some cycles (``rows``, as for an array of counts)."""
        return StoredHistograms(self.hist[rows])


def sample_histograms(torque: np.ndarray | StoredHistograms, cycles: np.ndarray, scale: np.ndarray | None,
                period: int | None) -> tuple[np.ndarray, np.ndarray]:
    """12-bin |torque| histograms per sample (n_samples, 6, 12), a sample being a recorded cycle or
    a ``period`` of them, and per recorded cycle the index of its sample. ``torque`` is a
    :func:`torque_record`; stored 12-bin histograms are used as they are (``scale`` unused)."""
    hist = torque.hist if isinstance(torque, StoredHistograms) else binned_torque(torque, scale)
    groups = group_cycles(cycles, period)
    _, index = np.unique(groups, return_inverse=True)
    return np.stack([hist[index == g].mean(axis=0) for g in range(index.max() + 1)]), index


def kl_features(torque: np.ndarray, cycles: np.ndarray, scale: np.ndarray, period: int | None,
                 reference: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """KL divergence per axis of the (grouped) |torque| histograms against the run's first sample
    (thesis ch. 3.4), or against a fixed ``reference`` histogram (6, 12).

    Returns the features (n_samples, 6) and, per recorded cycle, the index of its sample.
    """
    from analysis.features import HistogramKL, kl_divergence

    grouped, index = sample_histograms(torque, cycles, scale, period)
    if reference is None:
        return HistogramKL(reference="first").fit_transform(grouped), index
    return kl_divergence(grouped, reference[None]), index
