"""The steps of a unit's monitor (:mod:`faultgen.monitor.scoring`'s docstring), functions over its
record (:class:`~faultgen.monitor.history.UnitHistory`): each log fed (:func:`add`, with its
program's baseline: :func:`run`) through the record's :class:`~faultgen.monitor.scoring.Stages`
appends its :class:`~faultgen.monitor.record.LogRow` to the record's ``rows``; maintenance
(:func:`maintenance`) given between logs (a new program learns its own baseline:
:class:`faultgen.monitor.programs.Baselines`); the unit's rows of alarms.csv (:func:`alarm_rows`);
and the record's entries fed again (:func:`replay`)."""

from __future__ import annotations

import numpy as np

from faultgen.monitor import record
from faultgen.monitor.history import Maintenance, ProgramChange, UnitHistory
from faultgen.monitor.programs import Fused
from faultgen.monitor.scoring import MODEL_UNCERTAINTY, NOT_OBSERVABLE, NOT_OBSERVABLE_LIMITS, Settings, Stages


def start(unit: str, settings: Settings, n_axes: int, signatures: np.ndarray | None = None) -> UnitHistory:
    """A record of ``unit`` before its first log, with its stages (:meth:`Stages.new`)."""
    return UnitHistory(unit, stages=Stages.new(unit, settings, n_axes, signatures))


def maintenance(unit: UnitHistory, stamp: str, event: str, axis: int) -> None:
    """A repair or gearbox change (``event``) on ``axis`` (1..N) logged at ``stamp``, before the next
    log, given to every program's baseline: the open alarm, if any, is closed by it (kept in the
    alarm's ``closed``), and each baseline's offset (the residual's mean, every feature's) is
    learned again from the next ``relearn_logs`` logs, which are scored but do not alarm; its slopes,
    noise and PCA model stay. The wear estimate of every axis restarts from the new offset, and the
    wear the later programs read starts at 0. During the first learning the learning restarts."""
    _maintenance(unit, stamp, event, axis)
    programs = unit.stages.programs
    for k in range(1, len(programs.saved) + 1):
        run(unit, k, lambda: _maintenance(unit, stamp, event, axis))
        if programs.offsets[k - 1] is not None:
            programs.offsets[k - 1] = (np.zeros(unit.stages.n_axes), np.zeros(unit.stages.n_axes))


def _maintenance(unit: UnitHistory, stamp: str, event: str, axis: int) -> None:
    """:func:`maintenance` of the baseline in place."""
    s, b = unit.stages, unit.stages.baseline
    if s.wear.tests is not None:
        s.wear.tests.reset()
    if b.pca is None:
        b.training, b.learned_expectations, b.placeholders = [], [], 0
        return
    s.alarm.close(b, stamp, f"{event} of axis {axis}")
    s.since = (f"{event} of axis {axis}", stamp, len(unit.rows))
    s.alarm.reset()
    b.relearning = []
    s.wear.trend.reset()


def run(unit: UnitHistory, program: int, call) -> None:
    """``call()`` (a step of ``unit``) with program ``program``'s baseline (0: the first's, as the
    stages hold it); the unit's learning pooled (:func:`pool`) once its programs have ``train``
    logs, the rows sorted by stamp after a program learns."""
    s = unit.stages
    if program == 0:
        call()
    else:
        _run(unit, program, call)
    learning = len(s.baseline.training) + sum(len(b.training) for b in s.programs.saved)  # every program's logs
    if s.baseline.pca is None and s.programs.saved and learning >= s.settings.train:
        pool(unit)


def _run(unit: UnitHistory, program: int, call) -> None:
    s, programs = unit.stages, unit.stages.programs
    first, trend = s.baseline, s.wear.trend
    s.baseline = programs.saved[program - 1]
    offset = programs.offsets[program - 1]
    if offset is None and trend.state is not None:
        offset = (trend.state[:, 0].copy(), trend.covariance[:, 0, 0].copy())
    zero = np.zeros(s.n_axes)
    s.wear.trend = Fused(trend, *(offset if offset is not None else (zero, zero)))
    learning = s.baseline.pca is None
    try:
        call()
    finally:
        if learning and s.baseline.pca is not None:  # learned: its rows join the unit's in stamp order
            programs.offsets[program - 1] = offset
            unit.rows.sort(key=lambda row: row.stamp)
        s.baseline, s.wear.trend = first, trend


def pool(unit: UnitHistory) -> None:
    """Learn the unit's baseline on the learning logs of all its programs (``train`` in all: module
    docstring of :mod:`faultgen.monitor.baseline`): each program with at least ``relearn_logs`` of
    them (and the first, always) its own offset, all of them the slopes, noise and PCA model
    (:meth:`~faultgen.monitor.baseline.Baseline.learn_with`); a program with fewer learns its offset
    on its own (:meth:`~faultgen.monitor.baseline.Baseline.fit_offset`). The learning logs' rows are
    scored in stamp order, each on its program's baseline."""
    s, first, baselines = unit.stages, unit.stages.baseline, unit.stages.programs
    parts = [first.training] + [b.training for b in baselines.saved]
    pooled = [k for k, logs in enumerate(parts) if k == 0 or len(logs) >= first.relearn_logs]
    logs = sorted(((t, i, e, c) for i, k in enumerate(pooled) for t, e, c in parts[k]), key=lambda log: log[0])
    groups = np.array([i for _, i, _, _ in logs])
    first.training = [(t, e, c) for t, _, e, c in logs]
    R, offsets = first.fit_shared(groups)
    common = s.shared = first.shared(R, len(R) - len(pooled) - len(first.regressors_))
    counts = np.bincount(groups)
    first.training, first.learned_ = [], int(counts[0])
    error = None if first.signatures is None else first.fit_signatures(R, common["dof"])
    s.wear.start(len(first.regressors_), error, first.gram_inv_)
    zero = np.zeros(s.n_axes)
    for i, k in enumerate(pooled[1:], 1):
        baselines.offsets[k - 1] = (zero, zero)  # learned with the first: its wear read from the same start
        baselines.saved[k - 1].learn_with(common, offsets[i], int(counts[i]))
    for k in range(1, len(parts)):
        if k not in pooled:
            baselines.saved[k - 1].borrowed_ = common
    learned = {t for t, _, _, _ in logs}
    unit.rows[:] = [row for row in unit.rows if row.stamp not in learned]
    for j, (stamp, i, _, _) in enumerate(logs):
        run(unit, pooled[i], lambda j=j, stamp=stamp: score_learning(unit, [stamp], R[j:j + 1], "training"))
    unit.rows.sort(key=lambda row: row.stamp)


def score_learning(unit: UnitHistory, stamps: list[str], R: np.ndarray, phase: str | None = None) -> None:
    """The rows of the learning logs ``stamps`` (residuals ``R`` less offset and slopes), in place of
    those listed for them since a program change; ``phase`` "relearning" after a program change,
    else "training" (None: as the baseline's ``program_changed`` says)."""
    b = unit.stages.baseline
    if b.placeholders:  # the rows standing for these logs since a program change (by stamp: another
        learned = set(stamps)  # program's logs may lie between them, faultgen.monitor.programs)
        unit.rows[:] = [row for row in unit.rows if row.stamp not in learned]
        b.placeholders = 0
    phase = phase or ("relearning" if b.program_changed else "training")
    b.program_changed = False
    for stamp, r in zip(stamps, R):
        wear = b.wear_estimate(r, b.scale_**2)
        _score(unit, stamp, r / b.scale_, phase=phase, wear=None if wear is None else (*wear, wear[1], None))


def add(unit: UnitHistory, stamp: str, residual: np.ndarray, temperature: float, payload: float,
        expected: np.ndarray | None = None) -> None:
    """Feed the unit the next log (``stamp`` later than every earlier one): its residual (n_features,),
    mean joint temperature (deg C, NaN when not logged), payload (kg) and the twin's expected
    features at its conditions (n_features,; None without a twin)."""
    s, b = unit.stages, unit.stages.baseline
    conditions = np.array([temperature, payload], dtype=float)
    if b.pca is None:
        b.training.append((stamp, np.asarray(residual, dtype=float), conditions))
        if expected is not None:
            b.learned_expectations.append(np.asarray(expected, dtype=float))
        if len(b.training) == b.learning_logs:  # learned (Baseline.fit), its logs scored; the first program's
            stamps, R, error, common = b.fit()  # also starts the wear filter and keeps what later ones borrow
            if common is not None:
                s.shared = common
                s.wear.start(len(b.regressors_), error, b.gram_inv_)
            score_learning(unit, stamps, R)
        elif b.program_changed:  # listed at once (scored when the learning is complete)
            unit.rows.append(record.listed(unit.unit, stamp, s.n_axes))
            b.placeholders += 1
        return
    e = np.asarray(residual, dtype=float)
    relearned = b.relearning is not None
    if relearned:
        b.relearning.append((e, conditions))
        if len(b.relearning) == b.relearn_logs:
            b.learn_offset(*(np.stack(logs) for logs in zip(*b.relearning)))
            b.relearning = None
            s.wear.trend.reset()  # the wear restarts from the new offset
            if s.wear.tests is not None:
                s.wear.tests.reset()
    factor = b.prediction_factor(conditions)
    z = b.standardise(e, conditions) / factor
    variance = (b.scale_ * factor) ** 2
    if expected is not None and b.learned_expectations:
        # the twin's prediction of a change from every condition learned from is trusted to
        # MODEL_UNCERTAINTY of its size: that much is added to the residual's noise
        change = np.min(np.abs(np.stack(b.learned_expectations) - expected), axis=0)
        z = z / np.sqrt(1.0 + (MODEL_UNCERTAINTY * change / b.scale_) ** 2)
        variance = variance + (MODEL_UNCERTAINTY * change) ** 2
    x = b.centred(conditions)
    wear = b.wear_estimate(e - b.mean_ - x @ b.slope_, variance)
    if wear is not None:
        # the trend carries the slopes' error in its state (WearTrend): its measurement's
        # error is the noise without the prediction interval's part from the slopes
        # (the offset's share, 1/m, stays: the trend's start carries it)
        noise = variance - (b.scale_ * factor) ** 2 + b.scale_**2 * (1.0 + 1.0 / b.learned_)
        trend_error = b.wear_estimate(np.zeros_like(e), noise)[1]
        wear = (*wear, trend_error, x)
    _score(unit, stamp, z, phase="relearning" if relearned else "monitoring", wear=wear)


def _score(unit: UnitHistory, stamp: str, z: np.ndarray, phase: str, wear=None) -> None:
    s, b = unit.stages, unit.stages.baseline
    t2, q = (float(v[0]) for v in b.pca.score_samples(z[None]))
    alarm = q > b.pca.q_limit_ or t2 > b.pca.t2_limit_
    wear_row, at_once = None, False
    if wear is not None:
        wear, alarm, at_once, wear_row = s.wear.read(stamp, wear, b.observable_)
    scores = b.axis_scores(z)
    ranking = np.argsort(-scores, kind="stable") + 1
    if phase == "monitoring":
        s.alarm.step(b, stamp, z, t2, q, wear, alarm, at_once)
    unit.rows.append(record.LogRow(unit.unit, stamp, phase, q, b.pca.q_limit_, t2, b.pca.t2_limit_, int(alarm),
                                   tuple(int(a) for a in ranking), np.asarray(scores, dtype=float), wear_row))


def alarm_row(unit: UnitHistory) -> dict:
    """The unit's current row of alarms.csv: its open alarm, or why there is none."""
    s, rows = unit.stages, unit.rows
    b, train = s.baseline, s.settings.train
    row = {**s.alarm.open_alarm(), "closed": "", "closed_by": ""}
    if not s.alarm.first_alarm:
        row["evidence"] = (f"no persistent alarm in {len(rows)} logs" if b.pca is not None else
                           f"still learning: {len(b.training)} of {train} logs")
        if s.since is not None and b.pca is not None:  # after maintenance
            what, stamp, before = s.since
            row["evidence"] = (f"no persistent alarm since the {what} of {stamp} ({len(rows) - before} logs "
                               f"since, {len(rows)} in all)")
        if b.relearning is not None:
            row["evidence"] += (f"; learning its offset again after maintenance: {len(b.relearning)} of "
                                f"{b.relearn_logs} logs")
    return row


def alarm_rows(unit: UnitHistory) -> list[dict]:
    """The unit's rows of alarms.csv: every alarm closed by maintenance (``closed``, ``closed_by``),
    then its current row (:func:`alarm_row`)."""
    return [*unit.stages.alarm.closed, alarm_row(unit)]


def not_observable_note(stages: Stages) -> str:
    """The axes not observable on the unit's program in words (:data:`NOT_OBSERVABLE_LIMITS`), or ""."""
    b = stages.baseline
    axes = np.flatnonzero(~b.observable_)
    if b.pca is None or not len(axes):
        return ""
    widths = ", ".join(f"axis {k + 1}: {b.width_[k]:.3g}" for k in axes)
    return (f"axis {', '.join(str(k + 1) for k in axes)} {NOT_OBSERVABLE} (no wear, trend or remaining life): "
            f"one log's 90 % interval of the wear is wider than {NOT_OBSERVABLE_LIMITS:g} x the wear limit "
            f"({NOT_OBSERVABLE_LIMITS * stages.settings.wear_limit:g} points; {widths} points), so the logs cannot "
            "tell it unworn from worn to the limit")


def replay(unit: UnitHistory, settings: Settings, n_axes: int, tests=None) -> UnitHistory:
    """``unit``'s entries fed in order to new stages, each with its program's baseline, its
    maintenance and program changes given where they came: the stages and rows the run that wrote
    the record ended with (``tests``: its friction tests' scale, ``stages.wear.tests``, given before
    the entries). Returns ``unit``."""
    unit.stages, unit.rows = Stages.new(unit.unit, settings, n_axes, unit.signatures), []
    unit.stages.wear.tests = tests
    given: dict[int, list[Maintenance]] = {}
    for m in unit.maintenance:  # grouped by entry, in their order: each looked at once
        given.setdefault(m.at, []).append(m)
    changes: dict[int, list[ProgramChange]] = {}
    for c in unit.program_changes:
        changes.setdefault(c.at, []).append(c)
    for i, e in enumerate(unit.entries):
        for m in given.get(i, ()):
            maintenance(unit, m.stamp, m.event, m.axis)
        for c in changes.get(i, ()):
            unit.stages.programs.new(unit.stages, c.signatures)
        run(unit, e.program, lambda e=e: add(unit, e.stamp, e.residual, e.temperature, e.payload, e.expected))
    for m in given.get(len(unit.entries), ()):
        maintenance(unit, m.stamp, m.event, m.axis)
    return unit
