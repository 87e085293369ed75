"""Hostile dataset files (issue 50, items 2, 4 and 5): links to other files, virtual datasets,
declared shapes of 447 GiB, text where numbers belong, groups where arrays belong, empty run
groups and absurd attributes. Every command that reads a dataset, and ``faultgen.open``, refuses
each with exit 2 (a ``ValueError``), the file and the item named, no traceback, nothing written."""

import shutil

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

import faultgen
from faultgen.cli import app
from faultgen.inputs import InputError

runner = CliRunner()


@pytest.fixture(scope="module")
def small(shared_sweep):
    return shared_sweep("analysis-small", robots=["irb6700"], tasks=["pick_place"], axes=[0, 1, 5], cycles=40)


def _first_run(f):
    return f["runs"][next(iter(f["runs"]))]


def _external_runs(f, other):
    del f["runs"]
    f["runs"] = h5py.ExternalLink(str(other), "/runs")


def _virtual_cycles(f, other):
    group = _first_run(f)
    n = group["cycles"].shape[0]
    del group["cycles"]
    layout = h5py.VirtualLayout(shape=(n,), dtype="i8")
    layout[:] = h5py.VirtualSource(str(other), f"{group.name}/cycles", shape=(n,))
    group.create_virtual_dataset("cycles", layout)


def _huge_signal(f, other):
    group = _first_run(f)
    del group["tau_m"]
    group.create_dataset("tau_m", shape=(10**10, 6), dtype="f8", chunks=(1024, 6))


def _text_feature(f, other):
    group = _first_run(f)
    shape = group["rms_torque"].shape
    del group["rms_torque"]
    group["rms_torque"] = np.full(shape, b"x")


def _group_for_t(f, other):
    group = _first_run(f)
    del group["t"]
    group.create_group("t")


def _empty_run(f, other):
    run_id = next(iter(f["runs"]))
    del f["runs"][run_id]
    f["runs"].create_group(run_id)


def _absurd_cycles(f, other):
    _first_run(f).attrs["cycles"] = np.int64(10**15)


HOSTILE = {
    "external link": (_external_runs, r"/runs is an external link to .*other\.h5:/runs"),
    "virtual dataset": (_virtual_cycles, r"/runs/\S+/cycles is a virtual dataset reading .*other\.h5"),
    "declared (1e10, 6)": (_huge_signal, r"/runs/\S+/tau_m (has shape|declares) \(10000000000, 6\)"),
    "text feature": (_text_feature, r"/runs/\S+/rms_torque holds \|S1 values; numbers are expected"),
    "t is a group": (_group_for_t, r"/runs/\S+/t is a group, not a dataset"),
    "empty run group": (_empty_run, r"run '\S+': no attribute 'robot'; every run carries robot, task"),
    "cycles = 1e15": (_absurd_cycles, r"run '\S+': attribute 'cycles' is 1000000000000000; a whole number 1\.\.1000000000"),
}


@pytest.fixture(scope="module", params=sorted(HOSTILE))
def hostile(request, small, tmp_path_factory):
    folder = tmp_path_factory.mktemp("hostile")
    other = folder / "other.h5"
    shutil.copy(small, other)
    path = folder / "data.h5"
    shutil.copy(small, path)
    build, message = HOSTILE[request.param]
    with h5py.File(path, "r+") as f:
        build(f, other)
    return path, message


def _refused(result, path, message):
    assert result.exit_code == 2, result.output
    line = result.output.strip()
    assert line.startswith("error: ") and "\n" not in line and "Traceback" not in line, line
    assert str(path) in line
    assert __import__("re").search(message, line), line


@pytest.mark.parametrize("command", [["validate"], ["info"], ["info", "--card"], ["plot"], ["detect"]])
def test_every_dataset_command_refuses_a_hostile_file(hostile, tmp_path, command):
    path, message = hostile
    extra = {"plot": ["-o", str(tmp_path / "fig.png")], "detect": ["-o", str(tmp_path / "det")]}.get(command[0], [])
    result = runner.invoke(app, [command[0], str(path), *command[1:], *extra])
    _refused(result, path, message)
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_export_refuses_a_hostile_file_and_writes_nothing(hostile, tmp_path):
    path, message = hostile
    result = runner.invoke(app, ["export", str(path), "-o", str(tmp_path / "table.csv")])
    _refused(result, path, message)
    assert list(tmp_path.iterdir()) == []


def test_faultgen_open_refuses_a_hostile_file(hostile):
    path, message = hostile
    with pytest.raises(InputError, match=message):
        with faultgen.open(path) as data:
            data.features()


def test_the_untouched_copy_still_reads(small):
    """The refusals above come from the edits: the same file unedited opens and validates."""
    result = runner.invoke(app, ["validate", str(small)])
    assert result.exit_code == 0 and "valid" in result.output
    with faultgen.open(small) as data:
        assert len(data.runs) == 3 and data.features().shape[0] > 0
