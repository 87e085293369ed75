"""`classify` judges every result against chance: each row's chance level, a permutation p-value,
an explicit above_chance column and a one-line verdict (issue 51, item 2)."""

import shutil

import h5py
import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from analysis import benchmark
from faultgen.cli import app

runner = CliRunner()
ROWS = ["control", "+var3"]


@pytest.fixture(scope="module")
def seeds3(shared_sweep):
    """j2-like on a small scale: pick and place, no wear and axes 2 and 5 worn by 20 % (exp4), three
    seeds (units), 6 cycles all recorded, no signals: 9 runs, 3 of them without wear."""
    return shared_sweep("verdict-seeds", robots=["irb6700"], tasks=["pick_place"], axes=[0, 2, 5], cycles=6,
                        seeds=[0, 1, 2], signals=False)


@pytest.fixture(scope="module")
def shuffled(seeds3, tmp_path_factory):
    """The same runs with their labels (worn axes, wear schedule, friction multiplier) exchanged
    between runs at random: a run's features no longer go with its wear."""
    path = tmp_path_factory.mktemp("shuffled") / "shuffled.h5"
    shutil.copy(seeds3, path)
    with h5py.File(path, "a") as f:
        ids = list(f["runs"])
        order = np.random.default_rng(1).permutation(len(ids))
        assert (order != np.arange(len(ids))).sum() >= len(ids) - 1
        saved = [(f["runs"][i]["friction_multiplier"][()], dict(f["runs"][i].attrs)) for i in ids]
        for run_id, k in zip(ids, order, strict=True):
            group = f["runs"][run_id]
            group["friction_multiplier"][...] = saved[k][0]
            for key in ("worn_axes", "wear"):
                group.attrs[key] = saved[k][1][key]
    return path


def _table(path):
    return benchmark.classification_table(path, classifiers=["lr"], preprocessing=ROWS, n_pairs=None,
                                          progress=False, chance=True, n_jobs=1)


def test_rows_on_j2_like_data_are_above_chance(seeds3):
    table = _table(seeds3)
    assert table.attrs["pairs"] == 6 * 3 and table.attrs["permutations"] == benchmark.CHANCE_PERMUTATIONS == 19
    for row in ROWS:
        assert table.loc[row, ("lr", "p")] <= 0.05 and table.loc[row, ("lr", "above")] is True
        assert 0.5 < table.loc[row, ("lr", "null")] < table.loc[row, ("lr", "mean")]
    verdict = benchmark.classification_verdict(table, "faultgen classify x.h5")
    assert verdict.startswith("verdict: 2 of 2 judged cells above chance at the 5 % level")


def test_with_the_labels_shuffled_no_row_is_above_chance_and_the_verdict_says_so(shuffled):
    table = _table(shuffled)
    assert not table[("lr", "above")].astype(bool).any()
    assert (table[("lr", "p")] > 0.05).all()
    assert (table[("lr", "mean")] > 0.9).all()  # the AUCs look high: only the chance level shows they are not
    verdict = benchmark.classification_verdict(table, "faultgen classify x.h5")
    assert verdict.startswith("verdict: no judged cell is above chance at the 5 % level")
    assert "more worn and unworn runs" in verdict and "seeds" in verdict and "cycles" in verdict
    printed = benchmark.classification_printed(table)
    assert list(printed[("above_chance", "")]) == ["none", "none"]


def test_classify_prints_and_writes_above_chance_per_row_and_a_verdict(seeds3, tmp_path):
    stem = tmp_path / "c"
    result = runner.invoke(app, ["classify", str(seeds3), "--classifier", "lr", "--classifier", "svm",
                                 "--preprocessing", "control", "--pairs", "20", "--jobs", "1", "--no-progress",
                                 "-o", str(stem)])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "| chance | above_chance |" in text and "verdict: 1 of 1 judged cells above chance" in text
    assert "svm not judged" in text
    assert "over 18 held-out (worn, unworn) run pair(s)" in text  # what exists, not the 20 asked for
    tidy = pd.read_csv(stem.with_suffix(".csv"))
    assert {"auc_null", "p", "above_chance"} <= set(tidy.columns)
    cells = tidy.set_index("classifier")
    assert bool(cells.loc["lr", "above_chance"]) and pd.isna(cells.loc["svm", "above_chance"])
    assert "verdict:" in stem.with_suffix(".md").read_text()


def test_too_few_permutations_cannot_be_above_chance_and_say_so():
    table = pd.DataFrame({("lr", "mean"): [0.99], ("lr", "std"): [0.01]}, index=pd.Index(["control"], name="preprocessing"))
    table.columns = pd.MultiIndex.from_tuples(table.columns, names=["classifier", "statistic"])
    judged = benchmark.with_verdict(table, {"lr control": np.array([0.5] * 5)})
    assert judged.loc["control", ("lr", "p")] == pytest.approx(1 / 6) and judged.loc["control", ("lr", "above")] is False
    assert "with 5 label exchanges p cannot go below 0.17" in benchmark.classification_verdict(judged)
