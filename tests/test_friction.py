"""The static Stribeck map of thesis eq. 6.3 against hand-computed values, and its validation."""

import math

import numpy as np
import pytest

from faultgen.effects.friction import FIELDS, MotorFriction


def one_axis(**overrides):
    values = dict(
        coulomb_pos=1.0,
        coulomb_neg=0.8,
        static=0.5,
        stribeck_velocity=2.0,
        stribeck_exponent=2.0,
        viscous=0.01,
        bristle_stiffness=1000.0,
        bristle_damping=1.0,
    )
    values.update(overrides)
    return MotorFriction(**{k: [v] for k, v in values.items()})


@pytest.mark.parametrize(
    ("v", "expected"),
    [
        (0.0, 0.0),  # no torque at rest: the kinetic map has no stiction
        (2.0, 1.0 + 0.5 * math.exp(-1.0) + 0.02),  # at the Stribeck velocity
        (-2.0, -(0.8 + 0.5 * math.exp(-1.0)) - 0.02),  # negative side uses coulomb_neg
        (1e-9, 1.5 + 1e-11),  # just above zero: Coulomb + full static excess
        (100.0, 1.0 + 1.0),  # far above: Coulomb + viscous, Stribeck term gone
    ],
)
def test_stribeck_torque_known_values(v, expected):
    assert one_axis().stribeck_torque(np.array([[v]]))[0, 0] == pytest.approx(expected, rel=1e-12, abs=1e-15)


def test_stribeck_exponent_shapes_the_curve():
    # gamma = 1: exp(-|v/vs|) at v = vs/2 is exp(-0.5)
    friction = one_axis(stribeck_exponent=1.0, viscous=0.0)
    assert friction.stribeck_torque(np.array([[1.0]]))[0, 0] == pytest.approx(1.0 + 0.5 * math.exp(-0.5))


def test_rows_round_trip():
    rows = np.arange(1, 17, dtype=float).reshape(2, 8)
    friction = MotorFriction.from_rows(rows)
    np.testing.assert_array_equal(friction.as_rows(), rows)
    assert friction.stribeck_velocity.tolist() == [4.0, 12.0]
    assert len(FIELDS) == 8


@pytest.mark.parametrize(
    ("field", "value", "match"),
    [
        ("coulomb_pos", -0.1, r"axis 1: friction coulomb_pos = -0\.1 N m, expected a finite value >= 0"),
        ("viscous", float("nan"), r"axis 1: friction viscous = nan"),
        ("stribeck_velocity", 0.0, r"axis 1: friction stribeck_velocity = 0\.0 rad/s, expected a finite value > 0"),
    ],
)
def test_invalid_parameters_are_refused_with_axis_and_field(field, value, match):
    with pytest.raises(ValueError, match=match):
        one_axis(**{field: value})


def test_parameters_are_read_only():
    friction = one_axis()
    with pytest.raises(ValueError):
        friction.static[0] = 2.0
