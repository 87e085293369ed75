"""`detect` and `bench-isolators` state what their numbers rest on (issue 51, item 2): runs whose
monitor learned the fault are out of the summary, advice is what the data allows, a false-alarm
rate above alpha is flagged, located_pct 0 says why, and an isolator is scored by one rule, with
"not applicable" where the dataset is too short for it."""

import numpy as np
import pytest
from sklearn.base import BaseEstimator
from test_analysis_benchmark import NeverDecides
from typer.testing import CliRunner

from analysis import benchmark, isolation
from analysis.benchmark import detection_report
from faultgen.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def small(shared_sweep):
    """Pick and place, no wear and axes 1 and 5 worn, 40 cycles all recorded (as test_analysis_benchmark)."""
    return shared_sweep("analysis-small", robots=["irb6700"], tasks=["pick_place"], axes=[0, 1, 5], cycles=40)


@pytest.fixture(scope="module")
def two_seeds(shared_sweep):
    return shared_sweep("analysis-seeds", robots=["irb6700"], tasks=["pick_place"], axes=[0, 5], cycles=20,
                        seeds=[0, 1])


@pytest.fixture(scope="module")
def sparse(shared_sweep):
    return shared_sweep("analysis-sparse", robots=["irb6700"], tasks=["pick_place"], axes=[0, 2, 5], cycles=40,
                        record=[10, 20, 30, 40])


def test_runs_trained_on_the_fault_are_left_out_of_the_summary_and_the_advice_is_possible(small):
    table = benchmark.detection_table(small, progress=False, protocol="first-cycles")
    assert table["trained_on_fault"].all()  # exp4 wear begins at cycle 1, inside the 20 samples learned
    summary = benchmark.detection_summary(table)
    assert summary.loc[("all", "all"), "left_out"] == len(table) and summary.loc[("all", "all"), "runs"] == 0
    assert np.isnan(summary.loc[("all", "all"), "detected_pct"])  # nothing counted rests on them
    advice = benchmark.detection_advice(table, "first-cycles")
    assert "2 of 2 runs are left out of the summary" in advice
    assert "below 1" not in advice and "No --first avoids it" in advice and "--protocol other-seeds" in advice
    assert "--preset quick" not in advice


def test_detect_says_what_its_summary_rests_on(small, tmp_path):
    result = runner.invoke(app, ["detect", str(small), "--protocol", "first-cycles", "--no-progress",
                                 "-o", str(tmp_path / "d")])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "summary (of 0 of 2 runs: 2 left out, their monitor learned the fault;" in text
    assert "2 of 2 runs are left out of the summary" in text


def test_the_advice_suggests_the_datasets_own_sweep_with_seeds():
    assert detection_report._with_seeds("faultgen sweep --preset j2 -o j2.h5 --no-progress") == \
        "faultgen sweep --preset j2 --seed 0 --seed 1 --seed 2 -o j2-seeds.h5"


class AlwaysAlarms(BaseEstimator):
    """A detector that alarms on every sample: its false-alarm rate is 100 %."""

    def fit(self, X, y=None):
        return self

    def predict(self, X):
        return np.ones(len(X), dtype=bool)


def test_a_held_out_false_alarm_rate_above_alpha_is_flagged_in_words(two_seeds):
    table = benchmark.detection_table(two_seeds, progress=False, detector=AlwaysAlarms(), protocol="other-seeds")
    assert (table["false_alarm_pct"] == 100).all() and table["false_alarm_above_alpha"].all()
    low = float(table["false_alarm_ci_pct"].iloc[0].split("-")[0])
    assert 75 < low < 100
    advice = benchmark.detection_advice(table, "other-seeds")
    assert "held-out false-alarm rate is above the nominal 5 % by more than its 95 % interval" in advice
    assert benchmark.false_alarm_interval(0, 20) == (0.0, pytest.approx(16.84, abs=0.01))  # Clopper-Pearson


def test_located_pct_of_zero_says_why(sparse):
    table = benchmark.detection_table(sparse, progress=False, persistence=1)
    assert table["detected"].all() and not table["located"].any()
    assert (table["located_axis"] == benchmark.TOO_FEW_CYCLES).any()  # an onset after two samples
    advice = benchmark.detection_advice(table)
    assert "located_pct is 0 (of 2 detected runs)" in advice and "too few to locate" in advice


def test_an_isolator_is_scored_by_one_rule_and_not_applicable_where_the_data_is_too_short(sparse):
    isolators = {"never": NeverDecides(), "pca_contribution": isolation.make("pca_contribution")}
    table = benchmark.isolation_table(sparse, isolators, levels=[5.0, 15.0], progress=False)
    accuracy = benchmark.isolation_accuracy(table)
    never = accuracy["never"]
    assert (never.xs(0.0, level="wear_pct") == 100).all() and (never.drop(0.0, level="wear_pct") == 0).all()
    assert accuracy["pca_contribution"].isna().all()  # 4 cycles < 21: not scored 0
    text = benchmark.isolation_accuracy_text(table)
    assert text.loc[("pick_place", 0.0), "pca_contribution"] == "not applicable: 4 cycles < 21 needed"
    assert all(v.startswith("not applicable: ") and v.endswith(" < 21 needed") for v in text["pca_contribution"])
    assert "not applicable" in benchmark.isolation_markdown(table, marked="never")


def test_bench_isolators_prints_the_rule_its_table_follows(sparse, tmp_path):
    result = runner.invoke(app, ["bench-isolators", str(sparse), "--no-progress", "-o", str(tmp_path / "iso")])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "not applicable: 4 cycles < 21 needed" in text  # pca_contribution on the no-fault rows
    assert "one that never decides scores 100 % on \"no fault\" and 0 % elsewhere" in text
    assert "Cases with fewer cycles than it needs are not scored" in text
