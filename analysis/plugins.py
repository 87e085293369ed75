"""A user's detector or isolator, named ``module:Class`` on the command line (``detect
--detector``, ``bench-isolators --isolator``), loaded and held to its contract.

A plug-in is executed code: importing its module runs whatever the module does, with the user's
rights, as ``python -c "import module"`` would. Name only modules you trust (docs/reliability.md,
"Threat model"). What this module adds is that a plug-in that fails, or answers outside its
contract, stops the command with one line naming it (:class:`PluginError`, exit 2), before any
output is written, instead of a traceback or a table built on a wrong answer:

- its module must import (any exception: refused), the class must be a scikit-learn estimator
  and ``Class()`` must succeed;
- an isolator's ``fit(X)``, X of shape (n_cycles, N), must set ``source_axis_`` to a whole number
  in 0..N (0: undecided). A ``ValueError`` from ``fit`` keeps its meaning in the isolator contract
  (too few cycles for this isolator); any other exception is refused;
- a detector's ``fit(X)`` and ``predict(X)`` must not raise, and ``predict(X)`` must give one
  finite alarm per sample (shape (n_samples,)). A detector that also has control charts, a
  ``score_samples(X)`` giving ``(t2, q)`` and fitted limits ``t2_limit_`` and ``q_limit_`` (as
  :class:`analysis.monitoring.PCAMonitor`), has them drawn by ``detect`` like the PCA monitor's;
  they too must be finite (T2 and Q one per sample, the limits positive).

The current folder is searched first while the module is imported, and only then: ``sys.path``
is left as it was, so a later import in faultgen never finds a file of the current folder.
"""

from __future__ import annotations

import importlib
import os
import sys

import numpy as np
from sklearn.base import BaseEstimator

from faultgen.checks import is_whole

ROLES = ("isolator", "detector")
#: A detector's control limits, read with its ``score_samples`` (the charts of ``detect``).
_LIMITS = ("t2_limit_", "q_limit_")


class PluginError(Exception):
    """A plug-in that failed or broke its contract; the command line prints it as one line and
    exits with :attr:`exit_code` (2: the plug-in is refused)."""

    exit_code = 2


def load(spec: str, role: str) -> "Plugin":
    """The plug-in ``spec`` (``"package.module:Class"``), imported and built once with its
    defaults to check it, as a :class:`Plugin` the benchmarks can clone and fit.

    Raises
    ------
    PluginError
        If ``spec`` is not ``module:Class``, the module cannot be imported (any exception while
        importing it), it has no such class, the class is not a scikit-learn estimator
        (``sklearn.base.BaseEstimator``) or ``Class()`` raises; the message names the plug-in.
    """
    if role not in ROLES:
        raise ValueError(f"role {role!r}: expected one of {', '.join(ROLES)}")
    plugin = Plugin(spec, role)
    plugin._build()
    return plugin


def _estimator_class(spec: str) -> type:
    module_name, _, class_name = spec.partition(":")
    if not module_name or not class_name.isidentifier():
        raise PluginError(f"plug-in {spec!r}: expected package.module:Class, e.g. mine:MyIsolator")
    module = sys.modules.get(module_name)
    if module is None:
        try:
            module = import_here(module_name)
        except ImportError as err:
            raise PluginError(f"plug-in {spec!r}: cannot import {module_name!r} ({err}); put it in the current "
                              "folder or on PYTHONPATH") from None
        except (Exception, SystemExit) as err:  # SyntaxError, sys.exit(), whatever the module's own code raised
            raise PluginError(f"plug-in {spec!r}: importing {module_name!r} failed: {_what(err)}") from None
    cls = getattr(module, class_name, None)
    if not isinstance(cls, type):
        raise PluginError(f"plug-in {spec!r}: module {module_name!r} has no class {class_name!r}")
    if not issubclass(cls, BaseEstimator):
        raise PluginError(f"plug-in {spec!r}: {class_name} is not a scikit-learn estimator; derive it from "
                          "analysis.isolation.Isolator or sklearn.base.BaseEstimator")
    return cls


def import_here(module_name: str):
    """``importlib.import_module(module_name)`` with the current folder first on ``sys.path`` for this
    import only (a user's plug-in or prognoser module beside them); raises what the import raises."""
    added = os.getcwd() not in sys.path
    if added:
        sys.path.insert(0, os.getcwd())
    try:
        return importlib.import_module(module_name)
    finally:
        if added and os.getcwd() in sys.path:
            sys.path.remove(os.getcwd())


def _what(err: BaseException) -> str:
    """'TypeError: message' of an exception, on one line."""
    return " ".join(f"{type(err).__name__}: {err}".split())


class Plugin(BaseEstimator):
    """A user's estimator behind a guard that holds it to its role's contract.

    Parameters
    ----------
    spec : str
        ``"package.module:Class"``; the estimator is ``Class()``.
    role : {"isolator", "detector"}

    Attributes
    ----------
    estimator_ : BaseEstimator
        The user's estimator, fitted.
    source_axis_ : int
        An isolator's answer, 1..N, or 0 (undecided).
    t2_limit_, q_limit_ : float
        A detector's control limits, present only when its estimator has them and
        ``score_samples`` (its charts are then drawn).
    """

    def __init__(self, spec: str = "", role: str = "isolator"):
        self.spec = spec
        self.role = role

    def build(self) -> BaseEstimator:
        """A new, unfitted ``Class()`` of the plug-in (``faultgen bench score`` fits a classifier
        with labels through it); raises :class:`PluginError` as :func:`load` does."""
        return self._build()

    def _build(self) -> BaseEstimator:
        cls = _estimator_class(self.spec)
        try:
            return cls()
        except Exception as err:
            raise PluginError(f"plug-in {self.spec!r}: {cls.__name__}() failed: {_what(err)}") from None

    def fit(self, X, y=None) -> "Plugin":
        """Fit the user's estimator on ``X`` (n_samples, n_features) and check what it set.

        Raises
        ------
        ValueError
            An isolator's own ValueError (too few rows for it), unchanged.
        PluginError
            If ``fit`` raised anything else (a detector: anything), or an isolator's
            ``source_axis_`` is missing or not a whole number in 0..N.
        """
        X = np.asarray(X)
        estimator = self._build()
        try:
            estimator.fit(X)
        except ValueError as err:
            if self.role == "isolator":  # the isolator contract's "too few cycles"
                raise
            raise PluginError(f"plug-in {self.spec!r}: fit(X) of X {X.shape} failed: {_what(err)}") from None
        except Exception as err:
            raise PluginError(f"plug-in {self.spec!r}: fit(X) of X {X.shape} failed: {_what(err)}") from None
        self.estimator_ = estimator
        if self.role == "isolator":
            axis = getattr(estimator, "source_axis_", None)
            if isinstance(axis, (float, np.floating)) and float(axis).is_integer():
                axis = int(axis)
            if not is_whole(axis, 0) or axis > X.shape[1]:
                raise PluginError(f"plug-in {self.spec!r}: fit(X) set source_axis_ = {axis!r}; the isolator "
                                  f"contract is a whole number 1..{X.shape[1]} (the axis), or 0 when undecided")
            self.source_axis_ = int(axis)
        if self.role == "detector" and all(hasattr(estimator, a) for a in ("score_samples", *_LIMITS)):
            for name in _LIMITS:
                value = getattr(estimator, name)
                if not (isinstance(value, (int, float, np.number)) and np.isfinite(value) and value > 0):
                    raise PluginError(f"plug-in {self.spec!r}: fit(X) set {name} = {value!r}; a control limit is a "
                                      "finite number > 0")
                setattr(self, name, float(value))
        return self

    def score_samples(self, X) -> tuple[np.ndarray, np.ndarray]:
        """A detector's control-chart statistics ``(t2, q)`` for ``X`` (n_samples, n_features),
        each of shape (n_samples,), when its estimator has them (``t2_limit_`` is then set).

        Raises
        ------
        AttributeError
            If the detector has no charts (no ``score_samples`` or limits).
        PluginError
            If ``score_samples`` raised, or did not give two finite arrays of shape (n_samples,).
        """
        if not hasattr(self, "t2_limit_"):
            raise AttributeError(f"plug-in {self.spec!r} has no control charts (score_samples, t2_limit_, q_limit_)")
        X = np.asarray(X)
        try:
            t2, q = (np.asarray(v, dtype=float) for v in self.estimator_.score_samples(X))
        except Exception as err:
            raise PluginError(f"plug-in {self.spec!r}: score_samples(X) of X {X.shape} failed: {_what(err)}") from None
        for name, values in (("t2", t2), ("q", q)):
            if values.shape != (len(X),) or not np.isfinite(values).all():
                raise PluginError(f"plug-in {self.spec!r}: score_samples(X) gave {name} of {_describe(values)} for "
                                  f"X {X.shape}; expected (t2, q), each finite, shape ({len(X)},)")
        return t2, q

    def predict(self, X) -> np.ndarray:
        """A detector's alarms for ``X`` (n_samples, n_features): bool array of shape (n_samples,).

        Raises
        ------
        PluginError
            If ``predict`` raised, or its answer is not one finite number (or bool) per sample.
        """
        return alarms(self.spec, self.estimator_, X)


def alarms(spec: str, estimator, X) -> np.ndarray:
    """``estimator.predict(X)`` held to the detector contract (:meth:`Plugin.predict`): bool array
    of shape (n_samples,), or :class:`PluginError` naming ``spec`` (``faultgen bench score`` calls
    a plug-in's classifier, which it fits with labels outside a :class:`Plugin`, through it too)."""
    X = np.asarray(X)
    try:
        found = np.asarray(estimator.predict(X))
    except PluginError:  # a Plugin's own predict: already held to the contract
        raise
    except Exception as err:
        raise PluginError(f"plug-in {spec!r}: predict(X) of X {X.shape} failed: {_what(err)}") from None
    finite = found.dtype.kind in "biuf" and (found.dtype.kind != "f" or bool(np.isfinite(found).all()))
    if found.shape != (len(X),) or not finite:
        raise PluginError(f"plug-in {spec!r}: predict(X) gave {_describe(found)} for X {X.shape}; the "
                          f"detector contract is one finite alarm (bool or 0/1) per sample, shape ({len(X)},)")
    return found.astype(bool)


def _describe(values: np.ndarray) -> str:
    """'shape (3,), dtype float64, with NaN or inf' of an answer, for a message."""
    text = f"shape {values.shape}, dtype {values.dtype}"
    if values.dtype.kind == "f" and not np.isfinite(values).all():
        text += ", with NaN or inf"
    return text
