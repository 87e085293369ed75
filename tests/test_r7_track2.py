"""Issue 75, item 7 (track2): the prognostics track's version 2 (friction tests in the test split)
and the fleet's friction-test program carried as text (no cache path in a run's configuration)."""

import os

import pytest

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
    either cache, and one test run (cut to axis 1, 3 speeds, for time) written to identical HDF5 bytes."""
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
    for name in ("a", "b"):
        monkeypatch.setenv("FAULTGEN_CACHE", str(tmp_path / f"cache-{name}"))
        config = fleet.Fleet(**TINY).runs()[1][1]
        config = type(config)(**{**{f: getattr(config, f) for f in ("robot", "friction", "wear", "cycles", "seed",
                                                                    "noise", "conditions", "signals", "fault")},
                                 "task": TextProgram("puma560-short", short), "record": (6,), "nthread": 1,
                                 "resolved": config.model})
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
