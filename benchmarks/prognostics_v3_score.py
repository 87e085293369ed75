"""Every baseline of the prognostics track's version 3 scored on a made folder (the full size by
default), its leaderboard rows (docs/leaderboard.md) per test variant, and the lives' figures the
card states; prints each scoring's wall and CPU time.

    faultgen bench make prognostics --version 3 -o prognostics-v3-full
    python benchmarks/prognostics_v3_score.py --data prognostics-v3-full [--variants scatter-14 noscatter-none] [--twins]

``--twins`` scores beside them the twin emulated from its measured error, without friction tests and
with a test every 14 days (:mod:`faultgen.bench.twin_emulator`, the monitor's
:func:`faultgen.monitor.prognosis.remaining_life` on readings made from the true wear with the
monitor's measured error: not the monitor run on logs, which version 3 does not ship). They read the
labels and the record days only, so their figures are the same in every variant. Their "best other
baseline" is chosen among every other prognoser (the other twin too); the baselines' rows leave the
twins out of theirs, so that each is the row its own command prints.

Issue 85: "on v3 full: the naive's relative accuracy at lambda below 0.5; the oracle's at least 0.85;
every baseline's row with its intervals in docs/leaderboard.md".
"""

from __future__ import annotations

import argparse
import datetime
import time
from pathlib import Path

from faultgen.bench import files, make, prognostics_v3, rul_v3, twin_emulator
from faultgen.monitor import prognosis

#: The emulated twins' names on the leaderboard -> days between friction tests (0: none).
TWINS = {"twin (emulated from its measured error), without tests": 0,
         "twin (emulated from its measured error), with tests every 14 days": twin_emulator.TESTS_EVERY}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, required=True, help="a folder of `faultgen bench make prognostics --version 3`")
    parser.add_argument("--variants", nargs="+", default=[prognostics_v3.DEFAULT_VARIANT],
                        choices=list(prognostics_v3.VARIANTS))
    parser.add_argument("--twins", action="store_true", help="score the two emulated twins beside the baselines")
    args = parser.parse_args()
    _, made = files.read_with_attrs(args.data / "test.h5", ("track", "version", "size"))
    checked = make.compare(args.data, made)
    print(f"folder {args.data}: track {made['track']} v{made['version']} ({made['size']}), comparable "
          f"{checked['comparable']}")
    labelled = files.attach_labels(files.read(args.data / "test.h5"), args.data / "test_labels.csv")
    failing = [u for u in labelled if (u.fault_level >= rul_v3.FAILURE_WEAR).any()]
    print(f"test units {len(labelled)}: {len(failing)} run to failure, "
          f"{sum(not u.worn_axis for u in labelled)} healthy, the rest censored")
    print(rul_v3.HEADER)
    for variant in args.variants:
        wall, cpu = time.perf_counter(), time.process_time()
        twins = {name: twin_emulator.EmulatedTwin(prognosis.remaining_life, every)
                 for name, every in TWINS.items()} if args.twins else {}
        per_method, attrs = rul_v3.score_all(args.data, twins, variant)
        took = f"{time.perf_counter() - wall:.0f} s wall, {time.process_time() - cpu:.0f} s CPU"
        on = "" if variant == prognostics_v3.DEFAULT_VARIANT else f" --variant {variant}"
        for name in (*rul_v3.BASELINES, *twins):
            scored = per_method if name in twins else {k: v for k, v in per_method.items() if k not in twins}
            results = {**rul_v3.results_for(name, scored), **{k: str(v) for k, v in attrs.items()},
                       "date": datetime.date.today().isoformat()}
            command = (f"python benchmarks/prognostics_v3_score.py --data {args.data.name} --twins"
                       + (f" --variants {variant}" if on else "") if name in twins else
                       f"faultgen bench score prognostics --data {args.data.name} --baseline {name}{on}")
            print(rul_v3.markdown_row(results, command))
        print(f"variant {variant}: the {len(rul_v3.BASELINES) + len(twins)} prognosers scored in {took}")


if __name__ == "__main__":
    main()
