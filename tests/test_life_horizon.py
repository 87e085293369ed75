"""No load-based date more than 30 years after the last log (issue 90, item 4;
:data:`faultgen.monitor.life.HORIZON_DAYS`): a light duty on every shipped robot's ratings gives no
days left, no "service by" and says why; a heavy one gives its date, within the horizon."""

from __future__ import annotations

import datetime
from dataclasses import dataclass

import numpy as np
import pytest

from faultgen.model import robots
from faultgen.monitor import life


@dataclass
class _Entry:
    stamp: str
    load: np.ndarray | None
    duration: float


def _entries(ratings, share_of_rated_torque: float) -> list[_Entry]:
    """Ten daily logs of 60 s, each axis at its rated speed and ``share`` of its rated torque."""
    t = np.linspace(0.0, 60.0, 601)
    qd = np.tile([r.rated_speed for r in ratings], (len(t), 1))
    tau = np.tile([share_of_rated_torque * r.rated_torque for r in ratings], (len(t), 1))
    load = life.load_integrals(t, qd, tau)
    return [_Entry(f"2026-03-{d:02d}", load, 60.0) for d in range(1, 11)]


@pytest.mark.parametrize("name", sorted(robots.available()))
def test_a_light_duty_on_a_shipped_robot_gives_no_date_beyond_30_years_and_a_heavy_one_its_date(name):
    ratings = life.ratings_of(robots.load(name))
    light = life.of_unit("u", _entries(ratings, 0.01), [], ratings)
    for row in light:
        # at 1 % of the rated torque the rated life lasts 100^p / (16/24) h: far beyond 30 years
        assert row.duty > 0 and row.days_left is None, row
        assert "not within 30 years of the last log: no date given" in row.verdict
    rows = [{k: str(v) if v is not None else "" for k, v in zip(life.COLUMNS, r.cells())} for r in light]
    assert life.service_by("2026-03-10", rows, []) == ("", "")
    assert life.table_cell(rows).endswith("(not within 30 years)")
    heavy = life.of_unit("u", _entries(ratings, 1.0), [], ratings)
    rows = [{k: str(v) if v is not None else "" for k, v in zip(life.COLUMNS, r.cells())} for r in heavy]
    date, why = life.service_by("2026-03-10", rows, [])
    # at the rated point, 16 h a day: the rated life (6000-7000 h) lasts 375-438 days
    days = (datetime.date.fromisoformat(date) - datetime.date(2026, 3, 10)).days
    assert 300 < days < 440 and why.startswith("load: axis")


def test_no_date_is_written_beyond_the_horizon():
    assert life.date_after("2026-03-10", 365.0) == "2027-03-10"
    assert life.date_after("2026-03-10", life.HORIZON_DAYS) == "2056-03-09"  # 10957.5 days
    assert life.date_after("2026-03-10", life.HORIZON_DAYS + 1.0) == "not within 30 years"
    assert life.date_after("2026-03-10", float("nan")) == "not within 30 years"
    assert life.date_after("17", 40.0) == "in 40 days"
