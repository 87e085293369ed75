"""The remote-monitoring histograms and the detection's torque counts against numpy.histogram."""

import numpy as np

from faultgen.simulation import sensors


def test_histograms_and_torque_counts_equal_numpy_histogram():
    rng = np.random.default_rng(3)
    values = rng.uniform(-1.0, 5.0, size=(4, 250, 6))  # some outside [0, 4]: counted in the end bins
    low, high = np.zeros(6), np.full(6, 4.0)
    hist = sensors.histogram(values, low, high)
    counts = sensors.torque_counts(values, high)
    assert hist.shape == (4, 6, 12) and counts.shape == (4, 6, sensors.TORQUE_COUNT_BINS)
    assert counts.dtype == np.uint8  # the smallest type holding 250 samples
    for cycle in range(4):
        for axis in range(6):
            inside = np.clip(values[cycle, :, axis], 0.0, np.nextafter(4.0, 0))
            expected, _ = np.histogram(inside, bins=12, range=(0.0, 4.0))
            np.testing.assert_allclose(hist[cycle, axis] * 250, expected, rtol=0, atol=1e-9)
            magnitude = np.minimum(np.abs(values[cycle, :, axis].astype(np.float32)), np.nextafter(4.0, 0))
            expected, _ = np.histogram(magnitude, bins=sensors.TORQUE_COUNT_BINS, range=(0.0, 4.0))
            np.testing.assert_array_equal(counts[cycle, axis], expected)
