"""``robots.load`` compiles a robot file once per process and content, and what it shares is safe to share."""

import shutil
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from faultgen.model import robots


def test_a_robot_is_compiled_once_and_an_edited_file_again(tmp_path, monkeypatch):
    folder = tmp_path / "puma560"
    shutil.copytree(robots.available()["puma560"].parent, folder)
    path = folder / "puma560.xml"
    compiled = []
    original = robots._from_file
    monkeypatch.setattr(robots, "_from_file", lambda p, *rest: compiled.append(p) or original(p, *rest))
    first = robots.load(path)
    assert robots.load(path) is first and robots.load(str(path)) is first
    assert len(compiled) == 1
    path.write_text(path.read_text().replace('<numeric name="friction1" data="0.395',
                                             '<numeric name="friction1" data="0.5'))
    edited = robots.load(path)
    assert len(compiled) == 2 and edited is not first
    assert edited.friction.coulomb_pos[0] == 0.5 and first.friction.coulomb_pos[0] == 0.395


def test_the_shared_robot_cannot_be_changed_by_one_caller():
    robot = robots.load("irb6700")
    for array in (robot.gear_ratio, robot.friction.coulomb_pos, robot.home, robot.effects["torque_offset"].offset):
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 1.0


def test_inverse_dynamics_from_several_threads_is_what_one_thread_computes():
    robot = robots.load("puma560")
    rng = np.random.default_rng(0)
    motions = [tuple(rng.uniform(-1, 1, size=(200, 6)) for _ in range(3)) for _ in range(8)]
    alone = [robot.inverse_dynamics(*m) for m in motions]
    with ThreadPoolExecutor(4) as pool:
        together = list(pool.map(lambda m: robot.inverse_dynamics(*m), motions))
    for a, b in zip(alone, together, strict=True):
        np.testing.assert_array_equal(a, b)
