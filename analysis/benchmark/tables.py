"""How the analysis tables are printed and written: what an isolator's answer means where it is not an
axis, a table as Markdown, a table as CSV and Markdown files, and the advice shared by every analysis of a
dataset imported from logs."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

#: What an isolator's answer means where it is not an axis number 1..N (defined with the rules that
#: score it, :mod:`analysis.scoring`).
from analysis.scoring import TOO_FEW_CYCLES, UNDECIDED


def axis_label(value: int) -> str:
    """How an axis number is printed: "1".."6", "none" or "undecided" for 0 (a run without wear's
    true axis, or an isolator that names none), "too few cycles" for -1."""
    return {UNDECIDED: "undecided", TOO_FEW_CYCLES: "too few cycles"}.get(int(value), str(int(value)))


#: Columns holding an axis number that may be 0 (undecided) or -1 (too few cycles).
AXIS_COLUMNS = {"predicted", "located_axis"}


def markdown(table: pd.DataFrame, digits: int = 3) -> str:
    """A DataFrame as a Markdown table (index included unless it is a plain range)."""
    frame = table if isinstance(table.index, pd.RangeIndex) else table.reset_index()
    if isinstance(frame.columns, pd.MultiIndex):  # ("lr", "mean") -> "lr mean"
        frame = frame.set_axis([" ".join(str(p) for p in c if p) for c in frame.columns], axis=1)
    for column in AXIS_COLUMNS & set(frame.columns):  # 0 and -1 are not axes: say what they mean
        frame = frame.assign(**{column: frame[column].map(axis_label)})
    cells = [[f"{v:.{digits}g}" if isinstance(v, float) else str(v) for v in row] for row in frame.itertuples(index=False)]
    head = [str(c) for c in frame.columns]
    return "\n".join(["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
                     + ["| " + " | ".join(row) + " |" for row in cells])


def write_outputs(table: pd.DataFrame, stem: Path, text: str | None = None) -> list[Path]:
    """Write ``table`` as ``<stem>.csv`` and ``text`` (default: the table) as ``<stem>.md``."""
    stem = Path(stem)
    csv, md = stem.with_suffix(".csv"), stem.with_suffix(".md")
    from faultgen.data import cells

    cells.escaped(table).to_csv(csv, index=not isinstance(table.index, pd.RangeIndex))
    md.write_text((text or markdown(table)) + "\n")
    return [csv, md]


#: What a dataset imported from logs (``faultgen logs import``) can do next, in an analysis's advice.
MEASURED_NEXT = ("label more logs in the logs folder's events.csv (`onset` or `failure` rows for worn axes, `healthy` "
                 "rows for units inspected healthy) and import again, or run `faultgen monitor LOGS --robot ROBOT -o "
                 "OUT` on the folder, which needs no labels (each unit judged against its calibrated twin)")
