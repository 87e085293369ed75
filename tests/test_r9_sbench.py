"""Issue 74 (the suite's time), round 9, the bench, sweep and cluster tests: the two library paths
made faster. The bench scorer's ROC curves (faultgen.bench.score._roc, the path every bootstrap
resample of `faultgen bench score` takes) against scikit-learn's, which they replace there, bit for
bit; and a sweep run's garbage collection (faultgen.runs.worker.run_memory)."""

from __future__ import annotations

import numpy as np
import pytest
from sklearn.metrics import auc, roc_auc_score, roc_curve

from faultgen.bench import score


def _cases():
    """Labels and scores as the scorer gets them: bool or 0/1 labels, float, float32, integer (alarms)
    and bool scores, with and without ties, one record of a class or many."""
    rng = np.random.default_rng(74)
    for k in range(60):
        n = int(rng.integers(2, 300))
        labels = rng.random(n) < rng.uniform(0.05, 0.95)
        labels[rng.integers(n)], labels[rng.integers(n)] = True, False  # both classes
        if labels.all() or not labels.any():
            labels[0], labels[-1] = True, False
        kind = k % 5
        if kind == 0:
            scores = rng.normal(size=n) + labels
        elif kind == 1:
            scores = np.round(rng.normal(size=n) + labels, 1)  # many ties
        elif kind == 2:
            scores = (rng.normal(size=n) + labels).astype(np.float32)
        elif kind == 3:
            scores = rng.integers(0, 3, size=n)  # alarms as scores
        else:
            scores = rng.random(n) < 0.5
        yield (labels if k % 2 else labels.astype(float)), scores


@pytest.mark.parametrize("drop_intermediate", [True, False])
def test_the_scorers_roc_curve_is_sklearns_bit_for_bit(drop_intermediate):
    for labels, scores in _cases():
        fpr, tpr, _ = roc_curve(labels, scores, drop_intermediate=drop_intermediate)
        got = score._roc(labels, scores, drop_intermediate=drop_intermediate)
        assert got[0].tobytes() == fpr.tobytes() and got[1].tobytes() == tpr.tobytes()
        if drop_intermediate:  # the area the scorer's AUROC takes: sklearn's, to the last bit
            expected = roc_auc_score(labels, scores)
            assert float(score.trapezoid(got[1], got[0])) == expected == auc(fpr, tpr)


def test_the_scorers_auroc_of_units_is_sklearns_and_a_non_finite_score_is_named():
    rng = np.random.default_rng(5)
    units = [{"scores": rng.normal(size=12) + k % 2, "positive": np.full(12, k % 2 == 1),
              "mask": rng.random(12) < 0.8} for k in range(6)]
    labels = np.concatenate([u["positive"][u["mask"]] for u in units])
    scores = np.concatenate([u["scores"][u["mask"]] for u in units])
    assert score._auroc(units) == roc_auc_score(labels, scores)
    assert np.isnan(score._auroc(units[1::2]))  # one class only
    units[0]["scores"][units[0]["mask"].argmax()] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        score._auroc(units)


def test_a_runs_cyclic_garbage_is_collected_at_its_end_and_nothing_stays_frozen():
    """faultgen.runs.worker.run_memory, around every run of a sweep: what was alive before the run is
    frozen during it (left out of the run's collection), the run's own cyclic garbage is collected when
    it ends, and everything is thawed after it, also when the run fails."""
    import gc
    import weakref

    from faultgen.runs import worker

    class Node:
        pass

    freed = []
    old = Node()
    old.cycle = old
    weakref.finalize(old, freed.append, "old")
    assert gc.get_freeze_count() == 0
    with worker.run_memory():
        assert gc.get_freeze_count() > 0 and gc.is_tracked(old)
        made = Node()
        made.cycle = made
        weakref.finalize(made, freed.append, "made")
        del made, old  # both now cyclic garbage: the run's own, and one from before the run
    assert freed == ["made"] and gc.get_freeze_count() == 0
    gc.collect()  # thawed: the older garbage goes at the next full collection
    assert freed == ["made", "old"]
    with pytest.raises(RuntimeError), worker.run_memory():
        raise RuntimeError("a run that failed")
    assert gc.get_freeze_count() == 0
