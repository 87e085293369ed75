"""The verdict of every ``faultgen bench score`` figure against what chance gets.

A figure alone says nothing: a detector that alarms on every record "detects" every failing unit.
Each figure of :mod:`faultgen.bench.score` is therefore judged against the value a method that does
not look at the data gets, by its 95 % bootstrap interval over test units:

- **above chance** when the whole interval lies above the chance level, **below chance** when it
  lies below, **at chance** when it holds it (:func:`word`);
- AUROC against 0.5; the detection rate at a 5 % false-alarm rate against 5 % (the share of worn
  records a detector that does not separate them alarms on at that rate); the share of failing
  units detected against the share a detector alarming at random at the observed false-alarm rate
  detects (:func:`chance_detected`) or, if larger, the share of healthy units on which the method's
  own alarms make an onset, by the interval of the difference and the range chance alone gives on
  as many units (:func:`detected_word`); isolation top-1 and fault
  type accuracy against 1 / the number of axes or fault types;
- the detection delay gets no verdict of its own: it is a delay only where detection is above chance.

:func:`records_needed` gives the records per unit below which an isolator's figure says nothing
(transfer entropy's plug-in estimate), for the warning of :func:`lines`.
"""

from __future__ import annotations

import numpy as np

from faultgen.checks import is_whole

#: Tolerance of the comparison with a chance level (a figure equal to it up to rounding is at chance).
TOLERANCE = 1e-9


def word(low: float, high: float, chance: float) -> str:
    """"above chance", "below chance" or "at chance": where the interval ``[low, high]`` lies
    relative to ``chance`` (same unit, e.g. a share 0..1); "no verdict" when the interval is not
    finite (too few units to resample)."""
    if not (np.isfinite(low) and np.isfinite(high)):
        return "no verdict"
    if low > chance + TOLERANCE:
        return "above chance"
    if high < chance - TOLERANCE:
        return "below chance"
    return "at chance"


def chance_detected(n_records, rate: float, persistence: int):
    """Probability that a detector alarming on each of ``n_records`` records independently with
    probability ``rate`` raises ``persistence`` alarms in a row somewhere (the onset rule of
    :func:`analysis.monitoring.detect_onset`): the share of failing units it "detects".

    Exact, by the Markov chain of the current run length (0 .. persistence - 1, and "run seen"),
    stepped once up to the largest ``n_records``.

    Parameters
    ----------
    n_records : int or array-like of int, shape (n_units,)
        Records of a unit (each >= 0).
    rate : float
        Probability of an alarm per record, in [0, 1].
    persistence : int
        Alarms in a row that make an onset, >= 1.

    Returns
    -------
    float, or ndarray of shape (n_units,) for an array ``n_records``

    Raises
    ------
    ValueError
        If a record count is not an integer >= 0, ``persistence`` not one >= 1, or ``rate`` not in [0, 1].
    """
    counts = np.asarray(n_records)
    if not np.issubdtype(counts.dtype, np.integer) or (counts < 0).any() or not is_whole(persistence, 1):
        raise ValueError(f"n_records = {n_records!r}, persistence = {persistence!r}: expected integers >= 0 and >= 1")
    if not 0.0 <= rate <= 1.0:
        raise ValueError(f"rate = {rate!r}: expected a probability in [0, 1]")
    state = np.zeros(persistence + 1)
    state[0] = 1.0
    seen = np.zeros(int(counts.max(initial=0)) + 1)  # seen[n]: a run within the first n records
    for n in range(1, seen.size):
        step = np.zeros_like(state)
        step[0] = state[:persistence].sum() * (1.0 - rate)
        step[1:persistence + 1] = state[:persistence] * rate
        step[persistence] += state[persistence]
        state = step
        seen[n] = state[persistence]
    return seen[counts] if counts.ndim else float(seen[counts])


def chance_range(n_units: int, chance: float) -> list[float]:
    """Central 95 % range [2.5 %, 97.5 % quantile] of the share of ``n_units`` units a detector
    detects when it detects each one with probability ``chance`` (binomial, ``scipy.stats.binom``);
    [nan, nan] when ``chance`` is not finite or there is no unit. A detected share inside it is
    what chance gives on so few units, whatever the bootstrap interval says (a share of 0 or 1 has
    a bootstrap interval of one point)."""
    from scipy.stats import binom

    if not n_units or not np.isfinite(chance):
        return [float("nan"), float("nan")]
    return [float(binom.ppf(q, n_units, chance)) / n_units for q in (0.025, 0.975)]


def detected_word(detected: dict, difference: dict) -> str:
    """The detected share's verdict: above (below) chance when the bootstrap interval of its
    difference from chance lies above (below) 0 and the share lies above (below) the range chance
    gives on as many units (:func:`chance_range`); else at chance ("no verdict" when undefined)."""
    word_ = word(difference["ci95"][0], difference["ci95"][1], 0.0)
    low, high = detected.get("chance_range95", [float("nan")] * 2)
    if word_ == "no verdict" or not np.isfinite(low):
        return "no verdict"
    if word_ == "above chance" and detected["value"] > high + TOLERANCE:
        return word_
    if word_ == "below chance" and detected["value"] < low - TOLERANCE:
        return word_
    return "at chance"


def records_needed(method) -> tuple[int, str] | None:
    """(records per unit, why) below which ``method``'s isolation figure says nothing, or None when
    the benchmark knows no such limit for it (any isolator but transfer entropy's).

    Transfer entropy (:class:`analysis.isolation.TransferEntropyIsolator`, ``bins`` quantile symbols,
    history ``h``) is a plug-in estimate: the transfer from one axis to another is counted only over
    the target's past states (``bins ** h`` of them) seen more than once, so it needs each of them
    seen a few times: ``3 * bins ** h + h`` records. Measured on 6 irb6700 pick-and-place
    runs of 100 cycles (exp4 to +20 % on each axis in turn, seed 1), transfer entropy on 30 random
    subsets of n cycles each: with 10 bins it named the worn axis on 0 % of them at n = 12 (71 %
    undecided: tied scores), 3 % at 16, 26 % at 21, 50 % at 26, 69 % at 31, 81-84 % at 36-51; with 5
    bins 60 % at 16, 71 % at 21, 82 % at 31. The thesis small track has 12 records a unit.
    """
    from analysis.isolation import TransferEntropyIsolator

    inner = method.build() if hasattr(method, "build") else method  # a plug-in: the user's own class
    if not isinstance(inner, TransferEntropyIsolator):
        return None
    bins, history = int(inner.bins), int(inner.history)
    need = 3 * bins**history + history
    return need, (f"transfer entropy with {bins} bins and history {history} counts only the target's past states "
                  f"seen more than once and needs each of its {bins}^{history} past states seen about 3 times: "
                  f"3 x {bins}^{history} + {history} = {need} records; with fewer its scores tie or are noise "
                  "(docs/bench.md)")


def _figure_line(name: str, figure: dict, scale: float, unit: str, against: str, short: bool = False) -> str:
    value, (low, high) = figure["value"] * scale, (x * scale for x in figure["ci95"])
    if not np.isfinite(value):
        return f"{name}: no verdict (undefined on these test units; {against})"
    verdict = ("no verdict, the track is too short for the method" if short
               else word(figure["ci95"][0], figure["ci95"][1], figure["chance"]))
    return f"{name} {value:.{3 if scale == 1 else 1}f}{unit} [{low:.{3 if scale == 1 else 1}f}, " \
           f"{high:.{3 if scale == 1 else 1}f}]: {verdict} ({against})"


def detector_lines(r: dict) -> list[str]:
    """The verdict lines of a detector's results (``results["results"]`` of
    :func:`faultgen.bench.score.score`)."""
    out = [_figure_line("AUROC", r["auroc"], 1.0, "", "chance 0.5: scores that do not separate worn records "
                                                       "(>= 10 %) from healthy ones")]
    at = r["detection_at_5pct_far"]
    out.append(_figure_line("detection at 5 % false alarms", at, 100.0, " % of worn records",
                            "chance 5.0 %: the threshold set on the healthy test units' scores so that 5 % of "
                            "their records alarm; a detector that does not separate alarms on 5 % of worn records"))
    det, diff, far = r["detected_share"], r["detected_minus_chance"], r["false_alarm_rate"]
    verdict = detected_word(det, diff)
    if np.isfinite(det["value"]) and not np.isfinite(det["chance"]):
        out.append(f"detected {100 * det['value']:.1f} % of failing units: no verdict (no healthy test unit to "
                   "measure the false-alarm rate its chance depends on)")
    elif np.isfinite(det["value"]):
        out.append(f"detected {100 * det['value']:.1f} % of failing units: {verdict} (chance "
                   f"{100 * det['chance']:.1f} %, the larger of: alarms at random on {100 * far['value']:.1f} % of "
                   f"records, the healthy units' false-alarm rate, detect {100 * det['chance_random_alarms']:.1f} %; "
                   f"the method's own alarms make an onset on {100 * det['healthy_units_detected']:.1f} % of the "
                   f"healthy units; difference {100 * diff['value']:+.1f} points "
                   f"[{100 * diff['ci95'][0]:+.1f}, {100 * diff['ci95'][1]:+.1f}]; chance alone detects "
                   f"{100 * det['chance_range95'][0]:.1f}-{100 * det['chance_range95'][1]:.1f} % of "
                   f"{det['units']} units)")
    else:
        out.append("detected: no verdict (no failing test unit)")
    delay = next(v for k, v in r.items() if k.startswith("delay_after_10pct"))
    early = sum(1 for u in r["per_unit"] if u["detected"] and u["after_start"] < 0)
    detected = sum(1 for u in r["per_unit"] if u["detected"])
    if verdict == "above chance" and np.isfinite(delay["value"]):
        out.append(f"delay after 10 % wear {delay['value']:.1f} [{delay['ci95'][0]:.1f}, {delay['ci95'][1]:.1f}]: "
                   f"a detection delay (detection above chance); the onset came before the fault started on "
                   f"{early} of {detected} units detected")
    else:
        share = "has no verdict" if verdict == "no verdict" else f"is {verdict}"
        out.append(f"delay: no verdict (the detected share {share}: a delay means something only where detection "
                   f"beats chance; the onset came before the fault started on {early} of {detected} units detected)")
    return out


def named_none(r: dict) -> bool:
    """True when an isolator left every worn test unit undecided (named no axis: its top-1 of 0 is
    an abstention, not a wrong answer, and says nothing either way)."""
    worn = [u for u in r.get("per_unit", []) if u.get("worn_axis")]
    return bool(worn) and all(u["named"] == 0 for u in worn)


def isolator_lines(r: dict) -> list[str]:
    """The verdict lines of an isolator's results, the too-short warning first."""
    out = [f"WARNING: {w}" for w in r.get("warnings", [])]
    top1 = r["top1_accuracy"]
    against = f"chance {100 * top1['chance']:.1f} %: one axis of {round(1 / top1['chance'])} named at random"
    if named_none(r) and not r.get("warnings"):
        worn = sum(1 for u in r["per_unit"] if u["worn_axis"])
        out.append(f"isolation top-1 0.0 %: no verdict (the method named no axis on any of the {worn} worn units: "
                   f"it says nothing; {against})")
    else:
        out.append(_figure_line("isolation top-1", top1, 100.0, " %", against, short=bool(r.get("warnings"))))
    if "fault_type_accuracy" in r:
        kind = r["fault_type_accuracy"]
        out.append(_figure_line("fault type", kind, 100.0, " %", f"chance {100 * kind['chance']:.1f} %: one of "
                                f"{round(1 / kind['chance'])} fault types named at random"))
    return out


#: The verdict's mark on the results of a folder that differs from its track's frozen manifest.
NOT_COMPARABLE = "NOT COMPARABLE: the data differ from the track's frozen manifest"


def modified_lines(results: dict) -> list[str]:
    """The warning lines of results scored with ``allow_modified`` on a folder that differs from its
    frozen manifest (:func:`faultgen.bench.make.compare`): the mark and each differing file and array
    named; none for a folder equal to it."""
    if results.get("comparable", True):
        return []
    named, count = results.get("modified", []), results.get("modified_count", 0)
    more = [f"WARNING: and {count - len(named)} more"] if count > len(named) else []
    return [f"WARNING: {NOT_COMPARABLE} ({count} differ)", *(f"WARNING: {line}" for line in named), *more]


def lines(results: dict) -> list[str]:
    """Every verdict line of ``results`` (:func:`faultgen.bench.score.score`), as printed and written."""
    r = results["results"]
    return modified_lines(results) + (detector_lines(r) if results["role"] == "detector" else isolator_lines(r))


def summary(results: dict) -> str:
    """The verdict cell of the leaderboard row: each figure's word, short (after :data:`NOT_COMPARABLE`
    for a folder that differs from its frozen manifest)."""
    cell = _summary(results)
    return cell if results.get("comparable", True) else f"{NOT_COMPARABLE}; {cell}"


def _summary(results: dict) -> str:
    r = results["results"]
    if results["role"] == "detector":
        detected = detected_word(r["detected_share"], r["detected_minus_chance"])
        return (f"AUROC {word(*r['auroc']['ci95'], 0.5)}; at 5 % false alarms "
                f"{word(*r['detection_at_5pct_far']['ci95'], 0.05)}; detected {detected}")
    top1 = r["top1_accuracy"]
    if r.get("warnings"):
        return "no verdict: the track is too short for the method (its figure says nothing)"
    if named_none(r):
        return "no verdict: the method named no axis on any worn unit"
    cell = f"top-1 {word(*top1['ci95'], top1['chance'])}"
    if "fault_type_accuracy" in r:
        kind = r["fault_type_accuracy"]
        cell += f"; fault type {word(*kind['ci95'], kind['chance'])}"
    return cell
