"""Reconstruction-based contributions (Alcala and Qin, Automatica 45 (2009) 1593-1600) of
:class:`analysis.monitoring.PCAMonitor`: the closed form against the definition (the fall of the
index when the sample is reconstructed, found by a numerical minimiser), the published property (a
large single-variable fault has its largest RBC on that variable, for every variable, where the
complete decomposition smears it), groups of variables, and the errors."""

import numpy as np
import pytest
from scipy import optimize

from analysis.monitoring import PCAMonitor, reconstruction_contributions

N = 8


def correlated(seed: int, m: int = 500) -> np.ndarray:
    """``m`` samples of ``N`` variables driven by 3 latent ones plus a little independent noise."""
    rng = np.random.default_rng(seed)
    return rng.normal(size=(m, 3)) @ rng.normal(size=(3, N)) + 0.3 * rng.normal(size=(m, N)) + 5.0


def by_hand(X: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """C~ = I - P P^T and D = P Lambda^-1 P^T of the first ``k`` eigenvectors of the correlation
    matrix (np.corrcoef, np.linalg.eigh: not the monitor's route)."""
    lam, vec = np.linalg.eigh(np.corrcoef(X, rowvar=False))
    lam, P = lam[::-1][:k], vec[:, ::-1][:, :k]
    return np.eye(X.shape[1]) - P @ P.T, P @ np.diag(1.0 / lam) @ P.T


def test_rbc_is_the_fall_of_the_index_when_the_sample_is_reconstructed_along_each_variable():
    X = correlated(0)
    monitor = PCAMonitor(variance=0.85).fit(X)
    C, D = by_hand(X, monitor.n_components_)
    new = correlated(1, 6) + np.array([0, 0, 3, 0, 0, 0, 0, -2.0])
    z = (new - X.mean(axis=0)) / X.std(axis=0, ddof=1)
    for statistic, M in (("q", C), ("t2", D)):
        np.testing.assert_allclose(monitor.index_matrix(statistic), M, atol=1e-10)
        rbc = monitor.contributions(new, statistic, method="rbc")
        # the published closed form: RBC_i = (xi_i^T M z)^2 / (xi_i^T M xi_i)
        np.testing.assert_allclose(rbc, (z @ M) ** 2 / np.diag(M), rtol=1e-9)
        # the definition: the index of z less its minimum over f of the index of z - f xi_i
        for s in range(len(z)):
            for i in range(N):
                def index(f, s=s, i=i, M=M):
                    r = z[s] - f * np.eye(N)[i]
                    return r @ M @ r
                fall = index(0.0) - optimize.minimize_scalar(index).fun
                assert rbc[s, i] == pytest.approx(fall, rel=1e-6, abs=1e-9)
    # the statistic itself is unchanged: the complete decomposition still sums to Q
    np.testing.assert_allclose(monitor.contributions(new, "q").sum(axis=1), monitor.score_samples(new)[1])


def sufficient_size(monitor: PCAMonitor, normal: np.ndarray, statistic: str, i: int) -> float:
    """A fault size along variable ``i`` beyond which RBC names ``i`` on every sample of ``normal``:
    with ``x = x* + f xi_i``, ``sqrt(RBC_j) = |u_j . M^(1/2) x* + f sqrt(m_ii) cos_ij|`` (``u_j`` the
    unit vector of ``M^(1/2) xi_j``), so ``|f| > 2 ||M^(1/2) x*|| / (sqrt(m_ii) (1 - max_j |cos_ij|))``
    suffices (the derivation of Alcala and Qin 2009, section on diagnosability), in standard
    deviations of the variable."""
    M = monitor.index_matrix(statistic)
    z = (normal - monitor.mean_) / monitor.scale_
    d = np.sqrt(np.diag(M))
    cos = np.delete(M[i] / (d[i] * d), i)
    return float(2 * np.sqrt(np.einsum("sj,jk,sk->s", z, M, z).max()) / (d[i] * (1 - np.abs(cos).max())))


def test_a_large_fault_along_any_one_variable_has_its_largest_rbc_there_where_complete_contributions_smear():
    # ten draws of correlated data, each variable in turn faulty on 40 samples, by 1.1 times the
    # size the derivation needs (from 9 to 4e7 standard deviations, median 66: two variables of draw 3 are
    # almost collinear in its 2-component T2 space)
    right = {(s, method): [] for s in ("q", "t2") for method in ("complete", "rbc")}
    for seed in range(10):
        X = correlated(seed)
        monitor = PCAMonitor(variance=0.85).fit(X)
        normal = correlated(100 + seed, 40)
        for i in range(N):
            for s in ("q", "t2"):
                faulty = normal.copy()
                faulty[:, i] += 1.1 * sufficient_size(monitor, normal, s, i) * monitor.scale_[i]
                for method in ("complete", "rbc"):
                    c = np.abs(monitor.contributions(faulty, s, method=method))  # T2's complete ones are signed
                    right[s, method].append(bool(np.all(c.argmax(axis=1) == i)))
    assert all(right["q", "rbc"]) and all(right["t2", "rbc"]), right
    # the complete decomposition names another variable for some of these faults
    assert not all(right["q", "complete"]) and not all(right["t2", "complete"]), right


def test_a_group_is_reconstructed_along_all_its_variables_at_once():
    X = correlated(2)
    monitor = PCAMonitor(variance=0.85).fit(X)
    groups = [[0, 1], [2, 3], [4, 5], [6, 7]]
    new = correlated(3, 5)
    new[:, 2] += 500 * monitor.scale_[2]
    new[:, 3] -= 300 * monitor.scale_[3]
    z = (new - X.mean(axis=0)) / X.std(axis=0, ddof=1)
    for statistic in ("q", "t2"):
        M = monitor.index_matrix(statistic)
        rbc = monitor.contributions(new, statistic, method="rbc", groups=groups)
        assert rbc.shape == (5, 4)
        assert np.all(rbc.argmax(axis=1) == 1)
        for s in range(5):
            for g, members in enumerate(groups):
                Xi = np.eye(N)[:, members]
                f = np.linalg.lstsq(np.linalg.cholesky(M + 1e-12 * np.eye(N)).T @ Xi,
                                    np.linalg.cholesky(M + 1e-12 * np.eye(N)).T @ z[s], rcond=None)[0]
                fall = z[s] @ M @ z[s] - (z[s] - Xi @ f) @ M @ (z[s] - Xi @ f)
                assert rbc[s, g] == pytest.approx(fall, rel=1e-6, abs=1e-6)
        # a group of one is the single variable's RBC
        np.testing.assert_allclose(monitor.contributions(new, statistic, "rbc", groups=[[4], [7]]),
                                   monitor.contributions(new, statistic, "rbc")[:, [4, 7]], rtol=1e-9)
    # complete contributions of a group are summed
    np.testing.assert_allclose(monitor.contributions(new, "q", groups=groups),
                               monitor.contributions(new, "q").reshape(5, 4, 2).sum(axis=2), rtol=1e-12)


def test_a_direction_the_index_cannot_see_contributes_nothing():
    M = np.diag([1.0, 0.0, 2.0])
    np.testing.assert_array_equal(reconstruction_contributions([[1.0, 5.0, 1.0]], M), [[1.0, 0.0, 2.0]])
    np.testing.assert_array_equal(reconstruction_contributions([[1.0, 5.0, 1.0]], M, groups=[[1]]), [[0.0]])


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"method": "cd"}, r"method = 'cd'; expected 'complete' or 'rbc'"),
    ({"statistic": "spe"}, r"statistic = 'spe'; expected 'q' or 't2'"),
    ({"method": "rbc", "groups": [[0, 8]]}, r"group 0 = \[0, 8\]; expected a non-empty list of feature indices in 0..7"),
    ({"method": "rbc", "groups": [[1], []]}, r"group 1 = \[\]; expected a non-empty list"),
])
def test_errors_name_the_offending_value(kwargs, message):
    monitor = PCAMonitor().fit(correlated(0, 50))
    with pytest.raises(ValueError, match=message):
        monitor.contributions(correlated(1, 2), **kwargs)
    with pytest.raises(ValueError, match=r"M has shape \(2, 2\); expected \(3, 3\)"):
        reconstruction_contributions(np.ones((1, 3)), np.eye(2))
