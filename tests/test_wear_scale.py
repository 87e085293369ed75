"""The wear in the robot's own scale (issue 59, part 1): the twin's wear signatures at the model's
own friction answer like a unit of an independent simulator, each log's estimate has a 90 %
interval that carries the twin's model uncertainty beside its noise, and ``wear.csv`` holds them."""

import csv

import numpy as np
import pinocchio_log
import pytest
from scipy.stats import norm

from faultgen.bench import independent
from faultgen.logs import measured
from faultgen.data import logfiles
from faultgen.model import robots
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import report, steps
from faultgen.monitor.wear import WearEstimator
from faultgen.monitor.history import UnitHistory
from faultgen.monitor.scoring import SCALE_UNCERTAINTY, WEAR_INTERVAL, Settings
from faultgen.monitor.twin import WEAR, Twin


def test_the_interval_is_the_estimate_with_its_noise_and_the_scale_uncertainty():
    estimate, error = np.array([20.0, 0.0, -4.0]), np.array([2.0, 3.0, 1.0])
    low, high = WearEstimator.wear_interval(estimate, error)
    half = norm.ppf(0.5 + WEAR_INTERVAL / 2) * np.sqrt(error**2 + (SCALE_UNCERTAINTY * estimate) ** 2)
    np.testing.assert_allclose(low, estimate - half)
    np.testing.assert_allclose(high, estimate + half)
    assert WEAR_INTERVAL == 0.90 and high[0] - low[0] > 2 * norm.ppf(0.95) * error[0]  # wider than the noise's


def test_the_interval_covers_nine_in_ten_when_the_scale_is_off_by_its_stated_uncertainty():
    # a unit whose features answer its wear k times the twin's (k normal about 1, sd the stated
    # scale uncertainty) plus noise: the 90 % interval covers the truth on 86-94 % of 4000 draws;
    # the noise's interval alone covers far fewer at these wears
    rng = np.random.default_rng(0)
    truth = rng.uniform(10.0, 40.0, 4000)
    error = rng.uniform(0.5, 3.0, truth.size)
    estimate = truth * rng.normal(1.0, SCALE_UNCERTAINTY, truth.size) + rng.normal(0.0, 1.0, truth.size) * error
    low, high = WearEstimator.wear_interval(estimate, error)
    covered = np.mean((low <= truth) & (truth <= high))
    assert 0.86 <= covered <= 0.94, covered
    noise_only = np.mean(np.abs(estimate - truth) <= norm.ppf(0.95) * error)
    assert noise_only < 0.75, noise_only  # 0.62: far from the 0.9 it claims


def _unit_with_scatter_along(axis: int, scatter: float, seed: int, correct: bool = True) -> tuple[UnitHistory, np.ndarray]:
    """A twin unit whose every log scatters ``scatter`` % of wear along ``axis``'s signature (a
    log's friction scatter) beside independent noise; 40 learning logs, 200 healthy logs after.
    Returns the monitor and the later logs' wear estimates over their errors on that axis."""
    rng = np.random.default_rng(seed)
    signatures = np.abs(rng.normal(0, 1, (6, 18))) * 0.05
    unit = steps.start("u", Settings(train=40), n_axes=6, signatures=signatures)
    z = []
    for i in range(240):
        residual = rng.normal(0, 0.05, 18) + rng.normal(0, scatter) * signatures[axis - 1]
        steps.add(unit, f"{i:03d}", residual, 30.0, 100.0, np.zeros(18))
        if i == 39 and not correct:
            unit.stages.baseline.dispersion_ = np.ones(6)
        if i >= 40:
            row = unit.rows[-1]
            error = (row.wear.log[axis - 1] - row.wear.log_lower[axis - 1]) / unit.stages.wear.bound_quantile
            z.append(row.wear.log[axis - 1] / error)
    return unit, np.array(z)


def test_a_scatter_along_a_signature_widens_the_error_to_what_the_later_logs_show():
    # the features' noise is not independent: a log's friction scatter moves an axis's features
    # together; measured on the learning logs, it widens the errors so that the later healthy logs'
    # estimates scatter by about one error (0.85-1.25, the mean over 4 units of 200 logs each), where
    # the error of independent noise alone understates it (> 2); without the scatter it stays 1-1.3
    spreads, uncorrected = [], []
    for seed in range(4):
        unit, z = _unit_with_scatter_along(3, 3.0, seed=seed)
        assert unit.stages.baseline.dispersion_[2] > 1.5, unit.stages.baseline.dispersion_
        spreads.append(np.std(z))
        uncorrected.append(np.std(_unit_with_scatter_along(3, 3.0, seed=seed, correct=False)[1]))
        quiet, _ = _unit_with_scatter_along(3, 0.0, seed=seed)
        assert np.all(quiet.stages.baseline.dispersion_ <= 1.3), quiet.stages.baseline.dispersion_
    assert 0.85 <= np.mean(spreads) <= 1.25, spreads
    assert np.mean(uncorrected) > 2.0, uncorrected


def test_wear_csv_holds_each_log_and_axis_estimate_with_its_interval_as_scores_csv(tmp_path):
    rng = np.random.default_rng(5)
    signatures = np.abs(rng.normal(0, 1, (6, 18))) * 0.05
    unit = steps.start("unit01", Settings(train=20), n_axes=6, signatures=signatures)
    own = steps.start("unit02", Settings(protocol="own", train=20), n_axes=6)
    for i in range(40):
        steps.add(unit, f"{i:03d}", rng.normal(0, 0.05, 18) + max(i - 25, 0) * signatures[1], 30.0, 0.0, np.zeros(18))
        steps.add(own, f"{i:03d}", rng.normal(0, 0.05, 18), 30.0, 0.0)
    report.wear_table([unit, own]).write(tmp_path)
    report.scores_table([unit, own], 6).write(tmp_path)
    with open(tmp_path / "wear.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    with open(tmp_path / "scores.csv", newline="") as f:
        scores = {r["stamp"]: r for r in csv.DictReader(f) if r["unit"] == "unit01"}
    assert tuple(rows[0]) == report.WEAR_COLUMNS
    assert len(rows) == 40 * 6 and {r["unit"] for r in rows} == {"unit01"}  # the unit without a twin has none
    for r in rows:
        s = scores[r["stamp"]]
        assert r["phase"] == s["phase"]
        assert float(r["wear"]) == pytest.approx(float(s[f"wear{r['axis']}"]), rel=1e-5)
        assert float(r["wear_lower"]) == pytest.approx(float(s[f"wear{r['axis']}_lower"]), rel=1e-5, abs=1e-9)
        assert float(r["wear_5"]) < float(r["wear"]) < float(r["wear_95"])
    last = next(r for r in rows if r["stamp"] == "039" and r["axis"] == "2")
    assert float(last["wear_5"]) <= 14.0 <= float(last["wear_95"])  # the planted 14 % on axis 2


@pytest.fixture(scope="module")
def kr210(tmp_path_factory):
    return pinocchio_log.add_kr210(tmp_path_factory.mktemp("kr210") / "kr210")


def test_the_twins_signatures_answer_like_an_independent_unit_per_percent_of_its_own_dry_friction(kr210, tmp_path):
    """The independent simulator (Pinocchio's dynamics, its own Lorentzian friction law with a
    viscous friction falling 2 %/K, faultgen.bench.independent) with the folder's nominal friction,
    noise-free, its joints at 20 and 40 deg C, no part and 25 kg: the change of its features per %
    of its dry friction (Coulomb and Stribeck) grown on one axis, projected on the twin's signature
    of that axis (least squares), is 0.85-1.15 of it on axes 1-5. At 20 deg C under faultgen's
    temperature law (1.30 times the dry and 2.86 times the viscous friction), as before issue 59,
    the twin's signatures were 1.6-2.1 times larger: those ratios stay below 0.75 (0.55-0.71; the
    friction torque, linear in the dry friction, only by the law's 1.30). The friction torque alone
    (``faultgen.monitor.logs.friction_torque``) answers 0.97-1.05 of its signature on every axis,
    temperature and part (1.02 measured, 2026-11-26): it reads the dry friction's mean, whatever
    the law."""
    robot = robots.load(kr210)
    gear, jm, friction = robot.gear_ratio, robot.motor_inertia, robot.friction
    fc, fs, fv = (np.asarray(x, dtype=float) for x in (friction.coulomb_pos, friction.static, friction.viscous))
    t, q, qd, qdd = independent._motion(robot, 125.0)

    def features(temperature, mass, axis=0, wear=0.0):
        grow = np.ones(robot.n_axes)
        if axis:
            grow[axis - 1] += wear / 100.0
        viscous = fv * np.exp(-independent.VISCOUS_PER_K * (temperature - 20.0))
        tau = (independent._rigid(robot, 125.0, mass) + gear**2 * jm * qdd
               + gear * independent.motor_friction(gear * qd, fc * grow, fs * grow, viscous))
        return fleet_logs.features_of(robot, measured.from_arrays(t, q, tau, robot))

    program = logfiles.write_csv(tmp_path / "program.csv", t, q, independent._rigid(robot, 125.0, 0.0))
    twin = Twin(robot, program, tmp_path / "cache" / "cycles")
    healthy20 = twin.cycle(20.0, 0.0)
    at20 = np.stack([(twin.cycle(20.0, 0.0, a) - healthy20) / WEAR for a in range(1, 6)])
    for temperature in (20.0, 40.0):
        for mass in (0.0, 25.0):
            base = features(temperature, mass)
            for a in range(1, 6):
                change = (features(temperature, mass, a, WEAR) - base) / WEAR
                s = twin.signatures[a - 1]
                ratio = float(s @ change / (s @ s))
                assert 0.85 <= ratio <= 1.15, (temperature, mass, a, ratio)
                before = float(at20[a - 1] @ change / (at20[a - 1] @ at20[a - 1]))
                assert before < 0.75, (temperature, mass, a, before)
                k = fleet_logs.FEATURES.index("friction_torque") * robot.n_axes + a - 1
                assert 0.97 <= change[k] / s[k] <= 1.05, (temperature, mass, a, change[k] / s[k])
