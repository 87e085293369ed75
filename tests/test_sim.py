"""The simulation core: wear reaches the motor torque, runs repeat bit for bit, long runs stay clean."""

import shutil

import mujoco
import numpy as np
import pytest

from faultgen.model import robots
from faultgen.operation import tasks
from faultgen.operation.wear import WearPlan
from faultgen.simulation import control
from faultgen.simulation import stepping as sim
from faultgen.simulation.sensors import NoiseConfig
from resolved_runs import run_config


def run(task="pick_place", wear=(), robot="irb6700", friction="lugre", **kwargs):
    plan = WearPlan.from_specs(list(wear), last_cycle=kwargs.get("cycles", 100))
    return sim.simulate(run_config(robot=robot, task=task, friction=friction, wear=plan, **kwargs),
                        progress=False)


@pytest.fixture(scope="module")
def nominal_last_cycle():
    return run(record=(100,))


@pytest.mark.parametrize("axis", range(1, 7))
def test_wear_on_an_axis_reaches_its_motor_torque_as_the_added_friction(axis, nominal_last_cycle):
    """Thesis Table 6.1, qualitatively: 20 % wear on axis i, cycle 100, IRB-6700-like, pick and place.

    The drive of the worn axis supplies the added friction: its extra torque along the direction
    of motion equals the added friction along it within 10 %; every other axis changes far less.
    """
    nominal = nominal_last_cycle
    worn = run(wear=[f"{axis}:exp4:20"], record=(100,))
    k = axis - 1
    assert worn.friction_multiplier[-1, k] == pytest.approx(1.2, rel=1e-12)
    direction = np.sign(nominal.qd_m[-1, :, k])
    added_friction = np.mean(direction * (worn.tau_f[-1, :, k] - nominal.tau_f[-1, :, k]))
    extra_drive = np.mean(direction * (worn.tau_m[-1, :, k] - nominal.tau_m[-1, :, k]))
    # the added friction is about 20 % of the nominal Coulomb + Stribeck level, not a trace
    assert added_friction > 0.15 * nominal.mean_friction_torque[-1, k] * 0.2
    assert extra_drive == pytest.approx(added_friction, rel=0.10)
    rise = np.mean(np.abs(worn.tau_m[-1]), axis=0) - np.mean(np.abs(nominal.tau_m[-1]), axis=0)
    others = np.delete(np.abs(rise), k)
    assert np.all(others < 0.1 * added_friction), rise


def test_same_seed_is_bit_identical_and_a_new_seed_changes_only_the_noise():
    first = run(task="spot_weld", wear=["3:exp4:20"], record=(1, 100), seed=7)
    again = run(task="spot_weld", wear=["3:exp4:20"], record=(1, 100), seed=7)
    for name in ("q_a", "q_m", "qd_a", "qd_m", "tau_m", "tau_f", "tau_dist", "friction_multiplier"):
        assert np.array_equal(getattr(first, name), getattr(again, name)), name
    other = run(task="spot_weld", wear=["3:exp4:20"], record=(1, 100), seed=8)
    assert not np.array_equal(first.tau_dist, other.tau_dist)
    assert not np.array_equal(first.q_a, other.q_a)
    np.testing.assert_array_equal(first.friction_multiplier, other.friction_multiplier)
    np.testing.assert_array_equal(first.q_ref, other.q_ref)
    # without noise the seed has nothing left to change
    quiet = NoiseConfig(disturbance=0.0, encoder=0.0)
    a = run(task="spot_weld", wear=["3:exp4:20"], record=(100,), seed=7, noise=quiet)
    b = run(task="spot_weld", wear=["3:exp4:20"], record=(100,), seed=8, noise=quiet)
    assert np.array_equal(a.tau_m, b.tau_m) and np.array_equal(a.q_a, b.q_a)


def test_a_cycle_does_not_depend_on_which_other_cycles_are_recorded():
    alone = run(task="arc_weld", wear=["2:linear:20"], record=(50,), seed=3)
    among = run(task="arc_weld", wear=["2:linear:20"], record=(10, 50, 90), seed=3)
    assert np.array_equal(alone.tau_m[0], among.tau_m[1])
    assert np.array_equal(alone.q_a[0], among.q_a[1])


@pytest.mark.parametrize("robot", ["puma560", "irb6700"])
@pytest.mark.parametrize("task", tasks.TASKS)
def test_100_cycles_without_warning_or_nan(robot, task):
    """All six axes wearing over 100 cycles: no MuJoCo warning (a warning raises), nothing
    non-finite. Every recorded cycle is its own simulation from the task's start state with that
    cycle's wear, so cycle 1 and every tenth span the whole wear range (recording all 100 cost
    80 s of the suite's CPU for cycles that differ only in a friction level in between)."""
    wear = [f"{axis}:exp4:20" for axis in range(1, 7)]
    cycles = (1, *range(10, 101, 10))
    result = run(task=task, robot=robot, wear=wear, nthread=1, record=cycles)
    assert result.tau_m.shape[:2] == (len(cycles), len(result.t))
    for name in ("q_a", "q_m", "qd_a", "qd_m", "tau_m", "tau_f"):
        assert np.all(np.isfinite(getattr(result, name))), name
    assert np.all(result.friction_multiplier[-1] == pytest.approx(1.2))
    # the drives track: the arm stays within 25 mrad of the reference
    assert np.max(result.tracking_error) < 0.025


def test_a_diverging_run_names_cycle_and_axis(tmp_path, monkeypatch):
    """A gearbox as stiff as a robot folder may declare (1e10 N m/rad, the bound: a stiffer one is
    refused when the folder loads, tests/test_robot_folders.py) on axis 3 makes the spring unstable
    under an integrator that treats it explicitly (the robots' own, ``discrete``, is implicit in
    position and holds it)."""
    monkeypatch.chdir(tmp_path)  # MuJoCo writes its warning to MUJOCO_LOG.TXT in the working folder
    source = robots.available()["irb6700"]
    text = source.read_text().replace('<fixed name="gearbox3" stiffness="1420000"', '<fixed name="gearbox3" stiffness="1e10"')
    text = text.replace('integrator="discrete"', 'integrator="implicitfast"')
    broken = tmp_path / "irb6700_unstable.xml"
    broken.write_text(text)
    shutil.copy(source.parent / "tasks.toml", tmp_path / "tasks.toml")
    with pytest.raises(sim.SimulationDiverged, match=r"cycle 7 diverged near t = [\d.]+ s on axis \d"):
        run(robot=str(broken), record=(7,), cycles=10)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(task="welding"), "unknown task 'welding'; expected one of: pick_place, spot_weld, arc_weld"),
        (dict(cycles=0), r"cycles = 0; expected a whole number >= 1"),
        (dict(friction="coulomb"), "unknown friction model 'coulomb'; expected one of: lugre, stribeck"),
        (dict(record=(0, 5)), r"recorded cycle 0 is out of range 1..100"),
        (dict(seed=-1), r"seed = -1; expected a whole number in 0 \.\. 4294967295"),
        ({"seed": True}, r"seed = True; expected a whole number in 0 \.\. 4294967295"),
        ({"seed": 2.0}, r"seed = 2.0; expected a whole number in 0 \.\. 4294967295"),
        ({"seed": 2**32}, r"seed = 4294967296; expected a whole number in 0 \.\. 4294967295"),
        (dict(robot="puma"), "unknown robot 'puma'"),
    ],
)
def test_bad_configuration_is_refused_before_simulation(kwargs, match):
    config = dict(robot="irb6700", task="pick_place", wear=WearPlan({}), cycles=100)
    config.update(kwargs)
    with pytest.raises(ValueError, match=match):
        run_config(**config)


def test_tracking_error_is_reported_per_task():
    for task in tasks.TASKS:
        result = run(task=task, record=(1,))
        assert result.tracking_error.shape == (1, 6)
        assert np.all(result.tracking_error > 0)


def test_static_friction_model_also_passes_wear_to_the_motor():
    """The stribeck path (friction level set from Python every step) behaves like the LuGre one."""
    nominal = run(friction="stribeck", record=(100,))
    worn = run(friction="stribeck", wear=["5:exp4:20"], record=(100,))
    again = run(friction="stribeck", wear=["5:exp4:20"], record=(100,))
    assert np.array_equal(worn.tau_m, again.tau_m)
    direction = np.sign(nominal.qd_m[-1, :, 4])
    added = np.mean(direction * (worn.tau_f[-1, :, 4] - nominal.tau_f[-1, :, 4]))
    extra = np.mean(direction * (worn.tau_m[-1, :, 4] - nominal.tau_m[-1, :, 4]))
    assert added > 0.05
    assert extra == pytest.approx(added, rel=0.10)


def test_cycles_beyond_one_batch_are_stepped_in_groups_with_the_same_result(monkeypatch):
    whole = run(task="pick_place", wear=["6:linear:20"], record=(3, 20, 77), seed=5)
    monkeypatch.setattr(sim, "BATCH_CYCLES", 2)
    grouped = run(task="pick_place", wear=["6:linear:20"], record=(3, 20, 77), seed=5)
    for name in ("q_a", "tau_m", "tau_f", "friction_multiplier"):
        assert np.array_equal(getattr(whole, name), getattr(grouped, name)), name


def test_back_to_back_cycles_carry_the_state_over():
    """Cycle 1 of a back-to-back run is the independent cycle 1. Cycle 2 goes on from the state
    cycle 1 ended in: it differs from an independent cycle 2 (which starts from the start state,
    drive integrators empty) at its start, and the two converge once the drives have settled."""
    independent = run(task="pick_place", cycles=2, seed=4, friction="stribeck")
    chained = run(task="pick_place", cycles=2, seed=4, friction="stribeck", back_to_back=True)
    for name in ("q_a", "q_m", "tau_m"):
        assert np.array_equal(getattr(independent, name)[0], getattr(chained, name)[0]), name
    scale = np.abs(independent.tau_m[1]).max(axis=0)
    change = np.abs(independent.tau_m[1] - chained.tau_m[1]) / scale
    assert change[independent.t < 0.1].max() > 0.05
    assert change[independent.t > 2.0].max() < 1e-3


@pytest.mark.parametrize("kwargs", [dict(wear=WearPlan.from_specs(["2:linear:20"], 3)), dict(record=(2,))])
def test_back_to_back_refuses_wear_and_a_record_subset(kwargs):
    config = dict(robot="irb6700", task="pick_place", cycles=3, back_to_back=True) | kwargs
    with pytest.raises(ValueError, match="back_to_back runs step every cycle in one simulation without wear"):
        run_config(**config)


def test_a_cycle_starts_at_rest_on_the_loaded_flank_of_its_backlash(tmp_path):
    """With backlash b the start state puts the arm b/2 beyond the static sag, on the flank that
    carries the load: held by its drives, the arm then stays where it is instead of falling
    across the dead band."""
    source = robots.available()["irb6700"]
    text = source.read_text().replace('name="gearbox2" stiffness="1420000" damping="4530" springlength="0"',
                                      'name="gearbox2" stiffness="1.42e6" damping="4.53e3" springlength="-0.005 0.005"')
    assert text != source.read_text()
    model = tmp_path / "irb6700_backlash.xml"
    model.write_text(text)
    robot = robots.load(model)
    assert robot.effects["backlash"].width[1] == pytest.approx(0.01)
    compiled = sim.build(robot)
    q0 = np.array([0.3, 0.4, -0.2, 0.0, 0.5, 0.0])
    data = mujoco.MjData(compiled.model)
    data.qpos[:], data.qvel[:] = sim.start_state(robot, q0)
    zeros = np.zeros((1, 6))
    data.ctrl[compiled.drive_ctrl] = control.setpoints(robot, q0[None], zeros, zeros)[0]
    start = data.qpos[robot.arm_qpos].copy()
    for _ in range(round(0.3 / compiled.model.opt.timestep)):
        mujoco.mj_step(compiled.model, data)
    # at rest the arm moves by far less than a tenth of the half-width it would fall across
    assert np.max(np.abs(data.qpos[robot.arm_qpos] - start)) < 0.1 * 0.005
