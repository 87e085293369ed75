"""A rerun on another robot model is refused naming the robot and what changed, not a digest alone
(issue 88, item 6: "robot '9371fba401f3...'"). A small synthetic fleet, protocol own."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.model import robots

sys.path.insert(0, str(Path(__file__).parent))
import fleetlog_folder  # noqa: E402

runner = CliRunner()


def test_a_state_of_another_model_file_is_refused_naming_the_robot(tmp_path):
    puma = robots.load("puma560")
    logs = fleetlog_folder.write_fleet(tmp_path / "LOGS", puma, units=1, days=3)
    out = tmp_path / "out"
    common = ["--protocol", "own", "-o", str(out)]
    result = runner.invoke(app, ["monitor", str(logs), "--robot", "puma560", *common])
    assert result.exit_code == 0, result.output
    edited = tmp_path / "puma560"
    shutil.copytree(puma.path.parent, edited)
    model = edited / puma.path.name
    model.write_text(model.read_text().replace("<mujoco", "<!-- edited -->\n<mujoco", 1))
    result = runner.invoke(app, ["monitor", str(logs), "--robot", str(edited), *common])
    assert result.exit_code == 2, result.output
    text = " ".join(result.output.split())
    assert "holds a monitor run with other settings or inputs: the robot model puma560: its model file is not the " \
           "one the state was made with (SHA-256 " in text, text
    assert "now: another robot or an edited model file)" in text and "robot '" not in text, text
