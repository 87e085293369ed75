"""Issue 61, item 3: hostile benchmark folders. ``faultgen bench score`` (and every reader of a
benchmark folder, faultgen.bench.files) opens ``train.h5`` and ``test.h5`` through the guarded
opener of the dataset readers (faultgen.inputs) and reads ``test_labels.csv`` only as a bounded
regular file inside the folder: an external link, a virtual dataset, a declared shape of 10^10
rows, a missing attribute and a labels symlink leaving the folder are each refused with exit 2,
one ``error:`` line naming the file, and nothing of the other file used or shown.

The folders are built in a few milliseconds with :func:`faultgen.bench.files.write` and
:func:`~faultgen.bench.files.write_labels` (no track is made)."""

from __future__ import annotations

import json
import re

import bench_plugins
import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

from faultgen.bench import files, make, score
from faultgen.cli import app
from faultgen.inputs import InputError

runner = CliRunner()

#: A value no real feature has: it must never reach a score or an error message.
MARKER = 987654.125
#: The first line of a file outside the folder: it must never appear in an error.
MARKER_LINE = "SECRET-MARKER-7f3a9c-outside-the-benchmark-folder"
RECORDS, AXES = 8, 6


def _unit(uid: str, k: int, worn_axis: int, top: float = 40.0) -> files.Unit:
    rng = np.random.default_rng(k)
    arrays = {"cycles": np.arange(1, RECORDS + 1)}
    for name in files.FEATURES:
        arrays[name] = 1.0 + rng.random((RECORDS, AXES))
    if worn_axis:
        arrays["mean_abs_torque"][:, worn_axis - 1] += np.linspace(0, 2, RECORDS)
    level = np.linspace(0, top, RECORDS) if worn_axis else np.zeros(RECORDS)
    return files.Unit(id=uid, robot="irb6700", task="pick_place", sample="cycle", arrays=arrays,
                      fault_level=level, worn_axis=worn_axis, fault="friction_wear" if worn_axis else "none")


def _folder(root, track="thesis", version=2, axes=((0, 2), (0, 3, 5)), top=40.0):
    """A benchmark folder as `bench make` writes it: train units worn on ``axes[0]`` and test units on
    ``axes[1]`` (0: healthy) up to ``top`` %, the test labels apart."""
    folder = root / "bench"
    folder.mkdir()
    attrs = {"track": track, "version": version, "size": "small", "licence": "CC0-1.0"}
    train = [_unit(f"train-{k:03d}", k, axis, top) for k, axis in enumerate(axes[0])]
    test = [_unit(f"test-{k:03d}", 10 + k, axis, top) for k, axis in enumerate(axes[1])]
    files.write(folder / "train.h5", train, {**attrs, "split": "train"})
    files.write_labels(folder / "test_labels.csv", test)
    for unit in test:
        unit.fault_level = unit.worn_axis = unit.fault = None
    files.write(folder / "test.h5", test, {**attrs, "split": "test"})
    return folder


def _outside(root):
    """A benchmark file outside the folder whose features are all MARKER."""
    other = root / "elsewhere"
    other.mkdir()
    unit = _unit("test-001", 99, 0)
    unit.arrays = {name: np.full_like(values, MARKER) if name != "cycles" else values
                   for name, values in unit.arrays.items()}
    unit.fault_level = unit.worn_axis = unit.fault = None
    files.write(other / "other.h5", [unit], {"track": "thesis", "version": 2, "size": "small"})
    return other / "other.h5"


def _cli_score(folder, out):
    return runner.invoke(app, ["bench", "score", "thesis", "--data", str(folder), "--isolator",
                               "bench_plugins:AlwaysBacklash", "--allow-modified", "-o", str(out)])


def _refused(result, out, *absent):
    """Exit 2, one ``error:`` line, no traceback, no score written, none of ``absent`` shown."""
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)
    assert not out.with_name(out.name + ".json").exists() and not out.with_name(out.name + ".md").exists()
    for text in absent:
        assert text not in result.output
    return lines[0]


def test_a_clean_tiny_folder_scores_and_a_labels_symlink_inside_the_folder_is_read(tmp_path):
    folder = _folder(tmp_path)
    (folder / "labels").mkdir()
    (folder / "test_labels.csv").rename(folder / "labels" / "real.csv")
    (folder / "test_labels.csv").symlink_to("labels/real.csv")
    result = _cli_score(folder, tmp_path / "ok")
    assert result.exit_code == 0, result.output
    results = json.loads((tmp_path / "ok.json").read_text())
    assert results["track"] == "thesis" and results["results"]["top1_accuracy"]["units"] == 2
    # the manifest's reader too: per unit its attributes and arrays (cycles, 4 features; fault_level in train)
    assert len(make.hashes(folder)) == 2 * 7 + 3 * 6 + 1


def test_an_external_link_to_a_file_outside_the_folder_is_refused(tmp_path):
    """(a) test.h5's unit array an external link to a file outside the folder: refused, its values
    never scored (before: followed, and the score changed with the other file)."""
    folder, other = _folder(tmp_path), _outside(tmp_path)
    with h5py.File(folder / "test.h5", "r+") as f:
        del f["units/test-001/mean_abs_torque"]
        f["units/test-001/mean_abs_torque"] = h5py.ExternalLink(str(other), "/units/test-001/mean_abs_torque")
    with pytest.raises(InputError, match=r"test\.h5: /units/test-001/mean_abs_torque is an external link to "):
        files.read(folder / "test.h5")
    with pytest.raises(InputError, match="external link"):
        score.score(folder, bench_plugins.AlwaysBacklash(), "always", "isolator")
    line = _refused(_cli_score(folder, tmp_path / "a"), tmp_path / "a", str(MARKER), "987654")
    assert "test.h5" in line and "external link" in line


def test_a_virtual_dataset_reading_another_file_is_refused(tmp_path):
    """(b) a virtual dataset in train.h5 whose source is a file outside the folder."""
    folder, other = _folder(tmp_path), _outside(tmp_path)
    with h5py.File(folder / "train.h5", "r+") as f:
        del f["units/train-001/rms_torque"]
        layout = h5py.VirtualLayout(shape=(RECORDS, AXES), dtype="f8")
        layout[:] = h5py.VirtualSource(str(other), "/units/test-001/rms_torque", shape=(RECORDS, AXES))
        f["units/train-001"].create_virtual_dataset("rms_torque", layout)
    with pytest.raises(InputError, match=r"train\.h5: /units/train-001/rms_torque is a virtual dataset reading"):
        files.read(folder / "train.h5")
    line = _refused(_cli_score(folder, tmp_path / "b"), tmp_path / "b", str(MARKER))
    assert "virtual dataset" in line


@pytest.mark.parametrize("array", ["rms_torque", "cycles"])
def test_a_declared_shape_of_ten_billion_rows_is_refused_before_any_read(tmp_path, array):
    """(c) a chunked dataset declaring 10^10 rows, no data written (the file stays small): an
    InputError from the declared shape (before: MemoryError, 447 GiB asked for)."""
    folder = _folder(tmp_path)
    with h5py.File(folder / "train.h5", "r+") as f:
        group = f["units/train-000"]
        del group[array]
        shape = (10**10,) if array == "cycles" else (10**10, AXES)
        group.create_dataset(array, shape=shape, maxshape=(None, *shape[1:]), chunks=(1024, *shape[1:]),
                             dtype="i8" if array == "cycles" else "f8")
    assert (folder / "train.h5").stat().st_size < 2**20
    with pytest.raises(InputError, match=rf"train\.h5.*(unit 'train-000'.*{array}|/units/train-000/{array})"):
        files.read(folder / "train.h5")
    _refused(_cli_score(folder, tmp_path / "c"), tmp_path / "c")


@pytest.mark.parametrize("name", ["robot", "worn_axis", "fault"])
def test_a_missing_attribute_is_named(tmp_path, name):
    """(d) a train unit without an attribute: an InputError naming the file, the unit and the
    attribute (before: KeyError)."""
    folder = _folder(tmp_path)
    with h5py.File(folder / "train.h5", "r+") as f:
        del f["units/train-001"].attrs[name]
    with pytest.raises(InputError, match=rf"train\.h5: unit 'train-001': no attribute '{name}'; .* is expected"):
        files.read(folder / "train.h5")
    line = _refused(_cli_score(folder, tmp_path / "d"), tmp_path / "d")
    assert f"no attribute '{name}'" in line


def test_wrong_types_and_missing_arrays_are_named(tmp_path):
    folder = _folder(tmp_path)
    with h5py.File(folder / "test.h5", "r+") as f:
        f["units/test-002"].attrs["robot"] = np.arange(3)
    with pytest.raises(InputError, match=r"test\.h5: unit 'test-002': attribute 'robot' is of type int64 and shape "
                                         r"\(3,\); a text \(the robot.s name\) is expected"):
        files.read(folder / "test.h5")
    with h5py.File(folder / "test.h5", "r+") as f:
        f["units/test-002"].attrs["robot"] = "irb6700"
        del f["units/test-002/mean_abs_torque"]
        f["units/test-002/mean_abs_torque"] = np.full((RECORDS, AXES), b"x")
    with pytest.raises(InputError, match=r"test\.h5: /units/test-002/mean_abs_torque holds \|S1 values; numbers"):
        files.read(folder / "test.h5")
    with h5py.File(folder / "test.h5", "r+") as f:
        del f["units/test-002/mean_abs_torque"]
    with pytest.raises(InputError, match=r"test\.h5: unit 'test-002': no array 'mean_abs_torque'"):
        files.read(folder / "test.h5")


def test_a_labels_symlink_leaving_the_folder_is_refused_without_echoing_its_target(tmp_path):
    """(e) test_labels.csv a symlink to a file outside the folder whose first line is a marker:
    refused, the link named, the marker never shown (before: `columns ['SECRET-...']`)."""
    folder = _folder(tmp_path)
    secret = tmp_path / "elsewhere.csv"
    secret.write_text(MARKER_LINE + "\nsecond line\n")
    (folder / "test_labels.csv").unlink()
    (folder / "test_labels.csv").symlink_to(secret)
    test = files.read(folder / "test.h5")
    with pytest.raises(InputError, match=r"test_labels\.csv: a symbolic link to a file outside the benchmark folder") \
            as err:
        files.attach_labels(test, folder / "test_labels.csv")
    assert MARKER_LINE not in str(err.value) and "SECRET" not in str(err.value)
    line = _refused(_cli_score(folder, tmp_path / "e"), tmp_path / "e", MARKER_LINE, "SECRET")
    assert "test_labels.csv" in line


def test_label_rows_with_bad_values_name_the_file_and_row(tmp_path):
    folder = _folder(tmp_path)
    test = files.read(folder / "test.h5")
    labels = folder / "test_labels.csv"
    good = labels.read_text().splitlines()
    for row, message in ((["unit,cycle,level"], r"row 1: columns \['unit', 'cycle', 'level'\]; expected unit, cycle"),
                         ([good[0], "test-000,1,abc,0,none"], r"row 2: fault_level_pct 'abc'; expected a finite number"),
                         ([good[0], "test-000,1,nan,0,none"], r"row 2: fault_level_pct 'nan'; expected a finite"),
                         ([good[0], good[1], "test-000,2,0.0"], r"row 3: 3 fields; 5 are expected"),
                         ([*good, good[1]], rf"row {len(good) + 1}: more label rows than the {3 * RECORDS} records")):
        labels.write_text("\n".join(row) + "\n")
        with pytest.raises(InputError, match=r"test_labels\.csv, " + message):
            files.attach_labels(test, labels)


@pytest.mark.parametrize("plugin, message", [
    ("AlarmsOnlyRaising", r"plug-in 'bench_plugins:AlarmsOnlyRaising': predict\(X\) of X \(8, 24\) failed: KeyError"),
    ("ClassifierTooFewAlarms", r"predict\(X\) gave shape \(2,\), dtype bool for X \(8, 24\); the detector contract"),
    ("ClassifierFlatProbabilities", r"predict_proba\(X\) gave shape \(0,\) or non-finite values for X \(8, 24\)"),
])
def test_a_detector_plug_in_breaking_the_detect_contract_is_refused_on_one_line(tmp_path, plugin, message):
    """Issue 61, item 7: `bench score --detector` holds a plug-in to the contract `detect` holds it to
    (analysis.plugins): one without decision_function whose predict raises, a classifier answering
    too few alarms, a 1-D predict_proba (before: a KeyError or IndexError traceback, exit 1)."""
    folder = _folder(tmp_path)
    result = runner.invoke(app, ["bench", "score", "thesis", "--data", str(folder), "--detector",
                                 f"bench_plugins:{plugin}", "--allow-modified", "-o", str(tmp_path / "s")])
    line = _refused(result, tmp_path / "s")
    assert re.search(message, line), line
