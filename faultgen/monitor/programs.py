"""A unit's programs in the monitor (issue 90, items 1 and 2): each log placed among the programs
the unit has run (:func:`faultgen.logs.align.place`, from the motion alone), scored on its whole
cycles against that program's own baseline and twin, and every program's wear estimate of an axis
fed to the axis's one filter.

- **References.** A program is known by its :class:`faultgen.logs.align.Reference`, learned from its
  program log (the log its twin replays: the unit's first log, or the first log of a program new to
  the unit) by :func:`reference_of`; a program log of one cycle (no repetition in it) is its own
  cycle. The references are not stored: the unit's state names each program's log (``program``,
  ``program_changes``), from which they are learned again, as the twin is made again from it.
- **Whole cycles.** A log of a known program is scored on the longest run of its whole cycles
  (:func:`span_of`, :func:`scored`), or on as many whole periods from its first sample when it
  holds more of them; the parts before and after are not (a part of a cycle would weigh that part
  of the motion more than the twin's one whole cycle does, and the features are per-sample means);
  a part of at most :data:`EDGE_SAMPLES` samples is the rounding of a boundary and is scored with
  the cycle beside it. A log with no whole cycle is skipped with its reason
  (:func:`refusal_text`).
- **Baselines.** The unit learns once it has ``train`` logs in all, its programs' together
  (:func:`faultgen.monitor.steps.pool`, :mod:`faultgen.monitor.baseline`): each program met by then
  with at least ``relearn_logs`` of them its own offset, all of them one set of condition slopes,
  noise and PCA model; each program its own wear signatures (its twin's). A program met later, or with fewer
  logs in that learning, learns only its offset on its own first ``relearn_logs`` logs (as a unit
  after maintenance does) and borrows the rest. Each program's
  :class:`~faultgen.monitor.baseline.Baseline` is swapped in for its logs (:class:`Baselines`,
  :func:`faultgen.monitor.steps.run`); the unit's stages hold its first program's between logs. The
  alarm (its run of alarming logs), the rows and the friction tests are the unit's.
- **One filter per axis.** Every program's per-log wear estimate of an axis goes to the unit's one
  :class:`faultgen.monitor.wear_trend.WearTrend` with that program's own standard error (an axis a
  program barely excites has a large one and moves the filter little: the Kalman update's
  inverse-variance weighting). A program learned after the first reads the wear since its
  learning; the filtered wear at its learning (and its variance) is added to each of its
  estimates (:class:`Fused`). Its condition slopes' error is not in the filter's state (only the
  first program's is).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from faultgen.logs import align
from faultgen.monitor.baseline import Baseline

#: A log whose span lies within this share of a period of a whole number of periods seems to hold
#: whole cycles (:func:`_starts_a_cycle`, :func:`same_program`: a program log or a unit's first log,
#: which the alignment then checks).
EDGE = align.HINT_SLACK
#: A part of a log before its first or after its last whole cycle of at most this many samples is a
#: boundary rounded to a sample (the alignment finds a cycle's edges to about one sample): scored
#: with the cycle beside it; a log's span short of a whole number of periods by at most this many
#: of its samples counts that period (:func:`periods`).
EDGE_SAMPLES = 2
#: A program log of whole cycles is taken to start at its cycle's start when its first samples are
#: at rest: its joint speed over them below this share of the log's top speed.
START_REST = 0.1
#: Two units' first logs run the same program (they share its twin) within this RMS angle, rad.
SAME_PROGRAM = 1e-3


def _starts_a_cycle(t: np.ndarray, q: np.ndarray, period: float) -> bool:
    """Whether a log seems to start where its program's cycle starts: it spans a whole number of
    periods (within :data:`EDGE`) and its mean joint speed over its first
    :data:`faultgen.logs.align.REST_WINDOW` s is under :data:`START_REST` of its top (at rest)."""
    k = align.log_span(t) / period
    if round(k) < 1 or abs(k - round(k)) > EDGE:
        return False
    w = max(1, int(np.searchsorted(t - t[0], align.REST_WINDOW)))
    top = np.max(np.linalg.norm(q[w:] - q[:-w], axis=1))
    return bool(np.linalg.norm(q[w] - q[0]) <= START_REST * top)


def reference_of(t, q, cycle=None, name: str = "program 1") -> align.Reference:
    """A program's reference from its program log (``t`` (n,) s, ``q`` (n, N) rad, ``cycle`` column
    or None): :func:`faultgen.logs.align.learn`, its cycle started at the log's first sample when
    the log is whole cycles from rest (:func:`_starts_a_cycle`: it replays from its start, as it
    ran), else where ``learn`` starts it; a log that does not repeat is one cycle, its span the period.

    Raises
    ------
    ValueError
        The log barely moves (no program can be told by its motion), or is malformed.
    """
    t, q = np.asarray(t, dtype=float), np.asarray(q, dtype=float)
    found = align.learn(name, t, q, cycle)
    if isinstance(found, align.NoWholeCycle):
        if found.why is not align.Why.NO_PERIOD:
            raise ValueError(f"no program can be learned from the log: {found.why.value} ({found.detail})")
        step = float(np.median(np.diff(t)))
        grid = align.resampled(t, q, step)
        return align.Reference(name, grid, step * len(grid))
    if (align.check_hint(t, cycle, np.zeros(len(t)), len(found.q), found.period).verdict is not align.HintVerdict.AGREES
            and _starts_a_cycle(t, q, found.period)):
        shift = int(round(align.fit(t, q, found).shift)) % len(found.q)
        found = align.Reference(name, np.roll(found.q, -shift, axis=0), found.period)
    return found


def whole_span(cut: align.Cycles, n: int) -> tuple[int, int, int]:
    """The ``[start, stop)`` samples of the longest run of back-to-back whole cycles of ``cut`` in a
    log of ``n`` samples (a part left before or after it of at most :data:`EDGE_SAMPLES` taken in),
    and how many cycles it holds."""
    runs: list[list[align.Cycle]] = []
    for c in cut.cycles:
        if runs and runs[-1][-1].stop == c.start:
            runs[-1].append(c)
        else:
            runs.append([c])
    best = max(runs, key=len)
    start, stop = best[0].start, best[-1].stop
    start = 0 if start <= EDGE_SAMPLES else start
    stop = n if n - stop <= EDGE_SAMPLES else stop
    return start, stop, len(best)


def periods(t, period: float) -> int:
    """How many whole periods of ``period`` s a log of samples ``t`` (n,) s spans: a span short of a
    whole number by at most :data:`EDGE_SAMPLES` of its samples counts it (the rounding of a period to
    a sample, a log at another rate than its program's), a span short by more does not. Scored as
    that many periods (:func:`window`), a log cut 2 % of a period short of three (a tolerance of
    :data:`EDGE` once) lacked 2 % of one cycle, and the friction torque of a move cut in the middle
    keeps its inertial part (:func:`faultgen.monitor.logs.friction_torque`): on a cell with no
    friction scatter such logs' wear reads scattered by 2.5 points where the others' by 0.8
    (docs/analysis.md, "a log scored on whole cycles only")."""
    t = np.asarray(t, dtype=float)
    step = float(np.median(np.diff(t)))
    return int(np.floor((align.log_span(t) + EDGE_SAMPLES * step) / period + 1e-9))  # 1e-9: the sum's rounding


def window(t, period: float, count: int) -> tuple[int, int]:
    """The ``[start, stop)`` samples of ``count`` periods of ``period`` s from the log's first sample."""
    t = np.asarray(t, dtype=float)
    step = float(np.median(np.diff(t)))
    return 0, min(len(t), int(np.searchsorted(t - t[0], count * period - 0.5 * step)))


def span_of(t, cut: align.Cycles | align.NoWholeCycle, period: float) -> tuple[int, int] | None:
    """The ``[start, stop)`` samples of a log (``t`` (n,) s) scored: its longest run of whole cycles
    (:func:`whole_span`) when the log holds no more whole periods than that, or leaves the program's
    path somewhere (a cycle or a part off it); else (a log cut so that
    one of its periods straddles the program's start: :attr:`faultgen.logs.align.Why.CUT_INSIDE`,
    or one a part of a sample short of a period: a cycle logged at 500 Hz against one logged at
    250 Hz) as many whole periods from its first sample (the features are means over the samples of a
    periodic motion: any run of whole periods holds each phase of the cycle as often). None when
    the log spans no whole period or is no whole cycle of the program (another refusal)."""
    count = periods(t, period)
    if isinstance(cut, align.NoWholeCycle):  # on the program's path (it fits), but no cycle from its start inside
        on_path = cut.why in (align.Why.CUT_INSIDE, align.Why.SHORTER_THAN_A_CYCLE)
        return window(t, period, count) if on_path and count >= 1 else None
    start, stop, run = whole_span(cut, len(t))
    off_path = cut.off or any(f is not None and f.use is align.Use.OFF_PATH for f in (cut.lead, cut.trail))
    return (start, stop) if run >= count or off_path else window(t, period, count)


def scored(data, span: tuple[int, int]):
    """The samples ``span`` ``[start, stop)`` of a checked log ``data``
    (:class:`faultgen.logs.measured.MeasuredData`; :func:`span_of`); ``data`` itself when they are all of it."""
    start, stop = span
    if (start, stop) == (0, len(data)):
        return data
    part = slice(start, stop)
    arrays = {name: getattr(data, name)[part] for name in ("t", "q", "qd", "qdd", "tau")}
    arrays.update({name: getattr(data, name)[part] for name in ("joint_temperature", "payload_mass", "cycle")
                   if getattr(data, name) is not None})
    return replace(data, **arrays)


def first_cycle(t, q, cycle=None) -> tuple[np.ndarray, np.ndarray, str]:
    """What a twin replays of its program log (``t`` (n,) s, ``q`` (n, N) rad, ``cycle`` column or
    None): its first whole cycle (``t`` from its start, ``q``) and what it is, for the twin's cache
    key: "" for the whole log (one cycle), ``"1 of K"`` for the first of a log of K whole cycles,
    ``"samples A:B"`` for a whole cycle inside a log cut anywhere, and ``"reference"`` for the
    program's reference cycle itself (the log folded at its period and averaged, from rest:
    :func:`reference_of`) when the log holds no whole cycle from the program's start.

    Raises
    ------
    ValueError
        No program can be learned from the log."""
    t, q = np.asarray(t, dtype=float), np.asarray(q, dtype=float)
    reference = reference_of(t, q, cycle)
    cut = align.whole_cycles(t, q, reference, cycle)
    if isinstance(cut, align.NoWholeCycle):
        if cut.why is not align.Why.CUT_INSIDE:
            raise ValueError(f"the program log has no whole cycle to replay: {refusal_text(cut)}")
        return reference.step * np.arange(len(reference.q)), reference.q, "reference"
    start, stop, count = whole_span(cut, len(t))
    if (start, stop) == (0, len(t)):
        return (t - t[0], q, "") if count == 1 else (t[:cut.cycles[0].stop] - t[0], q[:cut.cycles[0].stop],
                                                     f"1 of {count}")
    first = cut.cycles[0]
    return t[first.start:first.stop] - t[first.start], q[first.start:first.stop], f"samples {first.start}:{first.stop}"


def same_program(earlier_t, earlier_q, earlier_cycle, t, q) -> bool:
    """Whether a log (``t``, ``q``) runs the program of an earlier unit's first log to within
    :data:`SAME_PROGRAM` rad RMS over a whole number of its cycles (at any sample rate)."""
    try:
        reference = reference_of(earlier_t, earlier_q, earlier_cycle)
    except ValueError:  # a log that barely moves: no program to share
        return False
    t = np.asarray(t, dtype=float)
    k = align.log_span(t) / reference.period
    return round(k) >= 1 and abs(k - round(k)) <= EDGE and align.fit(t, q, reference).rms <= SAME_PROGRAM


def refusal_text(refusal: align.NoWholeCycle) -> str:
    """A log's skip reason for its :class:`faultgen.logs.align.NoWholeCycle`: its ``why`` and the
    program it was held against (the same text for every log of one reason, so a unit's reason
    names it once with its count)."""
    against = f" of {refusal.program}" if refusal.program else ""
    return f"no whole cycle{against}: {refusal.why.value}"


class Fused:
    """The unit's wear filter as a program learned after the first feeds it: each of the program's
    estimates plus the filtered wear at its learning (``offset``, its variance ``variance``, both
    (n_axes,)), with no condition slopes (only the first program's are in the filter's state)."""

    def __init__(self, trend, offset: np.ndarray, variance: np.ndarray):
        self.trend, self.offset, self.variance = trend, offset, variance

    def update(self, estimate, error, conditions=None):
        return self.trend.update(np.asarray(estimate) + self.offset,
                                 np.sqrt(np.asarray(error) ** 2 + self.variance), None)

    def condition_part(self, conditions):
        return np.zeros(self.trend.n_axes)

    def reset(self) -> None:
        self.trend.reset()


@dataclass
class Baselines:
    """The baselines of a unit's programs after the first (``saved[k - 1]``: program ``k``'s
    :class:`faultgen.monitor.baseline.Baseline`) and, once each has learned, the filtered wear at
    its learning (``offsets[k - 1]``: (estimate, variance) per axis, or None before)."""

    saved: list[Baseline] = field(default_factory=list)
    offsets: list[tuple[np.ndarray, np.ndarray] | None] = field(default_factory=list)

    def new(self, stages, signatures: np.ndarray | None) -> int:
        """A new program's baseline, empty (learning from its next log), with ``signatures``, among the unit's
        ``stages`` (:class:`faultgen.monitor.scoring.Stages`): its index."""
        # the unit has learned: the new program learns its offset alone
        fresh = Baseline(stages.settings, stages.n_axes, signatures,
                         stages.shared if stages.baseline.pca is not None else None)
        fresh.program_changed = True  # its learning logs listed as they come, then scored as relearning
        self.saved.append(fresh)
        self.offsets.append(None)
        return len(self.saved)


def learning(stages, program: int) -> bool:
    """Whether the unit's program ``program`` (0: its first) is still learning its baseline (``stages``:
    :class:`faultgen.monitor.scoring.Stages`)."""
    return (stages.baseline if program == 0 else stages.programs.saved[program - 1]).pca is None


def mix(entries, names: list[str]) -> str:
    """A unit's program mix: each of its programs (in the order met, ``names``: each baseline's name,
    :func:`faultgen.monitor.sources.labels`) and its scored logs, e.g. ``"program 1: 12 logs, program 2:
    9 logs"`` (``entries`` with a ``program`` index)."""
    count = len(names)
    logs = np.bincount([e.program for e in entries], minlength=count) if entries else np.zeros(count, int)
    return ", ".join(f"{names[k]}: {int(n)} logs" for k, n in enumerate(logs))


def mix_note(stages, entries, names: list[str]) -> str:
    """A unit's note on its programs when it has run more than one (:func:`mix`, and each later
    program of its ``stages`` still learning its baseline), else ""; ``names`` as :func:`mix`'s."""
    if len(names) < 2:
        return ""
    saved = stages.programs.saved
    learning = [f"{names[k + 1]} learning: {len(b.training)} of {b.learning_logs} logs"
                for k, b in enumerate(saved) if b.pca is None]
    return "; ".join([f"programs: {mix(entries, names)}", *learning])
