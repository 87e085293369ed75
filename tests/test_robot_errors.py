"""Bad names, malformed or incomplete MJCF files and bad trajectories get errors that say what is wrong."""

import re
import shutil

import numpy as np
import pytest

from faultgen.model import robots


def test_unknown_robot_lists_the_known_ones():
    with pytest.raises(robots.UnknownRobotError) as err:
        robots.load("puma")
    message = str(err.value)
    assert "'puma'" in message
    for name in robots.available():
        assert name in message


def copy_robot(tmp_path, name="puma560"):
    target = tmp_path / f"{name}_copy.xml"
    shutil.copy(robots.available()[name], target)
    return target


def test_a_copied_model_loads_from_its_path(tmp_path):
    path = copy_robot(tmp_path)
    robot = robots.load(path)
    assert robot.name == "puma560_copy"
    np.testing.assert_array_equal(robot.gear_ratio, robots.load("puma560").gear_ratio)


def test_malformed_mjcf_names_the_file_and_line(tmp_path):
    path = copy_robot(tmp_path)
    lines = path.read_text().splitlines()
    bad_line = next(i for i, line in enumerate(lines) if 'name="joint3"' in line)
    lines[bad_line] = lines[bad_line].replace('class="arm"', 'class="arm" type="bogus"')
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(robots.ModelError) as err:
        robots.load(path)
    message = str(err.value)
    assert str(path) in message
    assert re.search(rf"line {bad_line + 1}\b", message), message


def test_broken_xml_names_the_file_and_line(tmp_path):
    path = tmp_path / "broken.xml"
    path.write_text("<mujoco>\n  <worldbody>\n    <body>\n  </worldbody>\n</mujoco>\n")
    with pytest.raises(robots.ModelError) as err:
        robots.load(path)
    assert str(path) in str(err.value)
    assert re.search(r"[Ll]ine( number=)? ?\d+", str(err.value))


def test_missing_gearbox_is_named(tmp_path):
    path = copy_robot(tmp_path)
    text = path.read_text()
    start = text.index('<fixed name="gearbox3"')
    end = text.index("</fixed>", start) + len("</fixed>")
    path.write_text(text[:start] + text[end:])
    with pytest.raises(robots.ModelError, match="gearbox3"):
        robots.load(path)


def test_gearbox_with_wrong_coefficients_is_refused(tmp_path):
    path = copy_robot(tmp_path)
    text = path.read_text().replace('<joint joint="joint2" coef="-1"/>', '<joint joint="joint2" coef="-2"/>')
    path.write_text(text)
    with pytest.raises(robots.ModelError, match="gearbox2.*coef"):
        robots.load(path)


def test_negative_friction_parameter_names_axis_and_field(tmp_path):
    path = copy_robot(tmp_path)
    text = path.read_text().replace(
        '<numeric name="friction4" data="0.0112', '<numeric name="friction4" data="-0.0112'
    )
    path.write_text(text)
    with pytest.raises(robots.ModelError, match=r"axis 4: friction coulomb_pos = -0\.0112"):
        robots.load(path)


def test_friction_numeric_of_wrong_length_is_refused(tmp_path):
    path = copy_robot(tmp_path)
    original = path.read_text()
    text = original.replace('data="0.126 0.071 0.02 0.5 2 0.000817 0.985 0"', 'data="0.126"')
    assert text != original
    path.write_text(text)
    with pytest.raises(robots.ModelError, match="friction2.*1 values, expected 8"):
        robots.load(path)


@pytest.mark.parametrize(
    ("q", "qd", "match"),
    [
        (np.zeros((3, 5)), np.zeros((3, 6)), r"q must have shape \(n, 6\), got \(3, 5\)"),
        (np.zeros((3, 6)), np.zeros((4, 6)), r"qd must have shape \(3, 6\), got \(4, 6\)"),
        (np.zeros(6), np.zeros(6), r"q must have shape \(n, 6\), got \(6,\)"),
    ],
)
def test_inverse_dynamics_checks_shapes(q, qd, match):
    robot = robots.load("puma560")
    with pytest.raises(ValueError, match=match):
        robot.inverse_dynamics(q, qd, np.zeros_like(qd))


def test_inverse_dynamics_names_the_first_non_finite_value():
    robot = robots.load("puma560")
    qdd = np.zeros((4, 6))
    qdd[2, 4] = np.nan
    with pytest.raises(ValueError, match="qdd holds a non-finite value at row 2, axis 5"):
        robot.inverse_dynamics(np.zeros((4, 6)), np.zeros((4, 6)), qdd)
