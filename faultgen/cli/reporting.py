"""``faultgen report``: the fleet report page of a ``faultgen monitor`` output folder, written again
(faultgen.monitor.page)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from faultgen.cli.base import Command
from faultgen.cli.main import app


@app.command("report", cls=Command)
def report_command(
    out: Annotated[Path, typer.Argument(help="A `faultgen monitor` output folder (units.csv, alarms.csv, "
                                        "scores.csv; rul.csv, life.csv and settings.json when the monitor "
                                        "wrote them).")],
) -> None:
    """Write the fleet report page OUT/report.html again from a monitor's output folder: one file
    that opens in a browser offline (plotly.js inside it, no server, nothing fetched).

    The page is built from OUT/units.csv, OUT/alarms.csv and OUT/scores.csv, where present
    OUT/wear.csv, rul.csv, life.csv and tests.csv (the friction tests; rul.csv and life.csv are
    named when missing: the page then has no such date), with the run's settings of
    OUT/settings.json (from an output of an earlier faultgen without it, those of the monitors'
    state, OUT/.state). It shows the fleet table, one line per unit: a state light (service due,
    watch, stale, unknown, ok; rules on the page and in docs/analysis.md), the "service by" date
    with its 5-95 % interval, the axis, its wear with its 90 % interval, the life consumed by load
    and the last log, the earliest service first; a panel per unit (click it in the table: the
    rules met, each axis's wear and its scale, the alarm's evidence, the remaining-life and life
    verdicts, closed alarms and the maintenance that closed them, a chart of each axis's wear with
    its interval and the wear limit, T2 and Q over their limits, the learning logs shaded,
    relearning after maintenance and the friction-test days marked, and each alarming axis's
    friction curve, first test against latest) and the run's settings with the
    false-alarm statement `faultgen monitor` prints. `faultgen monitor` writes the page itself;
    this command writes it again, e.g. after copying the CSVs of a run elsewhere.

    \b
      faultgen monitor LOGS --robot irb6700 -o monitor-own --protocol own --no-progress
      faultgen report monitor-own
    """
    from faultgen.monitor import page, run_settings

    if not out.is_dir():
        raise ValueError(f"{out} is not a folder; give a `faultgen monitor` output folder (its units.csv, alarms.csv "
                         "and scores.csv)")
    written = page.write(out, run_settings.read_settings(out))
    for name, what in OPTIONAL.items():
        if not (out / name).is_file():
            typer.echo(f"note: {out / name} is missing: the page shows no {what}", err=True)
    typer.echo(f"wrote {written}")


#: The tables of a monitor's output the page shows when they are there (a copy of the CSVs may leave them out).
OPTIONAL = {"rul.csv": "remaining life (the condition-based service date)",
            "life.csv": "life consumed by load (the load-based service date)"}
