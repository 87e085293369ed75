"""The layout of the independent fleet's logs (:mod:`faultgen.bench.independent`):
the rate a log is taken at (:func:`plan`) and how many back-to-back cycles of the unit's program it
holds, drawn per log (:func:`draws`)."""

from __future__ import annotations

import numpy as np


def plan(rate, plan_rate: float) -> tuple[float, int]:
    """How a motion planned at ``plan_rate`` Hz is logged at ``rate`` Hz: ``(dt, step)``, planned with
    the time step ``dt`` s and every ``step``-th sample taken: ``(1 / plan_rate, plan_rate / rate)``
    for ``plan_rate`` divided by a whole number, ``(1 / rate, 1)`` for a whole multiple of it (the
    planner's samples on the finer grid hold the coarser grid's: a 500 Hz log of a 250 Hz plan).

    Raises
    ------
    ValueError
        ``rate`` is neither (named, with what was expected).
    """
    value = float(rate) if isinstance(rate, (int, float, np.number)) and not isinstance(rate, bool) else 0.0
    if value > plan_rate and abs(value / plan_rate - round(value / plan_rate)) < 1e-9 and value <= 8 * plan_rate:
        return value ** -1, 1
    k = int(round(plan_rate / value)) if 0 < value <= plan_rate else 0
    if k < 1 or abs(plan_rate / k - value) > 1e-9:
        raise ValueError(f"rate = {rate!r} Hz; expected {plan_rate:g} Hz divided by a whole number "
                         f"({plan_rate:g}, {plan_rate / 2:g}, ...) or times 2..8 ({2 * plan_rate:g}, ...)")
    return plan_rate ** -1, k


def check(cycles, rates, plan_rate: float) -> tuple[tuple[int, ...], tuple[float, ...]]:
    """``cycles`` (whole numbers in 1..10) and ``rates`` (Hz, each :func:`plan`'s) as tuples; ValueError
    naming a bad one."""
    cycles, rates = tuple(cycles), tuple(rates)
    if not cycles or not all(isinstance(k, int) and not isinstance(k, bool) and 1 <= k <= 10 for k in cycles):
        raise ValueError(f"fleet cycles = {cycles!r}: expected cycles per log as whole numbers in 1..10")
    for rate in rates:
        plan(rate, plan_rate)
    return cycles, tuple(float(r) for r in rates)


def draws(cycles: tuple[int, ...], rates: tuple[float, ...], rate: float, seed: int):
    """Each log's ``(cycles, rate Hz)``, one a day, forever: drawn from ``cycles`` and ``rates``
    (empty: ``rate``) by a stream of their own (``[seed, 2]``), so that a fleet's other draws are
    the same whatever its layouts; ``(1, rate)`` every day for ``cycles == (1,)`` and no ``rates``."""
    if cycles == (1,) and not rates:
        while True:
            yield 1, rate
    stream = np.random.default_rng([seed, 2])
    while True:
        yield int(stream.choice(cycles)), float(stream.choice(rates or (rate,)))
