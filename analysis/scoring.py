"""One scoring path: the detection and isolation figures of every command, computed from alarms,
answers and the truth by the functions of this module, under named rules.

Who scores here (a test spies on each, tests/test_scoring.py):

- ``faultgen detect`` (:mod:`analysis.benchmark.detection`; with ``--train``
  :mod:`analysis.crossdata`): onset, alarms before the fault, held-out false-alarm rate, under
  :data:`DETECT_RULES` (its ``persistence`` the command's ``--persistence``);
- ``faultgen bench score`` (:mod:`faultgen.bench.score`, and through it the twin's answers,
  :mod:`faultgen.bench.recorded`): onset, share detected, delays, false-alarm rate, top-1
  accuracy, under :data:`BENCH_RULES`;
- ``faultgen bench-isolators`` (:mod:`analysis.benchmark.isolation_scores`): top-1 accuracy per
  task, wear level and isolator, under :data:`ISOLATION_TABLE_RULES`.

The commands measure the same things under different rules, each for a reason (docs/architecture.md,
"Detector baselines"): a rule is a named parameter of :class:`Rules`, never an ``if`` in a caller.

- ``onset_from``: where the onset of a run is looked for. ``"fault"``: from the fault's first sample
  (and after the samples the monitor learned from); an alarm before it is a false alarm, never a
  detection (``detect``: a dataset knows when each fault begins, and a fleet's failing robots wear
  from a drawn onset day, long after their first records). ``"first_record"``: from the first record
  shown (``bench score``: the method never sees the labels, and its answers are judged as they come,
  an early onset counting as detected with a negative delay; the healthy units' onsets give the
  share's chance).
- ``false_alarm_rate``: how the rates of several healthy runs are put together. ``"per_run_mean"``:
  the mean of each run's rate (``detect``: each held-out healthy run is judged by a monitor of its
  own protocol, each run's rate one value). ``"pooled"``: alarms over all records (``bench score``:
  every healthy unit's records at once, bootstrapped by unit).
- ``persistence``: alarms in a row that make an onset (:func:`analysis.monitoring.detect_onset`).
- ``too_few_cycles``: an isolator's answer "too few cycles" (:data:`TOO_FEW_CYCLES`).
  ``"not_applicable"``: the case is left out (``bench-isolators``: Table 6.2's cells per wear level,
  a level reached before the isolator can run says nothing of it). ``"undecided"``: the case counts
  as no axis named (``bench score``: one figure per unit; a method that cannot answer on the track's
  units has not isolated them).

The module imports only NumPy (:mod:`analysis.monitoring`'s onset rule when an onset is asked for),
so every layer that scores (the analysis tables, the bench) imports it, and nothing of it imports back.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Sequence

import numpy as np

#: What an isolator's answer means where it is not an axis number 1..N.
UNDECIDED, TOO_FEW_CYCLES = 0, -1

#: The values of each rule (:class:`Rules`).
ONSET_FROM = ("fault", "first_record")
FALSE_ALARM_RATES = ("pooled", "per_run_mean")
TOO_FEW = ("not_applicable", "undecided")


@dataclasses.dataclass(frozen=True)
class Rules:
    """The rules a command scores by (the module's docstring says what each means).

    Parameters
    ----------
    persistence : int
        Alarms in a row that make an onset.
    onset_from : {"fault", "first_record"}
        Where the onset is looked for.
    false_alarm_rate : {"pooled", "per_run_mean"}
        How several healthy runs' false alarms make one rate.
    too_few_cycles : {"not_applicable", "undecided"}
        What an isolator's "too few cycles" answer counts as.
    """

    persistence: int
    onset_from: str
    false_alarm_rate: str
    too_few_cycles: str = "undecided"

    def __post_init__(self):
        for name, allowed in (("onset_from", ONSET_FROM), ("false_alarm_rate", FALSE_ALARM_RATES),
                              ("too_few_cycles", TOO_FEW)):
            if getattr(self, name) not in allowed:
                raise ValueError(f"{name} = {getattr(self, name)!r}; expected one of: {', '.join(allowed)}")

    def with_persistence(self, persistence: int) -> Rules:
        """These rules with another ``persistence`` (``detect --persistence``)."""
        return dataclasses.replace(self, persistence=persistence)


#: ``faultgen detect`` (and ``--train``): the onset from the fault's first sample, the held-out
#: healthy runs' rates averaged; 3 in a row is the command's default ``--persistence``.
DETECT_RULES = Rules(persistence=3, onset_from="fault", false_alarm_rate="per_run_mean")

#: ``faultgen bench score`` (the twin's recorded answers too): the onset from the first record, the
#: healthy units' records pooled, 3 in a row; an isolator's "too few cycles" is undecided.
BENCH_RULES = Rules(persistence=3, onset_from="first_record", false_alarm_rate="pooled", too_few_cycles="undecided")

#: ``faultgen bench-isolators`` (Table 6.2): a case with too few cycles is not applicable, left out.
#: (Its tables have no detection figures; the detection rules are ``bench score``'s.)
ISOLATION_TABLE_RULES = dataclasses.replace(BENCH_RULES, too_few_cycles="not_applicable")


def _start(n: int, fault_start: int | None) -> int:
    return n if fault_start is None else int(fault_start)


def onset(alarms, rules: Rules, fault_start: int | None = None, skip: int = 0) -> int | None:
    """The onset of a run: the first of ``rules.persistence`` alarms in a row
    (:func:`analysis.monitoring.detect_onset`), looked for from sample ``skip`` (those before it the
    monitor learned from) and, under ``onset_from="fault"``, from ``fault_start`` (the fault's first
    sample; None: no fault, no onset); an index into ``alarms`` or None."""
    from analysis.monitoring import detect_onset

    alarms = np.asarray(alarms)
    first = skip if rules.onset_from == "first_record" else max(skip, _start(len(alarms), fault_start))
    found = detect_onset(alarms[first:], persistence=rules.persistence)
    return None if found is None else found + first


def before_fault(alarms, fault_start: int | None, skip: int = 0) -> np.ndarray:
    """The alarms of the samples tested before the fault begins (after ``skip``; the whole run when
    ``fault_start`` is None): under ``onset_from="fault"`` false alarms of a worn run."""
    alarms = np.asarray(alarms)
    return alarms[skip:_start(len(alarms), fault_start)]


def false_alarm_rate(runs: Sequence, rules: Rules, scale: float = 1.0) -> float:
    """The false-alarm rate of healthy runs' alarms (each a 1-D array, one alarm per sample judged),
    times ``scale`` (100: in %): the share of all their alarmed samples (``"pooled"``) or the mean of
    each run's share (``"per_run_mean"``); NaN without runs."""
    if not len(runs):
        return float("nan")
    if rules.false_alarm_rate == "pooled":
        return scale * float(np.mean(np.concatenate([np.asarray(r) for r in runs])))
    return float(np.mean([scale * float(np.mean(np.asarray(r))) for r in runs]))


def alarm_counts(runs: Iterable) -> tuple[int, int]:
    """(alarms, samples) over healthy runs' alarms: what a false-alarm rate's interval is made from."""
    flags = [np.asarray(r, dtype=bool) for r in runs]
    return sum(int(np.sum(f)) for f in flags), sum(int(f.size) for f in flags)


def detected_share(detected: Sequence[bool]) -> float:
    """The share of failing units with an onset (NaN without units)."""
    return float(np.mean(detected)) if len(detected) else float("nan")


def fault_start(level) -> int | None:
    """The first record whose fault level is above 0 (None: no fault)."""
    found = np.flatnonzero(np.asarray(level) > 0)
    return int(found[0]) if found.size else None


def first_reaching(level, pct: float) -> int | None:
    """The first record whose fault level reaches ``pct`` (None: never)."""
    found = np.flatnonzero(np.asarray(level) >= pct)
    return int(found[0]) if found.size else None


def delay(onset_at: int | None, cycles, since: int | None) -> float:
    """The onset's delay after record ``since``, in the records' cycles (days for daily records):
    ``cycles[onset] - cycles[since]``; NaN without an onset or a ``since``."""
    if onset_at is None or since is None:
        return float("nan")
    return float(cycles[onset_at] - cycles[since])


def too_few_answer(rules: Rules) -> int:
    """The answer an isolator gets where it cannot run (too few cycles): :data:`TOO_FEW_CYCLES`
    (not applicable) or :data:`UNDECIDED`, as ``rules.too_few_cycles`` says."""
    return TOO_FEW_CYCLES if rules.too_few_cycles == "not_applicable" else UNDECIDED


def isolation_right(named, true) -> np.ndarray:
    """Per case, whether the axis named is the true one; on a run without fault (true axis
    :data:`UNDECIDED`) only naming none is right: naming an axis there is a false isolation."""
    return np.asarray(named) == np.asarray(true)


def top1_accuracy(named, true, rules: Rules) -> float:
    """The share of cases whose named axis (1..N, :data:`UNDECIDED`, :data:`TOO_FEW_CYCLES`) is the
    true one (:func:`isolation_right`); "too few cycles" left out (``"not_applicable"``) or counted
    as undecided (``"undecided"``). NaN without a case."""
    named, true = np.asarray(named), np.asarray(true)
    if rules.too_few_cycles == "not_applicable":
        keep = named != TOO_FEW_CYCLES
        named, true = named[keep], true[keep]
    else:
        named = np.where(named == TOO_FEW_CYCLES, UNDECIDED, named)
    return float(np.mean(isolation_right(named, true))) if named.size else float("nan")
