"""The classifiers of thesis ch. 5.2, each a factory of a scikit-learn ``Pipeline``: logistic
regression, an RBF support vector machine, a random forest and the LR + SVM stack with an LR
meta-classifier (Fig. 5-3)."""

from __future__ import annotations

from collections.abc import Callable

from sklearn.ensemble import RandomForestClassifier, StackingClassifier
from sklearn.linear_model import LogisticRegression
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.svm import SVC


def _lr(random_state: int | None = 0) -> LogisticRegression:
    return LogisticRegression(max_iter=1000, random_state=random_state)


def _svc(random_state: int | None = 0) -> SVC:
    # No Platt scaling (probability=False): AUC needs only a ranking, which decision_function
    # gives without SVC's internal cross-validation (slower, and random).
    return SVC(kernel="rbf", C=1.0, gamma="scale", random_state=random_state)


def logistic_regression(random_state: int | None = 0) -> Pipeline:
    """LR (thesis eq. 5.2) on standardised features: ``StandardScaler`` -> ``LogisticRegression``."""
    return Pipeline([("scale", StandardScaler()), ("lr", _lr(random_state))])


def support_vector_machine(random_state: int | None = 0) -> Pipeline:
    """SVM with a Gaussian RBF kernel (thesis eq. 5.3), ``C = 1``, ``gamma = "scale"``, on
    standardised features. Scores are ``decision_function`` values (a ranking is all AUC needs)."""
    return Pipeline([("scale", StandardScaler()), ("svm", _svc(random_state))])


def random_forest(random_state: int | None = 0) -> Pipeline:
    """Random forest of 100 trees, seeded; trees need no scaling."""
    return Pipeline([("rf", RandomForestClassifier(n_estimators=100, random_state=random_state))])


def stacking(random_state: int | None = 0, inner_cv: str = "run") -> Pipeline:
    """Ensemble stack of thesis Fig. 5-3: LR and SVM base classifiers, LR meta-classifier.

    The meta-classifier is trained on 5-fold cross-validated base outputs (LR probabilities, SVM
    decision values), on standardised features. ``inner_cv="run"``: :func:`fit_by_run` splits the
    folds by run (:func:`run_folds`), so the base outputs it learns from are, as at test time,
    those of robots the base classifiers did not see. ``"sample"``: scikit-learn's stratified
    folds over samples, what faultgen used before (a run's days on both sides of a fold).
    Measured (docs/analysis.md, "Stacking's inner cross-validation"): on the default 26-robot
    fleet the two splits are within 0.10 of each other (by run higher with PCA, lower elsewhere),
    both below LR alone; on an 8-robot fleet by run scores far lower, below chance without
    differencing (grouped folds on few robots bias the out-of-fold outputs against the labels).
    """
    from sklearn.model_selection import StratifiedKFold

    if inner_cv not in ("run", "sample"):
        raise ValueError(f"inner_cv = {inner_cv!r}; expected 'run' or 'sample'")
    stack = StackingClassifier(estimators=[("lr", _lr(random_state)), ("svm", _svc(random_state))],
                               final_estimator=_lr(random_state), cv=5 if inner_cv == "run" else StratifiedKFold(5))
    return Pipeline([("scale", StandardScaler()), ("stacking", stack)])


#: Classifier name -> factory ``f(random_state=0) -> Pipeline`` (thesis ch. 5.2; "stacking" is ES).
CLASSIFIERS: dict[str, Callable[..., Pipeline]] = {
    "lr": logistic_regression,
    "svm": support_vector_machine,
    "rf": random_forest,
    "stacking": stacking,
}
