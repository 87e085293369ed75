"""Friction tests in fleets (issue 75, item 1's fleets): ``faultgen fleet --friction-test-every``
(a robot's test run beside its daily records, labelled, read back as a log) and the independent
fleets' tests (:mod:`faultgen.bench.independent`, ``FleetSpec.friction_test_every``: faultgen's test
motion through Pinocchio and the fleet's own friction law, their truth in truth_tests.csv).

The full check of the independent fleets' tests (3 units x 60 days, a test every 14 days, both laws)
is ``benchmarks/fleet_friction_tests.py`` (docs/friction-test.md, "Tests in a fleet")."""

import csv
import dataclasses

import numpy as np
import pinocchio_log
import pytest

import faultgen
from faultgen.bench import independent
from faultgen.calibrate import friction_report
from faultgen.data import dataset, friction_records, validator, writer
from faultgen.logs import measured
from faultgen.model import robots
from faultgen.operation import friction_test, programs
from faultgen.runs import fleet
from faultgen.simulation import stepping as sim

SMALL = dict(size=2, days=6, cycles_per_day=1, models=("puma560",), failure_wear=50.0)


@pytest.fixture(scope="module")
def tested(tmp_path_factory):
    """The small fleet with a test every 5 days, and its runs (the test programs written into a cache
    folder of the test's own)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("FAULTGEN_CACHE", str(tmp_path_factory.mktemp("cache")))
        plan = fleet.Fleet(**SMALL, friction_test_every=5)
        return plan, plan.runs()


def test_a_fleet_without_tests_is_todays_and_with_tests_adds_one_labelled_test_run_per_robot(tested):
    plain, (tested, after) = fleet.Fleet(**SMALL), tested
    before = plain.runs()
    # without the option: no test run, and the stored settings lack the field (as before it existed)
    assert "friction_test_every" not in plain.to_json() and '"friction_test_every": 5' in tested.to_json()
    assert [r for r, _ in after[0::2]] == [r for r, _ in before]
    assert [dataset.config_key(c) for _, c in after[0::2]] == [dataset.config_key(c) for _, c in before]
    assert [r for r, _ in after[1::2]] == [r + fleet.TEST_SUFFIX for r, _ in before]
    for (_, daily), (_, test) in zip(after[0::2], after[1::2]):
        assert test.recorded_cycles.tolist() == [1, 6] and test.signals and not test.daily
        assert test.wear == daily.wear and test.seed == daily.seed and test.cycles == daily.cycles
        assert test.conditions.payloads is None and test.conditions.thermal == daily.conditions.thermal
        assert writer.is_friction_test(programs.record(test.task)) and not writer.is_friction_test(
            programs.record(daily.task))
    with pytest.raises(ValueError, match=r"^fleet friction_test_every \(--friction-test-every\) = 3651: expected a "
                                         r"whole number within 0\.\.3650$"):
        fleet.Fleet(**SMALL, friction_test_every=3651)
    assert fleet.Fleet(**SMALL, friction_test_every=30).test_days() == [1]  # longer than the fleet: day 1 only


def test_a_fleet_test_record_reads_back_as_the_robots_dry_level_at_its_wear(tested, tmp_path):
    """The failing robot's test on its failure day (wear 1.5 on its axis), simulated, written and
    merged with its daily run as `faultgen fleet` does: the typed reader keeps it beside the runs,
    labelled; read back as a log (friction_records.log, friction_report.read: what `faultgen
    friction-test` does), each axis tested (the worn one and axis 1) has its dry level is the robot's nominal Coulomb friction times the
    run's own truth (wear multiplier, temperature and unit-spread factor) within 2 %, its viscous
    coefficient within 5 % (not independent: faultgen's model simulated and read; the plumbing)."""
    plan, runs = tested
    runs = dict(runs)
    failing = next(r for r in runs if r.endswith("failing"))
    test = runs[failing + fleet.TEST_SUFFIX]
    # the fleet's test run on its last test day, its program cut to the worn axis and axis 1 (5
    # speeds each: 70 s of motion, not 256 s; the same program maker, faultgen.operation.friction_test)
    worn = test.wear.worn_axes[0]
    short = tmp_path / "short.toml"
    short.write_text(friction_test.text(test.model, sorted({1, worn}), 5))
    test = dataclasses.replace(test, task=str(short), record=(6,))
    parts = []
    for run_id, config in ((failing, runs[failing]), (failing + fleet.TEST_SUFFIX, test)):
        parts.append((run_id, writer.write_run(tmp_path / f"{run_id}.h5", sim.simulate(config, progress=False),
                                                run_id)))
    path = dataset.merge(parts, tmp_path / "fleet.h5", grid=plan.to_json())
    assert validator.validate(path) == []
    robot = robots.load("puma560")
    with faultgen.open(path) as data:
        assert [r.id for r in data.runs] == [failing] and not data.runs[0].friction_test
        (record,) = data.friction_tests
        assert record.id == failing + fleet.TEST_SUFFIX and record.recorded.tolist() == [6]
        wear, dry = record.array("friction_multiplier")[0], record.array("dry_friction_factor")[0]
        viscous = record.array("viscous_factor")[0]
        assert wear.max() == pytest.approx(1.5)
        fits = friction_report.read(friction_records.log(record, 0, robot), robot).fits
        written = measured.read(friction_records.write(record, 0, tmp_path / "test.csv"), robot)
        as_log = friction_records.log(record, 0, robot)  # the file holds the log, to the CSV's digits
        assert np.allclose(written.tau, as_log.tau, rtol=1e-6) and np.allclose(written.q, as_log.q, rtol=1e-9)
    f, G = robot.friction, robot.gear_ratio
    axes = fits["axis"].to_numpy() - 1
    assert axes.tolist() == sorted({0, worn - 1}) and int(np.argmax(wear)) == worn - 1
    truth_dry = (G * (f.coulomb_pos + f.coulomb_neg) / 2 * wear * dry)[axes]
    truth_viscous = (G**2 * f.viscous * viscous)[axes]
    assert np.allclose(fits["coulomb_Nm"], truth_dry, rtol=0.02), fits["coulomb_Nm"].to_numpy() / truth_dry
    assert np.allclose(fits["viscous_Nms_rad"], truth_viscous, rtol=0.05), fits["viscous_Nms_rad"] / truth_viscous
    unworn = fits["coulomb_Nm"].to_numpy()[-1] / (truth_dry[-1] / 1.5)
    assert unworn == pytest.approx(1.5, rel=0.02)  # the worn axis reads 1.5 times its unworn level
    with pytest.raises(ValueError, match="is not a friction test"):
        with faultgen.open(path) as data:
            friction_records.log(data.runs[0], 0, robot)


@pytest.fixture(scope="module")
def kr210(tmp_path_factory):
    return pinocchio_log.add_kr210(tmp_path_factory.mktemp("kr210") / "kr210")


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_an_independent_units_test_reads_its_plants_friction_and_leaves_its_logs_as_they_were(kr210, tmp_path):
    """1 unit x 1 test of the independent fleet (Pinocchio, its Lorentzian law): the daily logs and
    truth.csv are the same bytes with and without tests; the test log (faultgen's motion through
    the plant) read by faultgen gives every axis's dry level within 3 % and viscous coefficient
    within 10 % of truth_tests.csv (the issue's criterion, here on faultgen's own motion)."""
    spec = independent.FleetSpec(units=1, worn=1, days=2, seed=3, onset=(1, 1))
    plain_logs, _ = independent.write_fleet(tmp_path / "plain", spec, kr210)
    logs, _ = independent.write_fleet(tmp_path / "tested", dataclasses.replace(spec, friction_test_every=14), kr210)
    for day in independent.stamps(spec):
        assert (logs / "unit01" / f"{day}.csv").read_bytes() == (plain_logs / "unit01" / f"{day}.csv").read_bytes()
    assert (tmp_path / "tested/truth.csv").read_bytes() == (tmp_path / "plain/truth.csv").read_bytes()
    assert not (plain_logs / "unit01" / independent.TEST_FOLDER).exists()
    assert not (tmp_path / "plain/truth_tests.csv").exists()
    tests = sorted((logs / "unit01" / independent.TEST_FOLDER).iterdir())
    assert [p.name for p in tests] == ["2026-01-05.csv"]
    truth = read_rows(tmp_path / "tested/truth_tests.csv")
    assert list(truth[0]) == list(independent.TEST_TRUTH_COLUMNS) and len(truth) == 6
    robot = robots.load(kr210)
    log = measured.read(tests[0], robot, accelerations=False)
    assert np.all(log.payload_mass == 0.0)
    assert np.allclose(log.joint_temperature[0], [float(r["temperature_degC"]) for r in truth])
    fits = friction_report.read(log, robot).fits
    dry = fits["coulomb_Nm"].to_numpy() / np.array([float(r["coulomb_Nm"]) for r in truth]) - 1
    viscous = fits["viscous_Nms_rad"].to_numpy() / np.array([float(r["viscous_Nms_rad"]) for r in truth]) - 1
    assert np.all(np.abs(dry) < 0.03), dry
    assert np.all(np.abs(viscous) < 0.10), viscous
    # a resumed write keeps the complete unit and draws the same truth of its tests
    again = (tmp_path / "tested/truth_tests.csv").read_bytes()
    independent.write_fleet(tmp_path / "tested", dataclasses.replace(spec, friction_test_every=14), kr210)
    assert (tmp_path / "tested/truth_tests.csv").read_bytes() == again


def test_a_negative_test_interval_is_refused_by_name():
    with pytest.raises(ValueError, match=r"^fleet friction_test_every = -1: expected a whole number >= 0$"):
        independent.FleetSpec(units=2, worn=1, friction_test_every=-1)


def test_a_tests_scatter_scales_the_same_draws_and_a_bad_one_is_refused_by_name():
    """``FleetSpec.test_jitter``: the default is a log's scatter (the fleets drawn before the option
    existed are the same); another scatter scales the same standard normal draws (a fleet compared
    at two scatters differs in that alone), and its temperature and noise stream are unchanged."""
    spec = independent.FleetSpec(units=2, worn=1, seed=3)
    assert spec.test_jitter == independent.JITTER == 0.03
    unit = independent._units(spec, 6)[0]
    temperature = np.full(6, 31.0)
    warm, log_jitter, rng = independent.friction_test_draws(unit, 15, temperature, 6)
    same = independent.friction_test_draws(unit, 15, temperature, 6, scatter=independent.JITTER)
    less = independent.friction_test_draws(unit, 15, temperature, 6, scatter=0.01)
    assert np.array_equal(same[1], log_jitter) and np.array_equal(less[0], warm)
    assert np.allclose(np.log(less[1]), np.log(log_jitter) / 3, rtol=1e-12, atol=0)
    assert less[2].random() == rng.random()  # the test's noise draws follow unchanged
    for bad in (-0.01, 0.6, True):
        with pytest.raises(ValueError, match=rf"^fleet test_jitter = {bad!r}: expected a friction test's scatter "):
            independent.FleetSpec(test_jitter=bad)
