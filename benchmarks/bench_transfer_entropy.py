"""Transfer entropy speed: analysis.isolation against PyInform's C implementation, same symbols.

    python benchmarks/bench_transfer_entropy.py [--samples 100000] [--bins 10] [--repeat 5] [--pairs-repeat 20]

Six axes of ``--samples`` samples each (a lag-1 coupled chain plus noise), symbolised once with
``analysis.isolation.symbolise`` into ``--bins`` quantile bins; then, best of ``--repeat`` runs:

- ours, pairwise: ``transfer_entropy(source, target)`` for all 30 ordered pairs;
- ours, fit: ``TransferEntropyIsolator(bins).fit(X)`` (symbolisation, then one batched count
  per target for the whole T_{i->j} matrix), checked against the same PyInform values;
- PyInform (``pyinform.transfer_entropy(source, target, k=1)``, history 1, bits) for the same
  30 pairs: the baseline. The two must agree to 1e-9 bits, or the script exits with an error.
- infomeasure's discrete estimator (pure Python) is timed too when installed.

Then per pair (issue 87): each of the 30 pairs timed alone, ours and PyInform alternately, best of
``--pairs-repeat`` calls each; printed: the time per pair of each, the ratio per pair (median, best
and worst over the pairs), and the largest difference of ``transfer_entropy`` from the batched NumPy
count of the same pair (``analysis.isolation._te_matrix``, the estimator before the compiled
count; must be <= 1e-12 bits). The first call's time (numba's compile, or its load from the cache)
is printed apart: it is paid once per process and signature, not per pair.

The last line is ``ratio <float>``: ours, ``transfer_entropy`` per pair, over PyInform (the 30 pairs
together), with its verdict against the aim <= 1.0.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import pyinform

from analysis.isolation import TransferEntropyIsolator, _te_matrix, symbolise, transfer_entropy


def best_seconds(run, repeat: int) -> tuple[float, np.ndarray]:
    best, out = np.inf, None
    for _ in range(repeat):
        started = time.perf_counter()
        out = run()
        best = min(best, time.perf_counter() - started)
    return best, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=100_000)
    parser.add_argument("--bins", type=int, default=10)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--pairs-repeat", type=int, default=20)
    args = parser.parse_args()

    rng = np.random.default_rng(0)
    X = rng.standard_normal((args.samples, 6))
    for j in range(1, 6):  # axis j follows axis j-1 with one sample of delay
        X[1:, j] += 0.8 * X[:-1, j - 1]
    S = np.column_stack([symbolise(c, args.bins) for c in X.T]).astype(np.int32)
    pairs = [(i, j) for i in range(6) for j in range(6) if i != j]
    started = time.perf_counter()
    transfer_entropy(S[:, 0], S[:, 1])
    t_first = time.perf_counter() - started

    def matrix(te_of):
        te = np.zeros((6, 6))
        for i, j in pairs:
            te[i, j] = te_of(S[:, i], S[:, j])
        return te

    t_ours, te_ours = best_seconds(lambda: matrix(transfer_entropy), args.repeat)
    t_fit, fitted = best_seconds(lambda: TransferEntropyIsolator(bins=args.bins).fit(X), args.repeat)
    t_pyinform, te_pyinform = best_seconds(
        lambda: matrix(lambda s, t: pyinform.transfer_entropy(s, t, k=1)), args.repeat)
    for name, te in (("transfer_entropy", te_ours), ("fit", fitted.te_)):
        err = np.abs(te - te_pyinform).max()
        if err > 1e-9:
            raise SystemExit(f"ours ({name}) and PyInform differ by {err:.3g} bits")

    print(f"6 axes x {args.samples} samples, {args.bins} bins, {len(pairs)} ordered pairs, best of {args.repeat}")
    print(f"ours, transfer_entropy per pair : {t_ours * 1e3:9.2f} ms")
    print(f"ours, TransferEntropyIsolator.fit: {t_fit * 1e3:8.2f} ms")
    print(f"PyInform (C)                    : {t_pyinform * 1e3:9.2f} ms")
    try:
        import infomeasure
    except ImportError:
        print("infomeasure                     : not installed")
    else:
        t_im, _ = best_seconds(lambda: matrix(lambda s, t: infomeasure.transfer_entropy(
            s, t, approach="discrete", base=2)), 1)
        print(f"infomeasure (Python), 1 run     : {t_im * 1e3:9.2f} ms")
    per_pair = [pair_times(S[:, i], S[:, j], args.pairs_repeat) for i, j in pairs]
    ratios = np.array([ours / theirs for ours, theirs, _ in per_pair])
    worst_diff = max(diff for _, _, diff in per_pair)
    print(f"first call (numba compile or cache load): {t_first * 1e3:.1f} ms, once per process")
    print(f"per pair, best of {args.pairs_repeat}: ours {np.median([p[0] for p in per_pair]) * 1e3:.3f} ms, "
          f"PyInform {np.median([p[1] for p in per_pair]) * 1e3:.3f} ms (medians over the {len(pairs)} pairs)")
    print(f"per-pair ratio ours / PyInform: median {np.median(ratios):.3f}, best {ratios.min():.3f}, "
          f"worst {ratios.max():.3f}")
    print(f"largest difference from the NumPy count (_te_matrix): {worst_diff:.3g} bits "
          f"({'within' if worst_diff <= 1e-12 else 'ABOVE'} 1e-12)")
    if worst_diff > 1e-12:
        raise SystemExit("transfer_entropy differs from the batched NumPy count by more than 1e-12 bits")
    ratio = t_ours / t_pyinform
    print(f"ratio {ratio:.3f}  ({'at or below' if ratio <= 1.0 else 'above'} PyInform's time per pair)")


def pair_times(source: np.ndarray, target: np.ndarray, repeat: int) -> tuple[float, float, float]:
    """(ours s, PyInform s, |ours - NumPy count| bits) of one pair: best of ``repeat`` calls each,
    alternating."""
    ours = theirs = np.inf
    for _ in range(repeat):
        started = time.perf_counter()
        value = transfer_entropy(source, target)
        middle = time.perf_counter()
        pyinform.transfer_entropy(source, target, k=1)
        ours, theirs = min(ours, middle - started), min(theirs, time.perf_counter() - middle)
    base = int(max(source.max(), target.max())) + 1
    reference = _te_matrix(source[None].astype(np.int64), target[None].astype(np.int64), base, 1)[0, 0]
    return ours, theirs, abs(value - reference)


if __name__ == "__main__":
    main()
