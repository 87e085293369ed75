"""The random forest of thesis ch. 5.2 without scikit-learn's Python around each tree: the same trees,
the same probabilities, bit for bit (issue 89)."""

from __future__ import annotations

import numbers

import numpy as np
from scipy.sparse import issparse
from sklearn.ensemble import RandomForestClassifier
from sklearn.tree import DecisionTreeClassifier
from sklearn.utils.validation import check_is_fitted, check_random_state, validate_data

#: The largest tree seed, as scikit-learn's forests draw them (``np.iinfo(np.int32).max``).
MAX_INT = np.iinfo(np.int32).max


class Forest(RandomForestClassifier):
    """``sklearn.ensemble.RandomForestClassifier`` (the same parameters) whose ``fit`` and
    ``predict_proba`` build and sum the same trees with scikit-learn's own tree builder, each tree
    without the per-tree ``clone``, ``set_params``, target and weight checks, fresh parameter
    reading and joblib dispatch that the forest runs 100 times a fit (about nine tenths of a fit of
    100 trees on a few hundred samples, docs/performance.md, issue 89).

    Every tree is what ``RandomForestClassifier.fit`` grows: the seeds drawn one per tree from
    ``random_state`` in order, each bootstrap sample drawn by ``RandomState(seed)`` and passed as
    counts in float64, the labels encoded by the forest and again by the tree, the splitter seeded
    by a second ``RandomState(seed)``; the probabilities summed over the trees in their order and
    divided by their number. tests/test_classify_forest.py compares both with scikit-learn's
    forest, bit for bit. Anything else (sparse ``X``, sample weights, several outputs, bootstrap
    off, ``max_samples``, class weights, out-of-bag scores, warm start, monotonic constraints,
    pruning, ``max_leaf_nodes``) is scikit-learn's own ``fit``.
    """

    def fit(self, X, y, sample_weight=None):
        """Fit as ``RandomForestClassifier.fit``; returns self."""
        if sample_weight is not None or not self._lean() or issparse(X) or np.ndim(y) != 1:
            return super().fit(X, y, sample_weight)
        X, y = validate_data(self, X, y, multi_output=True, accept_sparse="csc", dtype=np.float32,
                             ensure_all_finite=False)
        missing = DecisionTreeClassifier(criterion=self.criterion)._compute_missing_values_in_feature_mask(
            X, estimator_name="RandomForestClassifier")
        y = np.reshape(y, (-1, 1))
        self._n_samples, self.n_outputs_ = y.shape
        y, _ = self._validate_y_class_weight(y, None)
        y = np.ascontiguousarray(y, dtype=np.float64)
        self._sample_weight = None
        self._n_samples_bootstrap = X.shape[0]
        self._validate_estimator()
        random_state = check_random_state(self.random_state)
        seeds = [random_state.randint(MAX_INT) for _ in range(self.n_estimators)]
        grow = _Grower(self, X, y, missing)
        self.estimators_ = [grow(seed) for seed in seeds]
        self.n_classes_ = self.n_classes_[0]
        self.classes_ = self.classes_[0]
        return self

    def predict_proba(self, X):
        """As ``RandomForestClassifier.predict_proba``: shape (n_samples, n_classes)."""
        check_is_fitted(self)
        if self.n_outputs_ != 1 or issparse(X):
            return super().predict_proba(X)
        X = self._validate_X_predict(X)
        proba = np.zeros((X.shape[0], self.n_classes_), dtype=np.float64)
        for tree in self.estimators_:  # in order, as the forest's one-job loop adds them
            proba += tree.predict_proba(X, check_input=False)
        proba /= len(self.estimators_)
        return proba

    def _lean(self) -> bool:
        """Whether :meth:`fit` grows the trees itself (the parameters it reproduces)."""
        return (self.bootstrap and not self.oob_score and not self.warm_start and self.class_weight is None
                and self.max_samples is None and self.monotonic_cst is None and self.ccp_alpha == 0.0
                and self.max_leaf_nodes is None and self.criterion in ("gini", "entropy", "log_loss"))


class _Grower:
    """Grows one tree of a :class:`Forest` from its seed, as ``DecisionTreeClassifier._fit`` does
    with the forest's encoded labels and bootstrap counts (``check_input=False``)."""

    def __init__(self, forest: Forest, X: np.ndarray, y: np.ndarray, missing):
        from sklearn.tree._classes import CRITERIA_CLF

        self.X, self.missing, self.forest = X, missing, forest
        self.params = {p: getattr(forest, p) for p in forest.estimator_params if p != "random_state"}
        self.classes, encoded = np.unique(y[:, 0], return_inverse=True)
        self.y = np.ascontiguousarray(encoded.reshape(-1, 1), dtype=np.float64)
        self.n_classes = np.array([self.classes.shape[0]], dtype=np.intp)
        self.criterion = CRITERIA_CLF[forest.criterion]
        n_samples, n_features = X.shape
        leaf = forest.min_samples_leaf
        self.leaf = leaf if isinstance(leaf, numbers.Integral) else int(np.ceil(leaf * n_samples))
        split = forest.min_samples_split
        split = split if isinstance(split, numbers.Integral) else max(2, int(np.ceil(split * n_samples)))
        self.split = max(split, 2 * self.leaf)
        self.max_features = _max_features(forest.max_features, n_features)
        self.depth = np.iinfo(np.int32).max if forest.max_depth is None else forest.max_depth

    def __call__(self, seed: int) -> DecisionTreeClassifier:
        from sklearn.tree._classes import DENSE_SPLITTERS
        from sklearn.tree._tree import DepthFirstTreeBuilder, Tree

        X, n_samples = self.X, self.X.shape[0]
        tree = DecisionTreeClassifier(**self.params, random_state=seed)
        indices = np.random.RandomState(seed).randint(0, n_samples, n_samples).astype(np.int32)
        weight = np.bincount(indices, minlength=n_samples).astype(np.float64)
        min_weight_leaf = tree.min_weight_fraction_leaf * np.sum(weight)
        criterion = self.criterion(1, self.n_classes)  # a fresh one per tree, as each tree's fit makes
        splitter = DENSE_SPLITTERS[tree.splitter](criterion, self.max_features, self.leaf, min_weight_leaf,
                                                  np.random.RandomState(seed), None)
        tree.n_features_in_, tree.n_outputs_, tree.max_features_ = X.shape[1], 1, self.max_features
        tree.tree_ = Tree(X.shape[1], self.n_classes, 1)
        builder = DepthFirstTreeBuilder(splitter, self.split, self.leaf, min_weight_leaf, self.depth,
                                        tree.min_impurity_decrease)
        builder.build(tree.tree_, X, self.y, weight, self.missing)
        tree.classes_, tree.n_classes_ = self.classes, self.n_classes[0]
        return tree


def _max_features(max_features, n_features: int) -> int:
    """The features a split draws from, as ``DecisionTreeClassifier._fit`` reads ``max_features``."""
    if max_features == "sqrt":
        return max(1, int(np.sqrt(n_features)))
    if max_features == "log2":
        return max(1, int(np.log2(n_features)))
    if max_features is None:
        return n_features
    if isinstance(max_features, numbers.Integral):
        return max_features
    return max(1, int(max_features * n_features)) if max_features > 0.0 else 0
