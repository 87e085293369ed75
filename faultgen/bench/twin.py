"""``faultgen monitor``'s twin as a detector and isolator of a benchmark track: its outputs read as
each test unit's answers (docs/bench.md, "The twin on the leaderboard").

The monitor runs on the test split's raw logs (:mod:`faultgen.bench.rawlogs`) and writes
``scores.csv`` (per monitor unit and log) and ``alarms.csv`` (per unit, its persistent alarms and the
axis each names). Read back per test unit (:func:`answers`):

- **score** of a record: the largest over the axes of the lower ``1 - alpha`` bound of the wear at the
  log (``wearI_lower``, % of the axis's own dry friction, filtered over the unit's logs up to that
  one, :class:`faultgen.monitor.wear_trend.WearTrend`): the statistic the monitor alarms on
  with the twin (a log alarms when it reaches ``--wear-limit``). The monitor gives it for the logs it
  learned from too (``phase`` training, estimated with what it learned from them); a log it gave no
  row (a unit still learning when its logs ended, a log skipped) gets :data:`UNSCORED` below every
  score of the run and no alarm: the twin says nothing of it.
- **alarm** of a record: the log's own alarm (``alarm``, 0 or 1, before the monitor's persistence).
  ``faultgen bench score`` then applies its own rule (the first of 3 alarms in a row) as to every
  detector.
- **axis named**: the source axis of the unit's first persistent alarm (``alarms.csv``); 0 (undecided)
  without one. A test unit monitored as several units (one per program) names the axis of the
  alarm among them that became known first: ordered by alarms.csv's ``known`` (the log on which a
  daily run saw the alarm), not by ``first_alarm`` (the first log of the persistence
  window, a date on which nobody could have seen it); ``first_alarm`` only for a folder written
  before ``known`` existed. The detection itself never reads alarms.csv: it is the per-log alarm
  above under the scorer's rule, timed on the log that raises it.

The bench layer does not import the monitor (they are sibling layers): it reads these files.
"""

from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np

from faultgen.bench.rawlogs import Written

#: How far below the run's lowest score a record the monitor gave no row gets, in % of wear.
UNSCORED = 1.0


def _stamps(folder: Path) -> list[str]:
    """The stamps of a monitor unit's logs in stamp order (the names :mod:`faultgen.bench.rawlogs`
    writes, ISO dates or zero-padded sequence numbers, sort as text)."""
    return sorted(p.name.split(".")[0] for p in folder.iterdir() if p.name.endswith((".csv", ".csv.gz", ".h5")))


def _read(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def answers(out: Path, written: Written, n_records: dict[str, int]) -> tuple[dict, dict, dict, dict]:
    """(scores, alarms, axis named, answered) per test unit from the monitor's output folder ``out``.

    Parameters
    ----------
    out : Path
        The folder ``faultgen monitor LOGS -o OUT`` wrote (``scores.csv``, ``alarms.csv``).
    written : Written
        What the monitor read (:func:`faultgen.bench.rawlogs.write`): per test unit, its monitor units
        and the test records their logs are.
    n_records : dict of test unit id -> int

    Returns
    -------
    scores : dict of unit id -> ndarray of shape (n_records,), float
    alarms : dict of unit id -> ndarray of shape (n_records,), bool
    named : dict of unit id -> int (1..N, 0 undecided)
    answered : dict of unit id -> ndarray of shape (n_records,), bool
        The records the monitor gave a row (the others scored at the floor).

    Raises
    ------
    ValueError
        ``scores.csv`` without the twin's wear columns (a run under ``--protocol own``), or a row of a
        log that is not among the unit's logs.
    """
    rows = _read(Path(out) / "scores.csv")
    lower = sorted((c for c in (rows[0] if rows else {}) if re.fullmatch(r"wear\d+_lower", c)),
                   key=lambda c: int(c[4:-6]))
    if rows and not lower:
        raise ValueError(f"{out}/scores.csv has no wear estimates (wearI_lower): the monitor ran without the twin")
    by_unit: dict[str, dict[str, dict]] = {}
    for row in rows:
        by_unit.setdefault(row["unit"], {})[row["stamp"]] = row
    raised: dict[str, list[dict]] = {}
    for row in _read(Path(out) / "alarms.csv"):
        if row["first_alarm"]:
            raised.setdefault(row["unit"], []).append(row)
    values = [max(float(r[c]) for c in lower) for r in rows]
    floor = (min(values) if values else 0.0) - UNSCORED
    scores, alarms, named, answered = {}, {}, {}, {}
    for uid, monitored in written.records.items():
        n = n_records[uid]
        score, alarm, seen = np.full(n, floor), np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
        first = []  # (record of the log the alarm became known on, axis)
        for name, records in monitored.items():
            stamps = _stamps(written.logs / name)
            if len(stamps) != len(records):
                raise ValueError(f"monitor unit {name}: {len(stamps)} logs for {len(records)} records")
            at = dict(zip(stamps, records))
            for stamp, row in by_unit.get(name, {}).items():
                if stamp not in at:
                    raise ValueError(f"{out}/scores.csv: unit {name} has no log {stamp}")
                score[at[stamp]] = max(float(row[c]) for c in lower)
                alarm[at[stamp]] = row["alarm"] == "1"
                seen[at[stamp]] = True
            first += [(at[r.get("known") or r["first_alarm"]], int(r["source_axis"] or 0))
                      for r in raised.get(name, [])]
        scores[uid], alarms[uid], answered[uid] = score, alarm, seen
        named[uid] = min(first)[1] if first else 0
    return scores, alarms, named, answered
