"""A gearbox rating in ``drivetrain.toml`` is bounded so that the rated-life formula stays
representable (issue 86, item 9): ``rated_torque = 1e-300`` passed and put inf and NaN into
life.csv (``T_N^p`` underflows to 0, the share of life divides by it)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from faultgen.model import drivetrain, rating, robots
from faultgen.monitor import life


@pytest.mark.parametrize("key, value", [("rated_torque", "1e-300"), ("rated_torque", "5e-324"),
                                        ("rated_speed", "1e-300"), ("rated_life", "1e-300")])
def test_a_rating_too_small_for_the_formula_is_refused_naming_file_axis_key_and_range(tmp_path, key, value):
    robot = robots.load("puma560")
    text = (robot.path.parent / "drivetrain.toml").read_text()
    path = tmp_path / "drivetrain.toml"
    path.write_text(text.replace("[axis.2]\n", f"[axis.2]\n{key} = {value}\n"))
    low, high = drivetrain.RATING_BOUNDS[key]
    for read in (lambda: drivetrain.read_table(path, robot.n_axes), lambda: rating.given(path, robot.n_axes)):
        with pytest.raises(drivetrain.DrivetrainError) as raised:
            read()
        message = str(raised.value)
        assert f"axis 2: {key} = {float(value)!r}" in message and f"from {low:g} to {high:g}" in message, message
        assert "\n" not in message


def test_at_the_bounds_the_share_of_life_of_the_heaviest_log_stays_finite():
    """Every corner of the bounds against a log far heavier than any robot's: 1e3 rad/s at 1e7 N m
    for a day (and a log of no load): the share of rated life, the rate per day and the days left are
    finite numbers, as life.csv writes them."""
    day = 86400.0
    heavy = np.array([[1e3 * 1e7**p * day] for p in life.EXPONENTS])
    for kind in rating.EXPONENTS:
        for torque in drivetrain.RATING_BOUNDS["rated_torque"]:
            for speed in drivetrain.RATING_BOUNDS["rated_speed"]:
                for hours in drivetrain.RATING_BOUNDS["rated_life"]:
                    r = rating.GearboxRating(kind, torque, speed, hours)
                    for load in (heavy, np.zeros_like(heavy)):
                        share = float(life.consumed(load, (r,))[0])
                        assert math.isfinite(share) and share >= 0, (kind, torque, speed, hours, share)
                        assert math.isfinite(share / day * 24 * 3600 * 100 * 1e5)  # % per day, over 1e5 days


def test_a_rating_made_in_code_is_checked_against_the_same_bounds():
    assert rating.GearboxRating("cycloid", drivetrain.RATING_BOUNDS["rated_torque"][0], 1.0, 1.0).rated_torque == 1e-6
    assert 1e-300 ** (10 / 3) == 0.0  # what the formula divided by before the bound
    with pytest.raises(drivetrain.DrivetrainError, match="rated_torque = 1e-300"):
        rating.GearboxRating("cycloid", 1e-300, 1.0, 1.0)
