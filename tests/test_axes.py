"""Axis numbering: array index 0..5 <-> axis number 1..6, converted in one module."""

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
    with pytest.raises(ValueError, match=r"expected 1\.\.6") as error:
        axes.index(bad)
    assert repr(bad) in str(error.value)


def test_a_wear_plan_and_a_report_number_the_same_axis_alike():
    """The worn axis of ``--wear 5:...`` is column 4 of the multipliers, and an effect fitted on
    column 4 is reported on axis "5"."""
    from faultgen.effects import make
    from faultgen.operation.wear import WearPlan

    multipliers = WearPlan.from_specs(["5:step:20"], 10).multipliers(np.array([10]))
    assert np.flatnonzero(multipliers[0] != 1.0).tolist() == [4]
    offset = make("torque_offset", offset=[0, 0, 0, 0, 1.5, 0])
    assert offset.report([4]) == {"5": {"offset": 1.5}}
