"""The one builder: the built-in robots are their arm plus their drivetrain, and drivetrain tables
are checked at the boundary. (The bit-for-bit comparison with the hand-written MJCFs of 4a0c437
is benchmarks/rebuild_identical.py: it needs the git history.)"""

import shutil

import mujoco
import numpy as np
import pytest

from faultgen.model import builder, drivetrain, robots


@pytest.mark.parametrize("name", ["puma560", "irb6700"])
def test_built_in_robot_is_its_arm_plus_its_drivetrain(name):
    folder = robots.robots_dir() / name
    assert (folder / f"{name}.xml").read_text() == builder.build_files(
        folder / "arm.xml", folder / "drivetrain.toml"
    )


@pytest.mark.parametrize("name", ["puma560", "irb6700"])
def test_drivetrain_table_is_what_the_model_holds(name):
    robot = robots.load(name)
    table = drivetrain.read(robots.robots_dir() / name / "drivetrain.toml", robot.n_axes)
    built = robots.drivetrain_of(robot)
    for given, read in zip(table.axes, built.axes):
        for key in drivetrain.KEYS:
            assert getattr(read, key) == pytest.approx(getattr(given, key), rel=1e-15)
    # the tendon coefficient is 1/G exactly as the table gives G
    tendon = robot.model.tendon("gearbox1")
    assert robot.model.wrap_prm[robot.model.tendon_adr[tendon.id]] == 1.0 / table.axes[0].gear_ratio


def test_a_robot_folder_loads_by_path(tmp_path):
    folder = tmp_path / "my_puma"
    shutil.copytree(robots.robots_dir() / "puma560", folder)
    (folder / "puma560.xml").rename(folder / "my_puma.xml")
    robot = robots.load(folder)
    assert robot.name == "my_puma" and robot.n_axes == 6 and robot.gear_ratio.shape == (6,)
    np.testing.assert_array_equal(robot.gear_ratio, robots.load("puma560").gear_ratio)


def test_a_folder_without_a_robot_is_refused(tmp_path):
    (tmp_path / "scene.xml").write_text("<mujoco/>")
    with pytest.raises(robots.UnknownRobotError, match="not a robot folder"):
        robots.load(tmp_path)


def test_rotor_sits_on_the_link_carrying_the_motor_coaxial_with_its_joint():
    model = robots.load("irb6700").model
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    data.qpos[[model.joint(f"joint{i}").qposadr[0] for i in range(1, 7)]] = [0.3, -0.4, 0.5, 1.0, -0.7, 0.2]
    mujoco.mj_kinematics(model, data)
    for i in range(1, 7):
        arm, rotor = model.joint(f"joint{i}").id, model.joint(f"rotor{i}").id
        np.testing.assert_allclose(data.xanchor[rotor], data.xanchor[arm], atol=1e-12)
        np.testing.assert_allclose(data.xaxis[rotor], data.xaxis[arm], atol=1e-12)
        assert model.body_parentid[model.jnt_bodyid[rotor]] == model.body_parentid[model.jnt_bodyid[arm]]


def test_drivetrain_with_unknown_key_is_refused(tmp_path):
    path = tmp_path / "drivetrain.toml"
    path.write_text(
        robots.drivetrain_of(robots.load("puma560")).to_toml().replace("viscous =", "viscosity =", 1)
    )
    with pytest.raises(drivetrain.DrivetrainError, match=r"axis 1: unknown key 'viscosity'"):
        drivetrain.read(path, 6)


def test_drivetrain_with_a_missing_axis_is_refused(tmp_path):
    path = tmp_path / "drivetrain.toml"
    text = robots.drivetrain_of(robots.load("puma560")).to_toml()
    path.write_text(text[: text.index("[axis.6]")])
    with pytest.raises(drivetrain.DrivetrainError, match="axis 6 is missing"):
        drivetrain.read(path, 6)
    assert 6 not in drivetrain.read_table(path, 6, partial=True)  # --drivetrain may be partial


def test_drivetrain_with_a_negative_value_is_refused(tmp_path):
    path = tmp_path / "drivetrain.toml"
    text = robots.drivetrain_of(robots.load("puma560")).to_toml()
    start = text.index("[axis.3]")
    text = text[:start] + text[start:].replace("gearbox_damping = 44.5", "gearbox_damping = -44.5", 1)
    path.write_text(text)
    with pytest.raises(drivetrain.DrivetrainError, match=r"axis 3: gearbox_damping = -44.5"):
        drivetrain.read_table(path, 6, partial=True)


def test_drivetrain_for_an_axis_the_arm_lacks_is_refused(tmp_path):
    path = tmp_path / "drivetrain.toml"
    path.write_text("[axis.7]\ngear_ratio = 100\n")
    with pytest.raises(drivetrain.DrivetrainError, match=r"\[axis.7\] is not an axis of this arm \(1..6\)"):
        drivetrain.read_table(path, 6, partial=True)
