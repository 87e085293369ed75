"""The compiled per-pair count of transfer entropy (analysis.te_counts, issue 87): the joint-state
counts are those of a plain Python count, and ``transfer_entropy`` gives the values of the batched
NumPy count (``_te_matrix``, the estimator it replaced for one pair) to 1e-12 bits, whatever the
symbols' type, layout, sign or size."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from analysis import te_counts
from analysis.isolation import _te_matrix, transfer_entropy


def python_counts(source, target, base: int, history: int) -> np.ndarray:
    """The counts of (future, target past, source past), one Python loop over the samples."""
    n_past = base**history
    counted = Counter()
    for t in range(history - 1, len(source) - 1):
        target_past = source_past = 0
        for k in range(t - history + 1, t + 1):  # oldest first
            target_past, source_past = target_past * base + int(target[k]), source_past * base + int(source[k])
        counted[(int(target[t + 1]) * n_past + target_past) * n_past + source_past] += 1
    out = np.zeros(base * n_past * n_past, np.int64)
    for cell, count in counted.items():
        out[cell] = count
    return out


@pytest.mark.parametrize("history", [1, 2, 3])
def test_joint_counts_are_a_plain_count(history):
    rng = np.random.default_rng(history)
    source, target = rng.integers(0, 4, 300), rng.integers(0, 4, 300)
    target[1:] ^= source[:-1] & 1  # coupled
    counts = te_counts.joint_counts(source, target, 4, history)
    assert np.array_equal(counts, python_counts(source, target, 4, history))
    assert counts.sum() == 300 - history


def test_value_range_is_the_smallest_and_largest_symbol_of_both():
    assert te_counts.value_range(np.array([3, -2, 7]), np.array([9, 0, 1])) == (-2, 9)


@pytest.mark.parametrize("dtype", [np.int8, np.int32, np.int64, np.uint16, np.uint64])
@pytest.mark.parametrize("history", [1, 2])
def test_transfer_entropy_is_the_batched_count_to_1e_12(dtype, history):
    rng = np.random.default_rng(7)
    symbols = rng.integers(0, 6, (3, 2000))
    symbols[1, 1:] = (symbols[0, :-1] + rng.integers(0, 2, 1999)) % 6
    strided = symbols.T.astype(dtype)  # columns: not contiguous
    for i, j in [(0, 1), (1, 0), (2, 1)]:
        expected = _te_matrix(symbols[i][None], symbols[j][None], 6, history)[0, 0]
        assert abs(transfer_entropy(strided[:, i], strided[:, j], history) - expected) <= 1e-12


def test_symbols_outside_the_small_range_are_relabelled_first():
    rng = np.random.default_rng(3)
    codes = rng.integers(0, 5, (2, 1000))
    expected = _te_matrix(codes[:1], codes[1:], 5, 1)[0, 0]
    for labels in (np.array([-7, -1, 0, 4, 1 << 40]), np.array([2**63 + 5, 1, 2**64 - 1, 9, 0], dtype=np.uint64)):
        value = transfer_entropy(labels[codes[0]], labels[codes[1]])
        assert abs(value - expected) <= 1e-12
    assert expected > 0


def test_the_state_space_bound_still_refuses_before_counting():
    symbols = np.arange(2000) % 200
    with pytest.raises(ValueError, match="joint states"):
        transfer_entropy(symbols, symbols[::-1].copy(), history=2)
