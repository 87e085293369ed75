"""The joint-state counts of one transfer-entropy pair in one compiled pass (numba), for
:func:`analysis.isolation.transfer_entropy`: the per-pair call users make from their own code,
at PyInform's C speed (benchmarks/bench_transfer_entropy.py). The counts are the ones the
batched :func:`analysis.isolation._te_matrix` makes with NumPy, cell for cell, so the estimator
and its values are unchanged.

Compiled on first use and cached on disk (``numba.njit(cache=True)``, as faultgen.calibrate.gearbox):
the first call in a fresh environment compiles for about a second, later processes load it.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def value_range(source: np.ndarray, target: np.ndarray) -> tuple[int, int]:
    """(smallest, largest) symbol of both 1-D integer sequences (of one length > 0), in one pass."""
    low = high = np.int64(source[0])
    for t in range(source.size):
        s, y = np.int64(source[t]), np.int64(target[t])
        low = min(low, s, y)
        high = max(high, s, y)
    return low, high


@numba.njit(cache=True, nogil=True)
def joint_counts(source: np.ndarray, target: np.ndarray, base: int, history: int) -> np.ndarray:
    """Counts of (future, target past, source past), shape (base * base**history * base**history,):
    cell ``(future * n_past + target_past) * n_past + source_past`` with ``n_past = base**history``
    and a past ``s[t-history+1 .. t]`` numbered oldest symbol first (``analysis.isolation._past``),
    for t = history-1 .. n-2. Symbols are integers in 0 .. base-1."""
    n_past = np.int64(base) ** history
    counts = np.zeros(np.int64(base) * n_past * n_past, np.int64)
    for t in range(source.size - history):
        target_past = np.int64(0)
        source_past = np.int64(0)
        for k in range(history):
            target_past = target_past * base + np.int64(target[t + k])
            source_past = source_past * base + np.int64(source[t + k])
        counts[(np.int64(target[t + history]) * n_past + target_past) * n_past + source_past] += 1
    return counts
