"""The least median wear error a scale learned from friction tests can give (issue 75, "What it must
show", bullet 2; docs/analysis.md, "The wear on the friction tests' scale").

    python benchmarks/monitor_scale_bound.py --work WORK [--out monitor] [--prior-sd 0.5 0.3 0.1 0.05]
                                             [--filter-sd 0 1.6]

``WORK`` is a run of ``benchmarks/monitor_wear_scale.py --friction-test-every D`` (its ``truth.csv``
and ``OUT/tests.csv``). The monitor puts a log's wear on the tests' scale as ``f x`` (``x`` the
filtered wear in the twin's scale, ``f`` the factor fitted on the tests up to the log:
:class:`faultgen.monitor.friction_tests.Rescale`). Here ``f`` is given every advantage the monitor
does not have: the reference test's error known (``b = 0``), each test's ``x`` exact (the true wear
over the true factor), each test's error its own only (the plant's day-to-day friction scatter the
test reads, ``tests.csv``'s interval less the reference's). Then ``f``'s relative posterior
standard deviation after the tests ``j`` up to a log is, for a normal prior of relative standard
deviation ``p`` (Bayesian linear regression through the origin; Gelman et al., *Bayesian Data
Analysis*, 3rd ed., ch. 14)::

    r = (1 / p^2 + sum_j (w_j / s_j)^2) ^ (-1/2)

``w_j`` the true wear at test ``j`` and ``s_j`` its error, points of wear; the log's wear error is
normal with standard deviation ``sqrt((w r)^2 + e^2)`` (``w`` its true wear, ``e`` the filter's own
error, ``--filter-sd``), so its median absolute error is ``0.6745`` times that. The median of these
over the worn axes' logs with true wear in [10, 40] % is what any estimator of this form can reach
at best on that fleet; ``p = 0.3`` is the monitor's prior (:data:`faultgen.monitor.friction_tests.SCALE_PRIOR`;
0.5 before 2026-11-27), smaller ``p`` a twin whose scale is known that well before any test.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
from pathlib import Path

import numpy as np
from scipy import stats

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

#: The median absolute value of a standard normal variable.
MEDIAN_ABS = float(stats.norm.ppf(0.75))
#: The issue's window of true wear, %.
WINDOW = (10.0, 40.0)


def factor_error(test_wear, test_error, prior_sd: float) -> float:
    """The relative posterior standard deviation of the scale factor (module docstring) from the tests'
    true wear ``test_wear`` % and errors ``test_error`` points (equal-length sequences, possibly
    empty) under a prior of relative standard deviation ``prior_sd`` (> 0). ValueError otherwise."""
    w, s = np.asarray(test_wear, dtype=float), np.asarray(test_error, dtype=float)
    if not prior_sd > 0 or w.shape != s.shape or np.any(s <= 0) or not np.all(np.isfinite(w)):
        raise ValueError(f"prior_sd {prior_sd!r} must be > 0 and each test a finite wear with an error > 0 "
                         f"(got {w.size} wears, {s.size} errors)")
    return float(1.0 / math.sqrt(1.0 / prior_sd**2 + float(np.sum((w / s) ** 2))))


def median_error_bound(logs: list[tuple[float, list[tuple[float, float]]]], prior_sd: float,
                       filter_sd: float = 0.0) -> float:
    """The median over ``logs`` of each log's median absolute wear error, points (module docstring):
    each log ``(true wear %, [(a test's true wear %, its error, points), ...] the tests up to it)``."""
    if filter_sd < 0 or not logs:
        raise ValueError(f"filter_sd {filter_sd!r} must be >= 0 and logs not empty")
    each = []
    for wear, tests in logs:
        r = factor_error([w for w, _ in tests], [s for _, s in tests], prior_sd)
        each.append(MEDIAN_ABS * math.hypot(wear * r, filter_sd))
    return float(np.median(each))


def own_test_errors(truth: dict, out: Path) -> dict[str, list[tuple[str, float, float]]]:
    """Each worn unit's friction tests of its worn axis after its reference, ``{unit: [(stamp, own
    relative error, read %), ...]}`` from ``OUT/tests.csv``: a test's 90 % interval in ``ln`` as a
    standard deviation, the reference test's variance taken off (its offset is known to the estimators
    here), and its wear read against the reference.
    ``truth`` as :func:`faultgen.bench.independent.read_truth` gives it."""
    z = float(stats.norm.ppf(0.95))
    tests: dict[str, list[tuple[str, float, float]]] = {}
    reference: dict[str, float] = {}
    with open(out / "tests.csv", newline="") as f:
        for r in csv.DictReader(f):
            t = truth[r["unit"]]
            if int(r["axis"]) != t["axis"] or not r["wear_lower"]:
                continue
            sd = (math.log1p(float(r["wear_upper"]) / 100) - math.log1p(float(r["wear_lower"]) / 100)) / (2 * z)
            if r["verdict"].startswith("reference"):  # the first test since the last repair
                reference[r["unit"]] = sd
                continue
            own = math.sqrt(max(sd**2 - reference[r["unit"]] ** 2, 1e-12))
            tests.setdefault(r["unit"], []).append((r["stamp"], own, float(r["wear"])))
    return tests


def fleet_logs(work: Path, out: Path) -> list[tuple[float, list[tuple[float, float]]]]:
    """The worn axes' logs in the window with the tests up to each (:func:`median_error_bound`):
    the true wear from ``truth.csv``, each test's own error from ``OUT/tests.csv``
    (:func:`own_test_errors`) in points at its true wear."""
    import independent_fleet

    truth = independent_fleet.read_truth(work / "truth.csv")
    tests = own_test_errors(truth, out)
    logs = []
    for unit, t in truth.items():
        if not t["axis"]:
            continue
        true = dict(zip(t["stamps"], t["wear"]))
        for stamp, wear in true.items():
            if WINDOW[0] <= wear <= WINDOW[1]:
                seen = [(true[s], 100 * (1 + true[s] / 100) * e)
                        for s, e, _ in tests.get(unit, []) if s <= stamp]
                logs.append((wear, seen))
    return logs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--work", type=Path, required=True)
    parser.add_argument("--out", default="monitor")
    parser.add_argument("--prior-sd", type=float, nargs="+", default=[0.5, 0.3, 0.1, 0.05])
    parser.add_argument("--filter-sd", type=float, nargs="+", default=[0.0, 1.6])
    args = parser.parse_args()
    logs = fleet_logs(args.work, args.work / args.out)
    print(f"{args.work}: {len(logs)} logs of worn axes with true wear in {WINDOW[0]:g}-{WINDOW[1]:g} %")
    print("| prior sd of the factor | filter's own error, points | least median abs. error, points |")
    print("| --- | --- | --- |")
    for p in args.prior_sd:
        for e in args.filter_sd:
            print(f"| {p:g} | {e:g} | {median_error_bound(logs, p, e):.2f} |")


if __name__ == "__main__":
    main()
