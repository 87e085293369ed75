"""Set-up time of a sweep: grid validation up to the first physics step of its first run.

Times, for a preset (default ``j2``), what ``faultgen sweep`` does before it steps: build and
validate the grid (``Grid.from_preset``: every run's configuration, each naming its robot), list
the runs again (as the sweep does), and prepare the first run (compile the simulation model,
the task path, the set-points at every physics step). Counts the MJCF compilations of robot files.
The baseline, measured in the same run, is the same work with the robot cache off (every
``robots.load`` compiles its file, as before the cache); the last line, ``ratio``, is the
total set-up time cached over uncached.

    python benchmarks/setup_time.py --preset j2

With ``--simulate --base OLD --new NEW`` it times instead what a default ``faultgen simulate
--cycles 2`` does before its first physics step, with each checkout first on ``PYTHONPATH`` in a
fresh interpreter, the two alternating (``--repeat`` each, medians shown): the imports up to the
command line (``import``), then from the command's call to the first ``mujoco.batch.Batch``
(``set-up``: validation, robot, task path, simulation model, set-points, output size estimate, the
batch's start state), ``step`` or ``rollout``.
The step itself is not run: the clock stops at its call. The last line, ``ratio``, is NEW's total
over OLD's::

    python benchmarks/setup_time.py --simulate --base /work/base --new .
"""

from __future__ import annotations

import argparse
import contextlib
import json
import statistics
import subprocess
import tempfile
import time
from pathlib import Path
from unittest import mock

from faultgen import children
from faultgen.model import robots
from faultgen.runs import sweep
from faultgen.simulation import stepping as sim


def set_up(preset: str) -> tuple[float, float, int]:
    """(validation s, first-run preparation s, robot compilations) of one fresh set-up."""
    compiled = 0
    compile_file = robots._from_file

    def counted(path, *rest):
        nonlocal compiled
        compiled += 1
        return compile_file(path, *rest)

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


#: Runs in a fresh interpreter: the clock starts before faultgen is imported and stops at the first
#: physics step (``mujoco.batch.Batch.step`` or ``rollout``), which raises to end the run there.
FIRST_STEP = r"""
import time
started = time.perf_counter()
import json, sys
from mujoco import batch as mjbatch
from faultgen.cli import app
imported = time.perf_counter()

class FirstStep(Exception):
    pass

def first_step(self, *args, **kwargs):
    raise FirstStep(time.perf_counter())

mjbatch.Batch.step = mjbatch.Batch.rollout = first_step  # static friction steps, LuGre rolls out
called = time.perf_counter()
try:
    app(sys.argv[1:], standalone_mode=False)
except FirstStep as reached:
    stepped = reached.args[0]
    print("TIMES " + json.dumps([imported - started, stepped - called]))
"""


def first_step_times(checkout: Path, out: Path) -> tuple[float, float]:
    """(import s, set-up s) of one default ``faultgen simulate --cycles 2`` with ``checkout``."""
    env = children.environment({"PYTHONPATH": str(checkout.resolve())})
    done = subprocess.run(children.command("-c", FIRST_STEP, "simulate", "--cycles", "2", "--no-progress",
                                           "--overwrite", "-o", str(out)), env=env, cwd=out.parent, capture_output=True,
                          text=True, check=False)
    line = [x for x in done.stdout.splitlines() if x.startswith("TIMES ")]
    if not line:
        raise RuntimeError(f"{checkout}: no first physics step reached\n{done.stdout}{done.stderr}")
    imported, set_up = json.loads(line[-1].removeprefix("TIMES "))
    return imported, set_up


def compare_simulate(base: Path, new: Path, repeat: int) -> None:
    """Print the medians of :func:`first_step_times` for ``base`` and ``new``, alternating."""
    times: dict[str, list[tuple[float, float]]] = {"base": [], "new": []}
    with tempfile.TemporaryDirectory() as folder:
        for _ in range(repeat):
            for label, checkout in (("base", base), ("new", new)):
                times[label].append(first_step_times(checkout, Path(folder) / "run.h5"))
    totals = {}
    for label, checkout in (("base", base), ("new", new)):
        imported = statistics.median(t[0] for t in times[label])
        set_up = statistics.median(t[1] for t in times[label])
        totals[label] = statistics.median(t[0] + t[1] for t in times[label])
        print(f"{label:>5} {checkout}: import {imported:.3f} s, set-up to the first physics step {set_up:.3f} s, "
              f"total {totals[label]:.3f} s (median of {repeat})")
    print(f"ratio {totals['new'] / totals['base']:.3f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--preset", default="j2", choices=list(sweep.PRESETS))
    parser.add_argument("--repeat", type=int, default=5, help="set-ups timed per variant; the median is shown")
    parser.add_argument("--simulate", action="store_true",
                        help="time a default `faultgen simulate --cycles 2` up to its first physics step instead, "
                             "--base against --new")
    parser.add_argument("--base", type=Path, help="with --simulate: the checkout before the change")
    parser.add_argument("--new", type=Path, help="with --simulate: the checkout after the change")
    args = parser.parse_args()
    if args.simulate:
        if args.base is None or args.new is None:
            parser.error("--simulate needs --base and --new")
        compare_simulate(args.base, args.new, args.repeat)
        return
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
