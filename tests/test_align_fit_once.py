"""A log's fit against a program made once (faultgen.logs.align): the program's own FFTs computed once
a reference (:attr:`Reference.spectra`, never pickled with it), and :func:`whole_cycles` cutting a
log by the fit :func:`recognise` made of it (:func:`known_fit`) instead of fitting it again: the same
numbers, bit for bit, as fitting from scratch (issue 87 item 2: the monitor's time per log)."""

import pickle

import numpy as np
import pytest

from faultgen.logs import align

M = 7 * 31  # a cycle of 217 samples: a length pocketfft factors badly, as the iiwa fleet's 3899 = 7 x 557


def _path(phase: np.ndarray) -> np.ndarray:
    w = 2 * np.pi * phase
    return np.column_stack([np.sin(w), 0.5 * np.cos(2 * w), 0.3 * np.sin(3 * w + 1.0)])


@pytest.fixture
def log():
    """A program's reference (one cycle of M samples, 2.17 s) and a log of 3.2 of its cycles at
    another rate from phase 0.37, with noise; and another program far from it."""
    step = 0.01
    reference = align.Reference("program 1", _path(np.arange(M) / M), M * step)
    other = align.Reference("program 2", _path(np.arange(M) / M)[:, ::-1] + 1.0, M * step)
    t = np.arange(int(3.2 * M * step / 0.004)) * 0.004
    q = _path(0.37 + t / (M * step)) + np.random.default_rng(3).normal(0.0, 1e-3, (len(t), 3))
    return t, q, reference, other


def _old_shift_distances(x: np.ndarray, r: np.ndarray) -> np.ndarray:
    """The distances as computed before the reference's FFTs were kept: every FFT taken per call."""
    def circular(a, b):
        return np.fft.irfft(np.conj(np.fft.rfft(a)) * np.fft.rfft(b), len(a))
    m, n = len(r), len(x)
    bins = np.arange(n) % m
    folded = np.column_stack([np.bincount(bins, x[:, a], minlength=m) for a in range(x.shape[1])])
    count = np.bincount(bins, minlength=m).astype(float)
    cross = sum(circular(folded[:, a], r[:, a]) for a in range(r.shape[1]))
    total = np.sum(x * x) + circular(count, np.sum(r * r, axis=1)) - 2.0 * cross
    return np.maximum(total, 0.0) / x.size


def test_the_kept_ffts_give_the_bits_of_ffts_taken_per_log(log):
    t, q, reference, _ = log
    x = align.resampled(t, q, reference.step)
    first = align._shift_distances(x, reference)
    assert "spectra" in vars(reference)  # kept on the reference after its first fit
    np.testing.assert_array_equal(first, _old_shift_distances(x, reference.q))
    np.testing.assert_array_equal(align._shift_distances(x[: M // 2], reference), _old_shift_distances(x[: M // 2], reference.q))
    found = align.fit(t, q, reference)
    assert found.shift == pytest.approx((0.37 * M) % M, abs=0.05) and found.rms < 3e-3


def test_a_reference_is_pickled_without_its_ffts_and_fits_the_same_after(log):
    t, q, reference, _ = log
    bare = pickle.dumps(reference)
    before = align.fit(t, q, reference)
    assert pickle.dumps(reference) == bare  # the kept FFTs do not travel with it
    again = pickle.loads(bare)
    assert "spectra" not in vars(again) and again.name == reference.name
    assert align.fit(t, q, again) == before


def test_whole_cycles_cut_by_the_recognised_fit_are_those_of_a_fit_from_scratch(log):
    t, q, reference, other = log
    found = align.recognise(t, q, [other, reference])
    assert found.status is align.Status.KNOWN and found.program == "program 1"
    fitted = align.known_fit(found, [other, reference])
    assert fitted == align.fit(t, q, reference)
    given = align.whole_cycles(t, q, reference, fitted=fitted)
    assert given == align.whole_cycles(t, q, reference) and len(given.cycles) == 2
    placed = align.place(t, q, [other, reference])
    assert placed.cycles == given


def test_no_fit_is_reused_for_a_new_program_or_a_name_two_programs_bear(log):
    t, q, reference, other = log
    assert align.known_fit(align.recognise(t, q, [other]), [other]) is None  # NEW: nothing fitted to reuse
    twins = [reference, align.Reference("program 1", other.q, other.period)]
    assert align.known_fit(align.recognise(t, q, twins), twins) is None


def test_a_fit_of_another_program_is_refused_by_name(log):
    t, q, reference, other = log
    with pytest.raises(ValueError, match=r"^a fit against program 'program 2' given for program 'program 1': expected "):
        align.whole_cycles(t, q, reference, fitted=align.fit(t, q, other))
