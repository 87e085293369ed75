"""The whole benchmark in one run: every track's data (`faultgen bench make`) and every baseline
(`faultgen bench score`), each command timed, the peak memory of the largest process, and the
leaderboard rows (docs/leaderboard.md) as the commands wrote them.

    python benchmarks/bench_all.py --size small -o bench-all            # minutes
    python benchmarks/bench_all.py --jobs 2 -o bench-all                # the full tracks (issue 48: <= 60 min, <= 4 GB)
    python benchmarks/bench_all.py --size small --made thesis=DIR ...   # score folders made before
    python benchmarks/bench_all.py --jobs 2 --freeze -o bench-all       # maintainers: freeze new versions

The issue's target is a budget, not a ratio: the script prints the wall time of each command and
their sum, and the largest resident set of any child process (``ru_maxrss`` of the children).
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import time
from pathlib import Path

from faultgen import children
from faultgen.bench import baselines, make, score, tracks


def run(argv: list[str]) -> tuple[float, str | None]:
    """(wall s, None) of a command, or (wall s, its last error line) when it failed."""
    start = time.perf_counter()
    done = subprocess.run(argv, env=children.environment(), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    error = None
    if done.returncode != 0:
        lines = [line for line in done.stderr.splitlines() if line.strip()]
        error = f"exit {done.returncode}: {lines[-1] if lines else '(no message)'}"
    return time.perf_counter() - start, error


def methods() -> tuple[str, ...]:
    """The baselines each track is scored with: every registered detector, then every isolator
    (:func:`faultgen.bench.baselines.scorable`, at the time of the call; not the twin, which runs on
    the monitor's outputs: benchmarks/twin_baseline.py, nor the prognosers). Each is scored by a
    ``faultgen`` process, which knows the baselines declared in analysis/registry.py and
    faultgen/bench/baselines.py: a baseline registered by a module of one's own
    (tests/baseline_example.py) is listed, but its score fails as unknown unless it is declared
    there."""
    return baselines.scorable()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--out", type=Path, required=True, help="folder for the tracks and the scores")
    parser.add_argument("--size", default="full", choices=tracks.SIZES)
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--made", action="append", default=[], metavar="TRACK=DIR", help="a track's folder made before")
    parser.add_argument("--track", action="append", default=[], help="only these tracks (default: every one with a version)")
    parser.add_argument("--freeze", action="store_true",
                        help="maintainers: make a track version that has no frozen manifest at this size with "
                             "`faultgen bench make --freeze` (its manifest becomes the version's reference)")
    args = parser.parse_args()
    args.out.mkdir(exist_ok=True)
    made = dict(m.split("=", 1) for m in args.made)
    faultgen = children.command("-m", "faultgen.cli")
    names = args.track or [n for n in tracks.names() if tracks.load(n).versions]
    rows, total, failed = [], 0.0, []
    for name in names:
        folder = Path(made.get(name, args.out / name))
        if name not in made:
            freeze = args.freeze and not make.manifest_path(name, tracks.load(name).latest, args.size).exists()
            seconds, error = run([*faultgen, "bench", "make", name, "--size", args.size, "--jobs", str(args.jobs),
                                  "--no-progress", "-o", str(folder), *(["--freeze"] if freeze else [])])
            total += seconds
            print(f"make {name} ({args.size}{', frozen now' if freeze and not error else ''}): {seconds:.1f} s"
                  + (f"; FAILED, {error}" if error else ""), flush=True)
            if error:  # its baselines cannot be scored; the other tracks still run
                failed.append(f"make {name}")
                continue
        for baseline in methods():
            stem = args.out / f"{name}-{baseline}"
            seconds, error = run([*faultgen, "bench", "score", name, "--data", str(folder), "--baseline", baseline,
                                  "-o", str(stem)])
            total += seconds
            print(f"score {name} {baseline}: {seconds:.1f} s" + (f"; FAILED, {error}" if error else ""), flush=True)
            if error:
                failed.append(f"score {name} {baseline}")
                continue
            rows.append(stem.with_name(stem.name + ".md").read_text().splitlines()[2])  # header, separator, row
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    print(f"\ntotal {total / 60:.1f} min; largest process {peak:.0f} MB")
    print(f"NOT the whole benchmark: {len(failed)} step(s) failed ({', '.join(failed)})\n" if failed else "")
    print(score.HEADER)
    print(score.SEPARATOR)
    print("\n".join(rows))


if __name__ == "__main__":
    main()
