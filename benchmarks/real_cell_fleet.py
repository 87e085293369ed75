"""The real cell's fleets of issue 90 (its first "must show" bullet), made by the independent simulator
(:mod:`faultgen.bench.independent`: Pinocchio's dynamics, the fleet's own friction law; the cell's
options in :mod:`faultgen.bench.cell`), and optionally today's ``faultgen monitor`` run on one.

    python benchmarks/real_cell_fleet.py WORK [--scatter 0.015 0.03] [--units 12] [--worn 8] [--days 120]
        [--seed 0] [--one-program] [--rates 3 0.3] [--onset 45 50] [--monitor] [--timeout S] [--jobs N]

Each fleet, ``WORK/scatter-<sigma>[-one-program]/``: KR210 units (rtb-data's KR210 L150, added as
``faultgen robots add`` adds it, in ``WORK/kr210``) logging once a day; the cell has 3 programs (the
pick and place and two part variants), the units running 1, 2 and 3 of them in turn, one a day; each
log 1.5-3 cycles from a random phase; a friction test every 14 days; ``--worn`` units wearing on one
axis, linearly, quadratically and exponentially in turn, from a day drawn in the first 1/6-5/12 of
the record to 60 % on the last; the dry friction falling 0.4 % per kelvin and the viscous as the
generator's law (deterministic); the friction of each log and each test scattering from day to day
by ``--scatter`` (log-normal sigma, both alike; the issue's 1.5 % and 3 %). ``--one-program``: the
same fleets with every unit on the pick and place alone and one whole cycle a log (the issue's
comparison). ``--rates 3 0.3``: the first two worn units wear 3 and 0.3 points a day from their onset
instead (the issue's fast and slow wear; ``-rates`` in the folder's name). ``--onset A B``: the worn
units' onset drawn in days A-B instead (``-onset-A-B`` in the folder's name; e.g. 45 50: a fast wear
that begins after the unit has learned, about its 30th day). A fleet already there is kept (the same
seed draws the same files).

``--monitor``: ``faultgen monitor LOGS --robot WORK/kr210 -o OUT`` on each fleet, timed, killed past
``--timeout`` s (then it has written nothing: the monitor writes its outputs at the end; its console
with its progress is in ``OUT.console.txt``); printed: the CPU time per log (the monitor's and its
children's: on a shared machine the wall time is not its own), the units monitored (units.csv's
status), the program changes it reported (its notes "program changed at") against those the truth
has (a unit meeting a program it had not run before, ``truth_programs.csv``), and the worn units'
first alarm against the true wear. Each figure with its verdict against the issue's criterion.
Results: docs/analysis.md, "A real cell: the baseline".
"""

from __future__ import annotations

import argparse
import csv
import resource
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import pinocchio_log

from faultgen import children
from faultgen.bench import cell, independent

#: The issue's cell: programs, the programs each unit runs in turn, a log's span (cycles), the test interval, days.
PROGRAMS, UNIT_PROGRAMS, SPAN, TEST_EVERY = 3, (1, 2, 3), (1.5, 3.0), 14
#: The dry friction's fall per kelvin (the second independent fleet's, benchmarks/wear_hump_fleet.py).
DRY_PER_K = 0.004
#: Every unit monitored by its 40th day; the first alarm between 8 and 15 % true wear (issue 90).
MONITORED_BY, ALARM = 40, (8.0, 15.0)


def spec(scatter: float, units: int = 12, worn: int = 8, days: int = 120, seed: int = 0,
         one_program: bool = False, rates: tuple[float, ...] = (),
         onset: tuple[int, int] | None = None) -> independent.FleetSpec:
    """The issue's fleet at ``scatter`` (module docstring); ``one_program``: one program, whole cycles;
    ``rates``: the first worn units' wear in points a day; ``onset``: the days the worn units' onset
    is drawn in (None: the first 1/6-5/12 of the record)."""
    cell_options = {} if one_program else {"programs": PROGRAMS, "unit_programs": UNIT_PROGRAMS, "span": SPAN}
    return independent.FleetSpec(
        units=units, worn=worn, days=days, seed=seed, onset=onset or (max(days // 6, 1), max(days * 5 // 12, 1)),
        friction_test_every=TEST_EVERY, wear_laws=cell.WEAR_LAWS, log_jitter=scatter, test_jitter=scatter,
        dry_per_k=DRY_PER_K, wear_rates=tuple(rates), **cell_options)


def new_programs(root: Path) -> dict[str, list[str]]:
    """Per unit the stamps on which it runs a program it had not run before (its first log excluded),
    from ``truth_programs.csv``; every unit of a one-program fleet: none."""
    path = root / "truth_programs.csv"
    out: dict[str, list[str]] = {}
    if not path.is_file():
        return out
    seen: dict[str, set] = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            known = seen.setdefault(row["unit"], set())
            if known and row["program"] not in known:
                out.setdefault(row["unit"], []).append(row["stamp"])
            known.add(row["program"])
    return out


def run_monitor(logs: Path, robot: Path, out: Path, timeout: float, jobs: int,
                options: tuple[str, ...] = ()) -> tuple[float, float, int | None]:
    """``faultgen monitor`` on ``logs`` (more of its ``options`` after the others): (wall time s, CPU
    time s of it and its children, exit status or None when killed past ``timeout``). On a shared
    machine the CPU time is the figure to compare."""
    command = [*children.command("-m", "faultgen.cli"), "monitor", str(logs), "--robot", str(robot), "-o", str(out),
               "--jobs", str(jobs), *options]
    started, cpu = time.perf_counter(), _children_cpu()
    console = out.with_name(out.name + ".console.txt")  # its progress, read when it was killed
    try:
        with open(console, "w") as sink:
            result = subprocess.run(command, env=children.environment(), stdout=sink, stderr=subprocess.STDOUT,
                                    text=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        return time.perf_counter() - started, _children_cpu() - cpu, None
    if result.returncode not in (0, 3):
        raise SystemExit(f"{' '.join(command)} failed ({result.returncode}):\n{console.read_text()[-3000:]}")
    return time.perf_counter() - started, _children_cpu() - cpu, result.returncode


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def summary(root: Path, out: Path, fleet: independent.FleetSpec) -> list[str]:
    """The monitor's outcome on the fleet at ``root`` (module docstring), lines with verdicts."""
    with open(out / "units.csv", newline="") as f:
        units = list(csv.DictReader(f))
    status = {u["unit"]: u["status"] for u in units}
    reported = {u["unit"]: sum(str(v).count("program changed at") for v in u.values()) for u in units}
    truth_new = new_programs(root)
    monitored = sum(s == "monitored" for s in status.values())
    lines = [f"units monitored at the end ({fleet.days} days): {monitored} of {len(status)} "
             f"({'met' if monitored == len(status) else 'NOT met'}: every unit monitored by day {MONITORED_BY}); "
             f"statuses {dict(sorted((s, list(status.values()).count(s)) for s in set(status.values())))}"]
    for name in sorted(status):
        lines.append(f"  {name}: {status[name]}; program changes reported {reported[name]}, new programs met "
                     f"{len(truth_new.get(name, []))} ({'met' if reported[name] == len(truth_new.get(name, [])) else 'NOT met'})")
    truth = independent.read_truth(root / "truth.csv")
    with open(out / "alarms.csv", newline="") as f:
        alarms = [r for r in csv.DictReader(f) if r["first_alarm"]]
    for name, t in sorted(truth.items()):
        first = min((r["first_alarm"] for r in alarms if r["unit"] == name), default="")
        wear = dict(zip(t["stamps"], t["wear"])).get(first)
        if t["axis"]:
            ok = wear is not None and ALARM[0] <= wear <= ALARM[1]
            lines.append(f"  {name} (axis {t['axis']} worn): first alarm {first or 'none'}"
                         f"{'' if wear is None else f' at {wear:.1f} % true wear'} ({'met' if ok else 'NOT met'}: "
                         f"{ALARM[0]:g}-{ALARM[1]:g} %)")
        elif first:
            lines.append(f"  {name} (healthy): alarm {first} (NOT met: healthy units quiet)")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("work", type=Path)
    parser.add_argument("--scatter", type=float, nargs="+", default=[0.015, 0.03])
    parser.add_argument("--units", type=int, default=12)
    parser.add_argument("--worn", type=int, default=8)
    parser.add_argument("--days", type=int, default=120)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--one-program", action="store_true")
    parser.add_argument("--rates", type=float, nargs="*", default=[])
    parser.add_argument("--onset", type=int, nargs=2, default=None, metavar=("FIRST", "LAST"))
    parser.add_argument("--monitor", action="store_true")
    parser.add_argument("--timeout", type=float, default=3600.0)
    parser.add_argument("--jobs", type=int, default=1)
    args = parser.parse_args()
    robot = args.work / "kr210"
    if not (robot / "drivetrain.toml").is_file():
        pinocchio_log.add_kr210(robot)
    for scatter in args.scatter:
        onset = tuple(args.onset) if args.onset else None
        fleet = spec(scatter, args.units, args.worn, args.days, args.seed, args.one_program, tuple(args.rates), onset)
        root = args.work / (f"scatter-{scatter:g}{'-one-program' if args.one_program else ''}"
                            f"{'-rates' if args.rates else ''}{f'-onset-{onset[0]}-{onset[1]}' if onset else ''}")
        started = time.perf_counter()
        logs, _ = independent.write_fleet(root, fleet, robot)
        print(f"fleet {root.name}: {fleet.units} units x {fleet.days} days written in "
              f"{time.perf_counter() - started:.0f} s ({logs})")
        if not args.monitor:
            continue
        wall, cpu, code = run_monitor(logs, robot, root / "monitor", args.timeout, args.jobs)
        n = fleet.units * fleet.days
        if code is None:
            print(f"  faultgen monitor killed after {wall:.0f} s (--timeout; the CPU time of a killed run is not "
                  f"counted): no outputs; more than {wall / n:.1f} s wall per log ({n} logs)")
            continue
        print(f"  faultgen monitor: exit {code}, {wall:.0f} s wall, {cpu:.0f} s CPU: {cpu / n:.2f} s CPU per log "
              f"({n} logs, --jobs {args.jobs})")
        for line in summary(root, root / "monitor", fleet):
            print(line)


if __name__ == "__main__":
    main()
