"""Thesis Fig. 6-5: transfer-entropy isolation accuracy against the number of bins, per wear level.

On a dataset like the j2 preset (IRB-6700-like, exp4 wear to +20 % over 100 cycles, every cycle
recorded), every run of one task that wears one axis is shown to transfer entropy with 5 to 20
bins at each wear level (thesis Table 6.2's 1, 5, 10 and 15 %), as ``faultgen bench-isolators``
does; the accuracy is the share of the six worn axes named. Prints the table (rows: bins, columns:
wear levels) and writes it as CSV with a PNG of the curves (the layout of Fig. 6-5).

    python benchmarks/fig_6_5.py j2.h5 [--task pick_place] [--speed-window 50,120] -o fig_6_5
"""

from __future__ import annotations

import argparse
from pathlib import Path

from analysis import benchmark, isolation

BINS = tuple(range(5, 21))


def accuracy_by_bins(path: Path, task: str, speed_window: tuple[float, float] | None):
    """Accuracy (%) of TE per bin count (rows) and wear level (columns) for ``task``'s worn runs."""
    isolators = {b: isolation.make("transfer_entropy", bins=b) for b in BINS}
    table = benchmark.isolation_table(path, isolators, progress=True, speed_window=speed_window)
    table = table[(table["task"] == task) & (table["worn_axis"] > 0)]
    if table.empty:
        raise SystemExit(f"{path} has no run of task {task!r} that wears one axis")
    accuracy = table.groupby(["isolator", "wear_pct"])["correct"].mean().mul(100).unstack("wear_pct")
    accuracy.columns = [f"{level:g} % wear" for level in accuracy.columns]
    return accuracy.rename_axis(index="bins").round(1)


def figure(accuracy, task: str, out: Path) -> Path:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7, 4.5))
    ax = fig.subplots()
    for level in accuracy.columns:
        ax.plot(accuracy.index, accuracy[level], marker="o", label=level)
    ax.set(xlabel="bins", ylabel="source axis isolated (%)", ylim=(-3, 103),
           title=f"transfer entropy against the number of bins, {task} (thesis Fig. 6-5)")
    ax.set_xticks(list(accuracy.index))
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("dataset", type=Path)
    parser.add_argument("--task", default="pick_place", help="thesis task 1 is pick and place")
    parser.add_argument("--speed-window", default=None, help="LOW,HIGH rad/s of motor speed, e.g. 50,120")
    parser.add_argument("-o", "--out", type=Path, default=Path("fig_6_5"), help="output stem (.csv, .png)")
    args = parser.parse_args()
    window = tuple(float(x) for x in args.speed_window.split(",")) if args.speed_window else None
    accuracy = accuracy_by_bins(args.dataset, args.task, window)
    accuracy.to_csv(args.out.with_suffix(".csv"))
    figure(accuracy, args.task, args.out.with_suffix(".png"))
    print(benchmark.markdown(accuracy, digits=4))
    print(f"wrote {args.out.with_suffix('.csv')}, {args.out.with_suffix('.png')}")


if __name__ == "__main__":
    main()
