"""The `faultgen` command, through its installed entry point and through typer's runner."""

import subprocess
import sys
from pathlib import Path

from typer.testing import CliRunner

from faultgen import robots
from faultgen.cli import app

runner = CliRunner()


def test_robots_lists_every_robot_with_a_description():
    result = runner.invoke(app, ["robots"])
    assert result.exit_code == 0, result.output
    lines = result.output.strip().splitlines()
    assert [line.split()[0] for line in lines] == list(robots.available())
    for line in lines:
        assert len(line.split(maxsplit=1)[1]) > 20


def test_robots_name_shows_the_parameters_per_axis():
    result = runner.invoke(app, ["robots", "puma560"])
    assert result.exit_code == 0, result.output
    assert "axis 6" in result.output
    assert "gear ratio G [1]" in result.output
    assert "62.611" in result.output  # G1 of the PUMA 560
    assert "friction coulomb_neg [N m]" in result.output


def test_unknown_robot_is_an_error_listing_the_known_ones():
    result = runner.invoke(app, ["robots", "puma"])
    assert result.exit_code == 2
    assert "unknown robot 'puma'" in result.output
    assert "puma560" in result.output and "irb6700" in result.output


def test_help_teaches_the_first_steps():
    result = runner.invoke(app, ["--help"])
    assert result.exit_code == 0
    assert "faultgen robots" in result.output


def test_console_script_is_installed():
    script = Path(sys.executable).parent / "faultgen"  # installed beside the interpreter
    assert script.is_file(), f"no console script at {script}: install the project with pip"
    out = subprocess.run([str(script), "robots"], capture_output=True, text=True, check=True).stdout
    assert "puma560" in out and "irb6700" in out
