"""A unit's program as cycles: a log may hold one or several back-to-back cycles
of the program, at any sample rate, and is the same program when each of its cycles traces the
program's cycle; only a log whose cycles match neither the program nor a whole number of its
cycles is another program (an unlogged program change, :func:`faultgen.monitor.feed.new_program`).

The cycles are found as ``faultgen logs import`` finds them (:func:`faultgen.data.fleetlogs.log_record`):
from the log's ``cycle`` column when it has one; without one, from the program's period, the log
being a whole number of back-to-back cycles of it (:func:`log_cycles`). The program's own period
is found the same way on the program log (:meth:`Program.of`): its ``cycle`` column, or the largest
number ``k`` (up to :data:`MAX_CYCLES`) of equal parts of its time span that trace the same motion
(within :data:`PROGRAM_CHANGE`), one cycle when none does.

Every comparison is in time, not in samples (angles interpolated linearly onto the program's
samples), so a log at 500 Hz of a program logged at 250 Hz is the same program.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from faultgen.logs import measured

#: A log whose angles lie more than this off its program's cycle, rad, or whose cycles' span differs
#: by more than PROGRAM_LENGTH of the program's period, runs another program (noise and tracking:
#: about 1e-3 rad).
PROGRAM_CHANGE, PROGRAM_LENGTH = 0.05, 0.05
#: The most cycles a log without a ``cycle`` column is looked at for: a log of more cycles of the
#: program (a whole number of periods) still matches it, by its span.
MAX_CYCLES = 10


def _span(t: np.ndarray) -> float:
    """The time a log of samples ``t`` (n,) s covers, s: last minus first plus one sample period
    (the median step), so that ``k`` back-to-back cycles of a program span ``k`` times its span."""
    t = np.asarray(t, dtype=float)
    return float(t[-1] - t[0] + np.median(np.diff(t))) if len(t) > 1 else 0.0


def _at(t: np.ndarray, q: np.ndarray, times: np.ndarray) -> np.ndarray:
    """The angles ``q`` (n, N) sampled at ``t`` (n,), interpolated linearly at ``times`` (m,): (m, N)."""
    return np.column_stack([np.interp(times, t, q[:, axis]) for axis in range(q.shape[1])])


def _off(t: np.ndarray, q: np.ndarray, ref_t: np.ndarray, ref_q: np.ndarray) -> float:
    """The largest angle difference, rad, between a motion (``t`` from its start, ``q``) and a
    reference cycle (``ref_t`` from its start, ``ref_q``) over the time both cover (on the
    reference's samples)."""
    end = min(t[-1], ref_t[-1])
    keep = ref_t <= end
    if not np.any(keep):
        return float("inf")
    return float(np.max(np.abs(_at(t, q, ref_t[keep]) - ref_q[keep])))


def _parts(t: np.ndarray, cycle: np.ndarray | None, k: int) -> list[slice]:
    """The samples of each cycle: the runs of the ``cycle`` column, else ``k`` equal parts of the span."""
    if cycle is not None:
        parts = measured.cycle_slices(cycle)
    else:
        step = _span(t) / k
        edges = [0, *np.searchsorted(t - t[0], step * np.arange(1, k) - 1e-9).tolist(), len(t)]
        parts = [slice(a, b) for a, b in zip(edges[:-1], edges[1:])]
    return [p for p in parts if p.stop > p.start]


@dataclass(frozen=True)
class Program:
    """One cycle of a unit's program: ``t`` (m,) s from its start, ``q`` (m, N) rad, ``period`` s
    (the cycle's span: :func:`_span`), and ``cycles``, how many the program log held."""

    t: np.ndarray
    q: np.ndarray
    period: float
    cycles: int = 1

    @classmethod
    def of(cls, t, q, cycle=None) -> Program:
        """The program of a program log: its samples ``t`` (n,) s, angles ``q`` (n, N) rad and
        ``cycle`` column (n,) or None; its first cycle of the cycles found (module docstring)."""
        t, q = np.asarray(t, dtype=float), np.asarray(q, dtype=float)
        if cycle is not None:
            parts = _parts(t, np.asarray(cycle), 0)
            whole = parts[1] if len(parts) > 2 else parts[0]  # the first and last a log's ends may cut
            return cls(t[whole] - t[whole][0], q[whole], _span(t[whole]), len(parts))
        for k in range(MAX_CYCLES, 1, -1):
            parts = _parts(t, None, k)
            if len(parts) == k and all(_off(t[p] - t[p][0], q[p], t[parts[0]] - t[0], q[parts[0]]) <= PROGRAM_CHANGE
                                       for p in parts[1:]):
                first = parts[0]
                return cls(t[first] - t[0], q[first], _span(t) / k, k)
        return cls(t - t[0], q, _span(t), 1)

    def log_cycles(self, t, q, cycle=None, tolerance: float = PROGRAM_CHANGE) -> int | None:
        """How many cycles of this program a log holds (its samples ``t`` (n,) s, angles ``q`` (n, N)
        rad, ``cycle`` column or None), or None when it runs another program: a span that is not a
        whole number of periods (within :data:`PROGRAM_LENGTH`; each cycle of a ``cycle`` column but
        the log's first and last, which its ends may cut), or a cycle more than ``tolerance`` rad
        (:data:`PROGRAM_CHANGE` by default) off the program's over the time both cover."""
        t, q = np.asarray(t, dtype=float), np.asarray(q, dtype=float)
        if cycle is None:
            k = int(round(_span(t) / self.period))
            if k < 1 or abs(_span(t) - k * self.period) > PROGRAM_LENGTH * self.period:
                return None
            parts = _parts(t, None, k)
            inner = parts
        else:
            parts = _parts(t, np.asarray(cycle), 0)
            inner = parts[1:-1] if len(parts) > 2 else parts
        if any(abs(_span(t[p]) - self.period) > PROGRAM_LENGTH * self.period for p in inner):
            return None
        if any(_off(t[p] - t[p][0], q[p], self.t, self.q) > tolerance for p in inner):
            return None
        return len(parts)
