"""Where `faultgen monitor`'s time per log goes on the iiwa-like fleet (issue 87 item 2): the
monitor run in this process under cProfile, its seconds per log and the profile's top entries.

    python benchmarks/monitor_profile.py [--units 2] [--days 16] [--seed 5] [--top 25] [--work DIR]

The fleet is benchmarks/monitor_cycles.py's mixed one (faultgen/bench/independent.py through
tests/independent_fleet.py: rtb-data's LBR iiwa 14 R820 added with ``--payload 14``, 7 axes,
logs of 1 or 2 cycles at 250 or 500 Hz, Pinocchio's dynamics, one worn unit), written under
``WORK/mixed`` (kept: a rerun profiles the monitor only); the monitor is ``loop.monitor`` with the
nominal twin, train 10, persistence 3, one job, as in monitor_cycles.py. cProfile slows Python-heavy
code more than compiled code: the seconds per log are printed with and without it (two runs).
"""

from __future__ import annotations

import cProfile
import io
import os
import pstats
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from monitor_cycles import arguments, fleet  # noqa: E402  (sibling module)

from faultgen.monitor import loop  # noqa: E402
from faultgen.monitor.run import resolve_run  # noqa: E402
from faultgen.monitor.scoring import Settings  # noqa: E402


def main() -> None:
    parser = arguments(__doc__, 2, 16, "monitor_profile_work")
    parser.add_argument("--top", type=int, default=25)
    args = parser.parse_args()
    root = args.work / "mixed"
    robot, logs = fleet(args.work, root, args.units, args.days, args.seed, True)
    n = args.units * args.days

    def run(tag: str) -> None:
        loop.monitor(resolve_run(robot, logs, root / f"out-{tag}-{time.strftime('%Y%m%dT%H%M%S')}", calibrate=False,
                                 settings=Settings(train=10, persistence=3), progress=False))

    wall, cpu = time.perf_counter(), time.process_time()
    run("plain")
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    profile = cProfile.Profile()
    profiled = time.perf_counter()
    profile.runcall(run, "profiled")
    profiled = time.perf_counter() - profiled
    print(f"{n} logs ({args.units} units x {args.days} days), load average {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores: {wall / n:.3f} s per log wall, {cpu / n:.3f} s CPU; under cProfile "
          f"{profiled / n:.3f} s per log wall")
    for key in ("tottime", "cumulative"):
        text = io.StringIO()
        pstats.Stats(profile, stream=text).sort_stats(key).print_stats(args.top)
        print(f"--- top {args.top} by {key}")
        print("\n".join(line for line in text.getvalue().splitlines() if line.strip())[:20000])


if __name__ == "__main__":
    main()
