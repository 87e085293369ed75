"""`faultgen classify`'s evaluation does the work its protocol needs and no more (issue 89): model fits
per cell, PCA fits and stateless steps per held-out pair, tasks and the bytes each ships, counted by
benchmarks/bench_classify.py's `counted_work` at a tiny size (counts, not times)."""

import importlib.util
import warnings
from pathlib import Path

import numpy as np
import pytest

from analysis.classify import evaluation

ROWS = ["control", "+estM+diff+var3+pca"]


def _bench():
    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_classify.py"
    spec = importlib.util.spec_from_file_location("bench_classify", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def seeds3(shared_sweep):
    """9 runs (3 seeds; no wear, axis 2 or 5 worn by 20 %), 6 cycles each, no signals."""
    return shared_sweep("verdict-seeds", robots=["irb6700"], tasks=["pick_place"], axes=[0, 2, 5], cycles=6,
                        seeds=[0, 1, 2], signals=False)


def _counted(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return _bench().counted_work(path, n_pairs=1, chance=True, preprocessing=ROWS)


def test_fits_tasks_and_bytes_are_what_the_protocol_needs(seeds3):
    found = _counted(seeds3)
    table = found["table"]
    assert list(table.index) == ROWS and table.attrs["chance_source"] == "lr"
    assert set(found["fits"]) == {"lr", "svm", "rf", "stacking", "pca", "sequence", "scale", "tasks"}
    # 1 pair: each classifier once on the true labels, lr also on each of the 19 exchanged sets
    assert found["needed"]["svm"] == found["needed"]["rf"] == found["needed"]["stacking"] == 1
    assert 1 < found["needed"]["lr"] <= 20
    assert found["fits"] == found["needed"]
    # the classifiers' scaling once per row and held-out pair (lr's 20 label sets, svm and stacking
    # share it), and +pca's own: 1.5 per row and pair on these two rows
    assert found["needed"]["scale"] == 1.5 * found["needed"]["pca"]
    # one task per held-out pair of runs: 6 worn x 3 unworn runs make 18 pairs, fewer than the 20 label sets
    assert found["needed"]["tasks"] <= 18
    assert 0 < found["bytes"] <= found["bytes_needed"]
    assert np.isfinite(table.loc["control", ("lr", "p")])


def test_a_task_per_label_set_and_pair_shipping_more_is_caught(seeds3, monkeypatch):
    """As before issue 89: one task per (label set, pair), the preprocessing fitted again for every
    label set that holds out the same runs, and each task shipping a second copy of the features (the
    old tasks shipped them twice, with the estimated block): the counts say more than the protocol needs."""
    tasks, cells = evaluation._tasks, evaluation.pair_cells
    monkeypatch.setattr(evaluation, "pair_cells", lambda *args: cells(*args[:-1]))
    monkeypatch.setattr(evaluation, "_tasks", lambda X, *args: [([j], (*task[:4], [task[4][i]], *task[5:], X.copy()))
                                                                for members, task in tasks(X, *args)
                                                                for i, j in enumerate(members)])
    found = _counted(seeds3)
    assert found["fits"]["tasks"] > found["needed"]["tasks"]
    assert found["fits"]["pca"] > found["needed"]["pca"] and found["fits"]["sequence"] > found["needed"]["sequence"]
    assert found["fits"]["scale"] > found["needed"]["scale"]
    assert all(found["fits"][c] == found["needed"][c] for c in ("lr", "svm", "rf", "stacking"))
    assert found["bytes"] > found["bytes_needed"]


def test_one_clone_of_the_classifier_per_fit_through_the_harness(monkeypatch):
    """A cell's classifier is cloned once per fit: the harness's clone of the ``ByRun`` wrapper shares
    its unfitted estimator (``ByRun.__sklearn_clone__``), which ``ByRun.fit`` clones (before: deep
    clones by both, two per fit); the estimator given is never fitted."""
    from sklearn.base import clone
    from sklearn.linear_model import LogisticRegression

    from analysis.classify import ByRun
    from analysis.classify.leave_pair_out import _scores
    from analysis.evaluate import Data

    made = []
    original = LogisticRegression.__sklearn_clone__
    monkeypatch.setattr(LogisticRegression, "__sklearn_clone__", lambda self: made.append(1) or original(self))
    rng = np.random.default_rng(0)
    X, y = rng.normal(size=(40, 3)), np.r_[np.zeros(20, dtype=int), np.ones(20, dtype=int)]
    model = LogisticRegression()
    scores = _scores(model, Data(X, np.repeat(np.arange(8), 5), y), np.arange(30), np.arange(30, 40), "lr")
    assert len(made) == 1 and scores.shape == (10,) and not hasattr(model, "coef_")
    wrapper = ByRun(model)
    assert clone(wrapper).estimator is model and clone(wrapper) is not wrapper


def test_a_named_classifier_is_made_anew_per_fit_not_cloned(monkeypatch):
    """``pair_cells`` makes each fit of a named classifier anew (``ByRun(..., make)``): no scikit-learn
    clone of it per fit (before: one, whose ``get_params`` reads the signature every time), one fit per
    label set, and the same AUC, bit for bit, as the cell's whole pipeline cloned and fitted
    (:func:`_pair_auc`, scikit-learn's own clone)."""
    from sklearn.linear_model import LogisticRegression

    from analysis.classify.leave_pair_out import _pair_auc, folds, pair_cells
    from analysis.classify.preprocessing import make_pipeline

    rng = np.random.default_rng(3)
    groups = np.repeat(np.arange(8), 6)
    labels = np.where((groups < 4) & (np.tile(np.arange(6), 8) >= 3), 1, 0)
    X = rng.normal(size=(48, 3)) + labels[:, None]
    swapped = np.where((groups >= 4) & (np.tile(np.arange(6), 8) >= 3), 1, 0)  # the runs' roles exchanged
    fold = folds([0], [4], groups)[0]
    made, fitted = [], []
    original_clone, original_fit = LogisticRegression.__sklearn_clone__, LogisticRegression.fit
    monkeypatch.setattr(LogisticRegression, "__sklearn_clone__", lambda self: made.append(1) or original_clone(self))
    monkeypatch.setattr(LogisticRegression, "fit", lambda self, *a, **k: fitted.append(1) or original_fit(self, *a, **k))
    sets = [(labels, (0, 4), ["lr"]), (swapped, (4, 0), ["lr"])]
    found = pair_cells(X, None, groups, (0, 4), sets, ["control", "+diff"], {"lr": "lr"}, 0, False)
    assert made == [] and len(fitted) == 4 and found.shape == (2, 2)
    for c, name in enumerate(["control", "+diff"]):
        expected = _pair_auc(lambda name=name: make_pipeline("lr", name), X, labels, groups, fold)
        assert found[0, c] == expected and len(made) == c + 1  # the reference does clone
    assert np.isfinite(found).all()


def test_the_repeated_timing_is_judged_on_the_medians_of_its_pairs():
    """bench_classify.py --repeat: one pair's ratio is the minute's, so the target is judged on the
    medians (wall 0.95, CPU 0.98 here: met, though one pair alone was 1.3x)."""
    verdict = _bench().repeated_verdict([(0.9, 0.95), (1.3, 1.2), (0.95, 0.98)])
    assert "wall 0.95 (median; 0.90-1.30), CPU 0.98 (0.95-1.20)" in verdict
    assert "target <= 1.0x on the medians: met (0.98x at worst); met by 2 of 3 pairs alone" in verdict
    assert "NOT MET (1.02x at worst); met by 1 of 2" in _bench().repeated_verdict([(1.05, 0.9), (1.0, 0.95)])
