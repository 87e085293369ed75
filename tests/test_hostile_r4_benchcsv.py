"""Hostile inputs, round 4: benchmark folders and the CSV files faultgen writes.

- ``bench score`` (and ``bench score prognostics``) compares the folder with the track version's
  frozen manifest (the SHA-256 of every array and of test_labels.csv, faultgen.bench.make.compare):
  a folder that differs is refused in one line naming the file and array, or, with
  ``--allow-modified``, scored with a warning naming them and a verdict marked NOT COMPARABLE.
- every value a benchmark reader reads is checked against the range a run writes (finite; wear
  0..500 %; a prognoser's times of end of life 0..1e9 or inf).

The folders are built in milliseconds with faultgen.bench.files (as tests/test_bench_hostile.py);
their "frozen" manifest is their own hashes, through a patched ``make.manifest_path``, except in the
one test that reproduces the finding on the thesis track made once a session (conftest.py).
"""

from __future__ import annotations

import csv
import json
import shutil

import capped
import numpy as np
import pytest
from typer.testing import CliRunner

from faultgen.bench import files, make, prognosers, prognostics
from faultgen.cli import app
from faultgen.inputs import InputError

runner = CliRunner()
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
    """A benchmark folder as `bench make` writes it: train units, test units, their labels apart."""
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


@pytest.fixture
def frozen(tmp_path, monkeypatch):
    """A folder whose hashes are its track version's frozen manifest (in tmp_path, not the package)."""
    folder = _folder(tmp_path)
    manifest = tmp_path / "frozen.json"
    manifest.write_text(json.dumps({"arrays": make.hashes(folder)}))
    monkeypatch.setattr(make, "manifest_path", lambda t, v, s: manifest if (t, v, s) == ("thesis", 2, "small")
                        else tmp_path / "none.json")
    return folder


def _swap_labels(path, a: str, b: str) -> None:
    """The labels (fault level, worn axis, fault) of units ``a`` and ``b`` swapped, row for row."""
    rows = list(csv.reader(path.open()))
    mine = {u: [r for r in rows[1:] if r[0] == u] for u in (a, b)}
    for ra, rb in zip(mine[a], mine[b], strict=True):
        ra[2:], rb[2:] = rb[2:], ra[2:]
    with path.open("w", newline="") as f:
        csv.writer(f, lineterminator="\n").writerows(rows)


def _score(folder, out, *extra):
    return runner.invoke(app, ["bench", "score", "thesis", "--data", str(folder), "--isolator",
                               "bench_plugins:AlwaysBacklash", "-o", str(out), *extra])


def test_a_folder_equal_to_its_frozen_manifest_scores_comparable(frozen, tmp_path):
    result = _score(frozen, tmp_path / "s")
    assert result.exit_code == 0, result.output
    assert json.loads((tmp_path / "s.json").read_text())["comparable"] is True
    assert "NOT COMPARABLE" not in result.output


def test_swapped_test_labels_are_refused_naming_the_file_or_scored_marked_not_comparable(frozen, tmp_path):
    _swap_labels(frozen / "test_labels.csv", "test-000", "test-001")
    result = _score(frozen, tmp_path / "s")
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ")
    assert result.exception is None or isinstance(result.exception, SystemExit)
    assert f"{frozen / 'test_labels.csv'} differs from the frozen manifest of track thesis version 2" in lines[0]
    assert "--allow-modified" in lines[0] and not (tmp_path / "s.json").exists()
    result = _score(frozen, tmp_path / "s", "--allow-modified")
    assert result.exit_code == 0, result.output
    saved = json.loads((tmp_path / "s.json").read_text())
    assert saved["comparable"] is False and saved["modified_count"] == 1
    assert "WARNING: NOT COMPARABLE" in result.output and "test_labels.csv differs" in result.output
    assert "| NOT COMPARABLE" in (tmp_path / "s.md").read_text()  # the leaderboard row's verdict cell
    assert saved["verdicts"][0].startswith("WARNING: NOT COMPARABLE")


def test_a_changed_train_array_and_a_version_without_manifest_are_named(frozen, tmp_path):
    import h5py

    with h5py.File(frozen / "train.h5", "r+") as f:
        f["units/train-001/fault_level"][3] = 7.0
    with pytest.raises(InputError, match=r"train\.h5: array /units/train-001/fault_level differs from the frozen"):
        make.compare(frozen, {"track": "thesis", "version": 2, "size": "small"})
    with pytest.raises(InputError, match=r"test\.h5: track thesis version 9 \(small\) has no frozen manifest"):
        make.compare(frozen, {"track": "thesis", "version": 9, "size": "small"})
    with pytest.raises(InputError, match=r"track \.\./\.\./x version 2 \(small\) has no frozen manifest"):
        make.compare(frozen, {"track": "../../x", "version": 2, "size": "small"})
    checked = make.compare(frozen, {"track": "thesis", "version": 2, "size": "small"}, allow_modified=True)
    assert checked["comparable"] is False and "fault_level differs" in checked["modified"][0]


def test_the_thesis_tracks_swapped_labels_are_refused_by_the_command(shared_bench, tmp_path):
    """The finding: two test units' labels swapped in a real thesis folder scored AUROC 0.845 instead
    of 0.986 without a word; now refused against the manifest shipped in the package."""
    folder = tmp_path / "thesis"
    shutil.copytree(shared_bench("thesis"), folder, ignore=shutil.ignore_patterns("score-*"))
    labels = {r["unit"]: r["fault"] for r in csv.DictReader((folder / "test_labels.csv").open())}
    worn, healthy = next(u for u, f in labels.items() if f != "none"), next(u for u, f in labels.items() if f == "none")
    _swap_labels(folder / "test_labels.csv", worn, healthy)
    done = capped.run("bench", "score", "thesis", "--data", folder, "--baseline", "pca", "-o", tmp_path / "pca",
                      cwd=tmp_path)
    capped.one_line_refusal(done, folder / "test_labels.csv", "frozen manifest of track thesis version 2 (small)")
    assert not (tmp_path / "pca.json").exists()


def _prognostics_folder(root):
    return _folder(root, track="prognostics", version=1, axes=((2, 3), (1, 4)), top=60.0)


@pytest.mark.parametrize(("where", "change", "named"), [
    ("train.h5", lambda f: f["units/train-001/fault_level"].__setitem__(2, 1e308), "fault_level holds 1e+308 at record 3"),
    ("train.h5", lambda f: f["units/train-000/fault_level"].__setitem__(4, -50.0), "fault_level holds -50.0 at record 5"),
    ("test.h5", lambda f: f["units/test-001/rms_torque"].__setitem__((1, 2), -np.inf), "rms_torque holds -inf at record 2"),
    ("test.h5", lambda f: f["units/test-000/cycles"].__setitem__(0, -3), "cycles holds -3 at record 1"),
])
def test_a_value_outside_the_range_a_run_writes_is_refused_naming_file_unit_and_array(tmp_path, where, change, named):
    import h5py

    folder = _prognostics_folder(tmp_path)
    with h5py.File(folder / where, "r+") as f:
        change(f)
    done = capped.run("bench", "score", "prognostics", "--data", folder, "--baseline", "linear", "-o",
                      tmp_path / "lin", cwd=tmp_path)
    capped.one_line_refusal(done, folder / where, named, "are expected (what a run writes)")
    assert not (tmp_path / "lin.json").exists()


@pytest.mark.parametrize(("cell", "shown"), [("-50", "'-50'"), ("1e308", "'1e308'"), ("-Infinity", "'-Infinity'"),
                                             ("500.5", "'500.5'")])
def test_a_label_outside_0_to_500_percent_is_refused_naming_the_row(tmp_path, cell, shown):
    folder = _prognostics_folder(tmp_path)
    rows = list(csv.reader((folder / "test_labels.csv").open()))
    rows[5][2] = cell
    with (folder / "test_labels.csv").open("w", newline="") as f:
        csv.writer(f, lineterminator="\n").writerows(rows)
    with pytest.raises(InputError, match=rf"test_labels\.csv, row 6: fault_level_pct {shown}; expected a finite number "
                                         r"within 0\.\.500 \(%\)"):
        prognostics.score(folder, prognostics.baseline("linear"), "linear", allow_modified=True)


class MinusInfinity:
    def fit(self, units, failure_wear):
        return self

    def predict(self, unit):
        return np.array([5.0, -np.inf])


def test_a_prognoser_answering_minus_infinity_is_refused_not_read_as_no_end_of_life():
    """-inf was taken for "beyond the horizon" (+inf's meaning) and scored."""
    with pytest.raises(ValueError, match=r"m: predict\(\) at time 3 gave 1 samples that are NaN, -inf or outside "
                                         r"0\.\.1e\+09 \(the first -inf\)"):
        prognosers.samples(MinusInfinity().predict(None), "m", 3.0)
    for bad in ([-1.0], [2e9], [np.nan]):
        with pytest.raises(ValueError, match="NaN, -inf or outside"):
            prognosers.samples(np.array(bad), "m", 3.0)
    assert prognosers.samples(np.array([4.0, np.inf]), "m", 3.0).tolist() == [4.0, np.inf]
