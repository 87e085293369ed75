"""`bench score`'s bootstrap ROC arithmetic (faultgen/bench/score.py): scikit-learn's floats, bit for bit,
without its input checks; a score that is not finite still gets scikit-learn's error."""

import numpy as np
import pytest
from sklearn.metrics import roc_auc_score, roc_curve

from faultgen.bench import score


def _units(truth, scores):
    return [{"scores": scores, "positive": truth, "mask": np.ones(truth.size, bool)}]


def test_the_roc_points_and_auroc_are_scikit_learns_bit_for_bit_on_scores_with_ties():
    rng = np.random.default_rng(0)
    for k in range(60):
        n = int(rng.integers(2, 80))
        truth = rng.random(n) < rng.uniform(0.1, 0.9)
        truth[:2] = [True, False]
        scores = np.round(rng.normal(size=n), int(rng.integers(0, 3)))  # 0 decimals: many ties
        fpr, tpr, _ = roc_curve(truth.astype(float), scores, drop_intermediate=False)
        mine = score._roc(truth.astype(float), scores)
        assert np.array_equal(mine[0], fpr) and np.array_equal(mine[1], tpr), k
        assert score._auroc(_units(truth, scores)) == roc_auc_score(truth, scores), k


def test_a_score_that_is_not_finite_gets_scikit_learns_error():
    truth = np.array([True, False, True])
    with pytest.raises(ValueError, match="NaN"):
        score._auroc(_units(truth, np.array([0.1, np.nan, 0.3])))
