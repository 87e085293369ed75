"""No forced fit: a library effect is written on an axis only when, after it, the axis's remainder
passes the residual tests (:mod:`faultgen.calibrate.residual_tests`) or no generic term of
:mod:`faultgen.calibrate.remainder` explains more of the remainder before it on the held-out part
(:func:`check`). When a generic term explains more, the effect is not written on that axis and the
axis is reported unexplained with that term (``report.json``: the unexplained axis's
``not_written``; the step's evidence ``declined``).

"Explains more" compares held-out nrmse drops on the remainder before the step: the effect's on
that axis (:attr:`faultgen.calibrate.search.Candidate.gain`) against the best single generic group's,
fitted alone, without an intercept, on the fitting part (:func:`faultgen.calibrate.remainder.best_single`);
the generic group wins when its drop is at least :data:`MORE` times the effect's. One form against
one form: an effect in the library that is the plant's explains its own remainder at least as
well as any other single form does.
"""

from __future__ import annotations

import numpy as np

from faultgen import axes as axis_numbers
from faultgen.calibrate import remainder, residual_tests, search
from faultgen.calibrate.criterion import rms

#: How many times the effect's held-out nrmse drop a single generic group's must reach to win.
MORE = 1.1


def check(candidate: search.Candidate, on: list[int], trial, before: np.ndarray, data, tau: np.ndarray,
          split: search.Split, gear_ratio: np.ndarray) -> tuple[list[int], list[dict]]:
    """The axes of ``on`` (0-based) where ``candidate`` may be written, and a record per axis where
    it may not (:func:`decline`).

    Parameters
    ----------
    candidate : Candidate
        The effect fitted to the remainder ``tau - before``.
    on : list of int
        The axes it would be written on.
    trial : faultgen.calibrate.trial.Trial
        The model with it on ``on``: its ``prediction`` (n, N) and held-out ``gap``.
    before : ndarray (n, N)
        The model's torque before the step, N m.
    data : MeasuredData
        The log (``t``, ``q``, ``qd``, ``qdd``).
    tau : ndarray (n, N)
        Measured torque, N m.
    split : Split
    gear_ratio : ndarray (N,)
        The robot's gear ratios (the motor angle of the generic library).
    """
    tests = residual_tests.run(data.t, tau - trial.prediction, split.held_out, tau, data.q, data.qd, data.qdd)
    failing = {u["axis"] - 1 for u in residual_tests.unexplained(tests, tau, split.held_out, trial.gap)}
    suspects = [a for a in on if a in failing]
    if not suspects:
        return list(on), []
    scale = rms(tau, split.held_out)
    declined = []
    for a in suspects:
        record = decline(candidate, a, data, tau, before, split, float(scale[a]) or 1.0, gear_ratio)
        if record is not None:
            declined.append(record)
    if not candidate.effect.per_axis:
        # robot-wide: not written when the generic wins on most of the axes it helps
        helped = [a for a in on if candidate.gain[a] >= search.MIN_GAIN] or list(on)
        if len([d for d in declined if d["axis"] - 1 in helped]) * 2 > len(helped):
            return [], declined
        return list(on), []
    out = {d["axis"] - 1 for d in declined}
    return [a for a in on if a not in out], declined


def decline(candidate: search.Candidate, axis: int, data, tau: np.ndarray, before: np.ndarray, split: search.Split,
            scale: float, gear_ratio: np.ndarray) -> dict | None:
    """The record of ``candidate`` declined on ``axis`` (0-based) when a single generic group explains
    at least :data:`MORE` times its held-out nrmse drop of the remainder ``tau - before``; else None."""
    fit, held = split.fit[:, axis], split.held_out[:, axis]
    library = remainder.groups(data.t, data.q, data.qd, data.qdd, tau, before, gear_ratio, axis, fit, drift=False)
    best, gain, theta = remainder.best_single(library, tau[:, axis] - before[:, axis], fit, held, scale)
    effect_gain = float(candidate.gain[axis])
    if best is None or gain < MORE * max(effect_gain, 0.0):
        return None
    value, unit = remainder.size(best, theta)
    return {"effect": candidate.effect.id, "axis": axis_numbers.number(axis), "effect_gain_nrmse": effect_gain,
            "generic": best.key, "generic_form": best.form, "generic_gain_nrmse": float(gain),
            "generic_words": remainder.words(best, axis, value, None, unit),
            "rule": (f"not written: a generic term alone lowers the held-out nrmse of the remainder by at least "
                     f"{MORE:g} times what the effect does, and with the effect the axis fails the residual tests")}

