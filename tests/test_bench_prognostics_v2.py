"""Issue 75, item 7 (track2): the prognostics track's version 2 (friction tests in the test split)
and the fleet's friction-test program carried as text (no cache path in a run's configuration)."""

import dataclasses
import json
import os
from collections import Counter

import numpy as np
import pytest

from faultgen.bench import files, make, prognosers, prognostics
from faultgen.data import dataset, writer
from faultgen.operation import friction_test, programs
from faultgen.operation.tasks import TextProgram
from faultgen.runs import fleet
from faultgen.simulation import stepping as sim

TINY = dict(size=2, days=6, cycles_per_day=1, models=("puma560",), failure_wear=50.0, friction_test_every=5)


def _tested_runs(cache, monkeypatch):
    monkeypatch.setenv("FAULTGEN_CACHE", str(cache))
    return fleet.Fleet(**TINY).runs()


def test_a_fleets_friction_test_travels_as_text_so_two_caches_make_the_same_runs_and_files(tmp_path, monkeypatch):
    """Two FAULTGEN_CACHE folders (two machines): the same test runs' keys, no file written into
    either cache, and one test run (cut to axis 1, 3 speeds and one cycle, for time) written to identical
    HDF5 bytes. Each cache's run is the one its own ``Fleet.runs()`` planned above (1.5 s of CPU a
    planning: not planned again)."""
    first = _tested_runs(tmp_path / "cache-a", monkeypatch)
    second = _tested_runs(tmp_path / "cache-b", monkeypatch)
    keys = [[dataset.config_key(c) for _, c in runs] for runs in (first, second)]
    assert keys[0] == keys[1]
    assert not (tmp_path / "cache-a").exists() and not (tmp_path / "cache-b").exists()
    test = first[1][1]
    assert isinstance(test.task, TextProgram) and str(tmp_path) not in keys[0][1]
    # the program's text is what faultgen tasks friction-test writes, named by its digest
    text = friction_test.text(test.model)
    assert test.task.text == text and programs.record(test.task)["text"] == text
    assert programs.identity(test.model, test.task)[1] == programs.identity(test.model, str(_file(tmp_path, text)))[1]
    short = friction_test.text(test.model, [1], 3)
    written = []
    for name, runs in (("a", first), ("b", second)):
        monkeypatch.setenv("FAULTGEN_CACHE", str(tmp_path / f"cache-{name}"))
        config = runs[1][1]
        config = type(config)(**{**{f: getattr(config, f) for f in ("robot", "friction", "wear", "seed",
                                                                    "noise", "conditions", "signals", "fault")},
                                 "task": TextProgram("puma560-short", short), "cycles": 1, "record": (1,),
                                 "nthread": 1, "resolved": config.model})
        path = writer.write_run(tmp_path / f"{name}.h5", sim.simulate(config, progress=False), "unit-friction-test")
        written.append(path.read_bytes())
    assert written[0] == written[1]


def _file(folder, text):
    path = folder / "program.toml"
    path.write_text(text)
    return path


def test_a_text_program_pickles_with_its_text_and_refuses_an_empty_name():
    import pickle

    task = TextProgram("robot", "name = 'x'\n")
    again = pickle.loads(pickle.dumps(task))
    assert type(again) is TextProgram and again == task and again.text == task.text
    assert str(task).startswith("robot-") and str(task).endswith(".toml") and not os.path.exists(str(task))
    with pytest.raises(ValueError, match=r"TextProgram\('', \.\.\.\): expected a non-empty name"):
        TextProgram("", "x")


@pytest.fixture(scope="module")
def v2_small(shared_bench):
    """The prognostics track's latest version (2) at its test size, made by the command once a session
    (conftest.py; tests/test_bench_prognostics.py checks it against its frozen manifest too)."""
    folder = shared_bench("prognostics")
    return folder, json.loads((folder / "manifest.json").read_text())


def _arrays(manifest: dict, split: str) -> dict[str, Counter]:
    """Per array name, the multiset of its digests in ``split`` (unit ids left out: the test units'
    order is drawn per version)."""
    out: dict[str, Counter] = {}
    for key, digest in manifest["arrays"].items():
        if key.startswith(f"{split}.h5:") and "@" not in key:
            out.setdefault(key.rsplit("/", 1)[1], Counter())[digest] += 1
    return out


def test_v2_is_made_again_as_frozen_with_v1s_records_and_each_units_friction_tests_on_their_days(v2_small):
    """Made identical to the frozen manifest; v1's train split and daily records (every digest of
    v1's frozen small manifest, the friction tests drawn from a stream of their own), and the tests'
    readings on days 1 and 15 only, their truth not in the folder."""
    folder, manifest = v2_small
    assert (manifest["track"], manifest["version"], manifest["status"]) == ("prognostics", 2, "checked")
    assert manifest["arrays"] == json.loads(make.manifest_path("prognostics", 2, "small").read_text())["arrays"]
    v1 = json.loads(make.manifest_path("prognostics", 1, "small").read_text())
    assert {k: v for k, v in manifest["arrays"].items() if k.startswith("train.h5:")} == {
        k: v for k, v in v1["arrays"].items() if k.startswith("train.h5:")}
    tested = _arrays(manifest, "test")
    assert {name: tested[name] for name in _arrays(v1, "test")} == _arrays(v1, "test")
    assert set(tested) - set(_arrays(v1, "test")) == set(files.TEST_ARRAYS)
    assert sorted(p.name for p in folder.iterdir() if not p.name.startswith("score-")) == sorted(make.OUTPUTS)
    for unit in files.read(folder / "test.h5"):
        days = np.flatnonzero(unit.arrays["friction_test"]) + 1
        assert days.tolist() == [1, 15] and unit.fault_level is None
        coulomb = unit.arrays["friction_test_coulomb"]
        low, high = unit.arrays["friction_test_coulomb_low"], unit.arrays["friction_test_coulomb_high"]
        assert np.all(coulomb[days - 1] > 0) and not np.any(np.delete(coulomb, days - 1, axis=0))
        assert np.all((low <= coulomb) & (coulomb <= high))
        # the logged temperature of the day's test: warm (the day's log's) or cold (below it)
        assert np.all(unit.arrays["friction_test_temperature"][days - 1] <= unit.arrays["joint_temperature"][days - 1]
                      + 0.01)


class SpyOnTests:
    """A prognoser that reads the friction tests it is shown: the naive lives, and a record of the
    last test day each prediction saw."""

    def fit(self, units, failure_wear):
        self.naive, self.seen = prognosers.MeanLife().fit(units, failure_wear), []
        return self

    def predict(self, unit):
        tests = np.flatnonzero(unit.arrays["friction_test"])
        self.seen.append((len(unit.arrays["cycles"]), int(tests[-1]) + 1 if tests.size else 0))
        return self.naive.predict(unit)


def test_v2_is_scored_with_the_late_share_and_the_phm08_score_and_a_prognoser_sees_no_later_test(v2_small, tmp_path):
    folder, _ = v2_small
    spy = SpyOnTests()
    results = prognostics.score(folder, spy, "spy")
    assert spy.seen and all(last <= shown for shown, last in spy.seen)
    assert {last for _, last in spy.seen} == {1, 15}  # the day-15 test seen from day 15 on
    json_path, md_path = prognostics.write(results, tmp_path / "spy", "cmd")
    header, rule, row = md_path.read_text().splitlines()
    assert header == prognostics.HEADER_V2 and rule.count("|") == header.count("|") == row.count("|")
    cells = [c.strip() for c in row.strip("|").split("|")]
    r = results["results"]
    late = f"{100 * r['late_share']['value']:.0f}"
    assert cells[:2] == ["prognostics v2 (small)", "spy"] and cells[5].startswith(late + " [")
    assert cells[6].startswith(f"{r['phm08_lambda']['value']:.3g} [")
    # the naive prognoser scored against itself: the same late share and score
    assert results["naive"]["late_share"] == r["late_share"] and results["naive"]["phm08_lambda"] == r["phm08_lambda"]
    # v1's rows keep their eight columns
    assert prognostics.header(1) == prognostics.HEADER and prognostics.HEADER.count("|") == 9


def test_on_tests_scale_puts_every_log_of_a_prefix_on_its_last_factor_as_rul_csv_that_day():
    """The twin-with-tests replay (benchmarks/prognostics_twin.py) fits the rows up to a day as the
    monitor's rul.csv would have that day: every log's twin-scale estimate times the last row's
    factor (not each log's own, scores.csv's), the factor's relative error as the scale's
    uncertainty; an axis in the twin's scale keeps the monitor's default; no test: unchanged."""
    from faultgen.monitor import friction_tests, scoring, tables

    def row(day, twin, factor, error, scale):
        return {"stamp": f"2026-01-{day:02d}", "phase": "monitoring", "wear1_twin_log": twin, "wear1_twin_log_lower": twin - 2.0,
                "wear1_factor": factor, "wear1_factor_error": error, "wear1_scale": scale,
                "wear1_log": factor * twin, "wear1_log_lower": factor * (twin - 2.0),
                "wear2_twin_log": 1.0, "wear2_twin_log_lower": 0.0, "wear2_factor": 1.0, "wear2_factor_error": 0.0,
                "wear2_scale": friction_tests.TWIN_SCALE, "wear2_log": 1.0, "wear2_log_lower": 0.0}

    rows = tables.log_rows([row(1, 10.0, 0.5, 0.1, friction_tests.TESTS_SCALE),
                            row(2, 20.0, 0.8, 0.2, friction_tests.TESTS_SCALE),
                            row(3, 30.0, 1.25, 0.25, friction_tests.TESTS_SCALE)])
    seen, uncertainty = friction_tests.on_tests_scale(rows[:2], 2)
    assert [r.wear.log[0] for r in seen] == pytest.approx([8.0, 16.0])  # 0.8 x (10, 20), not (5, 16)
    assert [r.wear.log_lower[0] for r in seen] == pytest.approx([6.4, 14.4])
    assert uncertainty == pytest.approx({1: 0.25, 2: scoring.SCALE_UNCERTAINTY})
    seen, uncertainty = friction_tests.on_tests_scale(rows, 2)
    assert [r.wear.log[0] for r in seen] == pytest.approx([12.5, 25.0, 37.5]) and uncertainty[1] == pytest.approx(0.2)
    assert rows[0].wear.log[0] == pytest.approx(5.0)  # the monitor's rows untouched
    plain = [dataclasses.replace(r, wear=dataclasses.replace(r.wear, tests=None)) for r in rows]
    assert friction_tests.on_tests_scale(plain, 2) == (plain, None)
