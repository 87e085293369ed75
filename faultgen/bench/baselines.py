"""The named baselines, one registry: each detector and isolator declared once, by :func:`register`
on a function that returns a new unfitted estimator. What reaches them by name:

- ``faultgen bench score --baseline NAME`` (scored like a ``--detector`` or ``--isolator`` plug-in,
  :mod:`faultgen.bench.score`), its help and its errors;
- ``faultgen detect --baseline NAME``, a detector that learns healthy samples (not one that learns
  labels: a classifier);
- ``faultgen bench baselines`` (the list) and ``benchmarks/bench_all.py`` (the leaderboard's rows,
  docs/leaderboard.md), through :func:`names`.

Adding a baseline is one decorated function here (or in a module of one's own imported before
the command runs: tests/baseline_example.py). The built-ins:

Detectors:

- ``pca``: the PCA monitor of thesis ch. 2.3 (:class:`analysis.monitoring.PCAMonitor`, 75 % of the
  variance as in ch. 3.2.2, alarm on T2 or Q above its 95 % limit), its score the larger of T2 and
  Q as a multiple of its limit; learns the healthy train units of the test unit's robot and task;
- ``lr``, ``svm``, ``rf``, ``stacking``: the classifiers of thesis ch. 5.2
  (:data:`analysis.classify.CLASSIFIERS`), trained on every train record labelled worn at
  >= 10 % (Table 5.2's rule);
- ``iforest``, ``ecod``: pyod's isolation forest (Liu, Ting & Zhou 2008) and ECOD (Li et al. 2022),
  outside the thesis, from the optional ``bench`` extra (``pip install faultgen-robots[bench]``).

Isolators (scored like an ``--isolator`` plug-in): ``transfer_entropy``, ``cross_correlation``,
``granger``, ``trend``, ``pca_contribution`` (:data:`analysis.isolation.ISOLATORS`, thesis ch. 3.3 and 6.3).

This module imports nothing heavy (each factory imports its estimator), so the command line's help
lists the registry without loading scikit-learn.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from sklearn.base import BaseEstimator

ROLES = ("detector", "isolator")


@dataclass(frozen=True)
class Baseline:
    """One named baseline.

    Attributes
    ----------
    name : str
        What ``--baseline`` takes; the method's name in the score files and the leaderboard.
    role : {"detector", "isolator"}
    factory : callable () -> estimator
        A new, unfitted scikit-learn estimator on every call.
    summary : str
        One line: what it is and where it comes from.
    needs : str or None
        The optional module it imports (e.g. ``"pyod"``), None when the base install has it.
    extra : str
        The package extra that installs ``needs``.
    labels : bool
        It learns from labelled records (a classifier, ``fit(X, y)``); ``faultgen detect``, which
        learns healthy samples only, refuses it.
    """

    name: str
    role: str
    factory: Callable[[], BaseEstimator]
    summary: str
    needs: str | None = None
    extra: str = "bench"
    labels: bool = False

    def make(self) -> BaseEstimator:
        """A new unfitted estimator.

        Raises
        ------
        ValueError
            If the optional module it needs is not installed (saying how to install it).
        """
        try:
            return self.factory()
        except ImportError as err:
            if self.needs is None or (err.name or "").partition(".")[0] != self.needs:
                raise
            raise ValueError(f"baseline {self.name!r} needs {self.needs}: pip install "
                             f"'faultgen-robots[{self.extra}]' (or {self.needs})") from None


#: Every registered baseline by name, in the order registered.
REGISTRY: dict[str, Baseline] = {}


def register(name: str, role: str, summary: str, *, needs: str | None = None, extra: str = "bench",
             labels: bool = False) -> Callable:
    """Decorator: register the decorated factory (no arguments -> a new unfitted estimator) as the
    baseline ``name`` (the fields of :class:`Baseline`); returns the factory unchanged.

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

    def add(factory: Callable[[], BaseEstimator]) -> Callable[[], BaseEstimator]:
        known = REGISTRY.get(name)
        if known is not None and known.factory is not factory:
            raise ValueError(f"baseline {name!r} is already registered ({known.summary})")
        REGISTRY[name] = Baseline(name, role, factory, summary, needs, extra, labels)
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


def make(name: str) -> tuple[str, BaseEstimator]:
    """(role, a new unfitted estimator) of the baseline ``name``.

    Raises
    ------
    ValueError
        For an unknown name (listing them), or a pyod baseline without pyod installed (saying how).
    """
    baseline = get(name)
    return baseline.role, baseline.make()


def healthy_detectors() -> tuple[str, ...]:
    """The detectors that learn healthy samples (not labels): the baselines ``faultgen detect`` takes."""
    return tuple(n for n in names("detector") if not REGISTRY[n].labels)


def healthy_detector(name: str) -> BaseEstimator:
    """A new unfitted detector of the baseline ``name`` that learns healthy samples: ``fit(X)``,
    ``predict(X)`` one alarm per sample (X of shape (n_samples, n_features)), the contract of
    ``faultgen detect``.

    Raises
    ------
    ValueError
        For an unknown name, an isolator or a classifier (which learns labels), each listing the
        baselines ``detect`` takes, or a missing optional module (as :func:`make`).
    """
    baseline = get(name)
    if baseline.role != "detector" or baseline.labels:
        takes = ", ".join(healthy_detectors())
        what = ("an isolator (`faultgen bench-isolators`, `bench score`)" if baseline.role != "detector" else
                "a classifier: it learns labelled records, and detect learns healthy samples only (`bench score`)")
        raise ValueError(f"baseline {name!r} is {what}; detect takes a detector that learns healthy samples: {takes}")
    return baseline.make()


def describe(role: str) -> str:
    """``role``'s names for a command's help: "pca, lr, ..., ecod (detectors; pyod's need the bench
    extra)"."""
    listed = names(role)
    needs = {b.needs: b.extra for b in REGISTRY.values() if b.role == role and b.needs}
    notes = "".join(f"; {module}'s need the {extra} extra" for module, extra in needs.items())
    return f"{', '.join(listed)} ({role}s{notes})"


def __getattr__(attribute: str):
    """``DETECTORS`` and ``ISOLATORS``, the names of each role as registered now (a baseline
    registered later is in them); ``PCADetector``, imported on first use."""
    if attribute == "DETECTORS":
        return names("detector")
    if attribute == "ISOLATORS":
        return names("isolator")
    if attribute == "PCADetector":
        from faultgen.bench.pca_detector import PCADetector

        return PCADetector
    raise AttributeError(f"module {__name__!r} has no attribute {attribute!r}")


# The built-ins. Detectors:


@register("pca", "detector", "PCA monitor, T2 or Q above its 95 % limit (thesis ch. 2.3, 75 % of variance)")
def _pca():
    from faultgen.bench.pca_detector import PCADetector

    return PCADetector()


def _classifier(name: str, **params):
    from analysis.classify import CLASSIFIERS

    return CLASSIFIERS[name](random_state=0, **params)


@register("lr", "detector", "logistic regression on labelled records (thesis ch. 5.2)", labels=True)
def _lr():
    return _classifier("lr")


@register("svm", "detector", "support vector machine on labelled records (thesis ch. 5.2)", labels=True)
def _svm():
    return _classifier("svm")


@register("rf", "detector", "random forest on labelled records (thesis ch. 5.2)", labels=True)
def _rf():
    return _classifier("rf")


@register("stacking", "detector", "LR and SVM stacked under LR, on labelled records (thesis Fig. 5-3)",
          labels=True)
def _stacking():
    return _classifier("stacking", inner_cv="sample")  # by sample: the fit sees records, not units


@register("iforest", "detector", "pyod's isolation forest (Liu, Ting & Zhou 2008), outside the thesis",
          needs="pyod")
def _iforest():
    from pyod.models.iforest import IForest

    return IForest(random_state=0)


@register("ecod", "detector", "pyod's ECOD (Li et al. 2022), outside the thesis", needs="pyod")
def _ecod():
    from pyod.models.ecod import ECOD

    return ECOD()


# Isolators: the analysis package's (analysis.isolation.ISOLATORS), with their defaults.


def _isolator(name: str):
    from analysis import isolation

    return isolation.make(name)


@register("transfer_entropy", "isolator", "largest summed net transfer entropy (thesis eq. 6.4-6.5)")
def _transfer_entropy():
    return _isolator("transfer_entropy")


@register("cross_correlation", "isolator", "the axis leading every other in cross-correlation (ch. 3.4.2)")
def _cross_correlation():
    return _isolator("cross_correlation")


@register("granger", "isolator", "largest summed net pairwise Granger F statistic (Granger 1969)")
def _granger():
    return _isolator("granger")


@register("trend", "isolator", "the axis whose signal drifts most against its own noise")
def _trend():
    return _isolator("trend")


@register("pca_contribution", "isolator", "largest contribution to the PCA residual Q (thesis eq. 3.3-3.4)")
def _pca_contribution():
    return _isolator("pca_contribution")
