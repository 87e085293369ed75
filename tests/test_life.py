"""The life a gearbox consumed by its load (faultgen.monitor.life) and the gearbox ratings it is
judged against (faultgen.model.rating): one log's consumption computed by hand from the makers'
formula, the catalogue's averaged form, the bookkeeping of life.csv, and the ratings' checks."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from faultgen.cli.main import app
from faultgen.model import drivetrain, rating, robots
from faultgen.monitor import life

UR5_DH = Path(__file__).resolve().parents[1] / "docs/examples/ur5_dh.toml"

# one log of four samples, 1 s apart: axis 1 a strain-wave gear, axis 2 a cycloid at its rated point
T = np.array([0.0, 1.0, 2.0, 3.0])
QD = np.array([[1.0, 1.0], [2.0, 1.0], [0.0, 1.0], [-2.0, 1.0]])
TAU = np.array([[5.0, 100.0], [-10.0, 100.0], [20.0, 100.0], [10.0, 100.0]])
RATINGS = (rating.GearboxRating("strain-wave", 10.0, 2.0, 1000.0), rating.GearboxRating("cycloid", 100.0, 1.0, 6000.0))


def test_one_logs_consumption_is_the_makers_formula_computed_by_hand():
    # axis 1: (|qd| / 2 rad/s) (|tau| / 10 N m)^3 at the samples: 0.0625, 1, 0, 1; trapezoid over
    # 1 s steps: (0.0625 + 1) / 2 + (1 + 0) / 2 + (0 + 1) / 2 = 1.53125 s at the rated point, of 1000 h
    # axis 2: at its rated torque and speed for 3 s: 3 s of 6000 h, whatever the exponent
    expected = [1.53125 / (1000 * 3600), 3.0 / (6000 * 3600)]
    assert life.consumption(T, QD, TAU, RATINGS) == pytest.approx(expected, rel=1e-12)


def test_the_catalogues_averaged_form_gives_the_same_consumption():
    # the catalogue: n_av = 3.5 rad / 3 s; T_av^3 = (trapezoid of |qd| |tau|^3 = 3062.5) / 3.5 = 875 N^3 m^3;
    # L = 1000 h (2 / n_av) (10 / T_av)^3 = 1959.18 h; the log's 3 s consume 3 s / L
    n_av, t_av = life.average_load(T, QD, TAU, RATINGS)
    assert n_av[0] == pytest.approx(3.5 / 3) and t_av[0] == pytest.approx(875 ** (1 / 3))
    rated_life = 1000.0 * (2.0 / n_av[0]) * (10.0 / t_av[0]) ** 3
    assert rated_life == pytest.approx(1000 * (2 / (3.5 / 3)) * (1000 / 875))
    assert life.consumption(T, QD, TAU, RATINGS)[0] == pytest.approx(3.0 / (rated_life * 3600), rel=1e-12)
    # twice the torque on a cycloid (p = 10/3), the life 2^(10/3) = 10.08 times shorter
    double = life.consumption(T, QD, 2 * TAU, RATINGS)
    assert double[1] / life.consumption(T, QD, TAU, RATINGS)[1] == pytest.approx(2 ** (10 / 3))


def test_a_log_of_the_wrong_shape_or_times_is_refused_naming_them():
    with pytest.raises(ValueError, match=r"qd \(4, 1\).*expected"):
        life.consumption(T, QD[:, :1], TAU, RATINGS)
    with pytest.raises(ValueError, match="2 ratings for 1 axes"):
        life.consumption(T, QD[:, :1], TAU[:, :1], RATINGS)
    with pytest.raises(ValueError, match="strictly increasing"):
        life.consumption(T[::-1], QD, TAU, RATINGS)


@dataclass
class _Entry:
    stamp: str
    load: np.ndarray | None
    duration: float


@dataclass
class _Event:
    stamp: str
    event: str
    axis: int
    at: int


def test_consumption_accumulates_between_logs_at_the_operating_hours_and_a_gearbox_change_resets_it():
    # each log: 60 s consuming 1e-6 of axis 1's and 2e-6 of axis 2's rated life (integral |qd| |tau|^p dt
    # = the share x n_N T_N^p L_n) -> per hour of operation 6e-5 and 1.2e-4; 16 h a day: 0.096 % and 0.192 %
    load = np.zeros((2, 2))
    load[0, 0] = 1e-6 * 2.0 * 10.0 ** 3 * 1000 * 3600  # strain-wave, p = 3: the first row
    load[1, 1] = 2e-6 * 1.0 * 100.0 ** (10 / 3) * 6000 * 3600  # cycloid, p = 10/3: the second
    entries = [_Entry(f"2026-03-{d:02d}", load, 60.0) for d in (1, 2, 4, 5)]
    rows = life.of_unit("u", entries, [], RATINGS, hours_per_day=16.0)
    # days counted between logs from the first: 1 + 2 + 1 = 4 days
    assert rows[0].consumed == pytest.approx(4 * 0.096) and rows[1].consumed == pytest.approx(4 * 0.192)
    assert rows[0].duty == pytest.approx(0.096)
    assert rows[0].days_left == pytest.approx((100 - 4 * 0.096) / 0.096)
    assert rows[0].since == "2026-03-01" and "first log" in rows[0].verdict
    # a gearbox change of axis 2 on 2026-03-03 (before entry 2): axis 2 counts from it, 1 + 1 days
    change = [_Event("2026-03-03", "gearbox_change", 2, 2)]
    rows = life.of_unit("u", entries, change, RATINGS, hours_per_day=16.0)
    assert rows[0].consumed == pytest.approx(4 * 0.096)
    assert rows[1].consumed == pytest.approx(2 * 0.192) and rows[1].since == "2026-03-03"
    assert "gearbox change" in rows[1].verdict
    # a repair leaves the gearbox's life as it was
    rows = life.of_unit("u", entries, [_Event("2026-03-03", "repair", 2, 2)], RATINGS)
    assert rows[1].consumed == pytest.approx(4 * 0.192)
    with pytest.raises(ValueError, match="hours_per_day = 25"):
        life.of_unit("u", entries, [], RATINGS, hours_per_day=25)


def test_service_by_is_the_earlier_of_the_load_and_the_condition_based_life():
    life_rows = [{"axis": "1", "days_left": "40"}, {"axis": "2", "days_left": ""}]
    rul_rows = [{"axis": "2", "rul": "12.4", "time_unit": "days"}]
    assert life.service_by("2026-03-01", life_rows, rul_rows) == ("2026-03-13", "condition: axis 2's wear")
    # the condition-based life at its 5 % quantile, never the median (issue 90)
    rul_rows = [{"axis": "2", "rul": "12.4", "rul_5": "6.6", "rul_95": "30", "time_unit": "days"}]
    assert life.service_by("2026-03-01", life_rows, rul_rows) == ("2026-03-07", "condition: axis 2's wear, its 5 % quantile")
    window = life.service_window(life_rows, rul_rows)
    assert (window.days, window.low, window.high, window.basis) == (6.6, 6.6, 30.0, "wear")
    assert life.service_window(life_rows, []).basis == "load"
    # a median not yet predictable (its 95 % end beyond the horizon) with its 5 % end given: that end
    only_low = [{"axis": "2", "rul": "", "rul_5": "3.5", "rul_95": "", "time_unit": "days"}]
    window = life.service_window(life_rows, only_low)
    assert (window.days, window.low, window.high, window.axis) == (3.5, 3.5, 40.0, 2)  # the upper end: the load's
    assert life.service_window([], only_low).high == math.inf
    assert life.service_by("2026-03-01", life_rows, only_low) == ("2026-03-04", "condition: axis 2's wear, its 5 % quantile")
    assert life.service_window([], [{"axis": "2", "rul": "", "rul_5": "", "time_unit": "days"}]) is None
    assert life.service_by("2026-03-01", life_rows, []) == ("2026-04-10", "load: axis 1's rated life")
    assert life.service_by("17", life_rows, []) == ("in 40 days", "load: axis 1's rated life")
    assert life.service_by("2026-03-01", [], []) == ("", "")


def test_the_defaults_follow_the_sizing_rules_and_the_catalogues():
    robot = robots.load("puma560")
    ratings = rating.of_robot(robot)
    assert [r.gearbox_type for r in ratings] == ["cycloid"] * 3 + ["strain-wave"] * 3
    assert all(r.defaults == rating.KEYS for r in ratings)
    # axis 2: its gear output's peak (about 104 N m) within RV-6E's 2.5 x 58 N m; cycloid 15 rpm, 6000 h
    assert ratings[1].rated_torque == 58.0 and not ratings[1].unrated
    # axis 4 (strain-wave): motor torque limit 0.29 N m x G 76.0364 / 2.5
    assert ratings[3].rated_torque == pytest.approx(robot.motor_torque_limit[3] * 76.0364 / 2.5, rel=1e-4)
    assert ratings[1].rated_speed == pytest.approx(15 * 2 * math.pi / 60) and ratings[1].rated_life == 6000
    # axis 4: strain-wave, 2000 rpm at the input over G 76.0364, 7000 h
    assert ratings[3].rated_speed == pytest.approx(2000 * 2 * math.pi / 60 / 76.0364) and ratings[3].rated_life == 7000


def test_drivetrain_toml_gives_the_rating_and_a_bad_one_is_refused_naming_axis_and_key(tmp_path):
    robot = robots.load("puma560")
    n = robot.n_axes
    text = (robot.path.parent / "drivetrain.toml").read_text()
    good = text.replace("[axis.2]\n", '[axis.2]\ngearbox_type = "strain-wave"\nrated_torque = 90.0\n')
    path = tmp_path / "drivetrain.toml"
    path.write_text(good)
    assert drivetrain.read_table(path, n)[2] == drivetrain.read_table(robot.path.parent / "drivetrain.toml", n)[2]
    ratings = rating.ratings(robots.drivetrain_of(robot), rating.given(path, n))
    assert ratings[1].gearbox_type == "strain-wave" and ratings[1].rated_torque == 90.0
    assert ratings[1].defaults == ("rated_speed", "rated_life") and ratings[1].rated_life == 7000  # the type's
    for bad, match in (('gearbox_type = "planetary"', "axis 2: gearbox_type = 'planetary'; expected one of"),
                       ("rated_torque = -1.0", r"axis 2: rated_torque = -1.0; expected a finite number > 0"),
                       ("rated_life = nan", r"axis 2: rated_life = nan; expected a finite number"),
                       ('rated_speed = "fast"', r"axis 2: rated_speed = 'fast'; expected"),
                       ('gearbox_type = ["cycloid"]', r"axis 2: gearbox_type = \"\['cycloid'\]\"; expected one of")):
        path.write_text(text.replace("[axis.2]\n", f"[axis.2]\n{bad}\n"))
        for read in (lambda: drivetrain.read_table(path, n), lambda: rating.given(path, n)):
            with pytest.raises(drivetrain.DrivetrainError, match=match):
                read()


def test_robots_name_prints_the_rating_with_its_defaults_marked():
    result = CliRunner().invoke(app, ["robots", "puma560"])
    assert result.exit_code == 0, result.output
    assert "rated torque [N m] (default)" in result.output
    assert "(default, or * where others are given) rated_life: cycloid 6000 h (Nabtesco RV-E, L10)" in result.output


def test_a_rating_given_to_robots_add_is_kept_in_the_folder_and_the_rest_defaults(tmp_path):
    drive = tmp_path / "drives.toml"
    drive.write_text('[axis.5]\ngearbox_type = "cycloid"\nrated_life = 9000.0\n')
    result = CliRunner().invoke(app, ["robots", "add", "ur5", "--from", str(UR5_DH), "--drivetrain", str(drive),
                                      "-o", str(tmp_path / "ur5")])
    assert result.exit_code == 0, result.output
    ratings = rating.of_robot(robots.load(tmp_path / "ur5"))
    assert (ratings[4].gearbox_type, ratings[4].rated_life, ratings[4].defaults) == \
        ("cycloid", 9000.0, ("rated_torque", "rated_speed"))
    assert ratings[3].gearbox_type == "strain-wave" and ratings[3].defaults == rating.KEYS
