"""Plug-ins for tests/test_bench.py: a deliberately bad detector (random scores) and a spy that
records what it is given, to show that no test label reaches a method; and :func:`make_small`, a
track made at its test size by the command, as the bench tests use it."""

from __future__ import annotations

import json
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin


#: ``--jobs`` of a track's make (1 where not named). The thesis track is made on two, as its ``--help``
#: example makes it (``bench make thesis --jobs 2``): tests/test_help_examples.py copies this folder
#: for that line instead of making the track a second time. A make on two jobs gives the frozen
#: bits of one (the make checks them against the frozen manifest); the other tracks make on one.
JOBS = {"thesis": 2}


#: The version the shared tests read of a track whose latest version has tests of its own (prognostics
#: v3, record-level: tests/test_bench_prognostics_v3.py); the others' latest.
VERSIONS = {"prognostics": 2}


def make_small(track: str, folder: Path) -> dict:
    """The latest version (:data:`VERSIONS`) of ``track`` at its test size made into ``folder`` by `faultgen bench make`
    (a command: it starts itself again in the version's numeric profile) on :data:`JOBS` jobs; its
    manifest."""
    jobs = ["--jobs", str(JOBS[track])] if track in JOBS else []
    jobs += ["--version", str(VERSIONS[track])] if track in VERSIONS else []
    done = subprocess.run([sys.executable, "-m", "faultgen.cli", "bench", "make", track, "--size", "small", *jobs,
                           "--no-progress", "-o", str(folder)], check=False, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return json.loads((folder / "manifest.json").read_text())


#: Bootstrap resamples of `bench score` (faultgen.bench.score.RESAMPLES, 1000) in the tests that read
#: no interval or verdict of a score: what the method is shown, a command's plumbing, a row's cells.
#: The intervals themselves are checked on the scorer's 1000 (tests/test_bench.py: the random scorers'
#: intervals hold 0.5 and lie below the PCA baseline's, an isolator's interval holds its value).
FEW_RESAMPLES = 20

#: Every call the spy saw: ("fit", X, y) or ("decision_function", X) or ("predict", X).
CALLS: list[tuple] = []


class RandomScores(BaseEstimator):
    """Scores and alarms drawn at random, independent of the labels: each call's draws seeded by a
    checksum of its X (the same records, the same draws; other records, other draws)."""

    def __init__(self, seed: int = 0):
        self.seed = seed

    def fit(self, X, y=None):
        return self

    def decision_function(self, X):
        return np.random.default_rng([self.seed, zlib.crc32(np.ascontiguousarray(X).tobytes())]).random(len(X))

    def predict(self, X):
        return self.decision_function(X) > 0.95


class Spy(ClassifierMixin, BaseEstimator):
    """A classifier that records its inputs (a classifier: the benchmark gives it the train labels)."""

    def fit(self, X, y=None):
        CALLS.append(("fit", np.array(X), None if y is None else np.array(y)))
        self.classes_ = np.array([0, 1])
        return self

    def decision_function(self, X):
        CALLS.append(("decision_function", np.array(X)))
        return np.zeros(len(X))

    def predict(self, X):
        CALLS.append(("predict", np.array(X)))
        return np.zeros(len(X), dtype=bool)


class AlwaysBacklash(BaseEstimator):
    """An isolator naming axis 1 and backlash whatever it sees (scored against the chance level)."""

    def fit(self, X, y=None):
        self.source_axis_ = 1
        self.fault_ = "backlash"
        return self


class NeverNames(BaseEstimator):
    """An isolator that names no axis on any unit (the contract's "too few cycles" refusal)."""

    def fit(self, X, y=None):
        raise ValueError("too few cycles to name an axis")


class AlarmsOnlyRaising(BaseEstimator):
    """A detector with no decision_function whose predict raises: its score is its alarms, and the
    raise is named on one line as `detect` names it (issue 61, item 7)."""

    def fit(self, X, y=None):
        return self

    def predict(self, X):
        raise KeyError("no alarms today")


class _TwoClasses(ClassifierMixin, BaseEstimator):
    """A classifier fitted to the classes 0 and 1 whatever it is given: the base of the broken ones below."""

    def fit(self, X, y=None):
        self.classes_ = np.array([0, 1])
        return self


class ClassifierTooFewAlarms(_TwoClasses):
    """A classifier (fitted with labels, outside the plug-in guard) answering two alarms for any X."""

    def decision_function(self, X):
        return np.zeros(len(X))

    def predict(self, X):
        return np.zeros(2, dtype=bool)


class ClassifierFlatProbabilities(_TwoClasses):
    """A classifier whose predict_proba gives one column-less value per record (1-D)."""

    def predict_proba(self, X):
        return np.zeros(len(X))

    def predict(self, X):
        return np.zeros(len(X), dtype=bool)


class AlwaysAlarm(BaseEstimator):
    """A detector alarming on every record, with no score of its own (its score is its alarms): it
    "detects" every failing unit at its first records, and must read as at chance."""

    def fit(self, X, y=None):
        return self

    def predict(self, X):
        return np.ones(len(X), dtype=bool)
