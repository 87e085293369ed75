"""benchmarks/monitor_rul.py scores the remaining life with friction tests as the monitor computes it
(docs/analysis.md, "Second session of 2026-11-27"): each prediction's rows on that prediction's
*latest* factor
(faultgen.monitor.friction_tests.on_tests_scale), not each log on the factor of its own day."""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import monitor_rul  # noqa: E402

from faultgen.monitor import friction_tests, prognosis, tables  # noqa: E402


def _rows(factors, twin):
    """Rows of one worn axis (axis 1 of 6) whose twin-scale wear is ``twin`` and factor then ``factors``."""
    rows = []
    for i, (f, x) in enumerate(zip(factors, twin)):
        stamp = str(np.datetime64("2026-01-01") + np.timedelta64(i, "D"))
        row = {"unit": "u", "stamp": stamp, "phase": "monitoring"}
        for k in range(1, 7):
            xk, fk = (x, f) if k == 1 else (0.0, 1.0)
            row |= {f"wear{k}_twin_log": xk, f"wear{k}_twin_log_lower": xk - 2.0, f"wear{k}_factor": fk,
                    f"wear{k}_factor_error": 0.05 * fk, f"wear{k}_scale": friction_tests.TESTS_SCALE,
                    f"wear{k}_log": fk * xk, f"wear{k}_log_lower": fk * (xk - 2.0), f"wear{k}": fk * xk}
        rows.append(row)
    return tables.log_rows(rows)


def test_each_prediction_on_its_latest_factor():
    twin = np.linspace(0.0, 30.0, 20)
    factors = [0.9] * 8 + [0.5] * 6 + [0.7] * 6  # a factor that moves at each test, as on the hump fleet
    rows = _rows(factors, twin)
    rescaled, uncertainty = monitor_rul.on_scale(rows[:12], 0.1, True)
    # the first 12 logs on the 12th log's factor (0.5), its relative error as the scale's uncertainty
    assert np.allclose([r.wear.log[0] for r in rescaled], 0.5 * twin[:12])
    assert np.allclose([r.wear.log_lower[0] for r in rescaled], 0.5 * (twin[:12] - 2.0))
    assert np.isclose(uncertainty[1], 0.05)
    # without tests: the rows and the given uncertainty as they are
    same, given = monitor_rul.on_scale(rows, 0.1, False)
    assert same is rows and given == 0.1


def test_the_mosaic_runs_late_and_the_latest_factor_does_not():
    """A straight twin-scale rise whose factor falls at two tests (as hump seed-1 unit09's: 0.90, 0.48,
    0.31): the mosaic (each log on its own day's factor, the benchmark before) fits a slower trend
    than the latest factor's straight line, and its end of life comes late."""
    twin = np.linspace(0.0, 38.0, 40)
    factors = [1.0] * 14 + [0.7] * 14 + [0.5] * 12
    rows = _rows(factors, twin)
    mosaic = prognosis.remaining_life("u", rows, 6, alpha=0.01, axes=[1], changepoint=False,
                                      scale_uncertainty=0.0, samples=200)[0]
    latest, uncertainty = monitor_rul.on_scale(rows, 0.0, True)
    fixed = prognosis.remaining_life("u", latest, 6, alpha=0.01, axes=[1], changepoint=False,
                                     scale_uncertainty={k: 0.0 for k in uncertainty}, samples=200)[0]
    slope = 0.5 * 38.0 / 39.0  # % per day on the latest factor; the wear is 19 % now
    assert fixed.rul is not None and abs(fixed.rul - 21.0 / slope) < 2.0
    assert mosaic.rul is None or mosaic.rul > 1.2 * fixed.rul
