"""Classifiers, preprocessing combinations and Procedures 1 and 2 of thesis ch. 5 (analysis.classify)."""

from __future__ import annotations

from typing import ClassVar

import numpy as np
import pandas as pd
import pingouin as pg
import pytest
from scipy import stats
from sklearn.base import BaseEstimator, ClassifierMixin, clone
from sklearn.pipeline import Pipeline

from analysis import classify
from analysis.features import Difference, WindowConcat


def runs(n_failed=4, n_normal=4, n_cycles=30, n_features=4, drift=0.15, noise_labels=False, seed=0):
    """Synthetic runs: rows are cycles in time order; failed runs drift in feature 0.

    Each run has its own offset per feature (task variability). A failed run's feature 0 grows
    by ``drift`` per cycle and its cycles from the middle on are labelled 1. With
    ``noise_labels`` the features are the same white noise in every run (no drift, no offsets:
    an offset would let whichever run of a held-out pair looks more "failed" swing its AUC) and
    the failed runs' labels are coin flips.
    """
    rng = np.random.default_rng(seed)
    failed = [f"worn{i}" for i in range(n_failed)]
    normal = [f"nowear{i}" for i in range(n_normal)]
    X, y, groups = [], [], []
    t = np.arange(n_cycles)
    for run in failed + normal:
        offset = 0.0 if noise_labels else rng.normal(0, 0.5, n_features)
        x = offset + rng.normal(0, 0.3, (n_cycles, n_features))
        labels = np.zeros(n_cycles, dtype=int)
        if run in failed:
            if noise_labels:
                labels = rng.integers(0, 2, n_cycles)
            else:
                x[:, 0] += drift * t
                labels = (t >= n_cycles // 2).astype(int)
        X.append(x)
        y.append(labels)
        groups.append(np.full(n_cycles, run, dtype=object))
    return np.vstack(X), np.concatenate(y), np.concatenate(groups), failed, normal


# ---------------------------------------------------------------------------- Procedure 1


def test_drifting_failed_runs_give_high_auc_for_lr():
    X, y, groups, failed, normal = runs()
    aucs = classify.leave_pair_out_auc(lambda: classify.make_pipeline("lr"), X, y, groups, failed, normal)
    assert aucs.shape == (len(failed) * len(normal),)
    assert np.all(aucs > 0.9), aucs
    assert aucs.mean() > 0.95


def test_noise_labels_give_chance_auc():
    X, y, groups, failed, normal = runs(n_failed=5, n_normal=5, noise_labels=True, seed=1)
    aucs = classify.leave_pair_out_auc(lambda: classify.make_pipeline("lr"), X, y, groups, failed, normal)
    assert aucs.shape == (25,)
    assert not np.isnan(aucs).any()
    assert abs(aucs.mean() - 0.5) < 0.15, aucs.mean()


class Spy(ClassifierMixin, BaseEstimator):
    """Records which runs (column 0 holds a run's code) it is fitted on and scores."""

    log: ClassVar[list] = []

    def fit(self, X, y):
        self.classes_ = np.unique(y)
        Spy.log.append(("fit", frozenset(X[:, 0].astype(int).tolist())))
        return self

    def predict_proba(self, X):
        Spy.log.append(("score", frozenset(X[:, 0].astype(int).tolist())))
        p = 1 / (1 + np.exp(-X[:, 1]))
        return np.column_stack([1 - p, p])


def test_every_auc_comes_from_a_model_that_never_saw_its_pair():
    X, y, groups, failed, normal = runs(n_failed=3, n_normal=4)
    extra = ["spare"]  # in neither list: always trained on
    codes = {g: i for i, g in enumerate(failed + normal + extra)}
    X = np.vstack([X, np.random.default_rng(2).normal(size=(10, X.shape[1]))])
    y = np.concatenate([y, np.zeros(10, dtype=int)])
    groups = np.concatenate([groups, np.full(10, "spare", dtype=object)])
    X[:, 0] = [codes[g] for g in groups]
    Spy.log = []
    aucs, pairs = classify.leave_pair_out_auc(lambda: Pipeline([("spy", Spy())]), X, y, groups, failed,
                                              normal, return_pairs=True)
    assert pairs == [(f, n) for f in failed for n in normal]  # Procedure 1's loops
    assert len(Spy.log) == 2 * len(pairs) and not np.isnan(aucs).any()
    everything = set(codes.values())
    for k, (f, n) in enumerate(pairs):
        (fit, seen), (score, scored) = Spy.log[2 * k], Spy.log[2 * k + 1]
        held_out = {codes[f], codes[n]}
        assert (fit, score) == ("fit", "score")
        assert seen == everything - held_out
        assert scored == held_out


def test_parallel_pairs_give_the_same_aucs():
    X, y, groups, failed, normal = runs(n_failed=2, n_normal=2)
    factory = lambda: classify.make_pipeline("svm", "+diff+var3")
    serial = classify.leave_pair_out_auc(factory, X, y, groups, failed, normal)
    parallel = classify.leave_pair_out_auc(factory, X, y, groups, failed, normal, n_jobs=2)
    np.testing.assert_array_equal(serial, parallel)


def test_random_subset_of_pairs_is_seeded():
    failed, normal = list("abcde"), list("vwxyz")
    first = classify.select_pairs(failed, normal, n_pairs=7, random_state=3)
    assert first == classify.select_pairs(failed, normal, n_pairs=7, random_state=3)
    assert first != classify.select_pairs(failed, normal, n_pairs=7, random_state=4)
    assert len(set(first)) == 7 and set(first) <= set(classify.select_pairs(failed, normal))
    assert classify.select_pairs(failed, normal, n_pairs=100) == classify.select_pairs(failed, normal)


def test_pair_with_one_class_gives_nan_and_a_warning():
    X, y, groups, failed, normal = runs(n_failed=3, n_normal=2)
    y[groups == "worn0"] = 0  # this failed run never reaches the threshold
    with pytest.warns(classify.UndefinedAUCWarning, match="2 of 6"):
        aucs, pairs = classify.leave_pair_out_auc(lambda: classify.make_pipeline("lr"), X, y, groups, failed,
                                                  normal, return_pairs=True)
    undefined = [p for p, a in zip(pairs, aucs) if np.isnan(a)]
    assert undefined == [("worn0", "nowear0"), ("worn0", "nowear1")]


def test_sequence_steps_are_applied_run_by_run():
    X, y, groups, _, _ = runs(n_failed=2, n_normal=2, n_cycles=8)
    pipe = classify.make_pipeline("lr", "+diff+var3")
    classify.fit_by_run(pipe, X, y, groups)
    scores = classify.score_by_run(pipe, X, groups)
    expected = np.vstack([WindowConcat(3).fit_transform(Difference().fit_transform(X[groups == g]))
                          for g in pd.unique(groups)])
    lr = pipe.named_steps["lr"]
    scale = pipe.named_steps["scale"]
    np.testing.assert_allclose(scores, lr.predict_proba(scale.transform(expected))[:, 1])
    # the first row of every run has no predecessor: all zeros after +diff
    starts = np.flatnonzero(np.r_[True, groups[1:] != groups[:-1]])
    assert np.all(expected[starts] == 0)


def test_labelling_rules():
    groups = np.array(["w"] * 4 + ["n"] * 3, dtype=object)
    wear = np.array([0, 5, 10, 20, 0, 0, 0], dtype=float)
    np.testing.assert_array_equal(classify.make_labels(wear, groups, ["w"], label_rule=10.0),
                                  [0, 0, 1, 1, 0, 0, 0])
    last3 = classify.make_labels(wear, groups, ["w"], label_rule=classify.last_samples(3))
    np.testing.assert_array_equal(last3, [0, 1, 1, 1, 0, 0, 0])
    np.testing.assert_array_equal(classify.make_labels(wear > 7, groups, ["w"]), [0, 0, 1, 1, 0, 0, 0])
    with pytest.raises(ValueError, match="not 0 or 1"):
        classify.make_labels(wear, groups, ["w"])
    with pytest.raises(ValueError, match="run 'n' is not a failed run"):
        classify.make_labels(np.r_[0, 0, 1, 1, 1, 0, 0], groups, ["w"])


def test_threshold_rule_matches_precomputed_labels():
    X, y, groups, failed, normal = runs(n_failed=2, n_normal=2)
    wear = np.where(np.isin(groups, failed), np.tile(np.arange(30.0), 4), 0.0)
    by_rule = classify.leave_pair_out_auc(lambda: classify.make_pipeline("lr"), X, wear, groups, failed,
                                          normal, label_rule=15.0)
    given = classify.leave_pair_out_auc(lambda: classify.make_pipeline("lr"), X, y, groups, failed, normal)
    np.testing.assert_array_equal(by_rule, given)


def test_bad_inputs_are_named():
    X, y, groups, failed, normal = runs(n_failed=2, n_normal=2, n_cycles=5)
    factory = lambda: classify.make_pipeline("lr")
    with pytest.raises(ValueError, match="run 'ghost' has no samples"):
        classify.leave_pair_out_auc(factory, X, y, groups, failed + ["ghost"], normal)
    with pytest.raises(ValueError, match="run 'worn0' is both failed and normal"):
        classify.leave_pair_out_auc(factory, X, y, groups, failed, normal + ["worn0"])
    with pytest.raises(ValueError, match=r"y must have shape \(20,\)"):
        classify.leave_pair_out_auc(factory, X, y[:-1], groups, failed, normal)


# ---------------------------------------------------------------------------- chance level


def test_permuted_roles_exchange_whole_label_sequences_between_runs_of_equal_length():
    _, y, groups, failed, normal = runs(n_failed=3, n_normal=3, n_cycles=12)
    y = y.copy()
    y[groups == "worn1"] = (np.arange(12) >= 9).astype(int)  # one failed run with its own sequence
    groups = np.concatenate([groups, np.full(5, "short", dtype=object)])  # alone in its length: stays put
    y = np.concatenate([y, np.zeros(5, dtype=int)])
    normal = [*normal, "short"]
    roles = classify.permuted_roles(y, groups, failed, normal, 50, random_state=1)
    assert len(roles) == 50
    sequences = {g: y[groups == g] for g in failed + normal}
    worn1_went_elsewhere = False
    for labels, f, n in roles:
        assert len(f) == len(failed) and sorted(f + n) == sorted(failed + normal)
        for g in f + n:  # each run carries one donor's whole sequence, failed ones from failed runs
            assert any(np.array_equal(labels[groups == g], sequences[d]) for d in (failed if g in f else normal)), \
                (g, labels[groups == g])
        assert "short" in n and np.array_equal(labels[groups == "short"], sequences["short"])
        assert sum(np.array_equal(labels[groups == g], sequences["worn1"]) for g in f) == 1
        worn1_went_elsewhere |= not np.array_equal(labels[groups == "worn1"], sequences["worn1"])
        assert classify.make_labels(labels, groups, f).sum() == y.sum()
    assert worn1_went_elsewhere
    assert sum(set(f) != set(failed) for _, f, _ in roles) > 40  # the roles really move
    again = classify.permuted_roles(y, groups, failed, normal, 50, random_state=1)
    for (a, fa, na), (b, fb, nb) in zip(roles, again, strict=True):  # seeded: the same sets again
        assert np.array_equal(a, b) and fa == fb and na == nb
    with pytest.raises(ValueError, match="n_permutations = 0; expected an integer >= 1"):
        classify.permuted_roles(y, groups, failed, normal, 0)


def test_null_p_value_counts_the_observation_and_nan_as_reaching_it():
    assert classify.null_p_value(0.7, np.array([0.5, 0.7, 0.8, np.nan])) == pytest.approx(4 / 5)
    assert classify.null_p_value(0.9, np.array([0.5, 0.6, 0.4])) == pytest.approx(1 / 4)


def test_evaluate_reports_the_chance_level_of_each_cell():
    X, y, groups, failed, normal = runs(n_failed=5, n_normal=5, n_cycles=16)
    table, aucs = classify.evaluate(X, y, groups, failed, normal, classifiers=["lr"], preprocessing=["control", "+diff"],
                                    n_pairs=6, permutations=9, return_aucs=True)
    assert list(table.columns) == [("lr", s) for s in ("mean", "std", "null", "p")]
    for name in table.index:  # by hand: the same label sets for every cell, Procedure 1 on each
        null = [np.nanmean(classify.leave_pair_out_auc(classify.make_pipeline("lr", name), X, labels, groups, f, n,
                                                      n_pairs=6, random_state=0))
                for labels, f, n in classify.permuted_roles(y, groups, failed, normal, 9, random_state=0)]
        assert table.loc[name, ("lr", "null")] == pytest.approx(np.mean(null))
        assert table.loc[name, ("lr", "p")] == pytest.approx(classify.null_p_value(aucs["lr", name].mean(), null))
    # the drift of the failed runs is found; with the roles exchanged half the "failed" runs do not drift
    assert table.loc["control", ("lr", "mean")] > 0.95
    assert table.loc["control", ("lr", "null")] < 0.8
    assert table.loc["control", ("lr", "p")] == pytest.approx(0.1)  # no exchange reaches it: 1 / (1 + 9)
    without = classify.evaluate(X, y, groups, failed, normal, classifiers=["lr"], preprocessing=["control"], n_pairs=6)
    assert list(without.columns) == [("lr", "mean"), ("lr", "std")]
    assert without.loc["control", ("lr", "mean")] == table.loc["control", ("lr", "mean")]
    for bad in (-1, True, 2.5):
        with pytest.raises(ValueError, match=f"permutations = {bad!r}; expected an integer >= 0"):
            classify.evaluate(X, y, groups, failed, normal, classifiers=["lr"], preprocessing=["control"],
                              permutations=bad)


def test_matched_rows_pair_each_failed_sample_with_the_same_day_of_the_normal_run():
    labels = np.array([0, 0, 1, 1, 0, 0, 0])
    groups = np.array(["f"] * 4 + ["n"] * 3, dtype=object)
    # the failed run's day 3 against the normal run's day 3; its day 4 has no match and is left out
    assert classify.matched_rows(labels, groups, ("f", "n")).tolist() == [False, False, True, False, False, False, True]


def time_cue_runs(fault, n_failed=6, n_normal=6, days=40, seed=0):
    """Runs whose feature 0 follows the day of the record in every run (a season, a life-average
    indicator settling), whose failed runs' last third is labelled failed (labels by wear), and
    whose feature 1 rises by ``fault`` on those days."""
    rng = np.random.default_rng(seed)
    failed, normal = [f"worn{i}" for i in range(n_failed)], [f"nowear{i}" for i in range(n_normal)]
    t = np.arange(days)
    X, y, groups = [], [], []
    for run in failed + normal:
        labels = (t >= 2 * days // 3).astype(int) if run in failed else np.zeros(days, dtype=int)
        X.append(np.column_stack([t / days, fault * labels]) + rng.normal(0, 0.1, (days, 2)))
        y.append(labels)
        groups.append(np.full(days, run, dtype=object))
    return np.vstack(X), np.concatenate(y), np.concatenate(groups), failed, normal


@pytest.mark.parametrize("seed", [0, 1])
def test_matched_days_take_away_the_time_cue_and_keep_the_fault(seed):
    lr = lambda: classify.make_pipeline("lr")
    X, y, groups, failed, normal = time_cue_runs(fault=0.0, seed=seed)
    # no fault: late days are told from early ones (measured 0.87-0.88) ...
    assert classify.leave_pair_out_auc(lr, X, y, groups, failed, normal).mean() > 0.8
    # ... but not from the same days of a healthy run (0.47-0.49)
    assert abs(classify.leave_pair_out_auc(lr, X, y, groups, failed, normal, matched=True).mean() - 0.5) < 0.1
    X, y, groups, failed, normal = time_cue_runs(fault=0.3, seed=seed)
    assert classify.leave_pair_out_auc(lr, X, y, groups, failed, normal, matched=True).mean() > 0.9  # 0.97-0.98


def test_matched_days_change_nothing_when_every_sample_of_a_failed_run_is_failed():
    X, _, groups, failed, normal = runs(n_failed=3, n_normal=3, n_cycles=12)
    state = np.isin(groups, failed).astype(int)  # the thesis's window: labelled by the robot's state
    pipe = lambda: classify.make_pipeline("lr", "+diff")
    np.testing.assert_array_equal(classify.leave_pair_out_auc(pipe, X, state, groups, failed, normal, matched=True),
                                  classify.leave_pair_out_auc(pipe, X, state, groups, failed, normal))


# ---------------------------------------------------------------------------- Procedure 2


def samples(sds, means, n=30, seed=0):
    rng = np.random.default_rng(seed)
    return {f"p{i}": rng.normal(m, s, n) for i, (m, s) in enumerate(zip(means, sds))}


def long(aucs):
    return pd.DataFrame({"preprocessing": np.concatenate([[k] * len(v) for k, v in aucs.items()]),
                         "auc": np.concatenate(list(aucs.values()))})


def test_equal_variances_choose_anova_and_tukey():
    aucs = samples(sds=[0.05, 0.05, 0.05], means=[0.6, 0.7, 0.65])
    result = classify.compare_preprocessing(aucs)
    levene = stats.levene(*aucs.values(), center="median")
    assert result.levene_p == pytest.approx(levene.pvalue) and result.levene_p >= 0.05
    assert (result.equal_variance, result.test, result.posthoc) == (True, "anova", "tukey")
    assert result.p_value == pytest.approx(stats.f_oneway(*aucs.values()).pvalue, rel=1e-9)
    assert result.p_value == pytest.approx(pg.anova(data=long(aucs), dv="auc", between="preprocessing")
                                           ["p_unc"].iloc[0], rel=1e-12)
    assert result.significant
    pd.testing.assert_frame_equal(result.pairwise, pg.pairwise_tukey(data=long(aucs), dv="auc",
                                                                      between="preprocessing"))


def test_unequal_variances_choose_welch_and_games_howell():
    aucs = samples(sds=[0.01, 0.1, 0.3], means=[0.5, 0.8, 0.7])
    result = classify.compare_preprocessing(aucs)
    assert result.levene_p == pytest.approx(stats.levene(*aucs.values()).pvalue) and result.levene_p < 0.05
    assert (result.equal_variance, result.test, result.posthoc) == (False, "welch_anova", "games_howell")
    welch = pg.welch_anova(data=long(aucs), dv="auc", between="preprocessing")
    assert result.p_value == pytest.approx(welch["p_unc"].iloc[0], rel=1e-12)
    assert result.statistic == pytest.approx(welch["F"].iloc[0], rel=1e-12)
    assert result.significant
    pd.testing.assert_frame_equal(result.pairwise, pg.pairwise_gameshowell(data=long(aucs), dv="auc",
                                                                            between="preprocessing"))


def test_no_posthoc_without_an_effect_and_nan_dropped():
    aucs = samples(sds=[0.05, 0.05], means=[0.7, 0.7], seed=5)
    aucs["p0"] = np.r_[aucs["p0"], np.nan]
    result = classify.compare_preprocessing(aucs)
    assert not result.significant and result.pairwise.empty
    assert result.n == {"p0": 30, "p1": 30}
    with pytest.raises(ValueError, match="'p1' has 1 AUC"):
        classify.compare_preprocessing({"p0": [0.1, 0.2], "p1": [0.3, np.nan]})


# ---------------------------------------------------------------------------- pipelines, Table 5.2


def test_table_5_2_combinations_are_all_there():
    assert set(classify.TABLE_5_2) <= set(classify.PREPROCESSING) and len(classify.TABLE_5_2) == 15
    names = lambda p: [n for n, _ in classify.preprocessing_steps(p)]
    assert names("control") == [] and names("+estM") == []
    assert names("+estM+diff+var3+pca") == ["diff", "var3", "pca_scale", "pca"]
    assert names("+diff+pca+var3") == ["diff", "pca_scale", "pca", "var3"]
    assert classify.preprocessing_steps("+var5")[0][1].width == 5
    bad_names = (("+fft", "unknown token '\\+fft'"), ("+diff+estM", "must come first"), ("diff", "expected"))
    for bad, match in bad_names:
        with pytest.raises(ValueError, match=match):
            classify.preprocessing_steps(bad)


@pytest.mark.parametrize("preprocessing", list(classify.PREPROCESSING))
def test_every_combination_builds_clones_and_fits(preprocessing):
    X, y, groups, _, _ = runs(n_failed=2, n_normal=1, n_cycles=12, n_features=3)
    if preprocessing.startswith(classify.ESTIMATED):
        X = np.hstack([X, np.random.default_rng(0).normal(size=(len(X), 2))])
    for name in classify.CLASSIFIERS:
        pipe = classify.make_pipeline(name, preprocessing)
        params = pipe.get_params()
        twin = clone(pipe)
        assert twin.get_params().keys() == params.keys()
        assert all(type(params[k]) is type(v) for k, v in twin.get_params().items())
        if name in ("lr", "svm"):  # rf and stacking are fitted on one combination below (time)
            classify.fit_by_run(twin, X, y, groups)
            assert classify.score_by_run(twin, X, groups).shape == (len(X),)


@pytest.mark.parametrize("name", list(classify.CLASSIFIERS))
def test_every_classifier_fits_the_fullest_combination(name):
    X, y, groups, _, _ = runs(n_failed=2, n_normal=1, n_cycles=15, n_features=3)
    pipe = classify.make_pipeline(name, "+diff+var5+pca", random_state=1)
    classify.fit_by_run(pipe, X, y, groups)
    scores = classify.score_by_run(pipe, X, groups)
    assert scores.shape == (len(X),) and np.isfinite(scores).all()
    assert pipe.named_steps["pca"].n_components_ <= 15  # 5 lags of 3 features


def test_classifiers_are_what_the_thesis_uses():
    from sklearn.ensemble import RandomForestClassifier, StackingClassifier
    from sklearn.linear_model import LogisticRegression
    from sklearn.svm import SVC

    assert isinstance(classify.make_pipeline("lr")[-1], LogisticRegression)
    assert classify.make_pipeline("svm")[-1].kernel == "rbf"
    assert classify.make_pipeline("rf", random_state=7)[-1].random_state == 7
    stack = classify.make_pipeline("stacking")[-1]
    assert isinstance(stack, StackingClassifier)
    assert [type(e) for _, e in stack.estimators] == [LogisticRegression, SVC]
    assert isinstance(stack.final_estimator, LogisticRegression)
    assert isinstance(classify.make_pipeline("rf")[-1], RandomForestClassifier)
    with pytest.raises(ValueError, match="unknown classifier 'knn'"):
        classify.make_pipeline("knn")


def test_evaluate_gives_table_5_2_layout():
    X, y, groups, failed, normal = runs(n_failed=3, n_normal=3, n_cycles=20)
    estimated = X[:, :2] * 2.0
    table, aucs = classify.evaluate(X, y, groups, failed, normal, classifiers=["lr", "svm"],
                                    preprocessing=["control", "+diff", "+estM+var3+pca"], estimated=estimated,
                                    n_pairs=4, random_state=0, return_aucs=True)
    assert list(table.index) == ["control", "+diff", "+estM+var3+pca"] and table.index.name == "preprocessing"
    assert list(table.columns) == [("lr", "mean"), ("lr", "std"), ("svm", "mean"), ("svm", "std")]
    assert set(aucs) == {(c, p) for c in ("lr", "svm") for p in table.index}
    for (c, p), a in aucs.items():
        assert a.shape == (4,)
        assert table.loc[p, (c, "mean")] == pytest.approx(a.mean())
        assert table.loc[p, (c, "std")] == pytest.approx(a.std(ddof=1))
    assert table.loc["control", ("lr", "mean")] > 0.9
    # same pairs and model as a direct Procedure 1 call
    direct = classify.leave_pair_out_auc(classify.make_pipeline("lr", "+diff"), X, y, groups, failed, normal,
                                         n_pairs=4, random_state=0)
    np.testing.assert_array_equal(direct, aucs["lr", "+diff"])
    # without estimated quantities the +estM rows are left out, and asking for one is an error
    default = classify.evaluate(X, y, groups, failed, normal, classifiers=["lr"], n_pairs=1)
    assert not any(p.startswith("+estM") for p in default.index) and "+diff+var3+pca" in default.index
    with pytest.raises(ValueError, match="needs the estimated quantities"):
        classify.evaluate(X, y, groups, failed, normal, classifiers=["lr"], preprocessing=["+estM"],
                          n_pairs=1)


def test_evaluate_fits_each_preprocessing_once_per_pair_and_gives_the_per_cell_aucs_in_parallel(monkeypatch):
    """Issue 40: one job per held-out pair, every cell of it on a preprocessing fitted once, on two
    processes (on Linux forked from this one, issue 89): the same AUC in every cell as Procedure 1
    run cell by cell with whole pipelines."""
    from faultgen import pools

    pooled, forked_pool = [], pools.forked_pool
    monkeypatch.setattr(pools, "forked_pool", lambda n_jobs: pooled.append(n_jobs) or forked_pool(n_jobs))
    X, y, groups, failed, normal = runs(n_failed=4, n_normal=3, n_cycles=18)
    names = ["control", "+diff+pca+var3", "+diff+var3+pca"]
    _, aucs = classify.evaluate(X, y, groups, failed, normal, preprocessing=names, n_pairs=3, random_state=0,
                                n_jobs=2, return_aucs=True)
    assert pooled == ([2] if pools.FORK else [])  # elsewhere joblib's loky
    for (column, name), got in aucs.items():
        expected = classify.leave_pair_out_auc(classify.make_pipeline(column, name), X, y, groups, failed, normal,
                                               n_pairs=3, random_state=0)
        np.testing.assert_array_equal(got, expected)
    assert not np.array_equal(aucs["lr", "+diff+pca+var3"], aucs["lr", "+diff+var3+pca"])  # order is step order
    assert classify.describe_preprocessing("+diff+pca+var3").index("PCA") < \
        classify.describe_preprocessing("+diff+pca+var3").index("windows of 3")


def test_stacking_cross_validates_by_run_never_splitting_one():
    from sklearn.ensemble import StackingClassifier

    X, y, groups, failed, normal = runs(n_failed=4, n_normal=4, n_cycles=12)
    labels = classify.make_labels(y, groups, failed)
    model = classify.fit_by_run(classify.make_pipeline("stacking"), X, labels, groups)
    stack = model[-1]
    assert isinstance(stack, StackingClassifier) and len(stack.cv) == 5
    tested = np.concatenate([test for _, test in stack.cv])
    assert sorted(tested) == list(range(len(y)))  # every sample out of fold once
    for train, test in stack.cv:
        assert not set(groups[train]) & set(groups[test])  # a run's days all on one side


def test_classification_outputs_a_tidy_table_and_a_caption_with_the_chance_level(tmp_path):
    from analysis import benchmark

    X, y, groups, failed, normal = runs(n_failed=4, n_normal=4, n_cycles=16)
    table = classify.evaluate(X, y, groups, failed, normal, classifiers=["lr", "svm"], preprocessing=["control", "+diff"],
                              n_pairs=4)
    tidy = benchmark.classification_tidy(table)
    tidy.to_csv(tmp_path / "t.csv", index=False)
    back = pd.read_csv(tmp_path / "t.csv")
    assert list(back.columns) == ["preprocessing", "steps", "classifier", "auc_mean", "auc_std"] and len(back) == 4
    assert back.set_index(["preprocessing", "classifier"]).loc[("+diff", "svm"), "auc_mean"] == \
        pytest.approx(table.loc["+diff", ("svm", "mean")])
    caption = benchmark.classification_caption(table, n_pairs=4, horizon=None, wear_threshold=10, matched=False,
                                               command="faultgen classify x.h5")
    assert "Chance level not measured, so no cell can be read as better than chance: " \
           "`faultgen classify x.h5 --permutations 19`" in caption
    judged = benchmark.with_verdict(table, {f"lr {row}": np.full(19, 0.81) for row in table.index})
    judged.attrs.update(chance_source="lr", pairs=4)
    caption = benchmark.classification_caption(judged, n_pairs=4, horizon=None, wear_threshold=10, matched=False,
                                               command="faultgen classify x.h5")
    assert "Chance level per row (column chance): the mean AUC of lr on that row" in caption
    assert "Token order" not in caption and "--full" not in caption
    both = judged.rename(index={"control": "+diff+pca+var3", "+diff": "+diff+var3+pca"})
    caption = benchmark.classification_caption(both, n_pairs=4, horizon=None, wear_threshold=10, matched=False,
                                               command="faultgen classify x.h5", short=True)
    assert "+diff+pca+var3 concatenates windows of PCA scores" in caption
    assert "every row of Table 5.2: `faultgen classify x.h5 --full`" in caption
    assert benchmark.classification_heatmap(judged, tmp_path / "h.png").stat().st_size > 0
    assert benchmark.classification_heatmap(table, tmp_path / "h0.png").stat().st_size > 0


def test_the_short_table_is_its_rows_of_the_full_one_with_the_same_aucs():
    """Issue 40: `faultgen classify` computes SHORT_TABLE's rows by default; each is the cell the full
    table has (same pairs, same seeds), and the short table is each step alone and the fullest
    combinations, in Table 5.2's order."""
    assert [n for n in classify.TABLE_5_2 if n in classify.SHORT_TABLE] == list(classify.SHORT_TABLE)
    singles = {t for n in classify.SHORT_TABLE for t in ["+" + t for t in n[1:].split("+")] if n != "control"}
    assert singles == {"+estM", "+diff", "+pca", "+var3"}
    X, y, groups, failed, normal = runs(n_failed=3, n_normal=3, n_cycles=14)
    estimated = X[:, :2] ** 2
    _, short = classify.evaluate(X, y, groups, failed, normal, classifiers=["lr"], estimated=estimated,
                                 preprocessing=classify.SHORT_TABLE, n_pairs=3, return_aucs=True)
    _, full = classify.evaluate(X, y, groups, failed, normal, classifiers=["lr"], estimated=estimated,
                                n_pairs=3, return_aucs=True)
    assert len(full) == len(classify.PREPROCESSING) and set(short) < set(full)
    for cell, aucs in short.items():
        np.testing.assert_array_equal(aucs, full[cell])


def test_classify_command_computes_the_short_table_unless_full(tmp_path, monkeypatch):
    from typer.testing import CliRunner

    from analysis import benchmark
    from faultgen.cli import analysis as cli_analysis
    from faultgen.cli import app

    seen = []

    def table(path, **kwargs):
        seen.append(kwargs["short"])
        return pd.DataFrame({("lr", "mean"): [0.5]}, index=pd.Index(["control"], name="preprocessing"))

    monkeypatch.setattr(benchmark, "classification_table", table)
    monkeypatch.setattr(cli_analysis, "analysis_input", lambda *args: None)  # no dataset: the hand-off only
    runner = CliRunner()
    outputs = []
    for flag, out in ([], "s"), (["--full"], "f"):
        result = runner.invoke(app, ["classify", str(tmp_path / "d.h5"), *flag, "--no-progress", "-o", str(tmp_path / out)])
        assert result.exit_code == 0, result.output
        outputs.append(" ".join(result.output.split()))
    assert seen == [True, False]
    assert "--full`." in outputs[0] and "--full`." not in outputs[1]
    assert "--full" in " ".join(runner.invoke(app, ["classify", "--help"]).output.split())


def test_every_pair_is_bounded_before_any_fit():
    # issue 50: --pairs 0 (every pair) had no upper bound; 400 x 300 runs would fit 120 000 pairs
    from analysis.classify import MAX_PAIRS, select_pairs
    from faultgen.cli.options import MAX_PAIRS as CLI_MAX_PAIRS

    assert CLI_MAX_PAIRS == MAX_PAIRS
    failed, normal = [f"w{i}" for i in range(400)], [f"h{i}" for i in range(300)]
    for n_pairs in (None, 120_000):
        with pytest.raises(ValueError, match="400 worn x 300 unworn runs is 120000 held-out pairs, more than 100000"):
            select_pairs(failed, normal, n_pairs)
    assert len(select_pairs(failed, normal, 20)) == 20
    assert len(select_pairs(failed[:300], normal, None)) == 90_000
