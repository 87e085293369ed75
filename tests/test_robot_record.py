"""What a run stores of its robot (issue 57 item 1): the analyses read each run's stored drivetrain,
limits and model digest (faultgen.data.robot_record, Run.drivetrain / .limits / .model_sha256), so
a dataset is analysed the same with the robot's folder moved away; files written before the runs
stored them still read, their robot loaded by its label."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

import faultgen
from analysis import crossdata
from faultgen.cli import app
from faultgen.data import dataset, fleetlogs
from faultgen.model import robots
from faultgen.operation import programs

sys.path.insert(0, str(Path(__file__).parent))
import fleetlog_folder  # noqa: E402

UR5 = Path(__file__).resolve().parents[1] / "docs/examples/ur5_dh.toml"
runner = CliRunner()


def imported_fleet(folder: Path, robot, worn: dict, units: int, days: int, start) -> Path:
    """A fleet of synthetic daily logs of ``robot`` imported as a dataset (tests/fleetlog_folder)."""
    logs = fleetlog_folder.write_fleet(folder / "LOGS", robot, units=units, days=days, worn=worn, suffix=".h5",
                                       start=start)
    rows = [f"u{u + 1},{start + fleetlog_folder.timedelta(days=onset + 1)},onset,{axis}"
            for u, (axis, onset, _) in worn.items()]
    (logs / "events.csv").write_text("unit,stamp,event,axis\n" + "\n".join(rows) + "\n")
    out = folder / "fleet.h5"
    fleetlogs.import_logs(logs, out, robot=robot, progress=False)
    return out


def outputs(commands: list[list[str]], folder: Path) -> dict[str, bytes]:
    """Each command's printed output and every file it wrote into ``folder`` (emptied first: the
    outputs compared are written to one folder, which the commands name), by name."""
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir()
    got = {}
    for k, command in enumerate(commands):
        result = runner.invoke(app, [a.format(out=folder / f"c{k}") for a in command])
        assert result.exit_code == 0, (command, result.output)
        got[f"c{k}.out"] = result.output.encode()
    got.update({p.name: p.read_bytes() for p in sorted(folder.iterdir())})
    return got


@pytest.fixture
def no_shipped_robots(tmp_path, monkeypatch):
    """The shipped robots made unreachable: the robot registry's folder is an empty one, and the
    working directory holds no robot of that name."""
    empty = tmp_path / "no-robots"
    empty.mkdir()
    monkeypatch.chdir(empty)
    return lambda: monkeypatch.setattr(robots, "robots_dir", lambda: empty)


def test_an_added_robots_dataset_is_analysed_the_same_with_its_folder_moved_away(tmp_path):
    assert runner.invoke(app, ["robots", "add", "ur5", "--from", str(UR5), "-o", str(tmp_path / "ur5")]).exit_code == 0
    ur5 = robots.load(tmp_path / "ur5")
    start = fleetlog_folder.date(2026, 3, 1)
    test = imported_fleet(tmp_path / "test", ur5, {0: (2, 8, 0.2), 2: (4, 8, 0.2)}, units=4, days=20, start=start)
    train = imported_fleet(tmp_path / "train", ur5, {1: (5, 6, 0.25)}, units=3, days=16, start=start)
    commands = [["info", str(test), "--card"],
                ["detect", str(test), "--train", str(train), "--first", "6", "--no-progress", "-o", "{out}"],
                ["bench-isolators", str(test), "--train", str(train), "--baseline", "6", "--no-progress", "-o", "{out}"]]
    with_folder = outputs(commands, tmp_path / "out")
    assert "robots ur5, tasks measured" in with_folder["c0.out"].decode()
    assert "0..peak motor torque: " + "; ".join(f"0..{t:.3g}" for t in ur5.motor_torque_limit) in \
        with_folder["c0.out"].decode()
    shutil.move(tmp_path / "ur5", tmp_path / "elsewhere")
    with pytest.raises(ValueError, match="unknown robot"):
        robots.load(tmp_path / "ur5")
    without = outputs(commands, tmp_path / "out")
    assert without == with_folder
    assert sorted(without) == ["c0.out", "c1-summary.csv", "c1.csv", "c1.md", "c1.out", "c1.png", "c2-confusion.csv",
                               "c2-confusion.png", "c2.csv", "c2.md", "c2.out", "c2.png"]


@pytest.fixture(scope="module")
def small(shared_sweep):
    return shared_sweep("analysis-small", robots=["irb6700"], tasks=["pick_place"], axes=[0, 1, 5], cycles=40)


def without(path: Path, out: Path, *names: str, arrays: tuple[str, ...] = ()) -> Path:
    """A copy of dataset ``path`` at ``out`` whose runs lack the attributes ``names`` and the arrays
    ``arrays``: a file as written before they existed."""
    shutil.copy(path, out)
    with h5py.File(out, "a") as f:
        for group in f["runs"].values():
            for name in names:
                del group.attrs[name]
            for name in arrays:
                del group[name]
    return out


def test_the_shipped_robots_unreachable_a_sweep_is_analysed_the_same(small, tmp_path, no_shipped_robots):
    # without torque_counts, detection bins the stored signals over the peak motor torque the run stored
    counted = without(small, tmp_path / "small.h5", arrays=("torque_counts",))
    commands = [["info", str(small), "--card"], ["detect", str(small), "--no-progress", "-o", "{out}"],
                ["detect", str(counted), "--no-progress", "-o", "{out}"]]
    reachable = outputs(commands, tmp_path / "out")
    card = reachable["c0.out"].decode()
    assert "| irb6700 | 6 | " in card and "0..the task's speed limit: 0..1.92; 0..1.92; 0..1.92; 0..3.32;" in card
    no_shipped_robots()
    with pytest.raises(ValueError, match="unknown robot 'irb6700'"):
        robots.load("irb6700")
    assert outputs(commands, tmp_path / "out") == reachable
    for name in ("c1.csv", "c1-summary.csv", "c1.md"):  # the signals binned give the stored counts' detection
        assert reachable[name] == reachable[name.replace("c1", "c2")]


def test_a_file_written_before_the_stored_limits_reads_and_analyses_the_same(tmp_path, no_shipped_robots):
    puma = robots.load("puma560")
    start = fleetlog_folder.date(2026, 3, 1)
    test = imported_fleet(tmp_path / "test", puma, {0: (2, 8, 0.2), 2: (4, 8, 0.2)}, units=4, days=20, start=start)
    train = imported_fleet(tmp_path / "train", puma, {1: (1, 6, 0.25)}, units=3, days=16, start=start)
    # `drivetrain` and `n_axes` were stored since robots of 5-7 axes; `limits` is new (issue 57)
    older = without(test, tmp_path / "older.h5", "limits")
    oldest = without(test, tmp_path / "oldest.h5", "limits", "drivetrain", "n_axes")
    assert dataset.validate(older) == [] and dataset.validate(oldest) == []
    with faultgen.open(test) as new, faultgen.open(older) as old, faultgen.open(oldest) as older_still:
        for a, b, c in zip(new.runs, old.runs, older_still.runs, strict=True):
            assert not a.limits.from_files and b.limits.from_files and c.drivetrain.from_files
            assert not a.drivetrain.from_files and not b.drivetrain.from_files
            for got in (b.limits, c.limits):
                np.testing.assert_array_equal(got.joint_range, a.limits.joint_range)
                np.testing.assert_array_equal(got.velocity, a.limits.velocity)
                np.testing.assert_array_equal(got.task_velocity, a.limits.task_velocity)
            np.testing.assert_array_equal(c.drivetrain.motor_torque_limit, a.drivetrain.motor_torque_limit)
            np.testing.assert_array_equal(c.drivetrain.friction["coulomb_pos"], a.drivetrain.friction["coulomb_pos"])
            assert a.model_sha256 == b.model_sha256 == dataset.model_hash(puma.path)
    np.testing.assert_array_equal(a.limits.joint_range, puma.joint_range)
    np.testing.assert_array_equal(a.limits.velocity, programs.robot_limits(puma)[0])

    def analysed(path: Path) -> dict[str, bytes]:
        got = outputs([["info", str(path), "--card"],
                       ["detect", str(path), "--train", str(train), "--first", "6", "--no-progress", "-o", "{out}"]],
                      tmp_path / "out")
        got["c0.out"] = got["c0.out"].replace(str(path).encode(), b"FILE").replace(path.name.encode(), b"FILE")
        got["c1.out"] = got["c1.out"].replace(str(path).encode(), b"FILE")
        return got

    assert analysed(older) == analysed(oldest) == analysed(test)
    # an older file needs the robot's files, and says so when they are not here; a new one does not
    no_shipped_robots()
    assert runner.invoke(app, ["info", str(test), "--card"]).exit_code == 0
    result = runner.invoke(app, ["info", str(older), "--card"])
    assert result.exit_code == 2 and "was written before runs stored their limits" in result.output
    assert "unknown robot 'puma560'" in result.output


def test_a_bad_limits_attribute_is_named_by_validate_and_the_reader(tmp_path):
    puma = robots.load("puma560")
    path = imported_fleet(tmp_path, puma, {}, units=1, days=3, start=fleetlog_folder.date(2026, 3, 1))
    with h5py.File(path, "a") as f:
        f["runs"]["u1"].attrs["limits"] = '{"joint_range": [[0, 1]], "velocity": [1], "task_velocity": [1]}'
    assert dataset.validate(path) == ["run u1: limits joint_range: expected 6 pairs of finite numbers, low below "
                                      "high, got [[0, 1]]"]
    with h5py.File(path, "a") as f:
        f["runs"]["u1"].attrs["limits"] = "not json"
    with pytest.raises(dataset.DatasetError, match="attribute 'limits' is not JSON"):
        faultgen.open(path)


def test_two_versions_of_one_robot_are_compared_by_what_each_stored(tmp_path):
    puma = robots.load("puma560")
    start = fleetlog_folder.date(2026, 3, 1)
    test = imported_fleet(tmp_path / "test", puma, {0: (2, 4, 0.2)}, units=2, days=10, start=start)
    train = shutil.copy(test, tmp_path / "train.h5")
    with h5py.File(train, "a") as f:  # another version of puma560: its joint ranges 10 % narrower
        for group in f["runs"].values():
            table = json.loads(group.attrs["limits"])
            table["joint_range"] = (0.9 * np.array(table["joint_range"])).tolist()
            group.attrs.update({"limits": json.dumps(table), "model_sha256": "f" * 64})
    assert dataset.validate(train) == []
    result = runner.invoke(app, ["detect", str(test), "--train", str(train), "--first", "4", "--no-progress",
                                 "-o", str(tmp_path / "d")])
    assert result.exit_code == 2, result.output
    assert f"robots 'puma560' and 'puma560' (models ffffffffffff and {dataset.model_hash(puma.path)[:12]})" in \
        result.output and "differ in their joint range" in result.output
    with faultgen.open(test) as a, faultgen.open(test) as b:  # the same version: comparable
        crossdata.check_comparable(a, b)


def test_a_program_files_own_speed_limits_are_stored_and_carded(tmp_path):
    text = programs.export(robots.load("puma560"), "pick_place").replace('name = "pick_place"', 'name = "slow_pp"')
    assert "velocity = [100, 95, 100, 150, 130, 110]" in text
    program = tmp_path / "slow.toml"
    program.write_text(text.replace("velocity = [100, 95, 100, 150, 130, 110]", "velocity = [80, 80, 80, 120, 100, 90]"))
    out = tmp_path / "slow.h5"
    result = runner.invoke(app, ["simulate", "--robot", "puma560", "--task", str(program), "--cycles", "2", "-o", str(out)])
    assert result.exit_code == 0, result.output
    with faultgen.open(out) as data:
        limits = data.runs[0].limits
    np.testing.assert_allclose(np.degrees(limits.task_velocity), [80, 80, 80, 120, 100, 90], rtol=1e-12)
    np.testing.assert_array_equal(limits.velocity, programs.robot_limits(robots.load("puma560"))[0])
    card = runner.invoke(app, ["info", str(out), "--card"])
    assert card.exit_code == 0, card.output  # before the runs stored it: "unknown task 'slow_pp'"
    assert "| puma560 | slow_pp | speed_hist | rad/s (arm) | 0..the task's speed limit: 0..1.4; 0..1.4; 0..1.4; 0..2.09; " \
           "0..1.75; 0..1.57 |" in card.output
