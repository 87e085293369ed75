"""analysis.benchmark and the bench-isolators / detect / classify commands on a small real dataset."""

import h5py
import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from analysis import benchmark, isolation
from faultgen import sweep
from faultgen.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """Pick and place, no wear and axes 1 and 5 worn (exp4, +20 % over 40 cycles), all recorded."""
    grid = sweep.Grid(robots=["irb6700"], tasks=["pick_place"], axes=[0, 1, 5], cycles=40)
    return sweep.run(grid, tmp_path_factory.mktemp("analysis") / "small.h5", jobs=1, progress=False)


def test_level_cycle_is_the_first_cycle_reaching_the_wear():
    multiplier = np.array([1.0, 1.004, 1.01, 1.05, 1.2])
    assert benchmark.level_cycle(multiplier, 1.0) == 2
    assert benchmark.level_cycle(multiplier, 5.0) == 3
    assert benchmark.level_cycle(multiplier, 25.0) is None


def test_isolation_table_runs_every_isolator_at_every_level(small):
    isolators = {"te5": isolation.make("transfer_entropy", bins=5), "trend": isolation.make("trend")}
    table = benchmark.isolation_table(small, isolators, levels=(5.0, 20.0), progress=False)
    assert set(table["isolator"]) == {"te5", "trend"}
    assert sorted(set(table["worn_axis"])) == [1, 5]
    # at 20 % every recorded cycle is used; at 5 % fewer
    full = table[table["wear_pct"] == 20.0]["cycles"]
    assert set(full) == {40} and table[table["wear_pct"] == 5.0]["cycles"].max() < 40
    assert (table["correct"] == (table["predicted"] == table["worn_axis"])).all()
    # the trend of the worn axis's torque gives it away at full wear
    assert table[(table["isolator"] == "trend") & (table["wear_pct"] == 20.0)]["correct"].all()
    accuracy = benchmark.isolation_accuracy(table)
    assert list(accuracy.columns) == ["te5", "trend"]
    text = benchmark.isolation_markdown(table, marked="trend")
    assert "| pick_place | 20 | ✓ | - | - | - | ✓ | - |" in text


def test_detection_flags_worn_runs_against_the_unworn_one(small):
    table = benchmark.detection_table(small, progress=False)
    assert sorted(table["worn_axis"]) == [1, 5]
    assert set(table.columns) >= {"detected", "onset", "onset_wear_pct", "located_axis", "located"}
    detected = table[table["detected"]]
    assert (detected["onset_wear_pct"] <= 20.0).all()


def test_bench_isolators_command_writes_csv_markdown_and_heatmap(small, tmp_path):
    stem = tmp_path / "iso"
    result = runner.invoke(app, ["bench-isolators", str(small), "--bins", "5", "--levels", "5,20", "--no-progress",
                                 "-o", str(stem)])
    assert result.exit_code == 0, result.output
    table = pd.read_csv(stem.with_suffix(".csv"))
    assert {"te5", "cross_correlation", "granger", "trend"} <= set(table["isolator"])
    assert "accuracy te5" in stem.with_suffix(".md").read_text()
    assert stem.with_suffix(".png").stat().st_size > 10_000


def test_bins_below_two_are_refused(small, tmp_path):
    result = runner.invoke(app, ["bench-isolators", str(small), "--bins", "1", "--no-progress", "-o", str(tmp_path / "x")])
    assert result.exit_code == 2
    assert "bins = 1" in result.output


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
