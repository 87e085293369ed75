"""Residual tests of a calibrated model, per axis, on the held-out part of the log (:func:`run`):
is what the model leaves white, and is it independent of the motion and the torque? An axis that
fails either is left unexplained by the library (:func:`unexplained`).

The two tests of MATLAB's ``resid`` (System Identification Toolbox; Ljung 1999, *System
Identification: Theory for the User*, 2nd ed., sec. 16.6), at its 99 % level:

* **whiteness**: the Ljung-Box statistic of the residual's autocorrelation over
  :data:`WHITENESS_LAGS` lags (Ljung & Box 1978; statsmodels' ``acorr_ljungbox``);
* **independence from the states**: the cross-correlation of the residual at ``t`` with each
  variable at ``t - k``, ``k = -LAGS..LAGS`` (:data:`LAGS` = 25, ``resid``'s default): the axis's
  own measured torque and every axis's ``q``, ``qd`` and ``qdd``. Under independence, with a white
  residual, each is normal with variance ``1 / n`` (Box, Jenkins & Reinsel 2008, *Time Series
  Analysis*, 4th ed., sec. 12.1.3); a variable's p-value is that of its largest ``|r_k|``, Bonferroni
  over the lags. The lag and variable of that peak say what the remainder follows.

**Effective sample size.** Even a model that is the plant leaves a residual correlated over a few
samples: the accelerations (and the speeds a log lacks) come out of the Savitzky-Golay filter
(:mod:`faultgen.derivatives`), a moving polynomial fit over ``W`` samples (0.05 s), so the
encoder noise enters the model's torque through a filter of length ``W``, which correlates it
over ``W - 1`` lags and not beyond (a moving average of white noise). The residual is therefore
thinned to every ``W``-th sample before testing (:func:`stride`): the noise of the log is then
white and the tests' sample size is the number of independent samples. The lags are counted in
thinned samples (25 of them: 1.25 s).

**Multiple tests.** Every axis has 1 + 1 + 3 N p-values (whiteness, own torque, motion of N axes);
all of them, over all axes, are adjusted together by Holm's step-down rule (Holm 1979;
statsmodels' ``multipletests``) at the family-wise level :data:`LEVEL`: on a log the model
explains, the chance that any axis is called unexplained is at most :data:`LEVEL`.

**Size.** A test on thousands of samples finds a mismatch too small to matter, so an axis is
called unexplained only when a test fails *and* its held-out nrmse is above
:data:`faultgen.calibrate.search.ABOVE_FLOOR` times its noise floor (:func:`faultgen.calibrate.criterion.noise_floor`),
the rule by which the search keeps an axis open.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import norm
from statsmodels.stats.diagnostic import acorr_ljungbox
from statsmodels.stats.multitest import multipletests

from faultgen import axes as axis_numbers
from faultgen import collection
from faultgen.calibrate.criterion import noise_floor
from faultgen.calibrate.search import ABOVE_FLOOR
from faultgen.derivatives import savgol_window

#: Family-wise level of the tests over all axes (MATLAB ``resid``'s 99 % confidence region).
LEVEL = 0.01
#: Cross-correlation lags either side, in thinned samples (MATLAB ``resid``'s default, 25).
LAGS = 25
#: Lags of the Ljung-Box statistic, in thinned samples.
WHITENESS_LAGS = 10
#: Fewest thinned held-out samples an axis needs to be tested.
MIN_SAMPLES = 40
#: The motion variables each axis's residual is tested against, per axis.
MOTION = ("q", "qd", "qdd")


def stride(t: np.ndarray) -> int:
    """Samples between two tested ones: the derivative filter's window at the log's median sample
    period (:func:`faultgen.derivatives.savgol_window`), beyond which its noise is uncorrelated."""
    t = np.asarray(t, dtype=float)
    return int(savgol_window(float(np.median(np.diff(t))), t.size))


def run(t: np.ndarray, residual: np.ndarray, held: np.ndarray, tau: np.ndarray, q: np.ndarray, qd: np.ndarray,
        qdd: np.ndarray) -> list[dict]:
    """The residual tests of every axis on its held-out samples, Holm-adjusted together.

    Parameters
    ----------
    t : ndarray of shape (n,)
        Sample times, s.
    residual : ndarray of shape (n, N)
        Measured minus model torque, N m.
    held : ndarray of bool of shape (n, N)
        The held-out samples of each axis (:class:`faultgen.calibrate.search.Split`).
    tau, q, qd, qdd : ndarray of shape (n, N)
        Measured torque (N m), joint angles (rad), speeds (rad/s), accelerations (rad/s^2).

    Returns
    -------
    list of dict
        One per axis: ``axis`` (1..N), ``tested`` (False: too few held-out samples, and nothing
        else), ``samples`` (thinned held-out samples), ``stride``, ``whiteness`` (``statistic``: Ljung-Box
        Q, ``lags``, ``p``, ``p_adjusted``), ``independence`` (per variable, e.g. ``"qd2"``:
        ``r`` and ``lag`` of the largest cross-correlation, ``band``: the 99 % band ``z / sqrt(n)``,
        ``p``, ``p_adjusted``), ``failed`` (the tests whose adjusted p is below :data:`LEVEL`,
        e.g. ``["whiteness", "tau2"]``) and ``follows`` (the failed variable with the largest ``|r|``: its
        name, lag in thinned samples and in s; None when none failed).
    """
    residual, held = np.asarray(residual, dtype=float), np.asarray(held, dtype=bool)
    n_axes = residual.shape[1]
    step = stride(t)
    period = float(np.median(np.diff(np.asarray(t, dtype=float)))) * step
    rows = np.arange(0, residual.shape[0], step)
    variables = {f"{name}{axis_numbers.number(b)}": np.asarray(x, dtype=float)[rows, b]
                 for name, x in zip(MOTION, (q, qd, qdd)) for b in range(n_axes)}
    records, pvalues = [], []
    for a in range(n_axes):
        mask = held[rows, a]
        x = np.where(mask, residual[rows, a], np.nan)
        record = {"axis": axis_numbers.number(a), "tested": bool(mask.sum() >= MIN_SAMPLES),
                  "samples": int(mask.sum()), "stride": step, "failed": [], "follows": None}
        records.append(record)
        if not record["tested"]:
            continue
        q_stat, p_white = _ljung_box(x[mask])  # the held-out samples end to end, across an axis's rests
        record["whiteness"] = {"statistic": q_stat, "lags": WHITENESS_LAGS, "p": p_white}
        own = {f"tau{axis_numbers.number(a)}": np.asarray(tau, dtype=float)[rows, a]}
        lags = _lagged(x)  # the residual's side of every lag, shared by the 19 variables
        record["independence"] = {name: _cross(lags, y) for name, y in {**own, **variables}.items()}
        pvalues += [(a, "whiteness", p_white)] + [(a, name, v["p"]) for name, v in record["independence"].items()]
    if pvalues:
        reject, adjusted, _, _ = _holm([p for _, _, p in pvalues])
        for (a, name, _), bad, p in zip(pvalues, reject, adjusted):
            test = records[a]["whiteness"] if name == "whiteness" else records[a]["independence"][name]
            test["p_adjusted"] = float(p)
            if bad:
                records[a]["failed"].append(name)
    for record in records:
        peaks = [(-abs(v["r"]), name) for name, v in record.get("independence", {}).items()
                 if name in record["failed"]]
        if peaks:
            name = min(peaks)[1]
            lag = record["independence"][name]["lag"]
            record["follows"] = {"variable": name, "lag": lag, "lag_s": lag * period}
    return records


def unexplained(tests: list[dict], tau: np.ndarray, held: np.ndarray, gap_after: dict, also=()) -> list[dict]:
    """The axes the model leaves unexplained: a residual test of :func:`run` failed (``tests``)
    and the axis's held-out nrmse (``gap_after``, :func:`faultgen.calibrate.search.gap`) is above
    :data:`ABOVE_FLOOR` times its noise floor (measured torque ``tau`` (n, N) on ``held`` (n, N));
    and the axes numbered in ``also`` whatever their tests say (a channel delay shown on them,
    :func:`faultgen.calibrate.delay.shown`).

    Returns
    -------
    list of dict
        Per such axis, its record of :func:`run` with ``nrmse``, ``noise_floor`` (nrmse) and
        ``level`` added.
    """
    floor = noise_floor(tau, held)
    found = []
    for record in tests:
        a = record["axis"] - 1
        nrmse = float(gap_after["nrmse"][a])
        if (record["failed"] and nrmse > ABOVE_FLOOR * floor[a]) or record["axis"] in also:
            found.append({**record, "nrmse": nrmse, "noise_floor": float(floor[a]), "level": LEVEL})
    return found


def summary(tests: list[dict]) -> dict:
    """A step's record of :func:`run`, short: per tested axis (numbered) its Ljung-Box p, the
    smallest independence p (adjusted) and its variable, and the failed tests."""
    short = {}
    for r in tests:
        if not r["tested"]:
            continue
        name, worst = min(((k, v) for k, v in r["independence"].items()), key=lambda kv: kv[1]["p_adjusted"])
        short[str(r["axis"])] = {"whiteness_p_adjusted": r["whiteness"]["p_adjusted"],
                                 "independence_p_adjusted": worst["p_adjusted"], "worst_variable": name,
                                 "lag": worst["lag"], "failed": r["failed"]}
    return short


def line(found: dict) -> str:
    """One console line for an axis of :func:`unexplained`."""
    tests = []
    if "whiteness" in found["failed"]:
        w = found["whiteness"]
        tests.append(f"not white (Ljung-Box Q = {w['statistic']:.1f} over {w['lags']} lags, "
                     f"p = {w['p_adjusted']:.2g})")
    shown = found.get("channel_delay")
    if shown is not None:
        low, high = shown["interval_s"]
        tests.append(f"its torque logged {1e3 * shown['seconds']:+.1f} ms off the motion ({shown['level']:.0%} interval "
                     f"{1e3 * low:+.1f} .. {1e3 * high:+.1f} ms; `--delay auto` corrects it)")
    follows = found["follows"]
    if follows is not None:
        v = found["independence"][follows["variable"]]
        tests.append(f"follows {follows['variable']} at lag {follows['lag']} ({1e3 * follows['lag_s']:+.0f} ms; "
                     f"r = {v['r']:+.2f}, 99 % band {v['band']:.2f}, p = {v['p_adjusted']:.2g})")
        others = [n for n in found["failed"] if n not in ("whiteness", follows["variable"])]
        if others:
            tests.append(f"also {', '.join(others)}")
    return (f"axis {found['axis']} LEFT UNEXPLAINED: held-out nrmse {found['nrmse']:.4f} (noise floor "
            f"{found['noise_floor']:.4f}); residual " + "; ".join(tests)
            + f" (Holm over all tests at {found['level']:g}); no effect of the library explains it")


def _holm(pvalues: list[float]) -> tuple:
    """statsmodels' ``multipletests(pvalues, alpha=LEVEL, method="holm")``, its result unchanged. Its
    Holm branch ends with a full ``gc.collect()``; run inside :func:`faultgen.collection.young_only`,
    that collection looks only at what the call made."""
    with collection.young_only():
        return multipletests(pvalues, alpha=LEVEL, method="holm")


def _ljung_box(x: np.ndarray) -> tuple[float, float]:
    frame = acorr_ljungbox(x, lags=[WHITENESS_LAGS], return_df=True)
    return float(frame["lb_stat"].iloc[0]), float(frame["lb_pvalue"].iloc[0])


def _lagged(x: np.ndarray) -> list[tuple]:
    """The residual ``x`` (NaN: not held out) at every lag ``k``, ``|k| <= LAGS``, with at least
    :data:`MIN_SAMPLES` held-out samples: ``(k, mask, n, centred, sum of squares)``, what
    :func:`_cross` needs of it whatever the variable (computed once per axis, not once per variable)."""
    m = x.size
    lags = []
    for k in range(-LAGS, LAGS + 1):
        xs = x[max(k, 0): m + min(k, 0)]
        ok = ~np.isnan(xs)
        n = int(ok.sum())
        if n < MIN_SAMPLES:
            continue
        a = xs[ok] - xs[ok].mean()
        lags.append((k, ok, n, a, np.sum(a * a)))
    return lags


def _cross(lags: list[tuple], y: np.ndarray) -> dict:
    """Largest cross-correlation of the residual at ``t`` (:func:`_lagged`) with ``y`` at ``t - k``
    over ``|k| <= LAGS``, its lag, the 99 % band and the Bonferroni p over the lags."""
    m = y.size
    best_z, r_best, k_best, n_best = -1.0, 0.0, 0, 1
    for k, ok, n, a, aa in lags:
        ys = y[max(-k, 0): m - max(k, 0)]
        b = ys[ok] - ys[ok].mean()
        scale = np.sqrt(aa * np.sum(b * b))
        r = float(np.sum(a * b) / scale) if scale > 0 else 0.0
        if abs(r) * np.sqrt(n) > best_z:
            best_z, r_best, k_best, n_best = abs(r) * np.sqrt(n), r, k, n
    p = min(1.0, (2 * LAGS + 1) * 2 * float(norm.sf(max(best_z, 0.0))))
    return {"r": r_best, "lag": int(k_best), "band": float(norm.ppf(1 - LEVEL / 2) / np.sqrt(n_best)), "n": n_best,
            "p": p}
