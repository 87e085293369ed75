"""The residual tests that call an axis unexplained (faultgen.calibrate.residual_tests): whiteness
(Ljung-Box) and independence from the states (cross-correlation over lags -25..25), Holm-adjusted
at 1 %, on the residual thinned to the derivative filter's window; named in the summary,
report.json and the figure. Synthetic residuals, and one calibration of a log of another simulator
with an effect outside the library; the null and late-torque logs are in tests/test_calibrate_delay.py."""

import numpy as np
import pandas as pd
import pytest
from independent_set import CASES, make
from matplotlib import pyplot

from faultgen.calibrate import RESIDUAL_TEST_LEVEL, Calibration, calibrate, figure, residual_tests
from faultgen.calibrate.criterion import gap

RATE = 250.0
N = int(40 * RATE)


@pytest.fixture(scope="module")
def log():
    """A 40 s, 250 Hz motion of six axes (sums of 8 sines, 0.05-1.5 Hz) with its torque and 1 %
    white noise."""
    rng = np.random.default_rng(0)
    t = np.arange(N) / RATE
    w = 2 * np.pi * rng.uniform(0.05, 1.5, (8, 6))
    phase = rng.uniform(0, 2 * np.pi, (8, 6))
    q = np.sum(np.sin(t[:, None, None] * w + phase) / w, axis=1) * 0.3
    qd = np.sum(np.cos(t[:, None, None] * w + phase), axis=1) * 0.3
    qdd = -np.sum(np.sin(t[:, None, None] * w + phase) * w, axis=1) * 0.3
    tau = 20 * np.sin(q) + 5 * qdd + 3 * np.sign(qd)
    held = np.zeros((N, 6), dtype=bool)
    held[int(0.7 * N):] = True
    noise = rng.normal(size=(N, 6)) * 0.01 * np.sqrt(np.mean(tau**2, axis=0))
    return t, q, qd, qdd, tau, held, noise


def test_a_white_residual_independent_of_the_states_passes(log):
    t, q, qd, qdd, tau, held, noise = log
    tests = residual_tests.run(t, noise, held, tau, q, qd, qdd)
    assert [r["failed"] for r in tests] == [[]] * 6
    assert all(r["tested"] and r["stride"] == 13 for r in tests)  # 0.05 s at 250 Hz: the filter's 13 samples
    # 1 whiteness + own torque + q, qd, qdd of six axes, per axis, Holm-adjusted together
    assert all(len(r["independence"]) == 19 and r["whiteness"]["p_adjusted"] >= r["whiteness"]["p"] for r in tests)
    prediction = tau + noise
    assert residual_tests.unexplained(tests, prediction, held, gap(prediction, tau, held)) == []


def test_a_residual_following_another_axis_speed_is_named_with_its_lag(log):
    """Axis 3's residual is 2 % of axis 5's speed 0.104 s (two thinned samples) earlier: the
    whiteness test and the independence test fail on axis 3 only, and the peak names qd5 at lag 2."""
    t, q, qd, qdd, tau, held, noise = log
    lag = 2 * 13
    residual = noise.copy()
    follows = np.roll(qd[:, 4], lag) / np.std(qd[:, 4]) * 0.02 * np.sqrt(np.mean(tau[:, 2] ** 2))
    residual[:, 2] += follows
    tests = residual_tests.run(t, residual, held, tau, q, qd, qdd)
    assert [bool(r["failed"]) for r in tests] == [False, False, True, False, False, False]
    assert "whiteness" in tests[2]["failed"] and "qd5" in tests[2]["failed"]
    assert tests[2]["follows"] == {"variable": "qd5", "lag": 2, "lag_s": pytest.approx(2 * 13 / RATE)}
    assert tests[2]["independence"]["qd5"]["r"] > tests[2]["independence"]["qd5"]["band"]
    measured = tau + residual
    (found,) = residual_tests.unexplained(tests, measured, held, gap(measured, tau, held))
    assert found["axis"] == 3 and found["level"] == RESIDUAL_TEST_LEVEL == 0.01
    assert found["nrmse"] > residual_tests.ABOVE_FLOOR * found["noise_floor"]


def test_a_failed_test_below_the_noise_floor_is_not_unexplained(log):
    """A structure the test finds but too small to matter (nrmse within 1.2x the noise floor)."""
    t, q, qd, qdd, tau, held, noise = log
    residual = noise.copy()
    residual[:, 2] += np.roll(qd[:, 4], 26) / np.std(qd[:, 4]) * 0.006 * np.sqrt(np.mean(tau[:, 2] ** 2))
    tests = residual_tests.run(t, residual, held, tau, q, qd, qdd)
    assert tests[2]["failed"]
    measured = tau + residual
    assert residual_tests.unexplained(tests, measured, held, gap(measured, tau, held)) == []


def test_the_summary_report_and_figure_name_the_axis(tmp_path, log, monkeypatch):
    t, q, qd, qdd, tau, held, noise = log
    residual = noise.copy()
    residual[:, 2] += np.roll(qd[:, 4], 26) / np.std(qd[:, 4]) * 0.02 * np.sqrt(np.mean(tau[:, 2] ** 2))
    measured, model = tau + residual, tau
    tests = residual_tests.run(t, residual, held, measured, q, qd, qdd)
    g = gap(measured, model, held)
    result = Calibration(robot="puma560", measured=str(tmp_path / "log.csv"), gap_before=g, steps=[], gap_after=g,
                         model_out=tmp_path / "m.xml", time=t, held_out=held, moving=np.ones((N, 6), dtype=bool),
                         tau=measured, nominal=model, calibrated=model, searches=1, residual_tests=tests)
    line = next(x for x in result.summary().splitlines() if x.startswith("axis 3 LEFT UNEXPLAINED"))
    assert "not white (Ljung-Box Q = " in line and "follows qd5 at lag 2 (+104 ms" in line and "Holm" in line
    assert sum("LEFT UNEXPLAINED" in x for x in result.summary().splitlines()) == 1
    (reported,) = result.report()["unexplained"]
    assert reported["axis"] == 3 and reported["whiteness"]["p_adjusted"] < 0.01 and reported["added"] == []
    assert reported["independence"]["qd5"]["p_adjusted"] < 0.01
    drawn = []
    monkeypatch.setattr(pyplot, "close", lambda fig: drawn.append(fig))
    figure.save(result, tmp_path / "c.png")
    (fig,) = drawn
    title = fig._suptitle.get_text()
    assert "axis 3: LEFT UNEXPLAINED" in title and "follows qd5 at +104 ms" in title
    assert "UNEXPLAINED" in fig.axes[4].get_ylabel() and "UNEXPLAINED" not in fig.axes[0].get_ylabel()
    clean = Calibration(**{**result.__dict__, "residual_tests": residual_tests.run(t, noise, held, tau, q, qd, qdd)})
    assert "UNEXPLAINED" not in clean.summary() and clean.report()["unexplained"] == []


def test_a_ripple_outside_the_library_is_left_unexplained_on_its_axis(tmp_path):
    """roboticstoolbox's PUMA 560 (puma560-01-none) with a torque ripple periodic in axis 2's arm
    angle, 3 periods a revolution, 6 % of the axis's RMS torque (the library's cogging is periodic in
    the motor angle): axis 2, and only it, is left unexplained. The torque offset the search fits
    there is not written since issue 73 (no forced fit, tests/test_calibrate_open_world.py); with it, axis 2's
    held-out nrmse was 1.6x the median axis's, which the earlier 3x-median rule missed.

    Without the tests (``tests=False``, as ``faultgen monitor`` calibrates its units): they choose
    nothing, so the model and parameters written are byte for byte the same; the report says null
    where it names axis 2, never an empty list (nothing unexplained), and the summary says so."""
    path, _ = make(next(c for c in CASES if c.name == "puma560-01-none"), tmp_path)
    frame = pd.read_csv(path)
    frame["tau2"] += 0.06 * np.sqrt(np.mean(frame["tau2"] ** 2)) * np.sin(3 * frame["q2"])
    frame.to_csv(path, index=False)
    result = calibrate("puma560", path, tmp_path / "out", figure=False)
    (found,) = result.unexplained()
    assert found["axis"] == 2 and "whiteness" in found["failed"], result.summary()
    assert found["nrmse"] > 1.5 * found["noise_floor"]
    assert not any(1 in s.axes for s in result.steps) and "torque_offset" in {d["effect"] for d in found["not_written"]}
    untested = calibrate("puma560", path, tmp_path / "untested", figure=False, tests=False)
    for name in ("puma560_calibrated.xml", "parameters.json"):
        assert (tmp_path / "out" / "model" / name).read_bytes() == \
            (tmp_path / "untested" / "model" / name).read_bytes()
    with_tests, without = result.report(), untested.report()
    assert [u["axis"] for u in with_tests["unexplained"]] == [2] and with_tests["residual_tests"]
    assert without["unexplained"] is None and without["residual_tests"] is None
    assert "residual tests not run" in untested.summary() and "residual tests not run" not in result.summary()
    assert without["steps"] == with_tests["steps"] and without["gap_after"] == with_tests["gap_after"]
