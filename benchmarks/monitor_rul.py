"""`faultgen monitor`'s remaining useful life (faultgen.monitor.prognosis, issue 59) scored against
the truth of a fleet made by a simulator that is not faultgen, with NASA ProgPy's metrics.

    python benchmarks/monitor_rul.py [--units 6] [--worn 4] [--days 120] [--seed 0] [--final-wear 60]
                                     [--failure-wear 40] [--work DIR]
    python benchmarks/monitor_rul.py --fleet WORK [--out monitor] [--failure-wear 40] [--from-alarm]
                                     [--scale-uncertainty 0.1]

The second form scores a run of ``benchmarks/monitor_wear_scale.py`` (its ``WORK``: the issue's two
independent fleets, first law and Stribeck-hump law, 12 units with 8 worn, with the calibrated
twin, the monitor's default) instead of writing a fleet and running the monitor: the remaining
life is recomputed from that run's ``scores.csv`` (which does not depend on ``--failure-wear``).
With friction tests the unit's monitor rows are replayed from ``OUT/.state`` (:func:`replayed_rows`)
and each prediction fits them on *its* latest factor with that factor's error as the scale's
uncertainty, as the monitor's own remaining life does
(:func:`faultgen.monitor.friction_tests.on_tests_scale`); scores.csv keeps each log on the factor of
its own day, a mosaic whose steps at each test bent the trend (hump law seed 1, unit09: 133.9 days
where 16.1 remained; docs/analysis.md, "Second session of 2026-11-27"). ``--scores-only``: that mosaic, as before 2026-11-27.

In one run of this script:

- the fleet (tests/independent_fleet.py: Pinocchio RNEA on rtb-data's KR210 URDF, our own
  motor-side friction, seasons, payloads, noise; ``--worn`` units wearing one axis each, linearly
  from a day drawn in 20-50 to ``--final-wear`` % on the last day), its truth in ``truth.csv``;
- `faultgen monitor LOGS --no-calibrate --failure-wear F` (the twin on the nominal model), timed
  (not with ``--fleet``);
- for each worn unit whose alarm names its worn axis: the remaining life of that axis computed as
  the monitor computes it (:func:`faultgen.monitor.prognosis.remaining_life` on the unit's rows of
  ``scores.csv`` up to each log, from the log that made the alarm persistent to the last), a
  profile of ProgPy time-of-event distributions (``ToEPredictionProfile``), scored against two
  end-of-life times:

  (A) **the true wear reaches F** (truth.csv only: independent of the monitor). The estimate is in
      % of the axis's own dry friction (0.82-1.23 % per % of true wear on this fleet; in the twin's
      scale before issue 59 part 1, 0.4-0.7, and the remaining life was late by a factor 1.4-2): its
      bias is reported, not hidden;
  (B) **the estimate's trend reaches F**: the day the unit's true wear, times its twin's scale (a
      straight line of the worn axis's estimate on the true wear, fitted in hindsight over the logs
      past 5 % true wear), reaches F; the true wear grows linearly, so this day is defined beyond
      the record too. Not independent (the scale is fitted on the estimates themselves): it says
      how well the trend is extrapolated, apart from the twin's scale.

Metrics (``progpy.metrics``, Saxena et al. 2010): alpha-lambda with alpha 0.2 and beta 0.5 (at least
half the distribution within +-20 % of the true remaining life) at lambda 0.5 (the first prediction
half-way from the persistent alarm to the end of life), with the share of the distribution that
lies within those bounds there and the distribution's 5-95 % width over the true remaining life
(to tell a late or early median from a wide distribution); the relative accuracy there and cumulated
over the predictions before the end of life; the prognostic horizon (the end-of-life time minus the
first prediction meeting the alpha criterion with beta 0.5); the median bias of the estimate (days,
predicted minus true remaining life). A sample beyond the prediction's horizon (365 days) enters the
metrics at the horizon (ProgPy drops a None sample from a mean). **Issue 75's figures** (:mod:`faultgen.bench.rul_scores`), at the first
prediction at or after (A)'s lambda, whatever its verdict: whether the 5-95 % interval covers the
true remaining life (criterion without friction tests: on at least 80 % of the worn units), whether
the median is late by more than alpha (20 %) of it (at most 20 % of the units without tests, none
with them), the PHM 2008 score of the median (Saxena et al. 2008); a "not yet predictable" there
counts as neither covering nor late, and its units are counted. A table per unit (markdown) and the
fleet's lines, each figure beside its criterion and verdict (met / NOT met). Before them, every
unit's remaining life at its last log as rul.csv gives it: the axes that do not wear with an end of
life within the horizon, the healthy units' within the fleet's span. **Reachable**: per unit, how far
from the true remaining life at (A)'s lambda an exact prediction of the day the estimate reaches F
(B's end of life) would be, ``(B - A) / (A - lambda)``; beyond alpha no trend fitted to that estimate
can meet (A)'s alpha-lambda, however sharp: the count bounds (A)'s criterion by the wear estimate.
"""

from __future__ import annotations

import argparse
import csv
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import independent_fleet
from benchmarks_common import fleet_options  # sibling module

from faultgen import children
from faultgen.bench import rul_scores
from faultgen.monitor import prognosis, tables

ALPHA, BETA, LAMBDA = 0.2, 0.5, 0.5
#: The monitor's defaults the benchmark replays (faultgen.monitor.scoring.Settings).
MONITOR_ALPHA, PERSISTENCE = 0.01, 5


def _absolute(toe, t_prediction: float, horizon: float):
    """ProgPy's time-to-event samples (from the prediction) as times of event (days), a sample beyond
    the horizon at the horizon."""
    from progpy.uncertain_data import UnweightedSamples

    return UnweightedSamples([{"failure": t_prediction + (horizon if v is None else v)} for v in toe.key("failure")])


def score(profile, eol: float, start: float, record_end: float) -> dict:
    """ProgPy's metrics of ``profile`` (times of prediction, day) against the end of life ``eol``
    (day); ``start`` the persistent alarm's day."""
    from progpy.metrics import alpha_lambda, prognostic_horizon
    from progpy.predictors import ToEPredictionProfile

    before = ToEPredictionProfile()
    for t, toe in profile.items():
        if t < eol:
            before.add_prediction(t, toe)
    truth = {"failure": eol}
    lam = start + LAMBDA * (eol - start)
    out = {"eol": eol, "lambda": lam, "predictions": len(before)}
    if not len(before):
        return out
    if lam <= max(before.keys()):
        out["alpha_lambda"] = bool(alpha_lambda(before, truth, lam, ALPHA, BETA)["failure"])
        at = min(t for t in before if t >= lam)
        out["ra_lambda"] = (before[at] - at).relative_accuracy({"failure": eol - at})["failure"]
        # what alpha-lambda judges there: the share of the distribution within +-alpha of the true
        # remaining life (met at >= beta), and the distribution's 5-95 % width over the true remaining life
        rul = eol - at
        out["mass_lambda"] = float((before[at] - at).percentage_in_bounds(
            {"failure": (rul * (1 - ALPHA), rul * (1 + ALPHA))})["failure"])
        samples = np.asarray((before[at] - at).key("failure"), dtype=float)
        low, high = np.percentile(samples, [5, 95])
        out["width_lambda"] = float((high - low) / rul)
        out["covers_lambda"] = bool(low <= rul <= high)
    else:
        out["alpha_lambda"] = None  # the record ends before lambda

    def criterion(tte, tte_truth):
        bounds = {k: (v - ALPHA * v, v + ALPHA * v) for k, v in tte_truth.items()}
        return {k: p >= BETA for k, p in tte.percentage_in_bounds(bounds).items()}

    out["ph"] = prognostic_horizon(before, criterion, truth)["failure"]
    # Saxena's cumulative relative accuracy on the remaining life: ProgPy's relative accuracy of each
    # prediction's remaining-life distribution against the true remaining life then (its
    # cumulative_relative_accuracy takes one ground truth for every prediction: a time of event, not
    # a remaining life), averaged
    out["cra"] = float(np.mean([(toe - t).relative_accuracy({"failure": eol - t})["failure"]
                                for t, toe in before.items()]))
    out["bias"] = float(np.median([np.median(toe.key("failure")) - eol for toe in before.values()]))
    out["end_of_record"] = record_end
    return out


def day_of(wear: np.ndarray, level: float) -> float:
    """The day (day 1 = the first log) the true wear series ``wear`` (one value a day, %) first
    reaches ``level`` %, linearly interpolated between days; beyond the record, extended along
    the last day's rate."""
    above = np.flatnonzero(wear >= level)
    if above.size and above[0] > 0:
        i = int(above[0])
        return i + (level - wear[i - 1]) / (wear[i] - wear[i - 1])  # between day i and day i + 1
    rate = wear[-1] - wear[-2]
    return len(wear) + (level - wear[-1]) / rate


def estimate_line(wear: np.ndarray, day: dict[str, int], rows: list[dict], axis: int) -> tuple[float, float]:
    """The scale and offset of ``axis``'s wear estimate on the true wear: the least-squares line of
    its monitoring ``rows``' ``wear<axis>`` (scores.csv) on the true ``wear`` (one value a day, %;
    ``day``: stamp -> day, 1-based) where the true wear is past 5 %."""
    past = [(wear[day[r.stamp] - 1], float(r.wear.estimate[axis - 1])) for r in rows
            if r.phase == "monitoring" and wear[day[r.stamp] - 1] >= 5]
    scale, offset = np.polyfit(*zip(*past), 1)
    return float(scale), float(offset)


def exact_crossing_error(wear: np.ndarray, scale: float, offset: float, start: int, failure: float) -> float:
    """(the day the estimate, ``scale`` x the true ``wear`` + ``offset``, reaches ``failure`` - the true
    end of life) over the true remaining life at lambda, ``start`` the persistent alarm's day: what
    an exact prediction of the estimate's own crossing would be off by ("reachable" within +-ALPHA)."""
    eol = day_of(wear, failure)
    lam = start + LAMBDA * (eol - start)
    return (day_of(wear, (failure - offset) / scale) - eol) / (eol - lam)


def replayed_rows(fleet: Path, out: Path, robot: Path | None = None) -> dict[str, list[dict]] | None:
    """Each unit's monitor rows (``UnitHistory.rows``, with the twin-scale columns and the factors
    scores.csv does not keep) of a run of ``benchmarks/monitor_wear_scale.py`` with friction tests:
    the state in ``out/.state`` replayed with the tests read from ``out``'s cache (the robot
    ``robot``, default ``fleet/kr210``, the logs ``fleet/logs``), as a continued monitor run replays it;
    None without tests."""
    from faultgen.model import robots
    from faultgen.monitor import friction_tests, history, steps
    from faultgen.monitor import logs as fleet_logs
    from faultgen.monitor import state as stored
    from faultgen.monitor.scoring import Settings

    _, suffixes = fleet_logs.reader_of()
    units = fleet_logs.fleet(fleet / "logs", suffixes)
    found = friction_tests.find(fleet / "logs", units, suffixes)
    if not any(found.values()):
        return None
    robot = fleet / "kr210" if robot is None else robot
    if not robot.is_dir():
        raise SystemExit(f"{robot}: no robot folder there (benchmarks/monitor_wear_scale.py makes it); "
                         "expected the fleet's KR210 to replay its monitor's state, or --scores-only")
    nominal = robots.load(robot)
    tests = friction_tests.read_tests(found, nominal, out)
    n, rows = nominal.n_axes, {}
    for name in units:
        path = out / ".state" / stored.unit_file(name, ".json")
        key = json.loads(path.read_text())["settings"]
        kept = history.read_unit(path, out, name, key, n, len(fleet_logs.FEATURES) * n)
        settings = Settings(**{k: key[k] for k in ("protocol", "train", "alpha", "variance", "persistence",
                                                   "wear_limit")})
        wears, _ = friction_tests.tests_wear(tests.get(name, []), n, ())
        rescale = friction_tests.Rescale(name, n, wears) if wears else None
        rows[name] = steps.replay(kept, settings, n, rescale).rows
    return rows


def on_scale(rows: list[dict], scale_uncertainty, tested: bool):
    """``rows`` and the scale uncertainty as the monitor's remaining life takes them: with friction
    tests each estimate on the *latest* row's factor and that factor's relative error
    (:func:`faultgen.monitor.friction_tests.on_tests_scale`), else as given."""
    from faultgen.monitor import friction_tests

    if not tested:
        return rows, scale_uncertainty
    rescaled, uncertainty = friction_tests.on_tests_scale(rows, 6)
    return rescaled, scale_uncertainty if uncertainty is None else uncertainty


def unit_rows(scores: list[dict], replayed: dict[str, list[dict]] | None, unit: str) -> tuple[list[dict], bool]:
    """``unit``'s rows: its replayed monitor rows with friction tests (:func:`replayed_rows`; each
    prediction then on its latest factor, :func:`on_scale`) and True, else scores.csv's and False."""
    rows = [r for r in scores if r.unit == unit]
    if replayed is None or unit not in replayed:
        return rows, False
    if [r.stamp for r in replayed[unit]] != [r.stamp for r in rows]:
        raise SystemExit(f"{unit}: the replayed state's logs are not scores.csv's: is OUT/.state this run's?")
    return replayed[unit], True


def run_fleet(args) -> tuple[Path, Path]:
    """Write the fleet (or resume it in ``--work``) and run the monitor on it; returns (truth.csv, OUT)."""
    work = args.work or Path(tempfile.mkdtemp(prefix="monitor-rul-"))
    spec = independent_fleet.FleetSpec(units=args.units, worn=args.worn, days=args.days, seed=args.seed,
                                       final_wear=args.final_wear)
    started = time.perf_counter()
    kept = work / "fleet" / "kr210"  # a rerun in the same --work keeps the robot folder (and resumes the fleet)
    robot, logs, truth_path = independent_fleet.write_fleet(work / "fleet", spec, robot=kept if kept.is_dir() else None)
    print(f"fleet of {args.units} units x {args.days} days ({args.worn} worn to {args.final_wear:g} %) written by "
          f"Pinocchio in {time.perf_counter() - started:.0f} s: {logs}")
    out = work / "monitor"
    command = [*children.command("-m", "faultgen.cli"), "monitor", str(logs), "--robot", str(robot), "-o", str(out),
               "--no-calibrate", "--failure-wear", f"{args.failure_wear:g}"]
    started = time.perf_counter()
    result = subprocess.run(command, env=children.environment(), check=False, capture_output=True, text=True)
    if result.returncode:
        raise SystemExit(f"{' '.join(command)} failed:\n{result.stderr[-3000:]}")
    print(f"faultgen monitor --no-calibrate --failure-wear {args.failure_wear:g}: {time.perf_counter() - started:.0f} s")
    return truth_path, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    fleet_options(parser, units=6, worn=4)
    parser.add_argument("--final-wear", type=float, default=60.0)
    parser.add_argument("--failure-wear", type=float, default=prognosis.FAILURE_WEAR)
    parser.add_argument("--fleet", type=Path, default=None,
                        help="Score an existing run of benchmarks/monitor_wear_scale.py instead (its WORK: truth.csv "
                             "and the monitor's OUT, --out): the remaining life is recomputed from its scores.csv "
                             "with --failure-wear; no fleet is written and no monitor run.")
    parser.add_argument("--out", default="monitor", help="With --fleet: the monitor's OUT inside it.")
    parser.add_argument("--from-alarm", action="store_true",
                        help="Fit the alarm's source axis from its alarm on, not with the changepoint trend over its "
                             "whole block (the monitor's rule before 2026-11-26).")
    parser.add_argument("--scale-uncertainty", type=float, default=None,
                        help="Relative standard uncertainty of the wear estimate's scale carried into the time of "
                             "event, drawn normal (0.10 before 2026-11-27; 0 as before 2026-11-26); default: the "
                             "monitor's, log-normal with faultgen.monitor.prognosis.TWIN_SCALE_LOG_SD without "
                             "friction tests.")
    parser.add_argument("--scores-only", action="store_true",
                        help="With --fleet and friction tests: fit scores.csv's estimates, each log on the factor "
                             "of its own day, with --scale-uncertainty (the benchmark before 2026-11-27), not the "
                             "replayed rows on the latest factor as the monitor's remaining life takes them.")
    args = parser.parse_args()
    replayed = None
    if args.fleet is not None:
        truth_path, out = args.fleet / "truth.csv", args.fleet / args.out  # scores.csv does not depend on F
        print(f"scoring the existing run {out} against {truth_path}")
        if not args.scores_only:
            replayed = replayed_rows(args.fleet, out)
            if replayed is not None:
                print("friction tests: each prediction on its latest factor, the factor's error as the scale's "
                      "uncertainty (faultgen.monitor.friction_tests.on_tests_scale)")
    else:
        truth_path, out = run_fleet(args)
    evaluate(truth_path, out, args.failure_wear, not args.from_alarm, args.scale_uncertainty, replayed)


def _at_lambda(predictions: list[tuple[int, prognosis.Remaining]], eol: float, start: float) -> dict:
    """The issue-75 figures of the first prediction at or after lambda (``start`` + LAMBDA (``eol`` -
    ``start``)), whatever its verdict: its median and 5-95 % interval, the true remaining life, and
    whether it is a number, covers the truth, is late by more than ALPHA, its PHM 2008 score."""
    lam = start + LAMBDA * (eol - start)
    after = [(d, r) for d, r in predictions if d >= lam and d < eol]
    if not after:
        return {"lambda": lam, "at": None}
    day, row = after[0]
    true = eol - day
    out = {"lambda": lam, "at": day, "true": true, "predictable": row.rul is not None, "verdict": row.verdict,
           "models": getattr(row, "models", "")}
    if row.rul is not None:
        out.update(median=row.rul, low=row.rul_5, high=row.rul_95,
                   covers=rul_scores.covers(row.rul_5, row.rul_95, true), late=rul_scores.late(row.rul, true),
                   phm08=float(rul_scores.phm08_score(row.rul, true)))
    return out


def quiet_axes(truth: dict, scores: list[dict], alarms: dict, failure_wear: float, changepoint: bool,
               scale_uncertainty, replayed: dict[str, list[dict]] | None = None) -> None:
    """Every unit's remaining life at its last log as the monitor writes it in rul.csv: the axes that
    do not wear with an end of life within the horizon, the healthy units' within the fleet's span."""
    span = max(len(t["wear"]) for t in truth.values())
    within, healthy, others = [], 0, 0
    for unit, t in truth.items():
        rows, uncertainty = [r for r in scores if r.unit == unit], scale_uncertainty
        if replayed is not None and unit in replayed:
            rows, uncertainty = on_scale(replayed[unit], scale_uncertainty, True)
        alarm = alarms[unit]
        source = int(alarm["source_axis"]) if alarm["source_axis"] else None
        for row in prognosis.remaining_life(unit, rows, 6, alpha=MONITOR_ALPHA, failure_wear=failure_wear,
                                            since=alarm["first_alarm"] or None, source_axis=source,
                                            changepoint=changepoint, scale_uncertainty=uncertainty):
            if row.axis == t["axis"]:
                continue
            others += 1
            healthy += not t["axis"]
            if row.rul is not None:
                within.append((unit, row.axis, row.rul, bool(t["axis"])))
    early = [w for w in within if not w[3] and w[2] <= span]
    print(f"axes that do not wear, at the last log: {others - len(within)} of {others} with no end of life within "
          f"the horizon ({', '.join(f'{u} axis {a} in {r:.0f} days' for u, a, r, _ in within) or 'none has one'}); "
          f"healthy units: {len(early)} of {healthy} axes with an end of life within the fleet's {span} days "
          f"(none: {verdict(not early)})")


def verdict(ok: bool) -> str:
    return "met" if ok else "NOT met"


def evaluate(truth_path: Path, out: Path, failure_wear: float, changepoint: bool = True,
             scale_uncertainty: float | None = None,
             replayed: dict[str, list[dict]] | None = None) -> dict[str, list[dict]]:
    """Score the remaining life of every worn unit of the run ``out`` against ``truth_path`` (module
    docstring); prints a block per unit and the fleet's lines, each figure beside the criterion of
    issue 75 and its verdict; returns the scores of (A) and (B) (each with ``at_lambda``); ``replayed``:
    :func:`unit_rows`."""
    truth = independent_fleet.read_truth(truth_path)
    with open(out / "scores.csv", newline="") as f:
        scores = tables.log_rows(list(csv.DictReader(f)))
    with open(out / "alarms.csv", newline="") as f:
        alarms = {r["unit"]: r for r in csv.DictReader(f)}
    F, H = failure_wear, prognosis.HORIZON
    quiet_axes(truth, scores, alarms, F, changepoint, scale_uncertainty, replayed)
    results = {"A": [], "B": []}
    started = time.perf_counter()
    from progpy.predictors import ToEPredictionProfile

    for unit, t in truth.items():
        if not t["axis"]:
            continue
        alarm, axis = alarms[unit], t["axis"]
        if not alarm["first_alarm"] or int(alarm["source_axis"]) != axis:
            print(f"\n{unit}: worn axis {axis}, alarm {alarm['first_alarm'] or 'none'} on axis "
                  f"{alarm['source_axis'] or '-'}: not scored")
            continue
        rows, tested = unit_rows(scores, replayed, unit)
        stamps = [r.stamp for r in rows]
        day = {s: i + 1 for i, s in enumerate(t["stamps"])}  # day 1 = the first log
        wear = t["wear"]
        true_eol = day_of(wear, F)  # (A)
        scale, offset = estimate_line(wear, day, on_scale(rows, scale_uncertainty, tested)[0], axis)
        estimate_eol = day_of(wear, (F - offset) / scale)  # (B)
        first = stamps.index(alarm["first_alarm"])
        start = day[stamps[first + PERSISTENCE - 1]]
        profile, predictions = ToEPredictionProfile(), []
        for j in range(first + PERSISTENCE - 1, len(rows)):
            now = day[rows[j].stamp]
            if now >= max(true_eol, estimate_eol):  # the metrics take the predictions before the end of life
                break
            upto, uncertainty = on_scale(rows[: j + 1], scale_uncertainty, tested)
            (row,) = prognosis.remaining_life(unit, upto, 6, alpha=MONITOR_ALPHA, failure_wear=F,
                                              since=alarm["first_alarm"], source_axis=axis, axes=[axis],
                                              changepoint=changepoint, scale_uncertainty=uncertainty)
            if row.rul is not None:  # a "not yet predictable" or no end of life gives no number
                profile.add_prediction(now, _absolute(row.distribution, now, H))
            predictions.append((now, row))
        print(f"\n{unit}: worn axis {axis}, true wear {F:g} % on day {true_eol:.1f}; estimate {scale:.2f} x true wear "
              f"{offset:+.1f} %, so {F:g} % estimated on day {estimate_eol:.1f}; alarm persistent on day {start}; "
              f"{len(profile)} of {len(predictions)} predictions before the end of life with a number")
        shown = predictions[:: max(1, len(predictions) // 6)]
        print("  day: predicted remaining life (median; '?' not yet predictable), true (A): " + "; ".join(
            f"{d}: {'?' if r.rul is None else f'{r.rul:.0f}'}, {true_eol - d:.0f}" for d, r in shown))
        for name, eol in (("A", true_eol), ("B", estimate_eol)):
            s = score(profile, eol, start, len(wear))
            s["unit"], s["axis"] = unit, axis
            s["at_lambda"] = _at_lambda(predictions, eol, start)
            if name == "A":  # a prediction of the estimate's own crossing, exact, judged against the truth
                s["perfect_error"] = exact_crossing_error(wear, scale, offset, start, F)
            results[name].append(s)
            if name == "B":
                continue
            a = s["at_lambda"]
            al = {None: "n/a", True: "met", False: "not met"}[s.get("alpha_lambda")]
            ph = "none" if s.get("ph") is None else f"{s['ph']:.0f} days"
            if a["at"] is None:
                print(f"  (A) end of life day {eol:.1f}: no prediction at lambda (day {a['lambda']:.1f})")
            elif not a["predictable"]:
                print(f"  (A) at lambda (day {a['at']}, true remaining life {a['true']:.1f} days): {a['verdict']}")
            else:
                print(f"  (A) at lambda (day {a['at']}): median {a['median']:.1f} days, 5-95 % {a['low']:.1f}-"
                      f"{'beyond' if a['high'] is None else format(a['high'], '.1f')}, true {a['true']:.1f}: "
                      f"{'covers' if a['covers'] else 'does NOT cover'}, {'LATE' if a['late'] else 'not late'} "
                      f"(> {ALPHA:g}), PHM 2008 score {a['phm08']:.2f}; models {a['models']}")
            print(f"      alpha-lambda {al}; RA at lambda {s.get('ra_lambda', float('nan')):.2f}; prognostic horizon "
                  f"{ph}; median bias {s.get('bias', float('nan')):+.1f} days; exact crossing of the estimate off by "
                  f"{s['perfect_error']:+.2f} ({'reachable' if abs(s['perfect_error']) <= ALPHA else 'out of reach'})")
    print(f"\nprofiles computed in {time.perf_counter() - started:.0f} s")
    summarise(results)
    return results


def summarise(results: dict[str, list[dict]]) -> None:
    """The fleet's lines: each figure of issue 75 beside its criterion and verdict (module docstring)."""
    rs = results["A"]
    n = len(rs)
    print("\n| unit (axis) | at lambda: day, true RUL | median (5-95 %), days | covers | late > 20 % | PHM 2008 | "
          "RA at lambda | alpha-lambda | PH, days | models (weights) |\n| --- | --- | --- | --- | --- | --- | --- | --- | "
          "--- | --- |")
    for r in rs:
        a = r["at_lambda"]
        if a.get("at") is None:
            cells = ["-", "no prediction at lambda", "-", "-", "-"]
        elif not a["predictable"]:
            cells = [f"{a['at']}, {a['true']:.1f}", "not yet predictable: " + a["verdict"].split(": ", 1)[1].split(" (median ")[0],
                     "no", "no", "-"]
        else:
            high = "beyond" if a["high"] is None else f"{a['high']:.1f}"
            cells = [f"{a['at']}, {a['true']:.1f}", f"{a['median']:.1f} ({a['low']:.1f}-{high})",
                     "yes" if a["covers"] else "**no**", "**LATE**" if a["late"] else "no", f"{a['phm08']:.2f}"]
        al = {None: "n/a", True: "met", False: "not met"}[r.get("alpha_lambda")]
        print(f"| {r['unit']} ({r['axis']}) | " + " | ".join(cells) + f" | {r.get('ra_lambda', float('nan')):.2f} | {al} | "
              f"{'-' if r.get('ph') is None else format(r['ph'], '.0f')} | {a.get('models') or '-'} |")
    at = [r["at_lambda"] for r in rs]
    numbers = [a for a in at if a.get("predictable")]
    covered = sum(bool(a.get("covers")) for a in at)
    late = sum(bool(a.get("late")) for a in at)
    unknown = sum(a.get("at") is not None and not a.get("predictable") for a in at)
    met = sum(r.get("alpha_lambda") is True for r in rs)
    phs = [r["ph"] for r in rs if r.get("ph") is not None]
    phm = [a["phm08"] for a in numbers]
    ra = [r["ra_lambda"] for r in rs if "ra_lambda" in r]
    print(f"(A) true wear reaches F, {n} worn units scored; at lambda {unknown} 'not yet predictable' "
          "(counted as not covering and not late):")
    print(f"  5-95 % interval covers the true remaining life at lambda: {covered} of {n} (>= 80 %: "
          f"{verdict(n and covered >= 0.8 * n)})")
    print(f"  median late by more than {ALPHA:.0%} of the true remaining life at lambda: {late} of {n} (<= 20 % "
          f"without friction tests: {verdict(late <= 0.2 * n)}; none with them: {verdict(late == 0)})")
    print(f"  alpha-lambda (alpha {ALPHA}, beta {BETA}, lambda {LAMBDA}): {met} of {n} (>= 80 % with friction tests: "
          f"{verdict(n and met >= 0.8 * n)})")
    print(f"  relative accuracy at lambda: median {np.median(ra) if ra else float('nan'):.2f} "
          f"({', '.join(f'{v:.2f}' for v in ra)}); prognostic horizon on {len(phs)} of {n} units "
          f"({', '.join(f'{p:.0f}' for p in phs) or '-'} days); PHM 2008 score at lambda: sum {sum(phm):.2f} over "
          f"{len(phm)} units with a number ({', '.join(f'{v:.2f}' for v in phm)})")
    b = results["B"]
    print(f"(B) the estimate's own crossing (hindsight): alpha-lambda {sum(r.get('alpha_lambda') is True for r in b)} "
          f"of {len(b)}; covers at lambda {sum(bool(r['at_lambda'].get('covers')) for r in b)}; late "
          f"{sum(bool(r['at_lambda'].get('late')) for r in b)}")
    reachable = sum(abs(r["perfect_error"]) <= ALPHA for r in rs)
    print(f"(A) reachable: an exact prediction of each estimate's crossing within +-{ALPHA:g} of the true remaining "
          f"life at lambda on {reachable} of {n} units")


if __name__ == "__main__":
    main()
