"""Arms from URDF, MJCF and DH tables: inverse dynamics against libraries faultgen did not write,
and bad arms refused with the element named.

Independent: Pinocchio's RNEA on the same URDF (as compiled: meshes left out, missing inertials
filled in, ``Arm.urdf``) and roboticstoolbox-python's ``rne`` on the same DH numbers; the
kinematics, the inertia transformations and the dynamics code are theirs. Shared: the numbers,
and the reflected motor inertia G^2 (Jm + rotor body inertia) qdd, added to theirs by formula.
"""

import math
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import roboticstoolbox as rtb
import rtbdata

from faultgen.model import builder, importers, robots, sizing

XACRO = Path(rtbdata.__file__).parent / "xacro"
URDFS = {
    "kr210": XACRO / "kuka_description/kuka_kr210/urdf/kr210l150.urdf",
    "irb140": XACRO / "abb_irb140_description/urdf/irb140.urdf",
    "iiwa14": XACRO / "kuka_description/kuka_lbr_iiwa/urdf/lbr_iiwa_14_r820.urdf",
}
#: The ROS packages their meshes name (``package://NAME/...``), as a user gives them with --package.
PACKAGES = {
    "kuka_kr210_support": XACRO / "kuka_description/kuka_kr210",
    "abb_irb140_support": XACRO / "abb_irb140_description",
    "kuka_lbr_iiwa_support": XACRO / "kuka_description/kuka_lbr_iiwa",
}
UR5 = Path(__file__).resolve().parents[1] / "docs/examples/ur5_dh.toml"
BOUND = 1e-6  # relative RMS per axis


def robot_of(arm):
    drive, _, _ = sizing.size(arm)
    return robots.from_spec(
        builder.build(arm.spec, drive, source=str(arm.source)), Path("/nonexistent/arm.xml")
    )


def motion(robot, n=40, seed=0):
    rng = np.random.default_rng(seed)
    low, high = robot.joint_range.T
    q = rng.uniform(low, high, (n, robot.n_axes))
    return q, rng.normal(0, 1, q.shape), rng.normal(0, 2, q.shape)


def relative_rms(ours, ref):
    return np.sqrt(np.mean((ours - ref) ** 2, axis=0)) / np.sqrt(np.mean(ref**2, axis=0))


@pytest.mark.parametrize("name", sorted(URDFS))
def test_urdf_robot_inverse_dynamics_matches_pinocchio(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", importers.GeometryDropped)
        arm = importers.read(URDFS[name], PACKAGES)
    robot = robot_of(arm)
    assert robot.n_axes == (7 if name == "iiwa14" else 6)
    model = pin.buildModelFromXML(arm.urdf)
    data = model.createData()
    idx = [model.joints[model.getJointId(j.name)].idx_q for j in arm.joints]
    q, qd, qdd = motion(robot)
    reflected = robot.gear_ratio**2 * (robot.motor_inertia + builder.ROTOR_INERTIA)
    ref = np.empty_like(q)
    for k in range(len(q)):
        qq, vv, aa = np.zeros(model.nq), np.zeros(model.nv), np.zeros(model.nv)
        qq[idx], vv[idx], aa[idx] = q[k], qd[k], qdd[k]
        ref[k] = pin.rnea(model, data, qq, vv, aa)[idx] + reflected * qdd[k]
    ours = robot.inverse_dynamics(q, qd, qdd, friction=False)
    assert np.all(relative_rms(ours, ref) < BOUND), relative_rms(ours, ref)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_dh_robot_inverse_dynamics_matches_roboticstoolbox(convention, tmp_path):
    text = UR5.read_text().replace('convention = "standard"', f'convention = "{convention}"')
    path = tmp_path / "ur5.toml"
    path.write_text(text)
    rows = tomllib.loads(text)["link"]
    robot = robot_of(importers.read(path))
    kind = rtb.RevoluteDH if convention == "standard" else rtb.RevoluteMDH
    links = [
        kind(
            d=r["d"],
            a=r["a"],
            alpha=r["alpha"],
            m=r["mass"],
            r=r["com"],
            I=[
                r["inertia"][0],
                r["inertia"][1],
                r["inertia"][2],
                r["inertia"][3],
                r["inertia"][5],
                r["inertia"][4],
            ],
            G=robot.gear_ratio[k],
            Jm=robot.motor_inertia[k] + builder.ROTOR_INERTIA,
            qlim=r["qlim"],
        )
        for k, r in enumerate(rows)
    ]
    reference = rtb.DHRobot(links, gravity=[0, 0, -9.81])
    q, qd, qdd = motion(robot)
    ref = np.array([reference.rne(q[k], qd[k], qdd[k]) for k in range(len(q))])
    ours = robot.inverse_dynamics(q, qd, qdd, friction=False)
    assert np.all(relative_rms(ours, ref) < BOUND), relative_rms(ours, ref)


def test_dh_table_limits_size_the_drivetrain():
    arm = importers.read(UR5)
    drive, origin, payload = sizing.size(arm)
    assert payload == 5.0
    G = np.array([a.gear_ratio for a in drive.axes])
    np.testing.assert_allclose(G, sizing.MOTOR_SPEED / math.pi)
    peak = np.array([a.motor_torque_limit for a in drive.axes]) * G
    np.testing.assert_allclose(peak, [150, 150, 150, 28, 28, 28])
    assert origin[1]["gear_ratio"].startswith("sized: G = 470")
    given, _, _ = sizing.size(arm, {2: {"gear_ratio": 101.0}})
    assert given.axes[1].gear_ratio == 101.0 and given.axes[0].gear_ratio == drive.axes[0].gear_ratio


def test_urdf_meshes_it_cannot_use_are_dropped_with_one_warning():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        importers.read(URDFS["kr210"], PACKAGES)
    dropped = [w for w in caught if issubclass(w.category, importers.GeometryDropped)]
    assert len(dropped) == 1 and "7 meshes left out" in str(dropped[0].message)


# ------------------------------------------------------------------------------- refusals --


def urdf(joints="revolute " * 6, limits=True, inertia="0.1 0.1 0.1", extra=""):
    links = ['<link name="base"/>']
    body = []
    for k, kind in enumerate(joints.split()):
        limit = '<limit lower="-1" upper="1" effort="0" velocity="2"/>' if limits else ""
        ixx, iyy, izz = inertia.split()
        links.append(
            f'<link name="l{k}"><inertial><mass value="1"/><origin xyz="0 0 0.1"/>'
            f'<inertia ixx="{ixx}" iyy="{iyy}" izz="{izz}" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        )
        parent = "base" if k == 0 else f"l{k - 1}"
        body.append(
            f'<joint name="j{k}" type="{kind}"><parent link="{parent}"/><child link="l{k}"/>'
            f'<origin xyz="0 0 0.2"/><axis xyz="0 {k % 2} {1 - k % 2}"/>{limit}</joint>'
        )
    return f'<robot name="test">{"".join(links)}{"".join(body)}{extra}</robot>'


REFUSED = {
    "floating base": (urdf("floating " + "revolute " * 6), r"joint 'j0' is floating"),
    "prismatic joint": (urdf("revolute prismatic " + "revolute " * 4), r"joint 'j1' is prismatic"),
    "too few joints": (urdf("revolute " * 4), r"4 revolute joints .*expected 5 to 7"),
    "too many joints": (urdf("revolute " * 8), r"8 revolute joints .*expected 5 to 7"),
    "missing limits": (urdf(limits=False), r"joint 'j0' has no joint limits"),
    "continuous joint": (urdf("continuous " + "revolute " * 5), r"joint 'j0' is continuous"),
    "non-positive-definite inertia": (urdf(inertia="0.1 0.1 0.5"), r"l0"),
    "zero inertia": (urdf(inertia="0 0 0"), r"l0"),
    "closed chain": (
        urdf(extra='<joint name="loop" type="fixed"><parent link="l5"/><child link="l1"/></joint>'),
        r"link 'l1' has two parent joints",
    ),
}


@pytest.mark.parametrize("case", sorted(REFUSED))
def test_bad_urdf_is_refused_with_the_element_named(case, tmp_path):
    text, message = REFUSED[case]
    path = tmp_path / "arm.urdf"
    path.write_text(text)
    with pytest.raises(builder.ArmError, match=message):
        importers.read(path)


def test_good_test_urdf_is_accepted(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(urdf())
    assert [j.name for j in importers.read(path).joints] == [f"j{k}" for k in range(6)]


def edited_puma(path, *edits):
    """The PUMA 560's MJCF written to ``path`` with each ``(old, new)`` of ``edits`` replaced (each
    ``old`` stands once in it); gives ``path``."""
    text = (robots.robots_dir() / "puma560" / "arm.xml").read_text()
    for old, new in edits:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    path.write_text(text)
    return path


def edited_puma_is_refused(tmp_path, old, new, message):
    """Importing the PUMA 560's MJCF with ``old`` replaced by ``new`` raises ``ArmError`` matching ``message``."""
    path = edited_puma(tmp_path / "arm.xml", (old, new))
    with pytest.raises(builder.ArmError, match=message):
        importers.read(path)


def test_mjcf_closed_chain_is_refused(tmp_path):
    edited_puma_is_refused(
        tmp_path, "</mujoco>",
        '<equality><connect name="loop" body1="link6" body2="link2" anchor="0 0 0"/></equality></mujoco>',
        "equality constraint 'loop' closes a chain",
    )


def test_dh_row_without_limits_is_refused(tmp_path):
    path = tmp_path / "ur5.toml"
    text = UR5.read_text()
    first = text.index("qlim =")
    path.write_text(text[:first] + text[text.index("\n", first) + 1 :])
    with pytest.raises(builder.ArmError, match="link 1: qlim is missing"):
        importers.read(path)


def test_mjcf_arm_reads_back_the_built_in_robot():
    arm = importers.read(robots.robots_dir() / "puma560" / "arm.xml")
    drive = robots.drivetrain_of(robots.load("puma560"))
    model = builder.build(arm.spec, drive).compile()
    reference = robots.load("puma560").model
    np.testing.assert_array_equal(model.body_inertia, reference.body_inertia)
    np.testing.assert_array_equal(model.tendon_stiffness, reference.tendon_stiffness)


def test_xacro_is_expanded_and_its_packages_found_in_the_folders_named(tmp_path):
    package = tmp_path / "my_arm_description"
    (package / "urdf").mkdir(parents=True)
    text = urdf()
    # a macro file in the package, included by $(find ...) from a top file with a property
    links = text[text.index(">") + 1 : text.rindex("</robot>")]
    (package / "urdf" / "macro.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:macro name="arm">'
        + links.replace('upper="1"', 'upper="${limit}"')
        + "</xacro:macro></robot>"
    )
    top = tmp_path / "robot" / "arm.urdf.xacro"
    top.parent.mkdir()
    top.write_text(
        '<robot name="xarm" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:property name="limit" value="1.5"/>'
        '<xacro:include filename="$(find my_arm_support)/urdf/macro.xacro"/><xacro:arm/></robot>'
    )
    with pytest.raises(builder.ArmError, match=r"--package my_arm_support=DIR \(a folder .*my_arm_description is near"):
        importers.read(top)
    arm = importers.read(top, {"my_arm_support": package})
    assert arm.kind == "xacro" and [j.range for j in arm.joints] == [(-1.0, 1.5)] * 6


def test_menagerie_style_mjcf_loses_its_actuators_and_joint_friction_and_keeps_its_torque_limits(tmp_path):
    path = edited_puma(tmp_path / "menagerie_like.xml", (
        '<joint name="joint2" class="arm"', '<joint name="joint2" class="arm" damping="3" frictionloss="1"'
    ), (
        "</mujoco>",
        '<actuator><position name="servo2" joint="joint2" kp="100" forcelimited="true" '
        'forcerange="-97 97"/></actuator></mujoco>',
    ))
    arm = importers.read(path)
    assert arm.effort_limit[1] == 97.0 and np.isnan(arm.effort_limit[0])
    assert any("joint2" in note and "damping" in note for note in arm.notes)
    model = builder.build(arm.spec, robots.drivetrain_of(robots.load("puma560"))).compile()
    assert model.nu == 6 and all(model.actuator(k).name == f"motor{k + 1}" for k in range(6))
    assert model.dof_damping.max() == 0 and model.dof_frictionloss.max() == 0


# (five axes need faultgen.effects to count axes from the model too: issue 37's other half)
@pytest.mark.parametrize("n", [7])
def test_robots_of_seven_axes_have_arrays_of_that_length(n, tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(urdf("revolute " * n))
    robot = robot_of(importers.read(path))
    assert robot.n_axes == n and robot.joint_names == tuple(f"joint{i}" for i in range(1, n + 1))
    for array in (
        robot.gear_ratio,
        robot.motor_inertia,
        robot.gearbox_stiffness,
        robot.motor_torque_limit,
        robot.home,
        robot.friction.coulomb_pos,
    ):
        assert array.shape == (n,)
    q, qd, qdd = motion(robot, n=3)
    assert robot.inverse_dynamics(q, qd, qdd).shape == (3, n)
    with pytest.raises(ValueError, match=rf"qd must have shape \(3, {n}\)"):
        robot.inverse_dynamics(q, qd[:, :-1], qdd)


def test_mjcf_floating_base_is_refused(tmp_path):
    edited_puma_is_refused(
        tmp_path, '<body name="base" childclass="puma560">',
        '<body name="base" childclass="puma560"><freejoint name="float"/>',
        "joint 'float' is a free joint: a floating base",
    )


def test_mjcf_with_missing_mesh_files_is_read_without_them_and_one_warning(tmp_path):
    path = edited_puma(
        tmp_path / "arm.xml",
        ("<worldbody>", '<asset><mesh name="shell" file="gone/shell.stl"/></asset><worldbody>'),
        ('<site name="dh2"/>', '<site name="dh2"/><geom type="mesh" mesh="shell" mass="0"/>'),
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        arm = importers.read(path)
    assert [w.category for w in caught] == [importers.GeometryDropped]
    assert len(arm.joints) == 6 and not arm.spec.meshes
