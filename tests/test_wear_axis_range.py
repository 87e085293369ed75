"""A wear spec's axis is checked against the robot's own number of axes (issue 88, item 6:
`simulate --wear 9:exp4:20` on a 6-axis arm said "out of range 1..7")."""

import pytest
from typer.testing import CliRunner

from faultgen.cli.main import app
from faultgen.operation import wear


@pytest.mark.parametrize("axis", [7, 9])
def test_simulate_names_the_robots_own_axis_range(tmp_path, axis):
    out = tmp_path / "w.h5"
    result = CliRunner().invoke(app, ["simulate", "--robot", "puma560", "--wear", f"{axis}:exp4:20", "--cycles", "2",
                                      "-o", str(out)])
    assert result.exit_code == 2, result.output
    assert f"bad wear spec '{axis}:exp4:20': axis {axis} is out of range 1..6;" in result.output
    assert not out.exists()


def test_parse_wear_checks_against_the_axes_given():
    with pytest.raises(ValueError, match=r"axis 7 is out of range 1\.\.6"):
        wear.parse_wear("7:exp4:20", 10, n_axes=6)
    assert wear.parse_wear("7:exp4:20", 10, n_axes=7)[0] == 7
    assert wear.WearPlan.from_specs(["6:exp4:20"], 10, n_axes=6).worn_axes == (6,)
