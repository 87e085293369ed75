"""Reconstruction-based against complete-decomposition contributions on Tennessee Eastman's faults
(Braatz's data set: Russell, Chiang and Braatz 2000; Chiang, Russell and Braatz, *Fault Detection
and Diagnosis in Industrial Systems*, 2001): for each of the 21 faults, the share of its alarming
test samples whose first-ranked variable is one of the fault's root variables, by Q and by T2, with
:meth:`analysis.monitoring.PCAMonitor.contributions` ``method="complete"`` (today's) and ``"rbc"``
(Alcala and Qin 2009). The table is in docs/analysis.md, "Isolation by reconstruction-based
contributions".

Data: the folder of ``d00.dat`` (500 normal training samples, stored 52 x 500) and ``d01_te.dat`` ..
``d21_te.dat`` (960 samples each, the fault from sample 161 on), 52 variables: XMEAS(1..41),
XMV(1..11). The data are not shipped with faultgen (they are the University of Illinois's,
redistributed with Braatz's Fortran code); give their folder:

    python benchmarks/tennessee_eastman_rbc.py TE_FOLDER            # seconds

Root variables (:data:`ROOTS`, 1-based, 42..52 = XMV(1..11)): a fault has known root variables when
the disturbance of Downs and Vogel (1993, Table 8) acts on a quantity one measured variable carries or
that one control loop of the closed-loop plant (Lyman and Georgakis 1995, the scheme of Braatz's
data) counters at once: the loop's measured and manipulated variables, and the variable at the
disturbance's place. The others (compositions, an unmeasured feed temperature, kinetics, the
"unknown" faults 16-20) have none and are listed without a share.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from analysis.monitoring import PCAMonitor, varying_columns

ONSET = 160  # 0-based index of the first faulty test sample (the fault starts after 8 h)
#: The root variables of the faults that have them (1-based).
ROOTS = {
    4: (9, 21, 51),    # reactor cooling water inlet temperature, step: reactor temperature, its outlet, the flow
    5: (11, 22, 52),   # condenser cooling water inlet temperature, step: separator temperature, outlet, flow
    6: (1, 44),        # A feed loss (stream 1): A feed flow and its valve
    7: (4, 45),        # C header pressure loss (stream 4): A and C feed flow and its valve
    11: (9, 21, 51),   # reactor cooling water inlet temperature, random variation
    12: (11, 22, 52),  # condenser cooling water inlet temperature, random variation
    14: (9, 21, 51),   # reactor cooling water valve sticking
    15: (11, 22, 52),  # condenser cooling water valve sticking
    21: (4, 45),       # the valve of stream 4 held at its steady-state position
}
WHY_NONE = {1: "A/C feed ratio (stream 4 composition)", 2: "B composition (stream 4)", 3: "D feed temperature (not measured)",
            8: "A, B, C feed composition", 9: "D feed temperature (not measured)",
            10: "C feed temperature (not measured)", 13: "reaction kinetics", 16: "unknown", 17: "unknown",
            18: "unknown", 19: "unknown", 20: "unknown"}


def first_ranked(monitor: PCAMonitor, X: np.ndarray, statistic: str, method: str) -> np.ndarray:
    """1-based first-ranked variable of each sample (|contribution|: T2's complete ones are signed)."""
    return np.abs(monitor.contributions(X, statistic, method=method)).argmax(axis=1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path, help="the folder of d00.dat and d01_te.dat .. d21_te.dat")
    parser.add_argument("--variance", type=float, default=0.85, help="PCA explained variance (default 0.85)")
    parser.add_argument("--alpha", type=float, default=0.01, help="significance of the T2 and Q limits (default 0.01)")
    args = parser.parse_args()
    train = np.loadtxt(args.folder / "d00.dat").T
    keep = varying_columns(train)
    names = keep + 1  # 1-based variable numbers of the kept columns
    monitor = PCAMonitor(variance=args.variance, alpha=args.alpha).fit(train[:, keep])
    print(f"PCA on d00.dat: {train.shape[0]} samples, {len(keep)} of {train.shape[1]} variables, "
          f"{monitor.n_components_} components, alpha {args.alpha:g}")
    print("| fault | root variables | statistic | alarming samples | complete: right % | RBC: right % | "
          "chance % | complete: most often first | RBC: most often first |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    pooled = {(s, m): [0, 0] for s in ("q", "t2") for m in ("complete", "rbc")}
    shares = {(s, m): [] for s in ("q", "t2") for m in ("complete", "rbc")}
    for fault in range(1, 22):
        X = np.loadtxt(args.folder / f"d{fault:02d}_te.dat")[ONSET:, keep]
        t2, q = monitor.score_samples(X)
        roots = ROOTS.get(fault)
        for statistic, alarm in (("q", q > monitor.q_limit_), ("t2", t2 > monitor.t2_limit_)):
            cells, modes = [], []
            for method in ("complete", "rbc"):
                first = names[first_ranked(monitor, X[alarm], statistic, method)]
                values, counts = np.unique(first, return_counts=True)
                modes.append(f"{values[counts.argmax()]} ({100 * counts.max() / max(alarm.sum(), 1):.0f} %)"
                             if alarm.any() else "-")
                if roots and alarm.any():
                    right = int(np.isin(first, roots).sum())
                    cells.append(f"{100 * right / alarm.sum():.1f}")
                    pooled[statistic, method][0] += right
                    pooled[statistic, method][1] += int(alarm.sum())
                    shares[statistic, method].append(right / alarm.sum())
                else:
                    cells.append("-")
            root = ", ".join(map(str, roots)) if roots else f"none: {WHY_NONE[fault]}"
            chance = f"{100 * len(roots) / len(keep):.1f}" if roots else "-"
            print(f"| {fault} | {root} | {statistic.upper()} | {int(alarm.sum())} of {len(X)} | {cells[0]} | {cells[1]} "
                  f"| {chance} | {modes[0]} | {modes[1]} |")
    for (statistic, method), (right, total) in pooled.items():
        print(f"{statistic.upper()} {method}: {right} of {total} alarming samples of the {len(ROOTS)} faults with root "
              f"variables ranked a root variable first ({100 * right / total:.1f} %); mean of the faults' shares "
              f"{100 * np.mean(shares[statistic, method]):.1f} %")


if __name__ == "__main__":
    main()
