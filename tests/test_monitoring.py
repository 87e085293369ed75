"""PCAMonitor and detect_onset: limits by hand, false-alarm rates, a single-feature fault."""

import numpy as np
import pytest
from scipy import stats
from sklearn.base import clone
from sklearn.exceptions import NotFittedError
from sklearn.pipeline import make_pipeline
from sklearn.utils.estimator_checks import check_estimator

from analysis.features import Difference, WindowConcat
from analysis.monitoring import PCAMonitor, detect_onset, varying_columns

# A fixed small training set: 8 samples of 4 features with different scales and correlations.
SMALL = np.array([
    [1.0, 10.0, 0.3, 5.0],
    [2.0, 19.0, 0.1, 4.0],
    [3.0, 33.0, 0.4, 6.5],
    [4.0, 41.0, 0.2, 5.5],
    [5.0, 48.0, 0.6, 7.0],
    [6.0, 62.0, 0.5, 5.0],
    [7.0, 69.0, 0.9, 8.0],
    [8.0, 81.0, 0.7, 6.0],
])


def gaussian(rng, mixing, n):
    """Correlated Gaussian 'normal operation': n samples of x = w A + offset, w ~ N(0, I)."""
    return rng.normal(size=(n, mixing.shape[0])) @ mixing + np.arange(mixing.shape[1]) * 3.0


def test_limits_equal_the_formulas_by_hand():
    m, k, alpha = SMALL.shape[0], 2, 0.05
    monitor = PCAMonitor(n_components=k, alpha=alpha).fit(SMALL)
    # Independent route: the correlation matrix by np.corrcoef, its eigenvalues by eigvalsh.
    lam = np.sort(np.linalg.eigvalsh(np.corrcoef(SMALL, rowvar=False)))[::-1]
    np.testing.assert_allclose(monitor.eigenvalues_, lam, atol=1e-12)
    np.testing.assert_allclose(monitor.mean_, SMALL.mean(axis=0))
    np.testing.assert_allclose(monitor.scale_, SMALL.std(axis=0, ddof=1))

    t2_hand = k * (m - 1) / (m - k) * stats.f.ppf(1 - alpha, k, m - k)
    assert monitor.t2_limit_ == pytest.approx(t2_hand, rel=1e-12)
    # The thesis's printed eq. 2.4 (F with m - 1 denominator degrees of freedom) differs here.
    printed = k * (m - 1) / (m - k) * stats.f.ppf(1 - alpha, k, m - 1)
    assert abs(monitor.t2_limit_ - printed) > 0.5

    th1, th2, th3 = lam[k:].sum(), (lam[k:] ** 2).sum(), (lam[k:] ** 3).sum()
    h0 = 1 - 2 * th1 * th3 / (3 * th2**2)
    c = stats.norm.ppf(1 - alpha)
    q_hand = th1 * (c * h0 * np.sqrt(2 * th2) / th1 + 1 + th2 * h0 * (h0 - 1) / th1**2) ** (1 / h0)
    assert monitor.q_limit_ == pytest.approx(q_hand, rel=1e-10)


def test_statistics_equal_projections_by_hand():
    monitor = PCAMonitor(n_components=2).fit(SMALL)
    lam, vec = np.linalg.eigh(np.corrcoef(SMALL, rowvar=False))
    lam, vec = lam[::-1], vec[:, ::-1]
    new = np.array([[4.5, 40.0, 0.8, 4.0], [1.0, 80.0, 0.1, 9.0]])
    z = (new - SMALL.mean(axis=0)) / SMALL.std(axis=0, ddof=1)
    t2_hand = ((z @ vec[:, :2]) ** 2 / lam[:2]).sum(axis=1)
    q_hand = ((z @ vec[:, 2:]) ** 2).sum(axis=1)  # squared length in the residual subspace
    t2, q = monitor.score_samples(new)
    np.testing.assert_allclose(t2, t2_hand, rtol=1e-10)
    np.testing.assert_allclose(q, q_hand, rtol=1e-10)
    np.testing.assert_allclose(monitor.contributions(new, "q").sum(axis=1), q, rtol=1e-12)
    np.testing.assert_allclose((monitor.contributions(new, "t2") ** 2).sum(axis=1), t2, rtol=1e-12)


def test_components_chosen_by_cumulative_variance():
    X = gaussian(np.random.default_rng(3), np.random.default_rng(4).normal(size=(6, 6)), 2000)
    for variance in (0.75, 0.85, 0.90):
        monitor = PCAMonitor(variance=variance).fit(X)
        cumulative = np.cumsum(monitor.explained_variance_ratio_)
        k = monitor.n_components_
        assert cumulative[k - 1] >= variance and (k == 1 or cumulative[k - 2] < variance)
        assert monitor.components_.shape == (k, 6)
        np.testing.assert_allclose(monitor.components_ @ monitor.components_.T, np.eye(k), atol=1e-12)


def test_false_alarm_rate_is_alpha_on_normal_data():
    rng = np.random.default_rng(0)
    mixing = rng.normal(size=(6, 6))
    monitor = PCAMonitor(variance=0.85, alpha=0.05).fit(gaussian(rng, mixing, 5000))
    t2, q = monitor.score_samples(gaussian(rng, mixing, 20000))
    t2_rate, q_rate = np.mean(t2 > monitor.t2_limit_), np.mean(q > monitor.q_limit_)
    print(f"k = {monitor.n_components_}, false alarms: T2 {t2_rate:.4f}, Q {q_rate:.4f}")
    assert abs(t2_rate - 0.05) < 0.01
    assert abs(q_rate - 0.05) < 0.01


def test_cross_validated_q_limit_holds_alpha_on_new_data():
    """With few training samples the in-sample residual eigenvalues are too small, so the limit of
    eq. 2.6 alarms more than alpha on new normal data; residual moments taken out of fold (cv)
    bring the rate back to alpha. Reference: the known generating distribution (fresh samples)."""
    mixing = np.diag([3.0, 2.5, 2.0, 1.5, 1.0, 0.6]) @ np.random.default_rng(10).normal(size=(6, 6))
    rates = {}
    for cv in (None, 20):
        rng = np.random.default_rng(11)
        monitors = [PCAMonitor(n_components=5, statistic="q", cv=cv).fit(gaussian(rng, mixing, 60)) for _ in range(40)]
        rates[cv] = np.mean([m.predict(gaussian(rng, mixing, 4000)).mean() for m in monitors])
    print(f"false alarms on new data at alpha 5 %: in-sample {rates[None]:.4f}, 20 folds {rates[20]:.4f}")
    assert rates[None] > 0.065
    assert abs(rates[20] - 0.05) < 0.012
    in_sample = PCAMonitor(n_components=5, statistic="q").fit(gaussian(np.random.default_rng(1), mixing, 60))
    folded = PCAMonitor(n_components=5, statistic="q", cv=20).fit(gaussian(np.random.default_rng(1), mixing, 60))
    assert folded.q_limit_ > in_sample.q_limit_
    np.testing.assert_array_equal(folded.components_, in_sample.components_)  # only the limit changes
    assert folded.t2_limit_ == in_sample.t2_limit_


def test_cross_validated_limit_with_a_feature_that_varies_in_one_block_only():
    X = np.random.default_rng(12).normal(size=(100, 4))
    X[:, 3] = 0.0
    X[95:, 3] = [0.1, 0.3, 0.2, 0.5, 0.4]  # constant in every fold that leaves the last block in
    monitor = PCAMonitor(n_components=2, statistic="q", cv=20).fit(X)
    assert np.isfinite(monitor.q_limit_) and monitor.q_limit_ > 0


def test_varying_columns_leave_out_rounding_noise():
    X = np.random.default_rng(13).normal(size=(50, 4))
    X[:, 1] = 4e-15 + np.random.default_rng(14).normal(scale=1e-16, size=50)  # a KL of zero up to rounding
    X[:, 2] = 1e3 + np.random.default_rng(15).normal(scale=1e-8, size=50)  # constant but for rounding of 1e3
    np.testing.assert_array_equal(varying_columns(X), [0, 3])


def test_offset_in_one_feature_is_detected_and_isolated_by_q():
    rng = np.random.default_rng(1)
    mixing = rng.normal(size=(6, 6))
    monitor = PCAMonitor(variance=0.85, statistic="q").fit(gaussian(rng, mixing, 2000))
    X, k = gaussian(rng, mixing, 300), 150
    X[k:, 3] += 4 * monitor.scale_[3]  # 4 training standard deviations on feature index 3
    onset = detect_onset(monitor.predict(X), persistence=3)
    assert onset is not None and k <= onset <= k + 3
    contributions = monitor.contributions(X[k:], statistic="q")
    assert contributions.shape == (300 - k, 6)
    assert np.argmax(contributions.mean(axis=0)) == 3
    assert np.mean(contributions.argmax(axis=1) == 3) > 0.9


def test_predict_follows_statistic():
    rng = np.random.default_rng(2)
    mixing = rng.normal(size=(5, 5))
    X, new = gaussian(rng, mixing, 500), gaussian(rng, mixing, 400) * 1.5
    fitted = {s: PCAMonitor(n_components=2, statistic=s).fit(X) for s in ("q", "t2", "either")}
    t2, q = fitted["q"].score_samples(new)
    np.testing.assert_array_equal(fitted["q"].predict(new), q > fitted["q"].q_limit_)
    np.testing.assert_array_equal(fitted["t2"].predict(new), t2 > fitted["t2"].t2_limit_)
    np.testing.assert_array_equal(fitted["either"].predict(new),
                                  (q > fitted["q"].q_limit_) | (t2 > fitted["t2"].t2_limit_))
    assert fitted["either"].predict(new).dtype == bool


def test_statistics_are_row_wise():
    # scikit-learn's sample-order check cannot index the (t2, q) tuple; the same property here.
    rng = np.random.default_rng(5)
    monitor = PCAMonitor(n_components=2).fit(rng.normal(size=(50, 4)))
    X = rng.normal(size=(20, 4))
    order = rng.permutation(20)
    t2, q = monitor.score_samples(X)
    t2_perm, q_perm = monitor.score_samples(X[order])
    np.testing.assert_allclose(t2_perm, t2[order])
    np.testing.assert_allclose(q_perm, q[order])
    one = [monitor.score_samples(X[i:i + 1]) for i in range(20)]
    np.testing.assert_allclose([t[0] for t, _ in one], t2)
    np.testing.assert_allclose([r[0] for _, r in one], q)


def test_fit_errors_name_the_problem():
    X = np.random.default_rng(6).normal(size=(30, 4))
    X[:, 2] = 7.5
    with pytest.raises(ValueError, match="feature 2 is constant"):
        PCAMonitor().fit(X)
    independent = np.random.default_rng(7).normal(size=(200, 3))
    with pytest.raises(ValueError, match="needs all 3 components"):
        PCAMonitor(variance=0.99).fit(independent)
    with pytest.raises(ValueError, match="n_components = 3 must be below n_features = 3"):
        PCAMonitor(n_components=3).fit(independent)
    with pytest.raises(ValueError, match="more than 2 training samples"):
        PCAMonitor(n_components=2).fit(independent[:2])
    for params, pattern in [({"alpha": 1.5}, "alpha = 1.5"), ({"variance": 0.0}, "variance = 0.0"),
                            ({"statistic": "spe"}, "statistic = 'spe'"),
                            ({"n_components": 0}, "n_components = 0"), ({"cv": 1}, "cv = 1; expected None"),
                            ({"cv": 300, "n_components": 1}, "cv = 300 folds need at least 300 training samples")]:
        with pytest.raises(ValueError, match=pattern):
            PCAMonitor(**params).fit(independent)
    collinear = np.column_stack([independent[:, 0], 2 * independent[:, 0], independent[:, 1]])
    with pytest.raises(ValueError, match="all zero"):
        PCAMonitor(n_components=2).fit(collinear)


def test_scoring_errors():
    monitor = PCAMonitor(n_components=1)
    with pytest.raises(NotFittedError):
        monitor.predict(SMALL)
    monitor.fit(SMALL)
    with pytest.raises(ValueError, match="4 features"):
        monitor.score_samples(SMALL[:, :3])
    with pytest.raises(ValueError, match="statistic = 'either'"):
        monitor.contributions(SMALL, statistic="either")


def test_detect_onset():
    alarms = [False, True, False, True, True, True, False, True]
    assert detect_onset(alarms) == 1
    assert detect_onset(alarms, persistence=2) == 3
    assert detect_onset(alarms, persistence=3) == 3
    assert detect_onset(alarms, persistence=4) is None
    assert detect_onset(np.zeros(5, dtype=bool)) is None
    assert detect_onset([], persistence=1) is None
    assert detect_onset(np.array([0, 1, 1])) == 1
    with pytest.raises(ValueError, match="persistence = 0"):
        detect_onset(alarms, persistence=0)
    with pytest.raises(ValueError, match="1-D"):
        detect_onset(np.ones((2, 3), dtype=bool))


def test_pipeline_and_clone():
    rng = np.random.default_rng(8)
    X = gaussian(rng, rng.normal(size=(4, 4)), 300).cumsum(axis=0)  # a random walk: differencing helps
    pipe = make_pipeline(Difference(), WindowConcat(width=3), PCAMonitor(variance=0.75, statistic="q"))
    assert pipe.fit(X) is pipe
    assert pipe.predict(X).shape == (300,)
    assert pipe[-1].n_features_in_ == 12
    monitor = PCAMonitor(variance=0.9, alpha=0.01)
    assert clone(monitor).get_params() == monitor.get_params()
    assert monitor.set_params(statistic="t2").statistic == "t2"


CHECKS_EXPECTED_TO_FAIL = {
    # score_samples returns the tuple (t2, q); this check indexes the output as one array.
    "check_methods_sample_order_invariance": "score_samples returns a (t2, q) tuple",
}


def test_scikit_learn_estimator_checks():
    # n_components=1: the checks fit 2-3 independent features, for which any variance share
    # needs all components and fit refuses (no residual space for Q).
    results = check_estimator(PCAMonitor(n_components=1), on_fail=None,
                              expected_failed_checks=CHECKS_EXPECTED_TO_FAIL)
    status = {r["check_name"]: (r["status"], str(r["exception"])) for r in results}
    assert [n for n, (s, _) in status.items() if s == "failed"] == []
    for name in CHECKS_EXPECTED_TO_FAIL:
        assert status[name][0] == "xfail", name
