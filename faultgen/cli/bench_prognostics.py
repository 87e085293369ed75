"""``faultgen bench score prognostics``: parse the prognoser, call :mod:`faultgen.bench.prognostics`,
print its leaderboard row and verdict (the ``score`` command of :mod:`faultgen.cli.bench` hands the
prognostics track here)."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

import typer


def score(data: Path, prognoser: str | None, baseline: str | None, out: Path | None,
          allow_modified: bool = False) -> None:
    """Score ``--prognoser MODULE:CLASS``, ``--prognoser NAME`` or ``--baseline NAME`` (a prognoser
    registered in :mod:`faultgen.bench.baselines`) on the prognostics track's files in ``data``;
    writes OUT.json and OUT.md and prints the row with the naive prognoser's figures.
    ``allow_modified``: as :func:`faultgen.bench.prognostics.score` (the differences printed first).

    Raises
    ------
    ValueError
        Unless exactly one of the two is given, for a name not registered as a prognoser (listing
        them), or what loading or scoring raises.
    """
    from faultgen.bench import baselines, prognosers, prognostics, verdicts

    if (prognoser is None) == (baseline is None):
        raise ValueError("the prognostics track takes one of --prognoser MODULE:CLASS or --prognoser/--baseline "
                         f"{'|'.join(baselines.names('prognoser'))}")
    name = prognoser or baseline
    method = prognosers.load(name) if ":" in name else prognostics.baseline(name)
    stem = out or data / f"score-{name.replace(':', '.')}"
    results = prognostics.score(data, method, name, allow_modified)
    command = shlex.join(["faultgen", *sys.argv[1:]])
    json_path, md_path = prognostics.write(results, stem, command)
    for line in verdicts.modified_lines(results):
        typer.echo(line)
    typer.echo(prognostics.header(results["version"]))
    typer.echo(prognostics.markdown_row(results, command))
    diff = results["ra_lambda_minus_naive"]
    typer.echo(f"verdict: {results['verdict']}; relative accuracy at lambda minus the naive prognoser's (mean life "
               f"of the train split): {diff['value']:.2f} [{diff['ci95'][0]:.2f}, {diff['ci95'][1]:.2f}]; "
               f"alpha {prognostics.ALPHA}, beta {prognostics.BETA}, "
               f"lambda {prognostics.LAMBDA}; intervals: bootstrap over {results['results']['ra_lambda']['units']} "
               f"test units (docs/bench/prognostics.md)")
    typer.echo(f"wrote {json_path}, {md_path}")
