"""The training-source study of thesis ch. 4 (Table 4.1) on a fleet of daily records.

Does a PCA monitor need each robot's own healthy data? Every robot of a dataset (a fleet:
``faultgen fleet``, one record per day, failing robots failing on their last day) is tested with
a PCA model of normal operation learnt

- one-to-one (OTO): from its own first ``training_days`` days (thesis Fig. 4-2 b), or
- one-to-many (OTM): from the first ``training_days`` days of one reference robot, in turn every
  healthy robot of the same model (Fig. 4-2 a; a reference of another model is not a model of
  this robot's operation: its torques are on another scale),

on three signal types (ch. 4.3.2): the raw measurements, the absolute difference between two
successive days, and both combined. The descriptors of the Q residual over the test days (ch.
4.3.3) are its coefficient of variation, the number of samples above the 95 % limit (NSAT) and
the lead time (test days left when the first sample crosses the limit); a three-way ANOVA with
interactions (training source x signal type x robot condition) and Tukey's HSD compare them, as
in Tables 4.2-4.4 and Figs. 4-4 to 4-6.

Measurements per day (the day's maximum of the per-cycle features, ``stepping.daily_record``):
mean |motor torque| and RMS motor torque per axis, and the angle, speed and torque histograms per
axis reduced by the KL divergence (eq. 4.1) against the first day of the window (raw) or the day
before (difference), as ch. 4.3.2 does for the measurements reported as distributions. Simulated
truth (friction torque, tracking error, wear, temperatures) is not a measurement and is left out.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import signal as scipy_signal
from sklearn.base import BaseEstimator
from tqdm.auto import tqdm

from analysis import registry
from analysis.benchmark.tables import markdown
from analysis.evaluate import Data, Given, evaluate
from analysis.features import kl_divergence
from analysis.monitoring import PCAMonitor, fit_q_monitor, varying_columns
from faultgen.checks import is_whole
from faultgen.data import reader

SOURCES = ("OTM", "OTO")
SIGNAL_TYPES = ("raw", "difference", "combined")
CONDITIONS = ("failure", "normal")
#: descriptor column -> its name in the thesis (ch. 4.3.3)
DESCRIPTORS = {"cov_q": "coefficient of variation of Q", "nsat": "samples above the Q limit (NSAT)",
               "lead_time_days": "lead time (days)"}
SCALARS = ("mean_abs_torque", "rms_torque")
HISTOGRAMS = ("angle_hist", "speed_hist", "torque_hist")


@dataclass(frozen=True)
class Window:
    """The days of a run the study uses (thesis ch. 4.3.2): the last ``training_days + test_days
    + gap_days`` records; the first ``training_days`` train, the next ``test_days`` are tested and
    the last ``gap_days`` (the days just before the failure, the failure day included) are left
    out. Thesis: 40 + 15 + 5 of a 60-day dataset."""

    training_days: int = 40
    test_days: int = 15
    gap_days: int = 5

    def __post_init__(self):
        for name, least in (("training_days", 3), ("test_days", 1), ("gap_days", 0)):
            value = getattr(self, name)
            if not is_whole(value, least):
                raise ValueError(f"{name} = {value!r}; expected an integer >= {least}")

    @property
    def days(self) -> int:
        return self.training_days + self.test_days + self.gap_days


def signals(arrays: dict, window: Window = Window()) -> dict[str, tuple[np.ndarray, list[str]]]:
    """The raw, difference and combined signals of one run over its window.

    Parameters
    ----------
    arrays : dict
        The run's :data:`SCALARS` (n, 6) and :data:`HISTOGRAMS` (n, 6, 12), one row per record
        (day), n >= ``window.days``.
    window : Window

    Returns
    -------
    dict
        signal type -> (ndarray of shape (window.days - 1, n_features), feature names). Row ``i``
        is day ``i + 2`` of the window (the first day has no difference); raw histograms are the
        KL divergence in bits against the window's first day, difference ones against the day
        before, difference scalars ``|x_d - x_(d-1)|`` in their unit (N m at the motor side).

    Raises
    ------
    ValueError
        If the run has fewer records than ``window.days``.
    """
    n = len(arrays[SCALARS[0]])
    if n < window.days:
        raise ValueError(f"{n} records, the study needs {window.days} ({window.training_days} training + "
                         f"{window.test_days} test + {window.gap_days} left out before the failure)")
    columns: dict[str, list] = {"raw": [], "difference": []}
    names: list[str] = []
    for name in SCALARS:
        x = np.asarray(arrays[name], dtype=float)[-window.days:]
        columns["raw"].append(x[1:])
        columns["difference"].append(np.abs(np.diff(x, axis=0)))
        names += [f"{name}_{axis}" for axis in range(1, x.shape[1] + 1)]
    for name in HISTOGRAMS:
        h = np.asarray(arrays[name], dtype=float)[-window.days:]
        columns["raw"].append(kl_divergence(h[1:], h[:1]))
        columns["difference"].append(kl_divergence(h[1:], h[:-1]))
        names += [f"kl_{name}_{axis}" for axis in range(1, h.shape[1] + 1)]
    raw, difference = np.hstack(columns["raw"]), np.hstack(columns["difference"])
    return {"raw": (raw, names), "difference": (difference, [f"diff_{c}" for c in names]),
            "combined": (np.hstack([raw, difference]), names + [f"diff_{c}" for c in names])}


def _detrend(X: np.ndarray) -> np.ndarray:
    """Each column without its least-squares linear trend, keeping its mean (ch. 4.3.2)."""
    return scipy_signal.detrend(X, axis=0, type="linear") + X.mean(axis=0)


def descriptors(q: np.ndarray, limit: float) -> dict[str, float]:
    """Ch. 4.3.3 descriptors of the test days' Q residuals ``q`` (n_test,) against ``limit``:
    coefficient of variation (sample std / mean), NSAT, and lead time: the test days left,
    counting the day itself, when Q first exceeds the limit (0 if never; add the left-out gap for
    the days before the failure, thesis ch. 4.3.3)."""
    above = np.flatnonzero(q > limit)
    return {"cov_q": float(np.std(q, ddof=1) / np.mean(q)), "nsat": int(above.size),
            "lead_time_days": int(len(q) - above[0]) if above.size else 0, "test_days": int(len(q)),
            "saturated": bool(above.size == len(q))}


def normal_false_alarms(cases: pd.DataFrame) -> pd.DataFrame:
    """What the descriptors mean on normal robots, which never fail: every test day above the
    limit is a false alarm and the "lead time" is only how early the first false alarm came.
    Per training source and signal type: normal-robot cases, their mean false-alarm share of the
    test days (%), and the cases whose limit is saturated (every test day above it: the model does
    not describe that robot at all, e.g. OTM across robots of different loads).

    Returns
    -------
    DataFrame indexed by (source, signal): cases, false_alarm_pct, saturated, saturated_pct.
    """
    normal = cases[cases["condition"] == "normal"]
    grouped = normal.assign(false_alarm_pct=100.0 * normal["nsat"] / normal["test_days"]).groupby(["source", "signal"])
    out = grouped.agg(cases=("nsat", "size"), false_alarm_pct=("false_alarm_pct", "mean"),
                      saturated=("saturated", "sum"))
    out["saturated_pct"] = 100.0 * out["saturated"] / out["cases"]
    return out.round(1)


def _fit(X: np.ndarray, variance: float, alpha: float, folds: int | None) -> tuple[np.ndarray, PCAMonitor]:
    """The features used and the Q monitor fitted on detrended training signals ``X``."""
    X = _detrend(X)
    used = varying_columns(X)
    made = registry.make("pca_monitor", variance=variance, alpha=alpha, statistic="q",
                         cv=None if folds is None else min(folds, len(X)))[1]
    return used, fit_q_monitor(X[:, used], made)


class QModel(BaseEstimator):
    """The model of one training source (ch. 4.3.2), an estimator of the evaluation harness
    (:func:`analysis.evaluate.evaluate`): ``fit(X)`` on the training days' signals (n_days,
    n_features) removes their linear trends, leaves out the features constant there and fits a Q
    monitor (the registry's ``pca_monitor``, ``variance``, ``alpha``, ``folds`` its ``cv``) on the
    rest (``used_``, ``monitor_``); ``decision_function(X)`` is the Q residual of each day, shape
    (n_days,)."""

    def __init__(self, variance: float = 0.90, alpha: float = 0.05, folds: int | None = 20):
        self.variance, self.alpha, self.folds = variance, alpha, folds

    def fit(self, X, y=None) -> QModel:
        self.used_, self.monitor_ = _fit(np.asarray(X), self.variance, self.alpha, self.folds)
        return self

    def decision_function(self, X) -> np.ndarray:
        return self.monitor_.score_samples(np.asarray(X)[:, self.used_])[1]


def _q_residuals(plan: list, kind: str, train: slice, test: slice, model: QModel, path, window: Window) -> dict:
    """(reference, robot) -> Q of the robot's test days, for the cases of ``plan`` of signal type
    ``kind``, each reference's model fitted once (:func:`analysis.evaluate.evaluate`, the folds given:
    the reference's training days, the test days of every robot it serves); and reference -> the
    fitted :class:`QModel`.

    Raises
    ------
    ValueError
        Naming the reference whose model cannot be fitted on the training days.
    """
    units = {r[0]: r for _, reference, robot in plan if _ == kind for r in (reference, robot)}
    data = Data.of_units([unit[4][kind][0] for unit in units.values()], list(units))
    served = {}
    for k, reference, robot in plan:
        if k == kind:
            served.setdefault(reference[0], []).append(robot[0])
    q, fitted = {}, {}
    for reference, robots in served.items():
        tested = [data.rows(robot)[test] for robot in robots]
        try:
            scores = evaluate(model, data, Given([(data.rows(reference)[train], np.concatenate(tested))]), None,
                              "training source", alarms=False)
        except ValueError as err:
            raise ValueError(f"{path}: the {kind} model of {reference} cannot be fitted on "
                             f"{window.training_days} training days ({err}); use more training days") from err
        fitted[reference] = scores.fitted[0]
        q.update({(reference, robot): scores.scores[rows] for robot, rows in zip(robots, tested)})
    return q, fitted


def _robots(path, window: Window) -> list[tuple]:
    """(run id, robot label, task, condition, signals) of every run of ``path`` (:func:`signals`)."""
    runs = []
    with reader.open(path) as data:
        for run in data.runs:
            try:
                made = signals({name: run.array(name) for name in SCALARS + HISTOGRAMS}, window)
            except ValueError as err:
                raise ValueError(f"{path}: run {run.id} has {err}; a fleet (`faultgen fleet`) records 60 days") from err
            runs.append((run.id, run.robot, run.task, "failure" if run.failing else "normal", made))
    return runs


def study(path, window: Window = Window(), variance: float = 0.90, alpha: float = 0.05,
          limit_folds: int | None = 20, progress: bool = True, train=None) -> pd.DataFrame:
    """Every test case of thesis Table 4.1 on the runs of ``path`` and its descriptors.

    Each run is a robot: failing (``robot condition`` failure) if it has worn axes or a fault,
    otherwise normal. Per signal type, a PCA model (components for ``variance`` of the variance,
    thesis: 90 %; features constant in training left out; linear trends removed from the training
    days, ch. 4.3.2) learns the training days (days 2 to ``training_days``: the first has no
    difference), and the Q residuals of the test days against the ``1 - alpha`` limit give the
    :func:`descriptors`. The limit is eq. 2.6's with residual moments taken over ``limit_folds``
    folds (:class:`~analysis.monitoring.PCAMonitor` ``cv``, at most one fold per day; None: the
    thesis's in-sample limit, crossed on most test days of normal robots when the features are
    nearly as many as the training days). OTO: each robot learns its own
    training days. OTM: each normal robot's training days serve, in turn, as the model for every
    other robot of the same model (robot label). With ``train`` (another dataset, its features
    comparable: :func:`analysis.crossdata.check_comparable`), OTM's models are the normal robots of
    ``train`` instead, each serving every robot of ``path`` of its model (column ``reference``:
    ``<train file>:<run id>``): one-to-many across datasets.

    Returns
    -------
    DataFrame, one row per test case: source (OTM/OTO), signal (raw/difference/combined),
    condition (failure/normal), robot (run id), model (robot label), task, reference (run id of
    the training robot), features (used), components (k), q_limit, cov_q, nsat, lead_time_days,
    test_days, saturated (every test day above the limit). On a normal robot nsat counts false
    alarms and lead_time_days the time since the first one (:func:`normal_false_alarms`).

    Raises
    ------
    ValueError
        If a run has fewer records than the window needs, or the dataset lacks a failing or a
        normal robot, or has no model with two robots for OTM (the message names the preset).
    """
    other = train  # the name `train` is the training days' slice below
    runs = _robots(path, window)
    counts = {c: sum(r[3] == c for r in runs) for c in CONDITIONS}
    if not all(counts.values()):
        raise ValueError(f"{path}: the study compares failing and normal robots; this dataset has {counts['failure']} "
                         f"failing and {counts['normal']} normal. Use a fleet: `faultgen fleet -o fleet.h5`")
    train, test = slice(0, window.training_days - 1), slice(window.training_days - 1, window.days - 1 - window.gap_days)
    cases = []
    if other is None:
        plan = [(kind, reference, robot) for kind in SIGNAL_TYPES for reference in runs
                for robot in runs if robot is reference or (reference[3] == "normal" and robot[1] == reference[1])]
    else:  # OTM's models from the normal robots of another dataset
        from analysis import crossdata

        with reader.open(other) as source, reader.open(path) as data:
            crossdata.check_comparable(source, data)
        normal = [(f"{Path(other).name}:{r[0]}", *r[1:]) for r in _robots(other, window) if r[3] == "normal"]
        plan = [(kind, reference, robot) for kind in SIGNAL_TYPES for robot in runs
                for reference in [robot, *(r for r in normal if r[1] == robot[1])]]
    if not any(robot is not reference for _, reference, robot in plan):
        raise ValueError(f"{path}: one-to-many needs a normal robot and another robot of the same model; "
                         + ("this dataset has none. Use a fleet: `faultgen fleet -o fleet.h5`" if other is None else
                            f"{other} has no normal robot of this dataset's models"))
    model = QModel(variance, alpha, limit_folds)
    judged = {kind: _q_residuals(plan, kind, train, test, model, path, window)
              for kind in tqdm(SIGNAL_TYPES, desc="training-source study", unit="signal", disable=not progress)}
    for kind, reference, robot in plan:
        q, fitted = judged[kind][0][reference[0], robot[0]], judged[kind][1][reference[0]]
        used, monitor = fitted.used_, fitted.monitor_
        cases.append(dict(source="OTO" if robot is reference else "OTM", signal=kind, condition=robot[3],
                          robot=robot[0], model=robot[1], task=robot[2], reference=reference[0],
                          features=len(used), components=monitor.n_components_, q_limit=monitor.q_limit_,
                          **descriptors(q, monitor.q_limit_)))
    return pd.DataFrame(cases)


def design(cases: pd.DataFrame) -> pd.DataFrame:
    """Thesis Table 4.1: test cases per training source, signal type and robot condition."""
    return (cases.groupby(["source", "signal", "condition"]).size().rename("test_cases")
            .reindex(pd.MultiIndex.from_product([SOURCES, SIGNAL_TYPES, CONDITIONS],
                                                names=["source", "signal", "condition"]), fill_value=0)
            .reset_index())


def group_means(cases: pd.DataFrame) -> pd.DataFrame:
    """Mean and standard error of the mean of each descriptor per training source, signal type
    and robot condition (the bars of thesis Figs. 4-4 to 4-6)."""
    grouped = cases.groupby(["source", "signal", "condition"])[list(DESCRIPTORS)]
    return grouped.mean().add_suffix("_mean").join(grouped.sem().add_suffix("_sem")).reset_index()


def anova(cases: pd.DataFrame) -> pd.DataFrame:
    """Three-way ANOVA with all interactions per descriptor (thesis Tables 4.2-4.4).

    Type III sums of squares (the thesis's "Adj SS") with sum-to-zero contrasts, as the design is
    unbalanced (more OTM than OTO cases); statsmodels ``ols`` and ``anova_lm``.

    Returns
    -------
    DataFrame: descriptor, term (``source``, ``signal``, ``condition`` and their products joined
    by ``*``; ``Error``), df, sum_sq, mean_sq, F, p.

    Raises
    ------
    ValueError
        If a cell of the design has no test case (its interactions cannot be estimated); the
        message names the cells.
    """
    import statsmodels.formula.api as smf
    from statsmodels.stats.anova import anova_lm

    empty = design(cases).query("test_cases == 0")
    if len(empty):
        cells = ", ".join("/".join(row) for row in empty[["source", "signal", "condition"]].itertuples(index=False))
        raise ValueError(f"the three-way ANOVA needs test cases in every cell; none in {cells}. A fleet needs "
                         "two normal robots of one model for OTM normal cases (`faultgen fleet` has 13 of 26)")
    names = {"C(source, Sum)": "source", "C(signal, Sum)": "signal", "C(condition, Sum)": "condition",
             "Residual": "Error"}
    tables = []
    for descriptor in DESCRIPTORS:
        fit = smf.ols(f"{descriptor} ~ C(source, Sum) * C(signal, Sum) * C(condition, Sum)", data=cases).fit()
        table = anova_lm(fit, typ=3).drop(index="Intercept")
        table.index = ["*".join(names[part] for part in term.split(":")) for term in table.index]
        table = table.rename(columns={"sum_sq": "sum_sq", "PR(>F)": "p"})
        table["mean_sq"] = table["sum_sq"] / table["df"]
        tables.append(table[["df", "sum_sq", "mean_sq", "F", "p"]].rename_axis("term").reset_index()
                      .assign(descriptor=descriptor))
    out = pd.concat(tables, ignore_index=True)
    return out[["descriptor", "term", "df", "sum_sq", "mean_sq", "F", "p"]]


def tukey(cases: pd.DataFrame, alpha: float = 0.05) -> pd.DataFrame:
    """Tukey's HSD over the twelve cells (source / signal / condition) per descriptor, the post-hoc
    test of ch. 4.3.3 (statsmodels ``pairwise_tukeyhsd``).

    Returns
    -------
    DataFrame, one row per pair of cells and descriptor: descriptor, group1, group2 (as
    ``source/signal/condition``), meandiff (group2 - group1), p_adj, lower, upper, reject, and
    failure_vs_normal (True for the pairs that differ only in the robot condition: the
    comparisons marked in Figs. 4-4 to 4-6).
    """
    from statsmodels.stats.multicomp import pairwise_tukeyhsd

    cell = cases["source"] + "/" + cases["signal"] + "/" + cases["condition"]
    rows = []
    for descriptor in DESCRIPTORS:
        result = pairwise_tukeyhsd(cases[descriptor].to_numpy(dtype=float), cell.to_numpy(), alpha=alpha)
        first, second = np.array(list(combinations(result.groupsunique, 2))).T  # the results' pair order
        rows.append(pd.DataFrame({"descriptor": descriptor, "group1": first, "group2": second,
                                  "meandiff": result.meandiffs, "p_adj": result.pvalues,
                                  "lower": result.confint[:, 0], "upper": result.confint[:, 1],
                                  "reject": result.reject}))
    out = pd.concat(rows, ignore_index=True)
    pair = out["group1"].str.rsplit("/", n=1).str[0] == out["group2"].str.rsplit("/", n=1).str[0]
    out["failure_vs_normal"] = pair
    return out[["descriptor", "group1", "group2", "meandiff", "p_adj", "lower", "upper", "reject", "failure_vs_normal"]]


def failure_vs_normal(tukey_table: pd.DataFrame) -> pd.DataFrame:
    """The Tukey pairs that differ only in the robot condition, one row per descriptor, training
    source and signal type: ``failure_minus_normal`` (difference of the means), ``p_adj`` and
    ``different`` (p_adj < the test's alpha), as starred in thesis Figs. 4-4 to 4-6."""
    pairs = tukey_table[tukey_table["failure_vs_normal"]]
    flipped = pairs["group1"].str.endswith("/normal")  # statsmodels orders the cells by name
    cell = pairs["group1"].str.split("/")
    return pd.DataFrame({"descriptor": pairs["descriptor"], "source": cell.str[0], "signal": cell.str[1],
                         "failure_minus_normal": np.where(flipped, pairs["meandiff"], -pairs["meandiff"]) + 0.0,
                         "p_adj": pairs["p_adj"], "different": pairs["reject"]}).reset_index(drop=True)


def figure(cases: pd.DataFrame, out: Path, marked: pd.DataFrame | None = None) -> Path:
    """Thesis Figs. 4-4 to 4-6 in one PNG: per descriptor, the mean (error bar: standard error)
    per training source and signal type, failure beside normal; ``*`` over a pair that Tukey's
    HSD (``marked``, from :func:`tukey`) finds different."""
    from matplotlib.figure import Figure

    means = group_means(cases)
    fig = Figure(figsize=(13, 4), layout="constrained")
    axes = fig.subplots(1, len(DESCRIPTORS))
    cells = [(s, k) for s in SOURCES for k in SIGNAL_TYPES]
    x = np.arange(len(cells))
    for ax, (descriptor, title) in zip(axes, DESCRIPTORS.items(), strict=True):
        for shift, condition, color in ((-0.2, "failure", "tab:red"), (0.2, "normal", "tab:blue")):
            part = means[means["condition"] == condition].set_index(["source", "signal"]).reindex(cells)
            ax.bar(x + shift, part[f"{descriptor}_mean"], 0.4, yerr=part[f"{descriptor}_sem"], color=color,
                   label=condition, capsize=3)
        top = float((means[f"{descriptor}_mean"] + means[f"{descriptor}_sem"].fillna(0)).max())
        ax.set_ylim(0, top * 1.15 if top > 0 else 1.0)
        if marked is not None:
            hits = marked[(marked["descriptor"] == descriptor) & marked["failure_vs_normal"] & marked["reject"]]
            for i, (source, kind) in enumerate(cells):
                if (hits["group1"].str.startswith(f"{source}/{kind}/")).any():
                    ax.text(i, top * 1.03, "*", ha="center", fontsize=14)
        ax.set_xticks(x, [f"{s}\n{k}" for s, k in cells], fontsize=8)
        ax.set_title(title, fontsize=10)
    axes[0].legend(title="robot condition", fontsize=8)
    fig.suptitle("Training source x signal type x robot condition (thesis ch. 4, Figs. 4-4 to 4-6); "
                 "* Tukey HSD failure vs normal, p < 0.05", fontsize=10)
    fig.savefig(out, dpi=110)
    return out


def report(cases: pd.DataFrame, train=None) -> tuple[str, pd.DataFrame | None, pd.DataFrame | None]:
    """(What ``faultgen training-source`` prints and writes to OUT.md, the ANOVA table, the Tukey HSD
    table) of a :func:`study`'s ``cases`` (``train``: the other dataset OTM learnt from, if any): the
    protocol, the design, the descriptors' means, the normal robots' false alarms, a note on saturated
    limits, and the ANOVA and Tukey HSD (None, said in the text, where a cell is empty)."""
    protocol = ("protocol: OTO, own history (each robot its own training days); OTM, "
                + (f"another dataset (each normal robot of {train} of the same model)" if train is not None
                   else "other robots of this dataset (each normal robot of the same model)"))
    parts = [protocol,
             "Design (thesis Table 4.1), test cases:\n\n" + markdown(design(cases)),
             "Descriptors of the Q residual over the test days, mean and standard error:\n\n"
             + markdown(group_means(cases)),
             "Normal robots never fail: their days above the limit are false alarms (nsat) and their lead_time_days "
             "only how early the first false alarm came. Per training source and signal, their false-alarm share "
             "of the test days and the cases whose limit is saturated (every test day above it):\n\n"
             + markdown(normal_false_alarms(cases))]
    saturated = cases[cases["saturated"] & (cases["condition"] == "normal")]
    if len(saturated):
        parts.append(f"Note: the limit is saturated in {len(saturated)} of {int((cases['condition'] == 'normal').sum())} "
                     "normal-robot cases (all their test days above it: "
                     + ", ".join(f"{s} {k}: {n}" for (s, k), n in saturated.groupby(["source", "signal"]).size().items())
                     + "); there the model does not describe the robot, and a failing robot's alarms in the same "
                     "cell say nothing about its fault")
    anova_table = tukey_table = None
    try:
        anova_table, tukey_table = anova(cases), tukey(cases)
    except ValueError as err:  # an empty cell: the cases and means stand, the tests cannot be run
        parts.append(f"No ANOVA or Tukey HSD: {err}")
    else:
        parts += ["Three-way ANOVA, type III (thesis Tables 4.2-4.4):\n\n" + markdown(anova_table),
                  "Tukey HSD, failure against normal robots per training source and signal type (the starred bars "
                  "of thesis Figs. 4-4 to 4-6):\n\n" + markdown(failure_vs_normal(tukey_table))]
    return "\n\n".join(parts), anova_table, tukey_table
