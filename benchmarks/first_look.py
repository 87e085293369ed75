"""The README's first analysis step, timed and judged against chance (issue 88, item 4).

    python benchmarks/first_look.py [--dataset first-look.h5] [--work DIR] [--jobs 2]

In one run of this script: ``faultgen sweep --preset first-look`` (skipped with --dataset), then
the three analyses the README sends a new user to, on that dataset, as written there:
``faultgen bench-isolators``, ``faultgen detect`` and ``faultgen classify``. Each command's wall and
CPU time (user + system of the command and the processes it waited for; a worker pool's processes
that outlive their waits are not counted), and each analysis's result against its chance level:

- bench-isolators: per isolator, the accuracy on the worn runs (every task and wear level the
  isolator ran on) against 1/N, N the robot's axes (naming an axis at random); the runs without
  wear are not part of this figure (the isolator's table gives them, "no fault").
- detect (``--locate contribution``, as the README runs it): the share of worn runs detected against
  the held-out false-alarm rate (a monitor that alarms at random detects at about its false-alarm
  rate), and the share located against 1/N.
- classify: the cells above their row's chance level (the command's own verdict, its
  ``above_chance`` column).

Wall times on a shared machine are upper bounds; the script prints ``uptime``'s load before and
after. The last line is ``beats chance: K of 3 analyses``.
"""
from __future__ import annotations

import argparse
import csv
import os
import subprocess
import tempfile
import time
from pathlib import Path

from faultgen import children

PRESET = "first-look"


def timed(command: list[str], log: Path) -> tuple[float, float]:
    """Wall time and CPU time (user + system, the command and the workers it waited for), s; its
    output to ``log``."""
    import resource

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    with open(log, "w") as sink:
        subprocess.run(command, env=children.environment(), check=True, stdout=sink, stderr=subprocess.STDOUT)
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def isolation_verdict(path: Path) -> tuple[bool, str]:
    """Per isolator, the accuracy on the worn runs' cases it ran on against 1/N."""
    table = [r for r in rows(path) if int(r["worn_axis"]) > 0 and int(r["predicted"]) >= 0]
    n_axes = max(int(r["n_axes"]) for r in rows(path))
    lines, best = [], 0.0
    for isolator in sorted({r["isolator"] for r in table}):
        mine = [r for r in table if r["isolator"] == isolator]
        accuracy = sum(r["correct"] == "True" for r in mine) / len(mine)
        best = max(best, accuracy)
        lines.append(f"  {isolator}: {100 * accuracy:.1f} % of {len(mine)} worn cases "
                     f"({'above' if accuracy > 1 / n_axes else 'not above'} chance, {100 / n_axes:.1f} %)")
    return best > 1 / n_axes, "\n".join(lines)


def detection_verdict(path: Path, n_axes: int) -> tuple[bool, str]:
    """The 'all' row of the detection summary: detected against false alarms, located against 1/N;
    above chance when both are."""
    every = [r for r in rows(path) if r.get("group") == "all"][-1]
    detected, false_alarms = float(every["detected_pct"]), float(every["false_alarm_pct"])
    located = float(every["located_pct"])
    text = (f"  detected {detected:.1f} % of worn runs against {false_alarms:.2f} % false alarms on healthy runs; "
            f"located {located:.1f} % against {100 / n_axes:.1f} % by chance")
    return detected > false_alarms and located > 100 / n_axes, text


def classification_verdict(path: Path) -> tuple[bool, str]:
    """The cells the command judged above their row's chance level."""
    table = [r for r in rows(path) if r.get("above_chance") not in ("", None)]
    above = [r for r in table if r["above_chance"] == "True"]
    return bool(above), f"  {len(above)} of {len(table)} judged cells above chance"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--dataset", type=Path, help="an existing first-look dataset: the sweep is not run")
    parser.add_argument("--work", type=Path, help="folder for the dataset and the outputs (default: a temporary one)")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    work = args.work or Path(tempfile.mkdtemp(prefix="first-look-"))
    work.mkdir(parents=True, exist_ok=True)
    faultgen = children.command("-m", "faultgen.cli")
    print(f"load average before: {load()}")
    data = args.dataset or work / f"{PRESET}.h5"
    times = {}
    if args.dataset is None:
        times["sweep"] = timed([*faultgen, "sweep", "--preset", PRESET, "--jobs", str(args.jobs), "--no-progress",
                                "-o", str(data)], work / "sweep.log")
    stem = work / data.stem
    steps = {"bench-isolators": ["bench-isolators", str(data), "-o", f"{stem}-isolation"],
             "detect": ["detect", str(data), "--locate", "contribution", "-o", f"{stem}-detection"],
             "classify": ["classify", str(data), "-o", f"{stem}-classification"]}
    for name, command in steps.items():
        times[name] = timed([*faultgen, *command, "--no-progress", "--overwrite"], work / f"{name}.log")
    print(f"load average after: {load()}")
    for name, (wall, cpu) in times.items():
        print(f"{name}: wall {wall:.1f} s, CPU {cpu:.1f} s")
    n_axes = max(int(r["n_axes"]) for r in rows(Path(f"{stem}-isolation.csv")))
    verdicts = {"bench-isolators": isolation_verdict(Path(f"{stem}-isolation.csv")),
                "detect": detection_verdict(Path(f"{stem}-detection-summary.csv"), n_axes),
                "classify": classification_verdict(Path(f"{stem}-classification.csv"))}
    for name, (above, text) in verdicts.items():
        print(f"{name}: {'above chance' if above else 'NOT above chance'}\n{text}")
    print(f"outputs and logs in {work}")
    print(f"beats chance: {sum(above for above, _ in verdicts.values())} of {len(verdicts)} analyses")


if __name__ == "__main__":
    main()
