"""Classification speed: `faultgen classify` against a plain scikit-learn loop and the sweep that made the data.

    python benchmarks/bench_classify.py [--dataset quick.h5] [--full] [--no-full] [--fleet fleet.h5 [--make-fleet]]
                                        [--steps 1,2,3,4,5] [--repeat N]

In one run of this script:

1. ``faultgen sweep --preset quick`` writes quick.h5 (timed; skipped with --dataset), then
   ``faultgen classify quick.h5`` with its defaults (timed, as a user runs it: the seven rows of
   ``analysis.classify.SHORT_TABLE``, pairs in parallel on every core, each row's chance level
   on lr included) and ``classify --full`` (every row; not with --no-full); the ratios classify /
   sweep, wall and CPU, and whether the default table meets the target, at most the sweep's time
   (1.0x) in both; with ``--repeat N`` the sweep and the default table N times, one after the
   other, and the target judged on the medians of their N ratios (one run's ratio moves by 0.2-0.3
   from one minute to the next on a 2-core machine);
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
5. the work of ``faultgen classify`` with its defaults counted on one process (:func:`counted_work`):
   model fits per cell, PCA fits and stateless steps per held-out pair, tasks and the bytes the
   largest ships, each against what the protocol needs (counts, not times;
   tests/test_classify_work_counts.py runs it at a tiny size);

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


#: The model classes whose fits are counted (a fit inside another counted one, stacking's base
#: classifiers, is the outer model's), by the column name of their classifier; PCA is the one
#: preprocessing step fitted on data, Difference and WindowConcat the stateless run-by-run ones,
#: StandardScaler the classifiers' scaling (shared by them and by the label sets) and PCA's.
COUNTED = {"LogisticRegression": "lr", "SVC": "svm", "RandomForestClassifier": "rf", "StackingClassifier": "stacking",
           "PCA": "pca", "Difference": "sequence", "WindowConcat": "sequence", "StandardScaler": "scale"}


def counted_work(path: Path, n_pairs: int = 20, **kwargs) -> dict:
    """``faultgen classify PATH``'s evaluation (:func:`analysis.benchmark.classification_table`, the
    chance estimate included; ``kwargs`` go to it) on one process, every model fit and every task of
    the worker pool counted, beside what the protocol needs (counts, not times).

    The protocol (thesis Procedure 1, docs/analysis.md): per cell (row, classifier) and label set
    (the true labels; with the chance estimate also the 19 exchanged sets, for the judged
    classifier only), one fit per held-out pair whose training runs and held-out runs both have
    both classes; a row's PCA fitted once per held-out pair of runs (the same training runs in every
    label set), its stateless steps run twice per held-out pair (training runs, held-out runs), one
    StandardScaler per row and held-out pair for every classifier that scales (learning no labels:
    shared by the label sets and the classifiers) and +pca's own;
    one task per held-out pair of runs, shipping the features, the runs, the labels of each of its
    label sets and the names, nothing more.

    Returns
    -------
    dict with ``fits`` and ``needed``: ``{"lr" | "svm" | "rf" | "stacking": fits per cell, "pca":
    per +pca row and held-out pair, "sequence": per stateless step and held-out pair, "scale":
    StandardScaler fits per row, "tasks": tasks}``; ``bytes``: the largest task's pickled arguments and ``bytes_needed`` the most it
    needs; ``table`` the table.
    """
    import pickle
    from contextlib import ExitStack
    from unittest import mock

    from analysis import benchmark
    from analysis.classify import evaluation

    counts: dict[str, int] = dict.fromkeys(set(COUNTED.values()) | {"tasks"}, 0)
    shipped: list[tuple[int, tuple]] = []
    depth = [0]

    def counting(method, name):
        def fit(self, *args, **kw):
            depth[0] += 1
            try:
                if depth[0] == 1:
                    counts[name] += 1
                return method(self, *args, **kw)
            finally:
                depth[0] -= 1
        return fit

    def task(*args):
        counts["tasks"] += 1
        shipped.append((len(pickle.dumps(args, protocol=pickle.HIGHEST_PROTOCOL)), args))
        return original(*args)

    original = evaluation.pair_cells
    classes = _counted_classes()
    with ExitStack() as stack:
        for cls in classes:  # fit, and fit_transform where the class has its own (PCA)
            for method in ("fit", *(["fit_transform"] if "fit_transform" in vars(cls) else [])):
                stack.enter_context(mock.patch.object(cls, method, counting(getattr(cls, method), COUNTED[cls.__name__])))
        stack.enter_context(mock.patch.object(evaluation, "pair_cells", task))
        table = benchmark.classification_table(path, n_pairs=n_pairs, progress=False, n_jobs=1, **kwargs)
    needed = protocol_needs(path, table, n_pairs, kwargs.get("random_state", 0), kwargs.get("wear_threshold", 10.0))
    columns = list(dict.fromkeys(table.columns.get_level_values(0)))
    fits = {c: counts[c] / len(table.index) for c in columns}
    fits.update(pca=counts["pca"] / max(needed.pop("pca_rows"), 1), sequence=counts["sequence"] / max(needed.pop("steps"), 1),
                scale=counts["scale"] / len(table.index), tasks=counts["tasks"])
    inputs = benchmark.classification_inputs(path, kwargs.get("wear_threshold", 10.0))
    over = [(size, task_bytes_needed(inputs, list(table.index), len(args[4]))) for size, args in shipped]
    most = max(over, key=lambda t: t[0] - t[1])
    return {"fits": fits, "needed": needed, "bytes": most[0], "bytes_needed": most[1], "table": table}


def _counted_classes() -> list[type]:
    from sklearn.decomposition import PCA
    from sklearn.ensemble import RandomForestClassifier, StackingClassifier
    from sklearn.linear_model import LogisticRegression
    from sklearn.preprocessing import StandardScaler
    from sklearn.svm import SVC

    from analysis.features import Difference, WindowConcat

    return [LogisticRegression, SVC, RandomForestClassifier, StackingClassifier, PCA, Difference, WindowConcat,
            StandardScaler]


def protocol_needs(path: Path, table, n_pairs: int, seed: int, wear_threshold: float) -> dict:
    """What the protocol needs for ``table`` (:func:`counted_work`): fits per cell per classifier,
    per +pca row and held-out pair, per stateless step and held-out pair, and the tasks; from the
    dataset's labels, the exchanged label sets and the pairs each draws."""
    from analysis import benchmark, classify

    inputs = benchmark.classification_inputs(path, wear_threshold)
    labels = classify.make_labels(inputs.y, inputs.groups, inputs.failed)
    sets = [(labels, inputs.failed, inputs.normal)]
    if table.attrs.get("chance_source") is not None:
        sets += classify.permuted_roles(labels, inputs.groups, inputs.failed, inputs.normal, table.attrs["permutations"],
                                        seed)
    judged = table.attrs.get("chance_source")
    valid, held_out = [], set()
    for k, (y, failed, normal) in enumerate(sets):
        for pair in classify.select_pairs(failed, normal, n_pairs, seed):
            held = np.isin(inputs.groups, list(pair))
            held_out.add(frozenset(pair))
            if len(set(y[~held])) == 2 and len(set(y[held])) == 2:
                valid.append((k, frozenset(pair)))
    needed = {}
    for column in dict.fromkeys(table.columns.get_level_values(0)):
        in_sets = {k for k in range(len(sets)) if k == 0 or judged in ("cell", column)}
        needed[column] = sum(1 for k, _ in valid if k in in_sets)
    fitted_pairs = len({pair for _, pair in valid})
    rows = list(table.index)
    needed["pca"] = fitted_pairs
    needed["pca_rows"] = sum("+pca" in row for row in rows)
    # per row and held-out pair: one scaling for every classifier that scales (all but rf), one in +pca
    scaled = any(column != "rf" for column in table.columns.get_level_values(0))
    needed["scale"] = fitted_pairs * sum(scaled + ("+pca" in row) for row in rows) / len(rows)
    needed["sequence"] = 2 * fitted_pairs
    needed["steps"] = sum(isinstance(step, classify.SEQUENCE_STEPS) for row in rows
                          for _, step in classify.preprocessing_steps(row))
    needed["tasks"] = len(held_out)
    return needed


def task_bytes_needed(inputs, rows: list[str], n_sets: int) -> int:
    """The most a task of :func:`counted_work` needs to ship, bytes: the features and the estimated
    block where ``rows`` use them, the run of each sample and the labels of each of its ``n_sets``
    label sets, pickled, and 2 KiB for the names, its pair and the settings."""
    import pickle

    from analysis.classify import ESTIMATED, make_labels

    labels = make_labels(inputs.y, inputs.groups, inputs.failed)
    data = (inputs.X if any(not r.startswith(ESTIMATED) for r in rows) else None,
            inputs.estimated if any(r.startswith(ESTIMATED) for r in rows) else None,
            inputs.groups, [labels.copy() for _ in range(n_sets)])  # each set its own array
    return len(pickle.dumps(data, protocol=pickle.HIGHEST_PROTOCOL)) + 2048


def print_counts(path: Path, pairs: int) -> None:
    """Step 5: :func:`counted_work` on ``path`` (classify's defaults, ``pairs`` pairs), each count
    beside what the protocol needs, with its verdict."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        found = counted_work(path, n_pairs=pairs, chance=True, short=True)
    print(f"work of `faultgen classify {path.name} --pairs {pairs}` counted (one process), against what the protocol needs:")
    for key, value in found["fits"].items():
        need = found["needed"][key]
        what = {"tasks": "tasks", "pca": "PCA fits per +pca row", "scale": "StandardScaler fits per row"}.get(
            key, f"{key} fits per cell")
        if key == "sequence":
            what = "stateless step runs per step"
        print(f"  {what:34s} {value:8g} (needed {need:g}): {'as needed' if value == need else 'NOT AS NEEDED'}")
    ok = found["bytes"] <= found["bytes_needed"]
    print(f"  {'bytes shipped, largest task':34s} {found['bytes']:8d} (needed at most {found['bytes_needed']}): "
          f"{'within' if ok else 'MORE THAN NEEDED'}")


def sweep_command(path: Path) -> list[str]:
    """``faultgen sweep --preset quick`` into ``path`` (replacing it: step 1 makes it again with --repeat)."""
    return [*faultgen(), "sweep", "--preset", "quick", "-o", str(path), "--no-progress", "--overwrite"]


def step_one(path: Path, folder: Path, make: bool, full: bool) -> tuple[float, float] | None:
    """Step 1 once: the quick sweep into ``path`` (timed, when ``make``), then ``faultgen classify``
    with its defaults (and ``--full`` when ``full``), each line printed with its ratios to the sweep.
    Returns the default table's (wall, CPU) ratios to the sweep (None without a sweep)."""
    sweep = None
    if make:
        sweep = timed(sweep_command(path))
        print(f"faultgen sweep --preset quick:   {sweep[0]:7.1f} s wall, {sweep[1]:7.1f} s CPU   ({load()})")
    ratios = None
    for flag in ([], *([["--full"]] if full else [])):
        t = timed([*faultgen(), "classify", str(path), *flag, "-o", str(folder / "cls"), "--no-progress",
                   "--overwrite"])
        what = f"faultgen classify {' '.join(flag) or '(defaults)'}"
        print(f"{what:33s} {t[0]:7.1f} s wall, {t[1]:7.1f} s CPU   ({load()})")
        if sweep is not None:
            print("  " + ratio_line(what, t, sweep, "the sweep"))
            if not flag:  # the target: the default table at most the sweep's time, wall and CPU
                ratios = (t[0] / sweep[0], t[1] / sweep[1])
                print(f"  target <= 1.0x the sweep, wall and CPU: {verdict(max(ratios))}")
    return ratios


def repeated_verdict(ratios: list[tuple[float, float]]) -> str:
    """The target judged on the median of step 1's repeated pairs (one run's ratio moves by 0.2-0.3
    from one minute to the next on a 2-core machine: docs/performance.md, issue 89), with the range."""
    wall, cpu = np.array(ratios).T
    met = sum(max(r) <= 1.0 for r in ratios)
    return (f"over {len(ratios)} pairs of sweep and classify, one after the other: classify / sweep wall "
            f"{np.median(wall):.2f} (median; {wall.min():.2f}-{wall.max():.2f}), CPU {np.median(cpu):.2f} "
            f"({cpu.min():.2f}-{cpu.max():.2f}); target <= 1.0x on the medians: "
            f"{verdict(max(np.median(wall), np.median(cpu)))}; met by {met} of {len(ratios)} pairs alone")


def verdict(worst: float) -> str:
    """The target's verdict on the worse of a wall and a CPU ratio to the sweep (at most 1.0x)."""
    return f"{'met' if worst <= 1.0 else 'NOT MET'} ({worst:.2f}x at worst)"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", type=Path, help="An existing dataset (default: make quick.h5, timed).")
    parser.add_argument("--full", action="store_true", help="Step 2 on every row (default: classify's seven).")
    parser.add_argument("--fleet", type=Path, help="A fleet for steps 3 and 4.")
    parser.add_argument("--make-fleet", action="store_true", help="Make --fleet first with `faultgen fleet`, timed.")
    parser.add_argument("--no-full", action="store_true",
                        help="Step 1 without `classify --full` (the default table only).")
    parser.add_argument("--pairs", type=int, default=20, help="Held-out pairs of step 2 (classify's default, 20).")
    parser.add_argument("--steps", default="1,2,3,4,5", help="Steps to run (3 and 4 need --fleet); default all.")
    parser.add_argument("--repeat", type=int, default=1,
                        help="Step 1's sweep and default classify this many times, one after the other: each "
                             "pair's ratios, then the target judged on their medians (default 1).")
    args = parser.parse_args()
    steps = {int(k) for k in args.steps.split(",")}

    print(f"{time.strftime('%Y-%m-%d %H:%M')} UTC, {os.cpu_count()} cores, {load()} "
          "(1-min average; > cores means the machine is shared)")
    folder = Path(tempfile.mkdtemp(prefix="bench-classify-"))
    try:
        path = args.dataset
        if path is None and steps & {1, 2, 5}:
            path = folder / "quick.h5"
            if 1 not in steps:
                subprocess.run(sweep_command(path), env=children.environment(), check=True, stdout=subprocess.DEVNULL)
        if 1 in steps:
            ratios = [step_one(path, folder, args.dataset is None, full=not args.no_full and i == 0)
                      for i in range(args.repeat if args.dataset is None else 1)]
            if len(ratios) > 1:
                print(repeated_verdict(ratios))
        if 5 in steps:
            print_counts(path, args.pairs)
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
