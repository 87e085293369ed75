"""Every baseline of the prognostics track's version 3 scored on a made folder (the full size by
default), its leaderboard rows (docs/leaderboard.md) per test variant, and the lives' figures the
card states; prints each scoring's wall and CPU time.

    faultgen bench make prognostics --version 3 -o prognostics-v3-full
    python benchmarks/prognostics_v3_score.py --data prognostics-v3-full [--variants scatter-14 noscatter-none]

Issue 85: "on v3 full: the naive's relative accuracy at lambda below 0.5; the oracle's at least 0.85;
every baseline's row with its intervals in docs/leaderboard.md".
"""

from __future__ import annotations

import argparse
import datetime
import time
from pathlib import Path

from faultgen.bench import files, make, prognostics_v3, rul_v3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, required=True, help="a folder of `faultgen bench make prognostics --version 3`")
    parser.add_argument("--variants", nargs="+", default=[prognostics_v3.DEFAULT_VARIANT],
                        choices=list(prognostics_v3.VARIANTS))
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
        per_method, attrs = rul_v3.score_all(args.data, {}, variant)
        took = f"{time.perf_counter() - wall:.0f} s wall, {time.process_time() - cpu:.0f} s CPU"
        for name in rul_v3.BASELINES:
            results = {**rul_v3.results_for(name, per_method), **{k: str(v) for k, v in attrs.items()},
                       "date": datetime.date.today().isoformat()}
            command = (f"faultgen bench score prognostics --data {args.data.name} --baseline {name}"
                       + ("" if variant == prognostics_v3.DEFAULT_VARIANT else f" --variant {variant}"))
            print(rul_v3.markdown_row(results, command))
        print(f"variant {variant}: the {len(rul_v3.BASELINES)} baselines scored in {took}")


if __name__ == "__main__":
    main()
