"""Robot descriptions from strangers (issue 50, item 1): `faultgen robots add` runs no code, reads
only the source's folder and the --package folders, and refuses every such attempt with exit 2,
the construct named and nothing written. Each exploit here worked on main at 41791db (the dunder
one ran a shell command; load_yaml, env and outside includes copied files into the robot).

Independent check: the xacro expander's URDF equals xacrodoc's (xacro's own processor) on
rtb-data's third-party xacros.
"""

import runpy
import struct
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import xacrodoc
import xacrodoc.packages

import robot_sources
from faultgen.model import robots

XACRO_NS = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'
SECRET = "s3cr3t-do-not-copy"


def urdf(extra="", name="test", mesh=""):
    """A six-axis URDF; ``extra`` goes inside <robot>, ``mesh`` (a filename) on the first link."""
    links = ['<link name="base"/>']
    joints = []
    for k in range(6):
        geometry = (
            f'<collision><geometry><mesh filename="{mesh}"/></geometry></collision>' if mesh and k == 0 else ""
        )
        links.append(
            f'<link name="l{k}"><inertial><mass value="1"/><origin xyz="0 0 0.1"/>'
            f'<inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>{geometry}</link>'
        )
        parent = "base" if k == 0 else f"l{k - 1}"
        joints.append(
            f'<joint name="j{k}" type="revolute"><parent link="{parent}"/><child link="l{k}"/>'
            f'<origin xyz="0 0 0.2"/><axis xyz="0 {k % 2} {1 - k % 2}"/>'
            '<limit lower="-1" upper="1" effort="0" velocity="2"/></joint>'
        )
    return f'<robot name="{name}" {XACRO_NS}>{"".join(links)}{"".join(joints)}{extra}</robot>'


def stl(path):
    """A binary STL tetrahedron of 0.1 m."""
    v = [(0, 0, 0), (0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1)]
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    data = b"\0" * 80 + struct.pack("<I", len(faces))
    for face in faces:
        data += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *v[i]) for i in face) + b"\0\0"
    path.write_bytes(data)
    return path


def refused(tmp_path, source, *construct, extra=()):
    """As :func:`robot_sources.refused`, and the secret is not in the message."""
    line = robot_sources.refused(tmp_path, source, *construct, extra=extra)
    assert SECRET not in line
    return line


@pytest.fixture
def folder(tmp_path):
    """The source's folder (tmp_path/robot) beside a secret outside it (tmp_path/secret.yaml)."""
    (tmp_path / "secret.yaml").write_text(f"key: {SECRET}\n")
    (tmp_path / "robot").mkdir()
    return tmp_path / "robot"


def test_a_xacro_cannot_run_a_command_through_dunder_strings(tmp_path, folder):
    marker = tmp_path / "PWNED"
    # python.vars + strings joined into dunder names: on 41791db this reached os.system
    base = "python.type(0).mro()[1]"
    subclasses = f"python.vars(python.type)['_'+'_subclasses_'+'_']({base})"
    wrap = f"[c for c in {subclasses} if 'wrap_close' in python.repr(c)][0]"
    init = f"python.vars({wrap})['_'+'_init_'+'_']"
    member = f"python.vars(python.type({init}))['_'+'_globals_'+'_']"
    globs = f"python.vars(python.type({member}))['_'+'_get_'+'_']({member}, {init})"
    expr = f"{globs}['system']('touch {marker}')"
    source = folder / "arm.urdf.xacro"
    source.write_text(urdf(f'<xacro:property name="x" value="${{{expr}}}"/><link name="z${{x}}"/>'))
    refused(tmp_path, source, str(source), "python.vars")
    assert not marker.exists()


@pytest.mark.parametrize(
    "payload, construct",
    [
        ('<link name="${xacro.load_yaml(\'SECRET_FILE\')[\'key\']}"/>', "xacro.load_yaml"),
        ('<link name="$(env HOME)"/>', "$(env HOME)"),
        ('<xacro:arg name="p" default="$(env PATH)"/><link name="$(arg p)"/>', "$(env PATH)"),
        ('<link name="$(cwd)"/>', "$(cwd)"),
        ('<link name="$(optenv HOME x)"/>', "$(optenv HOME x)"),
        ('<link name="$(eval 1 + 1)"/>', "$(eval 1 + 1)"),
        ('<link name="${eval(\'1\')}"/>', "eval"),
        ('<link name="${(1).real}"/>', "attribute access"),
        ('<link name="${x.y}"/>', "attribute access"),
    ],
)
def test_a_xacro_cannot_read_files_or_the_environment(tmp_path, folder, payload, construct):
    source = folder / "arm.urdf.xacro"
    source.write_text(urdf(payload.replace("SECRET_FILE", str(tmp_path / "secret.yaml"))))
    refused(tmp_path, source, str(source), construct)


@pytest.mark.parametrize("where", ["absolute", "relative"])
def test_a_xacro_includes_only_from_its_own_folder(tmp_path, folder, where):
    outside = tmp_path / "outside.xacro"
    outside.write_text(f'<robot {XACRO_NS}><link name="{SECRET}"/></robot>')
    name = str(outside) if where == "absolute" else "../outside.xacro"
    source = folder / "arm.urdf.xacro"
    source.write_text(urdf(f'<xacro:include filename="{name}"/>'))
    refused(tmp_path, source, "xacro include", name, "outside")


def test_a_xacro_include_resolves_against_its_own_folder_and_a_named_package(tmp_path, folder, monkeypatch):
    # a file of the same name in the current folder must not be the one read
    monkeypatch.chdir(tmp_path)
    (tmp_path / "part.xacro").write_text(f'<robot {XACRO_NS}><link name="{SECRET}"/></robot>')
    (folder / "part.xacro").write_text(f'<robot {XACRO_NS}><link name="mine"/></robot>')
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "m.xacro").write_text(
        f'<robot {XACRO_NS}><xacro:macro name="m" params="n *b">'
        '<link name="${n}"><xacro:insert_block name="b"/></link></xacro:macro></robot>'
    )
    source = folder / "arm.urdf.xacro"
    source.write_text(
        f'<robot name="r" {XACRO_NS}><xacro:include filename="part.xacro"/>'
        '<xacro:include filename="$(find pkg)/m.xacro"/><xacro:m n="${round(2*pi, 3)}"><inertial/></xacro:m>'
        "</robot>"
    )
    from faultgen.model import xacro

    text = xacro.expand(source, {"pkg": package})
    root = ET.fromstring(text)
    assert [link.get("name") for link in root.iter("link")] == ["mine", "6.283"]
    assert root.find("link/inertial") is not None and SECRET not in text


@pytest.mark.parametrize("where", ["absolute", "relative", "package", "symlink"])
def test_a_urdf_mesh_outside_its_folder_is_refused(tmp_path, folder, where):
    mesh = stl(tmp_path / "x.stl")
    (folder / "link.stl").symlink_to(mesh)
    name = {"absolute": str(mesh), "relative": "../x.stl", "package": "package://p/../../x.stl",
            "symlink": "link.stl"}[where]
    source = folder / "arm.urdf"
    source.write_text(urdf(mesh=name))
    refused(tmp_path, source, str(source), f'<mesh filename="{name}">', "outside")


def mjcf(tmp_path, extra):
    source = tmp_path / "robot" / "arm.xml"
    text = (robots.robots_dir() / "puma560" / "arm.xml").read_text()
    source.write_text(text.replace("</mujoco>", f"{extra}</mujoco>"))
    return source


def test_an_mjcf_include_outside_its_folder_is_refused(tmp_path, folder):
    outside = tmp_path / "outside.xml"
    outside.write_text(f'<mujoco><custom><text name="leak" data="{SECRET}"/></custom></mujoco>')
    source = mjcf(tmp_path, f'<include file="{outside}"/>')
    refused(tmp_path, source, str(source), f'<include file="{outside}">', "outside")


def test_an_mjcf_mesh_outside_its_folder_is_refused(tmp_path, folder):
    stl(tmp_path / "x.stl")
    source = mjcf(tmp_path, '<asset><mesh name="m" file="../x.stl"/></asset>')
    refused(tmp_path, source, str(source), '<mesh file="../x.stl">', "outside")


def test_an_mjcf_include_s_names_are_taken_from_the_main_file_s_folder_as_mujoco_does(tmp_path, folder):
    stl(tmp_path / "x.stl")
    (folder / "sub").mkdir()
    (folder / "sub" / "assets.xml").write_text('<mujoco><asset><mesh name="m" file="../x.stl"/></asset></mujoco>')
    source = mjcf(tmp_path, '<include file="sub/assets.xml"/>')
    refused(tmp_path, source, str(folder / "sub" / "assets.xml"), '<mesh file="../x.stl">', "outside")


def test_an_mjcf_plugin_is_refused(tmp_path, folder):
    source = mjcf(tmp_path, '<extension><plugin plugin="mujoco.elasticity.cable"/></extension>')
    refused(tmp_path, source, str(source), "<extension>", "plugin")


@pytest.mark.parametrize("kind", ["urdf", "dh"])
def test_a_name_that_would_end_the_mjcf_cdata_is_refused(tmp_path, folder, kind):
    injected = f']]&gt;&lt;include file=&quot;{tmp_path}/secret.yaml&quot;/&gt;&lt;![CDATA['
    if kind == "urdf":
        source = folder / "arm.urdf"
        source.write_text(urdf(name=injected))
    else:
        source = folder / "arm.toml"
        text = (Path(__file__).resolve().parents[1] / "docs/examples/ur5_dh.toml").read_text()
        source.write_text(text.replace('description = "', 'description = "]]><include file=\\"x\\"/>'))
    line = refused(tmp_path, source, str(source), "']]>'")
    assert "bug in faultgen" not in line


def test_a_killed_adds_staging_folder_is_removed_by_the_next_add(tmp_path, folder):
    import socket

    (tmp_path / "out").mkdir()
    stale = tmp_path / "out" / f".robot.partial-999999999@{socket.gethostname()}-abc123"
    (stale / "sub").mkdir(parents=True)
    source = folder / "arm.urdf"
    source.write_text(urdf(mesh="/nonexistent/x.stl"))
    refused(tmp_path, source, "<mesh")
    assert not stale.exists()


def test_xacro_expansion_equals_xacro_s_own_on_rtb_data():
    """Independent check: xacrodoc (xacro's processor) and faultgen's expander give the same URDF
    (elements, attributes, numbers to 12 digits) for eight of rtb-data's arms
    (``benchmarks/xacro_vs_xacrodoc.py`` runs all its files, with the same comparison)."""
    from faultgen.model import xacro

    bench = runpy.run_path(str(Path(__file__).resolve().parents[1] / "benchmarks/xacro_vs_xacrodoc.py"))
    root, packages, canonical = bench["ROOT"], bench["PACKAGES"], bench["canonical"]
    files = [
        "abb_irb140_description/urdf/irb140.xacro",
        "kuka_description/kuka_kr6/urdf/kr6r700sixx.xacro",
        "kuka_description/kuka_kr16/urdf/kr16_2.xacro",
        "kuka_description/kuka_kr120/urdf/kr120r2500pro.xacro",
        "kuka_description/kuka_lbr_iiwa/urdf/lbr_iiwa_14_r820.xacro",
        "qut_frankie_description/robots/panda_arm.urdf.xacro",
        "trossen_descriptions/urdf/wx250s.urdf.xacro",
        "unimation_puma560_description/urdf/puma560_robot.urdf.xacro",
    ]
    xacrodoc.packages.update_package_cache({k: str(v) for k, v in packages.items()})
    for name in files:
        ours = xacro.expand(root / name, packages)
        theirs = xacrodoc.XacroDoc.from_file(str(root / name), resolve_packages=False).to_urdf_string()
        assert canonical(ET.fromstring(ours)) == canonical(ET.fromstring(theirs)), name
        assert sum(1 for _ in ET.fromstring(ours).iter("joint")) >= 6, name


@pytest.mark.parametrize("kind", ["urdf", "mjcf"])
def test_the_written_robot_names_no_file_of_the_machine_it_was_added_on(tmp_path, folder, kind):
    from faultgen.model import folder as robot_folder

    (folder / "meshes").mkdir()
    stl(folder / "meshes" / "x.stl")
    if kind == "urdf":
        source = folder / "arm.urdf"
        source.write_text(urdf(mesh="meshes/x.stl"))
    else:
        source = mjcf(
            tmp_path,
            '<compiler meshdir="meshes"/><asset><mesh name="m" file="x.stl"/></asset>'
            '<worldbody><body name="stand"><geom type="mesh" mesh="m" mass="0"/></body></worldbody>',
        )
    added = robot_folder.add("robot", source, tmp_path / "out")
    written = {p.name: p.read_text() for p in added.folder.iterdir()}
    assert all(str(tmp_path) not in text for text in written.values())
    assert ("urdf_used.urdf" in written) == (kind == "urdf")
    if kind == "urdf":  # the URDF as compiled keeps the source's relative name
        assert 'filename="meshes/x.stl"' in written["urdf_used.urdf"]
    assert "file=" not in written["robot.xml"] and "meshdir" not in written["robot.xml"]


def test_a_urdf_whose_masses_need_an_unnamed_package_says_which_package_to_name(tmp_path):
    import rtbdata

    iiwa = Path(rtbdata.__file__).parent / "xacro/kuka_description/kuka_lbr_iiwa/urdf/lbr_iiwa_14_r820.urdf"
    refused(tmp_path, iiwa, "link_1", "--package kuka_lbr_iiwa_support=DIR", "kuka_lbr_iiwa is near the file")


@pytest.mark.parametrize("kind", ["mesh", "include"])
def test_a_loop_of_symbolic_links_is_refused(tmp_path, folder, kind):
    (folder / "a.xacro").symlink_to(folder / "b.xacro")
    (folder / "b.xacro").symlink_to(folder / "a.xacro")
    if kind == "mesh":
        source = folder / "arm.urdf"
        source.write_text(urdf(mesh="a.xacro"))
    else:
        source = folder / "arm.urdf.xacro"
        source.write_text(urdf('<xacro:include filename="a.xacro"/>'))
    refused(tmp_path, source, str(source), "a.xacro")
