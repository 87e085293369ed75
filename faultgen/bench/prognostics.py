"""``faultgen bench score prognostics``: a prognoser's remaining-useful-life predictions on the
prognostics track's test units, scored with NASA ProgPy's metrics and judged against a naive
prognoser.

The prognoser (:mod:`faultgen.bench.prognosers`: ``--prognoser MODULE:CLASS``, or a registered
prognoser of :mod:`faultgen.bench.baselines`, ``--baseline NAME`` or ``--prognoser NAME``:
``linear``, ``exponential``, ``mean_life``) learns from ``train.h5`` (run-to-failure units with
their labels) and the track's failure wear (:data:`FAILURE_WEAR`). ``test_labels.csv`` gives each
test unit's end of life (the first record whose true wear reaches the failure wear) and its onset
(the first record with wear); the prognoser is then shown each test unit's records up to every
record from the onset to the one before the end of life, and predicts the end-of-life time's
distribution each time (a ProgPy ``UnweightedSamples``; a sample beyond the horizon enters the
metrics at :data:`HORIZON` records after the prediction, as ProgPy drops a None from a mean).

Per unit (``progpy.metrics``, Saxena et al. 2010, "Metrics for offline evaluation of prognostic
performance"):

- **alpha-lambda** (:data:`ALPHA` 0.2, :data:`BETA` 0.5, :data:`LAMBDA` 0.5): at the first
  prediction at or after ``onset + 0.5 (EOL - onset)``, is at least half the distribution within
  +-20 % of the true remaining life;
- **relative accuracy** there (``1 - |true RUL - mean predicted RUL| / true RUL``; 1 is exact, it
  falls below 0 when the error exceeds the true RUL), and averaged over every prediction (cumulative);
- **prognostic horizon**: the end of life minus the first prediction meeting the alpha criterion
  (``progpy.metrics.prognostic_horizon``), 0 when none does, in records (days on the track);
- at lambda (:mod:`faultgen.bench.rul_scores`; in the JSON, and from version 2 in the
  leaderboard's row): whether the median is late by more than ALPHA of the true remaining life, whether the 5-95 %
  interval covers it, and the PHM 2008 score of the median (summarised as the late share, the
  covering share and the mean score; from version 2 the late share and the score are columns of
  the leaderboard's row, :func:`header`).

Over the units: the share meeting alpha-lambda, the mean relative accuracy at lambda and the median
prognostic horizon, each with a 95 % percentile bootstrap interval over test units
(``scipy.stats.bootstrap``, :data:`RESAMPLES` resamples, seed 0). **Verdict**: every figure beside
the naive prognoser's (:class:`~faultgen.bench.prognosers.MeanLife`: the train split's lives,
whatever the unit's records), and the paired bootstrap interval of the difference in relative
accuracy at lambda: above, below, or not distinguishable from the naive prognoser.
"""

from __future__ import annotations

import datetime
import json
import warnings
from pathlib import Path

import numpy as np

from faultgen.bench import baselines, files, prognosers, rul_scores
from faultgen.data import atomic

#: The failure wear of each version of the track, % (the end of life: docs/bench/prognostics.md).
FAILURE_WEAR = {1: 40.0, 2: 40.0}
ALPHA, BETA, LAMBDA = 0.2, 0.5, 0.5
#: Where a sample with no end of life enters the metrics: this many records after the prediction.
HORIZON = 365.0
RESAMPLES = 1000
TRACK = "prognostics"


def baseline(name: str):
    """A new registered prognoser (:func:`faultgen.bench.baselines.prognoser`): ``linear``,
    ``exponential`` (:mod:`faultgen.bench.degradation`), ``mean_life`` (the naive one), or one
    registered by a module of one's own.

    Raises
    ------
    ValueError
        For another name (listing the registered prognosers).
    """
    return baselines.prognoser(name)


def _progpy():
    """ProgPy's metrics, profile and samples types, imported with matplotlib's settings kept (its
    ``visualize`` module sets global rcParams when imported)."""
    import matplotlib

    with matplotlib.rc_context():
        from progpy.metrics import alpha_lambda, prognostic_horizon
        from progpy.predictors import ToEPredictionProfile
        from progpy.uncertain_data import UnweightedSamples
    return alpha_lambda, prognostic_horizon, ToEPredictionProfile, UnweightedSamples


def predictions(prognoser, name: str, unit: files.Unit, failure_wear: float) -> tuple[dict, float, float] | None:
    """``{time: samples}`` of ``prognoser`` on a labelled test ``unit`` (every record from the onset
    to the one before the end of life), its end of life and onset; None when its wear never reaches
    ``failure_wear``."""
    eol = prognosers.end_of_life(unit, failure_wear)
    if eol is None:
        return None
    cycles = np.asarray(unit.arrays["cycles"], dtype=float)
    worn = np.flatnonzero(np.asarray(unit.fault_level) > 0)
    first = int(worn[0]) if worn.size else 0
    out = {}
    for k in range(first, int(np.searchsorted(cycles, eol))):
        now = float(cycles[k])
        try:
            answer = prognoser.predict(prognosers.prefix(unit, k + 1))
        except Exception as err:  # noqa: BLE001 (a plug-in may raise anything: named on one line)
            raise ValueError(f"{name}: predict() on unit {unit.id} at time {now:g} failed: "
                             f"{type(err).__name__}: {err}") from None
        out[now] = prognosers.samples(answer, name, now)
    return out, eol, float(cycles[first])


def unit_metrics(profile: dict, eol: float, onset: float) -> dict:
    """ProgPy's metrics (module docstring) of ``{time: samples}`` against the end of life ``eol``."""
    alpha_lambda, prognostic_horizon, Profile, Samples = _progpy()
    before, finite = Profile(), {}
    for t, values in profile.items():
        values = np.where(np.isfinite(values), values, t + HORIZON)
        finite[t] = values
        before.add_prediction(t, Samples([{"failure": float(v)} for v in values]))
    truth = {"failure": eol}
    lam = onset + LAMBDA * (eol - onset)
    out = {"eol": eol, "onset": onset, "lambda": lam, "predictions": len(before)}
    if not len(before) or lam > max(before.keys()):
        return {**out, "alpha_lambda": None, "ra_lambda": None, "cra": None, "ph": None, "late_lambda": None,
                "covers_lambda": None, "phm08_lambda": None}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out["alpha_lambda"] = bool(alpha_lambda(before, truth, lam, ALPHA, BETA)["failure"])
        at = min(t for t in before if t >= lam)
        # faultgen.bench.rul_scores: the median late by more than ALPHA, the 5-95 % interval
        # covering the true remaining life, the PHM 2008 score of the median
        low, median, high = np.quantile(finite[at] - at, [0.05, 0.5, 0.95])
        true_rul = max(eol - at, 1e-9)
        out.update(late_lambda=rul_scores.late(median, true_rul, ALPHA),
                   covers_lambda=rul_scores.covers(low, high, eol - at),
                   phm08_lambda=float(rul_scores.phm08_score(median, eol - at)))
        out["ra_lambda"] = float((before[at] - at).relative_accuracy({"failure": eol - at})["failure"])

        def criterion(tte, tte_truth):
            bounds = {k: (v - ALPHA * v, v + ALPHA * v) for k, v in tte_truth.items()}
            return {k: p >= BETA for k, p in tte.percentage_in_bounds(bounds).items()}

        ph = prognostic_horizon(before, criterion, truth)["failure"]
        out["ph"] = float(ph) if ph is not None else 0.0
        out["cra"] = float(np.mean([(toe - t).relative_accuracy({"failure": eol - t})["failure"]
                                    for t, toe in before.items()]))
    return out


def _figure(values: list[float], statistic) -> dict:
    """``statistic`` of ``values`` with its 95 % percentile bootstrap interval over them."""
    from scipy.stats import bootstrap

    values = np.asarray(values, dtype=float)
    if not values.size:
        return {"value": float("nan"), "ci95": [float("nan")] * 2, "units": 0}
    value = float(statistic(values))
    if np.ptp(values) == 0:
        low = high = value
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ci = bootstrap((values,), statistic, n_resamples=RESAMPLES, method="percentile", rng=0).confidence_interval
        low, high = float(ci.low), float(ci.high)
    return {"value": value, "ci95": [low, high], "units": int(values.size)}


def summary(rows: list[dict]) -> dict:
    """The figures over units (module docstring) of per-unit metric rows (:func:`unit_metrics`)."""
    rows = [r for r in rows if r["alpha_lambda"] is not None]
    return {"alpha_lambda_share": _figure([float(r["alpha_lambda"]) for r in rows], np.mean),
            "ra_lambda": _figure([r["ra_lambda"] for r in rows], np.mean),
            "cumulative_ra": _figure([r["cra"] for r in rows], np.mean),
            "prognostic_horizon": _figure([r["ph"] for r in rows], np.median),
            "late_share": _figure([float(r["late_lambda"]) for r in rows if r.get("late_lambda") is not None], np.mean),
            "covers_share": _figure([float(r["covers_lambda"]) for r in rows if r.get("covers_lambda") is not None],
                                    np.mean),
            "phm08_lambda": _figure([r["phm08_lambda"] for r in rows if r.get("phm08_lambda") is not None], np.mean)}


def verdict(method: list[dict], naive: list[dict]) -> tuple[str, dict]:
    """The paired bootstrap interval of the method's relative accuracy at lambda minus the naive
    prognoser's over the units both scored, and the verdict in words."""
    pairs = [(m["ra_lambda"], n["ra_lambda"]) for m, n in zip(method, naive)
             if m["ra_lambda"] is not None and n["ra_lambda"] is not None]
    diff = _figure([m - n for m, n in pairs], np.mean)
    low, high = diff["ci95"]
    if not pairs:
        words = "no unit scored: no verdict"
    elif low > 0:
        words = "above the naive prognoser (relative accuracy at lambda, paired 95 % interval above 0)"
    elif high < 0:
        words = "below the naive prognoser (relative accuracy at lambda, paired 95 % interval below 0)"
    else:
        words = "not distinguishable from the naive prognoser (relative accuracy at lambda, paired 95 % interval covers 0)"
    return words, diff


def score(folder: str | Path, prognoser, name: str, allow_modified: bool = False) -> dict:
    """Score ``prognoser`` (unfitted: :mod:`faultgen.bench.prognosers`) on the prognostics track's files
    in ``folder``, with the naive prognoser beside it; returns the results (the JSON :func:`write` writes),
    with ``comparable`` as :func:`faultgen.bench.score.score` (``allow_modified`` alike: the verdict
    of a folder that differs from the frozen manifest starts with
    :data:`faultgen.bench.verdicts.NOT_COMPARABLE`).

    Raises
    ------
    ValueError
        If the folder's files are missing or not benchmark files (:func:`faultgen.bench.files.read_with_attrs`),
        hold another track or a version without a failure wear, differ from the frozen manifest
        without ``allow_modified`` (:func:`faultgen.bench.make.compare`), or the prognoser's fit or
        predict fails or answers outside the contract (naming it).
    """
    from faultgen.bench import make, verdicts

    folder = Path(folder)
    train = files.read(folder / "train.h5")
    test, made = files.read_with_attrs(folder / "test.h5", ("track", "version", "size"))
    if made.get("track") != TRACK:
        raise ValueError(f"{folder} holds track {made.get('track')!r}, not {TRACK!r}")
    if made["version"] not in FAILURE_WEAR:
        raise ValueError(f"{folder}: prognostics version {made['version']}; this module scores versions "
                         f"{', '.join(map(str, FAILURE_WEAR))}"
                         + ("; version 3 is scored by faultgen.bench.rul_v3.score (the command routes it there)"
                            if made["version"] == 3 else ""))
    failure = FAILURE_WEAR[made["version"]]
    labelled = files.attach_labels(test, folder / "test_labels.csv")
    checked = make.compare(folder, made, allow_modified)
    per_method = {}
    for label, method in ((name, prognoser), ("mean_life", prognosers.MeanLife())):
        try:
            method.fit(train, failure)
        except Exception as err:  # noqa: BLE001 (a plug-in may raise anything: named on one line)
            raise ValueError(f"{label}: fit(units, failure_wear={failure:g}) on {len(train)} train units failed: "
                             f"{type(err).__name__}: {err}") from None
        rows = []
        for unit in labelled:
            found = predictions(method, label, unit, failure)
            if found is not None:
                rows.append({"unit": unit.id, "worn_axis": unit.worn_axis, **unit_metrics(*found)})
        per_method[label] = rows
    method_rows, naive_rows = per_method[name], per_method["mean_life"]
    words, diff = verdict(method_rows, naive_rows)
    if not checked["comparable"]:
        words = f"{verdicts.NOT_COMPARABLE}; {words}"
    return {"method": name, "role": "prognoser", **{k: str(v) for k, v in made.items()}, **checked,
            "date": datetime.date.today().isoformat(), "failure_wear": failure, "alpha": ALPHA, "beta": BETA,
            "lambda": LAMBDA, "resamples": RESAMPLES, "unscored_units": len(labelled) - len(method_rows),
            "results": summary(method_rows), "naive": summary(naive_rows), "ra_lambda_minus_naive": diff,
            "verdict": words, "per_unit": method_rows, "naive_per_unit": naive_rows}


def _cell(figure: dict, scale: float = 1.0, digits: int = 2, kind: str = "f") -> str:
    value = figure["value"] * scale
    if not np.isfinite(value):
        return "-"
    low, high = (x * scale for x in figure["ci95"])
    return f"{value:.{digits}{kind}} [{low:.{digits}{kind}}, {high:.{digits}{kind}}]"


HEADER = ("| track | prognoser | alpha-lambda met % [95 % CI] (naive) | relative accuracy at lambda [CI] (naive) | "
          "prognostic horizon, median days [CI] (naive) | verdict | command | date |")


#: From version 2 on the table also gives, at lambda, the share of units whose median is late
#: by more than alpha and the mean PHM 2008 score of the median (:mod:`faultgen.bench.rul_scores`).
HEADER_V2 = HEADER.replace(" | verdict |", " | late by more than alpha at lambda, % of units [CI] (naive) | "
                                          "PHM 2008 score at lambda, mean [CI] (naive) | verdict |")


def header(version) -> str:
    """The leaderboard table's header for the track ``version`` (:data:`HEADER`, :data:`HEADER_V2` from 2)."""
    return HEADER if int(version) < 2 else HEADER_V2


def markdown_row(results: dict, command: str) -> str:
    """One row of the leaderboard's prognostics table (docs/leaderboard.md) for ``results`` (the
    columns of :func:`header` of its version)."""
    r, n = results["results"], results["naive"]
    track = f"{results['track']} v{results['version']}" + (f" ({results['size']})" if results["size"] != "full" else "")
    cells = [f"{_cell(r['alpha_lambda_share'], 100, 0)} ({_cell(n['alpha_lambda_share'], 100, 0)})",
             f"{_cell(r['ra_lambda'])} ({_cell(n['ra_lambda'])})",
             f"{_cell(r['prognostic_horizon'], 1, 0)} ({_cell(n['prognostic_horizon'], 1, 0)})",
             results["verdict"].split(" (")[0]]
    if int(results["version"]) >= 2:
        cells[3:3] = [f"{_cell(r['late_share'], 100, 0)} ({_cell(n['late_share'], 100, 0)})",
                      # three significant digits: a sample with no end of life scores exp(36.5) - 1 (HORIZON days late)
                      f"{_cell(r['phm08_lambda'], 1, 3, 'g')} ({_cell(n['phm08_lambda'], 1, 3, 'g')})"]
    return f"| {track} | {results['method']} | " + " | ".join(cells) + f" | `{command}` | {results['date']} |"


def write(results: dict, out: str | Path, command: str) -> tuple[Path, Path]:
    """``OUT.json`` (the results) and ``OUT.md`` (the table's header and its row), as one set."""
    return write_set(results, out, command, header(results["version"]), markdown_row(results, command))


def write_set(results: dict, out: str | Path, command: str, top: str, row: str) -> tuple[Path, Path]:
    """``OUT.json`` (``results`` with ``command``) and ``OUT.md`` (the table's header ``top``, its rule
    and ``row``), written as one set (:func:`faultgen.data.atomic.output_set`); any version's scorer."""
    out = Path(out)
    json_path, md_path = out.with_name(out.name + ".json"), out.with_name(out.name + ".md")
    with atomic.output_set([json_path, md_path]) as staged:
        staged(json_path).write_text(json.dumps({**results, "command": command}, indent=1) + "\n")
        staged(md_path).write_text(top + "\n|" + "---|" * (top.count("|") - 1) + "\n" + row + "\n")
    return json_path, md_path
