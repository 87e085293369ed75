"""Straight lines on a redundant (7-axis) arm: each knot's IK stays where the previous solution is
in the arm's null space, and a speed advised for a line too fast is planned and checked first
(issue 88, item 5: a Panda's 0.1 m vertical line at 0.1 m/s failed with "axis 3 needs 3433 deg/s^2
... about 0.0284 m/s would fit", a null-space jump of axes 1 and 3 inside the first 10 ms knot; the
same lines on a six-axis arm give the same bits as before)."""

import math
import re

import numpy as np
import pytest
from scipy.interpolate import CubicSpline
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.model import robots
from faultgen.operation import programs
from faultgen.operation.ik import FlangeIK, tool_rotation
from test_programs import line_segments

DT = 0.004  # s
READY = [0, -17.19, 0, -126.05, 0, 114.59, 45]  # deg: the Panda's "ready" pose (roboticstoolbox's qr)
#: The Panda's kinematics (Craig's modified DH: d, a, alpha; Franka's published table), joint ranges,
#: speed and torque limits; link masses roughly Franka's, inertias chosen (the lines test kinematics).
PANDA = [(0.333, 0, 0), (0, 0, -math.pi / 2), (0.316, 0, math.pi / 2), (0, 0.0825, math.pi / 2),
         (0.384, -0.0825, -math.pi / 2), (0, 0, math.pi / 2), (0, 0.088, math.pi / 2)]
MASS = [4.97, 0.646, 3.228, 3.587, 1.225, 1.666, 0.735]
RANGE = [(-2.8973, 2.8973), (-1.7628, 1.7628), (-2.8973, 2.8973), (-3.0718, -0.0698), (-2.8973, 2.8973),
         (-0.0175, 3.7525), (-2.8973, 2.8973)]


@pytest.fixture(scope="module")
def panda(tmp_path_factory):
    folder = tmp_path_factory.mktemp("panda")
    rows = ['name = "panda7"', 'convention = "modified"', "rated_payload = 3.0", ""]
    for i, ((d, a, alpha), mass, (low, high)) in enumerate(zip(PANDA, MASS, RANGE, strict=True)):
        rows += ["[[link]]", f"d = {d}", f"a = {a}", f"alpha = {alpha!r}", f"mass = {mass}", "com = [0.0, 0.0, 0.0]",
                 f"inertia = [{0.01 * mass:.4g}, {0.01 * mass:.4g}, {0.01 * mass:.4g}, 0.0, 0.0, 0.0]",
                 f"qlim = [{low}, {high}]", f"speed = {2.175 if i < 4 else 2.61}",
                 f"effort = {87.0 if i < 4 else 12.0}", ""]
    (folder / "panda_dh.toml").write_text("\n".join(rows))
    result = CliRunner().invoke(app, ["robots", "add", "panda7", "--from", str(folder / "panda_dh.toml"),
                                      "-o", str(folder / "p7")])
    assert result.exit_code == 0, result.output
    return robots.load(folder / "p7" / "panda7.xml")


def line_program(robot, to, speed, start=READY, head=""):
    """From ``start`` to the point above the table at (0.45, -0.25, 0.35) m, tool down, then a
    straight line to ``to`` at ``speed`` m/s (0.2 s ramps), then back to ``start``."""
    text = f"""name = "line"
start = {start}
{head}[tool]
z = [0, 0, -1]
x = [1, 0, 0]
[[segment]]
type = "move"
pose = [0.45, -0.25, 0.35]
[[segment]]
type = "linear"
to = {to}
speed = {speed}
ramp_time = 0.2
[[segment]]
type = "move"
to = {start}
"""
    return programs.parse(text, robot)


@pytest.mark.parametrize(("to", "speed"), [([0.45, -0.25, 0.45], 0.1), ([0.45, 0.15, 0.35], 0.2)])
def test_the_pandas_lines_plan_without_a_null_space_jump(panda, to, speed):
    path = line_program(panda, to, speed).trajectory(DT)  # ProgramError on main: the flange 1.4 mm off the path
    limits = np.radians([124.618] * 4 + [149.542] * 3)
    assert np.all(np.abs(path.qd) <= limits * 1.02)
    # the first 10 ms of the line: axes 1 and 3 move little (the jump was 0.2 deg, opposite)
    program = line_program(panda, to, speed)
    ik = FlangeIK(panda, program.start)
    rotation = tool_rotation([0, 0, -1], [1, 0, 0])
    q0 = ik.solve(np.array([0.45, -0.25, 0.35]), rotation, program.start)
    step = np.array(to) - [0.45, -0.25, 0.35]
    points = np.array([0.45, -0.25, 0.35]) + np.outer([0, 1e-4, 2e-4], step / np.linalg.norm(step))
    q, _, _ = ik.follow(np.array([0.0, 0.01, 0.02]), points, rotation, q0, np.array([0.0, 0.01, 0.02]))
    assert np.degrees(np.abs(q[1] - q0)).max() < 0.05, np.degrees(q[1] - q0)
    np.testing.assert_array_equal(ik.posture.target_q, program.start)  # the program's posture back after follow


def test_six_axis_lines_are_the_same_bits_as_before():
    """The IRB-6700-like arm: follow() equals the rule before (every knot with the posture task toward
    the program's start), bit for bit."""
    robot = robots.load("irb6700")
    start = np.radians([0, 20, 15, 0, 80, 0])
    rotation = tool_rotation([-0.5, 0.0, -0.866], [-1.0, 0.0, 0.0])
    ik, before = FlangeIK(robot, start), FlangeIK(robot, start)
    q0 = ik.solve(np.array([1.55, -0.25, 0.8]), rotation, start)
    knots = np.linspace(0.0, 0.4, 41)
    points = np.array([1.55, -0.25, 0.8]) + np.outer(knots / 0.4, [0.0, 0.2, 0.0])
    t = np.arange(101) * DT
    solutions = [q0]
    for k in range(1, len(knots)):
        solutions.append(before.solve(points[k], rotation, solutions[-1]))
    spline = CubicSpline(knots, np.array(solutions), bc_type="clamped", axis=0)
    expected = spline(t)
    expected[0], expected[-1] = solutions[0], solutions[-1]
    q, _, _ = ik.follow(knots, points, rotation, q0, t)
    np.testing.assert_array_equal(q, expected)


def test_an_advised_speed_is_planned_and_checked(tmp_path):
    """A line too fast for the IRB's joints: the speed advised plans within the limits."""
    robot = robots.load("irb6700")
    head = '[tool]\nz = [-0.5, 0.0, -0.866]\nx = [-1.0, 0.0, 0.0]\n'

    def program(speed):
        return programs.parse(f'name = "fast"\nstart = [0, 20, 15, 0, 80, 0]\n{head}' + line_segments(speed, 0.1), robot)

    with pytest.raises(ValueError) as refused:
        program(3.0).trajectory(DT)
    found = re.search(r"a speed of about ([0-9.]+) m/s would fit \(planned and checked\)", str(refused.value))
    assert found, str(refused.value)
    program(float(found.group(1))).trajectory(DT)  # plans: the advice holds
