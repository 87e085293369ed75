"""How well a model explains the held-out part of a log: the gap record (:func:`gap`), the noise
floor a perfect model would leave (:func:`noise_floor`) and the information criterion that
compares candidate effects (:func:`held_out_aic`, :func:`compare`; Akaike 1974, Burnham &
Anderson 2002). The search (:mod:`faultgen.calibrate.search`) fits, this module judges."""

from __future__ import annotations

import numpy as np

from faultgen import axes as axis_numbers

#: Held-out AIC difference up to which two effects are not separable on a log (Burnham & Anderson
#: 2002, sec. 2.6: 0-2 substantial support for both); the simpler one is fitted.
SEPARABLE = 2.0


def rms(x: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Per-axis RMS of ``x`` (n, 6) over the samples of ``mask`` (n, 6); 0 where there are none."""
    count = np.maximum(mask.sum(axis=0), 1)
    return np.sqrt(np.sum(np.where(mask, x, 0.0) ** 2, axis=0) / count)


def gap(tau: np.ndarray, predicted: np.ndarray, mask: np.ndarray) -> dict:
    """The design document's gap record on the samples of ``mask`` (n, 6), per axis.

    Returns
    -------
    dict
        ``rmse_Nm`` (6 floats, N m), ``nrmse`` (6 floats: RMSE over the RMS of the measured torque
        of that axis) and ``total_nrmse`` (their mean).
    """
    rmse = rms(tau - predicted, mask)
    scale = rms(tau, mask)
    nrmse = rmse / np.where(scale > 0, scale, 1.0)
    return {"rmse_Nm": [float(v) for v in rmse], "nrmse": [float(v) for v in nrmse],
            "total_nrmse": float(np.mean(nrmse))}


def noise_floor(tau: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Per-axis nrmse a perfect model would leave on the samples of ``mask`` (n, N): the torque
    sensor's noise, estimated from the second differences of ``tau`` (n, N) (N m) by their median
    absolute deviation (white noise ``e`` has ``var(e[t+1] - 2 e[t] + e[t-1]) = 6 var(e)``; the
    median keeps the steps of a friction reversal out), over the torque RMS on ``mask``.

    Returns
    -------
    ndarray of shape (N,)
        Noise standard deviation over the axis's torque RMS (0 for an axis without samples).
    """
    tau = np.asarray(tau, dtype=float)
    second = tau[2:] - 2 * tau[1:-1] + tau[:-2]
    inner = np.asarray(mask)[1:-1]
    sigma = np.array([1.4826 * np.median(np.abs(second[inner[:, a], a] - np.median(second[inner[:, a], a])))
                      / np.sqrt(6) if inner[:, a].any() else 0.0 for a in range(tau.shape[1])])
    scale = rms(tau, mask)
    return np.where(scale > 0, sigma / np.where(scale > 0, scale, 1.0), 0.0)


def effective_samples(residual: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Per axis, the number of independent samples the residual (n, N) on ``mask`` (n, N) is worth:
    the sample count over the integrated autocorrelation time ``1 + 2 sum_k rho_k``, summed up to
    the first lag whose autocorrelation is not positive (Geyer 1992's initial positive sequence, in
    its simplest form). White noise gives the sample count; a smooth residual far fewer.

    Returns
    -------
    ndarray of shape (N,)
        At least 1 where the axis has samples, 0 where it has none.
    """
    out = np.zeros(residual.shape[1])
    for a in range(residual.shape[1]):
        x = residual[mask[:, a], a]
        m = x.size
        if m < 3:
            out[a] = float(m)
            continue
        x = x - x.mean()
        spectrum = np.fft.rfft(x, 2 * m)
        acf = np.fft.irfft(spectrum * np.conj(spectrum))[:m]
        if acf[0] <= 0:
            out[a] = float(m)
            continue
        rho = acf[1:] / acf[0]
        stop = np.flatnonzero(rho <= 0)
        rho = rho[: stop[0] if stop.size else rho.size]
        out[a] = max(1.0, m / max(1.0, 1.0 + 2.0 * float(np.sum(rho))))
    return out


def held_out_aic(residual: np.ndarray, contribution: np.ndarray, held: np.ndarray, n_eff: np.ndarray,
                 parameters: int) -> float:
    """Akaike's information criterion of a model on the held-out part, up to a constant that is the
    same for every model of the same residual: ``sum_a n_eff_a ln(SSE_a / m_a) + 2 k`` with
    ``SSE_a`` the held-out sum of squares of ``residual - contribution`` (n, N) on axis a,
    ``m_a`` its held-out samples, ``n_eff_a`` their effective number (:func:`effective_samples`)
    and ``k`` the parameters fitted. Each axis has its own Gaussian noise variance, estimated by
    ``SSE_a / m_a`` (Akaike 1974; Burnham & Anderson 2002, sec. 2.2)."""
    error = np.where(held, residual - contribution, 0.0)
    count = np.maximum(held.sum(axis=0), 1)
    mse = np.maximum(np.sum(error**2, axis=0) / count, 1e-300)
    used = held.any(axis=0)
    return float(np.sum(n_eff[used] * np.log(mse[used])) + 2 * parameters)


def compare(candidates: list, residual: np.ndarray, split, reference=None) -> dict[str, dict]:
    """Held-out evidence of each candidate (:class:`faultgen.calibrate.search.Candidate`; ``split`` a
    :class:`faultgen.calibrate.search.Split`) with significant axes (:func:`held_out_aic`), keyed by
    effect id: ``aic``, ``delta_aic`` (over the best), ``weight`` (the Akaike weight
    ``exp(-delta/2) / sum exp(-delta_j/2)``), ``evidence_ratio`` (the best's weight over its own,
    ``exp(delta/2)``), ``axes`` (1..N) and ``separable`` (``delta_aic > SEPARABLE``; the best is
    not separable from itself). The effective sample sizes are those of the residual ``reference``
    leaves (default: the best by AIC), the same for every candidate."""
    held = split.held_out
    live = [c for c in candidates if c.axes]
    if not live:
        return {}
    if reference is None:
        crude = effective_samples(residual, held)
        reference = min(live, key=lambda c: held_out_aic(residual, c.contribution, held, crude, c.fitted_parameters))
    n_eff = effective_samples(residual - reference.contribution, held)
    aic = {c.effect.id: held_out_aic(residual, c.contribution, held, n_eff, c.fitted_parameters) for c in live}
    best = min(aic.values())
    delta = {k: v - best for k, v in aic.items()}
    total = sum(np.exp(-d / 2) for d in delta.values())
    return {c.effect.id: {"aic": aic[c.effect.id], "delta_aic": delta[c.effect.id],
                          "weight": float(np.exp(-delta[c.effect.id] / 2) / total),
                          "evidence_ratio": float(np.exp(min(delta[c.effect.id], 1400.0) / 2)),
                          "axes": axis_numbers.numbers(c.axes), "separable": bool(delta[c.effect.id] > SEPARABLE)}
            for c in live}
