"""Every robot folder is complete, every element is named, and names pair up by axis."""

import re
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest

from faultgen.model import robots

ROBOTS = sorted(robots.available())


def test_both_thesis_robots_are_available():
    assert {"puma560", "irb6700"} <= set(ROBOTS)


@pytest.mark.parametrize("name", ROBOTS)
def test_folder_has_model_scene_and_readme(name):
    folder = robots.robots_dir() / name
    assert (folder / f"{name}.xml").is_file()
    assert (folder / "scene.xml").is_file()
    readme = (folder / "README.md").read_text()
    # The README gives the source of the numbers it lists, per topic.
    for topic in ("gear ratio", "motor inertia", "stiffness", "friction", "mass"):
        assert topic in readme.lower(), f"{name}/README.md does not cover {topic!r}"


@pytest.mark.parametrize("name", ROBOTS)
def test_scene_only_includes_the_robot(name):
    folder = robots.robots_dir() / name
    scene = ET.parse(folder / "scene.xml").getroot()
    includes = [e.get("file") for e in scene.iter("include")]
    assert includes == [f"{name}.xml"]
    # Nothing that moves or acts is defined in the scene itself.
    for tag in ("body", "joint", "actuator", "tendon", "keyframe"):
        assert not list(scene.iter(tag)), f"scene.xml of {name} defines a <{tag}>"
    robot = robots.load(name).model
    scene_model = mujoco.MjModel.from_xml_path(str(folder / "scene.xml"))
    assert (scene_model.nq, scene_model.nu, scene_model.ntendon, scene_model.nbody) == (
        robot.nq,
        robot.nu,
        robot.ntendon,
        robot.nbody,
    )


NAMED_TYPES = {
    "body": (mujoco.mjtObj.mjOBJ_BODY, "nbody"),
    "joint": (mujoco.mjtObj.mjOBJ_JOINT, "njnt"),
    "geom": (mujoco.mjtObj.mjOBJ_GEOM, "ngeom"),
    "site": (mujoco.mjtObj.mjOBJ_SITE, "nsite"),
    "tendon": (mujoco.mjtObj.mjOBJ_TENDON, "ntendon"),
    "actuator": (mujoco.mjtObj.mjOBJ_ACTUATOR, "nu"),
    "keyframe": (mujoco.mjtObj.mjOBJ_KEY, "nkey"),
    "numeric": (mujoco.mjtObj.mjOBJ_NUMERIC, "nnumeric"),
}


@pytest.mark.parametrize("name", ROBOTS)
def test_every_element_is_named(name):
    model = robots.load(name).model
    for kind, (obj, count) in NAMED_TYPES.items():
        first = 1 if kind == "body" else 0  # body 0 is the world
        for i in range(first, getattr(model, count)):
            assert mujoco.mj_id2name(model, obj, i), f"{name}: {kind} {i} has no name"
    # frames are not compiled into the model, so check them in the source
    source = ET.parse(robots.available()[name]).getroot()
    assert all(f.get("name") for f in source.iter("frame")), f"{name}: unnamed <frame>"


@pytest.mark.parametrize("name", ROBOTS)
def test_joints_rotors_gearboxes_and_motors_pair_up(name):
    robot = robots.load(name)
    model = robot.model
    # exactly the 6 arm joints and 6 rotors, nothing else moves
    joint_names = {model.joint(i).name for i in range(model.njnt)}
    assert joint_names == {f"joint{i}" for i in range(1, 7)} | {f"rotor{i}" for i in range(1, 7)}
    assert model.nu == 6 and model.ntendon == 6
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    for i in range(1, 7):
        joint, rotor = model.joint(f"joint{i}"), model.joint(f"rotor{i}")
        actuator, tendon = model.actuator(f"motor{i}"), model.tendon(f"gearbox{i}")
        assert actuator.trnid[0] == rotor.id
        adr, num = model.tendon_adr[tendon.id], model.tendon_num[tendon.id]
        assert num == 2
        assert {int(model.wrap_objid[w]) for w in range(adr, adr + num)} == {joint.id, rotor.id}
        # Coaxial: the rotor turns about the same world axis as its arm joint, on the link
        # that carries the joint (the motor is mounted on the previous link).
        np.testing.assert_allclose(data.xaxis[rotor.id], data.xaxis[joint.id], atol=1e-12)
        np.testing.assert_allclose(data.xanchor[rotor.id], data.xanchor[joint.id], atol=1e-12)
        assert model.body_parentid[rotor.bodyid[0]] == model.body_parentid[joint.bodyid[0]]
        # the motor inertia is the rotor's armature, the rotor body itself is negligible
        assert model.dof_armature[rotor.dofadr[0]] > 0
        assert model.body_mass[rotor.bodyid[0]] < 1e-8
        assert re.fullmatch(r"friction\d", model.numeric(f"friction{i}").name)


@pytest.mark.parametrize("name", ROBOTS)
def test_home_keyframe_is_within_limits_and_undeflected(name):
    robot = robots.load(name)
    model = robot.model
    assert np.all(robot.home >= robot.joint_range[:, 0]) and np.all(robot.home <= robot.joint_range[:, 1])
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    np.testing.assert_allclose(data.ten_length, 0.0, atol=1e-12)


@pytest.mark.parametrize("name", ROBOTS)
def test_friction_parameters_are_in_one_place_per_axis(name):
    """A wear schedule edits friction{i} and nothing else: no friction elsewhere in the MJCF."""
    model = robots.load(name).model
    assert np.all(model.dof_frictionloss == 0)
    assert np.all(model.dof_damping == 0)
    assert np.all(model.actuator_biastype == mujoco.mjtBias.mjBIAS_NONE)
