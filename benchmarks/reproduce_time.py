"""The time of `faultgen reproduce`, each table against the sweep that makes its data, in one run.

Runs the reproduction (the full scale: about 30 min on 2 idle cores; --quick: the tiny scale, a
check of this script in a minute or two) and prints, per table of docs/reproduction.md, the
seconds of the steps that made its dataset(s) and of its analyses, the analyses' share, and the
wall time against the sum of every step's time (what running steps side by side saved). Last
line: ``ratio <wall / sum of step times>``.

    python benchmarks/reproduce_time.py -o repro            # the full run
    python benchmarks/reproduce_time.py --quick -o repro-q  # the tiny scale
    python benchmarks/reproduce_time.py --from repro        # the times of an earlier run's folder

A step kept from an earlier run (its outputs there) counts 0 s: time a fresh folder.
"""

from __future__ import annotations

import argparse
import os
import re
import time
from pathlib import Path

import pandas as pd

from faultgen import reproduce
from faultgen.reproduce import tables


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--out", type=Path, default=Path("repro"), help="output folder of the reproduction")
    parser.add_argument("--quick", action="store_true", help="the tiny scale (a check of the script)")
    parser.add_argument("--from", dest="source", type=Path, help="report an earlier run's folder; run nothing")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    folder = args.source or args.out
    if args.source is None:
        started = time.perf_counter()
        reproduce.run(folder, scale="tiny" if args.quick else "full", jobs=args.jobs, progress=print)
        wall = time.perf_counter() - started
    else:
        found = re.search(r"Wall time ([0-9.]+) min", (folder / "summary.md").read_text())
        wall = float(found.group(1)) * 60
    times = pd.read_csv(folder / "times.csv").set_index("step")
    print(f"load average at the end: {' '.join(f'{x:.1f}' for x in os.getloadavg())} on {os.cpu_count()} cores")
    rows = []
    for part in tables.parts(folder):
        used = times.reindex([s for s in part.steps if s in times.index])
        data = used.loc[used["makes_data"], "seconds"].sum()
        analysis = used.loc[~used["makes_data"], "seconds"].sum()
        rows.append({"table": part.title, "thesis": part.thesis_tables, "data (s)": round(data),
                     "analyses (s)": round(analysis),
                     "analyses / data": f"{analysis / data:.3f}" if data else "-"})
    print(pd.DataFrame(rows).to_markdown(index=False))
    kinds = times.groupby("makes_data")["seconds"].sum()
    total = times["seconds"].sum()
    print(f"steps: data {kinds.get(True, 0):.0f} s, analyses {kinds.get(False, 0):.0f} s, sum {total:.0f} s; "
          f"wall {wall:.0f} s ({wall / 60:.1f} min)")
    print(f"ratio {wall / total:.3f}" if total else "ratio nan")


if __name__ == "__main__":
    main()
