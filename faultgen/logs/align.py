"""A unit's programs recognised from the motion, and the whole cycles of a log cut anywhere (issue 90,
items 1 and 2).

A program is known by its **reference** (:class:`Reference`): the joint path of one whole cycle,
``q`` (m, N) rad at a step ``period / m`` s, its sample 0 the cycle's start, learned from the first log
of the program that holds enough of it (:func:`learn`). A log (samples ``t`` (n,) s, angles ``q`` (n, N)
rad, any span from any phase, any sample rate) is compared with each reference by the best circular
shift of the reference's cycle along the log (the log resampled linearly onto the reference's step;
every shift's mean squared angle difference at once by FFT cross-correlation, the best refined to a
fraction of a sample by a parabola): the RMS angle difference at that shift, rad, over every axis and
sample, is the log's distance from the program (:attr:`Fit.rms`; :attr:`Fit.window` over the log's best
stretch of one period). A log runs the program within :data:`TOLERANCE` of it over a whole period
(:func:`recognise`); within the tolerance of none it runs a new program, of two or more it is
ambiguous, and a log that barely moves (its path's RMS spread under :data:`MIN_MOTION`) tells no
program apart. Nothing but the motion is read: never a log's name, position or ``cycle`` column.

The **whole cycles** of a log (:func:`whole_cycles`) are where the fitted shift puts the reference's
start: ``[start, stop)`` sample spans of one period each, each checked against the reference
(:data:`TOLERANCE`). The parts before the first and after the last (:class:`Fragment`) are aligned
at their phase of the cycle and used when they span at least :data:`MIN_FRAGMENT` of a period and
trace the reference, else dropped, with the reason. A ``cycle`` column is a hint (:class:`Hint`):
checked against the period found in the motion (each run but the log's first and last one period
long within :data:`HINT_SLACK`, none longer, every boundary at one phase), reported, and never used
over the motion; a log whose hint says 0.072 s is a cycle of a 7 s program gets its whole cycles from
the motion all the same. A log with no whole cycle says why (:class:`NoWholeCycle`).

A **new program's period** (:func:`period`) is found without a reference from the log's own
autocorrelation: the first lag, past the lags at which the path has moved away from itself, at
which the log and itself shifted by the lag differ by at most :data:`TOLERANCE` over an overlap of at
least :data:`MIN_OVERLAP` of the lag (the squared-difference function of YIN, de Cheveigne & Kawahara
2002, on the joint path). Its reference (:func:`learn`) is the log folded at that period and
averaged, started where a checked ``cycle`` hint starts its cycles, else in the middle of the cycle's
longest rest (so that the cycle the twin replays starts and ends at rest).

Every tolerance here is for joint angles of a repeating controller program (encoder noise and
tracking: about 1e-3 rad): a speed override other than the one the reference was learned at changes
the period and reads as a new program.
"""

from __future__ import annotations

import enum
import functools
from dataclasses import dataclass

import numpy as np

from faultgen.logs.measured import cycle_slices

#: The largest RMS angle difference, rad, of a log from a program it runs (every axis and sample at
#: the best shift); the independent KR210 cell's part variants lie 0.5-1.8 rad apart (docs/analysis.md),
#: noise and tracking about 1e-3 rad.
TOLERANCE = 0.02
#: The least RMS spread of a log's path about its mean, rad, for its program to be told (a log of a
#: robot standing still matches every program that passes its pose).
MIN_MOTION = 0.05
#: The least overlap of a log with itself shifted by a period, as a share of the period, for a new
#: program's period to be found in it: a log of 1.3 cycles.
MIN_OVERLAP = 0.3
#: The least span of a leading or trailing fragment, as a share of the period, for it to be used.
MIN_FRAGMENT = 0.2
#: How far a ``cycle`` column's runs and boundaries may lie off the motion's, as a share of the period.
HINT_SLACK = 0.02
#: A reference sample is at rest below this share of the cycle's top joint speed (smoothed over
#: :data:`REST_WINDOW` s): the new reference starts in the middle of the longest rest.
REST_SHARE, REST_WINDOW = 0.02, 0.05


class Status(enum.Enum):
    """What :func:`recognise` made of a log."""
    KNOWN = "known"  #: within the tolerance of exactly one program
    NEW = "new"  #: within the tolerance of none
    AMBIGUOUS = "ambiguous"  #: within the tolerance of two or more
    STILL = "still"  #: too little motion to tell (:data:`MIN_MOTION`)


class Why(enum.Enum):
    """Why a log gives no whole cycle (:class:`NoWholeCycle`)."""
    SHORTER_THAN_A_CYCLE = "shorter than one cycle"
    CUT_INSIDE = "spans a cycle or more but holds no whole one"
    OFF_PROGRAM = "off the program's path"
    NO_PERIOD = "no period found"
    STILL = "too little motion"
    AMBIGUOUS = "matches several programs"


class Use(enum.Enum):
    """What was done with a leading or trailing fragment."""
    USED = "aligned and used"
    SHORT = "dropped: shorter than MIN_FRAGMENT of a cycle"
    OFF_PATH = "dropped: off the program's path"


class HintVerdict(enum.Enum):
    """A ``cycle`` column checked against the motion."""
    NONE = "no cycle column"
    AGREES = "agrees with the motion"
    DISAGREES = "disagrees with the motion: not used"
    UNCHECKED = "too few runs to check: not used"


@dataclass(frozen=True)
class Reference:
    """A program's reference: ``name``, ``q`` (m, N) rad, one whole cycle at a step of ``period / m``
    s, its sample 0 the cycle's start."""

    name: str
    q: np.ndarray
    period: float

    def __post_init__(self) -> None:
        q = np.asarray(self.q, dtype=float)
        if q.ndim != 2 or len(q) < 3 or not np.all(np.isfinite(q)):
            raise ValueError(f"program {self.name!r}: q of shape {q.shape}: expected finite angles (m >= 3, N) rad")
        if not (np.isfinite(self.period) and self.period > 0):
            raise ValueError(f"program {self.name!r}: period {self.period!r} s: expected a positive time")
        object.__setattr__(self, "q", q)

    @property
    def step(self) -> float:
        """The reference's sample step, s."""
        return self.period / len(self.q)

    @functools.cached_property
    def spectra(self) -> tuple[list[np.ndarray], np.ndarray]:
        """The real FFTs every :func:`fit` against this program takes of its cycle: each axis's
        column of :attr:`q` and the sum of their squares (the same calls, computed once a reference,
        not once a log; not pickled with it)."""
        return [np.fft.rfft(self.q[:, a]) for a in range(self.q.shape[1])], np.fft.rfft(np.sum(self.q * self.q, axis=1))

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state.pop("spectra", None)  # made again where needed
        return state


@dataclass(frozen=True)
class Fit:
    """A log against one program: ``program`` (its name), ``rms`` rad over the whole log, ``shift``:
    the reference sample (fractional, in [0, m)) at the log's first sample, and ``window``: the RMS,
    rad, over the log's best stretch of one period at that shift (the whole log's under a period): a
    log that runs the program for a whole period is of it even where it leaves it elsewhere (a stop)."""

    program: str
    rms: float
    shift: float
    window: float


@dataclass(frozen=True)
class Recognition:
    """The program a log runs: ``status``, ``program`` (a known program's name for KNOWN, else None),
    ``fits`` (every known program's :class:`Fit`, closest first) and ``spread`` (the log's path's RMS
    spread, rad)."""

    status: Status
    program: str | None
    fits: tuple[Fit, ...]
    spread: float


@dataclass(frozen=True)
class Cycle:
    """One whole cycle: samples ``[start, stop)`` of the log, its ``rms`` rad off the reference."""

    start: int
    stop: int
    rms: float


@dataclass(frozen=True)
class Fragment:
    """A part of a log before its first or after its last whole cycle: samples ``[start, stop)``,
    ``phase`` (the share of the cycle at its first sample), ``rms`` rad off the reference there, and
    ``use``."""

    start: int
    stop: int
    phase: float
    rms: float
    use: Use


@dataclass(frozen=True)
class Hint:
    """A ``cycle`` column checked: ``verdict`` and ``detail`` (a sentence for the log's row)."""

    verdict: HintVerdict
    detail: str = ""


@dataclass(frozen=True)
class Cycles:
    """The whole cycles of a log of ``program``: ``cycles`` (in order), ``off`` (cycles more than the
    tolerance off the reference: not whole cycles of it), ``lead`` and ``trail`` fragments (or None),
    ``period`` s, the log's ``fit`` and its ``hint``."""

    program: str
    cycles: tuple[Cycle, ...]
    off: tuple[Cycle, ...]
    lead: Fragment | None
    trail: Fragment | None
    period: float
    fit: Fit
    hint: Hint

    @property
    def spans(self) -> list[tuple[int, int]]:
        """The ``[start, stop)`` sample spans of the whole cycles."""
        return [(c.start, c.stop) for c in self.cycles]


@dataclass(frozen=True)
class NoWholeCycle:
    """A log not scored: ``why`` and ``detail`` (a sentence for the log's row), the ``program`` it was
    held against (or None) and its ``hint``."""

    why: Why
    detail: str
    program: str | None = None
    hint: Hint = Hint(HintVerdict.NONE)


def _checked(t, q) -> tuple[np.ndarray, np.ndarray]:
    """``t`` (n,) s strictly increasing and ``q`` (n, N) rad finite, as float arrays; ValueError naming
    the offending input."""
    t, q = np.asarray(t, dtype=float), np.asarray(q, dtype=float)
    if q.ndim == 1:
        q = q[:, None]
    if t.ndim != 1 or len(t) < 3 or q.ndim != 2 or len(q) != len(t):
        raise ValueError(f"a log of t {t.shape} and q {q.shape}: expected t (n >= 3,) s and q (n, N) rad")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(q))):
        raise ValueError("a log with a non-finite time or angle: expected finite t s and q rad")
    if np.any(np.diff(t) <= 0):
        k = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise ValueError(f"a log's time at sample {k + 1} ({t[k + 1]:g} s) does not follow {t[k]:g} s: "
                         "expected strictly increasing times")
    return t, q


def resampled(t: np.ndarray, q: np.ndarray, step: float) -> np.ndarray:
    """The log resampled linearly every ``step`` s from its first sample: (k, N) rad."""
    times = t[0] + step * np.arange(int(np.floor((t[-1] - t[0]) / step + 1e-9)) + 1)
    return np.column_stack([np.interp(times, t, q[:, a]) for a in range(q.shape[1])])


def _spread(q: np.ndarray) -> float:
    """The path's RMS spread about its mean, rad."""
    return float(np.sqrt(np.mean((q - q.mean(axis=0)) ** 2)))


def _circular(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``sum_k a[k] b[(k + s) mod m]`` for every ``s`` in [0, m): ``a`` (m,) and ``b`` the real FFT
    (``np.fft.rfft``) of the other array of length m."""
    return np.fft.irfft(np.conj(np.fft.rfft(a)) * b, len(a))


def _shift_distances(x: np.ndarray, program: Reference) -> np.ndarray:
    """The mean squared angle difference, rad^2, between ``x`` (n, N) and the cycle ``r`` (m, N) of
    ``program`` repeated, log sample ``i`` against reference sample ``(i + s) mod m``, for every ``s``
    in [0, m) (the cycle's FFTs :attr:`Reference.spectra`)."""
    r, (columns, squares) = program.q, program.spectra
    m, n = len(r), len(x)
    bins = np.arange(n) % m
    folded = np.column_stack([np.bincount(bins, x[:, a], minlength=m) for a in range(x.shape[1])])
    count = np.bincount(bins, minlength=m).astype(float)
    cross = sum(_circular(folded[:, a], columns[a]) for a in range(r.shape[1]))
    total = np.sum(x * x) + _circular(count, squares) - 2.0 * cross
    return np.maximum(total, 0.0) / x.size


def _vertex(before: float, at: float, after: float) -> float:
    """The offset in [-0.5, 0.5] of the vertex of the parabola through three equally spaced values."""
    curve = before - 2.0 * at + after
    return 0.0 if curve <= 0 else float(np.clip(0.5 * (before - after) / curve, -0.5, 0.5))


def _at(r: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """The cycle ``r`` (m, N) repeated, interpolated linearly at fractional sample ``positions``."""
    m = len(r)
    low = np.floor(positions)
    w = (positions - low)[:, None]
    low = low.astype(int) % m
    return r[low] * (1.0 - w) + r[(low + 1) % m] * w


def fit(t, q, program: Reference) -> Fit:
    """The log (``t`` (n,) s, ``q`` (n, N) rad) against ``program``: the best circular shift of its
    cycle along the log and the RMS angle difference there (module docstring). ValueError for a
    malformed log or one of another number of axes than the program's."""
    t, q = _checked(t, q)
    if q.shape[1] != program.q.shape[1]:
        raise ValueError(f"a log of {q.shape[1]} axes against program {program.name!r} of "
                         f"{program.q.shape[1]}: expected the same axes")
    x = resampled(t, q, program.step)
    d = _shift_distances(x, program)
    m, best = len(d), int(np.argmin(d))
    shift = (best + _vertex(d[best - 1], d[best], d[(best + 1) % m])) % m
    squares = np.mean((x - _at(program.q, shift + np.arange(len(x)))) ** 2, axis=1)
    rms = float(np.sqrt(np.mean(squares)))
    if len(x) <= m:
        return Fit(program.name, rms, float(shift), rms)
    sums = np.concatenate([[0.0], np.cumsum(squares)])
    return Fit(program.name, rms, float(shift), float(np.sqrt(np.min(sums[m:] - sums[:-m]) / m)))


def recognise(t, q, programs, tolerance: float = TOLERANCE) -> Recognition:
    """Which of ``programs`` (:class:`Reference` s, the unit's known programs) the log (``t`` (n,) s,
    ``q`` (n, N) rad) runs, from its motion alone: the one within ``tolerance`` rad RMS (default
    :data:`TOLERANCE`) of it over a whole period of the log (:attr:`Fit.window`, :func:`fit`);
    :attr:`Status.NEW` when none is, AMBIGUOUS when several are, STILL for a log that barely moves.
    ValueError for a malformed log or tolerance."""
    if not (np.isfinite(tolerance) and tolerance > 0):
        raise ValueError(f"tolerance {tolerance!r} rad: expected a positive angle")
    t, q = _checked(t, q)
    spread = _spread(q)
    fits = tuple(sorted((fit(t, q, p) for p in programs), key=lambda f: f.window))
    if spread < MIN_MOTION:
        return Recognition(Status.STILL, None, fits, spread)
    near = [f for f in fits if f.window <= tolerance]
    if len(near) == 1:
        return Recognition(Status.KNOWN, near[0].program, fits, spread)
    return Recognition(Status.AMBIGUOUS if near else Status.NEW, None, fits, spread)


def _index(t: np.ndarray, times: np.ndarray) -> np.ndarray:
    """The sample index, rounded, of each time in ``times``: fractional between samples, beyond the
    log's ends at its first and last sample steps."""
    n = len(t)
    inside = np.interp(times, t, np.arange(n, dtype=float))
    before = (times - t[0]) / (t[1] - t[0])
    after = (n - 1) + (times - t[-1]) / (t[-1] - t[-2])
    where = np.where(times < t[0], before, np.where(times > t[-1], after, inside))
    return np.round(where).astype(int)


def log_span(t: np.ndarray) -> float:
    """The time a log covers, s: its last sample's time minus its first, plus one median step."""
    return float(t[-1] - t[0] + np.median(np.diff(t)))


def _phase_gap(a: np.ndarray, b: float) -> np.ndarray:
    """The circular distance of phases ``a`` from ``b`` (shares of a cycle), in [0, 0.5]."""
    gap = np.abs((np.asarray(a) - b) % 1.0)
    return np.minimum(gap, 1.0 - gap)


def check_hint(t, cycle, positions: np.ndarray, m: int, period: float) -> Hint:
    """A ``cycle`` column (n,) (or None) checked against the motion: ``positions`` (n,) the reference
    sample each log sample ``t`` (n,) s lies at, ``m`` samples a cycle of ``period`` s. AGREES when no
    run is longer than a period, the runs but the first and last span one period each, and every run
    starts at one phase of the program (all within :data:`HINT_SLACK` of a period)."""
    if cycle is None:
        return Hint(HintVerdict.NONE)
    cycle = np.asarray(cycle)
    if cycle.shape != (len(t),):
        raise ValueError(f"a cycle column of shape {cycle.shape}: expected one value per sample ({len(t)},)")
    runs = cycle_slices(cycle)
    step = float(np.median(np.diff(t)))
    spans = [float(t[r.stop - 1] - t[r.start] + step) for r in runs]
    slack = HINT_SLACK * period
    for k, (run, span) in enumerate(zip(runs, spans)):
        inner = 0 < k < len(runs) - 1
        if span > period + slack or (inner and abs(span - period) > slack):
            return Hint(HintVerdict.DISAGREES, f"cycle {cycle[run.start]} spans {span:.3f} s, the program's "
                        f"period in the motion {period:.3f} s")
    if len(runs) < 3:
        return Hint(HintVerdict.UNCHECKED, f"{len(runs)} run(s) of the cycle column: no whole cycle to check")
    phases = (positions[[r.start for r in runs[1:]]] % m) / m
    if np.max(_phase_gap(phases, phases[0])) > HINT_SLACK:
        return Hint(HintVerdict.DISAGREES, "the cycle column's cycles start at different phases of the motion")
    return Hint(HintVerdict.AGREES, f"its cycles start at {phases[0]:.3f} of the program's cycle")


def _fragment(start: int, stop: int, positions, resid, m: int, tolerance: float) -> Fragment | None:
    """The fragment ``[start, stop)`` (None when empty), used or dropped (:class:`Use`)."""
    if stop <= start:
        return None
    rms = float(np.sqrt(np.mean(resid[start:stop])))
    share = (positions[stop - 1] - positions[start] + 1.0) / m
    use = Use.SHORT if share < MIN_FRAGMENT else Use.OFF_PATH if rms > tolerance else Use.USED
    return Fragment(start, stop, float(positions[start] % m / m), rms, use)


def known_fit(found: Recognition, programs) -> Fit | None:
    """The :class:`Fit` :func:`recognise` made (``found``) of a log against the program it knows it
    runs, among the ``programs`` it was given, for :func:`whole_cycles` (``fitted``: not fitted
    again); None when ``found`` is not KNOWN or two of ``programs`` bear its name."""
    if found.status is not Status.KNOWN or sum(p.name == found.program for p in programs) != 1:
        return None
    return next(f for f in found.fits if f.program == found.program)


def whole_cycles(t, q, program: Reference, cycle=None, tolerance: float = TOLERANCE,
                 fitted: Fit | None = None) -> Cycles | NoWholeCycle:
    """The whole cycles of ``program`` in a log (``t`` (n,) s, ``q`` (n, N) rad, at any phase and
    span), its leading and trailing fragments and what was done with each, and its ``cycle`` column
    (n,) checked as a hint (:func:`check_hint`; never used over the motion): a :class:`Cycles`, or a
    :class:`NoWholeCycle` with its reason (the log more than ``tolerance`` rad RMS off the program,
    shorter than a cycle, or cut so that no whole cycle lies inside). ``fitted``: this log's
    :func:`fit` against ``program`` already made (:func:`known_fit`: the same numbers), else it is
    fitted here. ValueError for a malformed log, or a ``fitted`` of another program."""
    t, q = _checked(t, q)
    if fitted is not None and fitted.program != program.name:
        raise ValueError(f"a fit against program {fitted.program!r} given for program {program.name!r}: "
                         "expected the log's fit against the program it is cut by")
    f = fit(t, q, program) if fitted is None else fitted
    m, step = len(program.q), program.step
    positions = f.shift + (t - t[0]) / step
    hint = check_hint(t, cycle, positions, m, program.period)
    if f.window > tolerance:
        return NoWholeCycle(Why.OFF_PROGRAM, f"{f.window:.3f} rad RMS off program {program.name!r} at its best "
                            f"shift (tolerance {tolerance:g} rad)", program.name, hint)
    count = int(np.ceil(log_span(t) / program.period)) + 2
    edges = _index(t, t[0] + (np.arange(count) * m - f.shift) * step)
    resid = np.mean((q - _at(program.q, positions)) ** 2, axis=1)
    inside = [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]) if a >= 0 and b <= len(t)]
    if not inside:
        span = log_span(t)
        why = Why.SHORTER_THAN_A_CYCLE if span < program.period else Why.CUT_INSIDE
        return NoWholeCycle(why, f"the log spans {span:.3f} s from phase {f.shift / m:.3f} of program "
                            f"{program.name!r}'s {program.period:.3f} s cycle: no whole cycle inside", program.name, hint)
    cycles = [Cycle(a, b, float(np.sqrt(np.mean(resid[a:b])))) for a, b in inside]
    if all(c.rms > tolerance for c in cycles):
        return NoWholeCycle(Why.OFF_PROGRAM, f"every whole cycle more than {tolerance:g} rad RMS off program "
                            f"{program.name!r}", program.name, hint)
    return Cycles(program.name, tuple(c for c in cycles if c.rms <= tolerance),
                  tuple(c for c in cycles if c.rms > tolerance),
                  _fragment(0, inside[0][0], positions, resid, m, tolerance),
                  _fragment(inside[-1][1], len(t), positions, resid, m, tolerance), program.period, f, hint)


def _lag_distances(x: np.ndarray) -> np.ndarray:
    """The mean squared difference, rad^2, of ``x`` (n, N) and itself shifted by each lag in [0, n)
    over their overlap (YIN's difference function, normalised by the overlap), by FFT."""
    n = len(x)
    spectrum = np.fft.rfft(x, 2 * n, axis=0)
    product = np.fft.irfft(np.sum(np.abs(spectrum) ** 2, axis=1), 2 * n)[:n]
    energy = np.concatenate([[0.0], np.cumsum(np.sum(x * x, axis=1))])
    lags = np.arange(n)
    total = energy[n - lags] + (energy[n] - energy[lags]) - 2.0 * product
    return np.maximum(total, 0.0) / ((n - lags) * x.shape[1])


def period(t, q, tolerance: float = TOLERANCE) -> float | NoWholeCycle:
    """A new program's period, s, from a log of it (``t`` (n,) s, ``q`` (n, N) rad) with no reference:
    the first lag at which the path repeats within ``tolerance`` rad RMS over an overlap of at least
    :data:`MIN_OVERLAP` of the lag (module docstring), refined by a parabola; a
    :class:`NoWholeCycle` (NO_PERIOD, STILL) when there is none. ValueError for a malformed log."""
    t, q = _checked(t, q)
    if _spread(q) < MIN_MOTION:
        return NoWholeCycle(Why.STILL, f"the path spreads {_spread(q):.4f} rad RMS: too little motion "
                            f"(at least {MIN_MOTION:g} rad) to find a period")
    step = float(np.median(np.diff(t)))
    x = resampled(t, q, step)
    d = _lag_distances(x)
    n, limit = len(x), int(len(x) / (1.0 + MIN_OVERLAP))
    away = np.flatnonzero(d > (2.0 * tolerance) ** 2)
    close = d <= tolerance**2
    lag = int(away[0]) if len(away) else limit + 1
    while lag <= limit:
        if close[lag]:
            stop = lag
            while stop + 1 <= limit and close[stop + 1]:
                stop += 1
            best = lag + int(np.argmin(d[lag:stop + 1]))
            if _spread(x[best:]) >= MIN_MOTION:
                return (best + _vertex(d[best - 1], d[best], d[min(best + 1, n - 1)])) * step
            lag = stop
        lag += 1
    return NoWholeCycle(Why.NO_PERIOD, f"the path does not repeat within {tolerance:g} rad over "
                        f"{MIN_OVERLAP:g} of any lag up to {limit * step:.3f} s: a new program needs "
                        f"{1 + MIN_OVERLAP:g} of its cycles in one log")


def _rest(r: np.ndarray, step: float) -> int:
    """The sample of the cycle ``r`` (m, N) in the middle of its longest rest (joint speed, smoothed
    over :data:`REST_WINDOW`, under :data:`REST_SHARE` of its top), or at its slowest."""
    w = max(1, int(round(REST_WINDOW / step)))
    speed = np.linalg.norm(np.roll(r, -w, axis=0) - np.roll(r, w, axis=0), axis=1) / (2 * w * step)
    still = speed <= REST_SHARE * speed.max()
    if not still.any() or still.all():
        return int(np.argmin(speed))
    m = len(r)
    first = int(np.flatnonzero(~still)[0])  # start the scan at a moving sample: no run wraps round
    order = (first + np.arange(m)) % m
    best, length, run_start = (0, 0), 0, 0
    for k, idx in enumerate(order):
        if still[idx]:
            run_start = k if length == 0 else run_start
            length += 1
            best = max(best, (length, run_start))
        else:
            length = 0
    length, run_start = best
    return int(order[(run_start + (length - 1) // 2) % m])


def learn(name: str, t, q, cycle=None, tolerance: float = TOLERANCE) -> Reference | NoWholeCycle:
    """A new program's :class:`Reference` named ``name`` from a log of it (``t`` (n,) s, ``q`` (n, N)
    rad, ``cycle`` column or None): the period found in the motion (:func:`period`), the log folded at
    it and averaged, started where the ``cycle`` column starts its cycles when it agrees with the
    motion (:func:`check_hint`), else in the middle of the cycle's longest rest; or why not
    (:class:`NoWholeCycle`: a log under 1 + :data:`MIN_OVERLAP` cycles, or one that does not repeat)."""
    t, q = _checked(t, q)
    found = period(t, q, tolerance)
    if isinstance(found, NoWholeCycle):
        return found
    m = int(round(found / float(np.median(np.diff(t)))))
    step = found / m
    x = resampled(t, q, step)
    bins = np.arange(len(x)) % m
    count = np.bincount(bins, minlength=m)
    sums = np.column_stack([np.bincount(bins, x[:, a], minlength=m) for a in range(x.shape[1])])
    cycle_q = sums / count[:, None]
    positions = (t - t[0]) / step
    hint = check_hint(t, cycle, positions, m, found)
    if hint.verdict is HintVerdict.AGREES:
        start = int(round(positions[cycle_slices(np.asarray(cycle))[1].start])) % m
    else:
        start = _rest(cycle_q, step)
    return Reference(name, np.roll(cycle_q, -start, axis=0), found)


@dataclass(frozen=True)
class Placement:
    """A log placed among a unit's programs (:func:`place`): its ``recognition``, its ``cycles`` (or
    None) or why it has none (``refusal``), and ``learned``: the new program's reference learned from
    it (None for a known program, or when it could not be learned)."""

    recognition: Recognition
    cycles: Cycles | None
    refusal: NoWholeCycle | None
    learned: Reference | None


def place(t, q, programs, cycle=None, name: str | None = None, tolerance: float = TOLERANCE) -> Placement:
    """A log (``t`` (n,) s, ``q`` (n, N) rad, ``cycle`` column or None) among ``programs`` (the
    unit's :class:`Reference` s, in the order met): the program it runs (:func:`recognise`) and its
    whole cycles (:func:`whole_cycles`); a log of a new program learns its reference (:func:`learn`,
    named ``name``, by default ``"program K"`` with K one more than the programs known) and is cut by
    it. A log of no program (still, ambiguous, or new and not learnable) has a ``refusal``."""
    programs = list(programs)
    found = recognise(t, q, programs, tolerance)
    if found.status is Status.KNOWN:
        program = next(p for p in programs if p.name == found.program)
        cut = whole_cycles(t, q, program, cycle, tolerance, known_fit(found, programs))
        return _placed(found, cut, None)
    if found.status is Status.NEW:
        reference = learn(name or f"program {len(programs) + 1}", t, q, cycle, tolerance)
        if isinstance(reference, NoWholeCycle):
            return Placement(found, None, reference, None)
        return _placed(found, whole_cycles(t, q, reference, cycle, tolerance), reference)
    return Placement(found, None, untold(found, tolerance), None)


def untold(found: Recognition, tolerance: float = TOLERANCE) -> NoWholeCycle:
    """Why a log whose recognition ``found`` is neither a known nor a new program (still, or within
    ``tolerance`` of several) is not scored."""
    why = Why.STILL if found.status is Status.STILL else Why.AMBIGUOUS
    detail = (f"the path spreads {found.spread:.4f} rad RMS: too little motion to tell its program"
              if why is Why.STILL else "within the tolerance of " + ", ".join(
                  f"{f.program!r} ({f.window:.3f} rad)" for f in found.fits if f.window <= tolerance))
    return NoWholeCycle(why, detail)


def _placed(found: Recognition, cut: Cycles | NoWholeCycle, learned: Reference | None) -> Placement:
    """A placement of whole cycles or of a refusal."""
    if isinstance(cut, NoWholeCycle):
        return Placement(found, None, cut, learned)
    return Placement(found, cut, None, learned)
