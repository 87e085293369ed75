"""The evaluation harness's contract (analysis/evaluate.py): every registered detector, monitor and
isolator through ``evaluate`` on a tiny dataset (one score and one alarm per tested record, one
answer per case, the same answers for the same seed), and every protocol keeping a unit's records
on one side of each fold (against scikit-learn's own ``LeaveOneGroupOut`` and a hand count)."""

from __future__ import annotations

import importlib.util
from itertools import product

import numpy as np
import pytest
from sklearn.model_selection import BaseCrossValidator, LeaveOneGroupOut

from analysis import registry, scoring
from analysis.evaluate import Data, Given, LeavePairOut, OwnHistory, TrackSplit, evaluate
from faultgen.bench import baselines  # noqa: F401  (registers the bench's baselines)

RULES = scoring.BENCH_RULES
N_AXES, RECORDS = 6, 24


def tiny(seed: int = 0) -> tuple[Data, list[str], list[str]]:
    """Six units of 24 records of 6 axes: u0-u2 healthy, u3-u5 with axis 2 (1-based) rising from
    record 12 on; the failed and the normal unit names."""
    rng = np.random.default_rng(seed)
    X, y, units = [], [], []
    for k in range(6):
        x = 1.0 + 0.05 * rng.standard_normal((RECORDS, N_AXES))
        level = np.zeros(RECORDS)
        if k >= 3:
            level[12:] = np.linspace(5.0, 60.0, RECORDS - 12)
            x[:, 1] *= 1.0 + level / 100.0
        X.append(x)
        y.append(level >= 10.0)
        units.append(f"u{k}")
    return Data.of_units(X, units, y, [k < 3 for k in range(6)]), units[3:], units[:3]


def _shipped(factory) -> bool:
    """Whether a registry factory (a function, or a partial of one) is faultgen's or analysis's."""
    function = getattr(factory, "func", factory)
    return function.__module__.split(".")[0] in ("faultgen", "analysis")


def runnable(role: str) -> list[str]:
    """The names of ``role`` that faultgen and analysis register and a command can build (no context;
    a test's own plug-in, registered by another file in the same process, is left out); one needing a
    module not installed here is checked by :func:`test_a_method_needing_a_missing_module_is_refused_by_name`."""
    names = [n for n in registry.names(role) if registry.get(n).context is None and _shipped(registry.get(n).factory)]
    return [n for n in names if registry.get(n).needs is None or importlib.util.find_spec(registry.get(n).needs)]


def track(data: Data) -> TrackSplit:
    """u0, u1, u3, u4 train; u2 and u5 test; two setups (robot a: u0, u2, u3; robot b: u1, u4, u5)."""
    unit = data.groups.astype(str)
    return TrackSplit(np.isin(unit, ["u2", "u5"]), np.where(np.isin(unit, ["u1", "u4", "u5"]), "b/t", "a/t"))


@pytest.mark.parametrize("name", runnable("detector") + runnable("monitor"))
def test_every_detector_scores_every_tested_record_the_same_for_the_same_seed(name):
    data, _, _ = tiny()
    _, method = registry.make(name)
    first = evaluate(method, data, track(data), RULES, name)
    again = evaluate(registry.make(name)[1], tiny()[0], track(data), RULES, name)
    tested = np.isin(data.groups, ["u2", "u5"])
    assert first.tested.tolist() == tested.tolist()
    assert first.scores.shape == first.alarms.shape == (len(data.X),)
    assert np.isfinite(first.scores[tested]).all() and np.isnan(first.scores[~tested]).all()
    assert first.alarms.dtype == bool and not first.alarms[~tested].any()
    assert len(first.folds) == track(data).get_n_splits() == 2
    np.testing.assert_array_equal(first.scores, again.scores)
    np.testing.assert_array_equal(first.alarms, again.alarms)


@pytest.mark.parametrize("name", runnable("isolator"))
def test_every_isolator_answers_each_case_the_same_for_the_same_seed(name):
    data, failed, normal = tiny()
    cases = [(u, None) for u in failed + normal] + [(failed[0], 2)]  # the last: too few records for any
    _, method = registry.make(name)
    first = evaluate(method, data, OwnHistory(cases), RULES, name, role="isolator")
    again = evaluate(registry.make(name)[1], data, OwnHistory(cases), RULES, name, role="isolator")
    assert first.named == again.named and len(first.named) == len(cases)
    axes = [axis for axis, _ in first.named]
    assert all(a in (scoring.UNDECIDED, *range(1, N_AXES + 1)) for a in axes)
    assert axes[-1] == scoring.too_few_answer(RULES) == scoring.UNDECIDED  # bench score's rule
    table = evaluate(method, data, OwnHistory(cases), scoring.ISOLATION_TABLE_RULES, name, role="isolator")
    assert table.named[-1][0] == scoring.TOO_FEW_CYCLES  # bench-isolators' rule: not applicable


def test_an_isolator_finds_the_rising_axis():
    """The tiny data's worn units rise on axis 2 only: the trend isolator names it in each."""
    data, failed, _ = tiny()
    scores = evaluate(registry.make("trend")[1], data, OwnHistory([(u, None) for u in failed]), RULES, "trend",
                      role="isolator")
    assert [axis for axis, _ in scores.named] == [2, 2, 2]


def test_a_method_needing_a_missing_module_is_refused_by_name():
    for name in registry.names():
        entry = registry.get(name)
        if entry.needs and not importlib.util.find_spec(entry.needs):
            with pytest.raises(ValueError, match=f"baseline {name!r} needs {entry.needs}"):
                registry.make(name)


def _sides(protocol, data: Data) -> list[tuple[set, set]]:
    return [(set(data.groups[train]), set(data.groups[test]))
            for train, test in protocol.split(data.X, data.y, data.groups)]


def test_no_protocol_puts_a_units_records_on_both_sides():
    data, failed, normal = tiny()
    for protocol in (track(data), LeavePairOut(failed, normal), LeavePairOut(failed, normal, n_pairs=4, random_state=3),
                     LeaveOneGroupOut()):
        assert isinstance(protocol, BaseCrossValidator)
        sides = _sides(protocol, data)
        assert sides and all(not (train & test) for train, test in sides), protocol
        assert len(sides) == protocol.get_n_splits(data.X, data.y, data.groups)
    # leave-pair-out: every (failed, normal) pair held out once, the rest trained on (Procedure 1)
    sides = _sides(LeavePairOut(failed, normal), data)
    assert [tuple(sorted(test)) for _, test in sides] == [tuple(sorted(p)) for p in product(failed, normal)]
    assert all(train | test == set(data.groups) for train, test in sides)
    # scikit-learn's leave-one-group-out: each unit tested once
    assert sorted(u for _, test in _sides(LeaveOneGroupOut(), data) for u in test) == sorted(failed + normal)


def test_a_drawn_subset_of_pairs_follows_its_seed():
    data, failed, normal = tiny()
    drawn = [LeavePairOut(failed, normal, n_pairs=4, random_state=s).pairs() for s in (3, 3, 4)]
    assert drawn[0] == drawn[1] and len(drawn[0]) == 4 and set(drawn[0]) <= set(product(failed, normal))
    assert drawn[0] == sorted(drawn[0], key=list(product(failed, normal)).index)  # in the full list's order


def test_the_track_split_fits_each_setup_on_its_own_train_units():
    data, _, _ = tiny()
    sides = _sides(track(data), data)
    assert sides == [({"u0", "u3"}, {"u2"}), ({"u1", "u4"}, {"u5"})]
    lonely = TrackSplit(np.isin(data.groups, ["u2"]), np.where(data.groups == "u2", "c/t", "a/t"))
    assert _sides(lonely, data) == [({"u0", "u1", "u3", "u4", "u5"}, {"u2"})]  # no train unit of c: all train


def test_the_scores_give_the_onset_under_the_rules():
    data, failed, _ = tiny()
    scores = evaluate(registry.make("pca")[1], data, LeavePairOut(failed, ["u0"]), RULES, "pca")
    rows = data.rows(failed[0])
    found = scores.onset(rows, fault_start=12)
    assert found == scoring.onset(scores.alarms[rows], RULES, fault_start=12)


def test_units_of_other_widths_stack_and_refuse_to_mix():
    data = Data.of_units([np.ones((3, 2)), np.zeros((2, 3))], ["a", "b"])
    assert data.X.shape == (5, 3) and np.isnan(data.X[:3, 2]).all()
    assert data.features(data.rows("a")).shape == (3, 2) and data.features(data.rows("b")).shape == (2, 3)
    with pytest.raises(ValueError, match="2 feature counts"):
        data.features(np.arange(5))


def test_bad_data_and_roles_are_refused_naming_them():
    with pytest.raises(ValueError, match=r"y must have shape \(3,\)"):
        Data(np.ones((3, 2)), np.zeros(3), y=np.zeros(2))
    with pytest.raises(ValueError, match="X must have shape"):
        Data(np.ones(3), np.zeros(3))
    data, failed, normal = tiny()
    with pytest.raises(ValueError, match="role 'prognoser'"):
        evaluate(registry.make("pca")[1], data, LeavePairOut(failed, normal), RULES, role="prognoser")


def test_given_folds_fit_once_and_judge_each_unit_on_its_own_rows():
    """A training source (thesis ch. 4): u0's first 12 records learnt, the last 12 of u0 (its own
    history), u1 and u3 judged; the Q model's residuals equal those of the same model fitted by
    hand, and u3's wear on axis 2 raises its Q above the normal units'."""
    from analysis.training_source import QModel

    data, _, _ = tiny()
    first, last = slice(0, 12), slice(12, None)
    tested = [data.rows(u)[last] for u in ("u0", "u1", "u3")]
    folds = [(data.rows("u0")[first], np.concatenate(tested))]
    scores = evaluate(QModel(0.75, 0.05, None), data, Given(folds), None, "q", alarms=False)
    assert len(scores.folds) == Given(folds).get_n_splits() == 1 and not scores.alarms.any()
    by_hand = QModel(0.75, 0.05, None).fit(data.X[data.rows("u0")[first]])
    for rows in tested:
        np.testing.assert_array_equal(scores.scores[rows], by_hand.decision_function(data.X[rows]))
    assert np.isnan(scores.scores[data.rows("u2")]).all()
    assert scores.scores[tested[2]].mean() > max(scores.scores[tested[0]].mean(), scores.scores[tested[1]].mean())


def test_a_pipeline_fitted_run_by_run_scores_as_fit_by_run_and_score_by_run():
    """classify's pipelines (differences taken within each run) through the harness: fitted on the
    train units with their groups, the test fold scored at once with its groups, as by hand."""
    from analysis.classify import ByRun, fit_by_run, make_pipeline, score_by_run

    data, failed, normal = tiny()
    protocol = LeavePairOut(failed, normal, n_pairs=2, random_state=0)
    scores = evaluate(ByRun(make_pipeline("lr", "+diff")), data, protocol, None, "lr +diff", alarms=False,
                      test_by="fold")
    for train, test in protocol.split(data.X, data.y, data.groups):
        model = fit_by_run(make_pipeline("lr", "+diff"), data.X[train], data.y[train], data.groups[train])
        np.testing.assert_allclose(scores.scores[test], score_by_run(model, data.X[test], data.groups[test]),
                                   rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match="test_by = 'unit'"):
        evaluate(ByRun(make_pipeline("lr")), data, protocol, None, test_by="unit")
