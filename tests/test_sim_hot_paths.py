"""The simulation's hot paths with less Python (round 10, "ssim"), each against the plain
computation it replaced, bit for bit: the static friction model's per-step update
(``friction_update.writer`` against ``apply``), a per-step batch's thread count, the rigid inverse
dynamics that skips a sample equal to the one before, the arm's inertia along a motion computed
once, a ruckig move sampled a block at a time and the Coulomb level of one bit pattern. Whole runs
before and after: benchmarks/sim_hot_paths_identical.py (docs/performance.md)."""

import mujoco
import numpy as np
import pytest
import stepped_robot
from test_backends import short_work

from faultgen.calibrate import gearbox
from faultgen.effects.motor_friction import MotorFriction
from faultgen.model import robots
from faultgen.operation import tasks
from faultgen.simulation import batch, friction_kernel, friction_update


@pytest.fixture(scope="module")
def stepped(tmp_path_factory):
    """tests/stepped_robot.py's robot: a drift in time, load-dependent friction in both forms."""
    return str(stepped_robot.write(tmp_path_factory.mktemp("stepped")))


@pytest.mark.parametrize("compiled", [True, False])
@pytest.mark.parametrize("name", ["puma560", "irb6700", "stepped"])
def test_the_writer_writes_the_bits_of_apply(name, compiled, stepped, monkeypatch):
    """Asymmetric (PUMA 560) and one-valued (IRB-6700-like) Coulomb levels, a gear loss and, on the
    stepped robot, a drift in time (a level changing every step) and a static-load term, runs at
    rest and moving: the friction loss ``writer`` puts in the model is ``apply``'s, compiled
    (friction_kernel) and through NumPy."""
    monkeypatch.setattr(friction_kernel, "numpy_bits", lambda: compiled)
    sim, work = short_work(stepped if name == "stepped" else name, "stribeck", "batch",
                           gear_loss=np.array([np.linspace(0.01, 0.05, 6), np.linspace(0.08, 0.02, 6)]))
    runs = batch.new_runs(sim, work)
    qvel = runs.bind("qvel")
    qvel[...] = np.random.default_rng(1).normal(0.0, 30.0, qvel.shape)
    qvel[0, sim.robot.rotor_dof[2]] = 0.0  # at rest: the larger Coulomb level
    schedule = sim.stepping.schedule(sim, work)
    kinematics = tuple(runs.bind(f) for f in friction_update.KINEMATICS) if schedule.reads_start_state else None
    runs.forward()
    update = schedule.chunk(10, 40)
    loss = runs.expand("dof_frictionloss")
    write = friction_update.writer(update, qvel, runs.bind("qpos"), kinematics, loss)
    assert write.compiled == compiled
    for k in (0, 13, 29):
        expected = friction_update.apply(update, k, qvel, runs.bind("qpos"), kinematics)
        write(k)
        np.testing.assert_array_equal(loss[:, sim.robot.rotor_dof], expected)
    if name == "stepped":
        assert update.reads_kinematics and not np.array_equal(update.level[:, 0], update.level[:, 29])
    one_level = np.array_equal(sim.robot.friction.coulomb_pos, sim.robot.friction.coulomb_neg)
    assert one_level == (name == "irb6700")


def test_as_slice_picks_the_same_elements():
    values = np.arange(40.0).reshape(2, 20)
    for index in ([0, 2, 4, 6], [3], [1, 4, 7], [5, 6, 7, 8], [0, 2, 3], [4, 2], []):
        picked = friction_update.as_slice(np.array(index, dtype=int))
        np.testing.assert_array_equal(values[:, picked], values[:, index])
        assert isinstance(picked, slice) == (len(index) > 0 and (len(index) < 2 or index[1] > index[0])
                                             and len(set(np.diff(index))) <= 1)


def test_a_batch_stepped_one_step_at_a_time_on_all_cpus_takes_a_thread_per_sixteen_runs():
    assert batch.STEP_RUNS_PER_THREAD == 16
    assert [batch.step_threads(0, n) for n in (1, 4, 16, 31, 32, 100)] == [1, 1, 1, 1, 2, 6]
    assert [batch.step_threads(4, n) for n in (1, 40, 100)] == [4, 4, 4]  # the user's choice kept
    assert batch.step_threads(1, 1000) == 1


@pytest.mark.parametrize("name", ["puma560", "irb6700"])
def test_the_rigid_dynamics_of_a_repeated_sample_is_its_own(name):
    """Holds (a sample repeated), a sample differing from the one before only in its acceleration
    or in the sign of a zero: every row is what one ``mj_inverse`` of its own state gives."""
    robot = robots.load(name)
    rng = np.random.default_rng(2)
    rows = [robot.home + rng.normal(0, 0.3, robot.n_axes) for _ in range(4)]
    q = np.array([rows[0], rows[0], rows[0], rows[1], rows[1], rows[2], rows[3], rows[3]])
    qd = np.zeros_like(q)
    qd[3:5] = 0.5
    qdd = np.zeros_like(q)
    qdd[4] = 1.0  # differs from row 3 in its acceleration only
    qdd[7, 0] = -0.0  # differs from row 6 in the sign of a zero only
    tau, load = robot._rigid(q, qd, qdd)
    model = robot.model.__copy__()
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    data = mujoco.MjData(model)
    G = robot.gear_ratio
    for k in range(len(q)):
        data.qpos[robot.arm_qpos], data.qpos[robot.rotor_qpos] = q[k], G * q[k]
        data.qvel[robot.arm_dof], data.qvel[robot.rotor_dof] = qd[k], G * qd[k]
        data.qacc[robot.arm_dof], data.qacc[robot.rotor_dof] = qdd[k], G * qdd[k]
        mujoco.mj_inverse(model, data)
        force = data.qfrc_inverse
        np.testing.assert_array_equal(load[k], force[robot.arm_dof])
        np.testing.assert_array_equal(tau[k], force[robot.arm_dof] + G * force[robot.rotor_dof])
    assert robot._rigid(q[:0], qd[:0], qdd[:0])[0].shape == (0, robot.n_axes)


def test_the_arm_inertia_of_a_motion_is_computed_once():
    robot = robots.load("irb6700")
    q = robot.home + 0.2 * np.sin(np.outer(np.arange(30) * 0.01, np.arange(1, 7)))
    first = gearbox._arm_mass(robot, q)
    assert gearbox._arm_mass(robot, q.copy()) is first and not first.flags.writeable
    np.testing.assert_array_equal(first, robot.arm_mass_matrix(q))
    moved = q.copy()
    moved[5, 1] += 1e-9
    other = gearbox._arm_mass(robot, moved)
    assert other is not first
    np.testing.assert_array_equal(other, robot.arm_mass_matrix(moved))
    puma = robots.load("puma560")
    np.testing.assert_array_equal(gearbox._arm_mass(puma, q), puma.arm_mass_matrix(q))


def test_a_move_is_sampled_a_block_at_a_time_as_one_sample_at_a_time(monkeypatch):
    """A move of more samples than a block (and a last block that is not full): the samples are
    ruckig's own, sample by sample."""
    monkeypatch.setattr(tasks, "SAMPLE_BLOCK", 700)
    start, goal = np.zeros(6), np.linspace(0.3, 1.2, 6)
    limits = (np.full(6, 2.0), np.full(6, 6.0), np.full(6, 60.0))
    q, qd, qdd = tasks.ptp(start, goal, *limits, dt=0.0005, where="test")
    assert len(q) > 2 * 700 and (len(q) - 1) % 700 != 0
    from ruckig import DurationDiscretization, InputParameter, Ruckig, Trajectory

    inp = InputParameter(6)
    inp.current_position, inp.target_position = start, goal
    inp.current_velocity = inp.current_acceleration = np.zeros(6)
    inp.target_velocity = inp.target_acceleration = np.zeros(6)
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = limits
    inp.duration_discretization = DurationDiscretization.Discrete
    trajectory = Trajectory(6)
    Ruckig(6, tasks.PLAN_PERIOD).calculate(inp, trajectory)
    for k in range(len(q) - 1):
        p, v, a = trajectory.at_time(k * 0.0005)
        assert q[k].tolist() == p and qd[k].tolist() == v and qdd[k].tolist() == a
    np.testing.assert_array_equal(q[-1], goal)
    assert not qd[-1].any() and not qdd[-1].any()


def test_one_coulomb_level_gives_the_bits_of_the_branch_on_the_sign():
    """Both directions' levels of the same bits: the level and torque are those of eq. 6.3 with the
    branch on the speed's sign (written out here); a level differing by the sign of a zero keeps it."""
    v = np.random.default_rng(4).normal(0.0, 40.0, (50, 3))
    v[::7] = 0.0
    for neg in ([0.4, 0.2, 0.0], [0.4, 0.2, -0.0]):
        f = MotorFriction(coulomb_pos=[0.4, 0.2, 0.0], coulomb_neg=neg, static=[0.1, 0.05, 0.02],
                          stribeck_velocity=[5.0, 9.0, 2.0], stribeck_exponent=[2.0, 1.0, 2.0],
                          viscous=[0.01, 0.02, 0.0])
        assert f._one_coulomb == (np.signbit(neg[2]) == 0)
        coulomb = np.where(v > 0, f.coulomb_pos, np.where(v < 0, f.coulomb_neg, np.maximum(f.coulomb_pos,
                                                                                         f.coulomb_neg)))
        stribeck = f.static * np.exp(-np.abs(v / f.stribeck_velocity) ** f.stribeck_exponent)
        np.testing.assert_array_equal(f.stribeck_level(v, 1.5), (coulomb + stribeck) * 1.5)
        torque = (np.where(v > 0, f.coulomb_pos, f.coulomb_neg) + stribeck) * np.sign(v) + f.viscous * v
        np.testing.assert_array_equal(f.stribeck_torque(v), torque)
