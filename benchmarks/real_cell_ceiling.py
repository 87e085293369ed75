"""What a monitor of faultgen's form could reach at best on a real-cell fleet (issue 90): the first
alarm at 8-15 % true wear, the remaining life within 20 % at lambda 0.5, the alarm's bound below the
truth on at least 95 % of alarming log-axes and the 90 % interval covering 80-97 % of the worn axes' logs
at 10-40 % true wear (the fleet's, and each unit's: the criterion of the units of a rate of their own), as
chances, per worn unit and per fleet, from the fleet's truth and its friction tests' own errors.

    python benchmarks/real_cell_ceiling.py FLEET OUT [FLEET OUT ...] [--twin-factor 1 1.2] [--draws 4000]
        [--seed 0] [--limit 8] [--prior-sd 0.3] [--prior-mean 1] [--error-ratio 1] [--confidence 0.9]
        [--actual]

``FLEET`` a fleet of ``benchmarks/real_cell_fleet.py`` (``truth.csv``), ``OUT`` a ``faultgen monitor``
output of it (``tests.csv``: each test's own error, :func:`monitor_scale_bound.own_test_errors`).

**The estimator** has the monitor's form (a log's wear on the tests' scale is ``f x``, ``x`` the twin's
wear read, ``f`` the factor fitted on the friction tests up to the log:
:class:`faultgen.monitor.friction_tests.Rescale`) and every advantage the monitor does not have: the twin
reads each log's wear exactly up to its scale, ``x = w / c`` (``w`` the true wear, ``c`` the twin's
factor on the plant, ``--twin-factor``; 1: a twin that reads the truth), with no noise and no lag; the
reference test's offset known; each test ``y_j = w_j + e_j`` with its own error ``s_j`` (normal, the
test's stated error at its true wear; ``--error-ratio``: drawn that many times it, the estimator
still told the stated one: tests that scatter more than they say). ``f`` is the Bayesian regression
through the origin of the tests on ``x`` under the monitor's prior ``N(m, p^2)`` (``--prior-mean``, 1, and
``--prior-sd``, the monitor's :data:`faultgen.monitor.friction_tests.SCALE_PRIOR`; or a fleet's,
``faultgen monitor --scale-prior``; Gelman et al., *Bayesian Data Analysis*, 3rd ed., ch. 14): precision
``1/p^2 + sum x_j^2 / s_j^2``, mean ``(m/p^2 + sum x_j y_j / s_j^2)`` over it.
A log alarms when its one-sided 90 % lower bound ``x (f - z sd_f)`` (``z`` the monitor's
:func:`faultgen.monitor.alarm.alarm_quantile`; ``--confidence``: another) reaches the limit, at once
(the monitor waits for nothing longer with the twin); its 90 % interval is ``x (f -+ 1.645 sd_f)`` (the
monitor's :data:`faultgen.monitor.baseline.WEAR_INTERVAL`). At lambda 0.5 (half-way from its own first alarm to the true failure
day, 40 %) it knows the trend's shape exactly: the remaining life is the day ``f x`` reaches 40 % on the
tests known that day, less the day (``monitor_rul.day_of``), judged by the table's own
``real_cell_table.lambda_outcome``. Each unit is drawn ``--draws`` times
(the tests' errors); a fleet's chances are over the same draws, units independent. ``--actual``: one
draw, the errors the fleet's own tests made (read against the truth, the reference's offset as its
healthy tests tell it): whether a unit the monitor misses is missed by this estimator on the same tests.

The monitor reads its twin with noise and lag and learns the offset: an estimator of this form with
an honest bound and that much more doubt does not expect better chances than these, so a criterion
this one meets rarely is out of the monitor's reach on that fleet by the tests' scatter and the twin's
factor, not by its arithmetic (a different form of estimator is not covered). ``c`` is not known to a
monitor (the prior's 0.3 says so); the truth of a fleet gives it only roughly (docs/analysis.md).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from statistics import NormalDist
from types import SimpleNamespace

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import monitor_bounds_check as bounds  # sibling modules
import monitor_rul
import monitor_scale_bound
from real_cell_table import FAILURE_WEAR, WITHIN, growth_at, lambda_outcome

from faultgen.bench import independent
from faultgen.monitor.alarm import alarm_quantile
from faultgen.monitor.baseline import WEAR_INTERVAL_Z
from faultgen.monitor.friction_tests import SCALE_PRIOR
from faultgen.monitor.scoring import Settings


def factor_draws(x: np.ndarray, tests: list[tuple[int, float, float]], draws: np.ndarray,
                 prior_sd: float, prior_mean: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The factor's posterior mean and standard deviation on every log, each (n_draws, n_logs): ``x``
    (n_logs,) the twin's read, %; ``tests`` ``(log index, true wear %, error points)``; ``draws``
    (n_draws, n_tests) the tests' errors, points. ValueError for a prior_sd not above 0."""
    if not prior_sd > 0:
        raise ValueError(f"prior_sd {prior_sd!r}: expected a number above 0")
    n = len(x)
    precision = np.full((len(draws), n), prior_sd**-2)
    weighted = prior_mean * precision
    for j, (log, wear, error) in enumerate(tests):
        precision[:, log:] += x[log] ** 2 / error**2
        weighted[:, log:] += (x[log] * (wear + draws[:, j]) / error**2)[:, None]
    return weighted / precision, precision**-0.5


def unit_chances(wear: np.ndarray, tests: list[tuple[int, float, float]], twin_factor: float,
                 errors: np.ndarray, limit: float, prior_sd: float, prior_mean: float = 1.0,
                 z: float | None = None) -> dict:
    """One worn unit's draws (module docstring): ``wear`` its true wear a log (n_logs,), %, ``tests``
    its worn axis's tests ``(log index, true wear %, stated error points)``, ``errors`` (n_draws,
    n_tests) what each test read above its true wear in each draw, points. A dict: ``alarm`` the true
    wear at each draw's first alarm (inf: none), ``in_window``, ``within`` and ``late`` booleans a
    draw, ``alarming`` and ``below`` the logs a draw whose bound is at or past the limit and, of them,
    those whose bound lies below the true wear, ``first_below`` whether the first alarming log's does
    (True without an alarm), ``spanned`` the logs at 10-40 % true wear (``bounds.SPAN``) and ``covered``
    those a draw's 90 % interval holds the truth on. ``z`` the bound's normal quantile (default the monitor's
    :func:`faultgen.monitor.alarm.alarm_quantile`). ValueError for a twin_factor not above 0."""
    if not twin_factor > 0:
        raise ValueError(f"twin_factor {twin_factor!r}: expected a number above 0")
    x, n, n_draws = np.asarray(wear, dtype=float) / twin_factor, len(wear), len(errors)
    factor, sd = factor_draws(x, tests, errors, prior_sd, prior_mean)
    bound = x * (factor - (alarm_quantile() if z is None else z) * sd)
    fires = bound >= limit
    below = fires & (bound < wear)
    half = WEAR_INTERVAL_Z * sd * x  # the 90 % interval's half width, the monitor's wear interval's z
    span = (wear >= bounds.SPAN[0]) & (wear <= bounds.SPAN[1])
    covered = (np.abs(factor * x - wear) <= half) & span
    first = np.where(fires.any(axis=1), fires.argmax(axis=1), n)  # log index
    alarm = np.where(first < n, wear[np.minimum(first, n - 1)], np.inf)
    fast = growth_at({"wear": wear}, bounds.ALARM[0]) > 1.0
    truth = {"stamps": list(range(1, n + 1)), "wear": np.asarray(wear, dtype=float)}  # a log's stamp its day
    within, late = np.zeros(n_draws, bool), np.zeros(n_draws, bool)
    for m in np.flatnonzero(first < n):  # the table's lambda day and verdicts; f x reaching the failure wear
        outcome = lambda_outcome(truth, int(first[m]) + 1, lambda day, m=m: SimpleNamespace(
            rul=monitor_rul.day_of(factor[m, day - 1] * x, FAILURE_WEAR) - day, rul_5=None))
        within[m], late[m] = outcome.get("within", False), outcome.get("late", False)
    return {"alarm": alarm, "in_window": np.array([bounds.alarm_in_window(a, fast) for a in alarm]),
            "within": within, "late": late, "alarming": fires.sum(axis=1), "below": below.sum(axis=1),
            "first_below": below[np.arange(n_draws), np.minimum(first, n - 1)] | (first == n),
            "spanned": int(span.sum()), "covered": covered.sum(axis=1)}


def fleet_chances(fleet: Path, out: Path, twin_factor: float, limit: float, prior_sd: float, *,
                  draws: int = 4000, seed: int = 0, error_ratio: float = 1.0,
                  prior_mean: float = 1.0, z: float | None = None, actual: bool = False) -> dict[str, dict]:
    """:func:`unit_chances` of every worn unit of ``fleet``: ``draws`` draws of the tests' errors,
    ``error_ratio`` times their stated ones (each unit its own stream of ``seed``, units in name order);
    ``actual``: one draw, the errors the fleet's tests made (:func:`actual_errors`). ValueError for
    draws below 1 or an error_ratio not above 0."""
    if draws < 1 or not error_ratio > 0:
        raise ValueError(f"draws {draws!r}, error_ratio {error_ratio!r}: expected at least 1 and above 0")
    truth = independent.read_truth(fleet / "truth.csv")
    own = monitor_scale_bound.own_test_errors(truth, out)
    streams = np.random.SeedSequence(seed).spawn(len(truth))
    result = {}
    for (unit, t), stream in zip(sorted(truth.items()), streams):
        if not t["axis"]:
            continue
        log = {s: i for i, s in enumerate(t["stamps"])}
        seen = [(s, e, y) for s, e, y in own.get(unit, []) if s in log]
        tests = [(log[s], float(t["wear"][log[s]]), 100 * (1 + t["wear"][log[s]] / 100) * e) for s, e, _ in seen]
        if actual:
            errors = actual_errors([(w, y) for (_, w, _), (_, _, y) in zip(tests, seen)])[None, :]
        else:
            errors = np.random.default_rng(stream).standard_normal((draws, len(tests)))
            errors *= error_ratio * np.array([s for _, _, s in tests])
        result[unit] = unit_chances(t["wear"], tests, twin_factor, errors, limit, prior_sd, prior_mean, z)
    return result


def actual_errors(tests: list[tuple[float, float]]) -> np.ndarray:
    """What each of a unit's tests ``(true wear %, read %)`` read above its true wear, points, once its
    reference's offset is taken off as its tests at no true wear tell it (the mean of their ``ln(1 +
    y/100)``, 0 without one) and as a factor: ``100 ((1 + y/100) / (1 + b/100) - 1) - w``
    (:func:`faultgen.monitor.bounds.less_reference`'s reading with ``b`` known)."""
    healthy = [np.log1p(y / 100) for w, y in tests if w == 0]
    offset = float(np.mean(healthy)) if healthy else 0.0
    return np.array([100 * np.expm1(np.log1p(y / 100) - offset) - w for w, y in tests])


def measured_error_ratio(fleet: Path, out: Path) -> tuple[float, int]:
    """How the worn axes' tests after the wear began scatter against the truth, in their stated errors:
    (the root mean square of ``(ln(1 + y/100) - b - ln(1 + w/100)) / sqrt(s^2 + s_b^2)``, the tests
    counted), ``y`` a test's read, ``w`` its true wear, ``s`` its own error in ``ln``
    (:func:`monitor_scale_bound.own_test_errors`), ``b`` the mean ``ln(1 + y/100)`` of the unit's tests
    at no true wear (its reference's offset as those tests tell it) and ``s_b`` its standard error from
    theirs; units without such a test are left out. 1: the tests are as good as they say; the
    ``--error-ratio`` to draw them with. (nan, 0) without such a test."""
    truth = independent.read_truth(fleet / "truth.csv")
    z = []
    for unit, tests in monitor_scale_bound.own_test_errors(truth, out).items():
        true = dict(zip(truth[unit]["stamps"], truth[unit]["wear"]))
        seen = [(true[s], e, np.log1p(y / 100)) for s, e, y in tests if s in true]
        healthy = np.array([(e, y) for w, e, y in seen if w == 0]).reshape(-1, 2)
        if not len(healthy):
            continue
        offset, offset_var = healthy[:, 1].mean(), np.sum(healthy[:, 0] ** 2) / len(healthy) ** 2
        z += [(y - offset - np.log1p(w / 100)) / np.sqrt(e**2 + offset_var) for w, e, y in seen if w > 0]
    return (float(np.sqrt(np.mean(np.square(z)))) if z else float("nan")), len(z)


def actual_table(name: str, outcome: dict[str, dict], twin_factor: float) -> list[str]:
    """The ideal estimator on the errors the fleet's tests made (``fleet_chances(..., actual=True)``):
    per worn unit its first alarm and whether the remaining life at lambda is within 20 %, late or
    early, as a markdown list. Not its bound nor its interval's coverage: they take the offset as known,
    which these errors (read about the healthy tests' mean) are not."""
    lines = [f"**{name}**, twin factor {twin_factor:g}, the fleet's own test errors", ""]
    for unit, c in sorted(outcome.items()):
        life = "within 20 %" if c["within"][0] else ("late" if c["late"][0] else "early")
        lines.append(f"- {unit}: first alarm at {c['alarm'][0]:.1f} % true wear "
                     f"({'in' if c['in_window'][0] else 'out of'} the window), at lambda {life}")

    def count(key: str) -> int:
        return sum(bool(c[key][0]) for c in outcome.values())

    summary = (f"- first alarms in the window: {count('in_window')} of {len(outcome)}; the remaining life at "
               f"lambda within {100 * WITHIN:g} %: {count('within')}, late by more: {count('late')}")
    lines += ["", summary]
    return lines


def table(name: str, chances: dict[str, dict], twin_factor: float) -> list[str]:
    """A markdown table of one fleet at one twin factor: per worn unit, then the fleet's chances of the
    issue's two criteria (every unit in the window; the median within 20 % on at least half)."""
    header = ("| unit | true wear at first alarm, median (5-95 %) | P(first alarm in window) "
              "| P(within 20 % at lambda) | P(late by > 20 %) | P(its logs covered 80-97 %) |")
    lines = [f"**{name}**, twin factor {twin_factor:g}", "", header, "| --- | --- | --- | --- | --- | --- |"]
    for unit, c in sorted(chances.items()):
        q = np.percentile(c["alarm"], [50, 5, 95])
        lines.append(f"| {unit} | {q[0]:.1f} ({q[1]:.1f}-{q[2]:.1f}) | {c['in_window'].mean():.2f} | "
                     f"{c['within'].mean():.2f} | {c['late'].mean():.2f} | {coverage_chance(c):.2f} |")
    window = np.array([c["in_window"] for c in chances.values()])
    within = np.array([c["within"] for c in chances.values()])
    late = np.array([c["late"] for c in chances.values()])
    need = int(np.ceil(0.5 * len(chances)))

    def counts(hits: np.ndarray) -> str:  # the units a draw meets the criterion on
        low, high = np.percentile(hits.sum(axis=0), [5, 95])
        return f"mean {hits.sum(axis=0).mean():.2f}, 5-95 %: {low:.0f}-{high:.0f} of {len(chances)}"

    every = (f"- every worn unit's first alarm in the window: chance {window.all(axis=0).mean():.2f} "
             f"(units in it: {counts(window)})")
    half = (f"- the median within {100 * WITHIN:g} % at lambda on at least {need} of {len(chances)}: chance "
            f"{(within.sum(axis=0) >= need).mean():.2f} (units within: {counts(within)}; late by more than "
            f"{100 * WITHIN:g} %: {counts(late)})")
    alarming = np.sum([c["alarming"] for c in chances.values()], axis=0)
    fraction = np.sum([c["below"] for c in chances.values()], axis=0) / np.maximum(alarming, 1)
    low, high = np.percentile(fraction, [5, 95])
    first = np.array([c["first_below"] for c in chances.values()])
    honest = (f"- the bound below the truth on >= {100 * bounds.BOUND_SHARE:g} % of alarming log-axes: chance "
              f"{(fraction >= bounds.BOUND_SHARE).mean():.2f} (the fleet's fraction: mean {100 * fraction.mean():.1f} %, "
              f"5-95 %: {100 * low:.1f}-{100 * high:.1f} %); on every first alarm: chance "
              f"{first.all(axis=0).mean():.2f}; with every first alarm in the window: chance "
              f"{(window.all(axis=0) & (fraction >= bounds.BOUND_SHARE)).mean():.2f}")
    spanned = sum(c["spanned"] for c in chances.values())
    share = np.sum([c["covered"] for c in chances.values()], axis=0) / max(spanned, 1)
    low, high = np.percentile(share, [5, 95])
    low_share, high_share = bounds.COVERAGE
    cover = (f"- the 90 % interval covering {100 * low_share:g}-{100 * high_share:g} % of the worn axes' "
             f"{spanned} logs at 10-40 %: chance {in_coverage(share).mean():.2f} (the fleet's coverage: mean "
             f"{100 * share.mean():.1f} %, 5-95 %: {100 * low:.1f}-{100 * high:.1f} %)")
    lines += ["", every, half, honest, cover]
    return lines


def in_coverage(share: np.ndarray) -> np.ndarray:
    """Whether each coverage (a share of logs) lies in the issue's 80-97 % (``bounds.COVERAGE``)."""
    return (share >= bounds.COVERAGE[0]) & (share <= bounds.COVERAGE[1])


def coverage_chance(chances: dict) -> float:
    """The chance that one unit's 90 % interval covers 80-97 % of its logs at 10-40 % (the criterion of
    a unit of a rate of its own); NaN for a unit with no such log."""
    if not chances["spanned"]:
        return float("nan")
    return float(in_coverage(chances["covered"] / chances["spanned"]).mean())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("pairs", type=Path, nargs="+", metavar="FLEET OUT")
    parser.add_argument("--twin-factor", type=float, nargs="+", default=[1.0, 1.2])
    parser.add_argument("--draws", type=int, default=4000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--limit", type=float, default=Settings().wear_limit)
    parser.add_argument("--prior-sd", type=float, default=SCALE_PRIOR)
    parser.add_argument("--prior-mean", type=float, default=1.0, help="the factor's prior mean (default 1)")
    parser.add_argument("--confidence", type=float, default=None,
                        help="the bound's one-sided confidence (default the monitor's alarm, 0.90)")
    parser.add_argument("--actual", action="store_true",
                        help="one draw: the errors the fleet's own tests made (is it the monitor or the draw?)")
    parser.add_argument("--error-ratio", type=float, default=1.0,
                        help="the tests' errors drawn this many times their stated ones (default 1)")
    args = parser.parse_args()
    if len(args.pairs) % 2:
        parser.error(f"expected pairs FLEET OUT; got {len(args.pairs)} paths")
    if args.confidence is not None and not 0.5 < args.confidence < 1:
        parser.error(f"--confidence {args.confidence!r}: expected a number between 0.5 and 1")
    z = None if args.confidence is None else NormalDist().inv_cdf(args.confidence)
    for fleet, out in zip(args.pairs[::2], args.pairs[1::2]):
        ratio, n = measured_error_ratio(fleet, out)
        print(f"{fleet.name}: the worn axes' {n} tests after the wear began scatter {ratio:.2f} times their "
              "stated errors about the truth (root mean square; 1: as stated; pass it as --error-ratio)\n")
        for c in args.twin_factor:
            chances = fleet_chances(fleet, out, c, args.limit, args.prior_sd, draws=args.draws,
                                    seed=args.seed, error_ratio=args.error_ratio, prior_mean=args.prior_mean, z=z,
                                    actual=args.actual)
            drawn = f", the tests' errors x {args.error_ratio:g}" if args.error_ratio != 1 else ""
            prior = (f", prior {args.prior_mean:g} +- {args.prior_sd:g}"
                     if (args.prior_mean, args.prior_sd) != (1.0, SCALE_PRIOR) else "")
            confidence = f", a {100 * args.confidence:g} % bound" if args.confidence is not None else ""
            title = fleet.name + drawn + prior + confidence
            print("\n".join((actual_table if args.actual else table)(title, chances, c)) + "\n", flush=True)


if __name__ == "__main__":
    main()
