"""``faultgen reproduce``: every table of docs/reproduction.md regenerated into one folder, each
beside the thesis's numbers with a verdict, and a summary.

The work is a list of steps (:mod:`.plan`): the datasets, each made once and shared by every table
that reads it, and the ``faultgen`` analyses that read them, run side by side
(:mod:`.runner`). The tables (:mod:`.tables`) are then built from the steps' outputs against the
thesis's numbers (:mod:`.thesis`) and written with the summary (:mod:`.report`)::

    from faultgen import reproduce
    summary = reproduce.run("repro", jobs=2)       # DIR/summary.md, DIR/tables/*.md, DIR/times.csv
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

from faultgen.reproduce import plan, report, runner, tables
from faultgen.reproduce.runner import Outcome, Step, StepFailed

__all__ = ["Outcome", "Step", "StepFailed", "describe", "plan", "run"]


def describe(scale: str = "full") -> str:
    """The steps of ``scale`` as text, one a line: its name, the command (run in the output
    folder) and the steps it needs; then the reductions of the full scale. Raises ValueError for a
    bad ``scale``."""
    lines = [f"{len(plan.steps(scale))} steps ({scale} scale), each run in the output folder:"]
    for step in plan.steps(scale):
        needs = f"  [after: {', '.join(step.needs)}]" if step.needs else ""
        lines.append(f"  {step.name}: {step.command()}{needs}")
    if scale == "full":
        lines.append("Less work than docs/reproduction.md's own commands:")
        lines += [f"  {key}: {text}" for key, text in plan.REDUCTIONS.items()]
    return "\n".join(lines)


def run(out: str | Path, scale: str = "full", jobs: int = 2,
        progress: Callable[[str], None] | None = None) -> Path:
    """Make every step of ``scale`` (:data:`.plan.SCALES`) in folder ``out`` (created; steps whose
    outputs are there, recorded as made with the same settings, are kept, so a killed run resumes;
    outputs of another scale are made again) with ``jobs`` steps at a time, build the
    tables and write the summary; return the summary's path.

    ``progress(line)`` receives one line as each step ends (``[done/total] name: ran in 3m02s``)
    and one per table written. Raises :class:`StepFailed` naming the first failed step and its
    log, ValueError for a bad ``scale`` or ``jobs`` < 1, or a file of an output's name that no
    earlier run's record claims (:func:`.runner.check_outputs`), before anything runs.
    """
    if jobs < 1:
        raise ValueError(f"jobs {jobs}: expected at least 1")
    steps = plan.steps(scale)
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()

    ended: list[Outcome] = []

    def said(outcome: Outcome, done: int, total: int) -> None:
        ended.append(outcome)
        report.write_times(folder, ended)
        if progress is not None:
            how = "kept (outputs there)" if outcome.status == "kept" else f"{outcome.status} in {_clock(outcome.seconds)}"
            progress(f"[{done}/{total}] {outcome.step.name}: {how}, {_clock(time.perf_counter() - started)} so far")

    outcomes = runner.execute(steps, folder, jobs=jobs, report=said)
    made = tables.parts(folder)
    path = report.write(folder, made, outcomes, scale, time.perf_counter() - started)
    if progress is not None:
        for part in made:
            progress(f"{part.title} (thesis {part.thesis_tables}): {part.verdict}")
    return path


def _clock(seconds: float) -> str:
    minutes, rest = divmod(round(seconds), 60)
    return f"{minutes}m{rest:02d}s" if minutes else f"{rest}s"
