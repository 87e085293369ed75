"""Classification speed: `faultgen classify` against a plain scikit-learn loop and the sweep that made the data.

    python benchmarks/bench_classify.py [--dataset quick.h5] [--full] [--fleet fleet.h5 [--make-fleet]] [--steps 1,2,3,4]

In one run of this script:

1. ``faultgen sweep --preset quick`` writes quick.h5 (timed; skipped with --dataset), then
   ``faultgen classify quick.h5`` with its defaults (timed, as a user runs it: the seven rows of
   ``analysis.classify.SHORT_TABLE``, pairs in parallel on every core, the cheap chance estimate
   included) and ``classify --full`` (every row); the ratios classify / sweep, wall and CPU;
2. on the same inputs and pairs, every cell of the default table (of every row with --full)
   three ways:
   - plain: a scikit-learn loop, each (cell, pair) its whole pipeline cloned, fitted and scored
     (:func:`analysis.classify.leave_pair_out_auc`, one process), what ``classify`` did before;
   - shared: :func:`analysis.classify.evaluate` on 1 process (each preprocessing fitted once
     per pair for all four classifiers);
   - parallel: the same on 2 processes; parallel efficiency t(1) / (2 t(2));
   and checks that the three give the same AUC in every cell (bit for bit);
3. with --fleet: stacking's inner cross-validation split by sample (scikit-learn's default,
   5 stratified folds, what ``classify`` did before) against split by run
   (:func:`analysis.classify.run_folds`), thesis protocol (--horizon 3), on the same pairs;
4. with --fleet: the thesis protocol ``faultgen classify FLEET --horizon 3 --pairs 0``, default
   rows and --full, timed; with --make-fleet FLEET is first made by ``faultgen fleet`` (timed,
   about 12 min on two idle cores) and the ratios printed.

Wall times on a shared machine are upper bounds; ratios of commands timed in one run hold
better, and CPU time (user + system, workers included) best. The script prints ``uptime``'s load.
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from faultgen import children


def timed(command: list[str]) -> tuple[float, float]:
    """Wall time and CPU time (user + system, the command and the workers it waited for), s."""
    import resource

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    subprocess.run(command, env=children.environment(), check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def faultgen() -> list[str]:
    """The faultgen command line, started without the current folder on its path (faultgen.children)."""
    return children.command("-m", "faultgen.cli")


def ratio_line(what: str, t: tuple[float, float], reference: tuple[float, float], name: str) -> str:
    return (f"{what}: {t[0] / reference[0]:.2f} of {name}'s wall time, {t[1] / reference[1]:.2f} of its CPU time "
            f"({'faster' if t[0] < reference[0] else 'SLOWER'})")


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
    parser.add_argument("--full", action="store_true", help="Step 2 on every row (default: classify's seven).")
    parser.add_argument("--fleet", type=Path, help="A fleet for steps 3 and 4.")
    parser.add_argument("--make-fleet", action="store_true", help="Make --fleet first with `faultgen fleet`, timed.")
    parser.add_argument("--pairs", type=int, default=20, help="Held-out pairs of step 2 (classify's default, 20).")
    parser.add_argument("--steps", default="1,2,3,4", help="Steps to run (3 and 4 need --fleet); default all.")
    args = parser.parse_args()
    steps = {int(k) for k in args.steps.split(",")}

    print(f"{time.strftime('%Y-%m-%d %H:%M')} UTC, {os.cpu_count()} cores, {load()} "
          "(1-min average; > cores means the machine is shared)")
    folder = Path(tempfile.mkdtemp(prefix="bench-classify-"))
    try:
        path = args.dataset
        sweep = None
        if path is None and steps & {1, 2}:
            path = folder / "quick.h5"
            command = [*faultgen(), "sweep", "--preset", "quick", "-o", str(path), "--no-progress"]
            if 1 in steps:
                sweep = timed(command)
                print(f"faultgen sweep --preset quick:   {sweep[0]:7.1f} s wall, {sweep[1]:7.1f} s CPU   ({load()})")
            else:
                subprocess.run(command, env=children.environment(), check=True, stdout=subprocess.DEVNULL)
        if 1 in steps:
            for flag in ([], ["--full"]):
                t = timed([*faultgen(), "classify", str(path), *flag, "-o", str(folder / "cls"), "--no-progress",
                           "--overwrite"])
                what = f"faultgen classify {' '.join(flag) or '(defaults)'}"
                print(f"{what:33s} {t[0]:7.1f} s wall, {t[1]:7.1f} s CPU   ({load()})")
                if sweep is not None:
                    print("  " + ratio_line(what, t, sweep, "the sweep"))
        if 2 in steps:
            shared_preprocessing(path, args.full, args.pairs)
        if args.fleet is not None:
            fleet_steps(args.fleet, args.make_fleet, steps, folder)
        print(f"at the end: {load()}")
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def load() -> str:
    """The machine's 1-minute load average, in words."""
    return f"load {os.getloadavg()[0]:.1f}"


def shared_preprocessing(path: Path, full: bool, pairs: int) -> None:
    """Step 2: the table by a plain scikit-learn loop and by classify.evaluate (shared preprocessing) on 1
    and 2 processes, timed, and whether all three give the same AUC in every cell."""
    from analysis import benchmark, classify

    inputs = benchmark.classification_inputs(path)
    rows = classify.PREPROCESSING if full else classify.SHORT_TABLE
    names = [n for n in rows if inputs.estimated is not None or not n.startswith(classify.ESTIMATED)]
    columns = list(classify.CLASSIFIERS)
    started, cpu = time.perf_counter(), time.process_time()
    with threadpool_limits(limits=1):  # as evaluate: one BLAS thread (tiny fits)
        plain = plain_loop(inputs, names, columns, pairs, 0)
    t_plain, cpu_plain = time.perf_counter() - started, time.process_time() - cpu
    times, tables = {}, {}
    for jobs in (1, 2):
        started, cpu = time.perf_counter(), time.process_time()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", classify.UndefinedAUCWarning)
            tables[jobs] = classify.evaluate(inputs.X, inputs.y, inputs.groups, inputs.failed, inputs.normal,
                                             estimated=inputs.estimated, preprocessing=names,
                                             n_pairs=pairs, random_state=0, n_jobs=jobs,
                                             return_aucs=True)[1]
        times[jobs] = time.perf_counter() - started
        if jobs == 1:
            cpu_shared = time.process_time() - cpu
    same = all(np.array_equal(plain[k], tables[1][k], equal_nan=True)
               and np.array_equal(plain[k], tables[2][k], equal_nan=True) for k in plain)
    print(f"{len(names)} preprocessings x {len(columns)} classifiers x {pairs} pairs on {path.name} "
          f"({load()}):")
    print(f"  plain scikit-learn loop, 1 process:     {t_plain:7.1f} s wall, {cpu_plain:7.1f} s CPU")
    print(f"  shared preprocessing, 1 process:        {times[1]:7.1f} s wall, {cpu_shared:7.1f} s CPU "
          f"({cpu_plain / cpu_shared:.2f}x less CPU)")
    print(f"  shared preprocessing, 2 processes:      {times[2]:7.1f} s   ({t_plain / times[2]:.2f}x)")
    print(f"  parallel efficiency t(1) / (2 t(2)):    {times[1] / (2 * times[2]):7.2f}")
    print(f"  same AUC in every cell, all three:      {same}")


def fleet_steps(fleet: Path, make_fleet: bool, steps: set[int], folder: Path) -> None:
    """Steps 3 and 4 on ``fleet`` (made first, timed, with ``make_fleet``): stacking's inner CV, and
    `faultgen classify --horizon 3 --pairs 0` timed (by the fleet's time when it was made)."""
    made = None
    if make_fleet:
        made = timed([*faultgen(), "fleet", "-o", str(fleet), "--no-progress", "--overwrite"])
        print(f"faultgen fleet (default, 26 robots): {made[0]:7.1f} s wall, {made[1]:7.1f} s CPU   ({load()})")
    if 3 in steps:
        stacking_check(fleet)
    for flag in ([], ["--full"]) if 4 in steps else ():
        t = timed([*faultgen(), "classify", str(fleet), "--horizon", "3", "--pairs", "0", *flag,
                   "-o", str(folder / "fleet-cls"), "--no-progress", "--overwrite"])
        what = f"classify {fleet.name} --horizon 3 --pairs 0 {' '.join(flag)}"
        print(f"{what}: {t[0]:7.1f} s wall, {t[1]:7.1f} s CPU   ({load()})")
        if made is not None:
            print("  " + ratio_line(what, t, made, "faultgen fleet"))


def stacking_check(path: Path) -> None:
    """Step 3: stacking with its inner CV by sample and by run, and LR alone, on the thesis protocol."""
    from scipy.stats import wilcoxon

    from analysis import benchmark, classify

    fleet = benchmark.classification_inputs(path, horizon=3)
    by_sample = classify.stacking(0, inner_cv="sample")
    subset = ["control", "+pca", "+var3+pca", "+diff", "+diff+pca"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", classify.UndefinedAUCWarning)
        table, aucs = classify.evaluate(fleet.X, fleet.y, fleet.groups, fleet.failed, fleet.normal,
                                        classifiers={"by run": classify.stacking(0), "by sample": by_sample,
                                                     "lr": classify.logistic_regression(0)},
                                        preprocessing=subset, n_pairs=None, random_state=0, n_jobs=2,
                                        return_aucs=True)
    print(f"stacking's inner CV on {path.name} (--horizon 3, every pair), mean AUC (std); by run - by sample "
          "pair by pair: mean, pairs higher / lower, Wilcoxon signed-rank p:")
    for name in subset:
        d = aucs["by run", name] - aucs["by sample", name]
        d = d[~np.isnan(d)]
        print(f"  {name:12s} " + "  ".join(f"{c} {table.loc[name, (c, 'mean')]:.2f} "
                                           f"({table.loc[name, (c, 'std')]:.2f})"
                                           for c in ("by sample", "by run", "lr"))
              + f"  diff {d.mean():+.2f}, {int((d > 0).sum())} / {int((d < 0).sum())}, p {wilcoxon(d).pvalue:.2g}")


if __name__ == "__main__":
    main()
