"""Issue 48: the sim-to-real track (a track part of kind ``logs``: a fleet of the independent
simulator, faultgen/bench/independent.py, read by ``faultgen logs import``) at its test size: the
make against its frozen manifest, the labels apart and equal to the simulator's truth, a stopped make
that resumes, and the recipe errors."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

from faultgen.bench import files, independent, make, tracks
from faultgen.data import fleetlogs


@pytest.fixture(scope="module")
def sim_to_real(shared_bench):
    """The latest version at its test size, made by the command (in the version's numeric profile)
    once a session (conftest.py)."""
    folder = shared_bench("sim-to-real")
    return folder, json.loads((folder / "manifest.json").read_text())


def test_sim_to_real_is_made_against_its_frozen_manifest_with_the_fleet_as_the_test_split(sim_to_real):
    folder, manifest = sim_to_real
    assert manifest["status"] == "checked"  # faultgen/bench/manifests/sim-to-real-2-small.json
    frozen = json.loads(make.manifest_path("sim-to-real", 2, "small").read_text())["arrays"]
    assert manifest["arrays"] == frozen
    train, test = files.read(folder / "train.h5"), files.read(folder / "test.h5")
    # train: faultgen's simulation (cycles); test: the independent fleet's logs, one record a day
    assert {(u.robot, u.task, u.sample) for u in train} == {("kr210", "pick_place", "cycle")}
    assert {(u.robot, u.task, u.sample) for u in test} == {("kr210", "pick_place", "log")}
    assert all(u.fault_level is None and u.worn_axis is None for u in test)
    # the labels apart are the simulator's truth (3 units, 2 worn, 24 days; small size of the fleet part)
    spec = independent.FleetSpec(units=3, worn=2, days=24, onset=(6, 10), final_wear=60.0, seed=2)
    truth = {}
    for unit, _, axis, wear in independent.truth_rows(spec):
        truth.setdefault(unit, (axis, []))[1].append(float(wear))
    labelled = files.attach_labels(test, folder / "test_labels.csv")
    got = sorted((u.worn_axis, tuple(np.round(u.fault_level, 4))) for u in labelled)
    assert got == sorted((axis, tuple(wear)) for axis, wear in truth.values())
    assert sum(axis > 0 for axis, _ in truth.values()) == 2 and all(len(u.arrays["cycles"]) == 24 for u in test)


#: sim-to-real version 1's recipe (its third-party robot, its faultgen part and its fleet part of kind
#: logs) at a smaller test size: one 3-cycle train run and a fleet of 2 units over 4 days.
STOPPABLE = """name = "stoppable"
summary = "sim-to-real version 1 at a smaller test size"
licence = "CC0-1.0"
[[versions]]
version = 1
train_seeds = [0, 1]
test_seeds = [2]
small = { axes = [2], cycles = 3, seeds = [0] }
[[versions.robots]]
name = "kr210"
from = "rtbdata:xacro/kuka_description/kuka_kr210/urdf/kr210l150.urdf"
packages = { kuka_kr210_support = "rtbdata:xacro/kuka_description/kuka_kr210" }
[[versions.parts]]
name = "faultgen"
robots = ["kr210"]
tasks = ["pick_place"]
axes = [0, 1, 2, 3, 4, 5]
increases = [60.0]
schedules = ["linear"]
cycles = 120
test_seeds = []
conditions = { thermal = {}, payloads = { masses = [10.0, 30.0], sizes = [0.1547, 0.2231], pattern = "random" }, \
spread = {}, cycles_per_day = 1, start_day = 0.0 }
[[versions.parts]]
name = "fleet"
kind = "logs"
robot = "kr210"
task = "pick_place"
fleet = { units = 12, worn = 8, days = 120, onset = [20, 50], final_wear = 60.0 }
small = { units = 2, worn = 1, days = 4, onset = [2, 3] }
train_seeds = []
"""


def test_a_stopped_make_resumes_from_the_sweep_and_the_logs_it_finished(tmp_path, monkeypatch):
    """Stopped (Ctrl-C) at the import of the fleet's logs: the train sweep and the fleet are done and kept
    beside the output; the make run again makes neither again and gives the manifest of a make never
    stopped. In this process (to stop it), so a version without a numeric profile, checked against a
    make of this process rather than a frozen manifest (made on one kind of processor): sim-to-real
    version 1's recipe at a smaller size (:data:`STOPPABLE`; the sizes do not enter the resume)."""
    folder = tmp_path / "tracks"
    folder.mkdir()
    (folder / "stoppable.toml").write_text(STOPPABLE)
    monkeypatch.setattr(tracks, "_folder", lambda: folder)
    monkeypatch.setattr(make, "manifest_path", lambda t, v, s: tmp_path / f"{t}-{v}-{s}.json")
    unstopped = make.make("stoppable", tmp_path / "unstopped", size="small", progress=False)
    real_import = fleetlogs.import_logs
    seen = []

    def stopped(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(fleetlogs, "import_logs", stopped)
    with pytest.raises(KeyboardInterrupt):
        make.make("stoppable", tmp_path / "out", size="small", progress=False)
    assert not (tmp_path / "out").exists()
    sweeps = tmp_path / ".out.stoppable-1-small.sweeps"
    done = sorted(p for p in sweeps.rglob("*") if p.is_file() and p.suffix in (".h5", ".csv", ".xml"))
    assert sweeps / "train-faultgen.h5" in done and len([p for p in done if p.parent.name.startswith("unit")]) == 8
    before = {p: os.stat(p).st_mtime_ns for p in done}

    def spy(*args, **kwargs):  # at the import, everything made before the stop is as it was
        seen.append({p: os.stat(p).st_mtime_ns for p in done})
        return real_import(*args, **kwargs)

    monkeypatch.setattr(fleetlogs, "import_logs", spy)
    manifest = make.make("stoppable", tmp_path / "out", size="small", progress=False)
    assert len(seen) == 1 and [p.name for p in before if seen[0][p] != before[p]] == []
    assert manifest["arrays"] == unstopped["arrays"] and not sweeps.exists()
    made = {key.split("/")[2] for key in manifest["arrays"] if "/units/" in key and "@" not in key}
    assert made == {"train-000", "test-000", "test-001"}


def test_a_logs_part_must_name_an_added_robot_and_a_source_must_be_installed():
    version = {"version": 1, "train_seeds": [0], "test_seeds": [1],
               "parts": [{"robots": ["irb6700"], "test_seeds": []},
                         {"name": "fleet", "kind": "logs", "robot": "kr210", "task": "pick_place", "train_seeds": []}]}
    track = {"name": "x", "summary": "s", "licence": "CC0-1.0", "versions": [version]}
    with pytest.raises(ValueError, match=r"logs part 'fleet': robot 'kr210' must be one of .* \(none\)"):
        tracks.parse(track, "x.toml")
    version["robots"] = [{"name": "kr210", "from": "rtbdata:xacro/kuka_description/kuka_kr210/urdf/kr210l150.urdf"}]
    parsed = tracks.parse(track, "x.toml").version()
    assert [name for name, _ in parsed.fleets("test")] == ["fleet-1"] and parsed.fleets("train") == []
    with pytest.raises(ValueError, match="'no_such_data' is not installed.*faultgen-robots\\[bench\\]"):
        tracks.source_path("no_such_data:robot.urdf")
    with pytest.raises(ValueError, match="nope.urdf does not exist in the installed 'rtbdata'"):
        tracks.source_path("rtbdata:nope.urdf")


def test_transfer_v2_adds_the_urdf_robot_to_the_test_split_and_leaves_v1_as_frozen():
    track = tracks.load("transfer")
    v1, v2 = track.version(1), track.version(2)
    assert track.latest == 3 and v1.robots == [] and [r["name"] for r in v2.robots] == ["kr210"]
    assert track.version(3).robots == v2.robots  # version 3: version 2 in the numeric profile
    assert v2.grids("train", "small") == v1.grids("train", "small")  # the same nominal unit to learn
    tested = {(name, tuple(fields["robots"])) for name, fields in v2.grids("test", "small")}
    assert tested == {("other_units", ("irb6700",)), ("urdf_robot", ("kr210",))}
    for size in ("small", "full"):  # version 1's frozen manifests stay (faultgen bench make --version 1 checks them)
        assert json.loads(make.manifest_path("transfer", 1, size).read_text())["version"] == 1
    assert json.loads(make.manifest_path("transfer", 2, "small").read_text())["status"] == "frozen"
    assert tracks.source_path(v2.robots[0]["from"]).name == "kr210l150.urdf"


def test_without_pinocchio_the_track_is_refused_before_any_sweep_naming_the_extra(tmp_path, monkeypatch):
    def missing():
        raise ImportError("the independent simulator needs Pinocchio: pip install 'faultgen-robots[bench]'")

    monkeypatch.setattr(independent, "pinocchio_module", missing)
    with pytest.raises(ValueError, match=r"track sim-to-real version 1: .*faultgen-robots\[bench\]"):
        make.make("sim-to-real", tmp_path / "out", version=1, size="small", progress=False)
    assert list(tmp_path.iterdir()) == []
