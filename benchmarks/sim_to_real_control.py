"""The sim-to-real track's within-simulator control: the same train part (faultgen's kr210), judged on
faultgen's own units of the same recipe (seeds 3 and 4) instead of the independent fleet.

    python benchmarks/sim_to_real_control.py -o DIR [--jobs 2] [--size small]

If the detectors beat chance here and not on the sim-to-real track, the independent fleet's gap
is what they fail on; if they are at chance here too, the track's question is hard within faultgen
already (docs/leaderboard.md says which was seen). Prints each detector baseline's AUROC and
false-alarm rate with their bootstrap intervals (faultgen.bench.score), and the make's time.
"""

from __future__ import annotations

import argparse
import tempfile
import time
import tomllib
from pathlib import Path

from faultgen.bench import baselines, make, score, tracks


def control_recipe() -> dict:
    """sim-to-real version 1 with its fleet part replaced by its faultgen part's test seeds 3 and 4."""
    with open(Path(tracks.__file__).parent / "tracks" / "sim-to-real.toml", "rb") as f:
        track = tomllib.load(f)
    version = dict(track["versions"][0])
    parts = [dict(p) for p in version["parts"] if p.get("kind", "grid") != "logs"]
    for part in parts:
        part.pop("test_seeds", None)
    version.update(parts=parts, test_seeds=[3, 4])
    return {**track, "name": "sim-to-real-control", "versions": [version]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--out", type=Path, required=True, help="folder to make the control's files in")
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--size", default="full", choices=tracks.SIZES)
    args = parser.parse_args()
    control = tracks.parse(control_recipe(), "sim-to-real control")
    folder = Path(tempfile.mkdtemp(prefix="control-"))
    tracks.load = lambda name: control  # the control is no track of the package: make is given it here
    make.manifest_path = lambda t, v, s: folder / f"{t}-{v}-{s}.json"  # never frozen
    started = time.perf_counter()
    make.make("sim-to-real-control", args.out, size=args.size, jobs=args.jobs, progress=False)
    print(f"made {args.out} in {time.perf_counter() - started:.0f} s")
    for name in baselines.DETECTORS:
        role, method = baselines.make(name)
        r = score.score(args.out, method, name, role, allow_modified=True)["results"]  # never frozen: not comparable
        auroc, false = r["auroc"], r["false_alarm_rate"]
        print(f"{name:9s} AUROC {auroc['value']:.3f} [{auroc['ci95'][0]:.3f}, {auroc['ci95'][1]:.3f}]  "
              f"false alarms {100 * false['value']:.1f} % [{100 * false['ci95'][0]:.1f}, {100 * false['ci95'][1]:.1f}]")


if __name__ == "__main__":
    main()
