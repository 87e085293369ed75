"""Classification speed: `faultgen classify` against a plain scikit-learn loop and the sweep that made the data.

    python benchmarks/bench_classify.py [--dataset quick.h5] [--fleet fleet.h5] [--skip-cli]

In one run of this script:

1. ``faultgen sweep --preset quick`` writes quick.h5 (timed; skipped with --dataset), then
   ``faultgen classify quick.h5`` with its defaults (timed, as a user runs it: pairs in parallel
   on every core, the cheap chance estimate included);
2. on the same inputs and pairs, every cell of the default table three ways:
   - plain: a scikit-learn loop, each (cell, pair) its whole pipeline cloned, fitted and scored
     (:func:`analysis.classify.leave_pair_out_auc`, one process), what ``classify`` did before;
   - shared: :func:`analysis.classify.evaluate` on 1 process (each preprocessing fitted once
     per pair for all four classifiers);
   - parallel: the same on 2 processes; parallel efficiency t(1) / (2 t(2));
   and checks that the three give the same AUC in every cell (bit for bit);
3. with --fleet: stacking's inner cross-validation split by sample (scikit-learn's default,
   5 stratified folds, what ``classify`` did before) against split by run
   (:func:`analysis.classify.run_folds`), thesis protocol (--horizon 3), on the same pairs.

The machine may be shared: say so beside any figure, with ``uptime``'s load.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits


def timed(command: list[str]) -> tuple[float, float]:
    """Wall time and CPU time (user + system, the command and the workers it waited for), s."""
    import resource

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def faultgen() -> str:
    return str(Path(sys.executable).with_name("faultgen"))


def plain_loop(inputs, names, classifiers, n_pairs, seed) -> dict:
    from analysis import classify

    aucs = {}
    for name in names:
        data = inputs.X if not name.startswith(classify.ESTIMATED) else np.hstack([inputs.X, inputs.estimated])
        for column in classifiers:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", classify.UndefinedAUCWarning)
                aucs[column, name] = classify.leave_pair_out_auc(
                    classify.make_pipeline(column, name, random_state=seed), data, inputs.y, inputs.groups,
                    inputs.failed, inputs.normal, n_pairs=n_pairs, random_state=seed)
    return aucs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", type=Path, help="An existing dataset (default: make quick.h5, timed).")
    parser.add_argument("--fleet", type=Path, help="A fleet for the stacking check (step 3).")
    parser.add_argument("--pairs", type=int, default=20)
    parser.add_argument("--skip-cli", action="store_true", help="Skip step 1's timed commands.")
    parser.add_argument("--only-cli", action="store_true", help="Step 1 only.")
    args = parser.parse_args()

    from analysis import benchmark, classify

    print(f"{time.strftime('%Y-%m-%d %H:%M')} UTC, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f} "
          "(1-min average; > cores means the machine is shared)")
    folder = Path(tempfile.mkdtemp(prefix="bench-classify-"))
    try:
        path = args.dataset
        if path is None:
            path = folder / "quick.h5"
            if not args.skip_cli:
                t_sweep, cpu = timed([faultgen(), "sweep", "--preset", "quick", "-o", str(path), "--no-progress"])
                print(f"faultgen sweep --preset quick:   {t_sweep:7.1f} s wall, {cpu:7.1f} s CPU")
            else:
                subprocess.run([faultgen(), "sweep", "--preset", "quick", "-o", str(path), "--no-progress"],
                               check=True, stdout=subprocess.DEVNULL)
        if not args.skip_cli:
            t_cli, cpu = timed([faultgen(), "classify", str(path), "-o", str(folder / "cls"), "--no-progress"])
            print(f"faultgen classify (defaults):    {t_cli:7.1f} s wall, {cpu:7.1f} s CPU   "
                  f"(load now {os.getloadavg()[0]:.1f})")

        if args.only_cli:
            return
        inputs = benchmark.classification_inputs(path)
        names = [n for n in classify.PREPROCESSING if inputs.estimated is not None or not n.startswith("+estM")]
        columns = list(classify.CLASSIFIERS)
        started = time.perf_counter()
        with threadpool_limits(limits=1):  # as evaluate: one BLAS thread (tiny fits)
            plain = plain_loop(inputs, names, columns, args.pairs, 0)
        t_plain = time.perf_counter() - started
        times, tables = {}, {}
        for jobs in (1, 2):
            started = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", classify.UndefinedAUCWarning)
                tables[jobs] = classify.evaluate(inputs.X, inputs.y, inputs.groups, inputs.failed, inputs.normal,
                                                 estimated=inputs.estimated, n_pairs=args.pairs, random_state=0,
                                                 n_jobs=jobs, return_aucs=True)[1]
            times[jobs] = time.perf_counter() - started
        same = all(np.array_equal(plain[k], tables[1][k], equal_nan=True)
                   and np.array_equal(plain[k], tables[2][k], equal_nan=True) for k in plain)
        print(f"{len(names)} preprocessings x {len(columns)} classifiers x {args.pairs} pairs on {path.name}:")
        print(f"  plain scikit-learn loop, 1 process:     {t_plain:7.1f} s")
        print(f"  shared preprocessing, 1 process:        {times[1]:7.1f} s   ({t_plain / times[1]:.2f}x)")
        print(f"  shared preprocessing, 2 processes:      {times[2]:7.1f} s   ({t_plain / times[2]:.2f}x)")
        print(f"  parallel efficiency t(1) / (2 t(2)):    {times[1] / (2 * times[2]):7.2f}")
        print(f"  same AUC in every cell, all three:      {same}")

        if args.fleet is not None:
            fleet = benchmark.classification_inputs(args.fleet, horizon=3)
            by_sample = classify.stacking(0, inner_cv="sample")
            subset = ["control", "+pca", "+var3+pca", "+diff", "+diff+pca"]
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", classify.UndefinedAUCWarning)
                table = classify.evaluate(fleet.X, fleet.y, fleet.groups, fleet.failed, fleet.normal,
                                          classifiers={"by run": classify.stacking(0), "by sample": by_sample,
                                                       "lr": classify.logistic_regression(0)},
                                          preprocessing=subset, n_pairs=None, random_state=0, n_jobs=2)
            print(f"stacking's inner CV on {args.fleet.name} (--horizon 3, every pair), mean AUC (std):")
            for name in subset:
                print(f"  {name:12s} " + "  ".join(f"{c} {table.loc[name, (c, 'mean')]:.2f} "
                                                   f"({table.loc[name, (c, 'std')]:.2f})"
                                                   for c in ("by sample", "by run", "lr")))
        print(f"load at the end {os.getloadavg()[0]:.1f}")
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
