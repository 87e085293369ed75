"""Hostile inputs, round 4: benchmark folders and the CSV files faultgen writes.

- ``bench score`` (and ``bench score prognostics``) compares the folder with the track version's
  frozen manifest (the SHA-256 of every array and of test_labels.csv, faultgen.bench.make.compare):
  a folder that differs is refused in one line naming the file and array, or, with
  ``--allow-modified``, scored with a warning naming them and a verdict marked NOT COMPARABLE.
- every value a benchmark reader reads is checked against the range a run writes (finite; wear
  0..500 %; a prognoser's times of end of life 0..1e9 or inf).

The folders are built in milliseconds by tests/test_bench_hostile.py's `_folder` (faultgen.bench.files);
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

from faultgen.bench import make, prognosers, prognostics
from faultgen.cli import app
from faultgen.data import cells
from faultgen.inputs import InputError
from test_bench_hostile import _folder  # the same hand-built folder

runner = CliRunner()


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


@pytest.mark.parametrize(("where", "array", "at", "value", "named"), [
    ("train.h5", "units/train-001/fault_level", 2, 1e308, "fault_level holds 1e+308 at record 3"),
    ("train.h5", "units/train-000/fault_level", 4, -50.0, "fault_level holds -50.0 at record 5"),
    ("test.h5", "units/test-001/rms_torque", (1, 2), -np.inf, "rms_torque holds -inf at record 2"),
    ("test.h5", "units/test-000/cycles", 0, -3, "cycles holds -3 at record 1"),
])
def test_a_value_outside_the_range_a_run_writes_is_refused_naming_file_unit_and_array(tmp_path, where, array, at, value,
                                                                                     named):
    import h5py

    folder = _prognostics_folder(tmp_path)
    with h5py.File(folder / where, "r+") as f:
        f[array][at] = value
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


# -- every CSV faultgen writes: one cell function (faultgen.data.cells) -------------------------------

EVIL = ("=1+1\r\nevil", "x\r=1+1")


def _checked_csv(path) -> list[list[str]]:
    """The rows of a CSV file faultgen wrote, after checking that no row spans lines (for a reader that
    splits at any line break, str.splitlines) and that no text cell starts with a formula character."""
    import io

    content = path.read_text()
    rows = list(csv.reader(io.StringIO(content, newline="")))
    assert len(content.splitlines()) == len(rows), f"{path.name}: a row split across lines"
    for row in rows:
        for value in row:
            assert not value.lstrip(" ").startswith(cells.FORMULA) or cells._NUMBER.fullmatch(value.strip()), \
                (path.name, value)
    return rows


@pytest.fixture(scope="module")
def evil_fleet(tmp_path_factory):
    """Two units of 11 daily logs named with a line break and a formula, beside a plain one."""
    import fleetlog_folder

    from faultgen.model import robots

    logs = fleetlog_folder.write_fleet(tmp_path_factory.mktemp("evil") / "LOGS", robots.load("puma560"), units=3,
                                       days=11)
    for k, name in enumerate(EVIL, start=1):
        (logs / f"u{k}").rename(logs / name)
    return logs


def test_a_unit_named_with_a_line_break_and_a_formula_keeps_each_export_row_whole(evil_fleet, tmp_path):
    data, out = tmp_path / "d.h5", tmp_path / "e.csv"
    result = runner.invoke(app, ["logs", "import", str(evil_fleet), "--robot", "puma560", "-o", str(data),
                                 "--no-progress"])
    assert result.exit_code == 0, result.output
    result = runner.invoke(app, ["export", str(data), "-o", str(out)])
    assert result.exit_code == 0, result.output
    rows = _checked_csv(out)
    per_run = {}
    for row in rows[1:]:
        per_run[row[0]] = per_run.get(row[0], 0) + 1
    assert sorted(per_run) == ["'=1+1  evil", "u3", "x =1+1"]
    assert len(set(per_run.values())) == 1  # as many rows for each unit: none split


def test_the_monitors_csv_files_keep_a_unit_named_with_a_line_break_on_one_row(evil_fleet, tmp_path):
    result = runner.invoke(app, ["monitor", str(evil_fleet), "--robot", "puma560", "-o", str(tmp_path / "OUT"),
                                 "--protocol", "own", "--train", "10", "--no-progress"])
    assert result.exit_code == 0, result.output
    written = {name: _checked_csv(tmp_path / "OUT" / name)
               for name in ("units.csv", "alarms.csv", "scores.csv", "wear.csv", "rul.csv")}
    assert sorted(row[0] for row in written["units.csv"][1:]) == ["'=1+1  evil", "u3", "x =1+1"]
    per_unit = {}
    for row in written["scores.csv"][1:]:
        per_unit[row[0]] = per_unit.get(row[0], 0) + 1
    assert sorted(per_unit) == ["'=1+1  evil", "u3", "x =1+1"] and len(set(per_unit.values())) == 1  # 11 logs each


def test_a_cell_is_neutralised_only_where_it_is_text():
    assert cells.text("=1+1\r\nevil") == "'=1+1  evil" and cells.text("x\r=1+1") == "x =1+1"
    assert cells.text("\u2028@SUM(A1)") == "' @SUM(A1)" and cells.text("\t-x") == "'\t-x"
    for number in ("-1.5", "+3e-2", "-inf", "12"):
        assert cells.text(number) == number
    assert cells.line(["a,b", "=1", -2.5, "x\ny"]) == "\"a,b\",'=1,-2.5,x y"


#: CSV writes that do not go through faultgen.data.cells: none. Each entry: (file, line's text) of a
#: call the walk below finds that writes no CSV.
NOT_CSV = {
    ("faultgen/operation/faults.py", 'return ":".join([*fields, ",".join(options)] if options else fields)'),
    ("faultgen/calibrate/excitation.py", "atomic.write_text(path, self.to_csv(dt, periods))"),
}


def test_every_csv_faultgen_writes_goes_through_the_one_cell_function():
    """A walk of faultgen's and the analysis package's source: csv.writer and csv.DictWriter only in
    faultgen/data/cells.py; every DataFrame.to_csv on ``cells.escaped(...)``; every numpy.savetxt with
    ``header=cells.line(...)``; no comma-joined line (``",".join``, but in an f-string's message) but the
    ones of :data:`NOT_CSV`."""
    import ast
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    found = []
    for path in sorted([*root.glob("faultgen/**/*.py"), *root.glob("analysis/**/*.py")]):
        name = str(path.relative_to(root))
        source = path.read_text()
        lines = source.splitlines()
        tree = ast.parse(source)
        in_text = {id(n) for f in ast.walk(tree) if isinstance(f, ast.JoinedStr) for n in ast.walk(f)}  # messages
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call) or not isinstance(node.func, ast.Attribute) or id(node) in in_text:
                continue
            func, where = node.func, (name, lines[node.lineno - 1].strip())
            if where in NOT_CSV:
                continue
            if func.attr in ("writer", "DictWriter") and isinstance(func.value, ast.Name) and func.value.id == "csv":
                ok = name == "faultgen/data/cells.py"
            elif func.attr == "to_csv":
                receiver = func.value
                ok = isinstance(receiver, ast.Call) and getattr(receiver.func, "attr", None) == "escaped"
            elif func.attr == "savetxt":
                header = next((k.value for k in node.keywords if k.arg == "header"), None)
                ok = isinstance(header, ast.Call) and getattr(header.func, "attr", None) == "line"
            elif func.attr == "join" and isinstance(func.value, ast.Constant) and func.value.value == ",":
                ok = False
            else:
                continue
            if not ok:
                found.append(f"{name}:{node.lineno}: {where[1]}")
    assert not found, "CSV writes not through faultgen.data.cells:\n" + "\n".join(found)
