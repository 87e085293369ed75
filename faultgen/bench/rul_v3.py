"""``faultgen bench score prognostics`` on the track's version 3 (issue 85): remaining-life scores
that rank, each with a paired bootstrap interval against the naive prognoser and against the best
other baseline.

**Who is scored.** The method, and beside it every baseline of :data:`BASELINES`: the naive
(``mean_life``, :class:`~faultgen.bench.prognosers.MeanLife`), the load-based rated life
(``load_life``), a fit of the friction tests' wear (``tests_fit``; not the twin) and the oracle
(``oracle``, the ceiling, which reads the labels): :mod:`faultgen.bench.prognosers_v3`; the linear and
exponential fits of a health index (:mod:`faultgen.bench.degradation`). Each learns from ``train.h5`` and is shown a test unit's
records up to the time of prediction (the oracle with their labels).

**When (lambda).** Per run-to-failure test unit (its wear reaches :data:`FAILURE_WEAR` within its
record; the end of life is that record's day), at four times: the first records whose true wear
reaches 20, 25 and 30 % (``wear20``, ``wear25``, ``wear30``: the same days for every method), and
Saxena's ``t_P + 0.5 (EOL - t_P)`` (``saxena``; Saxena et al. 2010) with ``t_P`` the method's first
prediction: the first record, asked every :data:`GRID` th record from the first, at which its median
end of life is finite. :data:`HEADLINE` is the leaderboard's lambda.

**Scores at a lambda** (the samples' median is the point prediction; a sample with no end of life
counts :data:`HORIZON` days after the prediction): relative accuracy ``1 - |RUL - median| / RUL``;
alpha-lambda (:data:`ALPHA` 0.2, :data:`BETA` 0.5: at least half the samples within +-20 % of the
true RUL); late (:func:`faultgen.bench.rul_scores.late`: the median later than the truth by more
than 20 % of it); the PHM 2008 score of the median (:func:`faultgen.bench.rul_scores.phm08_score`);
the absolute error, and the skill ``1 - MAE / MAE_naive``. Over the units: each mean with its 95 %
percentile bootstrap interval (:data:`RESAMPLES` resamples of the units, seed 0).

**Comparisons.** For each score, the paired bootstrap interval (the same resampled units for both)
of the method's mean minus the reference's: the naive, and the best other baseline (the one of
:data:`BASELINES` other than the method, the naive and the oracle with the highest mean relative
accuracy at the lambda). ``better`` when the interval lies on the better side of 0 (above for the
relative accuracy, the alpha-lambda share and the skill; below for the late share and the PHM
score), ``worse`` on the other side, else ``not distinguishable``; the skill's difference is
``(MAE_ref - MAE_method) / MAE_naive``.

**No end of life.** A censored or healthy test unit is asked once, :data:`NO_EOL_BEFORE` days before
its record's end: right when its median end of life lies after the record's end (``no_eol_share``).
"""

from __future__ import annotations

import datetime
from pathlib import Path

import numpy as np

from faultgen.bench import files, prognosers, rul_scores

FAILURE_WEAR = 40.0
ANCHORS = {"wear20": 20.0, "wear25": 25.0, "wear30": 30.0, "saxena": None}
HEADLINE = "wear25"
ALPHA, BETA = 0.2, 0.5
HORIZON = 365.0
GRID = 6
NO_EOL_BEFORE = 30
RESAMPLES = 2000
BASELINES = ("mean_life", "load_life", "linear", "exponential", "tests_fit", "oracle")
#: The baselines that read the labels of the records shown (never a submission); a method passed to
#: :func:`score_all` with ``reads_labels`` True is shown them too (the emulated twins,
#: :mod:`faultgen.bench.twin_emulator`).
LABELLED = ("oracle",)
#: Score -> (key of the per-unit row, whether higher is better).
SCORES = {"ra": ("ra", True), "alpha_lambda": ("al", True), "late_share": ("late", False),
          "phm08": ("phm", False), "skill": ("ae", None)}


def baseline(name: str):
    """A new unfitted baseline of :data:`BASELINES`; ValueError for another name."""
    from faultgen.bench import degradation, prognosers_v3

    made = {"mean_life": prognosers.MeanLife, "load_life": prognosers_v3.LoadLife,
            "linear": degradation.LinearDegradation, "exponential": degradation.ExponentialDegradation,
            "tests_fit": prognosers_v3.TestsFit, "oracle": prognosers_v3.Oracle}.get(name)
    if made is None:
        raise ValueError(f"prognostics v3 baseline {name!r}; expected one of {', '.join(BASELINES)}")
    return made()


def _shown(unit: files.Unit, n: int, labelled: bool) -> files.Unit:
    """``unit``'s first ``n`` records as a prognoser sees them (with their labels for the oracle)."""
    out = prognosers.prefix(unit, n)
    if labelled:
        out.fault_level, out.worn_axis = np.asarray(unit.fault_level)[:n], unit.worn_axis
    return out


def _ask(method, name: str, unit: files.Unit, n: int, labelled: bool) -> np.ndarray:
    now = float(unit.arrays["cycles"][n - 1])
    try:
        answer = method.predict(_shown(unit, n, labelled))
    except Exception as err:  # noqa: BLE001 (a plug-in may raise anything: named on one line)
        raise ValueError(f"{name}: predict() on unit {unit.id} at time {now:g} failed: {type(err).__name__}: {err}") \
            from None
    return prognosers.samples(answer, name, now)


def at_lambda(samples: np.ndarray, now: float, eol: float) -> dict:
    """The scores (module docstring) of a prediction's ``samples`` made at ``now`` for the end of life ``eol``."""
    predicted = np.where(np.isfinite(samples), samples, now + HORIZON) - now
    rul = eol - now
    median = float(np.median(predicted))
    return {"day": now, "rul": rul, "median": median, "ra": 1.0 - abs(rul - median) / rul,
            "al": float(np.mean(np.abs(predicted - rul) <= ALPHA * rul) >= BETA),
            "late": float(rul_scores.late(median, rul, ALPHA)), "phm": float(rul_scores.phm08_score(median, rul)),
            "ae": abs(median - rul)}


def unit_row(method, name: str, unit: files.Unit, labelled: bool) -> dict:
    """One labelled test unit's row: its scores at each lambda (None where the lambda is not before the
    end of life), or for a unit without an end of life in its record whether the method says so."""
    days = np.asarray(unit.arrays["cycles"], dtype=float)
    eol = prognosers.end_of_life(unit, FAILURE_WEAR)
    if eol is None:
        n = int(np.searchsorted(days, days[-1] - NO_EOL_BEFORE, side="right"))
        if n < 1:
            return {"unit": unit.id, "kind": "no_eol", "no_eol_right": None}
        median = float(np.median(_ask(method, name, unit, n, labelled)))
        return {"unit": unit.id, "kind": "healthy" if not unit.worn_axis else "censored",
                "no_eol_right": float(median > days[-1])}
    end = int(np.searchsorted(days, eol))
    wear = np.asarray(unit.fault_level, dtype=float)
    row = {"unit": unit.id, "kind": "failing", "eol": eol, "worn_axis": unit.worn_axis}
    at = {}
    for anchor, level in ANCHORS.items():
        if level is not None:
            reached = np.flatnonzero(wear >= level)
            at[anchor] = int(reached[0]) if reached.size and reached[0] < end else None
    t_p = None
    for k in range(0, end, GRID):
        if np.isfinite(np.median(_ask(method, name, unit, k + 1, labelled))):
            t_p = float(days[k])
            break
    row["t_p"] = t_p
    if t_p is not None:
        k = int(np.searchsorted(days, t_p + 0.5 * (eol - t_p)))
        at["saxena"] = k if k < end else None
    else:
        at["saxena"] = None
    for anchor, k in at.items():
        row[anchor] = None if k is None else at_lambda(_ask(method, name, unit, k + 1, labelled), float(days[k]), eol)
    return row


def rows_of(method, name: str, train: list[files.Unit], test: list[files.Unit], labelled: bool = False) -> list[dict]:
    """``method`` fitted on ``train`` and its :func:`unit_row` on every labelled ``test`` unit.

    Raises
    ------
    ValueError
        Naming ``name``: its fit or predict fails or answers outside the contract.
    """
    try:
        method.fit(train, FAILURE_WEAR)
    except Exception as err:  # noqa: BLE001
        raise ValueError(f"{name}: fit(units, failure_wear={FAILURE_WEAR:g}) on {len(train)} train units failed: "
                         f"{type(err).__name__}: {err}") from None
    return [unit_row(method, name, unit, labelled) for unit in test]


def _resampled(n: int) -> np.ndarray:
    return np.random.default_rng(0).integers(0, n, (RESAMPLES, n))


def _interval(values: np.ndarray) -> list[float]:
    return [float(np.percentile(values, 2.5)), float(np.percentile(values, 97.5))]


def _figure(value: float, draws: np.ndarray, n: int) -> dict:
    return {"value": float(value), "ci95": _interval(draws) if n else [float("nan")] * 2, "units": n}


def _values(rows: list[dict], anchor: str, key: str) -> dict[str, float]:
    return {r["unit"]: r[anchor][key] for r in rows if r["kind"] == "failing" and r.get(anchor)}


def summary(rows: list[dict], naive: list[dict], anchor: str) -> dict:
    """The means over units at ``anchor`` with their bootstrap intervals, the skill against ``naive``'s
    rows on the units both scored."""
    out = {}
    for score, (key, _) in SCORES.items():
        if score == "skill":
            mine, ref = _values(rows, anchor, key), _values(naive, anchor, key)
            units = sorted(set(mine) & set(ref))
            m, r = np.array([mine[u] for u in units]), np.array([ref[u] for u in units])
            if not units or not r.sum():
                out[score] = _figure(float("nan"), np.array([np.nan]), 0)
                continue
            idx = _resampled(len(units))
            with np.errstate(divide="ignore", invalid="ignore"):
                draws = 1.0 - m[idx].mean(axis=1) / r[idx].mean(axis=1)
            out[score] = _figure(1.0 - m.mean() / r.mean(), draws[np.isfinite(draws)], len(units))
            continue
        values = np.array(list(_values(rows, anchor, key).values()))
        draws = values[_resampled(values.size)].mean(axis=1) if values.size else np.array([np.nan])
        out[score] = _figure(values.mean() if values.size else float("nan"), draws, int(values.size))
    return out


def _against(words: str) -> str:
    """A verdict as the start of a comparison: "better than", "worse than", "not distinguishable from"."""
    return {"better": "better than", "worse": "worse than", "not distinguishable": "not distinguishable from"}.get(
        words, f"{words}: against")


def _words(low: float, high: float, higher_better: bool) -> str:
    if not np.isfinite(low) or not np.isfinite(high):
        return "no verdict"
    if low > 0 or high < 0:
        return "better" if (low > 0) == higher_better else "worse"
    return "not distinguishable"


def compare(rows: list[dict], ref: list[dict], naive: list[dict], anchor: str) -> dict:
    """Each score's paired bootstrap difference (method minus ``ref``) at ``anchor`` with its verdict
    (module docstring), over the units both scored."""
    out = {}
    for score, (key, higher) in SCORES.items():
        mine, theirs = _values(rows, anchor, key), _values(ref, anchor, key)
        base = _values(naive, anchor, "ae")
        units = sorted(set(mine) & set(theirs) & (set(base) if score == "skill" else set(mine)))
        if not units:
            out[score] = {"value": float("nan"), "ci95": [float("nan")] * 2, "units": 0, "verdict": "no verdict"}
            continue
        m, t = np.array([mine[u] for u in units]), np.array([theirs[u] for u in units])
        idx = _resampled(len(units))
        if score == "skill":
            b = np.array([base[u] for u in units])
            with np.errstate(divide="ignore", invalid="ignore"):
                draws = (t[idx].mean(axis=1) - m[idx].mean(axis=1)) / b[idx].mean(axis=1)
            value, draws, higher = (t.mean() - m.mean()) / b.mean(), draws[np.isfinite(draws)], True
        else:
            value, draws = (m - t).mean(), (m - t)[idx].mean(axis=1)
        low, high = _interval(draws) if draws.size else (float("nan"), float("nan"))
        out[score] = {"value": float(value), "ci95": [low, high], "units": len(units),
                      "verdict": _words(low, high, higher)}
    return out


def no_eol(rows: list[dict]) -> dict:
    """The share of censored and healthy units the method rightly gives no end of life in the record."""
    values = np.array([r["no_eol_right"] for r in rows if r["kind"] in ("healthy", "censored")
                       and r["no_eol_right"] is not None])
    draws = values[_resampled(values.size)].mean(axis=1) if values.size else np.array([np.nan])
    return _figure(values.mean() if values.size else float("nan"), draws, int(values.size))


def best_other(name: str, per_method: dict[str, list[dict]], anchor: str) -> str | None:
    """The baseline other than ``name``, the naive and the oracle with the highest mean relative accuracy at ``anchor``."""
    means = {other: np.mean(list(_values(rows, anchor, "ra").values()) or [-np.inf])
             for other, rows in per_method.items() if other not in (name, "mean_life", "oracle")}
    return max(means, key=means.get) if means else None


def results_for(name: str, per_method: dict[str, list[dict]]) -> dict:
    """``name``'s figures at each lambda, its comparisons with the naive and the best other baseline, the
    no-end-of-life share, and the headline verdict (relative accuracy at :data:`HEADLINE` against the naive)."""
    rows, naive = per_method[name], per_method["mean_life"]
    out = {"method": name, "anchors": {}, "no_eol_share": no_eol(rows)}
    for anchor in ANCHORS:
        best = best_other(name, per_method, anchor)
        out["anchors"][anchor] = {"results": summary(rows, naive, anchor),
                                  "vs_naive": compare(rows, naive, naive, anchor), "best_other": best,
                                  "vs_best": compare(rows, per_method[best], naive, anchor) if best else None}
    head = out["anchors"][HEADLINE]
    against = [f"{_against(head['vs_naive']['ra']['verdict'])} the naive prognoser"]
    if head["best_other"]:
        against.append(f"{_against(head['vs_best']['ra']['verdict'])} {head['best_other']} (the best other baseline)")
    out["verdict"] = "; ".join(against) + f" (relative accuracy at lambda = {HEADLINE}, paired 95 % intervals)"
    out["per_unit"] = rows
    return out


def score_all(folder: str | Path, methods: dict, variant: str | None = None) -> tuple[dict, dict]:
    """Every baseline of :data:`BASELINES` and ``methods`` (name -> unfitted prognoser) scored on the
    version 3 folder's test split (``test.h5``, or ``test-<variant>.h5``): (name -> per-unit rows,
    the test file's attributes)."""
    from faultgen.bench import prognostics_v3

    folder = Path(folder)
    if variant not in (None, prognostics_v3.DEFAULT_VARIANT) and variant not in prognostics_v3.VARIANTS:
        raise ValueError(f"--variant {variant!r}: expected one of {', '.join(prognostics_v3.VARIANTS)}")
    name = "test.h5" if variant in (None, prognostics_v3.DEFAULT_VARIANT) else f"test-{variant}.h5"
    train = files.read(folder / "train.h5")
    test, made = files.read_with_attrs(folder / name, ("track", "version", "size"))
    labelled = files.attach_labels(test, folder / "test_labels.csv")
    out = {}
    for label in (*BASELINES, *[m for m in methods if m not in BASELINES]):
        method = methods.get(label) or baseline(label)
        reads = label in LABELLED or getattr(method, "reads_labels", False)
        out[label] = rows_of(method, label, train, labelled, reads)
    return out, {**made, "variant": variant or prognostics_v3.DEFAULT_VARIANT}


def score(folder: str | Path, prognoser, name: str, allow_modified: bool = False, variant: str | None = None) -> dict:
    """Score ``prognoser`` (None: the baseline ``name``) on a version 3 folder beside every baseline;
    the results :func:`faultgen.bench.prognostics.write` writes, with ``comparable`` as
    :func:`faultgen.bench.make.compare` gives it (``allow_modified`` alike)."""
    from faultgen.bench import make, verdicts

    folder = Path(folder)
    _, made = files.read_with_attrs(folder / "test.h5", ("track", "version", "size"))
    checked = make.compare(folder, made, allow_modified)
    per_method, made = score_all(folder, {} if prognoser is None else {name: prognoser}, variant)
    results = results_for(name, per_method)
    if not checked["comparable"]:
        results["verdict"] = f"{verdicts.NOT_COMPARABLE}; {results['verdict']}"
    return {**results, "role": "prognoser", **{k: str(v) for k, v in made.items()}, **checked,
            "date": datetime.date.today().isoformat(), "failure_wear": FAILURE_WEAR, "alpha": ALPHA, "beta": BETA,
            "headline": HEADLINE, "resamples": RESAMPLES,
            "baselines": {b: results_for(b, per_method) for b in BASELINES if b != name}}


def _cell(figure: dict | None, scale: float = 1.0, digits: int = 2, kind: str = "f") -> str:
    if not figure or not np.isfinite(figure["value"]):
        return "-"
    low, high = (x * scale for x in figure["ci95"])
    return f"{figure['value'] * scale:.{digits}{kind}} [{low:.{digits}{kind}}, {high:.{digits}{kind}}]"


def _versus(diff: dict | None) -> str:
    return "-" if not diff else f"{_cell(diff)} {diff['verdict']}"


HEADER = ("| track | prognoser | relative accuracy at 25 % wear [95 % CI] | minus the naive's [paired CI], verdict | "
          "best other baseline: minus its [paired CI], verdict | alpha-lambda met % [CI] | late by more than alpha % "
          "[CI] | PHM 2008 score, mean [CI] | skill 1 - MAE/MAE_naive [CI] | relative accuracy at 20 % / 30 % wear / "
          "Saxena's lambda | no end of life said right, % of censored and healthy [CI] | command | date |")


def markdown_row(results: dict, command: str) -> str:
    """The leaderboard row (:data:`HEADER`) of :func:`score`'s ``results``, at :data:`HEADLINE`."""
    head = results["anchors"][HEADLINE]
    r = head["results"]
    size = "" if results.get("size") == "full" else f" ({results.get('size')})"
    variant = results.get("variant", "scatter-14")
    track = f"prognostics v3{size}" + ("" if variant == "scatter-14" else f" {variant}")
    others = " / ".join(_cell({**results["anchors"][a]["results"]["ra"], "ci95": [0.0, 0.0]}).split(" [")[0]
                        for a in ("wear20", "wear30", "saxena"))
    best = f"{head['best_other']}: {_versus(head['vs_best']['ra'])}" if head["best_other"] else "-"
    cells = [_cell(r["ra"]), _versus(head["vs_naive"]["ra"]) if results["method"] != "mean_life" else "(the naive)",
             best, _cell(r["alpha_lambda"], 100, 0), _cell(r["late_share"], 100, 0), _cell(r["phm08"], 1, 3, "g"),
             _cell(r["skill"]), others, _cell(results["no_eol_share"], 100, 0)]
    return f"| {track} | {results['method']} | " + " | ".join(cells) + f" | `{command}` | {results['date']} |"


def write(results: dict, out: str | Path, command: str) -> tuple[Path, Path]:
    """``OUT.json`` (the results) and ``OUT.md`` (the table's header and its row), as one set
    (:func:`faultgen.bench.prognostics.write_set`, v1 and v2's writer)."""
    from faultgen.bench import prognostics

    return prognostics.write_set(results, out, command, HEADER, markdown_row(results, command))
