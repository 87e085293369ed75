"""How long ``faultgen --help`` and ``faultgen --version`` take, against ``python -c pass``, in one run.

    python benchmarks/cli_start.py [--repeat 15] [--before DIR]

Each command is started ``--repeat`` times as a fresh process (interleaved, so that a change in
the machine's load reaches every command alike); the median wall time of each is printed, and
its excess over ``python -c pass`` (the interpreter's own start: the floor of any Python
command), and the median CPU time (user + system) of each, which a loaded machine inflates less.
The aim (issue 87): at most 0.3 s above ``python -c pass`` on 2 idle cores. For comparison:
``import faultgen.cli`` and every command module (what ``faultgen --help`` imported when the
commands were not looked up lazily), and with ``--before DIR`` (a source tree of an earlier
faultgen, e.g. ``git archive 1ab5ff8 faultgen | tar -x -C DIR``) that tree's ``faultgen --help``.

``faultgen`` is ``python -m faultgen.cli`` with this interpreter (the console script's start adds
nothing to it but its own few lines). The last line is ``excess <seconds>``: the larger of the
two commands' excesses over ``python -c pass``, with its verdict.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import time

from faultgen import children
from faultgen.cli.table import MODULES

#: The aim: seconds above the interpreter's own start.
AIM = 0.3

COMMANDS = {
    "python -c pass": ["-c", "pass"],
    "faultgen --help": ["-m", "faultgen.cli", "--help"],
    "faultgen --version": ["-m", "faultgen.cli", "--version"],
    "every command module imported": ["-c", "import faultgen.cli; "
                                      + "; ".join(f"import faultgen.cli.{m}" for m in MODULES)],
}


def started(args: list[str], path: str | None = None) -> tuple[float, float]:
    """(wall s, CPU s) of one fresh ``python -P ARGS`` (its output checked), with ``path`` first
    on its ``PYTHONPATH`` when given."""
    env = children.environment()
    if path:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [path, env.get("PYTHONPATH")]))
    cpu = os.times()
    began = time.perf_counter()
    done = subprocess.run(children.command(*args), capture_output=True, env=env)
    took = time.perf_counter() - began
    after = os.times()
    if done.returncode != 0:
        raise SystemExit(f"{args} failed ({done.returncode}): {done.stderr.decode()[-500:]}")
    return took, (after.children_user - cpu.children_user) + (after.children_system - cpu.children_system)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--before", help="a source tree of an earlier faultgen: its faultgen --help timed too")
    args = parser.parse_args()
    commands = {name: (command, None) for name, command in COMMANDS.items()}
    if args.before:
        commands[f"faultgen --help of {args.before}"] = (COMMANDS["faultgen --help"], args.before)
    times: dict[str, list[tuple[float, float]]] = {name: [] for name in commands}
    for command, path in commands.values():  # once each first: the files in the page cache
        started(command, path)
    for _ in range(args.repeat):
        for name, (command, path) in commands.items():
            times[name].append(started(command, path))
    wall = {name: statistics.median(t for t, _ in runs) for name, runs in times.items()}
    cpu = {name: statistics.median(c for _, c in runs) for name, runs in times.items()}
    base = wall["python -c pass"]
    print(f"{children.command()[0]}, {args.repeat} starts each (interleaved), medians; load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    for name in times:
        print(f"{name:<40} wall {wall[name]:6.3f} s (+{wall[name] - base:.3f} s over python -c pass)   "
              f"CPU {cpu[name]:6.3f} s (+{cpu[name] - cpu['python -c pass']:.3f} s)")
    excess = max(wall[n] - base for n in ("faultgen --help", "faultgen --version"))
    print(f"excess {excess:.3f}  ({'within' if excess <= AIM else 'above'} the aim of {AIM} s over python -c pass)")


if __name__ == "__main__":
    main()
