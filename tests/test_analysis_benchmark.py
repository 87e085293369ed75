"""analysis.benchmark and the bench-isolators / detect / classify commands on a small real dataset."""

import h5py
from sklearn.base import BaseEstimator
import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from analysis import benchmark, isolation
from faultgen.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def small(shared_sweep):
    """Pick and place, no wear and axes 1 and 5 worn (exp4, +20 % over 40 cycles), all recorded."""
    return shared_sweep("analysis-small", robots=["irb6700"], tasks=["pick_place"], axes=[0, 1, 5], cycles=40)


def test_level_cycle_is_the_first_cycle_reaching_the_wear():
    multiplier = np.array([1.0, 1.004, 1.01, 1.05, 1.2])
    assert benchmark.level_cycle(multiplier, 1.0) == 2
    assert benchmark.level_cycle(multiplier, 5.0) == 3
    assert benchmark.level_cycle(multiplier, 25.0) is None


def test_isolation_table_runs_every_isolator_at_every_level(small):
    isolators = {"te5": isolation.make("transfer_entropy", bins=5), "trend": isolation.make("trend")}
    table = benchmark.isolation_table(small, isolators, levels=(5.0, 20.0), progress=False)
    assert set(table["isolator"]) == {"te5", "trend"}
    assert sorted(set(table["worn_axis"])) == [0, 1, 5]  # 0: the run without wear
    # at 20 % every recorded cycle is used; at 5 % fewer
    full = table[table["wear_pct"] == 20.0]["cycles"]
    assert set(full) == {40} and table[table["wear_pct"] == 5.0]["cycles"].max() < 40
    # the run without wear is shown as many cycles as the worn runs saw at each level
    healthy = table[table["worn_axis"] == 0]
    assert set(healthy["wear_pct"]) == {0.0} and set(healthy["run"]) == {"irb6700-pick_place-nowear-seed0"}
    assert sorted(set(healthy["cycles"])) == sorted(set(table[table["worn_axis"] > 0]["cycles"]))
    # right only when it names no axis (0, undecided); naming one is a false isolation
    assert (table["correct"] == (table["predicted"] == table["worn_axis"])).all()
    # the trend of the worn axis's torque gives it away at full wear
    assert table[(table["isolator"] == "trend") & (table["wear_pct"] == 20.0)]["correct"].all()
    accuracy = benchmark.isolation_accuracy(table)
    assert list(accuracy.columns) == ["te5", "trend"]
    text = benchmark.isolation_markdown(table, marked="trend")
    assert "| pick_place | 20 | ✓ | - | - | - | ✓ | - |" in text
    no_fault = accuracy.loc[("pick_place", 0.0)]
    for name in ("te5", "trend"):
        rows = healthy[healthy["isolator"] == name]
        assert no_fault[name] == pytest.approx(100 * (rows["predicted"] == 0).mean())
    assert "| pick_place | no fault | - | - | - | - | - | - |" in text


def test_confusion_counts_true_against_named_axis_per_isolator(small, tmp_path):
    isolators = {"te5": isolation.make("transfer_entropy", bins=5), "trend": isolation.make("trend")}
    table = benchmark.isolation_table(small, isolators, levels=(5.0, 20.0), progress=False)
    confusion = benchmark.isolation_confusion(table)
    assert list(confusion.columns) == ["undecided", "1", "2", "3", "4", "5", "6", "too few cycles"]
    assert list(confusion.loc["trend"].index) == ["none", "1", "2", "3", "4", "5", "6"]
    for name in ("te5", "trend"):
        rows = table[table["isolator"] == name]
        assert confusion.loc[name].to_numpy().sum() == len(rows)
        for true, label in ((0, "none"), (1, "1"), (5, "5")):
            named = rows[rows["worn_axis"] == true]["predicted"]
            for answer, column in ((0, "undecided"), (1, "1"), (5, "5"), (-1, "too few cycles")):
                assert confusion.loc[(name, label), column] == (named == answer).sum()
    png = benchmark.confusion_figure(confusion, tmp_path / "c.png")
    assert png.stat().st_size > 10_000


def test_markdown_prints_undecided_not_axis_0():
    table = pd.DataFrame({"run": ["a", "b", "c"], "located_axis": [0, 3, -1]})
    text = benchmark.markdown(table)
    assert "| a | undecided |" in text and "| b | 3 |" in text and "| c | too few cycles |" in text


def test_detection_flags_worn_runs_against_the_unworn_one(small):
    table = benchmark.detection_table(small, progress=False, protocol="same-run")
    assert sorted(table["worn_axis"]) == [1, 5]
    assert set(table.columns) >= {"detected", "onset", "onset_wear_pct", "located_axis", "located"}
    detected = table[table["detected"]]
    assert (detected["onset_wear_pct"] <= 20.0).all()
    assert set(table["protocol"]) == {"same-run (in-sample)"}
    assert set(table["trained_on"]) == {"irb6700-pick_place-nowear-seed0"}


@pytest.fixture(scope="module")
def two_seeds(shared_sweep):
    """Pick and place, no wear and axis 5 worn, seeds 0 and 1, 20 cycles all recorded: 4 runs."""
    return shared_sweep("analysis-seeds", robots=["irb6700"], tasks=["pick_place"], axes=[0, 5], cycles=20,
                        seeds=[0, 1])


def test_held_out_protocols_learn_from_data_the_tested_run_did_not_produce(two_seeds, small):
    table = benchmark.detection_table(two_seeds, progress=False, persistence=3)  # auto: other seeds exist
    assert list(table["protocol"]) == ["other-seeds", "other-seeds"]
    for row in table.itertuples():  # trained on the other seed's healthy run, judged on its own seed's
        assert row.trained_on == f"irb6700-pick_place-nowear-seed{1 - row.seed}"
        assert 0.0 <= row.false_alarm_pct <= 100.0
    first = benchmark.detection_table(small, progress=False, persistence=3)  # auto, one seed, 40 cycles
    assert set(first["protocol"]) == {"first-cycles"} and set(first["trained_on"]) == {"samples 1-20 of the run"}
    assert (first["false_alarm_pct"].notna()).all()
    assert (first[first["detected"]]["onset"] >= 20).all()  # never inside the samples it learned from
    summary = benchmark.detection_summary(first)  # the wear begins at cycle 1: both learned it, both left out
    assert first["trained_on_fault"].all()
    assert summary.loc[("all", "all"), "runs"] == 0 and summary.loc[("all", "all"), "left_out"] == 2
    summary = benchmark.detection_summary(table)  # other-seeds: nothing learned the fault
    assert summary.loc[("all", "all"), "runs"] == 2 and summary.loc[("all", "all"), "left_out"] == 0
    assert summary.loc[("all", "all"), "false_alarm_pct"] == pytest.approx(table["false_alarm_pct"].mean(), abs=0.01)


def test_a_protocol_the_dataset_cannot_serve_is_refused_saying_what_it_lacks(small):
    with pytest.raises(ValueError, match="protocol other-seeds needs runs without wear .* another seed than 0"):
        benchmark.detection_table(small, progress=False, protocol="other-seeds")
    with pytest.raises(ValueError, match="learns from the first 50 samples of a run and needs more; .* has 40"):
        benchmark.detection_table(small, progress=False, protocol="first-cycles", first=50)
    with pytest.raises(ValueError, match="unknown protocol 'held-out'; expected one of: auto, other-seeds"):
        benchmark.detection_table(small, progress=False, protocol="held-out")
    for folds in (1, 2.5, True):
        with pytest.raises(ValueError, match=rf"limit_folds = {folds!r}; expected None .* number of folds >= 2"):
            benchmark.detection_table(small, progress=False, limit_folds=folds)


def test_bench_isolators_command_writes_csv_markdown_and_heatmap(small, tmp_path):
    stem = tmp_path / "iso"
    result = runner.invoke(app, ["bench-isolators", str(small), "--bins", "5", "--levels", "5,20", "--no-progress",
                                 "-o", str(stem)])
    assert result.exit_code == 0, result.output
    table = pd.read_csv(stem.with_suffix(".csv"))
    assert {"te5", "cross_correlation", "granger", "trend"} <= set(table["isolator"])
    assert "accuracy te5" in stem.with_suffix(".md").read_text()
    assert stem.with_suffix(".png").stat().st_size > 10_000
    confusion = pd.read_csv(tmp_path / "iso-confusion.csv", index_col=[0, 1])
    assert confusion.loc[("trend", "none")].sum() == 2  # the run without wear, at 2 levels
    assert (tmp_path / "iso-confusion.png").stat().st_size > 10_000
    assert "no fault" in result.output


def test_bins_below_two_are_refused(small, tmp_path):
    result = runner.invoke(app, ["bench-isolators", str(small), "--bins", "1", "--no-progress", "-o", str(tmp_path / "x")])
    assert result.exit_code == 2
    assert "--bins '1': expected 2..100" in result.output  # refused at the option, before any work


def test_analysis_refuses_a_dataset_that_fails_validation(small, tmp_path):
    broken = tmp_path / "broken.h5"
    broken.write_bytes(small.read_bytes())
    with h5py.File(broken, "r+") as f:
        run = next(iter(f["runs"]))
        hist = f["runs"][run]["torque_hist"]
        hist[0, 0, 0] += 0.5  # a histogram that no longer sums to 1
    for command in ("bench-isolators", "detect", "classify"):
        result = runner.invoke(app, [command, str(broken)])
        assert result.exit_code == 2, (command, result.output)
        assert "fails validation" in result.output and "torque_hist" in result.output
    broken.write_bytes(small.read_bytes())
    with h5py.File(broken, "r+") as f:
        counts = f["runs"][run]["torque_counts"]
        counts[0, 0, 0] += 1  # one sample too many in a cycle's counts
    result = runner.invoke(app, ["detect", str(broken)])
    assert result.exit_code == 2, result.output
    assert "torque_counts: not counts of the" in " ".join(result.output.split())


@pytest.fixture(scope="module")
def sparse(shared_sweep):
    """Like the quick preset: every tenth cycle recorded (4 of 40), no wear and two worn axes."""
    return shared_sweep("analysis-sparse", robots=["irb6700"], tasks=["pick_place"], axes=[0, 2, 5], cycles=40,
                        record=[10, 20, 30, 40])


def test_on_a_quick_like_dataset_each_command_prints_a_table_or_what_the_data_lacks(sparse, tmp_path):
    result = runner.invoke(app, ["bench-isolators", str(sparse), "--no-progress", "-o", str(tmp_path / "iso")])
    assert result.exit_code == 0, result.output
    assert "note: this dataset lacks cycles: with at most 4 recorded cycles per run" in result.output
    assert "te10" in result.output.split("note:")[1] and "faultgen sweep --preset j2" in result.output

    result = runner.invoke(app, ["detect", str(sparse), "--no-progress", "-o", str(tmp_path / "det")])
    assert result.exit_code == 0, result.output
    assert "note: this dataset lacks runs without wear of other seeds" in " ".join(result.output.split())
    assert "--seed 0 --seed 1 --seed 2" in result.output
    table = pd.read_csv(tmp_path / "det.csv")
    # issue 40: the header says what false_alarm_pct measured under the protocol the rows used
    assert set(table["protocol"]) == {"same-run (in-sample)"}
    assert "summary (false_alarm_pct, %: same-run (in-sample): the training run itself: in-sample" in result.output
    assert "did not learn from" not in result.output.split("summary (")[1].splitlines()[0]
    printed = [line for line in result.output.splitlines() if line.startswith("| irb6700")]
    assert len(printed) == len(table) == 2
    for line, located in zip(printed, table["located_axis"], strict=True):
        assert line.split(" | ")[-2] == benchmark.axis_label(located)  # never a bare 0

    result = runner.invoke(app, ["classify", str(sparse), "--no-progress", "--pairs", "0", "-o", str(tmp_path / "cls")])
    # 4 cycles per run: with a pair held out, one worn run of 4 cycles is left to train on
    assert result.exit_code == 2, result.output
    message = " ".join(result.output.split())
    assert "error: " in message and "this dataset lacks runs for leave-pair-out classification" in message
    assert "the smallest training set has 1 failed samples (true wear >= 10 %) and 3 normal ones" in message
    assert "faultgen sweep --preset quick" in message
    assert not (tmp_path / "cls.csv").exists()

    result = runner.invoke(app, ["training-source", str(sparse), "--no-progress", "-o", str(tmp_path / "ch4")])
    assert result.exit_code == 2, result.output
    message = " ".join(result.output.split())
    assert "has 4 records, the study needs 60" in message and "a fleet (`faultgen fleet`) records 60 days" in message
    assert not list(tmp_path.glob("ch4*"))


PLUGINS = '''
import numpy as np
from sklearn.base import BaseEstimator

from analysis.isolation import Isolator


class LargestRise(Isolator):
    """Names the axis whose signal rose most from the first to the last cycle."""

    def _min_rows(self, n_rows):
        return 2

    def _scores(self, X):
        return (X[-1] - X[0]) / np.abs(X[0])


class ZScore(BaseEstimator):
    """Alarms where any feature leaves the healthy mean by more than `limit` standard deviations."""

    def __init__(self, limit=4.0):
        self.limit = limit

    def fit(self, X, y=None):
        self.mean_, self.std_ = X.mean(axis=0), X.std(axis=0) + 1e-12
        return self

    def predict(self, X):
        return (np.abs((X - self.mean_) / self.std_) > self.limit).any(axis=1)


class NotAnEstimator:
    pass
'''


def test_plug_ins_from_a_users_module_run_through_the_commands(small, tmp_path, monkeypatch):
    (tmp_path / "user_plugins_a.py").write_text(PLUGINS)
    monkeypatch.chdir(tmp_path)  # the module lies in the current folder, as a user's would
    result = runner.invoke(app, ["bench-isolators", str(small), "--bins", "5", "--levels", "5,20", "--no-progress",
                                 "--isolator", "user_plugins_a:LargestRise", "-o", str(tmp_path / "iso")])
    assert result.exit_code == 0, result.output
    table = pd.read_csv(tmp_path / "iso.csv")
    mine = table[table["isolator"] == "LargestRise"]
    assert len(mine) == len(table[table["isolator"] == "te5"]) > 0
    full = mine[mine["wear_pct"] == 20.0]
    assert (full["predicted"] == full["worn_axis"]).all()  # at 20 % the worn axis rose most

    result = runner.invoke(app, ["detect", str(small), "--no-progress", "--detector", "user_plugins_a:ZScore",
                                 "-o", str(tmp_path / "det")])
    assert result.exit_code == 0, result.output
    detected = pd.read_csv(tmp_path / "det.csv")
    assert sorted(detected["worn_axis"]) == [1, 5] and detected["detected"].all()


@pytest.mark.parametrize(("spec", "message"), [
    ("user_plugins_b", "expected package.module:Class"),
    ("no_such_module_xyz:Thing", "cannot import 'no_such_module_xyz'"),
    ("user_plugins_b:Missing", "has no class 'Missing'"),
    ("user_plugins_b:NotAnEstimator", "is not a scikit-learn estimator"),
])
def test_a_bad_plug_in_is_refused_naming_it(small, tmp_path, monkeypatch, spec, message):
    (tmp_path / "user_plugins_b.py").write_text(PLUGINS)
    monkeypatch.chdir(tmp_path)
    result = runner.invoke(app, ["bench-isolators", str(small), "--isolator", spec, "--no-progress",
                                 "-o", str(tmp_path / "iso")])
    assert result.exit_code == 2, result.output
    assert f"error: plug-in {spec!r}" in result.output and message in result.output
    assert not (tmp_path / "iso.csv").exists()


def test_speed_window_changes_the_signal_only_on_axes_whose_cycles_all_reach_it(small, tmp_path):
    isolators = {"trend": isolation.make("trend")}
    plain = benchmark.isolation_table(small, isolators, levels=(20.0,), progress=False)
    window = benchmark.isolation_table(small, isolators, levels=(20.0,), progress=False, speed_window=(50.0, 120.0))
    coverage = benchmark.motor_speed_coverage(small, (50.0, 120.0))
    assert list(coverage.columns) == ["p50_rad_s", "p99_rad_s", "in_window_pct"] and len(coverage) == 6
    windowed = {int(a) for a in window["windowed"].iloc[0].split()}
    assert set(plain["windowed"]) == {""}
    for axis in range(1, 7):  # an axis never inside the window cannot be windowed
        if coverage.loc[("irb6700", "pick_place", axis), "in_window_pct"] == 0:
            assert axis not in windowed
    assert windowed, "no axis of pick and place reaches 50-120 rad/s"
    result = runner.invoke(app, ["bench-isolators", str(small), "--bins", "5", "--levels", "20", "--no-progress",
                                 "--speed-window", "50,120", "-o", str(tmp_path / "w")])
    assert result.exit_code == 0, result.output
    assert "motor speeds against the window 50-120 rad/s" in result.output and "in_window_pct" in result.output
    result = runner.invoke(app, ["bench-isolators", str(small), "--speed-window", "120", "-o", str(tmp_path / "x")])
    assert result.exit_code == 2 and "expected LOW,HIGH in rad/s" in result.output


def test_classification_features_are_the_indicators_and_the_estimates(small, tmp_path, monkeypatch):
    from analysis import classify
    from analysis.features import duty_indicators
    from faultgen.data import dataset

    seen = {}
    monkeypatch.setattr(classify, "evaluate", lambda X, *args, estimated=None, **kw: seen.update(X=X, est=estimated)
                        or pd.DataFrame())
    benchmark.classification_table(small, progress=False)
    first = dataset.list_runs(small)[0]
    arrays, _ = dataset.read_run(small, first, names=dataset.DUTY_ARRAYS)
    n = len(arrays["average_speed"])
    speed, torque = duty_indicators(arrays["average_speed"], arrays["average_load_torque"])
    assert seen["X"].shape[1] == 30  # per axis: two indicators and three KL divergences (Table 5.1 without +estM)
    np.testing.assert_array_equal(seen["X"][:n, :12], np.hstack([speed, torque]))
    np.testing.assert_array_equal(seen["est"][:n], np.hstack([arrays["average_speed"], arrays["average_load_torque"]]))

    old = tmp_path / "old.h5"  # runs simulated before the duty was recorded: the torque levels, no +estM
    old.write_bytes(small.read_bytes())
    with h5py.File(old, "r+") as f:
        del f["runs"][first]["average_speed"], f["runs"][first]["average_load_torque"]
    benchmark.classification_table(old, progress=False)
    levels, _ = dataset.read_run(old, first, names=("mean_abs_torque", "rms_torque"))
    np.testing.assert_array_equal(seen["X"][:n, :12], np.hstack([levels["mean_abs_torque"], levels["rms_torque"]]))
    assert seen["est"] is None


def test_classification_table_scores_the_estimates_rows(small):
    table = benchmark.classification_table(small, progress=False, classifiers=["lr"],
                                           preprocessing=["control", "+estM"])
    assert list(table.index) == ["control", "+estM"]
    assert np.isfinite(table[("lr", "mean")]).all()


def test_classify_command_scores_chosen_cells_and_their_chance_level(small, tmp_path):
    result = runner.invoke(app, ["classify", str(small), "--classifier", "lr", "--preprocessing", "control",
                                 "--preprocessing", "+diff", "--permutations", "2", "--no-progress", "--jobs", "1",
                                 "-o", str(tmp_path / "c")])  # in this process: no worker start-up (5 s of CPU)
    assert result.exit_code == 0, result.output
    lines = [line for line in result.output.splitlines() if line.startswith("|")]
    assert lines[0] == "| preprocessing | lr mean | lr std | lr p | chance | above_chance |"
    assert "p cannot go below 0.33: use --permutations 19" in " ".join(result.output.split())
    assert [line.split(" | ")[0] for line in lines[2:]] == ["| control", "| +diff"]
    assert (tmp_path / "c.csv").exists()
    result = runner.invoke(app, ["classify", str(small), "--classifier", "knn", "--no-progress",
                                 "-o", str(tmp_path / "k")])
    assert result.exit_code == 2 and "unknown classifier 'knn'" in result.output
    assert not (tmp_path / "k.csv").exists()


def test_classify_command_hands_the_time_control_to_the_library(small, tmp_path, monkeypatch):
    seen = []

    def table(path, **kwargs):
        seen.append(kwargs["matched"])
        return pd.DataFrame({("lr", "mean"): [0.5]}, index=pd.Index(["control"], name="preprocessing"))

    monkeypatch.setattr(benchmark, "classification_table", table)
    for flag, out in (["--matched-days"], "m"), ([], "u"):
        result = runner.invoke(app, ["classify", str(small), *flag, "--no-progress", "-o", str(tmp_path / out)])
        assert result.exit_code == 0, result.output
    assert seen == [True, False]
    assert "--matched-days" in runner.invoke(app, ["classify", "--help"]).output


def test_the_thesis_window_keeps_t13_to_t3_labelled_by_the_robot(small, monkeypatch):
    from analysis import classify
    from analysis.benchmark import classification_features
    from faultgen.data import dataset

    # one unworn run: held out, it leaves no healthy robot to train on
    with pytest.raises(ValueError, match=r"has 11 failed samples \(worn runs' last 11 before the horizon\) and 0 normal"):
        benchmark.classification_table(small, progress=False, horizon=3)
    seen = []
    monkeypatch.setattr(classify, "evaluate", lambda X, y, groups, *a, estimated=None, **kw: seen.append((X, y, groups))
                        or pd.DataFrame())
    monkeypatch.setattr(classification_features, "_check_training_sets", lambda *args: None)
    benchmark.classification_table(small, progress=False)
    benchmark.classification_table(small, progress=False, horizon=3)
    (X, _, groups), (Xw, yw, groups_w) = seen
    for run_id in dataset.list_runs(small):  # 40 cycles: the 27th to the 37th (T-13 .. T-3 of T = 40)
        np.testing.assert_array_equal(Xw[groups_w == run_id], X[groups == run_id][26:37])
        worn = "nowear" not in run_id
        assert (yw[groups_w == run_id] == int(worn)).all() and (groups_w == run_id).sum() == 11
    with pytest.raises(ValueError, match="has 40 samples; horizon 30 needs at least 41"):
        benchmark.classification_table(small, progress=False, horizon=30)
    with pytest.raises(ValueError, match="horizon = -1: expected an integer >= 0"):
        benchmark.classification_table(small, progress=False, horizon=-1)


class NeverDecides(BaseEstimator):
    """An isolator that names no axis, ever (issue 40: it scored 100 % on "no fault" unexplained)."""

    def fit(self, X, y=None):
        self.source_axis_ = 0
        return self


def test_an_isolator_that_never_decides_is_shown_undecided_not_just_right_on_healthy_runs(small):
    isolators = {"never": NeverDecides(), "trend": isolation.make("trend")}
    table = benchmark.isolation_table(small, isolators, levels=(20.0,), progress=False)
    assert set(table.loc[table["isolator"] == "never", "answer"]) == {"undecided"}
    accuracy, decided = benchmark.isolation_accuracy(table), benchmark.isolation_decided(table)
    assert accuracy.loc[("pick_place", 0.0), "never"] == 100.0  # right on the healthy run, by never deciding
    assert decided.loc[("pick_place", 0.0), "never"] == 0.0 and decided.loc[("pick_place", 20.0), "never"] == 0.0
    assert decided.loc[("pick_place", 20.0), "trend"] == 100.0
    assert "never decides scores 100 % on \"no fault\"" in benchmark.isolation_markdown(table, marked="trend")
