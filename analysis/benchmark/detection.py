"""Onset of wear by PCA monitoring and its location, per worn run (thesis ch. 3.4, Table 3.5): the
protocols a monitor learns normal operation by, the monitors fitted, the false-alarm rate on healthy
data held out, the table and its charts."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import pandas as pd
from tqdm.auto import tqdm

from analysis import isolation, registry, scoring
from analysis.benchmark.detection_features import (
    StoredHistograms,
    detection_scale,
    group_cycles,
    kl_features,
    sample_histograms,
    torque_record,
)
from analysis.benchmark.tables import TOO_FEW_CYCLES, UNDECIDED
from analysis.benchmark.truth import fault_progress, opened
from analysis.monitoring import fit_q_monitor, reconstruction_contributions, varying_columns
from faultgen import axes
from faultgen.checks import is_whole
from faultgen.data import reader

#: Where the detector learns normal operation (``faultgen detect --protocol``):
#: other-seeds: the runs without wear of the same robot, task and friction model but other seeds
#: (other units); first-cycles: the first samples of the tested run itself (its "first days",
#: thesis ch. 4); same-run: the run without wear of the same seed (thesis ch. 3.4, optimistic: its
#: noise is the tested run's). auto: on a fleet first-cycles (each robot is a unit of its own);
#: on a sweep other-seeds where the dataset has them, else first-cycles where the run has more
#: samples than it learns from, else same-run where the run without wear of the seed exists.
PROTOCOLS = ("auto", "other-seeds", "first-cycles", "same-run")


#: How a detected onset is located (``faultgen detect --locate``): cross-correlation: the axis whose
#: KL features lead every other axis's up to the onset (thesis ch. 3.4.2, Table 3.5; it needs the
#: fault to travel from the worn axis to the others, :func:`locate_onset`); contribution: the axis
#: with the largest reconstruction-based contribution to the PCA monitor's combined index at the
#: samples that raised the alarm (:func:`locate_by_contribution`).
LOCATIONS = ("cross-correlation", "contribution")


#: The samples first-cycles learns from when ``first`` is not given; a run with no more samples
#: than this learns from its first half (:func:`fitted_first`).
FIRST = 20


#: The fewest samples ``auto`` lets a fleet's robot learn from (a PCA monitor and its folds).
MIN_FIRST = 5


def fitted_first(first: int | None, n_samples: int) -> int:
    """The samples first-cycles learns from on a run of ``n_samples``: ``first`` as given, else
    :data:`FIRST`, or half the run (rounded down) when the run has no more samples than that."""
    if first is not None:
        return first
    return FIRST if n_samples > FIRST else n_samples // 2


def detection_table(path, variance: float = 0.75, alpha: float = 0.05, persistence: int = 1,
                    period: int | None = None, progress: bool = True, detector=None, protocol: str = "auto",
                    first: int | None = None, limit_folds: int | None = 20, return_charts: bool = False,
                    locate: str = "cross-correlation"):
    """Onset of wear by PCA monitoring and its location, per worn run (thesis ch. 3.4, Table 3.5),
    with the false-alarm rate on healthy data the monitor did not learn from.

    Features per sample: for each axis, the KL divergence (eq. 5.4) of the 12-bin histogram of
    |motor torque|, normalised by the largest |motor torque| of the training data rounded up to a
    whole percent of the peak motor torque (thesis ch. 3.4: "normalized with respect to maximum
    torque and binned into twelve equal-sized intervals"; :func:`detection_scale`). The bins are
    formed from each cycle's fine counts (:func:`torque_record`), so a run recorded with signals and
    the same run recorded without give the same table (daily records, a fleet's, have only their
    stored 12-bin histograms, binned to the motor's peak torque, and use those). The divergence is
    taken against the run's first sample under same-run (the thesis's), and against the mean histogram
    of the training samples under the held-out protocols: one noisy first cycle shifts every later
    divergence of its run, which a monitor that learned other runs reads as a fault (j2, three
    seeds, other-seeds, 95 % limit, in-sample: 19.1 % false alarms against the first sample,
    8.7 % against the training mean, on 2026-11-22's physics). A sample is one recorded cycle, or
    all the cycles of a ``period`` (60 for the c2 preset's hours of one-minute cycles). A PCA
    monitor (components for ``variance`` of the variance, thesis: 75 %; features constant in
    training are left out) learns
    normal operation as ``protocol`` says (:data:`PROTOCOLS`; ``first`` samples for first-cycles,
    None: :func:`fitted_first`, 20 or half a shorter run);
    wear is detected at the first sample (after the training ones, and at or after the first
    sample with true wear or fault above 0: ``fault_begins_cycle``) whose Q statistic exceeds its
    ``1 - alpha`` limit for ``persistence`` samples in a row; alarms before the fault begins are
    false alarms (``alarms_before_fault_pct``), never a detection (a fleet's failing robots wear
    from a drawn onset day): :data:`analysis.scoring.DETECT_RULES`, computed by :mod:`analysis.scoring`
    as every command's figures are. Under the held-out protocols the Q
    limit is estimated out of sample over ``limit_folds`` folds of the training samples, at most
    one fold per training sample (:class:`~analysis.monitoring.PCAMonitor` ``cv``; None: in-sample,
    eq. 2.6 as in the thesis):
    j2, three seeds, other-seeds, alpha 5 %: 9.0 % false alarms in-sample, 6.2 % with 20 folds;
    same-run always uses the in-sample limit. The onset is located as ``locate`` says
    (:data:`LOCATIONS`): by default the axis the cross-correlation isolator names (ch. 3.4.2) on the
    KL features up to that sample; ``"contribution"`` (the PCA monitor only) the axis of the largest
    contribution to its combined index at the onset's samples.

    The false-alarm rate is the mean of each one's share of alarm samples (``"per_run_mean"``) over
    the runs without wear that the monitor did not learn from (:func:`false_alarm_meaning`): under
    other-seeds the run of the tested seed; under first-cycles every healthy run of the same robot,
    task and friction model (else of the same robot model: a fleet's healthy robots), each judged by
    the protocol itself, a monitor learnt from its own first ``first`` samples, after them. Under same-run it is measured on the
    training run itself (in-sample, said in the ``protocol`` column).

    ``detector``, a scikit-learn estimator whose ``fit(X)`` learns healthy samples and whose
    ``predict(X)`` gives one alarm (truthy) per sample, replaces the PCA monitor (``variance`` and
    ``alpha`` are then unused); it sees the same features.

    Returns
    -------
    DataFrame, one row per worn run: robot, task, run, seed, worn_axis, final_wear_pct, protocol
    (as used; "same-run (in-sample)"), trained_on (runs, or cycles of the run), false_alarm_pct
    (NaN without a healthy run to measure it on), false_alarm_runs (how many), fault_begins_cycle,
    trained_on_fault (the fault began inside the first-cycles training samples),
    alarms_before_fault_pct (alarm share of the tested run's samples after training and before the
    fault begins; NaN if none), features (axes used), detected, onset (sample index, 0-based; NaN
    if not detected), onset_cycle (1-based cycle of that sample's first recorded cycle),
    onset_wear_pct, located_axis (0: undecided), located. With ``return_charts`` also a dict run
    id -> its chart data (per sample: cycle, wear_pct, alarm, t2, q; t2_limit, q_limit, trained,
    begins, onset), what :func:`detection_figure` draws.

    Raises
    ------
    ValueError
        If ``protocol`` is unknown, or the dataset lacks the healthy data it needs (the message
        says what is missing and which protocol or grid provides it).
    """
    _check_settings(protocol, limit_folds, locate, detector)
    with opened(path) as data:
        table, charts = _detection(data, variance, alpha, persistence, period, progress, detector, protocol, first,
                                   limit_folds, locate)
        table.attrs.update(dataset_kind=data.kind, command=data.command, first=first, limit_folds=limit_folds,
                           alpha=alpha, protocol_reasons=charts.pop("_reasons"), locate=locate,
                           imported=bool(data.runs) and all(run.measured for run in data.runs),
                           n_axes=max((c["n_axes"] for c in charts.values()), default=0))
    return (table, charts) if return_charts else table


def _check_settings(protocol: str, limit_folds, locate: str, detector) -> None:
    """Refuse an unknown ``protocol`` or ``locate``, a ``limit_folds`` that is not None or >= 2, and
    location by contribution with a ``detector`` (it has no Q and T2 to take contributions to)."""
    if protocol not in PROTOCOLS:
        raise ValueError(f"unknown protocol {protocol!r}; expected one of: {', '.join(PROTOCOLS)}")
    if limit_folds is not None and not is_whole(limit_folds, 2):
        raise ValueError(f"limit_folds = {limit_folds!r}; expected None (the in-sample Q limit) or a number of folds >= 2")
    if locate not in LOCATIONS:
        raise ValueError(f"unknown location method {locate!r}; expected one of: {', '.join(LOCATIONS)}")
    if locate == "contribution" and detector is not None:
        raise ValueError("--locate contribution takes contributions to the PCA monitor's Q and T2; another detector "
                         "has none: use --locate cross-correlation")


def _auto_protocol(kind: str, others: list, own, n_samples: int, first: int | None) -> tuple[str, str]:
    """The protocol ``auto`` picks for one worn run, and why (a sentence for the user). On a fleet
    ``first`` is fitted to the record (:func:`fitted_first`); a sweep's choice is as before."""
    n_first = fitted_first(first, n_samples)
    if kind == "fleet" and MIN_FIRST <= n_first < n_samples:
        return "first-cycles", (f"a fleet: each robot is a unit of its own and learns its first {n_first} days "
                                "(thesis ch. 4, one-to-one)")
    if others:
        return "other-seeds", "the dataset has runs without wear of other seeds (other units)"
    if (first or FIRST) < n_samples:
        return "first-cycles", (f"no run without wear of another seed; each run learns its first {first or FIRST} "
                                "samples (sweep --seed 0 --seed 1 --seed 2 for other-seeds)")
    if own is not None:
        return "same-run", (f"no run without wear of another seed and runs of {n_samples} samples, too few to "
                            "learn from their first ones; the run without wear of the same seed (in-sample)")
    raise ValueError(f"no protocol fits: no run without wear of another seed or of the same seed, and runs of "
                     f"{n_samples} samples, too few to learn from their first ones (--first); record more cycles "
                     "or sweep with --axis 0 and several seeds")


class _Work:
    """What one detection table shares across its worn runs: the dataset's healthy runs and the
    settings, each run's torque record read once (:func:`torque_record`), one monitor per training
    set (``monitors``) and that monitor's false-alarm rate on the healthy runs it did not learn from
    (``false_alarms``)."""

    def __init__(self, data: reader.Dataset, variance, alpha, period, detector, limit_folds, rules, locate):
        self.path, self.healthy, self.locate = data.path, data.healthy, locate
        self.variance, self.alpha, self.period, self.rules = variance, alpha, period, rules
        self.detector, self.limit_folds = detector, limit_folds
        self.torque: dict[str, np.ndarray | StoredHistograms] = {}
        self.monitors: dict[tuple, tuple] = {}
        self.false_alarms: dict[tuple, tuple] = {}

    def located(self, features: np.ndarray, used: np.ndarray, monitor, onset: int | None) -> int:
        """The axis (1..N) an onset is located at, as ``locate`` says (:data:`LOCATIONS`), from a
        run's KL ``features`` (n_samples, N), the monitor that judged it and the features it used."""
        if self.locate == "contribution":
            return locate_by_contribution(features, used, monitor, onset, self.rules.persistence)
        return locate_onset(features, onset)

    def torque_of(self, run: reader.Run) -> np.ndarray | StoredHistograms:
        """A run's per-cycle |motor torque| counts (:func:`torque_record`), read once."""
        if run.id not in self.torque:
            self.torque[run.id] = torque_record(run)
        return self.torque[run.id]

    def similar(self, run: reader.Run) -> list[reader.Run]:
        """Healthy runs to measure false alarms on under first-cycles: of the same kind (robot,
        task, friction), else of the same robot model (a fleet's robots each have their own task),
        else all."""
        for match in (lambda r: _same_unit_kind(r, run), lambda r: r.robot == run.robot, lambda r: True):
            chosen = [r for r in self.healthy if match(r)]
            if chosen:
                return chosen
        return []

    def fit(self, training: list, held_out: bool) -> tuple:
        """:func:`_fit_monitor` on ``training`` with the table's settings; a monitor of a held-out
        protocol judges against the training data's mean histogram and, with ``limit_folds``, an
        out-of-sample Q limit."""
        return _fit_monitor(training, self.period, self.variance, self.alpha, self.detector,
                            fixed_reference=held_out, folds=self.limit_folds if held_out else None)

    def plan(self, run: reader.Run, protocol: str, own, others: list, sample_of: np.ndarray,
             samples: np.ndarray, n_first: int) -> tuple:
        """What the monitor of worn ``run`` learns from under ``protocol`` (``own``: the healthy run of
        its seed or None, ``others``: those of other seeds): the training (run id, torque record,
        cycles) list, the key of its monitor, what it was trained on (words), the healthy runs its
        false alarms are measured on, and the samples of ``run`` it learned from (``skip``).

        Raises
        ------
        ValueError
            If the dataset lacks the healthy data the protocol needs (naming what and the remedy).
        """
        if protocol == "other-seeds":
            if not others:
                raise ValueError(f"{self.path}: protocol other-seeds needs runs without wear of {run.robot} "
                                 f"{run.task} with another seed than {run.seed}; this dataset has none"
                                 f"{_unlike(run, self.healthy)}. Sweep "
                                 "several seeds (--seed 0 --seed 1 --seed 2) or use --protocol first-cycles")
            training = [(r.id, self.torque_of(r), r.recorded) for r in others]
            key, trained_on, heldout, skip = tuple(r.id for r in others), " ".join(r.id for r in others), \
                [own] if own else [], 0
            if own is None and len(others) > 1:  # no healthy run of the tested seed: each other one in turn
                heldout = [("leave-one-out", r, [o for o in others if o is not r]) for r in others]
        elif protocol == "first-cycles":
            if len(samples) <= n_first:
                raise ValueError(f"{self.path}: protocol first-cycles learns from the first {n_first} samples of a "
                                 f"run and needs more; {run.id} has {len(samples)}. Give a smaller --first, record more "
                                 "cycles, or sweep several seeds (--seed 0 --seed 1 --seed 2) for --protocol other-seeds")
            keep = np.isin(sample_of, samples[:n_first])
            training = [(run.id, self.torque_of(run)[keep], run.recorded[keep])]
            key, trained_on = (run.id, n_first), f"samples 1-{n_first} of the run"
            heldout, skip = self.similar(run), n_first
        else:  # same-run
            if own is None:
                raise ValueError(f"{self.path}: protocol same-run needs the run without wear of {run.robot} "
                                 f"{run.task} seed {run.seed}; this dataset has none{_unlike(run, self.healthy)}: "
                                 "use --protocol first-cycles (or auto)")
            training = [(own.id, self.torque_of(own), own.recorded)]
            key, trained_on, heldout, skip = (own.id,), own.id, [own], 0
        return training, key, trained_on, heldout, skip

    def false_alarm(self, run: reader.Run, protocol: str, heldout: list, fitted: tuple, skip: int,
                    n_first: int) -> tuple:
        """The false-alarm rate (%) of the monitor ``fitted`` (scale, reference, features used,
        monitor) for worn ``run`` on the healthy runs ``heldout`` it did not learn from, each judged
        as ``protocol`` says: (the rate of :func:`analysis.scoring.false_alarm_rate` under the table's
        rules, % or NaN, runs judged, its Clopper-Pearson interval)."""
        scale, reference, used, monitor = fitted
        judged = []  # each healthy run's alarms after what its monitor learned from
        for normal_run in heldout:
            if isinstance(normal_run, tuple):  # other-seeds: a monitor of the other healthy runs judges it
                _, normal_run, rest = normal_run
                n_scale, n_reference, n_used, n_monitor = self.fit(
                    [(r.id, self.torque_of(r), r.recorded) for r in rest], True)
                normal, _ = kl_features(self.torque_of(normal_run), normal_run.recorded, n_scale, self.period,
                                        n_reference)
                flags = np.asarray(n_monitor.predict(normal[:, n_used]), dtype=bool)
            elif protocol == "first-cycles" and normal_run is not run:  # the protocol on a healthy robot
                normal_of = group_cycles(normal_run.recorded, self.period)
                if len(np.unique(normal_of)) <= n_first:
                    continue
                own_keep = np.isin(normal_of, np.unique(normal_of)[:n_first])
                n_scale, n_reference, n_used, n_monitor = self.fit(
                    [(normal_run.id, self.torque_of(normal_run)[own_keep], normal_run.recorded[own_keep])], True)
                normal, _ = kl_features(self.torque_of(normal_run), normal_run.recorded, n_scale, self.period,
                                        n_reference)
                flags = np.asarray(n_monitor.predict(normal[:, n_used]), dtype=bool)[n_first:]
            else:
                normal, _ = kl_features(self.torque_of(normal_run), normal_run.recorded, scale, self.period,
                                        reference)
                flags = np.asarray(monitor.predict(normal[:, used]), dtype=bool)[skip:]
            judged.append(flags)
        return (scoring.false_alarm_rate(judged, self.rules, scale=100.0), len(judged),
                false_alarm_interval(*scoring.alarm_counts(judged)))


def _detection(data: reader.Dataset, variance, alpha, persistence, period, progress, detector, protocol, first,
               limit_folds, locate) -> tuple[pd.DataFrame, dict]:
    rules = scoring.DETECT_RULES.with_persistence(persistence)  # the onset from the fault's first sample
    work = _Work(data, variance, alpha, period, detector, limit_folds, rules, locate)
    healthy = work.healthy
    far: dict[str, tuple] = {}  # runs whose Q limit lies FAR_LIMIT times above every Q they were tested on
    rows, charts, reasons = [], {}, {}
    for run in tqdm(data.runs, desc="detection", unit="run", disable=not progress):
        if len(run.worn_axes) != 1:
            continue
        axis = run.worn_axes[0]
        same = [r for r in healthy if _same_unit_kind(r, run)]
        own = next((r for r in same if r.seed == run.seed), None)
        others = [r for r in same if r.seed != run.seed]
        sample_of = group_cycles(run.recorded, period)
        samples = np.unique(sample_of)
        n_samples = len(samples)
        used_protocol, n_first = protocol, fitted_first(first, n_samples)
        if protocol == "auto":  # a fleet's robots are units of their own: each learns its first days (thesis ch. 4)
            used_protocol, reason = _auto_protocol(data.kind, others, own, n_samples, first)
            if run.measured and used_protocol == "first-cycles":
                reason = (f"units imported from logs: each unit learns its first {fitted_first(first, n_samples)} logs "
                          "(thesis ch. 4, one-to-one)")
            reasons[used_protocol] = reason
        training, key, trained_on, heldout, skip = work.plan(run, used_protocol, own, others, sample_of, samples,
                                                             n_first)
        if key not in work.monitors:  # one monitor serves every worn run that learns from the same data
            work.monitors[key] = work.fit(training, used_protocol != "same-run")

        if used_protocol == "same-run":
            used_protocol = "same-run (in-sample)"
        scale, reference, used, monitor = work.monitors[key]
        worn, groups = kl_features(work.torque_of(run), run.recorded, scale, period, reference)
        alarms = np.asarray(monitor.predict(worn[:, used]), dtype=bool)
        # the fault's first sample: an alarm before it is a false alarm, never a detection (rules)
        begins = run.fault_begins
        start = None if begins is None else int(groups[begins])
        onset = scoring.onset(alarms, rules, fault_start=start, skip=skip)
        before = scoring.before_fault(alarms, start, skip)
        if key not in work.false_alarms:
            work.false_alarms[key] = work.false_alarm(run, used_protocol, heldout, work.monitors[key], skip,
                                                      n_first)
        false_alarm, n_normal, (low, high) = work.false_alarms[key]
        wear = fault_progress(run, axis) * 100.0 - 100.0
        located = work.located(worn, used, monitor, onset)
        rows.append(dict(robot=run.robot, task=run.task, run=run.id, seed=run.seed,
                         worn_axis=axis, final_wear_pct=round(float(wear[-1]), 2), protocol=used_protocol,
                         trained_on=trained_on, false_alarm_pct=round(false_alarm, 2), false_alarm_runs=n_normal,
                         false_alarm_ci_pct=f"{low:.1f}-{high:.1f}" if np.isfinite(low) else "",
                         false_alarm_above_alpha=bool(low > 100.0 * alpha),
                         fault_begins_cycle=np.nan if begins is None else int(run.recorded[begins]),
                         trained_on_fault=begins is not None and int(groups[begins]) < skip,
                         alarms_before_fault_pct=round(100.0 * float(before.mean()), 2) if before.size else np.nan,
                         features=" ".join(str(u + 1) for u in used), detected=onset is not None,
                         onset=np.nan if onset is None else int(onset),
                         onset_cycle=np.nan if onset is None else int(run.recorded[groups == onset][0]),
                         onset_wear_pct=np.nan if onset is None else round(float(wear[groups == onset].max()), 2),
                         located_axis=located, located=bool(scoring.isolation_right(located, axis))))
        if run.measured:  # no wear is measured: a worn log's friction_multiplier is a mark, not a percentage
            del rows[-1]["final_wear_pct"], rows[-1]["onset_wear_pct"]
        chart = {"sample": np.arange(len(alarms)),
                 "cycle": np.array([run.recorded[groups == g][0] for g in range(len(alarms))]),
                 "wear_pct": np.array([wear[groups == g].max() for g in range(len(alarms))]), "alarm": alarms}
        if hasattr(monitor, "score_samples") and hasattr(monitor, "q_limit_"):
            t2, q = monitor.score_samples(worn[:, used])
            chart.update(t2=t2, q=q, t2_limit=monitor.t2_limit_, q_limit=monitor.q_limit_)
            tested = q[skip:] if skip < len(q) else q
            if tested.size and monitor.q_limit_ >= FAR_LIMIT * max(float(tested.max()), 1e-300):
                far[run.id] = (float(monitor.q_limit_), float(tested.min()), float(tested.max()), trained_on)
        charts[run.id] = dict(chart, trained=skip, onset=onset, begins=None if begins is None else int(groups[begins]),
                              protocol=used_protocol, robot=run.robot, task=run.task, worn_axis=axis,
                              n_axes=worn.shape[1])
    table = pd.DataFrame(rows)
    # what detection_advice needs: the sample each fault begins at (what --first must stay below)
    table.attrs["fault_begins_sample"] = {r: c["begins"] for r, c in charts.items() if c["begins"] is not None}
    table.attrs["q_limit_far"] = far
    charts["_reasons"] = reasons
    return table, charts


def locate_onset(features: np.ndarray, onset: int | None) -> int:
    """The axis (1..N) the cross-correlation isolator (thesis ch. 3.4.2) names on ``features``
    (n_samples, N) up to and including the ``onset`` sample, as ``faultgen detect`` locates (with
    or without ``--train``); :data:`UNDECIDED` without an onset, :data:`TOO_FEW_CYCLES` when too
    few samples precede it to cross-correlate (said, not undecided)."""
    if onset is None:
        return UNDECIDED
    try:
        return int(isolation.make("cross_correlation").fit(features[: onset + 1]).source_axis_)
    except ValueError:
        return TOO_FEW_CYCLES


def locate_by_contribution(features: np.ndarray, used: np.ndarray, monitor, onset: int | None,
                           persistence: int = 1) -> int:
    """The axis (1..N) whose KL feature has the largest reconstruction-based contribution (Alcala and
    Qin, Automatica 45 (2009) 1593-1600) to the combined index ``Q / Q_limit + T2 / T2_limit`` (Yue
    and Qin 2001) of the fitted :class:`~analysis.monitoring.PCAMonitor` ``monitor``, averaged over
    the samples that raised the alarm (``onset`` .. ``onset + persistence - 1``); ``used``: the
    columns of ``features`` (n_samples, N) the monitor learned. :data:`UNDECIDED` without an onset or
    on a tie. Q alone cannot rank the axes when the monitor keeps all but one component (every
    axis's contribution is then the whole Q), as on six weakly correlated KL features at 75 %."""
    if onset is None:
        return UNDECIDED
    index = monitor.index_matrix("q") / monitor.q_limit_ + monitor.index_matrix("t2") / monitor.t2_limit_
    alarm = (features[onset: onset + persistence][:, used] - monitor.mean_) / monitor.scale_
    scores = reconstruction_contributions(alarm, index).mean(axis=0)
    best = np.flatnonzero(np.isclose(scores, scores.max(), rtol=1e-9, atol=1e-12))
    return axes.number(int(used[best[0]])) if best.size == 1 and np.isfinite(scores).all() else UNDECIDED


#: A Q limit this many times the largest Q of the samples a run is tested on (two decades) is said
#: by :func:`detection_advice`: Q cannot alarm there, and the usual cause is a learning sample unlike
#: the others (an outlying day or log), whose out-of-fold residual sets the limit.
FAR_LIMIT = 100.0


def false_alarm_interval(alarms: int, samples: int, level: float = 0.95) -> tuple[float, float]:
    """Clopper-Pearson ``level`` interval of a false-alarm rate, % (``scipy.stats.binomtest``),
    from the alarms among the healthy samples judged; (nan, nan) without samples. Samples of a run
    are correlated, so the interval is if anything too narrow: a rate whose interval lies above
    the nominal alpha is above it."""
    if samples == 0:
        return np.nan, np.nan
    from scipy.stats import binomtest

    ci = binomtest(int(alarms), int(samples)).proportion_ci(confidence_level=level, method="exact")
    return round(100.0 * ci.low, 2), round(100.0 * ci.high, 2)


def _same_unit_kind(a: reader.Run, b: reader.Run) -> bool:
    """Whether ``a`` and ``b`` may be compared: same robot, program (its hash), friction model and
    operating conditions (:attr:`faultgen.data.reader.Run.setup`)."""
    return a.setup == b.setup


def _unlike(run: reader.Run, healthy: Iterable[reader.Run]) -> str:
    """For an error: the healthy runs of ``run``'s robot and task label that differ in setup, and how."""
    unlike = [(r, reader.difference(run, r)) for r in healthy if (r.robot, r.task) == (run.robot, run.task)]
    unlike = [(r, why) for r, why in unlike if why]
    if not unlike:
        return ""
    return (f" ({len(unlike)} runs without wear of that label are not comparable with it: {unlike[0][0].id} differs "
            f"in {unlike[0][1]})")


def _fit_monitor(training: list, period: int | None, variance: float, alpha: float, detector=None,
                 fixed_reference: bool = False, folds: int | None = None):
    """The torque scale (:func:`detection_scale`), the KL reference (None: each run's first
    sample), the features used and the monitor (or ``detector``) fitted on the KL features of
    ``training``, a list of (run id, its :func:`torque_record`, cycles). With ``fixed_reference``
    the reference is the mean histogram of all training samples, shared by every run the monitor
    judges; ``folds`` is the PCA monitor's ``cv`` (out-of-sample Q limit)."""
    from sklearn.base import clone

    stored = [isinstance(t, StoredHistograms) for _, t, _ in training]
    scale = None if any(stored) else detection_scale([t for _, t, _ in training])
    reference = None
    if fixed_reference:
        reference = np.concatenate([sample_histograms(t, cycles, scale, period)[0] for _, t, cycles in training]).mean(axis=0)
    normal = np.vstack([kl_features(t, cycles, scale, period, reference)[0] for _, t, cycles in training])
    used = varying_columns(normal)  # features constant in training are left out
    if detector is not None:
        return scale, reference, used, clone(detector).fit(normal[:, used])
    if folds is not None:
        folds = min(folds, len(normal))  # at most one fold per training sample
    try:
        made = registry.make("pca_monitor", variance=variance, alpha=alpha, statistic="q", cv=folds)[1]
        return scale, reference, used, fit_q_monitor(normal[:, used], made)
    except ValueError as err:
        if folds is None:
            raise
        raise ValueError(f"the out-of-sample Q limit over {folds} folds of {len(normal)} training samples: {err}; "
                         "give fewer folds (--limit-folds 5) or 0 (the in-sample limit)") from None
