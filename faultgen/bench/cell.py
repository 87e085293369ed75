"""What makes the independent fleet (:mod:`faultgen.bench.independent`) a real cell rather than a
clean plant (issue 90, item 7), each off by default so that every fleet made before is made again
bit for bit:

- **Programs per unit**: the cell has :attr:`~faultgen.bench.independent.FleetSpec.programs`
  programs, variants of the robot folder's pick and place (program ``k`` its targets drawn
  :data:`VARIANT_SHRINK` ``[k]`` of the way from the start pose to the folder's: other poses, another
  motion, as part variants give); each unit runs a subset of them, of the size given in turn by
  :attr:`~faultgen.bench.independent.FleetSpec.unit_programs` and drawn per unit
  (:func:`unit_programs`), and each day's log is of one of its programs, drawn day by day
  (:func:`day_layouts`).
- **Logs cut anywhere**: with :attr:`~faultgen.bench.independent.FleetSpec.span` ``(a, b)`` a log
  holds ``s`` cycles' worth of samples, ``s`` drawn uniformly in ``[a, b]``, starting at a phase
  drawn uniformly in ``[0, 1)`` of the cycle (:func:`cut`): a controller's buffer, cut where it was cut.
- **Wear laws**: linear, quadratic and exponential (:func:`wear_fraction`), given to the worn units
  in turn (:attr:`~faultgen.bench.independent.FleetSpec.wear_laws`); or a rate in points a day from
  the onset on the first worn units (:attr:`~faultgen.bench.independent.FleetSpec.wear_rates`: a
  fast wear of 3 points a day, a slow one of 0.3).

Every draw here comes from streams of their own (``[seed, 4, unit index]`` for a unit's programs,
``[unit seed, 4]`` for its days), so that the fleet's other draws are the same whatever is chosen.
"""

from __future__ import annotations

import math

import numpy as np

#: The wear laws a worn unit may follow (:func:`wear_fraction`).
WEAR_LAWS = ("linear", "quadratic", "exponential")
#: The exponential law's rate over the span from the onset to the last day (ours): at half the span
#: the wear is 12 % of its final value, on the last day it grows 4.07 times as fast as the linear law's.
EXP_RATE = 4.0
#: Program ``k`` of the cell: the pick and place with its targets this share of the way from the start
#: pose (1: the folder's own).
VARIANT_SHRINK = (1.0, 0.75, 0.5)
#: The shortest and longest span of a log, cycles.
SPAN_LIMITS = (0.5, 10.0)


def wear_fraction(law: str, x: float) -> float:
    """The share of the final wear reached at ``x`` in [0, 1] of the span from the onset to the last
    day: ``x`` (linear), ``x^2`` (quadratic), ``(exp(r x) - 1) / (exp(r) - 1)`` with ``r =``
    :data:`EXP_RATE` (exponential). ValueError for another law."""
    if law == "linear":
        return x
    if law == "quadratic":
        return x * x
    if law == "exponential":
        return math.expm1(EXP_RATE * x) / math.expm1(EXP_RATE)
    raise ValueError(f"wear law {law!r}: expected one of {', '.join(WEAR_LAWS)}")


def check(spec) -> dict:
    """The cell's settings of ``spec`` (a :class:`~faultgen.bench.independent.FleetSpec`) checked:
    ``{"wear_laws", "unit_programs", "span", "wear_rates"}`` as tuples; ValueError naming a bad one."""
    laws = tuple(spec.wear_laws)
    for law in laws:
        if law not in WEAR_LAWS:
            raise ValueError(f"fleet wear_laws = {spec.wear_laws!r}: expected laws among {', '.join(WEAR_LAWS)}")
    n = spec.programs
    if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= len(VARIANT_SHRINK):
        raise ValueError(f"fleet programs = {n!r}: expected the cell's programs, a whole number in "
                         f"1..{len(VARIANT_SHRINK)}")
    counts = tuple(spec.unit_programs)
    if not counts or not all(isinstance(k, int) and not isinstance(k, bool) and 1 <= k <= n for k in counts):
        raise ValueError(f"fleet unit_programs = {spec.unit_programs!r}: expected the programs each unit runs, "
                         f"whole numbers in 1..{n} (the cell's programs)")
    span = tuple(float(s) for s in spec.span)
    if span and (len(span) != 2 or not SPAN_LIMITS[0] <= span[0] <= span[1] <= SPAN_LIMITS[1]):
        raise ValueError(f"fleet span = {spec.span!r}: expected () or the cycles a log holds, (least, most) "
                         f"with {SPAN_LIMITS[0]:g} <= least <= most <= {SPAN_LIMITS[1]:g}")
    if span and tuple(spec.cycles) != (1,):
        raise ValueError(f"fleet span = {spec.span!r} with cycles = {spec.cycles!r}: a log holds a span or whole "
                         "cycles, not both")
    rates = tuple(spec.wear_rates)
    if len(rates) > spec.worn or not all(isinstance(r, (int, float)) and not isinstance(r, bool) and 0 < r <= 100
                                         for r in rates):
        raise ValueError(f"fleet wear_rates = {spec.wear_rates!r}: expected at most {spec.worn} (the worn units) "
                         "rates in points a day, each in (0, 100]")
    return {"wear_laws": laws, "unit_programs": counts, "span": span, "wear_rates": tuple(float(r) for r in rates)}


def unit_programs(spec, index: int) -> tuple[int, ...]:
    """The programs (0-based, sorted) unit ``index`` (0-based) runs: ``spec.unit_programs[index %
    len]`` of the cell's ``spec.programs``, drawn from the stream ``[seed, 4, index]``; ``(0,)``
    for a cell of one program."""
    if spec.programs == 1:
        return (0,)
    count = spec.unit_programs[index % len(spec.unit_programs)]
    chosen = np.random.default_rng([spec.seed, 4, index]).permutation(spec.programs)[:count]
    return tuple(sorted(int(k) for k in chosen))


def day_layouts(spec, unit_seed: int, programs: tuple[int, ...]):
    """Each day's ``(program, phase, span)``, forever: the program drawn among ``programs``, the
    phase in [0, 1) of a cycle and the span in cycles (:attr:`span`; None: whole cycles, phase 0)
    from the stream ``[unit_seed, 4]``; ``(0, 0.0, None)`` every day without programs or spans."""
    if programs == (0,) and not spec.span:
        while True:
            yield 0, 0.0, None
    stream = np.random.default_rng([unit_seed, 4])
    while True:
        program = int(programs[int(stream.integers(len(programs)))])
        if spec.span:
            phase, span = float(stream.random()), float(stream.uniform(*spec.span))
            yield program, phase, span
        else:
            yield program, 0.0, None


def samples(length: int, phase: float, span: float) -> tuple[int, int]:
    """The first sample and the number of samples of a log of ``span`` cycles at ``phase`` of a cycle
    of ``length`` samples."""
    return int(phase * length), max(int(round(span * length)), 2)


def cut(x: np.ndarray, phase: float, span: float) -> np.ndarray:
    """A log's rows of the back-to-back cycles of ``x`` ((L, N): one cycle): ``span`` cycles' worth
    from ``phase`` of the first (:func:`samples`)."""
    first, n = samples(len(x), phase, span)
    reps = -(-(first + n) // len(x))
    return np.tile(x, (reps, 1))[first:first + n]
