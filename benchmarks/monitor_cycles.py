"""`faultgen monitor` on a fleet whose logs mix one- and two-cycle logs at 250 and 500 Hz, against the
same fleet with one cycle at 250 Hz per log (issue 72 item 8; docs/analysis.md and
docs/performance.md, "Logs of several cycles"): the program changes reported and the time per log
(wall and this process's CPU), measured in the same run.

    python benchmarks/monitor_cycles.py [--units 4] [--days 40] [--seed 5] [--work DIR]

The fleets (tests/independent_fleet.py: rtb-data's LBR iiwa 14 R820 added with ``--payload 14``,
Pinocchio's dynamics, one worn unit, one healthy unit with a program change nobody logged) are
written under ``WORK/mixed`` and ``WORK/plain`` (kept: a rerun times the monitor only); the monitor
runs in this process (``loop.monitor``, the nominal twin, train 10, persistence 3, one job).
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import independent_fleet  # noqa: E402

from faultgen.monitor import loop  # noqa: E402
from faultgen.monitor.run import resolve_run  # noqa: E402
from faultgen.monitor.scoring import Settings  # noqa: E402


def spec(units: int, days: int, seed: int, mixed: bool) -> independent_fleet.FleetSpec:
    layout = dict(cycles=(1, 2), rates=(250.0, 500.0)) if mixed else {}
    return independent_fleet.FleetSpec(units=units, worn=1, days=days, seed=seed, onset=(days // 4, days // 4),
                                       final_wear=100.0, wearable=(1, 2, 3, 4, 5, 6, 7), max_part=14.0,
                                       rated_part=True, program_changes=1, rate=250.0, **layout)


def arguments(doc: str, units: int, days: int, work: str) -> argparse.ArgumentParser:
    """The fleet's options (``--units``, ``--days``, ``--seed``, ``--work``) of a benchmark on this fleet."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--units", type=int, default=units)
    parser.add_argument("--days", type=int, default=days)
    parser.add_argument("--seed", type=int, default=5)
    parser.add_argument("--work", type=Path, default=Path(work))
    return parser


def fleet(work: Path, root: Path, units: int, days: int, seed: int, mixed: bool) -> tuple[Path, Path]:
    """(robot folder, logs folder): the iiwa 14 added under ``work`` once, the fleet written under ``root``."""
    robot = work / "iiwa14"
    if not robot.is_dir():
        independent_fleet.add_robot(robot, "iiwa14", payload=14.0)
    return robot, independent_fleet.independent.write_fleet(root, spec(units, days, seed, mixed), robot)[0]


def main() -> None:
    args = arguments(__doc__, 4, 40, "monitor_cycles_work").parse_args()
    for kind in ("mixed", "plain"):
        root = args.work / kind
        robot, logs = fleet(args.work, root, args.units, args.days, args.seed, kind == "mixed")
        out = root / f"out-{time.strftime('%Y%m%dT%H%M%S')}"
        wall, cpu = time.perf_counter(), time.process_time()
        loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=Settings(train=10, persistence=3),
                                 progress=False))
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        n = args.units * args.days
        with open(out / "units.csv", newline="") as f:
            changes = [note.split(" (not logged")[0] for row in csv.DictReader(f)
                       for note in row["reason"].split("; ") if note.startswith("program changed")]
        with open(out / "alarms.csv", newline="") as f:
            alarms = [(r["unit"], r["first_alarm"], r["source_axis"]) for r in csv.DictReader(f) if r["first_alarm"]]
        print(f"{kind}: {wall / n:.3f} s per log wall, {cpu / n:.3f} s CPU ({n} logs; load "
              f"{os.getloadavg()[0]:.1f}); program changes reported: {changes or 'none'}; alarms: {alarms}; "
              f"truth: {(root / 'changes.csv').read_text().splitlines()[1:]}")


if __name__ == "__main__":
    main()
