"""`faultgen monitor` on a fleet made by a simulator that is not faultgen: detection, isolation,
false alarms per protocol, and the loop's time against `faultgen fleet` (issue 46).

    python benchmarks/monitor_loop.py [--units 12] [--worn 8] [--days 120] [--seed 0] [--work DIR]
                                      [--protocols own,nominal,twin] [--skip-fleet] [--repeat]
                                      [--arm kr210|iiwa14 --payload KG] [--max-part KG [--rated-part]]
                                      [--wearable 1,2,..] [--gearbox-changes N] [--program-changes N]

The two fleets of issue 60 ("Two independent fleets of your own making", docs/analysis.md):

    python benchmarks/monitor_loop.py --arm kr210 --payload 150 --max-part 150 --rated-part --wearable 1,2,3,4,5,6 \
        --units 10 --worn 6 --days 100 --seed 7 --skip-fleet --protocols twin
    python benchmarks/monitor_loop.py --arm iiwa14 --payload 14 --max-part 14 --rated-part --wearable 1,2,3,4,5,6,7 \
        --gearbox-changes 1 --program-changes 1 --units 10 --worn 6 --days 100 --seed 8 --skip-fleet \
        --protocols twin

In one run of this script:

- the fleet (tests/independent_fleet.py: Pinocchio RNEA on rtb-data's KR210 URDF, or with ``--arm``
  the KR210 L150 or LBR iiwa 14 R820 added with ``--payload``; our own motor-side friction,
  seasons, parts up to ``--max-part`` kg, noise; ``--worn`` units wearing one axis each of
  ``--wearable``; ``--gearbox-changes`` worn units with a gearbox change in events.csv and
  ``--program-changes`` healthy units with a program change nobody logged), its truth in
  ``truth.csv`` and ``changes.csv``;
- `faultgen monitor` on it per protocol: ``own`` (the features themselves against the unit's first
  28 logs, no model), ``nominal`` (residuals against the twin built on the nominal model) and
  ``twin`` (the default: each unit's model calibrated on its first log); each timed (wall, peak
  RSS of the process tree);
- `faultgen fleet` simulating the same number of units and days (the same robot folder, one
  cycle a day, ``--jobs 1`` like the monitor), timed in the same run: the ratio monitor / fleet
  (goal <= 1);
- ``--repeat``: the fleet written again from the same seed and the twin monitor re-run: are the
  logs and alarms.csv / scores.csv identical?

Printed per protocol: worn units flagged with their wear at the first alarm in [10, 40) %
(the issue's window), before 10 %, at 40 % or later, or never; detection delay (days from the
wear reaching 10 % to the first alarm: median and range); isolation (worn axis named by the
alarm); healthy units that ever alarm; false alarms per healthy unit-day (logs over a limit
after the learning logs, of all such logs: what the log alarmed on, T2 or Q without a model, the
wear estimate's lower bound with the twin; at most 2 alpha for "T2 or Q", and N alpha for "any of
the N axes' bounds over the limit", if the residuals were independent normal). Then each unit as a
row of a Markdown table (status and model from units.csv, worn axis, first alarm and its day, the
true wear at it, the axis named, and what followed a gearbox or program change: the alarm it
closed, the logs learned again, any alarm after it).
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from faultgen import children

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import independent_fleet  # noqa: E402

from benchmarks_common import PeakRSS, fleet_options  # noqa: E402  (sibling module)

PROTOCOLS = {"own": ["--protocol", "own"], "nominal": ["--no-calibrate"], "twin": []}


def run(command: list[str]) -> tuple[float, int, str, int]:
    """Wall time (s), peak RSS of the process tree (bytes), stdout and exit status of ``command``."""
    with PeakRSS() as memory:
        started = time.perf_counter()
        result = subprocess.run(command, env=children.environment(), capture_output=True, text=True)
        wall = time.perf_counter() - started
    if result.returncode not in (0, 3):  # 3: some unit degraded or not monitored, every output written
        raise SystemExit(f"{' '.join(command)} failed:\n{result.stderr[-3000:]}")
    return wall, memory.peak, result.stdout, result.returncode


def summary(truth: Path, out: Path) -> dict:
    outcome = independent_fleet.evaluate(truth, out / "alarms.csv")
    worn = {u: o for u, o in outcome.items() if o["axis"]}
    healthy = [u for u, o in outcome.items() if not o["axis"]]
    delays = [o["delay"] for o in worn.values() if o["in_window"]]
    with open(out / "scores.csv", newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["unit"] in healthy and r["phase"] == "monitoring"]
    return {
        "in_window": sum(o["in_window"] for o in worn.values()),
        "early": sum(o["wear"] is not None and o["wear"] < 10 for o in worn.values()),
        "late": sum(o["wear"] is not None and o["wear"] >= 40 for o in worn.values()),
        "missed": sum(o["wear"] is None for o in worn.values()),
        "worn": len(worn),
        "delay": (float(np.median(delays)), min(delays), max(delays)) if delays else None,
        "isolated": sum(o["source"] == o["axis"] for o in worn.values() if o["alarm"]),
        "alarmed": sum(bool(o["alarm"]) for o in worn.values()),
        "healthy_alarm": sum(bool(outcome[u]["alarm"]) for u in healthy),
        "healthy": len(healthy),
        "false_rate": (sum(int(r["alarm"]) for r in rows), len(rows)),
        "units": outcome,
    }


def _after(rows: list[dict], stamp: str) -> dict:
    """Phases of a unit's scores.csv rows from ``stamp`` on: counts, and the first stamp monitored again."""
    later = [r for r in rows if r["stamp"] >= stamp]
    counts = {phase: sum(r["phase"] == phase for r in later) for phase in ("training", "relearning", "monitoring")}
    counts["back"] = next((r["stamp"] for r in later if r["phase"] == "monitoring"), "")
    return counts


def change_text(change: dict, o: dict, rows: list[dict], reason: str, truth: dict) -> str:
    """What followed a gearbox or program change on a unit (``change``: a row of changes.csv)."""
    stamp = change["stamp"]
    day = truth["stamps"].index(stamp) + 1
    phases = _after(rows, stamp)
    closed = [a for a in o["alarms"] if a["closed"]]
    later = [a for a in o["alarms"] if a["first_alarm"] >= stamp]
    after = "; alarms after it: " + (", ".join(f"{a['first_alarm']} axis {a['source_axis']}" for a in later)
                                     if later else "none")
    if change["change"] == "gearbox_change":
        before = float(truth["wear"][day - 2]) if day > 1 else 0.0
        shut = ", ".join(f"alarm from {a['first_alarm']} closed {a['closed']} by {a['closed_by']}" for a in closed)
        return (f"gearbox_change of axis {change['axis']} on {stamp} (day {day}, true wear {before:.1f} % the day "
                f"before; in events.csv): {shut or 'no alarm to close'}; offset relearned on "
                f"{phases['relearning']} logs, monitored again from {phases['back'] or '-'}" + after)
    found = "detected (units.csv: program changed at " + reason.split("program changed at ")[1].split(" ")[0] + ")" \
        if "program changed at " in reason else "NOT detected (units.csv says no program change)"
    return (f"program change on {stamp} (day {day}, not logged): {found}; learned again on {phases['training']} "
            f"logs, monitored again from {phases['back'] or '-'}" + after)


def unit_table(truth_path: Path, out: Path, outcome: dict) -> list[str]:
    """The Markdown table of each unit (module docstring)."""
    truth = independent_fleet.read_truth(truth_path)
    changes = independent_fleet.read_changes(truth_path.parent)
    with open(out / "units.csv", newline="") as f:
        status = {row["unit"]: row for row in csv.DictReader(f)}
    with open(out / "scores.csv", newline="") as f:
        scores: dict[str, list[dict]] = {}
        for r in csv.DictReader(f):
            scores.setdefault(r["unit"], []).append(r)
    lines = ["| unit | status (model) | worn axis | first alarm (day) | true wear at it | axis named | change |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for unit, o in outcome.items():
        row = status.get(unit, {})
        what = "; ".join(change_text(c, o, scores.get(unit, []), row.get("reason", ""), truth[unit])
                         for c in changes.get(unit, [])) or "-"
        alarm = f"{o['alarm']} ({o['day']})" if o["alarm"] else "-"
        wear = "-" if o["wear"] is None else f"{o['wear']:.1f} %"
        model = row.get("model") or row.get("protocol", "?")
        lines.append(f"| {unit} | {row.get('status', 'NOT IN units.csv')} ({model}) | {o['axis'] or '-'} | {alarm} "
                     f"| {wear} | {o['source'] or '-'} | {what} |")
    return lines


def digest(folder: Path, names) -> str:
    h = hashlib.sha256()
    for name in names:
        for path in sorted(folder.glob(name)):
            h.update(path.read_bytes())
    return h.hexdigest()[:16]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    fleet_options(parser, units=12, worn=8)
    parser.add_argument("--protocols", default="own,nominal,twin")
    parser.add_argument("--skip-fleet", action="store_true", help="Do not time `faultgen fleet`.")
    parser.add_argument("--repeat", action="store_true", help="Check the same seed gives identical outputs.")
    parser.add_argument("--arm", choices=sorted(independent_fleet.ARMS), default=None,
                        help="Add this arm with --payload (default: the KR210 as tests/pinocchio_log.py adds it).")
    parser.add_argument("--payload", type=float, default=None, help="`robots add --payload` with --arm, kg.")
    parser.add_argument("--max-part", type=float, default=independent_fleet.independent.MAX_PART,
                        help="The heaviest part, kg.")
    parser.add_argument("--rated-part", action="store_true",
                        help="The fleet's heaviest part drawn is made --max-part itself.")
    parser.add_argument("--wearable", default=",".join(map(str, independent_fleet.independent.WEARABLE)),
                        help="Axes that may wear, comma-separated.")
    parser.add_argument("--gearbox-changes", type=int, default=0)
    parser.add_argument("--program-changes", type=int, default=0)
    args = parser.parse_args()
    work = args.work or Path(tempfile.mkdtemp(prefix="monitor-loop-"))
    spec = independent_fleet.FleetSpec(units=args.units, worn=args.worn, days=args.days, seed=args.seed,
                                       wearable=tuple(int(a) for a in args.wearable.split(",")),
                                       max_part=args.max_part, rated_part=args.rated_part,
                                       gearbox_changes=args.gearbox_changes,
                                       program_changes=args.program_changes)
    started = time.perf_counter()
    folder = None
    if args.arm is not None:
        folder = work / args.arm
        if not (folder / "tasks.toml").is_file():
            independent_fleet.add_robot(folder, args.arm, args.payload)
    robot, logs, truth = independent_fleet.write_fleet(work / "fleet", spec, robot=folder)
    print(f"fleet of {args.units} units x {args.days} days ({args.worn} worn) of {robot.name} written by Pinocchio in "
          f"{time.perf_counter() - started:.0f} s: {logs}")
    faultgen = children.command("-m", "faultgen.cli")
    times = {}
    for name in args.protocols.split(","):
        out = work / f"monitor-{name}"
        wall, peak, _, status = run(faultgen + ["monitor", str(logs), "--robot", str(robot), "-o", str(out)]
                                    + PROTOCOLS[name])
        times[name] = wall
        s = summary(truth, out)
        delay = "n/a" if s["delay"] is None else f"{s['delay'][0]:.0f} days (range {s['delay'][1]} to {s['delay'][2]})"
        alarms, logs_ = s["false_rate"]
        print(f"\n{name}: {wall:.0f} s, peak RSS {peak / 2**20:.0f} MiB, exit status {status}")
        print(f"  worn units flagged at 10-40 % wear: {s['in_window']} of {s['worn']} (before 10 %: {s['early']}, "
              f"at >= 40 %: {s['late']}, never: {s['missed']}); delay from 10 % wear: {delay}")
        print(f"  worn axis named by the alarm: {s['isolated']} of {s['alarmed']} alarmed worn units")
        print(f"  healthy units that ever alarm: {s['healthy_alarm']} of {s['healthy']}; logs over a limit on "
              f"healthy units: {alarms} of {logs_} unit-days ({alarms / max(logs_, 1):.3f}; at most "
              f"{'2 alpha = 0.02 (T2 or Q)' if name == 'own' else 'N alpha = 0.06 (any axis wear bound)'} if "
              "independent normal)")
        with open(out / "units.csv", newline="") as f:
            status = {row["unit"]: row for row in csv.DictReader(f)}
        for unit, o in s["units"].items():
            row = status.get(unit, {})
            print(f"    {unit}: {row.get('status', '?')} ({row.get('protocol', '?')}, {row.get('model') or '-'} model), "
                  f"worn axis {o['axis'] or '-'}, alarm {o['alarm'] or '-'} (day {o['day'] or '-'}, "
                  f"wear {'-' if o['wear'] is None else round(o['wear'], 1)} %, 10 % on day {o['day10'] or '-'}), "
                  f"named axis {o['source'] or '-'}{'; ' + row['reason'][:160] if row.get('reason') else ''}")
        print("\n".join(["", *unit_table(truth, out, s["units"])]))
    if not args.skip_fleet:
        wall, peak, _, _ = run(faultgen + ["fleet", "--robots", str(args.units), "--failing", str(args.worn), "--days",
                                        str(args.days), "--cycles-per-day", "1", "--robot", str(robot), "--jobs", "1",
                                        "--no-progress", "-o", str(work / "faultgen-fleet.h5")])
        print(f"\nfaultgen fleet, {args.units} units x {args.days} days, 1 cycle a day, 1 job: {wall:.0f} s, "
              f"peak RSS {peak / 2**20:.0f} MiB")
        for name, t in times.items():
            print(f"  monitor ({name}) / fleet: {t / wall:.2f} (goal <= 1)")
    if args.repeat:
        _, logs2, _ = independent_fleet.write_fleet(work / "fleet-again", spec, robot=robot)
        same_logs = digest(logs, ["*/*.csv"]) == digest(logs2, ["*/*.csv"])
        out2 = work / "monitor-twin-again"
        run(faultgen + ["monitor", str(logs2), "--robot", str(robot), "-o", str(out2)])
        same = digest(work / "monitor-twin", ["alarms.csv", "scores.csv"]) == digest(out2, ["alarms.csv", "scores.csv"])
        print(f"\nsame seed: logs identical {same_logs}; alarms.csv and scores.csv identical {same}")


if __name__ == "__main__":
    main()
