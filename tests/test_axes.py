"""Axis numbering: array index 0..N-1 <-> axis number 1..N, converted in one module."""

import numpy as np
import pytest

from faultgen import axes


def test_numbers_and_indices_round_trip():
    assert axes.numbers(range(6)) == [1, 2, 3, 4, 5, 6]
    assert [axes.index(n) for n in range(1, 7)] == list(range(6))
    assert axes.index("3") == 2  # report.json's per-axis keys
    assert axes.number(np.int64(4)) == 5 and type(axes.number(np.int64(4))) is int


@pytest.mark.parametrize("bad", [0, 7, -1, "0", "x", 2.0, "2.5", None, True])
def test_an_axis_number_outside_1_to_6_is_refused_by_name(bad):
    with pytest.raises(ValueError, match=r"1\.\.6") as error:
        axes.index(bad, 6)
    assert repr(bad) in str(error.value)


@pytest.mark.parametrize("n_axes", [5, 6, 7])
def test_the_robots_axis_count_bounds_the_numbers(n_axes):
    assert [axes.index(n, n_axes) for n in range(1, n_axes + 1)] == list(range(n_axes))
    assert axes.numbers(range(n_axes), n_axes) == list(range(1, n_axes + 1))
    with pytest.raises(ValueError, match=rf"^axis {n_axes + 1} is out of range 1\.\.{n_axes}$"):
        axes.index(n_axes + 1, n_axes)
    with pytest.raises(ValueError, match=rf"out of range 0\.\.{n_axes - 1}"):
        axes.number(n_axes, n_axes)
    assert axes.index(7) == 6  # without a count: any axis a robot may have
    with pytest.raises(ValueError, match=r"n_axes = 8; a robot has 5\.\.7 axes"):
        axes.index(1, 8)


def test_a_wear_plan_and_a_report_number_the_same_axis_alike():
    """The worn axis of ``--wear 5:...`` is column 4 of the multipliers, and an effect fitted on
    column 4 is reported on axis "5"."""
    from faultgen.effects import make
    from faultgen.operation.wear import WearPlan

    multipliers = WearPlan.from_specs(["5:step:20"], 10).multipliers(np.array([10]), 6)
    assert np.flatnonzero(multipliers[0] != 1.0).tolist() == [4]
    offset = make("torque_offset", offset=[0, 0, 0, 0, 1.5, 0])
    assert offset.report([4]) == {"5": {"offset": 1.5}}
