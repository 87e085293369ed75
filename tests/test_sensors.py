"""The remote-monitoring histograms and the detection's torque counts against numpy.histogram."""

import numpy as np
import pytest

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


def test_duty_is_the_bearing_makers_mean_load_of_a_stepped_duty_cycle():
    # a duty cycle of three steps (speed n_i rad/s, torque F_i N m, time t_i samples), the stepped-load
    # form of the catalogues: n_av = sum(|n_i| t_i) / sum(t_i), T_av = (sum(F_i^p |n_i| t_i) / sum(|n_i| t_i))^(1/p)
    steps = [(2.0, 10.0, 100), (-0.5, -30.0, 50), (0.0, 80.0, 100)]  # standing still under 80 N m: no life used
    qd = np.concatenate([np.full(t, n) for n, _, t in steps])
    tau = np.concatenate([np.full(t, f) for _, f, t in steps])
    duty = sensors.duty(np.broadcast_to(qd[None, :, None], (1, 250, 6)), np.broadcast_to(tau[None, :, None], (1, 250, 6)))
    p = 10.0 / 3.0
    revolutions = 2.0 * 100 + 0.5 * 50
    assert duty["average_speed"][0, 0] == pytest.approx(revolutions / 250)
    assert duty["average_load_torque"][0, 0] == pytest.approx(((10.0**p * 200 + 30.0**p * 25) / revolutions) ** (1 / p))
    assert duty["average_load_torque"][0, 0] < 30.0  # between the moving steps' loads, the standing 80 N m ignored
    # an axis that never moves: speed 0 and the time-weighted mean load (no division by zero)
    still = sensors.duty(np.zeros((1, 4, 6)), np.full((1, 4, 6), 3.0))
    assert still["average_speed"][0, 2] == 0.0 and still["average_load_torque"][0, 2] == pytest.approx(3.0)
