"""A real cell's logs placed among their units' programs from the motion alone
(:func:`faultgen.logs.align.place`; issue 90, items 1 and 2), scored against the fleet's truth.

    python benchmarks/align_cell.py FLEET [--robot WORK/kr210]

``FLEET``: a fleet folder written by ``benchmarks/real_cell_fleet.py`` (``FLEET/logs/<unit>/*.csv``,
``FLEET/truth_programs.csv``; the robot folder by default ``FLEET/../kr210``). Each unit's logs are
placed in date order, the programs it learns kept, as the monitor would; the truth (each log's program,
span and phase; each program's cycle length from :func:`faultgen.bench.plant.motion`) is read only to
score. Printed, each with its verdict: the logs whose program was recognised (a learned program named
for the truth program of the log it was learned from), the new programs reported against those the
truth has (a unit's first log of each of its programs), the learned periods' error, the whole cycles'
length error and whether each unit's program is always cut at one phase, the logs with no whole
cycle against those the truth says hold none (given that phase), the fragments used and dropped,
and the CPU time per log of :func:`~faultgen.logs.align.place` (recognition, alignment and, on a
program's first log, learning) against the monitor's 0.32 s a log on the one-program fleet.
Results: docs/analysis.md.
"""

from __future__ import annotations

import argparse
import csv
import time
from collections import Counter
from pathlib import Path

import numpy as np

from faultgen.bench import cell, plant
from faultgen.logs import align
from faultgen.model import robots

#: The monitor's CPU time per log on the one-program real-cell fleet, s (docs/analysis.md, "A real cell":
#: 0.32 s).
TWIN_PER_LOG = 0.32


def truth_rows(fleet: Path) -> list[dict]:
    with open(fleet / "truth_programs.csv", newline="") as f:
        return list(csv.DictReader(f))


def place_unit(fleet: Path, rows: list[dict]) -> list[tuple[dict, align.Placement, str | None, float]]:
    """Each of a unit's logs (its truth rows in date order) placed: (row, placement, the program name
    it was given, CPU s)."""
    known, out = [], []
    for row in rows:
        data = np.loadtxt(fleet / "logs" / row["unit"] / f"{row['stamp']}.csv", delimiter=",", skiprows=1,
                          usecols=range(7))
        started = time.process_time()
        placed = align.place(data[:, 0], data[:, 1:], known)
        cpu = time.process_time() - started
        if placed.learned is not None:
            known.append(placed.learned)
        name = placed.learned.name if placed.learned else placed.recognition.program
        out.append((row, placed, name, cpu))
    return out


def score(placed, lengths: list[int], rate: float) -> list[str]:
    """The verdict lines (module docstring) of every unit's placed logs."""
    right = new_ok = period_err = 0.0
    new_reported, new_truth, length_err, phase_spread, holds, refused_ok, refused = [], [], 0, 0, 0, 0, 0
    uses, cpu, n = Counter(), [], 0
    for unit_logs in placed.values():
        truth_of, seen, phase = {}, set(), {}
        for row, p, name, seconds in unit_logs:
            program, n = int(row["program"]), n + 1
            cpu.append(seconds)
            if p.learned is not None:
                truth_of[p.learned.name] = program
                period_err = max(period_err, abs(p.learned.period - lengths[program] / rate))
            right += name is not None and truth_of.get(name) == program
            (new_truth if program not in seen else []).append((row["unit"], row["stamp"]))
            if p.recognition.status is align.Status.NEW:
                new_reported.append((row["unit"], row["stamp"]))
            seen.add(program)
            if p.cycles is None:
                continue
            first = int(float(row["phase"]) * lengths[program])
            for a, b in p.cycles.spans:
                length_err = max(length_err, abs(b - a - lengths[program]))
                at = (first + a) % lengths[program]
                phase.setdefault(program, at)
                phase_spread = max(phase_spread, abs(at - phase[program]))
            uses.update(f.use.value for f in (p.cycles.lead, p.cycles.trail) if f is not None)
        for row, p, _, _ in unit_logs:
            program = int(row["program"])
            length, first = lengths[program], int(float(row["phase"]) * lengths[program])
            n_samples = round(float(row["span_cycles"]) * length)
            expected = program in phase and (phase[program] - first) % length + length <= n_samples
            holds += expected
            refused += p.cycles is None
            refused_ok += (p.cycles is None) and not expected
    verdict = lambda ok: "PASS" if ok else "FAIL"  # noqa: E731
    per = np.array(cpu)
    return [
        f"programs recognised on {int(right)} of {n} logs: {verdict(right == n)}",
        f"new programs reported on {len(new_reported)} logs, the truth's first logs of a program {len(new_truth)}: "
        f"{verdict(new_reported == new_truth)}",
        f"learned periods within {period_err * 1e3:.2f} ms of the truth (one sample {1e3 / rate:.1f} ms): "
        f"{verdict(period_err <= 0.5 / rate)}",
        f"whole cycles' length within {length_err} sample(s) of the cycle, each unit's program cut at one phase "
        f"within {phase_spread} sample(s): {verdict(length_err <= 1 and phase_spread <= 1)}",
        f"logs with no whole cycle {refused} (the truth: {n - holds}), refused where the truth holds none "
        f"{refused_ok}: {verdict(refused == refused_ok == n - holds)}",
        "fragments: " + ", ".join(f"{k} {v}" for k, v in sorted(uses.items())),
        f"CPU per log: median {np.median(per) * 1e3:.1f} ms, 95 % {np.percentile(per, 95) * 1e3:.1f} ms, "
        f"max {per.max() * 1e3:.1f} ms; {TWIN_PER_LOG / np.median(per):.0f}x under the monitor's {TWIN_PER_LOG} s a log: "
        f"{verdict(per.max() < TWIN_PER_LOG / 10)}",
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("fleet", type=Path)
    parser.add_argument("--robot", type=Path, default=None)
    args = parser.parse_args()
    model = robots.load(args.robot or args.fleet.parent / "kr210")
    rows = truth_rows(args.fleet)
    first = np.loadtxt(args.fleet / "logs" / rows[0]["unit"] / f"{rows[0]['stamp']}.csv", delimiter=",",
                       skiprows=1, usecols=0)
    rate = float(round(1.0 / np.median(np.diff(first)), 6))
    lengths = [len(plant.motion(model, rate, False, s)[1]) for s in cell.VARIANT_SHRINK]
    by_unit: dict[str, list[dict]] = {}
    for row in rows:
        by_unit.setdefault(row["unit"], []).append(row)
    started = time.perf_counter()
    placed = {unit: place_unit(args.fleet, unit_rows) for unit, unit_rows in sorted(by_unit.items())}
    print(f"{args.fleet}: {len(rows)} logs of {len(by_unit)} units at {rate:g} Hz placed in "
          f"{time.perf_counter() - started:.0f} s wall (reading included)")
    for line in score(placed, lengths, rate):
        print("  " + line)


if __name__ == "__main__":
    main()
