"""What a dataset holds, for people and for other tools: :func:`summary` (``faultgen info``), and
:func:`features`, every per-cycle quantity as one tidy table, with :func:`export_features`
(``faultgen export``: CSV or Parquet).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

from faultgen.data import cells, reader
from faultgen.data.atomic import atomic_path
from faultgen.data.opening import attr, open_file
from faultgen.data.schema import FRICTION_TEST, MEASURED, RECORD_ATTRIBUTE, DatasetError
from faultgen.data.validator import attribute_problems
from faultgen.operation.faults import Fault
from faultgen.simulation import sensors

if TYPE_CHECKING:
    import pandas as pd

#: Labels of a run repeated on every row of :func:`features`.
FEATURE_LABELS = ("robot", "task", "friction_model", "seed")
#: Formats :func:`export_features` writes, by file-name ending.
EXPORT_SUFFIXES = (".csv", ".csv.gz", ".parquet")


def features(path: str | Path) -> pd.DataFrame:
    """Every per-cycle quantity of a dataset as one tidy table, for tools that do not read HDF5.

    One row per (run, recorded cycle, axis); columns: ``run``, the run's labels
    (:data:`FEATURE_LABELS`), ``worn_axes`` (the run's worn axes as text, "2" or "2 5"; "" for
    none), ``cycle`` (1-based), ``axis`` (1..N), ``worn`` (this axis wears in this run),
    ``wear_pct`` (true wear of this axis at this cycle, ``(friction_multiplier - 1) * 100``),
    then every array of :data:`~faultgen.data.schema.ARRAYS` with axes "cycle, axis" and of
    :data:`~faultgen.data.schema.DUTY_ARRAYS` (empty for runs without) under its own name and
    every histogram ("cycle, axis, bin") as one column per bin, ``torque_hist_1`` ..
    ``torque_hist_12``, and, for runs with operating conditions, each of their
    :data:`~faultgen.data.schema.CONDITION_ARRAYS` (a per-cycle value on each of the cycle's
    rows, a per-axis one on each axis's; empty for runs without). Values are the stored ones, in
    the units of :data:`~faultgen.data.schema.ARRAYS`; ``DataFrame.attrs["units"]`` maps
    each column to its unit.

    Raises
    ------
    DatasetError
        If ``path`` is not a finished faultgen dataset.
    """
    with reader.open(path) as data:
        return data.features()


def export_features(path: str | Path, out: str | Path) -> Path:
    """Write :func:`features` of ``path`` to ``out`` (CSV, gzip-compressed CSV or Parquet by its
    ending, :data:`EXPORT_SUFFIXES`), atomically.

    Raises
    ------
    ValueError
        If ``out`` has another ending (the message lists the accepted ones).
    DatasetError
        If ``path`` is not a finished faultgen dataset.
    """
    out = Path(out)
    if not out.name.lower().endswith(EXPORT_SUFFIXES):
        raise ValueError(f"cannot export to {out}: expected a name ending in {', '.join(EXPORT_SUFFIXES)}")
    table = features(path)
    with atomic_path(out) as tmp:
        if out.name.lower().endswith(".parquet"):
            table.to_parquet(tmp, index=False)
        else:
            cells.escaped(table).to_csv(tmp, index=False, compression="gzip" if out.name.lower().endswith(".gz") else None)
    return out


def summary(path: str | Path) -> str:
    """A few lines describing a dataset: runs, robots, tasks, wear, cycles, size, provenance."""
    with open_file(path) as f:
        runs = f["runs"]
        for run_id in runs:
            problems = [f"missing attribute {a!r}" for a in ("robot", "task", "friction_model", "seed", "worn_axes")
                        if a not in runs[run_id].attrs] + attribute_problems(runs[run_id])
            problems += [f"missing array {a!r}" for a in ("cycles", "t") if a not in runs[run_id]]
            if problems:
                raise DatasetError(f"{path}: run {run_id!r}: {problems[0]} (faultgen validate {path} lists every "
                                   "problem)")
        tests = [r for r in runs if attr(runs[r].attrs.get(RECORD_ATTRIBUTE)) == FRICTION_TEST]
        kept = [r for r in runs if r not in tests] or tests  # a fleet's tests on a line of their own
        rows = [{k: attr(v) for k, v in runs[r].attrs.items()} for r in kept]
        n_cycles = [runs[r]["cycles"].shape[0] for r in kept]
        n_log = [runs[r]["t"].shape[0] for r in kept]
        n_tests = sum(runs[r]["cycles"].shape[0] for r in tests) if len(kept) < len(runs) else 0
        version, command = attr(f.attrs.get("faultgen_version")), attr(f.attrs.get("command", ""))
    worn = sorted({tuple(int(a) for a in row["worn_axes"]) for row in rows})
    daily = any(row.get("sample") in ("day", "log") for row in rows)
    logs = any(row.get("sample") == "log" for row in rows)
    what, record = ("logs", "log records") if logs else ("days", "daily records") if daily else ("cycles", "recorded")
    signals = all(row.get("signals", True) for row in rows)
    lines = [
        f"{path}: {len(rows)} run(s){f' and {len(tests)} friction-test run(s)' if n_tests else ''}, {Path(path).stat().st_size / 1e6:.1f} MB, written by faultgen {version}",
        f"  robots:        {', '.join(sorted({r['robot'] for r in rows}))}",
        f"  tasks:         {', '.join(sorted({r['task'] for r in rows}))}",
        f"  friction:      {', '.join(sorted({r['friction_model'] for r in rows}))}",
        f"  worn axes:     {', '.join('none' if not w else '+'.join(map(str, w)) for w in worn)}",
        f"  seeds:         {', '.join(map(str, sorted({int(r['seed']) for r in rows})))}",
        f"  {what}:{' ' * (14 - len(what))}{min(n_cycles)}-{max(n_cycles)} "
        f"{record} per run, {sum(n_cycles)} in all; "
        + (f"{min(n_log)}-{max(n_log)} samples per cycle at {1 / sensors.LOG_PERIOD:.0f} Hz" if signals
           else "each log's features and its labels from events.csv (the logs' signals are not stored)"
           if all(row.get("source") == MEASURED for row in rows)
           else "features and truth only (no 250 Hz signals)"),
    ]
    if n_tests:
        lines.append(f"  friction tests: {len(tests)} run(s) labelled {RECORD_ATTRIBUTE}={FRICTION_TEST}, "
                     f"{n_tests} tests in all, with their signals (not counted above; docs/friction-test.md)")
    if any("conditions" in row for row in rows):
        tables = [json.loads(row["conditions"]) for row in rows if "conditions" in row]
        kinds = sorted({key for table in tables for key, value in table.items()
                        if key in ("thermal", "payloads", "spread", "task_mix") and value})
        lines.append(f"  conditions:    {sum('conditions' in row for row in rows)} run(s) with operating conditions: "
                     f"{', '.join(kinds)} (their per-cycle arrays: `faultgen info FILE --card`, docs/dataset.md)")
    with_fault = [Fault(**json.loads(row["fault"])).text() for row in rows if "fault" in row]
    if with_fault:
        counts = {text: with_fault.count(text) for text in dict.fromkeys(with_fault)}
        lines.append("  faults:        " + ", ".join(f"{text} ({n} run{'s' * (n > 1)})" for text, n in counts.items())
                     + " (EFFECT:AXIS:PARAMETER:FINAL, other than friction wear)")
    saturated = [row for row in rows if len(row.get("saturated", ()))]
    if saturated:
        lines.append(f"  saturated:     {len(saturated)} run(s) whose motors reached their torque limit (they do not "
                     "follow their task; `faultgen validate` lists them)")
    measured = [row for row in rows if row.get("source") == MEASURED]
    if measured:
        lines.append(f"  measured:      {len(measured)} unit(s) imported from logs (`faultgen logs import`): labels from "
                     "their events, nothing simulated")
    if command:
        lines.append(f"  command:       {command}")
    return "\n".join(lines)
