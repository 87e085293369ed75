"""Issue 57, item 3: one scoring path. `analysis.scoring` computes the detection and isolation figures
of `detect` (and `detect --train`), `bench score` (the twin's recorded answers through it) and
`bench-isolators`, each command under its named rules; here the rules against small hand-computed
cases, and a spy on the module under each command."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from test_bench_twin import injected  # noqa: F401 (the fixture: the twin's answers of a known outcome)
from typer.testing import CliRunner

from analysis import crossdata, scoring
from analysis.benchmark import detection, isolation_scores
from faultgen.bench import recorded, score, twin
from faultgen.cli import app

runner = CliRunner()


# --- the rules, against hand-computed cases ---------------------------------------------------------

#: Alarms of one run: three in a row from sample 0 (before its fault), then again from sample 5.
ALARMS = np.array([1, 1, 1, 0, 0, 1, 1, 1, 0, 0], dtype=bool)


def test_the_onset_is_looked_for_from_the_fault_or_from_the_first_record():
    detect, bench = scoring.DETECT_RULES, scoring.BENCH_RULES
    assert scoring.onset(ALARMS, bench, fault_start=4) == 0  # bench score: the early run counts
    assert scoring.onset(ALARMS, detect, fault_start=4) == 5  # detect: from the fault's sample 4 on
    assert scoring.onset(ALARMS, detect, fault_start=None) is None  # no fault, no onset under detect's rule
    assert scoring.onset(ALARMS, bench, fault_start=None) == 0
    assert scoring.onset(ALARMS, bench, skip=1) == 5  # samples 1-2: two in a row, not three
    assert scoring.onset(ALARMS, detect.with_persistence(1), fault_start=4) == 5
    assert scoring.onset(ALARMS, detect.with_persistence(1), fault_start=2) == 2
    assert scoring.onset(ALARMS, detect.with_persistence(4), fault_start=0) is None
    assert scoring.onset(ALARMS, detect, fault_start=1, skip=6) is None  # after what the monitor learned


def test_alarms_before_the_fault_are_those_after_the_learned_samples():
    assert scoring.before_fault(ALARMS, 4, skip=1).tolist() == [True, True, False]
    assert scoring.before_fault(ALARMS, None, skip=8).tolist() == [False, False]  # no fault: the rest of the run


def test_the_false_alarm_rate_pooled_or_the_mean_of_each_runs_rate():
    runs = [np.array([1, 0, 0, 0], dtype=bool), np.array([1, 1], dtype=bool)]
    pooled, per_run = scoring.BENCH_RULES, scoring.DETECT_RULES
    assert scoring.false_alarm_rate(runs, pooled) == 0.5  # 3 alarms of 6 records
    assert scoring.false_alarm_rate(runs, per_run) == 0.625  # (1/4 + 2/2) / 2
    assert scoring.false_alarm_rate(runs, per_run, scale=100.0) == 62.5
    assert scoring.false_alarm_rate(runs, pooled, scale=100.0) == 50.0
    assert math.isnan(scoring.false_alarm_rate([], pooled)) and math.isnan(scoring.false_alarm_rate([], per_run))
    assert scoring.alarm_counts(runs) == (3, 6)


def test_share_detected_and_delays_in_the_records_cycles():
    assert scoring.detected_share([True, False, True, True]) == 0.75
    assert math.isnan(scoring.detected_share([]))
    level, cycles = np.array([0.0, 0.0, 5.0, 12.0, 20.0]), np.array([10, 20, 30, 40, 50])
    assert scoring.fault_start(level) == 2 and scoring.first_reaching(level, 10.0) == 3
    assert scoring.fault_start(np.zeros(3)) is None and scoring.first_reaching(level, 50.0) is None
    assert scoring.delay(4, cycles, scoring.fault_start(level)) == 20.0
    assert scoring.delay(4, cycles, scoring.first_reaching(level, 10.0)) == 10.0
    assert scoring.delay(1, cycles, 3) == -20.0  # an onset before the level: a negative delay
    assert math.isnan(scoring.delay(None, cycles, 2)) and math.isnan(scoring.delay(4, cycles, None))


def test_top1_accuracy_leaves_too_few_cycles_out_or_counts_it_undecided():
    named, true = [2, 3, scoring.TOO_FEW_CYCLES, 0], [2, 2, 2, 0]  # right, wrong, too few, healthy left undecided
    assert scoring.top1_accuracy(named, true, scoring.ISOLATION_TABLE_RULES) == pytest.approx(2 / 3)
    assert scoring.top1_accuracy(named, true, scoring.BENCH_RULES) == 0.5
    assert scoring.top1_accuracy([scoring.TOO_FEW_CYCLES, 0], [0, 0], scoring.BENCH_RULES) == 1.0  # healthy
    assert math.isnan(scoring.top1_accuracy([scoring.TOO_FEW_CYCLES], [1], scoring.ISOLATION_TABLE_RULES))
    assert scoring.isolation_right([1, 0, 4], [1, 0, 0]).tolist() == [True, True, False]  # naming one on healthy
    assert scoring.too_few_answer(scoring.BENCH_RULES) == scoring.UNDECIDED
    assert scoring.too_few_answer(scoring.ISOLATION_TABLE_RULES) == scoring.TOO_FEW_CYCLES


def test_each_commands_rules_are_named_and_an_unknown_rule_is_refused():
    assert (scoring.DETECT_RULES.onset_from, scoring.DETECT_RULES.false_alarm_rate) == ("fault", "per_run_mean")
    assert (scoring.BENCH_RULES.onset_from, scoring.BENCH_RULES.false_alarm_rate) == ("first_record", "pooled")
    assert scoring.BENCH_RULES.persistence == scoring.DETECT_RULES.persistence == 3
    assert scoring.ISOLATION_TABLE_RULES.too_few_cycles == "not_applicable"
    assert score.RULES is scoring.BENCH_RULES
    with pytest.raises(ValueError, match="onset_from = 'later'; expected one of: fault, first_record"):
        scoring.Rules(persistence=3, onset_from="later", false_alarm_rate="pooled")
    with pytest.raises(ValueError, match="false_alarm_rate"):
        scoring.Rules(persistence=3, onset_from="fault", false_alarm_rate="max")


# --- each command scores through the module ---------------------------------------------------------

@pytest.fixture
def spied(monkeypatch):
    """Every call of the module's scoring functions: (function name, rules or None)."""
    calls: list[tuple[str, object]] = []
    for name in ("onset", "false_alarm_rate", "detected_share", "delay", "before_fault", "top1_accuracy",
                 "isolation_right"):
        real = getattr(scoring, name)

        def spy(*args, _real=real, _name=name, **kwargs):
            rules = next((a for a in (*args, *kwargs.values()) if isinstance(a, scoring.Rules)), None)
            calls.append((_name, rules))
            return _real(*args, **kwargs)

        monkeypatch.setattr(scoring, name, spy)
    return calls


def _rules(calls, name):
    return {rules for called, rules in calls if called == name}


def test_bench_score_scores_the_twins_recorded_answers_through_the_module(injected, spied):  # noqa: F811
    data, out, written, units = injected
    scores, alarms, named, _ = twin.answers(out, written, {u.id: 20 for u in units})
    results = score.score(data, recorded.RecordedDetector(recorded.detector_answers(units, scores, alarms)),
                          "twin", "detector", track="sim-to-real", allow_modified=True)["results"]
    assert _rules(spied, "onset") == _rules(spied, "false_alarm_rate") == {scoring.BENCH_RULES}
    assert {"detected_share", "delay"} <= {name for name, _ in spied}
    assert results["false_alarm_rate"]["value"] == pytest.approx(2 / 20)  # the figures the twin's test knows
    spied.clear()
    score.score(data, recorded.RecordedIsolator(recorded.isolator_answers(units, named)), "twin", "isolator",
                track="sim-to-real", allow_modified=True)
    assert _rules(spied, "top1_accuracy") == {scoring.BENCH_RULES}


def test_the_bench_score_command_scores_a_baseline_through_the_module(injected, spied, tmp_path):  # noqa: F811
    data = injected[0]
    result = runner.invoke(app, ["bench", "score", "sim-to-real", "--data", str(data), "--baseline", "pca",
                                 "--allow-modified", "-o", str(tmp_path / "pca")])
    assert result.exit_code == 0, result.output
    assert _rules(spied, "onset") == _rules(spied, "false_alarm_rate") == {scoring.BENCH_RULES}


@pytest.fixture(scope="module")
def two_seeds(shared_sweep):
    """tests/test_analysis_benchmark.py's: no wear and axis 5 worn, seeds 0 and 1, 20 cycles."""
    return shared_sweep("analysis-seeds", robots=["irb6700"], tasks=["pick_place"], axes=[0, 5], cycles=20,
                        seeds=[0, 1])


def test_detect_scores_through_the_module_under_its_rules(two_seeds, spied, tmp_path):
    result = runner.invoke(app, ["detect", str(two_seeds), "--no-progress", "--persistence", "2",
                                 "-o", str(tmp_path / "det")])
    assert result.exit_code == 0, result.output
    rules = scoring.DETECT_RULES.with_persistence(2)
    assert _rules(spied, "onset") == _rules(spied, "false_alarm_rate") == {rules}
    assert {"before_fault", "isolation_right", "detected_share"} <= {name for name, _ in spied}
    assert "scoring.onset" in Path(detection.__file__).read_text()  # no second onset rule beside it


def test_detect_train_scores_through_the_module_under_detects_rules(two_seeds, spied, tmp_path):
    table, _ = crossdata.detection_across(two_seeds, two_seeds, first=5, progress=False)
    assert len(table) == 2
    assert _rules(spied, "onset") == _rules(spied, "false_alarm_rate") == {scoring.DETECT_RULES}


def test_bench_isolators_scores_through_the_module(two_seeds, spied, tmp_path):
    result = runner.invoke(app, ["bench-isolators", str(two_seeds), "--no-progress", "-o", str(tmp_path / "iso")])
    assert result.exit_code == 0, result.output
    assert _rules(spied, "top1_accuracy") == {scoring.ISOLATION_TABLE_RULES}
    assert "isolation_right" in {name for name, _ in spied}  # each case's "correct"
    assert "scoring.top1_accuracy" in Path(isolation_scores.__file__).read_text()
