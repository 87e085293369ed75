"""The one registry of named methods: every detector, isolator, prognoser and monitor model declared
once, by :func:`register`, and made by name with :func:`make` (``make(NAME, **params)``).

It sits in the ``analysis`` package, below both of its users that may not import each other (the
``bench`` and ``monitor`` layers of faultgen, pyproject's import-linter contract). Declared here:
the analysis package's methods, ``pca`` (:class:`analysis.pca_detector.PCADetector`), the
classifiers ``lr``, ``svm``, ``rf``, ``stacking`` (thesis ch. 5.2, which ``faultgen classify``
makes through :func:`make`), and the monitor model of thesis ch. 2.3 (``pca_monitor``, role
``monitor``: :class:`analysis.monitoring.PCAMonitor`, Hotelling's T2 and Q with their limits),
which ``faultgen monitor`` (:mod:`faultgen.monitor.scoring`), ``faultgen detect``'s default Q
monitor and ``faultgen training-source`` make through :func:`make` (and so ``faultgen reproduce``,
which runs those commands). The benchmark's other baselines are declared in
:mod:`faultgen.bench.baselines` (its face: ``faultgen bench baselines``, ``bench score
--baseline``, ``detect --baseline``, ``bench-isolators``).

A **monitor** (role ``monitor``) is a scikit-learn estimator with ``fit(X)`` (X of shape (n_samples,
n_features), healthy samples), ``score_samples(X)`` -> (T2, Q), each of shape (n_samples,),
``t2_limit_`` and ``q_limit_`` (the ``1 - alpha`` limits) and ``contributions(X, statistic)`` (per
feature, shape (n_samples, n_features)). Nothing here imports scikit-learn (each factory imports its
estimator), so listing the registry loads none.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from sklearn.base import BaseEstimator

#: The roles, in the order :func:`names` lists them.
ROLES = ("detector", "isolator", "prognoser", "monitor")


@dataclass(frozen=True)
class Baseline:
    """One named baseline.

    Attributes
    ----------
    name : str
        What ``--baseline`` takes; the method's name in the score files and the leaderboard.
    role : {"detector", "isolator", "prognoser", "monitor"}
    factory : callable (**params) -> estimator
        A new, unfitted estimator on every call (a scikit-learn one for a detector, an isolator or
        a monitor; for a prognoser, the contract of :mod:`faultgen.bench.prognosers`); keyword
        parameters, when the estimator takes any, go to it. Never called for an entry with a
        ``context``.
    summary : str
        One line: what it is and where it comes from.
    needs : str or None
        The optional module it imports (e.g. ``"pyod"``), None when the base install has it.
    extra : str
        The package extra that installs ``needs``.
    labels : bool
        It learns from labelled records (a classifier, ``fit(X, y)``); ``faultgen detect``, which
        learns healthy samples only, refuses it.
    context : str or None
        What it runs on besides a track's train and test files (the twin: the monitor run on raw
        logs); None for an estimator any command builds. Commands that take only a track's files
        or a dataset refuse an entry with a context, naming it.
    isolates : bool
        A detector that also names the worn axis (the twin).
    """

    name: str
    role: str
    factory: Callable[..., BaseEstimator]
    summary: str
    needs: str | None = None
    extra: str = "bench"
    labels: bool = False
    context: str | None = None
    isolates: bool = False

    def make(self, **params) -> BaseEstimator:
        """A new unfitted estimator, ``params`` passed to its factory.

        Raises
        ------
        ValueError
            If the entry runs only in its context (naming it), or the optional module it needs is
            not installed (saying how to install it).
        """
        if self.context is not None:
            raise ValueError(f"baseline {self.name!r} runs on {self.context}; this command cannot run it")
        try:
            return self.factory(**params)
        except ImportError as err:
            if self.needs is None or (err.name or "").partition(".")[0] != self.needs:
                raise
            raise ValueError(f"baseline {self.name!r} needs {self.needs}: pip install "
                             f"'faultgen-robots[{self.extra}]' (or {self.needs})") from None


#: Every registered baseline by name, in the order registered.
REGISTRY: dict[str, Baseline] = {}


def register(name: str, role: str, summary: str, *, needs: str | None = None, extra: str = "bench",
             labels: bool = False, context: str | None = None, isolates: bool = False) -> Callable:
    """Decorator: register the decorated factory (keyword parameters or none -> a new unfitted
    estimator) as the baseline ``name`` (the fields of :class:`Baseline`); returns the factory
    unchanged. An entry with a ``context`` may decorate a function that stands for it: it is never
    called.

    Raises
    ------
    ValueError
        If ``role`` is not one of :data:`ROLES`, ``name`` is empty or holds a ``:`` (the mark of a
        ``MODULE:CLASS`` plug-in), or ``name`` is registered to another factory.
    """
    if role not in ROLES:
        raise ValueError(f"baseline {name!r}: role {role!r}; expected one of: {', '.join(ROLES)}")
    if not name or ":" in name:
        raise ValueError(f"baseline name {name!r}: expected a plain name (MODULE:CLASS names a plug-in)")

    def add(factory: Callable[..., BaseEstimator]) -> Callable[..., BaseEstimator]:
        known = REGISTRY.get(name)
        if known is not None and known.factory is not factory:
            raise ValueError(f"baseline {name!r} is already registered ({known.summary})")
        REGISTRY[name] = Baseline(name, role, factory, summary, needs, extra, labels, context, isolates)
        return factory

    return add


def names(role: str | None = None) -> tuple[str, ...]:
    """The registered names, detectors first, each role in the order registered; only ``role``'s
    when given."""
    return tuple(b.name for r in ROLES if role in (None, r) for b in REGISTRY.values() if b.role == r)


def get(name: str) -> Baseline:
    """The baseline ``name``.

    Raises
    ------
    ValueError
        For an unknown name, listing the registered ones.
    """
    if name not in REGISTRY:
        raise ValueError(f"unknown baseline {name!r}; expected one of: {', '.join(names())}")
    return REGISTRY[name]


def make(name: str, **params) -> tuple[str, BaseEstimator]:
    """(role, a new unfitted estimator) of the baseline ``name``, ``params`` given to it (e.g.
    ``make("transfer_entropy", bins=5)``).

    Raises
    ------
    ValueError
        For an unknown name (listing them), an entry that runs only in its context (the twin), or a
        pyod baseline without pyod installed (saying how).
    """
    baseline = get(name)
    return baseline.role, baseline.make(**params)


# The analysis package's detectors, declared here so that its own commands (classify) reach them:
# the PCA baseline and the classifiers of thesis ch. 5.2 (seed 0 unless given).


@register("pca", "detector", "PCA monitor, T2 or Q above its 95 % limit (thesis ch. 2.3, 75 % of variance)")
def _pca(**params):
    from analysis.pca_detector import PCADetector

    return PCADetector(**params)


def _classifier(name: str, **params):
    from analysis.classify.classifiers import CLASSIFIERS

    return CLASSIFIERS[name](**{"random_state": 0, **params})


@register("lr", "detector", "logistic regression on labelled records (thesis ch. 5.2)", labels=True)
def _lr(**params):
    return _classifier("lr", **params)


@register("svm", "detector", "support vector machine on labelled records (thesis ch. 5.2)", labels=True)
def _svm(**params):
    return _classifier("svm", **params)


@register("rf", "detector", "random forest on labelled records (thesis ch. 5.2)", labels=True)
def _rf(**params):
    return _classifier("rf", **params)


@register("stacking", "detector", "LR and SVM stacked under LR, on labelled records (thesis Fig. 5-3)",
          labels=True)
def _stacking(**params):
    # by sample: bench score's fit sees records, not units (classify asks for inner_cv="run")
    return _classifier("stacking", **{"inner_cv": "sample", **params})


# The monitor model, declared here so that the monitor layer reaches it without the bench layer.


@register("pca_monitor", "monitor", "PCA T2/Q monitor with its limits (thesis ch. 2.3, eq. 2.3-2.6): the model of "
          "faultgen monitor, detect's default and training-source")
def _pca_monitor(**params):
    from analysis.monitoring import PCAMonitor

    return PCAMonitor(**params)
