"""A robot carrying both kinds of stepped effect, for the tests of the static friction model's
per-step update (tests/test_backends.py, tests/test_friction_update.py): the puma560 with a warm-up
drift in time (``temperature``) on axes 1 and 3, and load-dependent friction on axis 2 in its
transmitted-load form and on axis 3 in its static-load form."""

from __future__ import annotations

import shutil
from pathlib import Path

import mujoco

from faultgen import effects
from faultgen.model import robots

#: The stepped effects' parameters by axis (0-based).
DRIFT = {0: {"amplitude": 0.4, "time_constant": 0.02}, 2: {"amplitude": 0.2, "time_constant": 0.05}}
LOAD = {1: {"coefficient": 0.04, "gravity_load": 0}, 2: {"coefficient": 0.06, "gravity_load": 1}}


def write(folder: Path) -> Path:
    """The robot's MJCF (and the puma560's tasks) in ``folder``; its path."""
    robot = robots.load("puma560")
    folder.mkdir(parents=True, exist_ok=True)
    spec = mujoco.MjSpec.from_file(str(robot.path))
    effects.get("temperature").fitted(robot, DRIFT).write(spec, robot, sorted(DRIFT))
    effects.get("load_dependent_friction").fitted(robot, LOAD).write(spec, robot, sorted(LOAD))
    path = folder / "puma560_stepped.xml"
    path.write_text(spec.to_xml())
    shutil.copyfile(robot.path.parent / "tasks.toml", folder / "tasks.toml")
    return path
