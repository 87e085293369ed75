"""``faultgen info``, ``validate``, ``export`` and ``plot``: look at a dataset."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from faultgen.cli.base import Command, check_outputs
from faultgen.cli.main import app
from faultgen.cli.options import Overwrite


@app.command("info", cls=Command)
def info_command(
    file: Annotated[Path, typer.Argument(help="A faultgen dataset (HDF5).")],
    show_card: Annotated[bool, typer.Option(
        "--card", help="Print the dataset card instead (Markdown): what 20 % wear means physically, label "
        "definitions, units, histogram bin edges, the command, versions.")] = False,
) -> None:
    """Summarise a dataset: runs, robots, tasks, worn axes, cycles, provenance.

    Examples:

    \b
      faultgen info quick.h5
      faultgen info quick.h5 --card > quick-card.md
    """
    from faultgen.data import dataset

    if show_card:
        from faultgen.data.card import card

        typer.echo(card(file))
        return
    typer.echo(dataset.summary(file))


@app.command("validate", cls=Command)
def validate_command(file: Annotated[Path, typer.Argument(help="A faultgen dataset (HDF5).")]) -> None:
    """Check a dataset against the schema (docs/dataset.md); exit 1 with the reasons if it fails.

    Runs whose motors saturated (their drive torque reached its limit) are named as warnings: the
    file is valid, but those runs do not follow their task where the drive is at its limit.

    Example:

    \b
      faultgen validate quick.h5
    """
    from faultgen.data import dataset

    problems = dataset.validate(file)
    if problems:
        for problem in problems[:50]:
            typer.echo(f"invalid: {problem}", err=True)
        raise typer.Exit(1)
    typer.echo(f"{file}: valid ({len(dataset.list_runs(file))} runs)")
    for warning in dataset.saturation_warnings(file):
        typer.echo(f"warning: {warning}", err=True)


@app.command("export", cls=Command)
def export_command(
    file: Annotated[Path, typer.Argument(help="A faultgen dataset (HDF5).")],
    out: Annotated[Path, typer.Option("--out", "-o", help="Table to write: .csv, .csv.gz or .parquet.")],
    overwrite: Overwrite = False,
) -> None:
    """Write every per-cycle feature of a dataset as one tidy table (CSV or Parquet).

    One row per run, recorded cycle and axis: the run's labels, the true wear of the axis, mean
    and RMS motor torque, friction torque, tracking error and the 12-bin histograms (a column per
    bin). Columns and units: docs/dataset.md. Read it with pandas: `pandas.read_parquet(OUT)`.

    Example:

    \b
      faultgen export quick.h5 -o quick.parquet
    """
    from faultgen.data import dataset

    check_outputs([out], overwrite)
    dataset.export_features(file, out)
    typer.echo(f"wrote {out}")


@app.command("plot", cls=Command)
def plot_command(
    file: Annotated[Path, typer.Argument(help="A faultgen dataset (HDF5).")],
    run: Annotated[str | None, typer.Option(help="Plot one run (default: the whole sweep, or its only run).")] = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="PNG to write (default: FILE with .png).")] = None,
    overwrite: Overwrite = False,
) -> None:
    """Draw how each axis's mean |motor torque| follows its true wear, as a PNG.

    A sweep: per axis, the change (%) of every run wearing it against the unworn run of the same
    program (its hash), conditions and seed. One run (or --run ID): mean |motor torque| per cycle with the true wear.

    Example:

    \b
      faultgen plot quick.h5 -o quick.png
    """
    from faultgen import plot
    from faultgen.data import reader

    target = out or file.with_suffix(".png")
    check_outputs([target], overwrite)
    plot.plot(file, target, run=run)
    with reader.open(file) as data:
        if data.unhashed:  # old files: the unworn reference is found by the task label alone
            typer.echo(data.unhashed)
    typer.echo(f"wrote {target}")
