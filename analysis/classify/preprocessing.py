"""The preprocessing combinations of thesis ch. 5.3.2 and Table 5.2 (``"+diff+var3+pca"``, ...) as
transformer steps, described in words, and put in front of a classifier (:func:`make_pipeline`)."""

from __future__ import annotations

from collections.abc import Sequence

from sklearn.base import BaseEstimator, clone
from sklearn.decomposition import PCA
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import StandardScaler

from analysis import registry
from analysis.classify.classifiers import CLASSIFIERS
from analysis.features import Difference, WindowConcat

#: Fraction of the variance the principal components of "+pca" keep (thesis ch. 5.3.2: > 90 %).
PCA_VARIANCE = 0.9


#: Token of a combination that appends the estimated-quantities block to the input (no step).
ESTIMATED = "+estM"


#: The fifteen combinations of thesis Table 5.2, in its order.
TABLE_5_2 = (
    "control", "+estM", "+diff", "+pca", "+var3", "+estM+diff", "+estM+pca", "+estM+var3", "+diff+pca",
    "+var3+pca", "+estM+diff+pca", "+estM+var3+pca", "+diff+pca+var3", "+diff+var3+pca",
    "+estM+diff+var3+pca",
)


#: The rows ``faultgen classify`` computes unless asked for more (``--full``): each step of Table 5.2
#: alone and the fullest combination without and with the estimates, in Table 5.2's order; 7 of
#: the 19 of :data:`PREPROCESSING`, at about 0.36 of their cost (docs/performance.md, "classify").
SHORT_TABLE = ("control", "+estM", "+diff", "+pca", "+var3", "+diff+var3+pca", "+estM+diff+var3+pca")


#: What classify asks of a registered classifier beyond its seed: stacking's inner folds by run
#: (thesis Procedure 1; the registry's default, for bench score's records, is by sample).
CLASSIFY_PARAMS = {"stacking": {"inner_cv": "run"}}

def preprocessing_steps(name: str) -> list[tuple[str, BaseEstimator]]:
    """Transformer steps of a combination such as ``"+diff+var3+pca"``, applied in its order.

    Tokens (thesis ch. 5.3.2): ``+diff``, :class:`~analysis.features.Difference`; ``+var<n>``,
    :class:`~analysis.features.WindowConcat` of width ``n`` ("+var3", "+var5"); ``+pca``,
    ``StandardScaler`` then ``PCA`` keeping :data:`PCA_VARIANCE` of the variance (the features
    have different units, so they are standardised first); ``+estM``, no step: it says that the
    input carries the block of estimated quantities (see :func:`evaluate`), which comes before
    every other step, as in the thesis (estimates are added before differencing). ``"control"``
    (or ``""``) is no step.

    Returns
    -------
    list of (str, estimator)
        New, unfitted steps named ``diff``, ``var3``, ``pca_scale``, ``pca``; a repeated token
        gets a numbered name (``diff_2``).

    Raises
    ------
    ValueError
        For an unknown token or ``+estM`` anywhere but first; the message names the token.
    """
    if name in ("control", ""):
        return []
    if not name.startswith("+"):
        raise ValueError(f"preprocessing {name!r}: expected 'control' or tokens like '+diff+var3+pca'")
    tokens = ["+" + t for t in name[1:].split("+")]
    steps: list[tuple[str, BaseEstimator]] = []
    for k, token in enumerate(tokens):
        if token == ESTIMATED:
            if k:
                raise ValueError(f"preprocessing {name!r}: {ESTIMATED} must come first (estimated "
                                 "quantities are added before any other step)")
            continue
        if token == "+diff":
            new = [("diff", Difference())]
        elif token == "+pca":
            new = [("pca_scale", StandardScaler()), ("pca", PCA(n_components=PCA_VARIANCE))]
        elif token.startswith("+var") and token[4:].isdigit() and int(token[4:]) >= 1:
            new = [(token[1:], WindowConcat(width=int(token[4:])))]
        else:
            raise ValueError(f"preprocessing {name!r}: unknown token {token!r}; expected +diff, +var<n>, "
                             f"+pca or {ESTIMATED} (first)")
        names = {n for n, _ in steps}
        for step_name, step in new:
            unique, i = step_name, 2
            while unique in names:
                unique, i = f"{step_name}_{i}", i + 1
            steps.append((unique, step))
    return steps


def describe_preprocessing(name: str) -> str:
    """What a combination does, step by step in its order, e.g. ``"+diff+pca+var3"`` -> "difference,
    then PCA (90 % variance), then windows of 3": the order of the tokens is the order of the steps."""
    words = []
    for step_name, step in preprocessing_steps(name):
        if isinstance(step, Difference):
            words.append("difference")
        elif isinstance(step, WindowConcat):
            words.append(f"windows of {step.width}")
        elif isinstance(step, PCA):
            words.append(f"PCA of the standardised features ({100 * PCA_VARIANCE:g} % variance)")
    return ", then ".join((["estimates added"] if name.startswith(ESTIMATED) else []) + words) or "none"


#: Combination name -> its steps (templates: :func:`make_pipeline` clones them). Table 5.2's
#: fifteen, "+var5" and the var3 / var5 pairs the thesis compares (ch. 5.4.2), and "+diff+var3".
PREPROCESSING: dict[str, list[tuple[str, BaseEstimator]]] = {
    name: preprocessing_steps(name)
    for name in (*TABLE_5_2, "+var5", "+diff+var3", "+diff+var5+pca", "+estM+diff+var5+pca")
}


def make_pipeline(classifier: str | BaseEstimator = "lr",
                  preprocessing: str | Sequence[tuple[str, BaseEstimator]] = "control",
                  random_state: int | None = 0) -> Pipeline:
    """One flat ``Pipeline``: preprocessing steps, then the classifier's steps.

    Parameters
    ----------
    classifier : str or estimator, default="lr"
        A key of :data:`CLASSIFIERS` (built with ``random_state``) or an estimator / Pipeline
        (cloned).
    preprocessing : str or list of (name, transformer), default="control"
        A combination name (any that :func:`preprocessing_steps` parses, e.g. a key of
        :data:`PREPROCESSING`) or steps (cloned).
    random_state : int or None, default=0
        Seed of the named classifiers.

    Returns
    -------
    Pipeline
        Unfitted; ``clone`` and ``get_params`` work as for any Pipeline.

    Raises
    ------
    ValueError
        For an unknown classifier or combination, or a step name used twice.
    """
    if isinstance(classifier, str):
        if classifier not in CLASSIFIERS:
            raise ValueError(f"unknown classifier {classifier!r}; expected one of: {', '.join(CLASSIFIERS)}")
        # the registry's classifier (analysis.registry), with classify's seed and stacking's inner folds
        model = registry.make(classifier, random_state=random_state, **CLASSIFY_PARAMS.get(classifier, {}))[1]
    else:
        model = clone(classifier)
    if isinstance(preprocessing, str):
        pre = preprocessing_steps(preprocessing)
    else:
        pre = [(n, clone(s)) for n, s in preprocessing]
    tail = list(model.steps) if isinstance(model, Pipeline) else [("classifier", model)]
    names = [n for n, _ in pre] + [n for n, _ in tail]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ValueError(f"step name(s) {', '.join(map(repr, dup))} used twice in the pipeline")
    return Pipeline(pre + tail)
