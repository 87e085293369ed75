"""Wear schedules (thesis eqs. 6.6 and 3.7) against hand-computed values, plans, specs, validation."""

import json
import math
import re

import numpy as np
import pytest

from faultgen.operation.wear import SCHEDULES, Schedule, WearPlan, parse_wear

CYCLES = np.arange(0, 101)


# --- exp4, thesis eq. 6.6 --------------------------------------------------------------------


def test_exp4_c1_solves_eq_6_6_for_20_percent_over_100_cycles():
    s = Schedule("exp4", 0.2, 100)
    c1 = s.to_dict()["c1"]
    assert c1 == pytest.approx(math.log(1.2) / 1e8, rel=1e-15)
    assert f"{c1:.3e}" == "1.823e-09"  # not the 1.785e-9 printed in the thesis, see below
    assert s.multiplier(0) == 1.0
    assert s.multiplier(100) == pytest.approx(1.2, abs=1e-12)


def test_thesis_printed_c1_falls_short_of_20_percent():
    """The thesis prints c1 = 1.785e-9, which gives exp(0.1785) = 1.1954, i.e. +19.54 % at k = 100."""
    assert math.exp(1.785e-9 * 100**4) == pytest.approx(1.19542, abs=1e-5)


def test_exp4_is_slow_then_steep():
    m = Schedule("exp4", 0.2, 100).multiplier(np.array([25, 50, 75, 100]))
    np.testing.assert_allclose(m, np.exp(math.log(1.2) * np.array([25, 50, 75, 100]) ** 4 / 1e8), rtol=1e-14)
    assert m[1] - 1 < 0.1 * 0.2  # less than a tenth of the increase by half-way (k^4: 1/16)
    assert np.all(np.diff(m) > 0)


# --- logistic, thesis eq. 3.7 ----------------------------------------------------------------


@pytest.mark.parametrize("shape", [0.3, 1.5, 2.0, 5.0])
def test_logistic_starts_at_1_ends_at_1_plus_p_and_never_falls(shape):
    s = Schedule("logistic", 0.1, 100, {"shape": shape})
    m = s.multiplier(CYCLES)
    assert m[0] == 1.0
    assert m[100] == pytest.approx(1.1, abs=1e-12)
    assert np.all(np.diff(m) >= 0)


def test_logistic_matches_eq_3_7_with_r0_for_nominal_start():
    """mu_k = r0 + c1 / (1 + exp(-(c2 k)^4)), r0 and c1 solved for mu_0 = 1, mu_K = 1 + p."""
    p, K, shape = 0.15, 80, 1.5
    c2 = shape / K
    s = lambda k: 1.0 / (1.0 + np.exp(-((c2 * k) ** 4)))
    c1 = p / (s(K) - 0.5)
    r0 = 1.0 - c1 / 2
    k = np.arange(0, K + 1)
    schedule = Schedule("logistic", p, K)
    np.testing.assert_allclose(schedule.multiplier(k), r0 + c1 * s(k), rtol=1e-12)
    assert schedule.to_dict() == {"kind": "logistic", "increase": p, "last_cycle": K, "shape": 1.5, "c2": c2}


def test_logistic_larger_shape_saturates_earlier():
    early = Schedule("logistic", 0.2, 100, {"shape": 3.0}).multiplier(50)
    late = Schedule("logistic", 0.2, 100, {"shape": 1.0}).multiplier(50)
    assert early > 1.19  # (3 * 0.5)^4 = 5.06: nearly saturated half-way
    assert late == pytest.approx(1 + 0.2 * math.tanh(0.5**4 / 2) / math.tanh(0.5), rel=1e-14)  # 1.0135


def test_logistic_tiny_shape_tends_to_k4_and_huge_shape_to_a_step():
    """s(k) - 1/2 ~ (c2 k)^4 / 4 for small c2 k, so m -> 1 + p (k/K)^4; tanh form keeps it exact."""
    tiny = Schedule("logistic", 0.2, 100, {"shape": 1e-20}).multiplier(np.array([0, 50, 100]))
    np.testing.assert_allclose(tiny, [1.0, 1.0 + 0.2 / 16, 1.2], rtol=1e-14)
    huge = Schedule("logistic", 0.2, 100, {"shape": 1e100}).multiplier(np.array([0, 1, 100]))
    np.testing.assert_array_equal(huge, [1.0, 1.2, 1.2])


# --- linear and step -------------------------------------------------------------------------


def test_linear_known_values():
    s = Schedule("linear", 0.2, 100)
    np.testing.assert_allclose(s.multiplier(np.array([0, 25, 50, 100])), [1.0, 1.05, 1.1, 1.2], rtol=1e-15)
    assert s.to_dict() == {"kind": "linear", "increase": 0.2, "last_cycle": 100}


def test_step_default_wears_the_second_half():
    s = Schedule("step", 0.2, 100)
    assert s.params["step_cycle"] == 51
    np.testing.assert_array_equal(s.multiplier(np.array([0, 1, 50, 51, 100])), [1.0, 1.0, 1.0, 1.2, 1.2])
    assert Schedule("step", 0.2, 1).params["step_cycle"] == 1


def test_step_at_given_cycle():
    s = Schedule("step", 0.3, 100, {"step_cycle": 40})
    np.testing.assert_array_equal(s.multiplier(np.array([39, 40, 41])), [1.0, 1.3, 1.3])
    assert s.to_dict() == {"kind": "step", "increase": 0.3, "last_cycle": 100, "step_cycle": 40}


@pytest.mark.parametrize("kind", SCHEDULES)
def test_every_kind_reaches_the_increase_and_keeps_the_shape_of_k(kind):
    s = Schedule(kind, 0.25, 60)
    assert s.multiplier(0) == 1.0
    assert s.multiplier(60) == pytest.approx(1.25, abs=1e-12)
    k = np.array([[0, 10], [20, 60]])
    m = s.multiplier(k)
    assert m.shape == (2, 2) and m.dtype == float
    assert s.multiplier(np.int64(5)).shape == ()
    assert np.all(Schedule(kind, 0.0, 60).multiplier(CYCLES) == 1.0)


@pytest.mark.parametrize("kind", SCHEDULES)
def test_to_dict_is_json_serialisable(kind):
    d = Schedule(kind, 0.2, 100).to_dict()
    assert json.loads(json.dumps(d)) == d


# --- plans -----------------------------------------------------------------------------------


def test_plan_gives_each_worn_axis_its_own_schedule():
    exp4 = Schedule("exp4", 0.2, 100)
    step = Schedule("step", 0.1, 100, {"step_cycle": 30})
    plan = WearPlan({5: step, 2: exp4})
    assert plan.worn_axes == (2, 5)
    m = plan.multipliers(CYCLES, 6)
    assert m.shape == (101, 6)
    np.testing.assert_array_equal(m[:, 1], exp4.multiplier(CYCLES))
    np.testing.assert_array_equal(m[:, 4], step.multiplier(CYCLES))
    np.testing.assert_array_equal(m[:, [0, 2, 3, 5]], 1.0)
    assert m[30, 4] == 1.1 and m[30, 1] < 1.002  # the step axis is worn long before the exp4 axis


def test_plan_to_dict():
    plan = WearPlan({3: Schedule("linear", 0.2, 100)})
    d = plan.to_dict()
    assert d == {
        "worn_axes": [3],
        "schedules": [{"axis": 3, "kind": "linear", "increase": 0.2, "last_cycle": 100}],
    }
    assert json.loads(json.dumps(d)) == d


def test_empty_plan_is_no_wear():
    plan = WearPlan()
    assert plan.worn_axes == ()
    np.testing.assert_array_equal(plan.multipliers(np.array([0, 1, 2]), 6), np.ones((3, 6)))
    assert plan.to_dict() == {"worn_axes": [], "schedules": []}
    assert WearPlan({2: Schedule("exp4", 0.2, 100)}).multipliers([], 5).shape == (0, 5)


def test_plan_from_specs():
    plan = WearPlan.from_specs(["2:exp4:20", "5:step:20:step_cycle=40"], 100)
    assert plan.schedules[2] == Schedule("exp4", 0.2, 100)
    assert plan.schedules[5] == Schedule("step", 0.2, 100, {"step_cycle": 40})
    with pytest.raises(ValueError, match=r"axis 2 has two wear specs, '2:exp4:20' and '2:linear:10'"):
        WearPlan.from_specs(["2:exp4:20", "2:linear:10"], 100)


def test_a_plan_is_held_to_the_robots_axes():
    """A plan accepts any axis a robot can have (1..7); a run holds it to its robot's N."""
    plan = WearPlan({7: Schedule("linear", 0.2, 100)})
    assert plan.multipliers(np.array([100]), 7)[0].tolist() == [1, 1, 1, 1, 1, 1, 1.2]
    with pytest.raises(ValueError, match=r"^axis 7 is out of range 1\.\.6$"):
        plan.multipliers(np.array([100]), 6)
    with pytest.raises(ValueError, match=r"^axis 7 is out of range 1\.\.5$"):
        plan.check(5)


# --- parse_wear ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("spec", "axis", "schedule"),
    [
        ("2:exp4:20", 2, Schedule("exp4", 0.2, 100)),
        ("3:logistic:10:shape=2", 3, Schedule("logistic", 0.1, 100, {"shape": 2.0})),
        ("5:step:20:step_cycle=40", 5, Schedule("step", 0.2, 100, {"step_cycle": 40})),
        ("6:linear:12.5", 6, Schedule("linear", 0.125, 100)),
        (" 1 : logistic : 0 : shape = 0.5 ", 1, Schedule("logistic", 0.0, 100, {"shape": 0.5})),
    ],
)
def test_parse_wear(spec, axis, schedule):
    assert parse_wear(spec, 100) == (axis, schedule)


@pytest.mark.parametrize("kind", SCHEDULES)
def test_parse_wear_round_trips_through_to_dict(kind):
    d = Schedule(kind, 0.2, 100).to_dict()
    options = {"logistic": f":shape={d.get('shape')}", "step": f":step_cycle={d.get('step_cycle')}"}
    spec = f"4:{d['kind']}:{d['increase'] * 100:g}" + options.get(kind, "")
    axis, schedule = parse_wear(spec, d["last_cycle"])
    assert axis == 4 and schedule.to_dict() == d


FORM = r"the form is AXIS:KIND:PERCENT\[:key=value,\.\.\.\], e\.g\. '2:exp4:20'"


@pytest.mark.parametrize(
    ("spec", "reason"),
    [
        ("2:exp4", r"it has 2 ':'-separated field\(s\), expected 3 or 4"),
        ("2:exp4:20:shape=1:x", r"it has 5 ':'-separated field\(s\)"),
        ("x:exp4:20", r"AXIS 'x' is not an int"),
        ("8:exp4:20", r"axis 8 is out of range 1\.\.7"),
        ("0:exp4:20", r"axis 0 is out of range 1\.\.7"),
        ("2:cubic:20", r"unknown wear schedule 'cubic'; known schedules: exp4, logistic, linear, step"),
        ("2:exp4:20%", r"PERCENT '20%' is not a number"),
        ("2:exp4:-10", r"PERCENT -10 is not a finite number >= 0 \(20 means \+20 % friction\)"),
        ("2:exp4:inf", r"PERCENT inf is not a finite number >= 0"),
        ("2:logistic:10:shape", r"option 'shape' is not key=value"),
        ("2:logistic:10:shape=wide", r"option shape=wide is not a number"),
        ("2:logistic:10:shape=0", r"logistic shape 0\.0 is invalid; expected a finite number > 0"),
        ("2:step:10:step_cycle=4.5", r"option step_cycle=4\.5 is not an int"),
        ("2:step:10:step_cycle=101", r"step_cycle 101 is out of range 1\.\.100 \(last_cycle\)"),
        ("2:exp4:20:shape=1", r"exp4 schedule has no parameter 'shape'; it takes parameters: onset"),
        ("2:linear:20:shape=1", r"linear schedule has no parameter 'shape'; it takes no parameters"),
        ("2:exp4:20:onset=100", r"exp4 onset 100 is invalid; expected an int in 0..99"),
        (
            "2:logistic:20:step_cycle=3",
            r"logistic schedule has no parameter 'step_cycle'; it takes parameters: shape",
        ),
    ],
)
def test_parse_wear_errors_quote_the_spec_and_show_the_form(spec, reason):
    with pytest.raises(ValueError, match=rf"^bad wear spec {re.escape(repr(spec))}: {reason}.*; {FORM}"):
        parse_wear(spec, 100)


# --- validation ------------------------------------------------------------------------------


FRACTION = r"expected a fraction >= 0 such as 0\.2 for 20 %"


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"kind": "cubic"}, r"unknown wear schedule 'cubic'; known schedules: exp4, logistic, linear, step"),
        ({"increase": -0.1}, rf"wear increase -0\.1 is negative; {FRACTION}"),
        ({"increase": float("nan")}, rf"wear increase nan is not finite; {FRACTION}"),
        ({"increase": float("inf")}, rf"wear increase inf is not finite; {FRACTION}"),
        ({"increase": "20%"}, rf"wear increase '20%' is not a number; {FRACTION}"),
        ({"increase": True}, rf"wear increase True is not a number; {FRACTION}"),
        ({"last_cycle": 0}, r"last_cycle 0 is invalid; expected an int >= 1 such as 100"),
        ({"last_cycle": 100.0}, r"last_cycle 100\.0 is invalid; expected an int >= 1"),
        ({"last_cycle": True}, r"last_cycle True is invalid; expected an int >= 1"),
        ({"kind": "exp4", "params": {"shape": 2}}, r"exp4 schedule has no parameter 'shape'"),
        (
            {"kind": "logistic", "params": {"shape": 0}},
            r"logistic shape 0 is invalid; expected a finite number > 0",
        ),
        ({"kind": "logistic", "params": {"shape": -1.5}}, r"logistic shape -1\.5 is invalid"),
        ({"kind": "logistic", "params": {"shape": float("nan")}}, r"logistic shape nan is invalid"),
        ({"kind": "logistic", "params": {"shape": 1e-90}}, r"logistic shape 1e-90 is too small to compute"),
        (
            {"kind": "step", "params": {"step_cycle": 0}},
            r"step_cycle 0 is out of range 1\.\.100 \(last_cycle\)",
        ),
        ({"kind": "step", "params": {"step_cycle": 101}}, r"step_cycle 101 is out of range 1\.\.100"),
        (
            {"kind": "step", "params": {"step_cycle": 40.0}},
            r"step_cycle 40\.0 is not an int; expected one in 1\.\.100",
        ),
    ],
)
def test_schedule_validation_names_the_value(kwargs, message):
    args = {"kind": "exp4", "increase": 0.2, "last_cycle": 100, "params": {}}
    args.update(kwargs)
    with pytest.raises(ValueError, match=f"^{message}"):
        Schedule(args["kind"], args["increase"], args["last_cycle"], args["params"])


def test_schedule_is_read_only():
    s = Schedule("step", 0.2, 100)
    with pytest.raises(AttributeError):
        s.increase = 0.5
    with pytest.raises(TypeError):
        s.params["step_cycle"] = 0


@pytest.mark.parametrize(
    ("k", "message"),
    [
        (-1, r"cycle index -1 is negative; expected an int >= 0"),
        (np.array([3, -2]), r"cycle index -2 is negative"),
        (1.5, r"cycle index must be an int or an int array, got 1\.5"),
        (np.array([1.0, 2.0]), r"cycle index must be an int or an int array, got an array of float64"),
        (np.array([True]), r"cycle index must be an int or an int array, got an array of bool"),
    ],
)
def test_multiplier_rejects_bad_cycles(k, message):
    with pytest.raises(ValueError, match=message):
        Schedule("linear", 0.2, 100).multiplier(k)
    with pytest.raises(ValueError, match=message):
        WearPlan().multipliers(k, 6)


@pytest.mark.parametrize("axis", [0, 8, -1, True, 2.0])
def test_plan_rejects_bad_axes(axis):
    with pytest.raises(ValueError, match=rf"^axis {axis!r} is out of range 1\.\.7$"):
        WearPlan({axis: Schedule("exp4", 0.2, 100)})


def test_plan_rejects_non_schedules_and_2d_cycles():
    with pytest.raises(TypeError, match=r"axis 2: expected a Schedule, got str"):
        WearPlan({2: "2:exp4:20"})
    with pytest.raises(ValueError, match=r"cycles must be an int or a 1-D int array, got shape \(2, 2\)"):
        WearPlan().multipliers(np.ones((2, 2), dtype=int), 6)
