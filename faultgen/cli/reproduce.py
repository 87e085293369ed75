"""``faultgen reproduce``: every table of docs/reproduction.md regenerated beside the thesis's."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from faultgen.cli.base import Command
from faultgen.cli.main import app
from faultgen.cli.options import Progress


@app.command("reproduce", cls=Command)
def reproduce_command(
    out: Annotated[Path, typer.Option("--out", "-o", help="Folder for the datasets, the tables and the summary; "
                                      "created if missing. A folder of an earlier run is resumed: steps whose "
                                      "outputs are there, made at the same scale (DIR/.steps), are kept; made at "
                                      "another, made again. A file of an output's name no run made is refused.")],
    jobs: Annotated[int, typer.Option(help="Steps run side by side, each a process (one per core is best).",
                                      min=1, max=64)] = 2,
    tiny: Annotated[bool, typer.Option("--tiny", help="Every step on grids of seconds: checks the command and "
                                       "its outputs; the numbers mean nothing.")] = False,
    show_plan: Annotated[bool, typer.Option("--plan", help="Print the steps (each a faultgen command, with the "
                                            "steps it needs) and stop: nothing is run or written.")] = False,
    progress: Progress = True,
) -> None:
    """Regenerate every table of docs/reproduction.md (thesis Tables 3.5, 4.1-4.4, 5.2, 6.1, 6.2 and
    Fig. 6-5): the datasets (j2, j2 with three seeds, c2, the fleet with and without its operating
    conditions), each made once and shared, then every analysis, each table written beside the
    thesis's numbers with a verdict (agrees, agrees in part, differs) and why they differ.

    Writes DIR/summary.md (every table with its verdict and time, and the tables of the page left
    out, with why), DIR/tables/*.md, the analyses' own outputs, DIR/times.csv and DIR/logs/. It
    does less than the page's own commands, for time: c2 records one cycle an hour, classify
    computes its seven default rows and the fleet's thesis protocol 40 pairs (docs/reproduction.md
    says what each changes and what was measured).

    The runs take minutes, so they are given in prose: the full run is `faultgen reproduce -o repro`;
    a check of the command and its outputs on grids of seconds is `faultgen reproduce --tiny -o
    repro-tiny` (a few minutes on 2 cores: two dozen commands, each its own process). What the full
    run will do, each step's command, without running it:

    \b
      faultgen reproduce --plan -o repro
    """
    from faultgen import reproduce

    if show_plan:
        typer.echo(reproduce.describe("tiny" if tiny else "full"))
        return

    if out.exists() and not out.is_dir():
        raise ValueError(f"{out} is a file; --out expects a folder for the reproduction")
    parent = out.absolute().parent
    if not parent.is_dir():
        raise ValueError(f"cannot make {out}: folder {parent} does not exist")
    import signal

    def stop(signum, frame):  # SIGTERM as a Ctrl-C: the running commands stop and keep what they made
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, stop)
    say = typer.echo if progress else None
    summary = reproduce.run(out, scale="tiny" if tiny else "full", jobs=jobs, progress=say)
    typer.echo(f"wrote {summary} and {out / 'tables'}")
