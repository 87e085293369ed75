"""``faultgen bench score prognostics``: parse the prognoser, call :mod:`faultgen.bench.prognostics`,
print its leaderboard row and verdict (the ``score`` command of :mod:`faultgen.cli.bench` hands the
prognostics track here)."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

import typer


def score(data: Path, prognoser: str | None, baseline: str | None, out: Path | None,
          allow_modified: bool = False, variant: str | None = None) -> None:
    """Score ``--prognoser MODULE:CLASS``, ``--prognoser NAME`` or ``--baseline NAME`` (a prognoser
    registered in :mod:`faultgen.bench.baselines`) on the prognostics track's files in ``data``;
    writes OUT.json and OUT.md and prints the row with the naive prognoser's figures.
    ``allow_modified``: as :func:`faultgen.bench.prognostics.score` (the differences printed first).
    A version 3 folder is scored by :mod:`faultgen.bench.rul_v3` (:func:`score_v3`; ``variant``: its
    test split's variant, test-VARIANT.h5); ``variant`` on another version is refused.

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
    if _version(data) == 3:
        return score_v3(data, name, out, allow_modified, variant)
    if variant is not None:
        raise ValueError(f"--variant {variant}: only the prognostics track's version 3 has test variants")
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


def _version(data: Path) -> int | None:
    """The version the folder's test.h5 says it holds (None where it cannot be read: the scoring then
    names what is wrong)."""
    from faultgen.bench import files

    try:
        return files.read_with_attrs(Path(data) / "test.h5", ("version",))[1]["version"]
    except ValueError:
        return None


def score_v3(data: Path, name: str, out: Path | None, allow_modified: bool, variant: str | None) -> None:
    """Score ``name`` (a baseline of :data:`faultgen.bench.rul_v3.BASELINES`, a registered prognoser or
    ``MODULE:CLASS``) on a version 3 folder with every baseline beside it; writes OUT.json and OUT.md and
    prints the row and the verdicts against the naive prognoser and the best other baseline."""
    from faultgen.bench import prognosers, prognostics, rul_v3, verdicts

    method = None if name in rul_v3.BASELINES else prognosers.load(name) if ":" in name else prognostics.baseline(name)
    stem = out or data / (f"score-{name.replace(':', '.')}" + (f"-{variant}" if variant else ""))
    results = rul_v3.score(data, method, name, allow_modified, variant)
    command = shlex.join(["faultgen", *sys.argv[1:]])
    json_path, md_path = rul_v3.write(results, stem, command)
    for line in verdicts.modified_lines(results):
        typer.echo(line)
    typer.echo(rul_v3.HEADER)
    typer.echo(rul_v3.markdown_row(results, command))
    head = results["anchors"][rul_v3.HEADLINE]
    for label, key in (("the naive prognoser", "vs_naive"), (f"{head['best_other']} (best other baseline)", "vs_best")):
        if head[key] is None or (key == "vs_naive" and name == "mean_life"):
            continue
        typer.echo(f"against {label}: " + "; ".join(
            f"{score} {d['value']:.3g} [{d['ci95'][0]:.3g}, {d['ci95'][1]:.3g}] {d['verdict']}"
            for score, d in head[key].items()))
    typer.echo(f"verdict: {results['verdict']}; lambda at {rul_v3.HEADLINE} of {head['results']['ra']['units']} "
               f"run-to-failure test units, variant {results['variant']} (docs/bench/prognostics.md, version 3)")
    typer.echo(f"wrote {json_path}, {md_path}")
