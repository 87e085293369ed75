"""`faultgen monitor`'s twin as a detector and isolator on the sim-to-real or conditions track, scored by
`faultgen bench score`'s own code (faultgen.bench.score) beside the baselines (issue 59, part 4).

    python benchmarks/twin_baseline.py --track sim-to-real --data bench-v2/sim-to-real [--work DIR]
    python benchmarks/twin_baseline.py --track conditions --data bench-v2/conditions [--no-calibrate]

DATA is the track's folder of `faultgen bench make` (its version and size are read from test.h5). The
twin reads raw logs, which test.h5 (features) does not hold, so the script

1. writes the test split again from the track version's recipe and seeds as raw logs
   (faultgen.bench.rawlogs: the sim-to-real track's fleet by the independent simulator; the conditions
   track's runs simulated again with their signals, each program's cycles a monitor unit of their own)
   and ties each regenerated unit to its test unit by its features (never by the labels);
2. runs `faultgen monitor LOGS --robot ROBOT -o WORK/monitor-trainN[-nominal] --train N` (calibrated twins
   by default, `--no-calibrate` the nominal model; N 28 at full size, 10 at small); a rerun with the same
   WORK reads the logs the first wrote (WORK/records.json);
3. reads each test unit's answers from the monitor's scores.csv and alarms.csv (faultgen.bench.twin:
   score per record the largest lower bound of the wear estimates, alarm per record the log's alarm,
   the axis its first persistent alarm names) and scores them with faultgen.bench.score.score, the
   function `faultgen bench score` calls, through the detector and isolator contracts
   (faultgen.bench.recorded). The twin learns nothing from train.h5: it learns each unit's first N logs.

Writes OUT-detector.json/.md and OUT-isolator.json/.md (default OUT: DATA/score-twin) and prints the two
leaderboard rows, the time of each step and each test unit's answer. Not in the track's numeric
profile: the regenerated data may differ from the track's in the last bits (the tie allows 1e-6).
"""

from __future__ import annotations

import argparse
import collections
import csv
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from faultgen import children
from faultgen.bench import files, rawlogs, recorded, score, twin

NAME = "twin (faultgen monitor)"
TRAIN = {"full": 28, "small": 10}


def monitor(written: rawlogs.Written, out: Path, train: int, calibrate: bool, jobs: int) -> list[str]:
    """Run `faultgen monitor` on the written logs; returns the command (SystemExit when it fails)."""
    command = [*children.command("-m", "faultgen.cli"), "monitor", str(written.logs), "--robot", written.robot,
               "-o", str(out), "--train", str(train), "--jobs", str(jobs), "--no-progress"]
    if not calibrate:
        command.append("--no-calibrate")
    done = subprocess.run(command, env=children.environment(), check=False, capture_output=True, text=True)
    if done.returncode not in (0, 3):  # 3: some unit degraded or not monitored, every output written
        raise SystemExit(f"{' '.join(command)} failed ({done.returncode}):\n{done.stderr[-3000:]}")
    return command


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--track", required=True, choices=("sim-to-real", "conditions"))
    parser.add_argument("--data", type=Path, required=True, help="The track's folder of `faultgen bench make`.")
    parser.add_argument("--work", type=Path, default=None, help="Folder for the logs and the monitor's output "
                        "(default: a new temporary folder).")
    parser.add_argument("--train", type=int, default=None, help="Logs each unit's monitor learns from (default 28, "
                        "10 at small size).")
    parser.add_argument("--no-calibrate", action="store_true", help="The twin on the nominal model.")
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--allow-modified", action="store_true", help="Score a folder that differs from the track's "
                        "frozen manifest anyway, marked not comparable (`faultgen bench score --allow-modified`).")
    parser.add_argument("-o", "--out", type=Path, default=None)
    args = parser.parse_args()
    command_line = "python benchmarks/twin_baseline.py " + " ".join(sys.argv[1:])
    test, made = files.read_with_attrs(args.data / "test.h5", ("track", "version", "size"))
    if made["track"] != args.track:
        raise SystemExit(f"{args.data} holds track {made['track']!r}, not {args.track!r}")
    size, version = str(made["size"]), int(made["version"])
    work = args.work or Path(tempfile.mkdtemp(prefix=f"twin-{args.track}-"))
    work.mkdir(parents=True, exist_ok=True)
    train = args.train or TRAIN[size]
    started = time.perf_counter()
    kept = work / "records.json"
    if kept.is_file():  # the logs an earlier run wrote into WORK (for another --train or --no-calibrate)
        held = json.loads(kept.read_text())
        written = rawlogs.Written(work / held["logs"], held["robot"], {
            uid: {name: np.array(rows, dtype=int) for name, rows in units.items()} for uid, units in held["records"].items()})
    else:
        written = rawlogs.write(args.track, version, size, test, work)
        kept.write_text(json.dumps({"logs": str(written.logs.relative_to(work)), "robot": written.robot, "records": {
            uid: {name: rows.tolist() for name, rows in units.items()} for uid, units in written.records.items()}}))
    n_logs = sum(len(r) for units in written.records.values() for r in units.values())
    print(f"{args.track} v{version} ({size}): {len(test)} test units, {n_logs} logs in "
          f"{sum(len(u) for u in written.records.values())} monitor units written in {time.perf_counter() - started:.0f} s")
    started = time.perf_counter()
    out = work / f"monitor-train{train}{'-nominal' if args.no_calibrate else ''}"
    command = monitor(written, out, train, not args.no_calibrate, args.jobs)
    print(f"{' '.join(command[2:])}: {time.perf_counter() - started:.0f} s")
    with open(out / "units.csv", newline="") as f:
        statuses = collections.Counter(r["status"] + " (" + r["model"] + ")" for r in csv.DictReader(f))
    print("monitor units: " + ", ".join(f"{n} {s}" for s, n in sorted(statuses.items())))
    scores, alarms, named, answered = twin.answers(out, written,
                                                   {u.id: len(u.arrays["cycles"]) for u in test})
    silent = sum(int((~a).sum()) for a in answered.values())
    if silent:
        print(f"warning: the monitor gave no row for {silent} of {sum(len(a) for a in answered.values())} records "
              f"(a unit still learning its {train} logs when its logs ended): scored below every answer, no alarm; "
              "the track is too short for the twin there")
    name = NAME + (", nominal model" if args.no_calibrate else "") + (
        f", {train} learning logs" if train != TRAIN[size] else "")
    stem = args.out or args.data / "score-twin"
    rows = []
    for role, method in (("detector", recorded.RecordedDetector(recorded.detector_answers(test, scores, alarms))),
                         ("isolator", recorded.RecordedIsolator(recorded.isolator_answers(test, named)))):
        results = score.score(args.data, method, name, role, track=args.track, allow_modified=args.allow_modified)
        json_path, _ = score.write(results, stem.with_name(f"{stem.name}-{role}"), command_line)
        rows.append(score.markdown_row(results, command_line))
        print(f"wrote {json_path}")
        if role == "isolator":
            for answer in results["results"]["per_unit"]:
                print(f"  {answer['unit']}: worn axis {answer['worn_axis']}, named {answer['named']}")
        else:
            for unit in results["results"]["per_unit"]:
                print(f"  {unit['unit']}: detected {unit['detected']}, after 10 % {unit['after_10pct']}")
    print(score.HEADER)
    print(score.SEPARATOR)
    print("\n".join(rows))


if __name__ == "__main__":
    main()
