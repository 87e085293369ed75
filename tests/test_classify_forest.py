"""analysis.classify.forest.Forest grows scikit-learn's RandomForestClassifier's trees and gives its
probabilities bit for bit, without its per-tree Python (issue 89)."""

import numpy as np
import pytest
from sklearn.ensemble import RandomForestClassifier

from analysis.classify.forest import Forest


def _data(seed: int, n: int = 60, d: int = 7, distinct: int | None = None, nan: bool = False):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(n, d))
    if distinct:  # many tied values: the splitter's thresholds between equal values
        X = np.round(X * distinct / 3) / distinct
    y = (X[:, 0] + rng.normal(size=n) > 0).astype(int)
    if nan:
        X[rng.random(size=X.shape) < 0.1] = np.nan
    return X, y


def _same(a: RandomForestClassifier, b: RandomForestClassifier) -> None:
    assert len(a.estimators_) == len(b.estimators_)
    for s, t in zip(a.estimators_, b.estimators_, strict=True):
        assert s.random_state == t.random_state
        for field in ("feature", "threshold", "value", "children_left", "children_right", "n_node_samples",
                      "weighted_n_node_samples", "impurity", "missing_go_to_left"):
            np.testing.assert_array_equal(getattr(s.tree_, field), getattr(t.tree_, field), err_msg=field)
        assert s.max_features_ == t.max_features_ and s.n_classes_ == t.n_classes_
        np.testing.assert_array_equal(s.classes_, t.classes_)
    np.testing.assert_array_equal(a.classes_, b.classes_)
    assert a.n_classes_ == b.n_classes_ and a.n_features_in_ == b.n_features_in_


@pytest.mark.parametrize("seed, distinct, nan, params", [
    (0, None, False, {}),
    (1, 2, False, {}),
    (2, 1, False, {"max_features": None, "min_samples_leaf": 3}),
    (3, None, True, {"criterion": "entropy", "max_depth": 4}),
    (4, 3, False, {"min_samples_split": 0.1, "min_samples_leaf": 0.05, "max_features": 0.5}),
])
def test_forest_is_scikit_learns_bit_for_bit(seed, distinct, nan, params):
    X, y = _data(seed, distinct=distinct, nan=nan)
    X_new, _ = _data(seed + 100, n=40, distinct=distinct, nan=nan)
    ours = Forest(n_estimators=25, random_state=seed, **params).fit(X, y)
    theirs = RandomForestClassifier(n_estimators=25, random_state=seed, **params).fit(X, y)
    _same(ours, theirs)
    np.testing.assert_array_equal(ours.predict_proba(X_new), theirs.predict_proba(X_new))
    np.testing.assert_array_equal(ours.predict(X_new), theirs.predict(X_new))
    assert np.unique(ours.predict_proba(X_new)).size > 2  # the trees disagree: a sum, not one tree


def test_labels_other_than_0_1_and_the_fallback():
    X, y = _data(5)
    labels = np.where(y == 1, "worn", "ok")
    ours = Forest(n_estimators=10, random_state=3).fit(X, labels)
    theirs = RandomForestClassifier(n_estimators=10, random_state=3).fit(X, labels)
    _same(ours, theirs)
    assert list(ours.classes_) == ["ok", "worn"]
    np.testing.assert_array_equal(ours.predict_proba(X), theirs.predict_proba(X))
    # sample weights: scikit-learn's own fit, the same forest
    weights = np.linspace(0.5, 2.0, len(y))
    _same(Forest(n_estimators=5, random_state=1).fit(X, y, sample_weight=weights),
          RandomForestClassifier(n_estimators=5, random_state=1).fit(X, y, sample_weight=weights))


def test_errors_are_scikit_learns():
    X, y = _data(6)
    with pytest.raises(ValueError, match="Found input variables with inconsistent numbers of samples"):
        Forest(n_estimators=3).fit(X, y[:-1])
    with pytest.raises(ValueError, match="Unknown label type"):
        Forest(n_estimators=3).fit(X, y + 0.5)
