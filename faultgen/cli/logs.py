"""``faultgen logs import``: a fleet's measured logs into a dataset that every command reads."""

from __future__ import annotations

import functools
import shlex
import sys
from pathlib import Path
from typing import Annotated

import typer

from faultgen.cli.base import Command, Group
from faultgen.cli.main import app
from faultgen.cli.options import LogFormat, Progress, TorqueConstants, log_adapter

logs_app = typer.Typer(cls=Group, no_args_is_help=True, add_completion=False, rich_markup_mode=None)
app.add_typer(logs_app, name="logs")


@logs_app.callback()
def logs_group() -> None:
    """Your robots' measured logs: import a fleet's folder of logs (LOGS/<unit>/<stamp>.csv) into a
    dataset that every command reads (docs/dataset.md, "A fleet's logs").

    Examples:

    \b
      faultgen logs import LOGS --robot irb6700 -o fleet-logs.h5
    """


@logs_app.command("import", cls=Command)
def import_command(
    logs: Annotated[Path, typer.Argument(help="The logs folder: LOGS/<unit>/<stamp>.csv|.csv.gz|.h5, optionally "
                                              "LOGS/events.csv (unit, stamp, event, axis).")],
    robot: Annotated[str, typer.Option(help="The robot of every unit: a name (`faultgen robots`) or a robot folder.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="The dataset to write; if it is an earlier import of these "
                                                          "logs, only the new logs are added.")],
    skip_bad: Annotated[bool, typer.Option("--skip-bad", help="Pass over bad files (listed in the summary) instead of "
                                                              "refusing the first one.")] = False,
    reimport_changed: Annotated[bool, typer.Option(
        "--reimport-changed", help="Import again a log whose content changed since it was imported (without it, "
        "such a log is refused, named).")] = False,
    log_format: LogFormat = "measured",
    torque_constants: TorqueConstants = None,
    progress: Progress = True,
) -> None:
    """Import a fleet's measured logs as a dataset: one run per unit, one record per log, with the
    per-cycle features of a simulated fleet's daily records computed by the same code, and the
    labels of LOGS/events.csv (worn, healthy; unknown without an event). `validate`, `info`,
    `plot`, `detect`, `classify`, `bench-isolators` and `training-source` read it.

    Each log is one or more cycles in the measured format (t, q1..qN, tau1..tauN arm side; optional
    qd1..qdN, temperature1..N, payload, cycle); docs/dataset.md, "A fleet's logs", gives the layout
    and the events. Run it again when the folder has grown: only the new logs are read.

    Examples:

    \b
      faultgen logs import LOGS --robot irb6700 -o fleet-logs.h5
      faultgen logs import LOGS --robot irb6700 -o fleet-logs.h5 --skip-bad
      faultgen info fleet-logs.h5 && faultgen detect fleet-logs.h5
    """
    from faultgen.data import fleetlogs
    from faultgen.model import robots

    resolved = robots.load(robot)  # once, for the log reader and the import
    adapter = log_adapter(log_format, torque_constants, resolved)
    read = {"reader": functools.partial(adapter.read, accelerations=False), "suffixes": adapter.suffixes}

    # the command as provenance, with LOGS given as an absolute path stored by its name: a dataset
    # meant to be shared keeps no path of this machine (docs/reliability.md, "Log folders")
    args = [logs.name if logs.is_absolute() and Path(a) == logs else a for a in sys.argv[1:]]
    command = "faultgen " + " ".join(shlex.quote(a) for a in args)
    summary = fleetlogs.import_logs(logs, out, robot=resolved, skip_bad=skip_bad, progress=progress,
                                    reimport_changed=reimport_changed, command=command, **read)
    typer.echo(str(summary))
