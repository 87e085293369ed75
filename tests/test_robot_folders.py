"""Robot folders from strangers (issue 50, item 1): a folder given as `--robot DIR` gets the checks
a description given to `robots add` gets (docs/reliability.md, threat model). Its MJCF may read
only its own folder, may load no plugin, and its masses and drivetrain values are bounded; a
refusal is one line `error: ...` naming the file and the construct, exit 2, nothing written.
Before this change MuJoCo read such a folder's MJCF with none of these checks.
"""

import re
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.model import robots

SECRET = "s3cr3t-do-not-copy"


@pytest.fixture
def folder(tmp_path):
    """A copy of the shipped PUMA 560's folder (tmp_path/puma560) beside a file outside it."""
    (tmp_path / "secret.xml").write_text(f"<mujoco><!-- {SECRET} --></mujoco>")
    target = tmp_path / "puma560"
    shutil.copytree(robots.load("puma560").path.parent, target)
    return target


def edit(folder: Path, old: str, new: str, count: int = 1) -> None:
    path = folder / "puma560.xml"
    text = path.read_text()
    assert old in text, old
    path.write_text(text.replace(old, new, count))


def refused(tmp_path, folder, *words):
    """`faultgen simulate --robot FOLDER -o OUT`: exit 2, one line naming every one of ``words``,
    no output written."""
    out = tmp_path / "out.h5"
    result = CliRunner().invoke(app, ["simulate", "--robot", str(folder), "--cycles", "2", "-o", str(out)])
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    for word in words:
        assert word in lines[0], lines[0]
    assert SECRET not in lines[0]
    assert not out.exists() and not list(tmp_path.glob("*.partial*"))
    return lines[0]


def test_an_unchanged_copy_loads_as_the_shipped_robot(folder):
    copy, shipped = robots.load(folder), robots.load("puma560")
    assert copy.n_axes == shipped.n_axes
    assert (copy.gear_ratio == shipped.gear_ratio).all()


def test_an_include_outside_the_folder_is_refused(tmp_path, folder):
    edit(folder, "<option", f'<include file="{tmp_path / "secret.xml"}"/>\n  <option')
    refused(tmp_path, folder, "puma560.xml", "<include", "outside the folder")


def test_a_relative_include_out_of_the_folder_is_refused(tmp_path, folder):
    edit(folder, "<option", '<include file="../secret.xml"/>\n  <option')
    refused(tmp_path, folder, "<include", "outside the folder")


def test_a_mesh_outside_the_folder_is_refused(tmp_path, folder):
    edit(folder, "<option", '<asset><mesh name="m" file="/etc/hostname"/></asset>\n  <option')
    refused(tmp_path, folder, "<mesh file=", "outside the folder")


def test_a_plugin_is_refused(tmp_path, folder):
    edit(folder, "<option", '<extension><plugin plugin="mujoco.elasticity.cable"/></extension>\n  <option')
    refused(tmp_path, folder, "<extension> refused", "plugins are code")


def test_a_body_mass_out_of_bounds_is_refused(tmp_path, folder):
    edit(folder, 'mass="0.001"', 'mass="1e12"')
    refused(tmp_path, folder, "puma560.xml", "body 'link1'", "mass = 1000000000000.0", "expected a number in")


def test_a_motor_inertia_out_of_bounds_is_refused(tmp_path, folder):
    edit(folder, 'armature="0.0002"', 'armature="1e9"')
    line = refused(tmp_path, folder, "puma560.xml", "axis 1", "motor_inertia")
    assert re.search(r"1e\+?0?9|1000000000", line), line


def test_a_description_too_large_is_refused(tmp_path, folder):
    edit(folder, "<option", "<!-- " + "x" * (11 * 2**20) + " -->\n  <option")
    refused(tmp_path, folder, "puma560.xml")
