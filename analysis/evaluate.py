"""One evaluation harness: ``evaluate(method, data, protocol, rules) -> Scores``.

Every command that judges a method fits it on some records and tests it on others; this module is
where that happens, once:

- **data** (:class:`Data`): the records as arrays, ``X`` of shape (n_records, n_features), their
  labels ``y`` (0/1: the record counts as faulty) and fault level, the unit (run) of each record
  (``groups``) and whether its unit is healthy;
- **protocol**: a scikit-learn splitter, ``split(X, y, groups)`` yielding (train, test) row indices
  and ``get_n_splits(X, y, groups)`` (:class:`sklearn.model_selection.LeaveOneGroupOut`, or one of
  this module's: :class:`TrackSplit`, a bench track's train and test files per robot and task;
  :class:`LeavePairOut`, thesis Procedure 1; :class:`OwnHistory`, an isolator reading the first
  cycles of the tested run itself; :class:`Given`, folds as given: a training source's days and the
  days it judges, thesis ch. 4). No protocol here puts rows of one group on both sides, except
  :class:`OwnHistory` and own-history folds given, whose method learns the tested unit's own
  history by design;
- **method**: an unfitted estimator made by :func:`analysis.registry.make` (or a user's plug-in,
  :mod:`analysis.plugins`), in one of the roles ``detector`` (a classifier ``fit(X, y)`` on all
  training records, anything else ``fit(X)`` on the healthy units' records; then per test unit its
  scores and alarms) or ``isolator`` (``fit(X)`` on each test case's records names
  ``source_axis_``);
- **rules**: :class:`analysis.scoring.Rules`, by which :class:`Scores` computes onsets and an
  isolator's "too few cycles" answer.

The commands (``bench score``, ``bench-isolators``, ``classify``, ...) keep their own figures and
tables: they format :class:`Scores`.
"""

from __future__ import annotations

import dataclasses
import inspect
from collections.abc import Iterator, Sequence
from itertools import product

import numpy as np
from sklearn.base import clone, is_classifier
from sklearn.model_selection import BaseCrossValidator, LeaveOneGroupOut

from analysis import plugins, scoring

#: The roles :func:`evaluate` runs (a registry entry's ``role``).
ROLES = ("detector", "isolator")

__all__ = ["Data", "Scores", "TrackSplit", "LeavePairOut", "OwnHistory", "Given", "LeaveOneGroupOut", "evaluate",
           "fit_detector", "detector_scores", "isolate"]


@dataclasses.dataclass(frozen=True)
class Data:
    """Records to evaluate a method on.

    Parameters
    ----------
    X : ndarray of shape (n_records, n_features)
        The features of each record (a unit's rows in time order).
    groups : ndarray of shape (n_records,)
        The unit (run, robot) of each record: a protocol splits by it, a detector is tested on each
        unit's rows on their own.
    y : ndarray of shape (n_records,) or None
        0/1 labels (1: the record counts as faulty), what a classifier learns; None: all 0.
    healthy : ndarray of bool of shape (n_records,) or None
        Rows of units without fault: what a detector that learns healthy records only is fitted on;
        None: the rows whose ``y`` is 0.
    width : ndarray of int of shape (n_records,) or None
        The features of each row: its first ``width`` columns of ``X`` (units of robots with other
        numbers of axes stacked, the rest NaN, :meth:`of_units`); None: every column.

    Raises
    ------
    ValueError
        When the shapes do not match (naming the array and the shape expected).
    """

    X: np.ndarray
    groups: np.ndarray
    y: np.ndarray | None = None
    healthy: np.ndarray | None = None
    width: np.ndarray | None = None

    def __post_init__(self):
        X = np.asarray(self.X)
        if X.ndim != 2:
            raise ValueError(f"X must have shape (n_records, n_features), got shape {X.shape}")
        object.__setattr__(self, "X", X)
        n = len(X)
        y = np.zeros(n, dtype=int) if self.y is None else np.asarray(self.y)
        healthy = (y == 0) if self.healthy is None else np.asarray(self.healthy, dtype=bool)
        width = np.full(n, X.shape[1]) if self.width is None else np.asarray(self.width, dtype=int)
        for name, value in (("groups", np.asarray(self.groups)), ("y", y), ("healthy", healthy), ("width", width)):
            if value.shape != (n,):
                raise ValueError(f"{name} must have shape ({n},) like X's rows, got {value.shape}")
            object.__setattr__(self, name, value)

    @classmethod
    def of_units(cls, X_units: Sequence[np.ndarray], unit_ids: Sequence, y_units: Sequence[np.ndarray] | None = None,
                 healthy_units: Sequence[bool] | None = None) -> Data:
        """Records of several units stacked: ``X_units`` one (n_k, n_features) array per unit,
        ``unit_ids`` their names, ``y_units`` their labels and ``healthy_units`` whether each is
        without fault (one bool per unit). Units with fewer features than the widest are padded
        with NaN (``width`` says how many are theirs)."""
        sizes, widths = [len(x) for x in X_units], [np.shape(x)[1] for x in X_units]
        dtype = np.result_type(*X_units) if len(X_units) else np.dtype(float)
        X = np.full((sum(sizes), max(widths, default=0)), np.nan, dtype=dtype if dtype.kind == "f" else float)
        for start, x, w in zip(np.cumsum([0, *sizes[:-1]]), X_units, widths):
            X[start:start + len(x), :w] = x
        groups = np.repeat(np.asarray(unit_ids, dtype=object), sizes)
        y = None if y_units is None else np.concatenate([np.asarray(v) for v in y_units]).astype(int)
        healthy = None if healthy_units is None else np.repeat(np.asarray(healthy_units, dtype=bool), sizes)
        return cls(X, groups, y, healthy, np.repeat(widths, sizes))

    def rows(self, group) -> np.ndarray:
        """The row indices of ``group``, in order (empty for a group without rows)."""
        if "_rows" not in self.__dict__:  # built once: a command asks for every unit's rows
            object.__setattr__(self, "_rows", _rows_of(self.groups))
        return self._rows.get(group, np.zeros(0, dtype=int))

    def features(self, rows: np.ndarray) -> np.ndarray:
        """``X`` of ``rows``, shape (len(rows), their width).

        Raises
        ------
        ValueError
            When the rows are of units with other numbers of features (naming them).
        """
        widths = np.unique(self.width[rows])
        if len(widths) > 1:
            raise ValueError(f"records of {len(widths)} feature counts ({', '.join(map(str, widths))}) in one set: "
                             "units of robots with other numbers of axes cannot be fitted together")
        return self.X[rows, :widths[0]] if len(widths) else self.X[rows]


def _rows_of(groups: np.ndarray) -> dict:
    """Group -> its row indices in order, for every group of ``groups`` (one pass)."""
    rows: dict = {}
    for i, group in enumerate(np.asarray(groups).tolist()):
        rows.setdefault(group, []).append(i)
    return {group: np.asarray(found, dtype=int) for group, found in rows.items()}


# --- protocols: scikit-learn splitters ------------------------------------------------------------------------


class _Splitter(BaseCrossValidator):
    """What the protocols share: a scikit-learn cross-validator whose ``split`` yields the folds and
    ``get_n_splits`` counts them."""

    def get_n_splits(self, X=None, y=None, groups=None) -> int:
        return sum(1 for _ in self.split(X, y, groups))


class TrackSplit(_Splitter):
    """A bench track's protocol: the method learns the records of the train file and is tested on
    those of the test file, one fold per setup (robot and task) of the test units, fitted on the
    train units of that setup (all train units where none has it).

    Parameters
    ----------
    is_test : array of bool, shape (n_records,)
        Rows of the test file.
    setups : array, shape (n_records,)
        Each row's setup (e.g. "robot/task"); folds in sorted order of the test setups.
    """

    def __init__(self, is_test, setups):
        self.is_test, self.setups = np.asarray(is_test, dtype=bool), np.asarray(setups)

    def split(self, X=None, y=None, groups=None) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        train_rows = ~self.is_test
        for setup in sorted(set(self.setups[self.is_test].tolist())):
            own = train_rows & (self.setups == setup)
            yield np.flatnonzero(own if own.any() else train_rows), np.flatnonzero(self.is_test & (self.setups == setup))


#: Most held-out pairs one evaluation fits (each pair fits every classifier of every combination):
#: "every pair" of a dataset with more is refused before any fit (``faultgen classify --pairs``).
MAX_PAIRS = 100_000


def select_pairs(failed_groups, normal_groups, n_pairs: int | None = None,
                 random_state: int | None = 0) -> list[tuple]:
    """(failed, normal) pairs of Procedure 1: all, failed-major, or ``n_pairs`` of them.

    A subset is drawn without replacement with ``numpy.random.default_rng(random_state)`` and
    kept in the same order as the full list, so equal arguments give equal pairs.

    Raises
    ------
    ValueError
        If ``n_pairs`` is below 1, or every pair is asked for (``None``, or at least as many as
        there are) and there are more than :data:`MAX_PAIRS`.
    """
    total = len(failed_groups) * len(normal_groups)
    if (n_pairs is None or n_pairs >= total) and total > MAX_PAIRS:
        raise ValueError(
            f"every pair of {len(failed_groups)} worn x {len(normal_groups)} unworn runs is {total} held-out "
            f"pairs, more than {MAX_PAIRS} (each fits every classifier); draw some with --pairs N (n_pairs)"
        )
    pairs = list(product(failed_groups, normal_groups))
    if n_pairs is None or n_pairs >= len(pairs):
        return pairs
    if n_pairs < 1:
        raise ValueError(f"n_pairs = {n_pairs!r}; expected None or an integer >= 1")
    chosen = np.sort(np.random.default_rng(random_state).choice(len(pairs), size=n_pairs, replace=False))
    return [pairs[i] for i in chosen]



class LeavePairOut(_Splitter):
    """Thesis Procedure 1: one failed and one normal unit held out at a time, the model trained on
    every other unit; every pair, failed-major, or ``n_pairs`` of them drawn with
    ``numpy.random.default_rng(random_state)`` and kept in the full list's order
    (:func:`select_pairs`, which refuses more than :data:`MAX_PAIRS`).

    Parameters
    ----------
    failed, normal : sequence
        The failed and normal units (values of ``groups``); units in neither always train.
    n_pairs : int or None
        None: every pair.
    random_state : int or None
        Seed of the drawn pairs.
    """

    def __init__(self, failed: Sequence, normal: Sequence, n_pairs: int | None = None, random_state: int | None = 0):
        self.failed, self.normal = list(failed), list(normal)
        self.n_pairs, self.random_state = n_pairs, random_state

    def pairs(self) -> list[tuple]:
        """The (failed, normal) pairs held out, in fold order."""
        return select_pairs(self.failed, self.normal, self.n_pairs, self.random_state)

    def split(self, X=None, y=None, groups=None) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        if groups is None:
            raise ValueError("LeavePairOut needs groups: the unit of each record")
        groups = np.asarray(groups)
        for pair in self.pairs():
            held = np.isin(groups, list(pair))
            yield np.flatnonzero(~held), np.flatnonzero(held)


class OwnHistory(_Splitter):
    """An isolator's protocol: each case is a unit's first ``n`` records, which the isolator both
    learns and names the source axis from (the tested unit's own history; nothing learnt from other
    units). ``cases``: (unit, n) pairs, n None for all of the unit's records; one fold per case, in
    order, train and test the same rows."""

    def __init__(self, cases: Sequence[tuple]):
        self.cases = list(cases)

    def split(self, X=None, y=None, groups=None) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        if groups is None:
            raise ValueError("OwnHistory needs groups: the unit of each record")
        rows_of = _rows_of(groups)
        for unit, n in self.cases:
            rows = rows_of.get(unit, np.zeros(0, dtype=int))[:n]
            yield rows, rows


class Given(_Splitter):
    """Folds given as they are: ``folds`` a list of (train, test) row indices, e.g. a training
    source's days learnt and the days of each robot it judges (thesis ch. 4: a robot's own first
    days, one-to-one, or a normal robot's, one-to-many; the own-history cases put one unit's
    earlier rows in train and its later ones in test, by design)."""

    def __init__(self, folds: Sequence[tuple]):
        self.folds = list(folds)

    def split(self, X=None, y=None, groups=None) -> Iterator[tuple[np.ndarray, np.ndarray]]:
        for train, test in self.folds:
            yield np.asarray(train), np.asarray(test)


# --- methods ----------------------------------------------------------------------------------------------------


def _takes_groups(function) -> bool:
    """Whether ``function`` takes a ``groups`` keyword (a method that fits or scores run by run,
    :class:`analysis.classify.ByRun`)."""
    return "groups" in inspect.signature(function).parameters


def fit_detector(method, X: np.ndarray, y: np.ndarray, healthy: np.ndarray, groups: np.ndarray | None = None,
                 fit=None):
    """A new copy of the detector ``method`` fitted on training records: a classifier
    (``sklearn.base.is_classifier``; a plug-in's class is asked through its ``build()``) ``fit(X, y)``
    on all of them (``fit(X, y, groups=groups)`` where its ``fit`` takes the unit of each record),
    any other estimator ``fit(X)`` on the ``healthy`` rows (``fit(X, estimator)`` where ``fit`` is
    given, e.g. :func:`analysis.monitoring.fit_q_monitor`). Returns (the fitted object that gives
    alarms, the estimator that gives scores).

    Raises
    ------
    ValueError
        When a classifier's ``fit`` raises (naming the shape of X and the error).
    """
    template = method.build() if hasattr(method, "build") else method  # a plug-in: the user's own class
    if is_classifier(template):
        try:
            inner = clone(template)
            inner = inner.fit(X, y, groups=groups) if _takes_groups(inner.fit) else inner.fit(X, y)
        except Exception as err:  # noqa: BLE001 (a plug-in may raise anything: named on one line)
            raise ValueError(f"fit(X, y) of X {X.shape} failed: {type(err).__name__}: {err}") from None
        return inner, inner
    # a plug-in: behind its contract guard (analysis.plugins)
    fitted = clone(method).fit(X[healthy]) if fit is None else fit(X[healthy], clone(method))
    return fitted, getattr(fitted, "estimator_", fitted)


def detector_scores(estimator, X: np.ndarray, name: str, groups: np.ndarray | None = None) -> np.ndarray:
    """A detector's score per record, shape (n_records,) (larger: more likely faulty):
    ``decision_function``, else ``predict_proba[:, -1]``, else its alarms (:func:`analysis.plugins.alarms`);
    ``groups`` (the unit of each record) given to a method that takes them.

    Raises
    ------
    ValueError
        Naming ``name`` when the method raises or gives other than one finite number per record.
    """
    for method in ("decision_function", "predict_proba"):
        if hasattr(estimator, method):
            call = getattr(estimator, method)
            try:
                values = np.asarray(call(X, groups=groups) if _takes_groups(call) else call(X), dtype=float)
            except Exception as err:  # noqa: BLE001 (a plug-in may raise anything: named on one line)
                raise ValueError(f"{name}: {method}(X) of X {X.shape} failed: {type(err).__name__}: {err}") from None
            if method == "predict_proba":
                values = values[:, -1] if values.ndim == 2 and values.shape[1] else np.full(0, np.nan)
            if values.shape != (len(X),) or not np.isfinite(values).all():
                raise ValueError(f"{name}: {method}(X) gave shape {values.shape} or non-finite values for X "
                                 f"{X.shape}; expected one finite score per record")
            return values
    return plugins.alarms(name, estimator, X).astype(float)


def isolate(method, X: np.ndarray, rules: scoring.Rules) -> tuple[int, object]:
    """The isolator ``method`` (unfitted; cloned) fitted on ``X`` (n_records, N axes): (the axis it
    names, 1..N or :data:`analysis.scoring.UNDECIDED`; its ``fault_`` or None). Where it cannot run
    (its ``fit`` raises ValueError: too few records) the answer ``rules`` gives
    (:func:`analysis.scoring.too_few_answer`) and None."""
    try:
        fitted = clone(method).fit(X)
        return int(fitted.source_axis_), getattr(getattr(fitted, "estimator_", fitted), "fault_", None)
    except ValueError:  # the isolator contract's "too few cycles"
        return scoring.too_few_answer(rules), None


# --- the harness ------------------------------------------------------------------------------------------------


@dataclasses.dataclass
class Scores:
    """What :func:`evaluate` measured.

    Attributes
    ----------
    name, role : str
        The method's name and role.
    rules : analysis.scoring.Rules
    folds : list of (train, test) index arrays
        The protocol's folds, in order.
    scores : ndarray of shape (n_records,)
        A detector's score of each tested record (NaN: not tested); for an isolator empty.
    alarms : ndarray of bool of shape (n_records,)
        A detector's alarm of each tested record.
    tested : ndarray of bool of shape (n_records,)
        Rows some fold tested (a row tested by several folds holds the last fold's answer).
    named : list of (int, object)
        An isolator's answer per fold: (axis named, ``fault_`` or None), :func:`isolate`.
    fitted : list
        A detector's fitted object per fold (what gave the alarms: e.g. a monitor whose limits a
        chart draws).
    """

    name: str
    role: str
    rules: scoring.Rules
    folds: list
    scores: np.ndarray
    alarms: np.ndarray
    tested: np.ndarray
    named: list
    fitted: list = dataclasses.field(default_factory=list)

    def of(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(scores, alarms) of the given rows."""
        return self.scores[rows], self.alarms[rows]

    def onset(self, rows: np.ndarray, fault_start: int | None = None, skip: int = 0) -> int | None:
        """The onset of the alarms of ``rows`` (one unit's, in order) under the rules
        (:func:`analysis.scoring.onset`): an index into ``rows`` or None."""
        return scoring.onset(self.alarms[rows], self.rules, fault_start=fault_start, skip=skip)


def evaluate(method, data: Data, protocol, rules: scoring.Rules | None, name: str = "method",
             role: str = "detector", *, alarms: bool = True, scores: bool = True, test_by: str = "group",
             fit=None) -> Scores:
    """``method`` fitted and tested on ``data`` as ``protocol`` splits it; its answers as
    :class:`Scores` under ``rules``.

    A detector is fitted once per fold (:func:`fit_detector`) and tested on each test unit's rows
    on their own (:func:`detector_scores`, :func:`analysis.plugins.alarms`: one score and one alarm
    per record), or on the fold's test rows at once (``test_by="fold"``, with their ``groups``
    where the method takes them); an isolator names the source axis of each fold's test rows
    (:func:`isolate`).

    Parameters
    ----------
    method : estimator
        Unfitted (cloned, never changed); e.g. ``analysis.registry.make(NAME)[1]``.
    data : Data
    protocol : splitter
        ``split(X, y, groups)`` -> (train, test) index arrays.
    rules : analysis.scoring.Rules or None
        None: scores only (a classifier's AUC needs no onset rule); an isolator needs rules.
    name : str
        The method's name in messages.
    role : {"detector", "isolator"}
    alarms, scores : bool
        Whether a detector's alarms (``predict``) and its scores are asked for (those not: all False,
        all NaN).
    fit : callable (X, estimator) -> fitted estimator, or None
        How a detector that learns healthy records is fitted (None: ``estimator.fit(X)``).
    test_by : {"group", "fold"}
        Test each unit's rows on their own, or each fold's test rows at once.

    Raises
    ------
    ValueError
        For another role, or what the method's fit or predict raises (named by :func:`fit_detector`,
        :func:`detector_scores`, :func:`analysis.plugins.alarms`).
    """
    if role not in ROLES:
        raise ValueError(f"role {role!r}; expected one of: {', '.join(ROLES)}")
    if test_by not in ("group", "fold"):
        raise ValueError(f"test_by = {test_by!r}; expected 'group' or 'fold'")
    if role == "isolator" and rules is None:
        raise ValueError("an isolator is scored under rules (what 'too few cycles' counts as); got rules=None")
    n = len(data.X)
    values, flags, tested = np.full(n, np.nan), np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
    folds, named, fits = [], [], []
    for train, test in protocol.split(data.X, data.y, data.groups):
        train, test = np.asarray(train), np.asarray(test)
        folds.append((train, test))
        tested[test] = True
        if role == "isolator":
            named.append(isolate(method, data.features(test), rules))
            continue
        fitted, inner = fit_detector(method, data.features(train), data.y[train], data.healthy[train],
                                     data.groups[train], fit)
        fits.append(fitted)
        test_groups = data.groups[test]
        sets = [test] if test_by == "fold" else [test[test_groups == g] for g in dict.fromkeys(test_groups.tolist())]
        for rows in sets:
            X = data.features(rows)
            if scores:
                values[rows] = detector_scores(inner, X, name, data.groups[rows])
            if alarms:
                flags[rows] = plugins.alarms(name, fitted, X)
    return Scores(name, role, rules, folds, values, flags, tested, named, fits)
