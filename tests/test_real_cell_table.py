"""The judging functions of benchmarks/real_cell_table.py (issue 90's tables) and the shared ones of
benchmarks/monitor_bounds_check.py, on a hand-made truth and monitor output of three units whose every
figure is worked out by hand below."""

from __future__ import annotations

import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import monitor_bounds_check as bounds  # noqa: E402
import real_cell_table as rct  # noqa: E402

STAMPS = [f"2026-01-{d:02d}" for d in range(1, 11)]
#: u1 wears axis 2 by 5 points a day from day 3 (day 10: 40 %); u2 healthy; u3 wears axis 1 by 3 a day from day 2.
TRUTH = {
    "u1": {"axis": 2, "stamps": STAMPS, "wear": np.array([0, 0, 5, 10, 15, 20, 25, 30, 35, 40], dtype=float)},
    "u2": {"axis": 0, "stamps": STAMPS, "wear": np.zeros(10)},
    "u3": {"axis": 1, "stamps": STAMPS, "wear": 3.0 * np.maximum(np.arange(10) - 1, 0)},
}


def wear_row(stamp, wear, low, high, lower):
    return {"stamp": stamp, "wear": str(wear), "wear_5": str(low), "wear_95": str(high), "wear_lower": str(lower)}


def test_monitored_by_day_40_is_per_unit_first_monitoring_log():
    scores = [{"unit": "u1", "stamp": STAMPS[0], "phase": "training"},
              {"unit": "u1", "stamp": STAMPS[3], "phase": "monitoring"},
              {"unit": "u1", "stamp": STAMPS[4], "phase": "monitoring"},
              {"unit": "u2", "stamp": STAMPS[1], "phase": "monitoring"},
              {"unit": "u3", "stamp": STAMPS[0], "phase": "training"}]
    first = rct.first_monitored(scores)
    assert first == {"u1": STAMPS[3], "u2": STAMPS[1], "u3": ""}
    _, figure, ok = rct.monitored_row(TRUTH, first)
    assert not ok and "2 of 3" in figure and "u3 never" in figure
    _, _, ok = rct.monitored_row({"u1": TRUTH["u1"]}, first)
    assert ok


def test_program_changes_against_the_truths_new_programs():
    units = [{"unit": "u1", "reason": "program changed at 2026-01-07 (not logged: ...); program changed at "
                                      "2026-01-09 (...)", "programs": ""},
             {"unit": "u2", "reason": "", "programs": ""}]
    reported = rct.reported_changes(units)
    assert reported == {"u1": ["2026-01-07", "2026-01-09"], "u2": []}
    assert rct.changes_row(reported, {"u1": ["2026-01-09", "2026-01-07"]})[2]
    _, figure, ok = rct.changes_row(reported, {"u1": ["2026-01-07"]})
    assert not ok and "u1 (2 vs 1)" in figure


def test_first_alarms_window_and_healthy_quiet():
    alarms = [{"unit": "u1", "first_alarm": STAMPS[5], "source_axis": "2"},  # 20 %: too late
              {"unit": "u1", "first_alarm": STAMPS[3], "source_axis": "2"},  # 10 %: the first, in the window
              {"unit": "u3", "first_alarm": STAMPS[5], "source_axis": "1"}]  # 12 % at 3 points a day: < 15
    firsts = bounds.first_alarms(TRUTH, alarms)
    assert firsts["u1"] == (STAMPS[3], 2, 10.0) and firsts["u2"] == ("", None, None)
    assert bounds.rate(TRUTH["u3"]) == 3.0 and bounds.rate(TRUTH["u2"]) == 0.0
    (_, figure, ok), (_, quiet, ok_quiet) = rct.alarm_rows(TRUTH, firsts)
    assert ok and "2 of 2" in figure and ok_quiet and "1 of 1 quiet" in quiet
    wrong_axis = bounds.first_alarms(TRUTH, [{**alarms[1], "source_axis": "3"}, alarms[2],
                                             {"unit": "u2", "first_alarm": STAMPS[9], "source_axis": "4"}])
    (_, figure, ok), (_, quiet, ok_quiet) = rct.alarm_rows(TRUTH, wrong_axis)
    assert not ok and "(axis 3)" in figure and not ok_quiet and "u2" in quiet
    assert not bounds.alarm_in_window(7.9, False) and bounds.alarm_in_window(7.9, True)
    # a unit at 0.5 point a day as its wear reaches 8 %: the window 8-15 %, not "before 15 %"
    slow = {"u4": {"axis": 3, "stamps": STAMPS, "wear": np.array([0, 4, 6, 7.5, 8, 8.5, 9, 30, 60, 90.0])}}
    assert rct.growth_at(slow["u4"], 8.0) == 0.5 and rct.growth_at(TRUTH["u3"], 8.0) == 3.0
    assert not rct.alarm_rows(slow, {"u4": (STAMPS[3], 3, 7.5)})[0][2]
    assert rct.alarm_rows(slow, {"u4": (STAMPS[4], 3, 8.0)})[0][2]
    assert not bounds.alarm_in_window(15.1, True) and not bounds.alarm_in_window(None, False)


def test_bound_share_coverage_and_median_error():
    wear = {("u1", 2): [wear_row(STAMPS[3], 12, 8, 16, 10.5),    # 10 % true: covered, error 2, bound above truth
                        wear_row(STAMPS[5], 19, 17, 21, 17.0),   # 20 %: covered, error 1, bound below
                        wear_row(STAMPS[7], 36, 33, 39, 33.0)],  # 30 %: not covered, error 6, bound above
            ("u1", 3): [wear_row(STAMPS[7], 1, -2, 4, -1.0)],   # an unworn axis: not in the window's logs
            ("u2", 1): [wear_row(STAMPS[9], 11, 9, 13, 10.0)]}  # healthy at the limit: bound above truth 0
    below, alarms = bounds.bound_below(TRUTH, wear, 10.0)
    assert (below, alarms) == (1, 4)
    assert rct.bound_row(below, alarms)[1:] == ("25.0 % (1 of 4)", False)
    alarm_rows = [{"unit": "u1", "first_alarm": STAMPS[3], "source_axis": "2"},  # 10.5 over 10: above
                  {"unit": "u1", "first_alarm": STAMPS[5], "source_axis": "2"},  # 17 under 20: below
                  {"unit": "u2", "first_alarm": STAMPS[9], "source_axis": "1"},  # 10 over 0: above
                  {"unit": "u2", "first_alarm": STAMPS[0], "source_axis": "1"}]  # no wear row that day: not counted
    assert rct.alarms_below(TRUTH, wear, alarm_rows) == (1, 3)
    assert rct.bound_row(19, 20)[2] and not rct.bound_row(0, 0)[2]
    per_unit = bounds.window_logs(TRUTH, wear)
    assert per_unit == {"u1": [(True, 2.0), (True, 1.0), (False, 6.0)]}
    (_, median, ok_median), (_, cover, ok_cover) = rct.error_rows(per_unit, 0.03, 1.6)
    assert median.startswith("2.00 points over 3 logs (<= 2.10") and ok_median
    assert cover.startswith("66.7 %") and not ok_cover


def test_the_median_criterion_per_scatter():
    assert rct.median_target(0.0, None) == 1.5
    assert rct.median_target(0.015, 1.2) == pytest.approx(1.7)
    assert rct.median_target(0.015, 2.6) == 2.0
    assert rct.median_target(0.03, 2.6) == pytest.approx(3.1)
    assert rct.median_target(0.03, None) is None


def remaining(rul, rul_5):
    return SimpleNamespace(rul=rul, rul_5=rul_5, verdict="")


def test_lambda_service_by_within_and_phm():
    # u1 reaches 40 % on day 10 (eol 10); alarm known on day 4: lambda 4 + 0.5 x 6 = day 7, true 3 days
    asked = []

    def predict(stamp):
        asked.append(stamp)
        return remaining(3.5, 2.0)

    o = rct.lambda_outcome(TRUTH["u1"], STAMPS[3], predict)
    assert asked == [STAMPS[6]]
    assert (o["eol"], o["day"], o["true"], o["service_by"]) == (10.0, 7, 3.0, 9.0)
    assert o["ok"] and o["within"] and not o["late"]
    assert o["phm08"] == pytest.approx(np.exp(0.5 / 10) - 1)
    late = rct.lambda_outcome(TRUTH["u1"], STAMPS[3], lambda s: remaining(4.0, None))  # no 5 %: the median
    assert late["service_by"] == 11.0 and not late["ok"] and late["late"] and not late["within"]
    assert rct.lambda_outcome(TRUTH["u1"], "", predict)["why"] == "no alarm"
    none = rct.lambda_outcome(TRUTH["u1"], STAMPS[3], lambda s: remaining(None, None))
    assert "median" not in none and none["why"].startswith("day 7: no remaining life")
    # a 5 % end without a median (the 95 % end beyond the horizon): a service-by date, no median
    low = rct.lambda_outcome(TRUTH["u1"], STAMPS[3], lambda s: remaining(None, 2.5))
    assert (low["service_by"], low["ok"]) == (9.5, True) and "median" not in low and low["why"].startswith("day 7: no median")
    assert rct.lambda_rows({"u1": low}, clean=False)[0][1].endswith("by day 9.5 (failure 10.0))")
    assert rct.lambda_rows({"u1": low}, clean=False)[0][2] and rct.lambda_rows({"u1": none}, clean=False)[0][2] is False
    rows = rct.lambda_rows({"u1": o, "u3": late}, clean=False)
    assert [r[2] for r in rows] == [False, True, None]
    assert rows[0][1].startswith("1 of 2") and rows[1][1] == "1 of 2; late by more than 20 %: 1"
    assert "by day 11.0 (failure 10.0)" in rows[0][1]  # the service by's day to a tenth: a fraction late shows
    assert rows[2][1] == f"{o['phm08'] + late['phm08']:.2f} over 2 units"
    clean = rct.lambda_rows({f"u{i}": o for i in range(6)} | {"u7": late, "u8": none}, clean=True)
    assert "at least 6 of 8, late on none" in clean[1][0] and not clean[1][2]


def test_the_median_with_the_wear_on_its_log_known():
    # the same trend put on the true level: at_level multiplies the worn axis's filtered and own wear
    # (and the own bound) by the truth over the last filtered estimate, every other axis untouched
    from faultgen.monitor.record import AxisWear, LogRow

    def row(stamp, estimate, log):
        e, g = np.array([estimate, 5.0]), np.array([log, 6.0])
        return LogRow("u1", stamp, "monitoring", 0, 1, 0, 1, 0, (), np.zeros(2),
                      AxisWear(e, e - 1, e - 2, e + 2, g, g - 1.5))

    rows = [row(STAMPS[0], 10.0, 11.0), row(STAMPS[1], 20.0, 19.0)]
    put = rct.at_level(rows, 1, 30.0)
    assert [r.wear.estimate.tolist() for r in put] == [[15.0, 5.0], [30.0, 5.0]]
    assert [r.wear.log.tolist() for r in put] == [[16.5, 6.0], [28.5, 6.0]]
    assert [r.wear.log_lower.tolist() for r in put] == [[14.25, 4.5], [26.25, 4.5]]
    assert rct.at_level([row(STAMPS[0], 0.0, 1.0)], 1, 30.0)[0].wear.log[0] == 1.0  # no level to scale
    # lambda on day 7 (true wear 25 %, 3 days left): the monitor's 5 is late, the known level's 3.5 within
    asked = []

    def known(stamp, wear):
        asked.append((stamp, wear))
        return remaining(3.5, 2.0)

    o = rct.lambda_outcome(TRUTH["u1"], STAMPS[3], lambda s: remaining(5.0, 2.0), known)
    assert asked == [(STAMPS[6], pytest.approx(float(TRUTH["u1"]["wear"][6])))]
    assert not o["within"] and o["within_known"]
    rows = rct.lambda_rows({"u1": o, "u3": rct.lambda_outcome(TRUTH["u1"], STAMPS[3], lambda s: remaining(3.0, 2.0),
                                                              lambda s, w: remaining(None, None))}, clean=False)
    assert rows[3][1:] == ("1 of 2 (monitor: 1)", None) and "wear on that log known" in rows[3][0]
    # a unit the monitor gives no number at lambda still counts where its known level gives one
    none = rct.lambda_outcome(TRUTH["u1"], STAMPS[3], lambda s: remaining(None, None), known)
    assert "median" not in none and none["within_known"]
    assert rct.lambda_rows({"u1": o, "u2": none}, clean=False)[3][1] == "2 of 2 (monitor: 0)"
    assert len(rct.lambda_rows({"u1": rct.lambda_outcome(TRUTH["u1"], STAMPS[3], lambda s: remaining(3.0, 2.0))},
                               clean=False)) == 3  # without predict_known: no such row


def test_rates_units_and_the_cpu_ratio():
    per_unit = {"u3": [(True, 1.0)] * 9 + [(False, 1.0)]}
    firsts = {"u1": (STAMPS[4], 2, 15.0), "u2": ("", None, None), "u3": (STAMPS[5], 1, 12.0)}
    rows = rct.rates_rows(TRUTH, firsts, per_unit)  # u1's 5 points a day is not one of RATES
    assert [(r[1], r[2]) for r in rows] == [("90 % of 10 logs", True), ("2026-01-06 at 12.0 %", True)]
    lines = rct.ratio_lines({"scatter-0.015": 0.3, "scatter-0.015-one-program": 0.25, "scatter-0.015-rates": 0.5,
                             "scatter-0.03": 0.2, "scatter-0.03-one-program": None})
    assert lines == ["- scatter-0.015 / its one-program fleet: CPU time per log 0.300 / 0.250 s = 1.20x (met: at "
                     "most 1.5x)"]
    assert rct.ratio_lines({"scatter-0.03": 0.4, "scatter-0.03-one-program": 0.25}) == [
        "- scatter-0.03 / its one-program fleet: CPU time per log 0.400 / 0.250 s = 1.60x (NOT met: at most 1.5x)"]


def test_a_fleet_folder_not_named_for_its_scatter_is_refused():
    assert rct.scatter_of(Path("/x/scatter-0.015-one-program")) == 0.015
    with pytest.raises(SystemExit, match="expected a fleet folder named scatter-<sigma>"):
        rct.scatter_of(Path("/x/fleet"))


@pytest.mark.parametrize("given, passed", [(["--limit", "10"], "10"), ([], "8")])
def test_monitor_runs_with_the_tables_limit_as_its_wear_limit(monkeypatch, tmp_path, capsys, given, passed):
    """``--monitor --limit L`` runs ``faultgen monitor ... --wear-limit L``, so the table judges the bound at
    the limit the alarms were raised at; without ``--limit`` both take the monitor's default (8 %: issue 90)."""
    calls = []

    def run_monitor(logs, robot, out, timeout, jobs, options=()):
        calls.append(options)
        return 12.0, 3.0, None  # killed past --timeout: no table, nothing else read

    monkeypatch.setattr(rct.real_cell_fleet, "run_monitor", run_monitor)
    monkeypatch.setattr(sys, "argv", ["real_cell_table.py", str(tmp_path / "fleet"), str(tmp_path / "out"),
                                      "--monitor", *given])
    rct.main()
    assert calls == [("--wear-limit", passed)]
    assert "faultgen monitor killed after 12 s" in capsys.readouterr().out
