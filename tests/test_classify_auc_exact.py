"""analysis.classify.roc.binary_auc: the same float as scikit-learn's roc_auc_score, bit for bit, on
random scores with and without ties; known values; and the parameter check evaluate does once, as its
workers fit with scikit-learn's parameter checks skipped (issue 89)."""

import numpy as np
import pytest
from sklearn.linear_model import LogisticRegression
from sklearn.metrics import roc_auc_score

from analysis.classify import evaluate, make_pipeline
from analysis.classify.evaluation import check_parameters
from analysis.classify.roc import binary_auc


def _scores(rng, kind: int, n: int) -> np.ndarray:
    """Scores with no ties, a few distinct values, values rounded to 0-2 decimals, and
    probabilities crowded near 0 (ties and near-ties as a classifier gives them)."""
    if kind == 0:
        return rng.normal(size=n)
    if kind == 1:
        return rng.integers(0, 4, n).astype(float)
    if kind == 2:
        return np.round(rng.normal(size=n), int(rng.integers(0, 3)))
    return rng.random(n) ** 12


def test_binary_auc_is_roc_auc_score_bit_for_bit_on_random_scores_with_ties():
    rng = np.random.default_rng(89)
    compared = ties = 0
    for case in range(400):
        n = int(rng.integers(2, 300))
        truth = rng.integers(0, 2, n)
        if truth.min() == truth.max():
            continue
        scores = _scores(rng, case % 4, n)
        expected = roc_auc_score(truth, scores)
        got = binary_auc(truth, scores)
        assert got.hex() == float(expected).hex(), (case, n, got, expected)
        compared += 1
        ties += np.unique(scores).size < n
    assert compared > 350 and ties > 150  # half the cases with tied scores


def test_binary_auc_takes_the_larger_label_as_positive_and_any_integer_type():
    rng = np.random.default_rng(3)
    truth = rng.integers(0, 2, 200)
    scores = np.round(rng.normal(size=200), 1)
    for labels in (truth.astype(np.int8), np.where(truth == 1, 5, 2), truth.astype(bool)):
        assert binary_auc(labels, scores) == roc_auc_score(labels, scores)


def test_binary_auc_known_values():
    # scikit-learn's roc_curve example: one positive below one negative of four pairs
    assert binary_auc(np.array([0, 0, 1, 1]), np.array([0.1, 0.4, 0.35, 0.8])) == 0.75
    assert binary_auc(np.array([0, 0, 1, 1]), np.array([1.0, 2.0, 3.0, 4.0])) == 1.0
    assert binary_auc(np.array([0, 0, 1, 1]), np.array([4.0, 3.0, 2.0, 1.0])) == 0.0
    assert binary_auc(np.array([0, 1, 0, 1]), np.full(4, 7.0)) == 0.5  # every pair tied: half each
    # 2 positives x 3 negatives: the positive at 2 beats the negative at 1 and ties the one at 2
    # (the trapezoids' sum rounds once more than 5.5 / 6: the same last bit as scikit-learn's, not the quotient's)
    assert binary_auc(np.array([1, 1, 0, 0, 0]), np.array([3.0, 2.0, 2.0, 1.0, 0.0])) == pytest.approx(5.5 / 6, abs=1e-15)


@pytest.mark.parametrize("truth, scores, message", [
    (np.array([1, 1, 1]), np.array([0.1, 0.2, 0.3]), r"two labels.*\[1\]"),
    (np.array([0, 1, 2]), np.array([0.1, 0.2, 0.3]), r"two labels.*\[0, 1, 2\]"),
    (np.array([0, 1, 0]), np.array([0.1, 0.2]), r"scores of shape \(2,\)"),
])
def test_binary_auc_refuses_what_has_no_binary_auc(truth, scores, message):
    with pytest.raises(ValueError, match=message):
        binary_auc(truth, scores)


def test_check_parameters_names_a_bad_parameter_nested_in_a_pipeline_and_passes_classify_s_own():
    for name in ("lr", "svm", "rf", "stacking"):
        check_parameters(make_pipeline(name, "+diff+var3+pca"))
    with pytest.raises(ValueError, match="'C' parameter of LogisticRegression.*Got -1"):
        check_parameters(make_pipeline(LogisticRegression(C=-1), "+diff"))


def test_evaluate_refuses_a_bad_estimator_before_fitting():
    rng = np.random.default_rng(0)
    groups = np.repeat(["f1", "f2", "n1", "n2"], 6)
    y = np.tile([0, 0, 0, 1, 1, 1], 4) * np.repeat([1, 1, 0, 0], 6)
    with pytest.raises(ValueError, match="'max_iter' parameter of LogisticRegression"):
        evaluate(rng.normal(size=(24, 3)), y, groups, ["f1", "f2"], ["n1", "n2"],
                 classifiers={"bad": LogisticRegression(max_iter=-5)}, preprocessing=["control"])
