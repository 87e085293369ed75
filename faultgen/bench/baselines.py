"""The named baselines, one registry (:mod:`analysis.registry`, re-exported here): each detector,
isolator and prognoser declared once, by :func:`register` on a function that returns a new unfitted
estimator; ``pca``, the classifiers and the monitor model ``pca_monitor`` are declared in
:mod:`analysis.registry` itself, where ``faultgen classify`` and the monitor layer reach them, the
others here. What reaches them by name:

- ``faultgen bench score --baseline NAME`` (scored like a ``--detector`` or ``--isolator`` plug-in,
  :mod:`faultgen.bench.score`), its help and its errors;
- ``faultgen detect --baseline NAME``, a detector that learns healthy samples (not one that learns
  labels: a classifier);
- ``faultgen bench-isolators``: every registered isolator (:func:`isolators`);
- ``faultgen bench score prognostics --baseline NAME`` or ``--prognoser NAME``: a prognoser
  (:func:`prognoser`, the contract of :mod:`faultgen.bench.prognosers`);
- ``faultgen bench baselines`` (the list) and ``benchmarks/bench_all.py`` (the leaderboard's rows,
  docs/leaderboard.md), through :func:`names` and :func:`scorable`.

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

Prognosers (the prognostics track): ``linear``, ``exponential`` (:mod:`faultgen.bench.degradation`)
and ``mean_life``, the naive one (:class:`faultgen.bench.prognosers.MeanLife`).

The twin (``twin``): ``faultgen monitor``'s twin as a detector and isolator. It runs on a context a
track's files do not hold (the test split written as raw logs, the monitor run on them:
``benchmarks/twin_baseline.py``), so it has no factory: :meth:`Baseline.make` refuses it naming that
context, and ``bench score --baseline``, ``detect --baseline`` and ``bench_all`` leave it out.

This module imports nothing heavy (each factory imports its estimator), so the command line's help
lists the registry without loading scikit-learn.
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING

# the registry itself (one for every layer: the monitor's model is in it too), re-exported here
from analysis.registry import REGISTRY, ROLES, Baseline, get, make, names, register

if TYPE_CHECKING:
    from sklearn.base import BaseEstimator

__all__ = ["REGISTRY", "ROLES", "Baseline", "describe", "for_track", "get", "healthy_detector", "healthy_detectors",
           "isolators", "make", "names", "prognoser", "register", "scorable"]

#: Why a command that takes a detector refuses a monitor model.
MONITOR = "is a monitor model (T2, Q and their limits: faultgen monitor's, detect's default's), not a detector"


def scorable() -> tuple[str, ...]:
    """The detectors and isolators ``faultgen bench score --baseline`` runs on a track's files alone
    (not an entry with a context): the leaderboard's list (``benchmarks/bench_all.py``)."""
    return tuple(n for n in names() if REGISTRY[n].role in ("detector", "isolator") and REGISTRY[n].context is None)


def for_track(name: str) -> tuple[str, BaseEstimator]:
    """(role, a new estimator) of the baseline ``name`` for ``faultgen bench score`` on a detection
    and isolation track.

    Raises
    ------
    ValueError
        For an unknown name, a prognoser (the prognostics track's), or an entry with a context (each
        listing what the command takes), or as :func:`make`.
    """
    baseline = get(name)
    if baseline.role not in ("detector", "isolator") or baseline.context is not None:
        what = {"prognoser": f"is a prognoser (`bench score prognostics --baseline {name}`)",
                "monitor": MONITOR}.get(baseline.role, f"runs on {baseline.context}")
        raise ValueError(f"baseline {name!r} {what}; bench score on this track takes: {', '.join(scorable())}")
    return make(name)


def isolators(bins=(5, 10)) -> dict[str, BaseEstimator]:
    """Every registered isolator (not one with a context) -> a new estimator with its defaults, in
    the order registered; ``transfer_entropy`` once per bin count of ``bins`` (``te5``, ``te10``:
    thesis ch. 6): the isolators of ``faultgen bench-isolators``.

    Raises
    ------
    ValueError
        As :func:`make` (a bin count the isolator refuses, a missing optional module).
    """
    chosen = {}
    for name in names("isolator"):
        if REGISTRY[name].context is not None:
            continue
        if name == "transfer_entropy":
            chosen.update({f"te{b}": make(name, bins=b)[1] for b in bins})
        else:
            chosen[name] = make(name)[1]
    return chosen


def prognoser(name: str):
    """A new prognoser of the registered name ``name`` (the contract of
    :mod:`faultgen.bench.prognosers`).

    Raises
    ------
    ValueError
        For an unknown name or another role, listing the registered prognosers.
    """
    if name not in REGISTRY or REGISTRY[name].role != "prognoser":
        raise ValueError(f"unknown prognostics baseline {name!r}; expected one of: {', '.join(names('prognoser'))} "
                         "(or MODULE:CLASS with --prognoser)")
    return make(name)[1]


def healthy_detectors() -> tuple[str, ...]:
    """The detectors that learn healthy samples (not labels): the baselines ``faultgen detect`` takes."""
    return tuple(n for n in names("detector") if not REGISTRY[n].labels and REGISTRY[n].context is None)


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
    if baseline.role != "detector" or baseline.labels or baseline.context is not None:
        takes = ", ".join(healthy_detectors())
        what = {"isolator": "is an isolator (`faultgen bench-isolators`, `bench score`)",
                "prognoser": "is a prognoser (`bench score prognostics`)", "monitor": MONITOR}.get(
            baseline.role, f"runs on {baseline.context}" if baseline.context else
            "is a classifier: it learns labelled records, and detect learns healthy samples only (`bench score`)")
        raise ValueError(f"baseline {name!r} {what}; detect takes a detector that learns healthy samples: {takes}")
    return baseline.make()


def describe(role: str) -> str:
    """``role``'s names a command builds (not one with a context) for its help: "pca, lr, ..., ecod
    (detectors; pyod's need the bench extra)"."""
    listed = [n for n in names(role) if REGISTRY[n].context is None]
    needs = {b.needs: b.extra for b in REGISTRY.values() if b.role == role and b.needs}
    notes = "".join(f"; {module}'s need the {extra} extra" for module, extra in needs.items())
    return f"{', '.join(listed)} ({role}s{notes})"


def __getattr__(attribute: str):
    """``DETECTORS``, ``ISOLATORS`` and ``PROGNOSERS``, the names of each role as registered now (a
    baseline registered later is in them); ``PCADetector``, imported on first use."""
    if attribute == "DETECTORS":
        return names("detector")
    if attribute == "ISOLATORS":
        return names("isolator")
    if attribute == "PROGNOSERS":
        return names("prognoser")
    if attribute == "PCADetector":
        from analysis.pca_detector import PCADetector

        return PCADetector
    raise AttributeError(f"module {__name__!r} has no attribute {attribute!r}")


# The built-ins (pca and the classifiers are declared in analysis.registry, where classify reaches them).
# Detectors:


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


def _isolator(name: str, **params):
    from analysis import isolation

    return isolation.make(name, **params)


#: analysis.isolation's isolators, registered in this order: (name, summary).
_ISOLATORS = (
    ("transfer_entropy", "largest summed net transfer entropy (thesis eq. 6.4-6.5)"),
    ("cross_correlation", "the axis leading every other in cross-correlation (ch. 3.4.2)"),
    ("granger", "largest summed net pairwise Granger F statistic (Granger 1969)"),
    ("trend", "the axis whose signal drifts most against its own noise"),
    ("pca_contribution", "largest contribution to the PCA residual Q (thesis eq. 3.3-3.4)"),
)
for _name, _summary in _ISOLATORS:
    register(_name, "isolator", _summary)(functools.partial(_isolator, _name))
del _name, _summary



# Prognosers: the prognostics track's (faultgen.bench.prognosers' contract).


@register("linear", "prognoser", "linear trend of the torque rise, extrapolated to the train split's end-of-life level")
def _linear(**params):
    from faultgen.bench.degradation import LinearDegradation

    return LinearDegradation(**params)


@register("exponential", "prognoser", "exponential trend of the torque rise (Gebraeel et al. 2005), extrapolated")
def _exponential(**params):
    from faultgen.bench.degradation import ExponentialDegradation

    return ExponentialDegradation(**params)


@register("mean_life", "prognoser", "the naive prognoser: the train split's lives, whatever the unit's records")
def _mean_life():
    from faultgen.bench.prognosers import MeanLife

    return MeanLife()


# The twin: the monitor's, run on raw logs outside any command that takes a track's files.


@register("twin", "detector", "faultgen monitor's twin: wear estimate's lower bound, the axis of its first alarm",
          context="the test split as raw logs, faultgen monitor run on them (benchmarks/twin_baseline.py)",
          isolates=True)
def _twin():  # never called: the entry has a context
    raise NotImplementedError
