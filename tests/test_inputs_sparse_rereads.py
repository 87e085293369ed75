"""Files read again after their bound was checked once, or never bounded (issue 86, item 3's
leftovers): the robot's model re-read by the calibration (:mod:`faultgen.calibrate.trial`,
:mod:`faultgen.calibrate.refit`), a sweep's record in OUT (``<parts>/sweep.json``) and a
reproduction's step records (``DIR/.steps/*.json``).

Each file is swapped for (or planted as) a sparse one made by ``os.truncate`` (nothing on disk) and
the reader must refuse it on its size, having read next to nothing (``/proc/self/io``, as in
``tests/test_inputs_sparse.py``), with the address space capped so that the old whole-file read
fails at once with a MemoryError instead of reading gigabytes of zeros.
"""

from __future__ import annotations

import json
import logging
import shutil
import sys
import types
from pathlib import Path

import mujoco
import pytest

from faultgen.calibrate import refit, trial
from faultgen.model import robots, sources
from faultgen.reproduce import runner
from faultgen.runs import sweep

sys.path.insert(0, str(Path(__file__).parent))
from test_inputs_sparse import address_space, io_bytes, sparse  # noqa: E402

GIB = 2**30
MIB = 2**20


@pytest.fixture
def robot(tmp_path):
    """puma560 loaded from a copy of its folder, so its MJCF can be swapped after the load."""
    folder = tmp_path / "puma560"
    shutil.copytree(robots.load("puma560").path.parent, folder)
    return robots.load(folder / "puma560.xml")


def test_the_nominal_model_is_the_file_read_once_and_its_loaded_spec(robot):
    model = trial.Model.nominal(robot)
    assert model.text == robot.path.read_text()  # the file's own text, as before
    assert model.xml == mujoco.MjSpec.from_file(str(robot.path)).to_xml()  # the same text to edit, not parsed again
    assert trial.file_text(robot) == model.text


def test_a_model_swapped_for_a_sparse_file_after_the_load_is_refused_on_its_size(robot):
    """20 GiB apparent since the load: ModelError naming the bound, not a MemoryError traceback."""
    sparse(robot.path, 20 * GIB)
    before = io_bytes()
    with address_space(), pytest.raises(
            robots.ModelError, match=rf"puma560\.xml: {20 * GIB} bytes; a robot MJCF is read up to "
                                     rf"{sources.MAX_DESCRIPTION_BYTES} bytes"):
        trial.Model.nominal(robot)
    assert io_bytes()[0] - before[0] < MIB


def test_a_model_changed_after_the_load_is_refused_by_its_digest(robot):
    text = robot.path.read_text()
    robot.path.write_text(text.replace("<mujoco", "<!-- edited -->\n<mujoco", 1))
    with pytest.raises(robots.ModelError, match=r"puma560\.xml: changed since the robot was read; load it again"):
        trial.file_text(robot)
    robot.path.write_bytes(b"\xff" + text.encode())
    with pytest.raises(robots.ModelError, match="changed since the robot was read"):
        trial.file_text(robot)


def test_refit_refuses_a_calibrated_model_swapped_for_a_sparse_file(robot):
    """refit read the calibrated model's file whole (``read_text``) after the loader had bounded it."""
    from mujoco import sysid  # noqa: F401 (imported here, so the bytes counted are refit's own reads)

    import faultgen.calibrate.prediction  # noqa: F401

    result = types.SimpleNamespace(model=robot, robot=robot.name, model_out=robot.path.parent, nominal_digest=None)
    sparse(robot.path, 20 * GIB)
    before = io_bytes()
    with address_space(), pytest.raises(robots.ModelError, match=rf"{20 * GIB} bytes; a robot MJCF is read up to"):
        refit.refit(result, None, robot)
    assert io_bytes()[0] - before[0] < MIB


# -- OUT's records ---------------------------------------------------------------------------------


def test_a_sparse_sweep_record_planted_in_out_is_not_read(tmp_path, caplog):
    """A killed sweep's record taken over: a 64 GiB sparse one is described without reading it."""
    out, parts = tmp_path / "out.h5", tmp_path / "out.h5.parts"
    parts.mkdir()
    sparse(parts / "sweep.json", 64 * GIB)
    before = io_bytes()
    with caplog.at_level(logging.WARNING), address_space():
        with sweep._claim(out, parts, "faultgen sweep again"):
            pass
    assert io_bytes()[0] - before[0] < MIB
    assert "took over" in caplog.text and "(a sweep that has not named itself yet)" in caplog.text
    assert not (parts / "sweep.json").exists()  # removed when the sweep ended, as before


@pytest.mark.parametrize(("content", "said"), [
    (json.dumps({"pid": 7, "host": "h", "started": "s", "command": "faultgen sweep x"}),
     "pid 7 on h, started s: faultgen sweep x"),
    (json.dumps({"pid": 7, "host": "h", "started": "s"}), "pid 7 on h, started s"),
    ("[1, 2]", "a sweep that has not named itself yet"),  # a TypeError traceback before
    ("[" * 200_000, "a sweep that has not named itself yet"),  # a RecursionError traceback before
    ("{", "a sweep that has not named itself yet"),
])
def test_a_sweep_record_is_described_or_passed_over(tmp_path, content, said):
    (tmp_path / "sweep.json").write_text(content)
    assert sweep._describe_holder(tmp_path) == said


def test_a_sweep_record_above_its_bound_is_passed_over(tmp_path, monkeypatch):
    monkeypatch.setattr(sweep, "HOLDER_MAX_BYTES", 100)
    record = json.dumps({"pid": 7, "host": "h", "started": "s", "command": "x" * 100})
    (tmp_path / "sweep.json").write_text(record)
    assert sweep._describe_holder(tmp_path) == "a sweep that has not named itself yet"
    monkeypatch.setattr(sweep, "HOLDER_MAX_BYTES", len(record))
    assert sweep._describe_holder(tmp_path) == "pid 7 on h, started s: " + "x" * 100


def test_a_sparse_step_record_is_no_record_and_the_output_it_claims_is_refused(tmp_path):
    """A reproduction's record planted as 64 GiB sparse: read as no record (nothing read), so the
    step's output there is a file no record claims and is refused before anything runs."""
    step = runner.Step("table", outputs=("table.csv",), call=lambda folder: None)
    (tmp_path / "table.csv").write_text("a\n1\n")
    (tmp_path / runner.RECORDS).mkdir()
    good = {"record": runner.records([step])["table"], "state": "done"}
    (tmp_path / runner.RECORDS / step.record_name).write_text(json.dumps(good))
    assert runner._read_record(step, tmp_path) == good
    runner.check_outputs([step], tmp_path)  # claimed: nothing refused
    sparse(tmp_path / runner.RECORDS / step.record_name, 64 * GIB)
    before = io_bytes()
    with address_space():
        assert runner._read_record(step, tmp_path) is None
        with pytest.raises(ValueError, match="table.csv"):
            runner.check_outputs([step], tmp_path)
    assert io_bytes()[0] - before[0] < MIB
    (tmp_path / runner.RECORDS / step.record_name).write_text("[" * 200_000)
    assert runner._read_record(step, tmp_path) is None  # a RecursionError traceback before


# -- the robot's files read again elsewhere --------------------------------------------------------


def test_a_datasets_model_hash_refuses_a_model_swapped_for_a_sparse_file(robot):
    """``model_sha256`` (every run of a sweep, every import) hashed the MJCF whole after the load."""
    from faultgen.data import dataset
    from faultgen.inputs import InputError

    import hashlib

    assert dataset.model_hash(robot.path) == hashlib.sha256(robot.path.read_bytes()).hexdigest()
    sparse(robot.path, 20 * GIB)
    before = io_bytes()
    with address_space(), pytest.raises(InputError, match=rf"{20 * GIB} bytes; a robot MJCF is read up to"):
        dataset.model_hash(robot.path)
    assert io_bytes()[0] - before[0] < MIB


def test_a_copy_with_another_timestep_reads_the_tasks_file_bounded(robot, tmp_path, monkeypatch):
    """``with_timestep`` copied the robot's ``tasks.toml`` whole (``shutil.copyfile``): the bound
    lowered to 1 MiB and the file made 64 MiB sparse, it is refused, nothing copied."""
    from faultgen import inputs

    made = robots.with_timestep(robot.path, 0.002, tmp_path / "copy")
    assert (made.parent / "tasks.toml").read_bytes() == (robot.path.parent / "tasks.toml").read_bytes()
    assert 'timestep="0.002"' in made.read_text()
    monkeypatch.setattr(inputs, "TOML_MAX_BYTES", MIB)
    sparse(robot.path.parent / "tasks.toml", 64 * MIB)
    before = io_bytes()
    with pytest.raises(robots.ModelError, match=rf"tasks\.toml: {64 * MIB} bytes; a tasks file is read up to {MIB}"):
        robots.with_timestep(robot.path, 0.002, tmp_path / "again")
    assert sum(io_bytes()) - sum(before) < MIB
