"""The reproduction's outputs: one Markdown file per table (``DIR/tables/KEY.md``), the summary
(``DIR/summary.md``: every table with its verdict, what the reduced work changes, and the tables of
docs/reproduction.md that this command does not regenerate, with why), and the time of every step
(``DIR/times.csv``)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from faultgen.reproduce.runner import Outcome
from faultgen.reproduce.tables import Part

#: Tables of docs/reproduction.md this command leaves out: their section, and why. Each is a study
#: beyond the thesis's tables (an ablation or a second seed), and its command is on that page.
NOT_REGENERATED = (
    ("Table 5.2 on a fleet: chance level of 16 cells, both fleets (--permutations 19)",
     "2h20m per fleet on 2 cores; each classify table above carries its own chance level on lr instead"),
    ("Table 5.2 on a fleet: the seed-1 fleet (every row of the thesis's protocol, by wear, chance)",
     "a second fleet seed: one more fleet (about 4 min) and its classify runs; a spread study, not a thesis table"),
    ("Table 5.2 on a fleet: before the indicators, with a task mix, --no-conditions --full",
     "measured on code before the indicators; the page marks them as history"),
    ("Gear efficiency, faults other than friction wear, more cycles a day, the temperature law's share, one "
     "condition at a time", "ablations of the fleet's conditions (3-12 min each per fleet); not thesis tables"),
    ("Table 3.5 j2: the torque-bin study (K = 100..10 000)", "an ablation of the histogram's bin edges"),
)


def write(folder: Path, parts: Sequence[Part], outcomes: Sequence[Outcome], scale: str, seconds: float) -> Path:
    """Write the tables, the summary and the times; return the summary's path."""
    from faultgen.data import atomic

    tables = folder / "tables"
    tables.mkdir(exist_ok=True)
    took = {o.step.name: o for o in outcomes}
    for part in parts:
        text = [f"# {part.title} (thesis {part.thesis_tables})", f"**Verdict:** {part.verdict}"]
        if part.reduced:
            text.append(f"**Reduced work:** {part.reduced}.")
        text.append(part.body)
        text.append("Made by: " + "; ".join(f"`{took[s].step.command()}`" for s in part.steps if s in took))
        atomic.write_text(tables / f"{part.key}.md", "\n\n".join(text) + "\n")
    rows = [{"table": f"[{p.title}](tables/{p.key}.md)", "thesis": p.thesis_tables, "verdict": p.verdict,
             "step time (s)": round(sum(took[s].seconds for s in p.steps if s in took))} for p in parts]
    summary = pd.DataFrame(rows)
    lines = [f"# Reproduction of the thesis's tables ({scale} scale)",
             f"Every table of docs/reproduction.md that this command regenerates, with its verdict against the thesis "
             f"(agrees, agrees in part, differs: the numbers it rests on follow). Wall time {seconds / 60:.1f} min; a "
             "table's step time counts the steps that made it (a shared dataset counts in every table it serves).",
             _markdown(summary)]
    if scale == "tiny":
        lines.append("Tiny scale: grids of seconds, to check the command's plumbing; the numbers mean nothing.")
    lines.append("Not regenerated here (their commands are in docs/reproduction.md):\n\n"
                 + "\n".join(f"- {what}: {why}." for what, why in NOT_REGENERATED))
    path = folder / "summary.md"
    atomic.write_text(path, "\n\n".join(lines) + "\n")
    write_times(folder, outcomes)
    return path


def write_times(folder: Path, outcomes: Sequence[Outcome]) -> Path:
    """``DIR/times.csv``: one row per step ended so far (step, status, seconds, makes_data,
    command), rewritten as each step ends so that a stopped run keeps the times it measured."""
    from faultgen.data import atomic, cells

    times = pd.DataFrame([{"step": o.step.name, "status": o.status, "seconds": round(o.seconds, 1),
                           "makes_data": o.step.makes_data, "command": o.step.command()} for o in outcomes],
                         columns=["step", "status", "seconds", "makes_data", "command"])
    with atomic.atomic_path(folder / "times.csv") as tmp:
        cells.escaped(times).to_csv(tmp, index=False)
    return folder / "times.csv"


def _markdown(frame: pd.DataFrame) -> str:
    from analysis import benchmark

    return benchmark.markdown(frame.set_index("table"), digits=3)
