"""KL divergence, HistogramKL, Difference, WindowConcat and cycle_statistics against hand values."""

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.exceptions import NotFittedError
from sklearn.utils.estimator_checks import check_estimator

from analysis.features import (
    Difference,
    HistogramKL,
    WindowConcat,
    cycle_statistics,
    duty_indicators,
    estimates_from_indicators,
    kl_divergence,
)

LOG2_3 = np.log2(3.0)


def test_kl_two_bins_by_hand():
    p, q = [0.5, 0.5], [0.25, 0.75]
    # 0.5 log2(0.5 / 0.25) + 0.5 log2(0.5 / 0.75) = 0.5 + 0.5 (1 - log2 3)
    assert kl_divergence(p, q, eps=0) == pytest.approx(1 - 0.5 * LOG2_3, rel=1e-14)
    nats = 0.5 * np.log(2) + 0.5 * np.log(2 / 3)
    assert kl_divergence(p, q, eps=0, unit="nats") == pytest.approx(nats, rel=1e-14)
    assert kl_divergence(q, p, eps=0) == pytest.approx(0.25 * np.log2(0.5) + 0.75 * np.log2(1.5), rel=1e-14)
    # The default smoothing moves a histogram without empty bins by ~1e-6 only.
    assert kl_divergence(p, q) == pytest.approx(1 - 0.5 * LOG2_3, rel=1e-5)


def test_kl_zero_for_identical_and_non_negative():
    rng = np.random.default_rng(0)
    h = rng.dirichlet(np.full(12, 0.3), size=(200, 6))  # many nearly empty bins
    h[:, :, 0] = 0.0  # and truly empty ones
    h /= h.sum(axis=-1, keepdims=True)
    assert np.all(kl_divergence(h, h) == 0.0)
    assert np.all(kl_divergence(h, h, eps=0) == 0.0)
    d = kl_divergence(h, h[::-1])
    assert d.shape == (200, 6) and np.all(d >= 0) and np.all(np.isfinite(d))
    assert kl_divergence(h, h[0]).shape == (200, 6)  # the reference broadcasts


def test_kl_empty_bins_as_documented():
    p, q = np.array([0.5, 0.5]), np.array([1.0, 0.0])
    assert kl_divergence(p, q, eps=0) == np.inf  # eq. 5.4 unsmoothed: empty reference bin
    assert kl_divergence(q, p, eps=0) == pytest.approx(1.0)  # 0 log 0 = 0: only log2(1 / 0.5)
    eps = 1e-3
    ps, qs = (p + eps) / (1 + 2 * eps), (q + eps) / (1 + 2 * eps)
    assert kl_divergence(p, q, eps=eps) == pytest.approx(np.sum(ps * np.log2(ps / qs)), rel=1e-14)
    # Finite and large: about 0.5 log2(0.5 / eps) for the empty reference bin.
    assert 8 < kl_divergence(p, q) < 10


def test_kl_errors_name_index_and_value():
    good = np.full((3, 4), 0.25)
    bad = good.copy()
    bad[2] = [0.2, 0.2, 0.2, 0.3]
    with pytest.raises(ValueError, match=r"q\[2\] sums to 0\.9.* expected 1"):
        kl_divergence(good, bad)
    bad = good.copy()
    bad[1] = [0.5, -0.1, 0.3, 0.3]
    with pytest.raises(ValueError, match=r"p\[1, 1\] = -0\.1 is negative"):
        kl_divergence(bad, good)
    with pytest.raises(ValueError, match="at least 2 bins"):
        kl_divergence([1.0], [1.0])
    with pytest.raises(ValueError, match="4 bins and q has 2"):
        kl_divergence(good, [0.5, 0.5])
    with pytest.raises(ValueError, match="not finite"):
        kl_divergence([np.nan, 1.0], [0.5, 0.5])
    with pytest.raises(ValueError, match="eps = -1"):
        kl_divergence(good, good, eps=-1)
    with pytest.raises(ValueError, match="unit = 'dits'"):
        kl_divergence(good, good, unit="dits")
    kl_divergence([0.5 + 5e-7, 0.5], [0.5, 0.5])  # within the 1e-6 tolerance


# Three samples of two 2-bin histograms.
HIST = np.array([
    [[0.5, 0.5], [1.0, 0.0]],
    [[0.25, 0.75], [0.5, 0.5]],
    [[0.5, 0.5], [0.5, 0.5]],
])


def test_histogram_kl_first_and_previous_by_hand():
    a = 1 - 0.5 * LOG2_3                                # D([.5 .5] || [.25 .75])
    b = 0.25 * np.log2(0.5) + 0.75 * np.log2(1.5)       # D([.25 .75] || [.5 .5])
    first = HistogramKL(reference="first", eps=0).fit_transform(HIST)
    np.testing.assert_allclose(first, [[0, 0], [b, np.inf], [0, np.inf]], rtol=1e-14)
    previous = HistogramKL(reference="previous", eps=0).fit_transform(HIST)
    np.testing.assert_allclose(previous, [[0, 0], [b, np.inf], [a, 0]], rtol=1e-14)
    # Default smoothing: the same where no bin is empty, finite where the reference has one.
    smoothed = HistogramKL().fit_transform(HIST)
    np.testing.assert_allclose(smoothed[:, 0], [0, b, 0], atol=1e-5)
    assert np.all(np.isfinite(smoothed))
    # The reference is that of fit: new samples are compared with the fitted first sample.
    model = HistogramKL(eps=0, unit="nats").fit(HIST[1:])
    np.testing.assert_allclose(model.transform(HIST[:1]), [[a * np.log(2), np.log(2)]], rtol=1e-12)
    np.testing.assert_array_equal(model.reference_, HIST[1])


def test_histogram_kl_conventions_and_errors():
    # check_estimator cannot run: every one of its checks feeds 2-D data, HistogramKL needs 3-D.
    est = HistogramKL(reference="previous", eps=1e-4)
    assert est.get_params() == {"reference": "previous", "eps": 1e-4, "unit": "bits"}
    assert clone(est).get_params() == est.get_params()
    assert est.set_params(reference="first") is est and est.reference == "first"
    with pytest.raises(NotFittedError):
        est.transform(HIST)
    assert est.fit(HIST) is est and est.n_features_in_ == 2 and est.n_bins_ == 2
    assert not hasattr(HistogramKL(), "reference_")  # __init__ only stores
    with pytest.raises(ValueError, match="reference = 'last'"):
        HistogramKL(reference="last").fit(HIST)
    with pytest.raises(ValueError, match=r"shape \(n_samples, n_features, n_bins\)"):
        est.transform(HIST[0])
    with pytest.raises(ValueError, match="fitted on 2 features of 2 bins"):
        est.transform(np.full((2, 2, 4), 0.25))
    bad = HIST.copy()
    bad[2, 1] = [0.6, 0.6]
    with pytest.raises(ValueError, match=r"X\[2, 1\] sums to 1\.2"):
        est.transform(bad)
    with pytest.raises(ValueError, match="at least 2 bins"):
        HistogramKL().fit(np.ones((3, 2, 1)))


def test_difference_values():
    X = np.array([[1.0, 10.0], [3.0, 7.0], [2.0, 7.5]])
    est = Difference()
    assert est.fit(X) is est
    np.testing.assert_array_equal(est.transform(X), [[0, 0], [2, 3], [1, 0.5]])
    assert list(est.get_feature_names_out()) == ["x0", "x1"]
    with pytest.raises(ValueError, match="2 features"):
        est.transform(X[:, :1])


def test_window_concat_values():
    X = np.array([[1.0, 10.0], [2.0, 20.0], [3.0, 30.0], [4.0, 40.0]])
    out = WindowConcat(width=3).fit_transform(X)
    np.testing.assert_array_equal(out, [
        [1, 10, 1, 10, 1, 10],   # window before the first sample: edge-padded
        [1, 10, 1, 10, 2, 20],
        [1, 10, 2, 20, 3, 30],   # [X_(k-2), X_(k-1), X_k]
        [2, 20, 3, 30, 4, 40],
    ])
    assert WindowConcat(width=5).fit_transform(X).shape == (4, 10)
    np.testing.assert_array_equal(WindowConcat(width=1).fit_transform(X), X)
    names = WindowConcat(width=2).fit(X).get_feature_names_out(["a", "b"])
    assert list(names) == ["a_lag1", "b_lag1", "a_lag0", "b_lag0"]
    for width in (0, 2.5, True):
        with pytest.raises(ValueError, match="width = "):
            WindowConcat(width=width).fit(X)


def test_cycle_statistics_by_hand():
    signal = np.zeros((2, 4, 6))
    signal[0, :, 0] = [1.0, -3.0, 2.0, -2.0]
    signal[1, :, 5] = [-4.0, 0.0, 0.0, 0.0]
    s = cycle_statistics(signal)
    assert set(s) == {"mean_abs", "rms", "max_abs"} and all(v.shape == (2, 6) for v in s.values())
    assert s["mean_abs"][0, 0] == 2.0 and s["rms"][0, 0] == pytest.approx(np.sqrt(18 / 4))
    assert s["max_abs"][0, 0] == 3.0 and s["max_abs"][1, 5] == 4.0 and s["rms"][1, 5] == 2.0
    assert s["mean_abs"][1, 0] == 0.0
    with pytest.raises(ValueError, match="shape"):
        cycle_statistics(signal[0])
    signal[1, 2, 3] = np.inf
    with pytest.raises(ValueError, match=r"signal\[1, 2, 3\]"):
        cycle_statistics(signal)


# Difference and WindowConcat read neighbouring rows: by design their output changes when the
# rows are reordered or transformed one at a time, which these two checks test for.
ORDER_DEPENDENT = {
    "check_methods_sample_order_invariance": "rows are a time series",
    "check_methods_subset_invariance": "rows are a time series",
}


@pytest.mark.parametrize("estimator", [Difference(), WindowConcat(), WindowConcat(width=5)], ids=repr)
def test_scikit_learn_estimator_checks(estimator):
    results = check_estimator(estimator, on_fail=None, expected_failed_checks=ORDER_DEPENDENT)
    status = {r["check_name"]: r["status"] for r in results}
    assert [n for n, s in status.items() if s == "failed"] == []
    assert all(status[n] == "xfail" for n in ORDER_DEPENDENT)


def test_speed_window_mean_averages_only_the_samples_inside_the_window():
    from analysis.features import speed_window_mean

    rng = np.random.default_rng(3)
    torque = rng.normal(size=(4, 50, 3))
    speed = rng.uniform(-150, 150, size=(4, 50, 3))
    speed[2, :, 1] = 10.0  # axis 2 of cycle 3 never reaches the window
    got = speed_window_mean(torque, speed, 50.0, 120.0)
    for c in range(4):
        for a in range(3):
            picked = [abs(torque[c, s, a]) for s in range(50) if 50.0 <= abs(speed[c, s, a]) <= 120.0]
            if picked:
                assert got[c, a] == pytest.approx(sum(picked) / len(picked), rel=1e-12)
            else:
                assert np.isnan(got[c, a])
    assert np.isnan(got[2, 1])
    with pytest.raises(ValueError, match=r"speed window \[120.0, 50.0\] rad/s: expected 0 <= low < high"):
        speed_window_mean(torque, speed, 120.0, 50.0)
    with pytest.raises(ValueError, match="same shape"):
        speed_window_mean(torque, speed[:, :10], 50.0, 120.0)


def test_duty_indicators_by_hand_and_back():
    p = 10.0 / 3.0
    speed = np.array([[1.0, 0.0], [3.0, 2.0]])
    torque = np.array([[2.0, 5.0], [4.0, 6.0]])
    s, t = duty_indicators(speed, torque)
    np.testing.assert_allclose(s, [[1.0, 0.0], [2.0, 1.0]])
    assert t[0, 0] == pytest.approx(2.0) and np.isnan(t[0, 1])  # axis 2 has not moved yet
    assert t[1, 0] == pytest.approx(((1 * 2.0**p + 3 * 4.0**p) / 4) ** (1 / p))
    assert t[1, 1] == pytest.approx(6.0)  # only its moving sample counts
    n, tau = estimates_from_indicators(s, t)
    np.testing.assert_allclose(n, speed, atol=1e-15)
    assert tau[0, 0] == pytest.approx(2.0) and np.isnan(tau[0, 1]) and tau[1, 1] == pytest.approx(6.0)
    # unequal production time: a day of twice the production weighs twice
    s, _ = duty_indicators(speed, torque, production_time=[1.0, 2.0])
    assert s[1, 0] == pytest.approx((1.0 + 3.0 * 2) / 3)


def test_estimates_from_indicators_invert_a_long_record():
    rng = np.random.default_rng(5)
    speed, torque = rng.uniform(0.1, 2.0, (1200, 6)), rng.uniform(1.0, 50.0, (1200, 6))
    hours = rng.uniform(0.5, 2.0, 1200)
    n, tau = estimates_from_indicators(*duty_indicators(speed, torque, hours), hours)
    np.testing.assert_allclose(n, speed, rtol=1e-10)
    np.testing.assert_allclose(tau, torque, rtol=1e-6)  # the docstring's figure: 3e-7


def test_duty_indicators_refuse_bad_input_naming_it():
    good = np.ones((3, 6))
    with pytest.raises(ValueError, match=r"average_speed\[1, 4\] = -0.5: expected a finite value >= 0"):
        bad = good.copy()
        bad[1, 4] = -0.5
        duty_indicators(bad, good)
    with pytest.raises(ValueError, match=r"same shape \(n_samples, n_axes\), got \(3, 6\) and \(2, 6\)"):
        duty_indicators(good, good[:2])
    with pytest.raises(ValueError, match="production_time must hold 3 finite values > 0"):
        duty_indicators(good, good, production_time=[1.0, 0.0, 1.0])
    with pytest.raises(ValueError, match=r"torque_indicator\[0, 0\] = -1.0"):
        estimates_from_indicators(good, -good)
