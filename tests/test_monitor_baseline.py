"""The baseline stage (:class:`faultgen.monitor.baseline.Baseline`) on its own: what it learns of a
program's normal operation, checked against independent least-squares fits."""

import numpy as np
import pytest

from faultgen.monitor.baseline import SHARED, Baseline
from faultgen.monitor.scoring import Settings

N_AXES, N_FEATURES = 2, 6


def _logs(rng, n: int, offset: np.ndarray, slope: np.ndarray, first: int = 0):
    """``n`` logs of residual ``offset + slope (T - 25) + noise`` at temperatures T of 20-30 deg C."""
    temperature = rng.uniform(20.0, 30.0, n)
    E = offset + np.outer(temperature - 25.0, slope) + rng.normal(0.0, 0.1, (n, N_FEATURES))
    C = np.column_stack([temperature, np.full(n, 10.0)])  # payload constant: not a regressor
    return [(f"{first + i:03d}", e, c) for i, (e, c) in enumerate(zip(E, C))], E, C


def test_the_offset_and_slope_are_an_ordinary_least_squares_fit_on_the_temperature():
    rng = np.random.default_rng(3)
    baseline = Baseline(Settings(protocol="own", train=20), N_AXES)
    baseline.training, E, C = _logs(rng, 20, rng.normal(0, 1, N_FEATURES), rng.normal(0, 0.2, N_FEATURES))
    stamps, R, error, common = baseline.fit()
    X = np.column_stack([np.ones(20), C[:, 0] - C[:, 0].mean()])  # intercept at the mean temperature
    solution = np.linalg.lstsq(X, E, rcond=None)[0]
    np.testing.assert_allclose(baseline.mean_, solution[0], atol=1e-12)
    np.testing.assert_allclose(baseline.slope_[0], solution[1], atol=1e-12)
    assert baseline.regressors_.tolist() == [0] and error is None and baseline.training == []
    np.testing.assert_allclose(R, E - X @ solution, atol=1e-12)
    np.testing.assert_allclose(baseline.scale_, np.sqrt((R**2).sum(axis=0) / (20 - 2)), rtol=1e-12)
    assert stamps[0] == "000" and set(common) == {*SHARED, "R", "dof"} and common["dof"] == 20 - 1 - 1
    # a log at the learned offset and slope standardises to 0, and its prediction factor is sqrt(1 + 1/m) at the mean
    at_mean = np.array([C[:, 0].mean(), 10.0])
    np.testing.assert_allclose(baseline.standardise(solution[0], at_mean), 0.0, atol=1e-12)
    assert baseline.prediction_factor(at_mean) == pytest.approx(np.sqrt(1 + 1 / 20))


def test_a_borrowing_baseline_learns_its_offset_alone_as_the_mean_less_the_slopes():
    rng = np.random.default_rng(4)
    first = Baseline(Settings(protocol="own", train=20), N_AXES)
    slope = rng.normal(0, 0.2, N_FEATURES)
    first.training = _logs(rng, 20, np.zeros(N_FEATURES), slope)[0]
    common = first.fit()[3]
    later = Baseline(first.settings, N_AXES, borrowed=common)
    assert later.learning_logs == later.relearn_logs == 5  # a quarter of train, at least 5
    later.training, E, C = _logs(rng, 5, np.full(N_FEATURES, 3.0), slope, first=20)
    R = later.fit()[1]
    assert later.pca is first.pca and later.slope_ is first.slope_ and later.learned_ == 5
    own = E - np.outer(C[:, 0] - first.condition_mean_[0], first.slope_[0])  # independent: the slopes' part taken out
    np.testing.assert_allclose(later.mean_, own.mean(axis=0), atol=1e-12)
    np.testing.assert_allclose(R, own - own.mean(axis=0), atol=1e-12)
    # after maintenance the same rule (learn_offset) on other logs
    _, E2, C2 = _logs(rng, 5, np.full(N_FEATURES, -1.0), slope)
    later.learn_offset(E2, C2)
    np.testing.assert_allclose(later.mean_, (E2 - np.outer(C2[:, 0] - first.condition_mean_[0], first.slope_[0])).mean(0),
                               atol=1e-12)


def test_an_unworn_axis_wear_error_sets_its_width_and_observability():
    rng = np.random.default_rng(5)
    signatures = np.zeros((N_AXES, N_FEATURES))
    signatures[0, 4], signatures[1, 5] = 0.05, 0.0005  # axis 2's friction torque barely moves with wear
    baseline = Baseline(Settings(train=20), N_AXES, signatures)
    baseline.training = _logs(rng, 20, np.zeros(N_FEATURES), np.zeros(N_FEATURES))[0]
    error = baseline.fit()[2]
    np.testing.assert_allclose(error, baseline.dispersion_ * baseline.scale_[4:] / np.abs(signatures[[0, 1], [4, 5]]),
                               rtol=1e-12)
    np.testing.assert_allclose(baseline.width_, 2 * 1.6448536 * error, rtol=1e-6)
    assert baseline.observable_.tolist() == [True, False]
