"""`faultgen monitor`'s CPU seconds per log on the iiwa-like fleet and on a one-cycle KR210 fleet
(issue 87 item 2, aim: at most 0.2 s a log on both), this checkout against a baseline checkout in
the same run, each measured in a process of its own, the two in turns.

    python benchmarks/monitor_per_log.py --baseline DIR [--units 2] [--days 16 48] [--repeat 2] [--work DIR]

``--baseline``: another checkout of faultgen (``git archive main | tar -x -C DIR``), run with its
own folder first on ``PYTHONPATH``; without it only this checkout is measured. The fleets (made
once, under ``WORK``, by a simulator that is not faultgen: tests/independent_fleet.py): the iiwa-like
one is benchmarks/monitor_cycles.py's mixed fleet (rtb-data's LBR iiwa 14 R820 added with
``--payload 14``, 7 axes, logs of 1 or 2 cycles at 250 or 500 Hz, one worn unit, one program change
nobody logged), seed 5; the KR210 one tests/independent_fleet.py's default (rtb-data's KR210, 6
axes, one cycle at 250 Hz a log, one worn unit), seed 5. Each measurement: the monitor run once in
the process (imports, caches of the libraries; not timed), then once more into a new output folder
(an empty twin cache: every cycle simulated again) timed by ``time.process_time`` (this process's
CPU: the run is ``--jobs 1``, the nominal twin, train 10, persistence 3). Printed: one row per run,
then per fleet and size the median of each checkout's runs, their ratio and the verdict against
0.2 s a log.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

AIM = 0.2  # CPU s per log (issue 87 item 2)
HERE = Path(__file__).resolve().parents[1]


def measure(checkout: Path, work: Path, fleet: str, units: int, days: int) -> float:
    """CPU seconds per log of one monitor run of ``checkout`` on the fleet (made under ``work``)."""
    env = {**os.environ, "PYTHONPATH": str(checkout), "OMP_NUM_THREADS": "1"}
    from faultgen import children  # -P: the child puts no script or current folder on its path

    out = subprocess.run(children.command(__file__, "--child", fleet, str(units), str(days), str(work)), env=env,
                         cwd=checkout, capture_output=True, text=True, check=False)
    rows = [line for line in out.stdout.splitlines() if line.startswith("CPU ")]
    if out.returncode or not rows:
        raise SystemExit(f"{checkout}: the run failed ({out.returncode}):\n{out.stderr[-3000:]}")
    return float(rows[-1].split()[1])


def child(fleet: str, units: int, days: int, work: Path) -> None:
    """One measurement in this process (its ``PYTHONPATH`` the checkout): prints ``CPU <s per log>``."""
    sys.path[:0] = [str(Path.cwd() / "tests"), str(Path.cwd() / "benchmarks")]
    import independent_fleet
    from monitor_cycles import fleet as iiwa_fleet

    from faultgen.monitor import loop
    from faultgen.monitor.run import resolve_run
    from faultgen.monitor.scoring import Settings

    if fleet == "iiwa":
        root = work / f"iiwa-{units}x{days}"
        robot, logs = iiwa_fleet(work, root, units, days, 5, True)
    else:
        root = work / f"kr210-{units}x{days}"
        robot, logs = root / "kr210", root / "logs"
        if not logs.is_dir():
            independent_fleet.write_fleet(root, independent_fleet.FleetSpec(units=units, worn=1, days=days, seed=5,
                                                                            onset=(days // 3, days // 2)))

    def run() -> None:
        out = Path(tempfile.mkdtemp(prefix="out-", dir=root))
        loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=Settings(train=10, persistence=3),
                                 progress=False))

    run()
    cpu = time.process_time()
    run()
    print(f"CPU {(time.process_time() - cpu) / (units * days):.4f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", type=Path, help="another checkout to measure in turns with this one")
    parser.add_argument("--units", type=int, default=2)
    parser.add_argument("--days", type=int, nargs="+", default=[16, 48])
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--work", type=Path, default=None, help="keep the fleets here (default: a temporary folder)")
    parser.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        fleet, units, days, work = args.child
        return child(fleet, int(units), int(days), Path(work))
    work = args.work or Path(tempfile.mkdtemp(prefix="monitor-per-log-"))
    work.mkdir(parents=True, exist_ok=True)
    checkouts = {"this": HERE} | ({"baseline": args.baseline.resolve()} if args.baseline else {})
    print(f"# {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {os.cpu_count()} cores, load average "
          f"{os.getloadavg()[0]:.1f} at the start; {args.units} units; checkouts: "
          + ", ".join(f"{k} {v}" for k, v in checkouts.items()))
    found: dict[tuple, list[float]] = {}
    for _ in range(args.repeat):
        for fleet in ("iiwa", "kr210"):
            for days in args.days:
                for name, checkout in reversed(checkouts.items()):  # the baseline first, then this one
                    cpu = measure(checkout, work, fleet, args.units, days)
                    found.setdefault((fleet, days, name), []).append(cpu)
                    print(f"{fleet} {args.units}x{days} {name}: {cpu:.4f} s CPU per log (load {os.getloadavg()[0]:.1f})",
                          flush=True)
    for fleet in ("iiwa", "kr210"):
        for days in args.days:
            this = statistics.median(found[fleet, days, "this"])
            line = f"{fleet} {args.units}x{days}: this {this:.4f} s CPU per log"
            if args.baseline:
                base = statistics.median(found[fleet, days, "baseline"])
                line += f", baseline {base:.4f} ({this / base:.2f}x)"
            print(f"{line}: {'met' if this <= AIM else 'not met'} (aim {AIM} s a log)")


if __name__ == "__main__":
    main()
