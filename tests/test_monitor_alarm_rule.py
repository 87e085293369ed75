"""The alarm stage (:class:`faultgen.monitor.alarm.AlarmRule`) on its own: persistence, the at-once
rule, and an alarm under way closed by maintenance."""

from types import SimpleNamespace

import numpy as np
import pytest

from faultgen.monitor.alarm import WEAR_ALARM_CONFIDENCE, AlarmRule, alarm_quantile
from faultgen.monitor.scoring import Settings

SETTINGS = Settings(persistence=3, wear_limit=10.0)
#: A twin baseline as the rule reads it: both axes observable, their reads' day-to-day scatter.
TWIN = SimpleNamespace(far_=None, observable_=np.array([True, True]), day_scatter_=np.array([1.0, 2.0]))


def _step(rule, stamp, estimate, alarm, at_once=False, baseline=TWIN):
    wear = (np.array(estimate, dtype=float), np.array([1.0, 1.0]))  # (filtered wear, its bound's error)
    rule.step(baseline, stamp, np.zeros(4), 1.0, 1.0, wear, alarm, at_once)


def test_the_alarm_persists_from_the_first_of_persistence_alarming_logs_and_is_known_on_the_last():
    rule = AlarmRule("u", SETTINGS)
    for stamp, alarm in [("001", True), ("002", True), ("003", False), ("004", True), ("005", True)]:
        _step(rule, stamp, [12.0, 1.0], alarm)
    assert rule.first_alarm is None and rule.run == 2  # the run broken on 003: two of three
    _step(rule, "006", [14.0, 1.0], True)
    assert (rule.first_alarm, rule.known, rule.source_axis, rule.statistic) == ("004", "006", 1, "wear")
    bound = (12 + 12 + 14) / 3 - alarm_quantile()  # the mean of the three logs' filtered wear less the quantile of its error
    assert f"axis 1 wear estimate {12 + 2 / 3:.3g} %" in rule.evidence and f"bound {bound:.3g} %" in rule.evidence
    assert f"lower {100 * WEAR_ALARM_CONFIDENCE:g} % bound" in rule.evidence and "next axis 2" in rule.evidence
    assert alarm_quantile() == pytest.approx(1.2816, abs=1e-4)


def test_a_bound_past_the_limit_by_its_own_width_alarms_at_once_and_an_axis_not_observable_is_not_the_source():
    rule = AlarmRule("u", SETTINGS)
    hidden = SimpleNamespace(**{**vars(TWIN), "observable_": np.array([False, True])})
    _step(rule, "001", [40.0, 30.0], True, at_once=True, baseline=hidden)
    assert (rule.first_alarm, rule.known, rule.source_axis) == ("001", "001", 2)
    assert "at once: its lower bound above the limit by more than its own width" in rule.evidence


def test_an_alarm_under_way_is_raised_and_closed_by_maintenance_and_the_run_starts_again():
    rule = AlarmRule("u", SETTINGS)
    _step(rule, "001", [12.0, 1.0], True)
    _step(rule, "002", [12.0, 1.0], True)
    rule.close(TWIN, "002 06:00", "repair of axis 1")
    rule.reset()
    assert rule.first_alarm is None and rule.run == 0 and len(rule.closed) == 1
    closed = rule.closed[0]
    assert (closed["first_alarm"], closed["known"], closed["closed"], closed["closed_by"]) == (
        "001", "002", "002 06:00", "repair of axis 1")
    assert "not yet persistent (2 of 3 logs) when it was closed" in closed["evidence"]
    assert rule.open_alarm() == {"unit": "u", "first_alarm": "", "known": "", "source_axis": "", "statistic": "",
                                 "limit": "", "evidence": ""}
