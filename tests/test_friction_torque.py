"""The monitor's ``friction_torque`` feature (faultgen.monitor.logs.friction_torque) against
closed-form values: the mean |friction| over a rest-to-rest motion, the inertial torque's zero, and
a change of the friction's shape read as the change of its mean, not of its peak.

Independent of faultgen's simulator: the torques are written here from the motion's closed form
(a rest-to-rest cosine move of each axis, there and back), not simulated."""

from __future__ import annotations

import numpy as np
import pytest

from faultgen.logs import measured
from faultgen.model import robots
from faultgen.monitor import logs as fleet_logs
from faultgen.operation import programs

RATE = 500.0  # Hz


@pytest.fixture(scope="module")
def robot():
    return robots.load("puma560")


def _motion(n_axes: int):
    """Each axis moves out and back by 0.6 rad in two rest-to-rest cosine moves of 2 s, with 0.5 s
    standing still before, between and after. Returns t, q, qd, qdd (arm side)."""
    t = np.arange(0.0, 5.5, 1.0 / RATE)
    q, qd, qdd = (np.zeros((len(t), n_axes)) for _ in range(3))
    for start, sign in ((0.5, 1.0), (3.0, -1.0)):
        s = (t >= start) & (t < start + 2.0)
        phase = np.pi * (t[s] - start) / 2.0
        amplitude = 0.3 * sign  # q moves by 2 * amplitude
        q[s] += amplitude * (1 - np.cos(phase))[:, None]
        qd[s] += (amplitude * np.pi / 2.0 * np.sin(phase))[:, None]
        qdd[s] += (amplitude * (np.pi / 2.0) ** 2 * np.cos(phase))[:, None]
        q[t >= start + 2.0] += 2 * amplitude
    return t, q, qd, qdd


def _friction(w_motor: np.ndarray, coulomb: float, hump: float, speed: float) -> np.ndarray:
    """Motor-side dry friction, N m: Coulomb plus a Lorentzian Stribeck hump, smooth sign."""
    return (coulomb + hump / (1.0 + (w_motor / speed) ** 2)) * np.tanh(w_motor / 0.05)


def _feature(robot, t, q, qd, tau_motor):
    data = measured.from_arrays(t, q, tau_motor * robot.gear_ratio, robot, qd=qd)
    return fleet_logs.friction_torque(robot, data)[0]


def test_inertial_torque_alone_reads_zero(robot):
    t, q, qd, qdd = _motion(robot.n_axes)
    inertia = 0.02  # kg m^2 at the motor
    tau_motor = inertia * robot.gear_ratio * qdd
    assert np.max(np.abs(_feature(robot, t, q, qd, tau_motor))) < 1e-3 * np.max(np.abs(tau_motor))


def test_reads_the_mean_dry_friction_over_the_motion_and_its_change_whatever_the_shape(robot):
    t, q, qd, qdd = _motion(robot.n_axes)
    w = robot.gear_ratio * qd  # motor speed, rad/s
    inertia, gravity = 0.02, 0.3  # kg m^2, N m: gravity the same each way, so it cancels there and back
    rigid = inertia * robot.gear_ratio * qdd + gravity
    healthy = _friction(w, 0.4, 0.2, 3.0)
    # a worn shape: the Coulomb level +10 %, the hump tripled and widened, as the hump law of
    # benchmarks/wear_hump_fleet.py grows it
    worn = _friction(w, 0.44, 0.6, 6.0)
    before = _feature(robot, t, q, qd, rigid + healthy)
    after = _feature(robot, t, q, qd, rigid + worn)
    # the closed form: the mean |friction| over the samples moving faster than MOVING_SPEED of the
    # axis's speed limit (the others count 0)
    moving = np.abs(qd) > fleet_logs.MOVING_SPEED * programs.robot_limits(robot)[0]
    np.testing.assert_allclose(before, np.mean(np.abs(healthy) * moving, axis=0), rtol=0.01)
    change = after - before
    np.testing.assert_allclose(change, np.mean((np.abs(worn) - np.abs(healthy)) * moving, axis=0), rtol=0.01)
    # what the slow samples leave out: a few % of the mean over every sample on this motion
    assert np.all(before > 0.93 * np.mean(np.abs(healthy), axis=0))
    # neither the Coulomb level's change alone (0.04 N m) nor the change at standstill (0.44 N m)
    assert np.all((change > 1.5 * 0.04) & (change < 0.5 * 0.44))


def test_is_one_of_the_monitor_features(robot):
    t, q, qd, qdd = _motion(robot.n_axes)
    tau_motor = _friction(robot.gear_ratio * qd, 0.4, 0.2, 3.0)
    data = measured.from_arrays(t, q, tau_motor * robot.gear_ratio, robot, qd=qd)
    vector = fleet_logs.features_of(robot, data)
    n = robot.n_axes
    k = fleet_logs.FEATURES.index("friction_torque")
    assert vector.shape == (len(fleet_logs.FEATURES) * n,)
    np.testing.assert_array_equal(vector[k * n:(k + 1) * n], fleet_logs.friction_torque(robot, data)[0])
