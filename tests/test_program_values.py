"""Issue 50 item 5, program files: a value the planner cannot use, a string where numbers go, a
program written for another robot and a process that is not one are refused with the file, the
key and what is expected, exit 2, before any planning or simulation, nothing written."""

import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.model import robots
from faultgen.operation import programs

runner = CliRunner()


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    return programs.export(robots.load("irb6700"), "pick_place")


def _edited(text: str, key: str, value: str) -> str:
    lines = text.splitlines()
    index = next(i for i, line in enumerate(lines) if line.startswith(f"{key} = "))
    lines[index] = f"{key} = {value}"
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(("key", "value", "message"), [
    ("velocity_scale", "1e-300", "velocity_scale: expected a fraction of the limit in 0.01..1, got 1e-300"),
    ("acceleration_scale", "1e-9", "acceleration_scale: expected a fraction of the limit in 0.01..1, got 1e-09"),
    ("start", '["0", 15, -60, 0, 0, 0]', "start: expected numbers, got ['0', 15, -60, 0, 0, 0]"),
    ("start", "[true, 15, -60, 0, 0, 0]", "start: expected numbers"),
    ("robot", '"puma560"', "robot: the program is for 'puma560', not for 'irb6700'"),
    ("process", '"nuke"', "process: 'nuke' is not a process; expected one of point-to-point"),
])
def test_a_program_value_out_of_range_is_refused_naming_file_and_key(exported, tmp_path, key, value, message):
    program = tmp_path / "p.toml"
    program.write_text(_edited(exported, key, value))
    out = tmp_path / "run.h5"
    result = runner.invoke(app, ["simulate", "--robot", "irb6700", "--task", str(program), "--cycles", "1",
                                 "--no-progress", "-o", str(out)])
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {program}: ") and message in lines[0], result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.toml"]


def test_the_programs_the_project_ships_still_read(exported):
    program = programs.parse(exported, robots.load("irb6700"))
    assert program.process == "point-to-point" and program.robot_name == "irb6700"
    robot = robots.load("irb6700")
    shipped = programs.read(robot.path.parent / "programs" / "palletize.toml", robot)
    assert shipped.process == "palletizing"
