"""A run built from objects once: the monitor's twin replays its smoothed program
in memory (a ``Motion``, no CSV written and read back), the hidden-effect log simulates the hidden
model compiled in memory, a task's kind is decided by ``programs.kind`` alone, the planned tasks are
cached by content digests, and a run's text (``RunSpec``) resolves into objects (``resolve``).

References: the written-then-read forms these replace (the CSV at 17 significant digits read by the
replay reader; the model file loaded by ``robots.load``), each compared bit for bit."""

from __future__ import annotations

import os
import pickle

import numpy as np
import pytest

from faultgen.calibrate import synth
from faultgen.data import cells, dataset, logfiles
from faultgen.logs import jointlog, measured
from faultgen.model import robots
from faultgen.monitor.twin import REFERENCE_WINDOW, Twin
from faultgen.operation import programs, tasks, wear
from faultgen.simulation import backends, prepare, resolve, spec
from faultgen.simulation import stepping as sim


@pytest.fixture(scope="module")
def puma():
    return robots.load("puma560")


@pytest.fixture(scope="module")
def cycle(puma):
    """One spot-weld cycle at the log rate: ``(t, q, tau)``, the arm-side torque by inverse dynamics."""
    path = programs.load(puma, "spot_weld").trajectory(0.004)
    return path.t, path.q, puma.inverse_dynamics(path.q, path.qd, path.qdd, t=path.t)


def _written_and_read(tmp_path, robot, t, q):
    """The replay of ``t, q`` as the twin made it before: a CSV at 17 significant digits, read back."""
    path = tmp_path / "motion.csv"
    np.savetxt(path, np.column_stack([t, q]), delimiter=",", comments="", fmt="%.17g",
               header=cells.line(["t", *(f"q{i}" for i in range(1, robot.n_axes + 1))]))
    return programs.load(robot, str(path))


def test_a_motion_in_memory_replays_as_its_log_written_and_read(tmp_path, puma, cycle):
    t, q, _ = cycle
    smoothed = np.asarray(q) + 1e-4 * np.sin(np.arange(len(t)))[:, None]  # not on a grid of round numbers
    old = _written_and_read(tmp_path, puma, t, smoothed)
    new = programs.load(puma, tasks.Motion("motion", t, smoothed))
    for name in ("t", "q", "qd", "qdd", "start"):
        assert np.array_equal(getattr(old, name), getattr(new, name)), name
    dt = puma.model.opt.timestep
    a, b = old.trajectory(dt), new.trajectory(dt)
    assert all(np.array_equal(getattr(a, k), getattr(b, k)) for k in ("t", "q", "qd", "qdd")) and a.segments == b.segments
    assert new.name == old.name == "motion"


def test_a_motion_is_a_value_keyed_by_its_samples(cycle):
    t, q, _ = cycle
    one, two = tasks.Motion("m", t, q), tasks.Motion("m", np.array(t), np.array(q))
    assert one == two and hash(one) == hash(two) and one != tasks.Motion("m", t, q + 1e-12)
    assert pickle.loads(pickle.dumps(one)) == one and str(one) == "m" and programs.label(one) == "m"
    assert programs.kind(one) == programs.MOTION and programs.record(one)["sha256"] == one.sha256
    with pytest.raises(ValueError, match=r"expected t of shape \(n,\) and q of shape \(n, N\), got \(3,\) and \(2, 6\)"):
        tasks.Motion("m", [0, 1, 2], np.zeros((2, 6)))
    with pytest.raises(AttributeError):
        one.name = "x"


def test_a_motion_is_checked_as_a_log_is(puma, cycle):
    t, q, _ = cycle
    with pytest.raises(jointlog.LogError, match="3 angle columns; puma560 has 6 axes"):
        programs.load(puma, tasks.Motion("m", t, q[:, :3]))
    bad = np.array(q)
    bad[5, 1] = np.nan
    with pytest.raises(jointlog.LogError, match="sample 5"):
        programs.load(puma, tasks.Motion("m", t, bad))


def test_the_twin_writes_no_program_and_replays_the_smoothed_log(tmp_path, puma, cycle):
    t, q, tau = cycle
    (tmp_path / "logs").mkdir()
    log = logfiles.write_csv(tmp_path / "logs" / "first.csv", t, q, tau)
    twin = Twin(puma, log, tmp_path / "out" / ".cache" / "cycles", cycles=False)
    motion = twin._reference
    assert isinstance(motion, tasks.Motion) and not (tmp_path / "out" / ".cache" / "programs").exists()
    data = measured.read(log, puma, accelerations=False)
    from faultgen import derivatives

    assert np.array_equal(motion.q, derivatives.smoothed(data.t, data.q, REFERENCE_WINDOW))
    # the twin cache is shared by the units of a program: its motion names no unit's log (issue 88 item 6)
    assert "smoothed" in motion.source and str(log) not in motion.source


def test_the_hidden_model_in_memory_is_the_file_written_beside_the_log(tmp_path, puma):
    hidden = synth.draw(puma, "coulomb", np.random.default_rng(1))
    text, model = synth.hidden_model(puma, hidden)
    reread = robots.load(synth.write_model(puma, hidden, tmp_path / "model"))
    assert (tmp_path / "model" / "puma560_hidden.xml").read_text() == text
    names = [k for k in dir(model.model) if not k.startswith("_") and isinstance(getattr(model.model, k), np.ndarray)]
    assert [k for k in names if not np.array_equal(getattr(model.model, k), getattr(reread.model, k))] == []
    assert np.array_equal(model.gear_ratio, reread.gear_ratio) and model.model.opt.timestep == synth.TIMESTEP


def test_the_hidden_log_does_not_read_its_model_back(tmp_path, puma, monkeypatch):
    loaded = []
    load = robots.load
    monkeypatch.setattr(robots, "load", lambda name: loaded.append(str(name)) or load(name))
    synth.record(puma, synth.Hidden(None), tmp_path / "m.csv", cycles=1, seed=1)
    assert loaded == [] and (tmp_path / "m_model" / "puma560_hidden.xml").is_file()


@pytest.mark.parametrize("task, kind", [
    ("pick_place", programs.THESIS), ("a/b.toml", programs.PROGRAM), ("B.TOML", programs.PROGRAM),
    ("log.csv", programs.LOG), ("log.csv.gz", programs.LOG), ("log.H5", programs.LOG), ("log.hdf5", programs.LOG),
    (programs.TextProgram("p", 'name = "p"\n'), programs.TEXT), ("weld", None), ("", None), (3, None),
])
def test_a_task_kind_is_decided_in_one_place(task, kind):
    assert programs.kind(task) == kind
    assert programs.is_file_task(task) == (kind in (programs.PROGRAM, programs.TEXT, programs.LOG))


def test_a_planned_task_is_cached_by_content_not_by_file_time(tmp_path, puma):
    path = tmp_path / "weld.toml"
    text = programs.export(puma, "spot_weld").replace('name = "spot_weld"', 'name = "cached_by_content"')
    path.write_text(text)
    first = resolve.task(puma, str(path))
    os.utime(path, ns=(1, 1))  # touched: the same content, planned once
    assert resolve.task(puma, str(path)) is first
    stamp = path.stat().st_mtime_ns
    path.write_text(text.replace("dwell = 0.2", "dwell = 0.3", 1) if "dwell = 0.2" in text else text + "\n# edited\n")
    os.utime(path, ns=(stamp, stamp))  # edited, its time put back: planned again
    assert resolve.task(puma, str(path)) is not first
    assert prepare.digests(puma, str(path))[1] != prepare.digests(puma, "pick_place")[0]


def test_a_spec_is_text_that_resolves_into_the_run_of_objects(tmp_path, puma):
    plan = wear.WearPlan.from_specs(["2:exp4:30"], 3)
    text = spec.RunSpec("puma560", "pick_place", friction="stribeck", wear=plan, cycles=3, record=(1, 3), seed=4,
                        stepper="loop")
    assert pickle.loads(pickle.dumps(text)) == text
    run = resolve.resolve(text)
    direct = sim.RunConfig(robot="puma560", task="pick_place", friction="stribeck", wear=plan, cycles=3,
                           record=(1, 3), seed=4)
    assert run.config == direct and run.config.model is puma and isinstance(run.stepper, backends.LoopStepper)
    assert dataset.config_key(run.config) == dataset.config_key(direct)
    with pytest.raises(TypeError, match="RunSpec robot = a Robot: expected a non-empty string"):
        spec.RunSpec(puma, "pick_place")
    with pytest.raises(ValueError, match="unknown stepping backend 'warp'"):
        resolve.resolve(spec.RunSpec("puma560", "pick_place", stepper="warp"))
    with pytest.raises(ValueError, match="unknown task 'weld'"):
        resolve.resolve(spec.RunSpec("puma560", "weld"))


def test_a_spec_for_workers_names_its_files_absolutely(tmp_path, monkeypatch, puma):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "p.toml").write_text(programs.export(puma, "pick_place"))
    moved = spec.RunSpec("puma560", "p.toml").for_workers()
    assert moved.robot == "puma560" and moved.task == str(tmp_path / "p.toml")
    assert spec.RunSpec("puma560", "pick_place").for_workers() == spec.RunSpec("puma560", "pick_place")
