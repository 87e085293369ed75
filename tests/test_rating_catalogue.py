"""Default ratings a planner can stand behind (issue 90, item 4; faultgen.model.rating): a cycloid
axis's rated torque is the smallest Nabtesco RV-E size whose allowable acceleration torque (2.5 x
rated) covers its gear output's peak, or no rating where none does, and then no consumption and no
date; the IRB-6700-like arm's default pick and place, 16 h a day, consumes 1-50 % of its axes 1-3's
rated life a year."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from faultgen.model import rating, robots, sizing
from faultgen.model.robot import drivetrain_of
from faultgen.monitor import life
from faultgen.simulation import stepping
from resolved_runs import run_config


def _peak_by_hand(drive, wrist: bool) -> float:
    """The gear output's peak: the motor torque limit less the 10 % margin, the rotor's acceleration to
    470 rad/s in 0.45 s (main axes) and the motor friction at 470 rad/s, times G."""
    G = drive.gear_ratio
    acceleration = 470.0 / G / (0.3 if wrist else 0.45)
    return G * (drive.motor_torque_limit / 1.1 - drive.motor_inertia * G * acceleration
                - drive.coulomb_pos - drive.viscous * 470.0)


@pytest.mark.parametrize("name, expected", [("irb6700", (4410.0, 4410.0, 3136.0)), ("puma560", (58.0, 58.0, 58.0))])
def test_a_cycloid_axis_gets_the_smallest_rv_e_size_whose_acceleration_torque_covers_its_peak(name, expected):
    robot = robots.load(name)
    ratings = rating.of_robot(robot)
    sizes = sorted(rating.RV_E_RATED_TORQUE.values())
    assert tuple(r.rated_torque for r in ratings[:3]) == expected
    for axis, (drive, r) in enumerate(zip(drivetrain_of(robot).axes[:3], ratings[:3]), start=1):
        peak = _peak_by_hand(drive, wrist=False)
        assert sizing.output_peak(drive, axis, 6) == pytest.approx(peak, rel=1e-12)
        assert 2.5 * r.rated_torque >= peak
        smaller = [t for t in sizes if t < r.rated_torque]
        assert not smaller or 2.5 * smaller[-1] < peak  # the smallest that covers it
        assert rating.catalogue_size(r).startswith("RV-") and r.gearbox_type == "cycloid"


def test_an_axis_whose_load_no_size_carries_has_no_rating_no_consumption_and_no_date():
    drive = dataclasses.replace(drivetrain_of(robots.load("irb6700")).axes[0], motor_torque_limit=500.0)
    values = rating.defaults(drive, 1, 6)
    assert values["rated_torque"] is None and "above the largest Nabtesco RV-E size's" in values["unrated"]
    unrated = rating.GearboxRating(**values)
    assert np.isnan(unrated.rated_torque) and rating.catalogue_size(unrated) == ""
    t = np.linspace(0.0, 60.0, 61)
    load = life.load_integrals(t, np.ones((61, 1)), np.full((61, 1), 1000.0))
    entry = type("Entry", (), {"stamp": "2026-03-01", "load": load, "duration": 60.0})
    row, = life.of_unit("u", [entry], [], (unrated,))
    assert row.days_left is None and row.verdict == unrated.unrated
    cells = dict(zip(life.COLUMNS, row.cells()))
    assert cells["rated_torque_Nm"] is None and cells["consumed_pct"] is None and cells["days_left"] is None
    with pytest.raises(rating.DrivetrainError, match="rated_torque = nan"):
        rating.GearboxRating("cycloid", float("nan"), 1.0, 6000.0)  # a nan given is refused, not taken as unrated


def test_a_rated_torque_given_replaces_the_missing_catalogue_size(tmp_path):
    drivetrain = drivetrain_of(robots.load("irb6700"))
    heavy = dataclasses.replace(drivetrain, axes=(dataclasses.replace(drivetrain.axes[0], motor_torque_limit=500.0),
                                                  *drivetrain.axes[1:]))
    assert rating.ratings(heavy)[0].unrated
    given = rating.ratings(heavy, {1: {"rated_torque": 7000.0}})[0]
    assert (given.rated_torque, given.unrated, given.defaults) == (7000.0, "", ("gearbox_type", "rated_speed",
                                                                               "rated_life"))


def test_the_irb6700s_pick_and_place_16_h_a_day_consumes_1_to_50_percent_of_axes_1_to_3_a_year():
    config = run_config(robot="irb6700", task="pick_place", cycles=2, record=(1,), signals=True, seed=0)
    result = stepping.simulate(config, progress=False)
    t, q = result.t, result.q_a[0]
    tau = result.tau_m[0] * config.model.gear_ratio  # arm side
    share = life.consumption(t, np.gradient(q, t, axis=0), tau, rating.of_robot(config.model))
    per_year = 100.0 * share / (t[-1] - t[0]) * 16 * 3600 * 365
    assert np.all((1.0 <= per_year[:3]) & (per_year[:3] <= 50.0)), per_year
