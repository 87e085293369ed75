"""Scores of a remaining-life prediction as the field gives them, beside ProgPy's metrics:
the PHM 2008 challenge's asymmetric score, a late median, and an interval covering the truth.

- :func:`phm08_score`: per prediction ``d = predicted - true`` remaining life, ``exp(-d / 13) - 1``
  when early (``d`` < 0) and ``exp(d / 10) - 1`` when late (Saxena, Goebel, Simon & Eklund 2008,
  "Damage propagation modeling for aircraft engine run-to-failure simulation", PHM 2008: the
  challenge's score, which charges a late prediction more than an early one of the same size); 0
  for an exact one, summed over units by the challenge.
- :func:`late`: the median later than the truth by more than ``alpha`` (0.2) of the true remaining
  life (a criterion on the share of units so late).
- :func:`covers`: the 5-95 % interval holds the true remaining life.

The time unit is the prediction's (days for the monitor's fleets; the challenge's were cycles, so
its constants 13 and 10 are in cycles there and in days here, as the prognostics track's figures
read them).
"""

from __future__ import annotations

import numpy as np

#: The PHM 2008 score's constants for early and late predictions (time units).
EARLY, LATE = 13.0, 10.0
#: Late by more than this share of the true remaining life counts as late.
ALPHA = 0.2


def phm08_score(predicted, true):
    """The PHM 2008 score of each prediction: ``d = predicted - true`` (remaining lives, same time
    unit; arrays broadcast), ``exp(-d / 13) - 1`` for ``d`` < 0 and ``exp(d / 10) - 1`` for ``d``
    >= 0; >= 0, 0 when exact. ValueError when a value is not finite."""
    d = np.asarray(predicted, dtype=float) - np.asarray(true, dtype=float)
    if not np.all(np.isfinite(d)):
        raise ValueError(f"phm08_score: predicted {predicted!r} and true {true!r} remaining lives must be finite")
    return np.where(d < 0, np.expm1(-d / EARLY), np.expm1(d / LATE))


def late(median: float, true: float, alpha: float = ALPHA) -> bool:
    """Whether the predicted ``median`` remaining life is later than the ``true`` one (> 0) by more
    than ``alpha`` of it. ValueError for a true remaining life not above 0."""
    if not true > 0:
        raise ValueError(f"late: true remaining life = {true!r}; expected a number above 0")
    return bool(median - true > alpha * true)


def covers(low: float, high: float | None, true: float) -> bool:
    """Whether the interval [``low``, ``high``] (``high`` None: beyond the horizon) holds ``true``."""
    return bool(low <= true <= (np.inf if high is None else high))
