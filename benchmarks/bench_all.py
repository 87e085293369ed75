"""The whole benchmark in one run: every track's data (`faultgen bench make`) and every baseline
(`faultgen bench score`), each command timed, the peak memory of the largest process, and the
leaderboard rows (docs/leaderboard.md) as the commands wrote them.

    python benchmarks/bench_all.py --size small -o bench-all            # minutes
    python benchmarks/bench_all.py --jobs 2 -o bench-all                # the full tracks (issue 48: <= 60 min, <= 4 GB)
    python benchmarks/bench_all.py --size small --made thesis=DIR ...   # score folders made before

The issue's target is a budget, not a ratio: the script prints the wall time of each command and
their sum, and the largest resident set of any child process (``ru_maxrss`` of the children).
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import time
from pathlib import Path

from faultgen.bench import baselines, tracks


def run(argv: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(argv, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--out", type=Path, required=True, help="folder for the tracks and the scores")
    parser.add_argument("--size", default="full", choices=tracks.SIZES)
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--made", action="append", default=[], metavar="TRACK=DIR", help="a track's folder made before")
    parser.add_argument("--track", action="append", default=[], help="only these tracks (default: every one with a version)")
    args = parser.parse_args()
    args.out.mkdir(exist_ok=True)
    made = dict(m.split("=", 1) for m in args.made)
    faultgen = [sys.executable, "-m", "faultgen.cli"]
    names = args.track or [n for n in tracks.names() if tracks.load(n).versions]
    rows, total = [], 0.0
    for name in names:
        folder = Path(made.get(name, args.out / name))
        if name not in made:
            seconds = run([*faultgen, "bench", "make", name, "--size", args.size, "--jobs", str(args.jobs),
                           "--no-progress", "-o", str(folder)])
            total += seconds
            print(f"make {name} ({args.size}): {seconds:.1f} s", flush=True)
        for baseline in baselines.DETECTORS + baselines.ISOLATORS:
            stem = args.out / f"{name}-{baseline}"
            seconds = run([*faultgen, "bench", "score", name, "--data", str(folder), "--baseline", baseline,
                           "-o", str(stem)])
            total += seconds
            print(f"score {name} {baseline}: {seconds:.1f} s", flush=True)
            rows.append(stem.with_name(stem.name + ".md").read_text().strip())
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    print(f"\ntotal {total / 60:.1f} min; largest process {peak:.0f} MB\n")
    print("| track | method | AUROC [95 % CI] | false alarms % | detected % | delay after 10 % wear (cycles) | "
          "isolation top-1 % | command | date |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
