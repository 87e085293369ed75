"""The prognostics track made twice by `faultgen bench make` (each in a fresh folder, in the version's
numeric profile), its two manifests' arrays compared with each other and with the frozen manifest
(faultgen/bench/manifests/prognostics-<version>-<size>.json) when there is one; prints each make's wall time.

    python benchmarks/prognostics_made_twice.py [--version 2] [--size full] [--work DIR]

Issue 75, item 7: "prognostics track v2 made twice with identical manifests" (the full size: some 15-30
minutes a make on a loaded 2-core machine; the test size is tests/test_bench_prognostics_v2.py's).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import tempfile
import time
from pathlib import Path

from faultgen import children
from faultgen.bench import make, tracks


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--version", type=int, default=2)
    parser.add_argument("--size", default="full", choices=tracks.SIZES)
    parser.add_argument("--work", type=Path, default=None)
    args = parser.parse_args()
    work = args.work or Path(tempfile.mkdtemp(prefix="prognostics-twice-"))
    work.mkdir(parents=True, exist_ok=True)
    manifests = []
    for k in (1, 2):
        out = work / f"made{k}"
        command = [*children.command("-m", "faultgen.cli"), "bench", "make", "prognostics", "--version",
                   str(args.version), "--size", args.size, "--no-progress", "-o", str(out)]
        started = time.perf_counter()
        done = subprocess.run(command, env=children.environment(), check=False, capture_output=True, text=True)
        if done.returncode:
            raise SystemExit(f"{' '.join(command)} failed ({done.returncode}):\n{done.stderr[-3000:]}")
        manifests.append(json.loads((out / "manifest.json").read_text()))
        print(f"make {k}: {time.perf_counter() - started:.0f} s, {len(manifests[-1]['arrays'])} arrays, "
              f"status {manifests[-1]['status']}")
    differs = make.first_difference(manifests[1]["arrays"], manifests[0]["arrays"])
    print("the two manifests: " + ("identical" if differs is None else f"differ at {differs[0]} ({differs[1]} arrays)"))
    frozen = make.manifest_path("prognostics", args.version, args.size)
    if frozen.is_file():
        against = make.first_difference(manifests[0]["arrays"], json.loads(frozen.read_text())["arrays"])
        print(f"against {frozen.name}: " + ("identical" if against is None else f"differ at {against[0]}"))
    raise SystemExit(0 if differs is None else 1)


if __name__ == "__main__":
    main()
