"""The monitor's typed log rows (faultgen.monitor.record, issue 84 item 1): what a unit's monitor
appends is a LogRow with its wear as per-axis arrays; scores.csv's columns are made from it and read
back into the same values (at the 6 significant digits the table keeps)."""

import csv
import io

import numpy as np
import pytest

from faultgen.monitor import record, report, steps, tables
from faultgen.monitor.history import UnitHistory
from faultgen.monitor.scoring import Settings


def _unit(seed: int = 4) -> UnitHistory:
    rng = np.random.default_rng(seed)
    signatures = np.abs(rng.normal(0, 1, (3, 9))) * 0.05
    unit = steps.start("u", Settings(train=12), n_axes=3, signatures=signatures)
    for i in range(30):
        steps.add(unit, f"{i:03d}", rng.normal(0, 0.05, 9) + max(i - 15, 0) * signatures[1], 30.0, 0.0, np.zeros(9))
    return unit


def test_a_monitors_rows_are_typed_and_their_wear_is_per_axis_arrays():
    unit = _unit()
    assert all(isinstance(r, record.LogRow) for r in unit.rows) and len(unit.rows) == 30
    scored = [r for r in unit.rows if r.phase == "monitoring"]
    assert scored and all(r.wear.estimate.shape == (3,) and r.scores.shape == (3,) for r in scored)
    # the lower bound the alarm is judged on lies under the filtered wear, by the alarm's quantile
    last = scored[-1].wear
    assert np.all(last.lower <= last.estimate) and np.all(last.p5 <= last.estimate) and last.tests is None
    assert sorted(scored[-1].ranking) == [1, 2, 3]


def test_scores_csv_cells_read_back_into_the_same_row():
    unit = _unit()
    buffer = io.StringIO()
    columns = list(report.score_cells(unit.rows[-1]))
    writer = csv.DictWriter(buffer, columns)
    writer.writeheader()
    writer.writerows(report.score_cells(r) for r in unit.rows)
    back = tables.log_rows(list(csv.DictReader(io.StringIO(buffer.getvalue()))))
    for row, again in zip(unit.rows, back):
        assert (again.unit, again.stamp, again.phase, again.alarm, again.ranking) == \
            (row.unit, row.stamp, row.phase, row.alarm, row.ranking)
        np.testing.assert_allclose(again.scores, row.scores, rtol=1e-12)
        np.testing.assert_allclose(again.wear.lower, row.wear.lower, rtol=1e-12)
        np.testing.assert_allclose(again.wear.log, row.wear.log, rtol=1e-12)
    assert report.score_cells(unit.rows[-1])["wear2_lower"] == pytest.approx(float(unit.rows[-1].wear.lower[1]))


def test_a_listed_relearning_log_has_no_statistic_and_no_wear():
    row = record.listed("u", "2026-01-05", 6)
    assert row.phase == "relearning" and np.isnan(row.Q) and row.wear is None and row.scores.shape == (6,)
    cells = report.score_cells(row)
    assert cells["ranking"] == "" and "wear1" not in cells and np.isnan(cells["score6"])
