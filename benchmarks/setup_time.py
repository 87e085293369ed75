"""Set-up time of a sweep: grid validation up to the first physics step of its first run.

Times, for a preset (default ``j2``), what ``faultgen sweep`` does before it steps: build and
validate the grid (``Grid.from_preset``: every run's configuration, each naming its robot), list
the runs again (as the sweep does), and prepare the first run (compile the simulation model,
the task path, the set-points at every physics step). Counts the MJCF compilations of robot files.
The baseline, measured in the same run, is the same work with the robot cache off (every
``robots.load`` compiles its file, as before the cache); the last line, ``ratio``, is the
total set-up time cached over uncached.

    python benchmarks/setup_time.py --preset j2
"""

from __future__ import annotations

import argparse
import contextlib
import time
from unittest import mock

from faultgen.model import robots
from faultgen.runs import sweep
from faultgen.simulation import stepping as sim


def set_up(preset: str) -> tuple[float, float, int]:
    """(validation s, first-run preparation s, robot compilations) of one fresh set-up."""
    compiled = 0
    compile_file = robots._from_file

    def counted(path):
        nonlocal compiled
        compiled += 1
        return compile_file(path)

    sim._prepare.cache_clear()
    clear = getattr(getattr(robots, "_cached", None), "cache_clear", None)
    if clear:
        clear()
    with mock.patch.object(robots, "_from_file", counted):
        started = time.perf_counter()
        grid = sweep.Grid.from_preset(preset)
        runs = grid.runs()
        validated = time.perf_counter()
        _, config = runs[0]
        sim._prepared(config.robot, config.task, config.friction)
        prepared = time.perf_counter()
    return validated - started, prepared - validated, compiled


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--preset", default="j2", choices=list(sweep.PRESETS))
    parser.add_argument("--repeat", type=int, default=5, help="set-ups timed per variant; the median is shown")
    args = parser.parse_args()
    n_runs = len(sweep.Grid.from_preset(args.preset).runs())
    results = {}
    cached = getattr(robots, "_cached", None)  # absent in versions without the cache
    variants = {"uncached (baseline)": cached.__wrapped__, "cached": cached} if cached else {"no cache": None}
    for label, loader in variants.items():
        with mock.patch.object(robots, "_cached", loader) if loader else contextlib.nullcontext():
            times = sorted((set_up(args.preset) for _ in range(args.repeat)), key=lambda r: r[0] + r[1])
        results[label] = times[len(times) // 2]
        valid, first, compiled = results[label]
        print(f"{label:>20}: validation {valid:.3f} s, first run prepared {first:.3f} s, total {valid + first:.3f} s, "
              f"{compiled} robot compilations ({args.preset}: {n_runs} runs)")
    if len(results) == 2:
        (base_valid, base_first, _), (valid, first, _) = results.values()
        print(f"cached / uncached: validation {valid / base_valid:.2f}, total "
              f"{(valid + first) / (base_valid + base_first):.2f}")
        print(f"ratio {(valid + first) / (base_valid + base_first):.3f}")


if __name__ == "__main__":
    main()
