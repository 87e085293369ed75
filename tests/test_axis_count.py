"""The number of axes comes from the model: robots of five and seven axes (tests/axis_robots.py,
the PUMA 560 with its last axis removed or a wrist axis added) load, simulate, write valid
datasets and are isolated on, with every per-axis array sized by the robot."""

import json

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

import axis_robots
from faultgen.cli import app
from faultgen.data import dataset
from faultgen.logs import measured
from faultgen.data import logfiles
from faultgen.effects import make
from faultgen.inputs import InputError
from faultgen.effects.payload import Payload
from faultgen.model import robots
from faultgen.operation.faults import parse_fault
from faultgen.operation.wear import WearPlan
from faultgen.model import sizing
from faultgen.runs import fleet
from faultgen.simulation import stepping as sim
from resolved_runs import run_config

runner = CliRunner()


@pytest.fixture(scope="module")
def arms(tmp_path_factory):
    folder = tmp_path_factory.mktemp("arms")
    return {n: axis_robots.make(folder, n) for n in (5, 6, 7)}


@pytest.mark.parametrize("n_axes", [5, 7])
def test_a_robot_has_the_axes_of_its_model(arms, n_axes):
    robot = robots.load(arms[n_axes])
    assert robot.n_axes == n_axes and robot.joint_names[-1] == f"joint{n_axes}"
    for array in (robot.gear_ratio, robot.motor_inertia, robot.gearbox_stiffness, robot.motor_torque_limit,
                  robot.home, robot.friction.coulomb_pos, *(e for e in robot.effects["backlash"]._values.values())):
        assert array.shape == (n_axes,)
    q = np.tile(robot.home, (3, 1))
    assert robot.inverse_dynamics(q, 0 * q, 0 * q).shape == (3, n_axes)
    with pytest.raises(ValueError, match=rf"q must have shape \(n, {n_axes}\), got \(3, 6\)"):
        robot.inverse_dynamics(np.zeros((3, 6)), np.zeros((3, 6)), np.zeros((3, 6)))


def _motion(robot, n_axes, seed=3):
    rng = np.random.default_rng(seed)
    low, high = robot.joint_range[:n_axes].T
    q = low + (high - low) * rng.random((20, n_axes))
    return q, rng.standard_normal((20, n_axes)), rng.standard_normal((20, n_axes))


def test_the_five_axis_arm_is_the_puma_with_its_last_joint_held(arms):
    """Reference: the six-axis PUMA 560 (itself checked against roboticstoolbox; here as MjSpec
    writes it) with joint 6 at rest at 0; only rotor 6 (1e-9 kg) is missing from the five-axis arm."""
    five, six = robots.load(arms[5]), robots.load(arms[6])
    q, qd, qdd = _motion(five, 5)
    pad = np.zeros((len(q), 1))
    expected = six.inverse_dynamics(np.hstack([q, pad]), np.hstack([qd, pad]), np.hstack([qdd, pad]))[:, :5]
    np.testing.assert_allclose(five.inverse_dynamics(q, qd, qdd), expected, rtol=1e-7, atol=1e-9)


def test_the_seven_axis_arm_is_the_puma_carrying_its_seventh_link(arms):
    """Reference: the PUMA 560 with a payload (faultgen.effects.Payload, a body at the flange) of
    link 7's mass and inertia, joint 7 at rest at 0: the same torques on axes 1..6."""
    seven, six = robots.load(arms[7]), robots.load(arms[6])
    carrying = six.edited(lambda spec: Payload(mass=0.2, com_z=0.08, ixx=2e-4, iyy=2e-4, izz=1e-4).write(spec, six))
    q, qd, qdd = _motion(six, 6)
    pad = np.zeros((len(q), 1))
    got = seven.inverse_dynamics(np.hstack([q, pad]), np.hstack([qd, pad]), np.hstack([qdd, pad]))
    np.testing.assert_allclose(got[:, :6], carrying.inverse_dynamics(q, qd, qdd), rtol=1e-7, atol=1e-9)


def test_effects_are_sized_by_the_robot(arms):
    seven = robots.load(arms[7])
    offset = make("torque_offset", offset=0.5)  # one value for every axis of any robot
    spec = __import__("mujoco").MjSpec.from_file(str(seven.path))
    offset.write(spec, seven)
    assert [spec.numeric(f"torque_offset{k}") is not None for k in range(1, 9)] == [True] * 7 + [False]
    assert make("torque_offset", offset=[0, 0, 0, 0, 0, 0, 1.5]).report([6]) == {"7": {"offset": 1.5}}
    assert type(offset)(n_axes=5).offset.shape == (5,)


def test_wear_and_faults_are_held_to_the_robots_axes(arms):
    with pytest.raises(ValueError, match=r"^axis 7 is out of range 1\.\.6$"):
        run_config(robot="puma560", task="pick_place", wear=WearPlan.from_specs(["7:exp4:20"], 10), cycles=10)
    with pytest.raises(ValueError, match=r"^axis 6 is out of range 1\.\.5$"):
        run_config(robot=str(arms[5]), task="pick_place", wear=WearPlan.from_specs(["6:exp4:20"], 10), cycles=10)
    with pytest.raises(ValueError, match=r"fault axis 7 is out of range 1\.\.6"):
        run_config(robot="puma560", task="pick_place", fault=parse_fault("backlash:7:width:0.01", 10), cycles=10)
    config = run_config(robot=str(arms[7]), task="pick_place", wear=WearPlan.from_specs(["7:exp4:20"], 10),
                           cycles=10)
    assert config.wear.multipliers(np.array([10]), 7)[0, 6] == pytest.approx(1.2)


def test_seven_axis_simulate_validate_and_isolate(arms, tmp_path):
    """simulate -> validate -> sweep -> bench-isolators on the seven-axis arm, by the command line."""
    robot = str(arms[7])
    out = tmp_path / "one.h5"
    result = runner.invoke(app, ["simulate", "--robot", robot, "--wear", "7:exp4:50", "--cycles", "2", "-o", str(out),
                                 "--no-progress"])
    assert result.exit_code == 0, result.output
    arrays, attrs = dataset.read_run(out, names=("tau_m", "friction_multiplier", "torque_hist"))
    assert arrays["tau_m"].shape[2] == 7 and arrays["torque_hist"].shape[1] == 7
    np.testing.assert_allclose(arrays["friction_multiplier"][-1], [1, 1, 1, 1, 1, 1, 1.5])
    assert attrs["n_axes"] == 7 and attrs["model_sha256"] == dataset.model_hash(arms[7])
    drivetrain = json.loads(attrs["drivetrain"])
    np.testing.assert_array_equal(drivetrain["gear_ratio"], robots.load(robot).gear_ratio)
    assert len(drivetrain["friction"]["static"]) == 7
    assert runner.invoke(app, ["validate", str(out)]).exit_code == 0

    swept = tmp_path / "sweep.h5"
    result = runner.invoke(app, ["sweep", "--robot", robot, "--task", "pick_place", "--axis", "0", "--axis", "7",
                                 "--wear-pct", "50", "--cycles", "8", "--jobs", "1", "--no-progress", "-o", str(swept)])
    assert result.exit_code == 0, result.output
    assert dataset.validate(swept) == []
    stem = tmp_path / "iso"
    result = runner.invoke(app, ["bench-isolators", str(swept), "--levels", "50", "--no-progress", "-o", str(stem)])
    assert result.exit_code == 0, result.output
    confusion = (tmp_path / "iso-confusion.csv").read_text().splitlines()
    assert confusion[0] == "isolator,true axis,undecided,1,2,3,4,5,6,7,too few cycles"
    assert "| axis 7 |" in (tmp_path / "iso.md").read_text()
    assert runner.invoke(app, ["plot", str(swept), "-o", str(tmp_path / "sweep.png")]).exit_code == 0
    result = runner.invoke(app, ["detect", str(swept), "--protocol", "same-run", "--no-progress", "-o",
                                 str(tmp_path / "det")])
    assert result.exit_code == 0, result.output
    assert "| 1 2 3 4 5 6 7 |" in (tmp_path / "det.md").read_text()  # the monitor's features: all 7 axes


def test_the_validator_uses_the_runs_own_axes(arms, tmp_path):
    result = sim.simulate(run_config(robot=str(arms[5]), task="pick_place", cycles=1, signals=False),
                          progress=False)
    path = dataset.write_run(tmp_path / "five.h5", result)
    assert dataset.validate(path) == []
    broken = tmp_path / "broken.h5"
    for name, value, problem in [
        ("drivetrain", json.dumps({**json.loads(h5py.File(path)["runs/run"].attrs["drivetrain"]),
                                   "gear_ratio": [1.0] * 6}), "drivetrain gear_ratio: expected 5 finite numbers"),
        ("n_axes", 8, "n_axes attribute 8, expected a whole number 5..7"),
        ("worn_axes", np.array([6]), "worn_axes: axis 6 is out of range 1..5"),
    ]:
        broken.write_bytes(path.read_bytes())
        with h5py.File(broken, "a") as f:
            f["runs/run"].attrs[name] = value
        assert any(problem in p for p in dataset.validate(broken)), (name, dataset.validate(broken))
    # n_axes 7 on a 5-axis run: its arrays disagree with it, refused before any array is read (issue 50)
    broken.write_bytes(path.read_bytes())
    with h5py.File(broken, "a") as f:
        f["runs/run"].attrs["n_axes"] = 7
    with pytest.raises(InputError, match=r"q_ref has shape \(\d+, 5\); \(\d+, 7\) is expected"):
        dataset.validate(broken)
    with h5py.File(broken, "a") as f:  # a file written before the attributes existed: six axes, still valid
        f["runs/run"].attrs["worn_axes"] = np.array([], dtype=int)
        del f["runs/run"].attrs["n_axes"], f["runs/run"].attrs["drivetrain"]
    assert dataset.validate(broken) == []


def test_measured_logs_have_the_robots_columns(arms, tmp_path):
    robot = robots.load(arms[7])
    t = np.arange(0, 3, 0.004)
    q = robot.home + 0.1 * np.sin(t)[:, None] * np.ones(7)
    tau = robot.inverse_dynamics(q, 0.1 * np.cos(t)[:, None] * np.ones(7), -0.1 * np.sin(t)[:, None] * np.ones(7))
    path = logfiles.write_csv(tmp_path / "log.csv", t, q, tau)
    assert path.read_text().splitlines()[0].split(",")[-1] == "tau7"
    data = measured.read(path, robot)
    assert data.q.shape == (len(t), 7)
    np.testing.assert_array_equal(data.tau, tau)
    with pytest.raises(measured.MeasuredDataError, match=r"missing column\(s\) q7, tau7.*required: t, q1\.\.q7"):
        measured.read(logfiles.write_csv(tmp_path / "six.csv", t, q[:, :6], tau[:, :6]), robot)


def test_fleet_parts_come_from_the_rated_payload(arms):
    seven = robots.load(arms[7])
    assert fleet.sized_parts(robots.load("puma560")) == fleet.PARTS["puma560"]  # the shipped arms keep theirs
    payload = fleet.rated_payload(seven)
    # the rule on the PUMA 560 gives 4.6 kg; link 7 (0.2 kg, 8 cm further out) costs a little
    assert 3.0 < payload < fleet.rated_payload(robots.load("puma560"))
    (small, small_edge), (big, _) = fleet.sized_parts(seven)
    assert small == (float(f"{0.05 * payload:.3g}"), float(f"{0.2 * payload:.3g}")) and big[1] < payload
    assert small_edge[0] == pytest.approx((small[0] / sizing.PART_DENSITY) ** (1 / 3), rel=1e-2)
    mixed = fleet.Fleet(size=4, failing=2, days=6, cycles_per_day=1, models=(str(arms[7]), "puma560", str(arms[5])))
    drawn = mixed.robots()
    assert [r["run"].split("-")[1] for r in drawn] == ["puma7", "puma560", "puma5", "puma7"]
    for row, (_, config) in zip(drawn, mixed.runs(), strict=True):
        assert 0 <= row["axis"] <= robots.load(row["model"]).n_axes
        assert config.conditions.payloads.masses[1] <= fleet.sized_parts(robots.load(row["model"]))[1][0][1]


def test_a_sweep_refuses_two_models_of_one_name(arms, tmp_path):
    from faultgen.runs import sweep

    other = axis_robots.make(tmp_path, 7)  # another folder, the same name puma7
    with pytest.raises(ValueError, match=r"both named 'puma7'; run ids need different names"):
        sweep.Grid(robots=[str(arms[7]), str(other)], tasks=["pick_place"], axes=[0], cycles=2)
    assert len(sweep.Grid(robots=[str(arms[7]), str(arms[5])], tasks=["pick_place"], axes=[0, 5], cycles=2).runs()) == 4


def test_classification_refuses_to_pool_robots_of_different_axis_counts(arms, tmp_path):
    from analysis.benchmark import classification_table

    parts = []
    for n in (5, 7):
        result = sim.simulate(run_config(robot=str(arms[n]), task="pick_place", cycles=1, signals=False),
                              progress=False)
        parts.append((f"puma{n}", dataset.write_run(tmp_path / f"{n}.h5", result)))
    mixed = dataset.merge(parts, tmp_path / "mixed.h5")
    assert dataset.validate(mixed) == []
    with pytest.raises(ValueError, match=r"puma5: 5 axes, puma7: 7 axes\) cannot share one classifier"):
        classification_table(mixed, progress=False)
