"""Isolators of analysis.isolation: transfer entropy against PyInform and infomeasure, each
isolator on synthetic driven systems, scikit-learn conventions, the registry and the errors."""

from __future__ import annotations

import infomeasure
import numpy as np
import pyinform
import pytest
from sklearn.base import clone
from sklearn.utils.estimator_checks import check_estimator

from analysis import isolation
from analysis.isolation import (
    ISOLATORS,
    CrossCorrelationIsolator,
    GrangerIsolator,
    PCAContributionIsolator,
    TransferEntropyIsolator,
    TrendIsolator,
    make,
    register,
    symbolise,
    transfer_entropy,
)


def driven(k, n=500, seed=0, a=0.8, phi=1.0, step=1.0, drift=0.0, noise=1.0, common=0.0, n_ref=0):
    """Six axes; axis k (1-based) carries w_t = phi w_{t-1} + drift + step e_t (zero for t <= n_ref),
    every other axis a * w_{t-1}; all get own noise and a shared per-cycle load ``common``."""
    rng = np.random.default_rng(seed)
    w = np.zeros(n)
    for t in range(n_ref + 1, n):
        w[t] = phi * w[t - 1] + drift + step * rng.standard_normal()
    X = noise * rng.standard_normal((n, 6)) + common * rng.standard_normal((n, 1))
    X[:, k - 1] += w
    X[1:, np.arange(6) != k - 1] += a * w[:-1, None]
    return X


LAGGED = {"phi": 0.5, "noise": 0.3}  # stationary AR(1) driver: a lead of one cycle
WEAR = {"drift": 0.05, "step": 0.1, "common": 3.0, "n_ref": 100}  # 100 normal cycles, then a drift


def reference_te(source, target, history):
    """PyInform for history 1 (it has a source history of 1 only), infomeasure for both."""
    values = [infomeasure.transfer_entropy(source, target, approach="discrete", base=2,
                                           src_hist_len=history, dest_hist_len=history)]
    if history == 1:
        values.append(pyinform.transfer_entropy(source, target, k=1))
    return values


# --- transfer entropy against independent implementations ----------------------------------------

_rng = np.random.default_rng(42)
_x = _rng.integers(0, 4, 3000)
SEQUENCES = {
    "random 10 symbols": (_rng.integers(0, 10, 2000), _rng.integers(0, 10, 2000)),
    "2 symbols": (_rng.integers(0, 2, 500), _rng.integers(0, 2, 500)),
    "20 symbols": (_rng.integers(0, 20, 5000), _rng.integers(0, 20, 5000)),
    "coupled y[t+1] = x[t] xor noise": (_x, np.roll(_x, 1) ^ (_rng.random(3000) < 0.2)),
    "constant source": (np.zeros(300, int), _rng.integers(0, 5, 300)),
    "constant target": (_rng.integers(0, 5, 300), np.full(300, 3)),
    "short, 20 bins": (symbolise(_rng.normal(size=60), 20), symbolise(_rng.normal(size=60), 20)),
}


@pytest.mark.parametrize("history", [1, 2, 3])
@pytest.mark.parametrize("case", list(SEQUENCES))
def test_transfer_entropy_matches_pyinform_and_infomeasure(case, history):
    source, target = SEQUENCES[case]
    if (max(source.max(), target.max()) + 1) ** (2 * history + 1) > isolation._MAX_STATES:
        pytest.raises(ValueError, transfer_entropy, source, target, history)  # e.g. 10^7 states
        source, target = source % 4, target % 4
    for x, y in ((source, target), (target, source)):
        ours = transfer_entropy(x, y, history=history)
        for theirs in reference_te(x, y, history):
            assert ours == pytest.approx(theirs, abs=1e-9)


def test_te_matrix_of_fit_matches_pairwise_pyinform():
    X = driven(2, n=400, **LAGGED)
    est = TransferEntropyIsolator(bins=5).fit(X)
    S = [symbolise(c, 5) for c in X.T]
    for i in range(6):
        for j in range(6):
            expected = 0.0 if i == j else pyinform.transfer_entropy(S[i], S[j], k=1)
            assert est.te_[i, j] == pytest.approx(expected, abs=1e-9)
    np.testing.assert_allclose(est.net_te_, est.te_ - est.te_.T)
    np.testing.assert_allclose(est.scores_, est.net_te_.sum(axis=1))


def test_copy_with_lag_one_carries_the_source_entropy_and_independence_carries_none():
    rng = np.random.default_rng(0)
    x = rng.integers(0, 8, 200_000)
    y = np.empty_like(x)
    y[0], y[1:] = 0, x[:-1]
    assert transfer_entropy(x, y) == pytest.approx(3.0, abs=0.01)  # log2(8) bits
    assert transfer_entropy(y, x) < 0.01
    assert transfer_entropy(x, rng.integers(0, 8, 200_000)) < 0.01
    # only equality of symbols matters: negative or sparse labels give the same value
    assert transfer_entropy(x[:1000] - 5, 1000 * y[:1000]) == pytest.approx(transfer_entropy(x[:1000], y[:1000]))


def test_symbolise_quantile_bins_and_ties():
    # n = 10, bins = 5: median-unbiased quantiles of 0..9 at 0.2, 0.4, ... are 1.53.., 3.6, 5.4, 7.46..
    np.testing.assert_array_equal(symbolise(np.arange(10.0), 5), [0, 0, 1, 1, 2, 2, 3, 3, 4, 4])
    # a value equal to a bound takes the lower symbol (thesis: q_{k-1} < X <= q_k)
    np.testing.assert_array_equal(symbolise([0.0, 1, 1, 1, 2], 2), [0, 0, 0, 0, 1])
    np.testing.assert_array_equal(symbolise(np.full(7, 2.5), 4), np.zeros(7))
    counts = np.bincount(symbolise(np.random.default_rng(1).normal(size=10_000), 10))
    np.testing.assert_array_equal(counts, np.full(10, 1000))


def test_effective_te_with_surrogates():
    X = driven(3, n=400, **LAGGED)
    est = TransferEntropyIsolator(bins=5, surrogates=20, random_state=0).fit(X)
    again = TransferEntropyIsolator(bins=5, surrogates=20, random_state=0).fit(X)
    np.testing.assert_array_equal(est.effective_te_, again.effective_te_)
    off = ~np.eye(6, dtype=bool)
    assert (est.effective_te_[off] < est.te_[off]).all()  # the surrogate mean (bias) is positive
    assert np.all(est.p_values_[2, off[2]] == 1 / 21)  # axis 3 drives every other axis
    assert np.isnan(np.diag(est.p_values_)).all() and (est.p_values_[off] <= 1).all()
    np.testing.assert_allclose(est.net_te_, est.effective_te_ - est.effective_te_.T)
    assert est.source_axis_ == 3
    assert np.isnan(TransferEntropyIsolator().fit(X).p_values_).all()


# --- every isolator finds the driver -------------------------------------------------------------


@pytest.mark.parametrize("k", range(1, 7))
@pytest.mark.parametrize("isolator", [TransferEntropyIsolator(), CrossCorrelationIsolator(), GrangerIsolator()])
def test_lead_based_isolators_find_a_driver_that_leads_by_one_cycle(isolator, k):
    est = clone(isolator).fit(driven(k, seed=k, **LAGGED))
    assert est.source_axis_ == k
    assert np.argmax(est.scores_) == k - 1


@pytest.mark.parametrize("k", range(1, 7))
@pytest.mark.parametrize(
    "isolator",
    [TransferEntropyIsolator(), GrangerIsolator(), TrendIsolator(), PCAContributionIsolator(n_reference=100)],
)
def test_isolators_find_a_drifting_worn_axis(isolator, k):
    est = clone(isolator).fit(driven(k, seed=10 + k, **WEAR))
    assert est.source_axis_ == k


def test_cross_correlation_sign_convention_and_eq_3_5():
    rng = np.random.default_rng(3)
    a = rng.standard_normal(300)
    X = np.column_stack([a, np.roll(a, 2), np.roll(a, 1)]) + 0.1 * rng.standard_normal((300, 3))
    est = CrossCorrelationIsolator(max_lag=5).fit(X)
    # axis 2 trails axis 1 by 2 cycles: eq. 3.5 peaks at dt = +2, Table 3.3 reports -2
    assert est.lag_[0, 1] == -2 and est.lag_[1, 0] == 2
    n, (ti, tj) = 300, (X[:, 0] - X[:, 0].mean(), X[:, 1] - X[:, 1].mean())
    R = {dt: sum(ti[t] * tj[t + dt] for t in range(max(0, -dt), min(n, n - dt))) / n / (ti.std() * tj.std())
         for dt in range(-5, 6)}  # eq. 3.5-3.6 written out
    assert max(R, key=R.get) == 2
    np.testing.assert_array_equal(est.lag_, [[0, -2, -1], [2, 0, 1], [1, -1, 0]])
    np.testing.assert_array_equal(est.scores_, [2, 0, 1])
    assert est.source_axis_ == 1
    assert CrossCorrelationIsolator().fit(X).max_lag_ == 75  # n // 4


def test_source_rule_on_thesis_table_3_3():
    table = [[0, -3, -3, -27, 0, -4], [3, 0, 0, 0, -38, -2], [3, 0, 0, 0, 6, 0],
             [27, 0, 0, 0, -22, 5], [0, 38, -6, 22, 0, 32], [4, 2, 0, -5, -32, 0]]
    # the thesis names axis 1 although its lag to axis 5 is 0, not negative
    assert isolation.source_from_lags(table) == 0
    assert isolation.source_from_lags(table, allow_zero_lag=True) == 1
    assert isolation.source_from_lags(np.zeros((6, 6), int), allow_zero_lag=True) == 0


def test_trend_scores_and_ties():
    t = np.arange(50.0)
    noise = np.random.default_rng(5).standard_normal((50, 3))
    est = TrendIsolator().fit(np.column_stack([noise[:, 0], 0.2 * t + noise[:, 1], 5.0 + 0 * t]))
    assert est.source_axis_ == 2 and est.scores_[2] == 0.0
    assert est.slope_[1] == pytest.approx(0.2, abs=0.02)
    assert TrendIsolator().fit(np.column_stack([t, noise[:, 0], t])).source_axis_ == 0  # two perfect lines


def test_pca_contribution_attributes():
    est = PCAContributionIsolator(n_reference=100, variance=0.75).fit(driven(4, **WEAR))
    assert est.n_components_ == 1 and est.components_.shape == (1, 6)
    assert est.scores_.shape == (6,) and est.source_axis_ == 4


# --- scikit-learn conventions, registry, errors --------------------------------------------------

ALL = [TransferEntropyIsolator(), TransferEntropyIsolator(surrogates=2, random_state=0),
       CrossCorrelationIsolator(), GrangerIsolator(), TrendIsolator(), PCAContributionIsolator(n_reference=5)]


# check_array_api_input needs SCIPY_ARRAY_API=1 before scipy is imported; it is sklearn's check of
# array-API dispatch, which these numpy-only isolators do not claim.
@pytest.mark.filterwarnings("ignore:Skipping check check_array_api_input")
@pytest.mark.parametrize("isolator", ALL, ids=lambda e: repr(e))
def test_scikit_learn_estimator_checks(isolator):
    check_estimator(isolator)


@pytest.mark.parametrize("name", sorted(ISOLATORS))
def test_init_stores_only_and_fit_returns_self(name):
    est = make(name)
    params = est.get_params()
    assert clone(est).get_params() == params
    X = driven(1, n=200, **WEAR)
    assert est.fit(X) is est
    assert est.scores_.shape == (6,) and isinstance(est.source_axis_, int)
    assert est.n_features_in_ == 6


def test_get_set_params_and_no_validation_in_init():
    est = TransferEntropyIsolator(bins=1, history="x")  # invalid, but __init__ must not check
    assert est.get_params() == {"bins": 1, "history": "x", "surrogates": 0, "random_state": None}
    assert est.set_params(bins=5, history=1) is est and est.bins == 5
    assert est.fit(driven(1, n=50)).source_axis_ in range(7)


def test_registry():
    assert set(ISOLATORS) >= {"transfer_entropy", "cross_correlation", "granger", "trend", "pca_contribution"}
    est = make("transfer_entropy", bins=5)
    assert isinstance(est, TransferEntropyIsolator) and est.bins == 5
    with pytest.raises(ValueError, match="unknown isolator 'nope'.*cross_correlation.*transfer_entropy"):
        make("nope")

    try:
        @register("mine")
        class Mine(isolation.Isolator):
            def __init__(self, axis=1):
                self.axis = axis

            def _min_rows(self, n_rows):
                return 1

            def _scores(self, X):
                return np.eye(X.shape[1])[self.axis - 1]

        assert make("mine", axis=4).fit(np.ones((3, 6))).source_axis_ == 4
        with pytest.raises(ValueError, match="'mine' is already registered to Mine"):
            register("mine")(TrendIsolator)
    finally:
        ISOLATORS.pop("mine", None)


@pytest.mark.parametrize(
    "isolator, X, message",
    [
        (TransferEntropyIsolator(bins=1), np.ones((20, 6)), r"bins = 1, expected an integer >= 2"),
        (TransferEntropyIsolator(history=0), np.ones((20, 6)), r"history = 0, expected an integer >= 1"),
        (TransferEntropyIsolator(bins=20, history=3), np.ones((20, 6)), r"20\^7 joint states"),
        (TransferEntropyIsolator(), np.ones((2, 6)), r"n_samples = 2 rows \(cycles\), at least 3 needed"),
        (TransferEntropyIsolator(history=2), np.ones((3, 6)), r"history=2\).*n_samples = 3 .*at least 4"),
        (CrossCorrelationIsolator(max_lag=10), np.ones((11, 6)), r"n_samples = 11 .*at least 12"),
        (CrossCorrelationIsolator(max_lag=0), np.ones((11, 6)), r"max_lag = 0"),
        (GrangerIsolator(maxlag=2), np.ones((7, 6)), r"n_samples = 7 .*at least 8"),
        (PCAContributionIsolator(variance=1.5), np.ones((30, 6)), r"variance = 1.5"),
        (PCAContributionIsolator(), np.ones((20, 6)), r"n_samples = 20 .*at least 21"),
        (TransferEntropyIsolator(), np.where(np.eye(20, 6) > 0, np.nan, 1.0), "NaN"),
        (TransferEntropyIsolator(), np.full((20, 6), np.inf), "infinity"),
        (TransferEntropyIsolator(), np.ones(20), "Expected 2D array"),
        (TransferEntropyIsolator(), np.ones((20, 1)), "1 feature.*minimum of 2"),
    ],
)
def test_errors_name_the_offending_value(isolator, X, message):
    with pytest.raises(ValueError, match=message):
        isolator.fit(X)


def test_function_errors():
    with pytest.raises(ValueError, match="bins = 1"):
        symbolise([1.0, 2.0], 1)
    with pytest.raises(ValueError, match="finite 1-D"):
        symbolise([1.0, np.nan], 2)
    with pytest.raises(ValueError, match=r"shapes \(3,\) and \(4,\)"):
        transfer_entropy([0, 1, 0], [0, 1, 0, 1])
    with pytest.raises(ValueError, match="symbols must be integers"):
        transfer_entropy([0.5, 1, 0], [0, 1, 0])
