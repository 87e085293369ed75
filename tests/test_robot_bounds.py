"""Numbers in a robot description out of physical bounds (issue 50, items 4-6): `faultgen robots
add` refuses each with exit 2 and one line naming the file, the joint, link or key and the
expected range; nothing is written. On main at 41791db these gave tracebacks (OverflowError,
RuckigError, "a bug in faultgen"), were taken as "not given" (velocity="nan", effort="-100"), or
were accepted (rated_payload = -5).
"""

import os
import re
from pathlib import Path

import pytest

from robot_sources import refused

UR5 = Path(__file__).resolve().parents[1] / "docs/examples/ur5_dh.toml"


DEFAULT = 'lower="-1" upper="1" effort="0" velocity="2"'


def urdf(limit=DEFAULT, mass="1", fixed=0):
    """A six-axis URDF whose joint j2 has ``limit`` and link l2 ``mass``, plus ``fixed`` fixed links."""
    links, joints = ['<link name="base"/>'], []
    for k in range(6):
        links.append(
            f'<link name="l{k}"><inertial><mass value="{mass if k == 2 else 1}"/><origin xyz="0 0 0.1"/>'
            '<inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        )
        joints.append(
            f'<joint name="j{k}" type="revolute"><parent link="{"base" if k == 0 else f"l{k - 1}"}"/>'
            f'<child link="l{k}"/><origin xyz="0 0 0.2"/><axis xyz="0 {k % 2} {1 - k % 2}"/>'
            f"<limit {limit if k == 2 else DEFAULT}/></joint>"
        )
    for k in range(fixed):
        links.append(f'<link name="f{k}"/>')
        joints.append(f'<joint name="fj{k}" type="fixed"><parent link="l5"/><child link="f{k}"/></joint>')
    return f'<robot name="test">{"".join(links)}{"".join(joints)}</robot>'


RANGE = {
    "velocity": " 100 rad/s",
    "effort": " 1e+06 N m",
    "lower": "in -100 .. 100 rad",
    "upper": "in -100 .. 100 rad",
}


@pytest.mark.parametrize(
    "attribute, value",
    [
        ("effort", "1e300"),
        ("effort", "-100"),
        ("velocity", "nan"),
        ("velocity", "abc"),
        ("velocity", "-2"),
        ("velocity", "1e-300"),
        ("effort", "1e-300"),
        ("lower", "-inf"),
        ("lower", "-1e300"),
        ("upper", "1e300"),
    ],
)
def test_a_urdf_limit_out_of_bounds_is_refused_naming_the_joint_and_attribute(tmp_path, attribute, value):
    limit = {"lower": "-1", "upper": "1", "effort": "0", "velocity": "2", attribute: value}
    source = tmp_path / "arm.urdf"
    source.write_text(urdf(" ".join(f'{k}="{v}"' for k, v in limit.items())))
    shown = "'abc'" if value == "abc" else repr(float(value))
    refused(tmp_path, source, str(source), "joint 'j2'", f"<limit {attribute}>", shown, RANGE[attribute])


def test_a_urdf_lower_limit_above_the_upper_is_refused(tmp_path):
    source = tmp_path / "arm.urdf"
    source.write_text(urdf('lower="1" upper="-1" effort="0" velocity="2"'))
    refused(tmp_path, source, str(source), "joint 'j2'", "expected lower < upper")


@pytest.mark.parametrize("mass", ["inf", "1e300", "-1"])
def test_a_urdf_mass_out_of_bounds_is_refused(tmp_path, mass):
    source = tmp_path / "arm.urdf"
    source.write_text(urdf(mass=mass))
    refused(tmp_path, source, str(source), "link 'l2'", "<mass value>", "in 0 .. 100000 kg")


@pytest.mark.parametrize(
    "fixed, message", [(1000, "1007 links; a robot arm description may have at most 500"),
                       (100_000, "bytes; a robot description is read up to 10000000 bytes")]
)
def test_a_urdf_with_too_many_links_is_refused_before_mujoco_compiles_it(tmp_path, fixed, message):
    source = tmp_path / "arm.urdf"
    source.write_text(urdf(fixed=fixed))
    refused(tmp_path, source, str(source), message)


@pytest.mark.parametrize("suffix", [".urdf", ".xml", ".toml", ".xacro"])
def test_a_description_that_is_not_utf8_names_the_file(tmp_path, suffix):
    source = tmp_path / f"arm{suffix}"
    source.write_bytes(urdf().encode().replace(b'name="test"', b'name="t\xff\xfe"'))
    refused(tmp_path, source, str(source), "not UTF-8" if suffix != ".xacro" else "not XML")


def test_a_description_that_is_not_a_regular_file_is_refused(tmp_path):
    fifo = tmp_path / "arm.urdf"
    os.mkfifo(fifo)  # a reader that opened it would wait for a writer for ever
    refused(tmp_path, fifo, str(fifo), "not a regular file")


def dh(tmp_path, link=None, top=None):
    """The UR5 DH table with ``link`` (key, value) set in link 2 or ``top`` (key, value) at the top."""
    text = UR5.read_text()
    if link is not None:
        key, value = link
        rows = text.split("[[link]]")
        if re.search(rf"^{key} = .*$", rows[2], flags=re.M):
            rows[2] = re.sub(rf"^{key} = .*$", f"{key} = {value}", rows[2], flags=re.M)
        else:
            rows[2] = rows[2].rstrip() + f"\n{key} = {value}\n\n"
        text = "[[link]]".join(rows)
    if top is not None:
        key, value = top
        text = re.sub(rf"^{key} = .*$", f"{key} = {value}", text, count=1, flags=re.M)
    source = tmp_path / "arm.toml"
    source.write_text(text)
    return source


@pytest.mark.parametrize(
    "key, value, expected",
    [
        ("speed", "1e300", "in 0.001 .. 100 rad/s"),
        ("speed", "-3.0", "in 0.001 .. 100 rad/s"),
        ("effort", "1e300", "in 0.001 .. 1e+06 N m"),
        ("d", "1e300", "in -100 .. 100 m"),
        ("a", "-1e300", "in -100 .. 100 m"),
        ("mass", "1e300", "in 0 .. 100000 kg"),
    ],
)
def test_a_dh_value_out_of_bounds_is_refused_naming_the_link_and_key(tmp_path, key, value, expected):
    source = dh(tmp_path, link=(key, value))
    refused(tmp_path, source, str(source), "link 2", f"{key} = {float(value)!r}", expected)


@pytest.mark.parametrize("value", ["-5", "1e300"])
def test_a_dh_rated_payload_out_of_bounds_is_refused(tmp_path, value):
    source = dh(tmp_path, top=("rated_payload", value))
    refused(tmp_path, source, str(source), "rated_payload", "in 0 .. 10000 kg")


@pytest.mark.parametrize("payload", [1e30, -1.0, float("nan")])
def test_a_payload_out_of_bounds_is_refused_by_the_library(tmp_path, payload):
    from faultgen.model import folder

    with pytest.raises(ValueError, match=r"payload = .* kg; expected a number in 0 \.\. 10000 kg"):
        folder.add("robot", UR5, tmp_path / "out", payload=payload)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "key, value, expected",
    [
        ("gear_ratio", "1e300", ">= 0.1 and <= 10000"),
        ("gear_ratio", "1e-300", ">= 0.1 and <= 10000"),
        ("stribeck_exponent", "1e300", "> 0 and <= 10"),
        ("motor_inertia", "1e300", "> 0 and <= 1000"),
    ],
)
def test_a_drivetrain_value_out_of_bounds_is_refused(tmp_path, key, value, expected):
    drive = tmp_path / "drive.toml"
    drive.write_text(f"[axis.2]\n{key} = {value}\n")
    refused(tmp_path, UR5, str(drive), "axis 2", key, expected, extra=("--drivetrain", drive))


@pytest.mark.parametrize("device", ["/dev/zero", "folder"])
def test_a_drivetrain_that_is_not_a_regular_file_is_refused(tmp_path, device):
    drive = Path(device) if device.startswith("/") else tmp_path
    refused(tmp_path, UR5, str(drive), "not a regular file", extra=("--drivetrain", drive))


@pytest.mark.parametrize("suffix", [".urdf", ".xml", ".xacro"])
def test_a_description_nested_thousands_deep_is_refused(tmp_path, suffix):
    source = tmp_path / f"arm{suffix}"
    deep = "<a>" * 50_000 + "</a>" * 50_000
    source.write_text(urdf().replace('<link name="base"/>', f'<link name="base">{deep}</link>'))
    refused(tmp_path, source, "arm" + suffix, "nested more than 200 deep")


@pytest.mark.parametrize(
    "old, new, words",
    [
        (r'mass="[^"]*"', 'mass="inf"', ("body 'link1'", "mass = inf", "0 .. 100000 kg")),
        (r'range="[^"]*"', 'range="-1e300 1e300"', ("joint 'joint1'", "range = -1e+300", "-100 .. 100 rad")),
        ("</mujoco>", '<option gravity="0 0 -1e300"/></mujoco>', ("<option gravity>", "-100 .. 100 m/s^2")),
        ("</mujoco>", '<actuator><motor joint="joint2" forcelimited="true" forcerange="-1e-300 1e-300"/></actuator>'
         "</mujoco>", ("joint 'joint2'", "effort limit = 1e-300", "0.001 .. 1e+06 N m")),
    ],
)
def test_an_mjcf_value_out_of_bounds_is_refused(tmp_path, old, new, words):
    from faultgen.model import robots

    source = tmp_path / "arm.xml"
    source.write_text(re.sub(old, new, (robots.robots_dir() / "puma560" / "arm.xml").read_text(), count=1))
    refused(tmp_path, source, str(source), *words)
