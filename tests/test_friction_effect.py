"""The robot's motor friction as a registered effect, and friction wear as a relative Fault on it (issue 37)."""

import math

import mujoco
import numpy as np
import pytest

from faultgen import effects
from faultgen.effects.motor_friction import FIELDS, MotorFriction
from faultgen.model import robots
from faultgen.operation.faults import Fault, dry_multipliers, parse_fault
from faultgen.operation.wear import Schedule, WearPlan
from resolved_runs import run_config


def test_motor_friction_is_a_registered_effect_but_no_calibration_candidate():
    robot = robots.load("puma560")
    assert isinstance(robot.friction, MotorFriction)
    assert type(effects.get(MotorFriction.id)) is MotorFriction
    assert MotorFriction.id in effects.REGISTRY and MotorFriction.id not in effects.EFFECTS
    assert MotorFriction.id not in robot.effects  # held once, as robot.friction
    assert list(robot.friction.units) == list(FIELDS)
    assert robot.friction.table()["coulomb_pos"] == [float(v) for v in robot.friction.coulomb_pos]


@pytest.mark.parametrize("name", ["puma560", "irb6700"])
def test_read_apply_round_trip(name):
    """Values written by the effect's apply into the robot's MjSpec are what its read gives back
    from the compiled model, bit for bit; the nominal ones read back as the robot's."""
    robot = robots.load(name)
    assert MotorFriction.read(robot.model, robot.path) == robot.friction
    rng = np.random.default_rng(0)
    rows = robot.friction.as_rows() * rng.uniform(0.5, 2.0, robot.friction.as_rows().shape)
    rows[:, FIELDS.index("stribeck_exponent")] = rng.uniform(0.5, 2.0, robot.n_axes)
    changed = MotorFriction.from_rows(rows)
    spec = mujoco.MjSpec.from_file(str(robot.path))
    changed.write(spec, robot)
    back = MotorFriction.read(spec.compile(), robot.path)
    assert back == changed
    np.testing.assert_array_equal(back.as_rows(), rows)


def test_a_friction_parameter_effect_writes_into_the_motor_friction():
    """coulomb (a calibration candidate, a change of part of the motor friction) written on axis 2
    changes those values of the motor friction read back, and nothing else."""
    robot = robots.load("puma560")
    spec = mujoco.MjSpec.from_file(str(robot.path))
    effects.make("coulomb", coulomb_pos=[0.5] * robot.n_axes, coulomb_neg=[0.25] * robot.n_axes).write(spec, robot, [1])
    back = MotorFriction.read(spec.compile(), robot.path).as_rows()
    expected = robot.friction.as_rows()
    expected[1, :2] = [0.5, 0.25]
    np.testing.assert_array_equal(back, expected)


def test_an_invalid_friction_value_names_axis_and_field():
    with pytest.raises(ValueError, match=r"axis 2: friction static = -1\.0 N m, expected a finite value >= 0"):
        MotorFriction(static=[0.1, -1.0])


def test_wear_as_a_fault_is_thesis_eq_6_6():
    """p = 0.5, K = 100: at k = 80, (1 + p)^((k/K)^4) = 1.5^0.4096 = exp(0.4096 ln 1.5) = 1.18067
    (by hand: ln 1.5 = 0.405465, times 0.4096 = 0.166078, exp = 1.180666), not the absolute
    fault's start + (final - start)(2^((k/K)^4) - 1) = 1 + 0.5 (2^0.4096 - 1) = 1.16424."""
    (fault,) = WearPlan.from_specs(["2:exp4:50"], last_cycle=100).faults()
    assert (fault.effect, fault.axis, fault.parameter, fault.growth) == (MotorFriction.id, 2, "dry", "relative")
    assert fault.parameters == ("coulomb_pos", "coulomb_neg", "static")
    m = float(fault.values(np.array([80]))[0])
    assert m == pytest.approx(1.180666, abs=1e-6)
    assert m == pytest.approx(math.exp(0.4096 * math.log(1.5)), rel=1e-14)
    assert abs(m - 1.16424) > 0.01
    assert fault.values(np.array([0, 100])).tolist() == [1.0, pytest.approx(1.5, rel=1e-14)]
    robot = robots.load("puma560")
    worn = fault.scaled(robot.friction, 80)
    for name in FIELDS:
        expected = getattr(robot.friction, name).copy()
        if name in fault.parameters:
            expected[1] *= m
        np.testing.assert_array_equal(getattr(worn, name), expected)


@pytest.mark.parametrize("spec", ["2:exp4:20", "3:exp4:50:onset=40", "4:logistic:10:shape=2", "5:step:30",
                                  "1:linear:5", "6:step:20:step_cycle=7"])
def test_the_wear_fault_is_the_schedule_bit_for_bit(spec):
    """The simulation's multipliers (through the faults) equal the schedule's own, bit for bit: one path."""
    plan = WearPlan.from_specs([spec], last_cycle=100)
    (axis, schedule), = plan.schedules.items()
    k = np.arange(0, 121)
    got = dry_multipliers(plan.faults(), k, 6)
    assert np.array_equal(got[:, axis - 1], schedule.multiplier(k))
    assert np.array_equal(np.delete(got, axis - 1, axis=1), np.ones((len(k), 5)))
    assert np.array_equal(plan.multipliers(k, 6), got)


def test_relative_faults_are_checked():
    with pytest.raises(ValueError, match=r"motor_friction has no group 'coulomb_pos' \(it has: dry\)"):
        Fault(MotorFriction.id, 2, "coulomb_pos", 0.2, 10, growth="relative")
    with pytest.raises(ValueError, match=r"start = 0"):
        Fault(MotorFriction.id, 2, "dry", 0.2, 10, growth="relative", start=0.1)
    with pytest.raises(ValueError, match=r"backlash has no group 'dry' \(it has none\)"):
        Fault("backlash", 2, "dry", 0.2, 10, growth="relative")
    with pytest.raises(ValueError, match=r"beyond the bound"):
        Fault(MotorFriction.id, 2, "dry", 9.0, 10, growth="relative")
    with pytest.raises(ValueError, match=r"growth 'grown'"):
        Fault(MotorFriction.id, 2, "dry", 0.2, 10, growth="grown")


def test_two_wear_faults_on_one_axis_are_refused():
    one = WearPlan.from_specs(["2:exp4:20"], last_cycle=10).faults()
    other = WearPlan.from_specs(["2:linear:10"], last_cycle=10).faults()
    with pytest.raises(ValueError, match=r"axis 2 has two friction wear faults"):
        dry_multipliers(one + other, np.arange(3), 6)


def test_a_fault_beside_wear_on_the_same_axis():
    """Friction wear and another effect's fault on one axis combine (their own truth arrays); a
    relative friction fault given as the run's fault is refused: friction wear is given as wear."""
    wear = WearPlan.from_specs(["2:exp4:20"], last_cycle=10)
    backlash = parse_fault("backlash:2:width:0.01", last_cycle=10)
    config = run_config("puma560", "pick_place", wear=wear, cycles=10, fault=backlash)
    assert config.faults == (*wear.faults(), backlash)
    with pytest.raises(ValueError, match=r"friction wear, given as wear"):
        run_config("puma560", "pick_place", cycles=10, fault=wear.faults()[0])
    assert Schedule("exp4", 0.2, 10) == wear.faults()[0].schedule
