"""Answers a method made outside ``faultgen bench score``, scored by it as any detector or isolator.

Some methods cannot read the benchmark's files: ``faultgen monitor``'s twin reads each unit's raw
logs (angles, torques, temperatures, payload at 125-250 Hz), which ``test.h5`` does not hold (it
holds per-record features). Such a method answers elsewhere, per test unit: a score and an alarm per
record, and the axis it names. :class:`RecordedDetector` and :class:`RecordedIsolator` hand those
answers to :func:`faultgen.bench.score.score` through the detector and isolator contracts, so that
they are scored by the same code, figures and bootstrap as every other method: the scorer fits them
on the train records (they learn nothing from them) and asks each test unit's records; they find the
unit by its records' features (:func:`key`: the bytes of the array the scorer shows, which are those
of ``test.h5``) and give its recorded answers. A unit they hold no answer for raises
:class:`MissingAnswer` (a LookupError: not the ValueError by which an isolator says "undecided").
"""

from __future__ import annotations

import hashlib

import numpy as np
from sklearn.base import BaseEstimator

from faultgen.bench import files


class MissingAnswer(LookupError):
    """The scorer showed a recorded method records it holds no answer for."""


def key(X: np.ndarray) -> str:
    """The SHA-256 of ``X`` (float64, C order, with its shape): how a recorded method finds the test unit
    whose records the scorer shows it."""
    X = np.ascontiguousarray(X, dtype=np.float64)
    return hashlib.sha256(repr(X.shape).encode() + X.tobytes()).hexdigest()


def detector_answers(units: list[files.Unit], scores: dict[str, np.ndarray],
                     alarms: dict[str, np.ndarray]) -> dict[str, tuple[list[float], list[bool]]]:
    """``{key of a unit's detector features: (scores, alarms)}`` for :class:`RecordedDetector`.

    Parameters
    ----------
    units : list of files.Unit
        The test units, as ``test.h5`` holds them (:func:`faultgen.bench.files.read`).
    scores, alarms : dict of unit id -> ndarray of shape (n_records,)
        Per unit, a finite score per record (larger: more likely faulty) and an alarm per record
        (bool), in the unit's record order.

    Raises
    ------
    ValueError
        A unit without answers, answers of another length than its records, non-finite scores, or
        two units with the same features (the scorer could not tell them apart).
    """
    out: dict[str, tuple[list[float], list[bool]]] = {}
    for unit in units:
        if unit.id not in scores or unit.id not in alarms:
            raise ValueError(f"no recorded answer for test unit {unit.id}")
        s, a = np.asarray(scores[unit.id], dtype=float), np.asarray(alarms[unit.id], dtype=bool)
        n = len(unit.arrays["cycles"])
        if s.shape != (n,) or a.shape != (n,) or not np.isfinite(s).all():
            raise ValueError(f"test unit {unit.id}: {n} records, recorded scores of shape {s.shape} (finite: "
                             f"{bool(np.isfinite(s).all())}) and alarms of shape {a.shape}")
        k = key(unit.features())
        if k in out:
            raise ValueError(f"test unit {unit.id} has the same features as another unit; answers keyed by them "
                             "cannot tell the two apart")
        out[k] = (s.tolist(), a.tolist())
    return out


def isolator_answers(units: list[files.Unit], named: dict[str, int]) -> dict[str, int]:
    """``{key of a unit's mean absolute torque: the axis named (1..N, 0 undecided)}`` for
    :class:`RecordedIsolator`; every unit of ``units`` must have an answer in ``named`` (ValueError)."""
    out = {}
    for unit in units:
        if unit.id not in named:
            raise ValueError(f"no recorded axis for test unit {unit.id}")
        axis = int(named[unit.id])
        if not 0 <= axis <= unit.n_axes:
            raise ValueError(f"test unit {unit.id}: recorded axis {axis} outside 0..{unit.n_axes}")
        out[key(unit.arrays["mean_abs_torque"])] = axis
    return out


class RecordedDetector(BaseEstimator):
    """The detector contract (``fit``, ``decision_function``, ``predict``) over recorded answers.

    Parameters
    ----------
    answers : dict
        :func:`detector_answers`'s: per unit's feature key, its scores and alarms per record.
    """

    def __init__(self, answers: dict | None = None):
        self.answers = answers

    def fit(self, X, y=None):
        """Learns nothing (the answers were made by the method itself); returns self."""
        return self

    def _answer(self, X) -> tuple[np.ndarray, np.ndarray]:
        found = (self.answers or {}).get(key(X))
        if found is None:
            raise MissingAnswer(f"no recorded answer for these {len(X)} records (features {np.shape(X)})")
        return np.asarray(found[0], dtype=float), np.asarray(found[1], dtype=bool)

    def decision_function(self, X) -> np.ndarray:
        """The recorded score of each record, shape (n_records,)."""
        return self._answer(X)[0]

    def predict(self, X) -> np.ndarray:
        """The recorded alarm of each record, bool of shape (n_records,)."""
        return self._answer(X)[1]


class RecordedIsolator(BaseEstimator):
    """The isolator contract (``fit(X)`` sets ``source_axis_``) over recorded answers.

    Parameters
    ----------
    answers : dict
        :func:`isolator_answers`'s: per unit's mean absolute torque key, the axis named (0 undecided).
    """

    def __init__(self, answers: dict | None = None):
        self.answers = answers

    def fit(self, X, y=None):
        """``source_axis_``: the recorded axis of the unit whose mean absolute torque is ``X`` (n_records,
        N); :class:`MissingAnswer` for a unit without one."""
        found = (self.answers or {}).get(key(X))
        if found is None:
            raise MissingAnswer(f"no recorded axis for these {len(X)} records")
        self.source_axis_ = int(found)
        return self
