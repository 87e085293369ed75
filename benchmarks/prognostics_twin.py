"""The twin's remaining useful life (`faultgen monitor`, faultgen.monitor.prognosis) on the
prognostics track's test fleet, scored as `faultgen bench score prognostics` scores a prognoser.

    python benchmarks/prognostics_twin.py --data prognostics-full [--size full] [--work DIR]
    python benchmarks/prognostics_twin.py --data prognostics-v2-full --version 2 [--without-tests]

The twin reads a fleet's raw logs, which a track's ``test.h5`` (features) no longer holds, so this
script writes the track version's test fleet again with its recipe (the independent simulator,
faultgen/bench/independent.py, the same spec and seed as the track's ``fleet`` part; the robot added
with the version's sizing rule), runs ``faultgen monitor LOGS --no-calibrate --failure-wear 40`` on
it, and replays the monitor's remaining life (:func:`faultgen.monitor.prognosis.remaining_life`) on
each unit's rows up to every day from the wear's onset to the day before its end of life: from the
day the unit's alarm became persistent, the distribution of the time until the alarm's source axis
reaches 40 % *estimated* wear (the twin's scale); before it, or for another axis, no prediction (every
sample beyond the horizon). The source axis is the one ``alarms.csv`` names at the end of the run.
The end of life and onset are the fleet's ``truth.csv`` (the same as the track's test labels); the
naive prognoser (the train split's lives, from ``--data``'s ``train.h5``) is scored on the same
days. Metrics, intervals and verdict: :mod:`faultgen.bench.prognostics`. Prints the leaderboard row.
Not in the track's numeric profile: the fleet's last bits may differ from the track's test split.

Version 2 (friction tests every 14 days, docs/bench/prognostics.md): the fleet is written with its
tests (``LOGS/<unit>/friction-test/``), which the monitor reads (faultgen.monitor.friction_tests):
the twin **with tests**. Its replay on a day fits the unit's rows up to that day as the monitor's
``rul.csv`` would have that day (:func:`faultgen.monitor.friction_tests.on_tests_scale`): every log's
twin-scale estimate times the factor of the tests up to that day, that factor's error as the
scale's uncertainty (not ``scores.csv``'s wear, each log on its own day's factor, with the default
uncertainty); those columns are not in ``scores.csv``, so the rows are the monitor's own, reloaded by
running it again on its OUT (no new log: its state replayed). ``--without-tests`` moves
the test folders out of LOGS first (to ``WORK/tests-apart``): the production-log twin on the same
fleet.
"""

from __future__ import annotations

import argparse
import csv
import datetime
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from faultgen import children
from faultgen.bench import files, independent, make, prognosers, prognostics, tracks
from faultgen.model import robots
from faultgen.monitor import friction_tests, loop, prognosis, tables
from faultgen.monitor.run import resolve_run

#: The monitor's defaults the replay uses (faultgen.monitor.scoring.Settings).
MONITOR_ALPHA, PERSISTENCE = 0.01, 5


def _failure_days(unit: str, seen: list[dict], n_axes: int, failure: float, first: str, axis: int) -> np.ndarray:
    """The days (from the first log, 1-based) at which the twin's remaining life on the unit's rows
    ``seen`` (its logs up to now) puts ``axis``'s wear at ``failure`` %: as the monitor's ``rul.csv``
    would have that day (on the factor of the tests up to now,
    :func:`faultgen.monitor.friction_tests.on_tests_scale`); inf beyond the horizon or with no fit."""
    seen, uncertainty = friction_tests.on_tests_scale(seen, n_axes)
    (row,) = prognosis.remaining_life(unit, seen, n_axes, alpha=MONITOR_ALPHA, failure_wear=failure, since=first,
                                      source_axis=axis, axes=[axis],
                                      **({} if uncertainty is None else {"scale_uncertainty": uncertainty}))
    if row.distribution is None:
        return np.array([np.inf])
    return np.array([np.inf if v is None else len(seen) + float(v) for v in row.distribution.key("failure")])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, required=True, help="The track's folder of `faultgen bench make`.")
    parser.add_argument("--size", default="full", choices=tracks.SIZES)
    parser.add_argument("--work", type=Path, default=None)
    parser.add_argument("--version", type=int, default=1, help="The track version (2: with friction tests).")
    parser.add_argument("--without-tests", action="store_true",
                        help="Version 2: monitor the production logs only (the test folders moved out of LOGS).")
    args = parser.parse_args()
    work = args.work or Path(tempfile.mkdtemp(prefix="prognostics-twin-"))
    recipe = tracks.load("prognostics").version(args.version)
    failure = prognostics.FAILURE_WEAR[args.version]
    started = time.perf_counter()
    robot = make.add_robots(recipe, work / "robots")["kr210"]
    (_, fleet), = recipe.fleets("test", args.size)
    spec = independent.FleetSpec(**{k: tuple(v) if isinstance(v, list) else v for k, v in fleet["spec"].items()})
    logs, truth_path = independent.write_fleet(work / "fleet", spec, robot)
    n_axes = robots.load(robot).n_axes
    print(f"fleet {spec} written in {time.perf_counter() - started:.0f} s")
    tested = sorted(logs.glob(f"*/{independent.TEST_FOLDER}"))
    if args.without_tests:  # the production-log twin: the tests out of the monitor's sight
        for folder in tested:
            (work / "tests-apart").mkdir(exist_ok=True)
            folder.rename(work / "tests-apart" / folder.parent.name)
    print(f"friction tests given to the monitor: {0 if args.without_tests else len(tested)} units' folders")
    out = work / "monitor"
    command = [*children.command("-m", "faultgen.cli"), "monitor", str(logs), "--robot", str(robot), "-o", str(out),
               "--no-calibrate", "--failure-wear", f"{failure:g}"]
    started = time.perf_counter()
    done = subprocess.run(command, env=children.environment(), check=False, capture_output=True, text=True)
    if done.returncode not in (0, 3):  # 3: some unit degraded or not monitored, every output written
        raise SystemExit(f"{' '.join(command)} failed ({done.returncode}):\n{done.stderr[-3000:]}")
    print(f"faultgen monitor --no-calibrate --failure-wear {failure:g}: {time.perf_counter() - started:.0f} s")
    truth = independent.read_truth(truth_path)
    with open(out / "scores.csv", newline="") as f:
        scores = tables.log_rows(list(csv.DictReader(f)))
    if tested and not args.without_tests:  # the rows' twin-scale wear and factors, which scores.csv leaves out
        started = time.perf_counter()
        kept = loop.monitor(resolve_run(robot, logs, out, calibrate=False, failure_wear=failure,
                                        progress=False)).units
        scores = [row for m in kept for row in m.rows]
        print(f"the monitor's rows reloaded from OUT's state (no new log): {time.perf_counter() - started:.0f} s")
    with open(out / "alarms.csv", newline="") as f:
        alarms = {r["unit"]: r for r in csv.DictReader(f)}
    naive = prognosers.MeanLife().fit(files.read(args.data / "train.h5"), failure)
    twin_rows, naive_rows = [], []
    started = time.perf_counter()
    for unit, t in truth.items():
        days = np.arange(1, len(t["stamps"]) + 1, dtype=float)
        eol = float(days[np.flatnonzero(t["wear"] >= failure)[0]])
        onset = float(days[np.flatnonzero(t["wear"] > 0)[0]])
        rows = [r for r in scores if r.unit == unit]
        day = {r.stamp: i + 1 for i, r in enumerate(rows)}
        alarm = alarms.get(unit, {})
        first, axis = alarm.get("first_alarm") or None, int(alarm.get("source_axis") or 0)
        persistent = (day[first] + PERSISTENCE - 1) if first in day else np.inf
        twin, mean_life = {}, {}
        for now in days[(days >= onset) & (days < eol)]:
            record = files.Unit(id=unit, robot="kr210", task="pick_place", sample="log",
                                arrays={"cycles": days[: int(now)]})
            mean_life[now] = naive.predict(record)
            twin[now] = _failure_days(unit, rows[: int(now)], n_axes, failure, first, axis) if (
                axis and now >= persistent) else np.array([np.inf])
        extra = {"unit": unit, "worn_axis": t["axis"], "alarm_axis": axis, "alarm_persistent_day": persistent}
        twin_rows.append({**extra, **prognostics.unit_metrics(twin, eol, onset)})
        naive_rows.append({**extra, **prognostics.unit_metrics(mean_life, eol, onset)})
    print(f"{sum(len(r) for r in twin_rows)} unit rows replayed in {time.perf_counter() - started:.0f} s")
    words, diff = prognostics.verdict(twin_rows, naive_rows)
    method = "twin (faultgen monitor)" if not tested else (
        "twin, production logs only (faultgen monitor)" if args.without_tests else "twin with friction tests (faultgen monitor)")
    results = {"method": method, "track": "prognostics", "version": str(args.version), "size": args.size,
               "date": datetime.date.today().isoformat(), "results": prognostics.summary(twin_rows),
               "naive": prognostics.summary(naive_rows), "verdict": words}
    for row in twin_rows:
        print({k: row[k] for k in ("unit", "worn_axis", "alarm_axis", "alarm_persistent_day", "eol", "alpha_lambda",
                                   "ra_lambda", "ph")})
    print(f"verdict: {words}; relative accuracy at lambda minus the naive's: {diff['value']:.2f} "
          f"[{diff['ci95'][0]:.2f}, {diff['ci95'][1]:.2f}]")
    print(prognostics.header(args.version))
    print(prognostics.markdown_row(results, "python benchmarks/prognostics_twin.py " + " ".join(sys.argv[1:])))


if __name__ == "__main__":
    main()
