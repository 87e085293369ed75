"""A friction drifting in time (a viscous friction growing as the gearbox oil warms) is named as a
drift in time by the remainder's description, not as "varying with the arm angle" or "cross-axis
coupling" (issue 88, item 6)."""

import numpy as np
import pytest

from faultgen.calibrate import remainder

PERIOD = 0.05  # s


def _log(kind):
    """Three axes moving back and forth for 30 min; axis 2's remainder: its viscous (or dry) friction
    growing with the oil's temperature, which rises steadily over the log (from the model's level to
    half as much again), plus noise; the model's own torque a smooth load."""
    t = np.arange(0.0, 1800.0, PERIOD)
    f = np.array([0.11, 0.17, 0.23])
    q = np.sin(2 * np.pi * f * t[:, None] + [0.0, 0.5, 1.0])
    qd = 2 * np.pi * f * np.cos(2 * np.pi * f * t[:, None] + [0.0, 0.5, 1.0])
    qdd = -(2 * np.pi * f) ** 2 * q
    model = 20 * np.sin(2 * np.pi * 0.05 * t)[:, None] + 5 * q
    warm = 0.5 * t / t[-1]
    drift = warm * (8.0 * qd[:, 1] if kind == "viscous" else 3.0 * np.sign(qd[:, 1]))
    tau = model.copy()
    tau[:, 1] += drift + 0.05 * np.random.default_rng(0).normal(size=t.size)
    moving = np.abs(qd) >= 0.05
    fit = moving & (t < 0.7 * t[-1])[:, None]
    return t, q, qd, qdd, tau, model, fit, moving & ~fit


@pytest.mark.parametrize(("kind", "form"), [("viscous", "speed_drift"), ("dry", "dry_drift")])
def test_a_friction_drifting_in_time_is_named_a_drift(kind, form):
    t, q, qd, qdd, tau, model, fit, held = _log(kind)
    found = remainder.explain(t, q, qd, qdd, tau, model, np.array([100.0, 100.0, 100.0]), fit, held, 1)
    first = found["terms"][0]
    assert first["form"] == form and first["variable_axis"] == 2, found["terms"]
    assert "drifting in time" in first["words"] and first["share"] > 0.5, first
    assert not any("arm angle" in t["words"] or "cross-axis" in t["words"] for t in found["terms"]), found["terms"]
