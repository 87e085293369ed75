"""``faultgen bench list|make|score``: the benchmark's frozen tracks and one score for any method."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path
from typing import Annotated

import typer

from faultgen.bench import baselines
from faultgen.cli.base import Command, Group
from faultgen.cli.main import app
from faultgen.cli.options import Jobs, Progress

bench_app = typer.Typer(cls=Group, no_args_is_help=True, add_completion=False, rich_markup_mode=None)
app.add_typer(bench_app, name="bench")

#: The largest track version a command takes (a bound for the option check).
MAX_VERSION = 1000


@bench_app.callback()
def bench_group() -> None:
    """The benchmark: frozen tracks of seeded train and test files (test labels apart), and one score
    for any detector or isolator with bootstrap intervals over test units (docs/bench.md; results in
    docs/leaderboard.md).

    Examples:

    \b
      faultgen bench list
      faultgen bench make thesis -o bench-thesis
      faultgen bench score thesis --data bench-thesis --baseline pca
    """


@bench_app.command("list", cls=Command)
def list_command() -> None:
    """List the tracks: versions, licence, what each asks, and what a slot still needs.

    Example:

    \b
      faultgen bench list
    """
    from faultgen.bench import make, tracks

    for name in tracks.names():
        track = tracks.load(name)
        if not track.versions:
            typer.echo(f"{name}: (slot, no version yet) {track.summary}\n  needs: {track.needs}")
            continue
        frozen = [f"{n} ({', '.join(s for s in tracks.SIZES if make.manifest_path(name, n, s).exists()) or 'not frozen'})"
                  for n in sorted(track.versions)]
        typer.echo(f"{name}: {track.summary}\n  versions (frozen sizes): {'; '.join(frozen)}; data licence "
                   f"{track.licence}; card {track.card}")


@bench_app.command("baselines", cls=Command)
def baselines_command() -> None:
    """List the named baselines of `bench score --baseline`, `detect --baseline`, `bench-isolators`
    and `bench score prognostics --prognoser`: role, what each is, and the extra or context it needs.

    Example:

    \b
      faultgen bench baselines
    """
    for name in baselines.names():
        entry = baselines.REGISTRY[name]
        needs = f" (needs {entry.needs}: the {entry.extra} extra)" if entry.needs else ""
        learns = ", a classifier (it learns labels: bench score only)" if entry.labels else ""
        role = f"{entry.role} and isolator" if entry.isolates else entry.role
        context = f"; runs on {entry.context}, no command builds it" if entry.context else ""
        typer.echo(f"{name}: {role}{learns}; {entry.summary}{needs}{context}")


@bench_app.command("make", cls=Command)
def make_command(
    track: Annotated[str, typer.Argument(help="A track of `faultgen bench list`.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="The folder to write (train.h5, test.h5, test_labels.csv, "
                                                          "manifest.json); its parent must exist.")],
    version: Annotated[int | None, typer.Option(help="The track version (default: the latest); old versions stay "
                                                     "makeable.", min=1, max=MAX_VERSION)] = None,
    size: Annotated[str, typer.Option(help="full, or small: the test-sized version (seconds), for tests and a first "
                                           "look.")] = "full",
    jobs: Jobs = 1,
    freeze: Annotated[bool, typer.Option(help="Maintainers: write the manifest as this version's frozen one, in the "
                                              "package (refused if it has one).")] = False,
    progress: Progress = True,
) -> None:
    """Make a track's train and test files and check them against the track version's frozen
    manifest (SHA-256 of every array): a faultgen that changes the data fails, naming the track and
    the first differing array, and writes nothing. The test labels go to test_labels.csv, apart
    from test.h5: give a method train.h5 and test.h5 only.

    `--size small` makes the test-sized version in seconds. A version made in a numeric profile
    (OpenBLAS's and NumPy's kernels pinned, so that any x86-64 machine with AVX2 gives the same
    bits) is made in a process started again with it.

    Example:

    \b
      faultgen bench make thesis --jobs 2 -o bench-thesis
    """
    from faultgen.bench import make, profile, tracks

    try:
        wanted = tracks.load(track).version(version).profile
    except ValueError:
        wanted = None  # make() names the problem
    if sys.argv[1:3] == ["bench", "make"]:  # run as a command (not inside a test's runner): pin the profile
        profile.restart_pinned(wanted, sys.argv[1:])
    manifest = make.make(track, out, version=version, size=size, jobs=jobs, progress=progress,
                         command=shlex.join(["faultgen", *sys.argv[1:]]), freeze=freeze)
    verdict = {"checked": "identical to the frozen manifest",
               "frozen": "frozen now: this manifest is the version's reference",
               "unfrozen": "no frozen manifest for this version and size: not checked"}[manifest["status"]]
    numeric = (f"numeric profile {wanted}" if wanted and profile.pinned(wanted) else
               f"NOT in its numeric profile {wanted} (this processor cannot take it: other machines may differ)"
               if wanted else "no numeric profile (a version frozen before profiles: its bits depend on the processor)")
    typer.echo(f"track {manifest['track']} version {manifest['version']} ({manifest['size']}): "
               f"{len(manifest['arrays'])} arrays, {verdict}; {numeric}; data licence {manifest['licence']}")
    typer.echo(f"wrote {out}/train.h5, {out}/test.h5, {out}/test_labels.csv, {out}/manifest.json")


@bench_app.command("score", cls=Command)
def score_command(
    track: Annotated[str, typer.Argument(help="The track the folder holds (`faultgen bench list`).")],
    data: Annotated[Path, typer.Option(help="The folder of `faultgen bench make`.")],
    detector: Annotated[str | None, typer.Option(
        metavar="MODULE:CLASS", help="Your detector (the contract of `faultgen detect --detector`; a scikit-learn "
        "classifier gets the train labels). Imported, so it runs as code: name only modules you trust.")] = None,
    isolator: Annotated[str | None, typer.Option(
        metavar="MODULE:CLASS", help="Your isolator (the contract of `faultgen bench-isolators --isolator`).")] = None,
    baseline: Annotated[str | None, typer.Option(
        help=f"A baseline (`faultgen bench baselines`): {baselines.describe('detector')}, "
             f"{baselines.describe('isolator')}; on the prognostics track {baselines.describe('prognoser')}.")] = None,
    prognoser: Annotated[str | None, typer.Option(
        metavar="NAME|MODULE:CLASS", help="Your prognoser, on the prognostics track (the contract of "
        f"faultgen.bench.prognosers), or a registered one: {baselines.describe('prognoser')}.")] = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Output stem: OUT.json and OUT.md (default: "
                                                                  "DATA/score-NAME).")] = None,
    allow_modified: Annotated[bool, typer.Option(
        "--allow-modified", help="Score a folder that differs from the track version's frozen manifest anyway: "
        "warned, each differing file and array named, and the verdict marked NOT COMPARABLE.")] = False,
    variant: Annotated[str | None, typer.Option(
        help="The prognostics track's version 3: the test split's variant (test-VARIANT.h5: scatter-7, "
             "noscatter-none, ...; default test.h5, scatter-14).")] = None,
) -> None:
    """Score a detector or an isolator on a track's test units: AUROC, false-alarm rate on healthy
    units, detection rate at 5 % false alarms, the share of failing units detected beside what
    random alarms at the same false-alarm rate detect, detection delay after the fault's start and
    after 10 % wear, isolation top-1 accuracy, each with a 95 % bootstrap interval over test units
    and its verdict against chance (above, at or below), and a warning when the track's units are
    too short for the method. The method learns from train.h5 only; test_labels.csv is read after
    it answered. Writes OUT.json and OUT.md (a row of docs/leaderboard.md and the verdict lines).

    The folder is first compared with the track version's frozen manifest (SHA-256 of every array
    and of test_labels.csv): a folder that differs is refused, naming the file and array, unless
    --allow-modified is given.

    Example:

    \b
      faultgen bench make thesis --size small -o bench-small
      faultgen bench score thesis --data bench-small --baseline pca
      faultgen bench score thesis --data bench-small --isolator mine:LargestRise
      faultgen bench score thesis --data bench-small --detector mine:ZScore
      faultgen bench make prognostics --size small -o bench-prognostics
      faultgen bench score prognostics --data bench-prognostics --baseline linear
    """
    if track == "prognostics" or prognoser:  # remaining useful life: its own contract and metrics
        from faultgen.cli import bench_prognostics

        return bench_prognostics.score(data, prognoser, baseline, out, allow_modified, variant)
    from analysis import plugins
    from faultgen.bench import score

    given = [(role, value) for role, value in (("detector", detector), ("isolator", isolator), ("baseline", baseline))
             if value]
    if len(given) != 1:
        raise ValueError("give one of --detector MODULE:CLASS, --isolator MODULE:CLASS or --baseline NAME")
    role, name = given[0]
    if role == "baseline":
        role, method = baselines.for_track(name)
    else:
        method = plugins.load(name, role)
    stem = out or data / f"score-{name.replace(':', '.')}"
    results = score.score(data, method, name, role, track=track, allow_modified=allow_modified)
    command = shlex.join(["faultgen", *sys.argv[1:]])
    json_path, md_path = score.write(results, stem, command)
    typer.echo(score.markdown(results, command), nl=False)
    typer.echo("intervals: 95 % bootstrap over test units; verdicts against chance (docs/bench.md)")
    typer.echo(f"wrote {json_path}, {md_path}")
