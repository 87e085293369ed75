"""The ``faultgen`` command group: its help, ``--version``, and nothing else (its commands are in
the table of :mod:`faultgen.cli.table`, each imported when it is run)."""

from __future__ import annotations

from typing import Annotated

import typer

from faultgen import __version__
from faultgen.cli.table import LazyTyper

app = LazyTyper(
    help=(
        "Simulate wear faults in industrial robots and analyse them.\n\n"
        "A first dataset: `faultgen sweep --preset quick -o quick.h5`, then `faultgen info quick.h5` and "
        "`faultgen plot quick.h5`. Analyse it with `faultgen bench-isolators`, `detect` and `classify`. "
        "`faultgen robots` lists the robot models; `faultgen robots NAME` shows one model's parameters. "
        "`faultgen COMMAND --help` explains each command, with examples."
    ),
    no_args_is_help=True,
    add_completion=False,
    # click's own help layout: paragraphs reflow to the terminal's width, paragraphs marked \b
    # (the examples) stay as written, and no option's help is cut
    rich_markup_mode=None,
)


def _version(value: bool) -> None:
    if value:
        typer.echo(f"faultgen {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: Annotated[
        bool | None,
        typer.Option("--version", callback=_version, is_eager=True, help="Print the version and exit."),
    ] = None,
) -> None:
    """faultgen: labelled wear-fault data for industrial robots."""
