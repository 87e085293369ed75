"""A stepping backend reaches sweeps, fleets and the monitor's twin through their execution context
(issue 57, item 4): the test-only backend of tests/backend_example.py, registered in that file
alone, is handed as an object to :func:`faultgen.runs.sweep.run` (a sweep's grid and a fleet), and to the monitor
(:func:`faultgen.monitor.loop.monitor`, whose context hands it to each twin); it is the one that
steps, and the outputs are the default backend's to the tolerance of tests/test_backends.py."""

import h5py
import numpy as np
import pytest

import backend_example
import independent_fleet
from faultgen.model import robots
from faultgen.monitor import loop
from faultgen.monitor.run import resolve_run
from faultgen.monitor.scoring import Settings
from faultgen.monitor.twin import Twin, base_cycles
from faultgen.runs import sweep
from faultgen.runs.context import ExecutionContext
from faultgen.runs.fleet import Fleet
from faultgen.simulation import backends

COUNTING = backend_example.COUNTING
#: The smallest fleet the monitor learns on (tests/test_monitor.py's settings): two units, 16 days.
FLEET = independent_fleet.FleetSpec(units=2, worn=1, days=16, seed=5, onset=(10, 11))
SETTINGS = Settings(train=14, persistence=3)
#: Attributes that say when and how long, not what (they differ between any two runs).
TIMING = ("command", "created", "stepping_time", "wall_time")


def counted(call):
    """(what ``call()`` returns, runs the counting backend made during it)."""
    before = COUNTING.runs
    value = call()
    return value, COUNTING.runs - before


def assert_same_datasets(a, b):
    """Every dataset and attribute of the HDF5 files ``a`` and ``b`` equal: floats to the tolerance of
    tests/test_backends.py, everything else exactly; timing attributes aside."""
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        names_a, names_b = [], []
        fa.visit(names_a.append)
        fb.visit(names_b.append)
        assert names_a == names_b
        for name in ["/", *names_a]:
            x, y = fa[name], fb[name]
            assert sorted(x.attrs) == sorted(y.attrs), name
            for key in x.attrs:
                if key not in TIMING:
                    assert np.array_equal(np.asarray(x.attrs[key]), np.asarray(y.attrs[key])), (name, key)
            if isinstance(x, h5py.Dataset):
                u, v = x[()], y[()]
                assert u.dtype == v.dtype and np.shape(u) == np.shape(v), name
                if u.dtype.kind == "f":
                    np.testing.assert_allclose(u, v, rtol=1e-9, atol=1e-9 * np.max(np.abs(v), initial=0.0),
                                               err_msg=name)
                else:
                    assert np.array_equal(u, v), name


def test_the_example_is_registered_by_its_own_file_and_refused_twice_under_its_name():
    assert type(backends.get("counting")) is backend_example.CountingBackend
    assert backends.register(backend_example.CountingBackend) is backend_example.CountingBackend  # again: no change
    with pytest.raises(ValueError, match="'counting' is already registered"):
        backends.register(type("Other", (backend_example.CountingBackend,), {}))
    with pytest.raises(ValueError, match="not a stepping backend"):
        backends.register("counting")


def test_a_sweep_steps_on_the_backend_it_is_given_with_the_default_backends_dataset(tmp_path):
    grid = sweep.Grid(robots=["puma560"], tasks=["pick_place"], axes=[0, 2], cycles=3, record=[1, 3])
    default = sweep.run(grid, tmp_path / "default.h5", progress=False)
    ours, runs = counted(lambda: sweep.run(grid, tmp_path / "counting.h5", progress=False,
                                              context=ExecutionContext(stepper=COUNTING)))
    assert runs == 2 * 2  # two runs of two recorded cycles each
    assert_same_datasets(ours, default)


def test_a_fleet_steps_on_the_backend_it_is_given_with_the_default_backends_dataset(tmp_path):
    fleet = Fleet(size=2, failing=1, days=6, cycles_per_day=1, models=("puma560",))
    default = sweep.run(fleet, tmp_path / "default.h5", progress=False)
    ours, runs = counted(lambda: sweep.run(fleet, tmp_path / "counting.h5", progress=False,
                                              context=ExecutionContext(stepper=COUNTING)))
    assert runs == 2 * 6  # two robots, one cycle a day for six days
    assert_same_datasets(ours, default)


def test_an_unknown_backend_is_refused_before_a_sweep_runs(tmp_path):
    grid = sweep.Grid(robots=["puma560"], tasks=["pick_place"], axes=[0], cycles=1)
    with pytest.raises(ValueError, match="'gpu' is not a stepper"):
        ExecutionContext(stepper="gpu")
    with pytest.raises(sweep.SweepRefused, match="context 'gpu': expected an ExecutionContext"):
        sweep.run(grid, tmp_path / "x.h5", "gpu", progress=False)
    assert list(tmp_path.iterdir()) == []


def test_the_monitors_twins_step_on_the_backend_it_is_given_with_the_default_backends_cycles(tmp_path):
    robot, logs, _ = independent_fleet.write_fleet(tmp_path / "fleet", FLEET)
    out = tmp_path / "out"
    _, runs = counted(lambda: loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS,
                                                       progress=False, context=ExecutionContext(stepper=COUNTING))))
    cycles = out / ".cache" / "cycles"
    assert runs == len(list(cycles.glob("*.json"))) > len(base_cycles(6))  # every twin cycle, payloads' too
    # the cycles the monitor keeps (the first unit's twin replays its first log) against the default backend's
    program = sorted((logs / "unit01").iterdir())[0]
    model = robots.load(robot)  # a Twin takes the robot, resolved once
    kept = Twin(model, program, cycles, root=out, cycles=False)
    assert all(kept.cached(*c) for c in base_cycles(6))
    default = Twin(model, program, tmp_path / "default" / "cycles", cycles=False)
    for c in base_cycles(6)[:3]:  # the healthy expectation, the healthy cycle at the model's friction, axis 1 worn
        np.testing.assert_allclose(kept.cycle(*c), default.cycle(*c), rtol=1e-9, atol=1e-9, err_msg=str(c))


def test_an_unknown_backend_is_refused_before_the_monitor_or_a_twin_starts(tmp_path):
    with pytest.raises(ValueError, match="'gpu' is not a stepper"):
        loop.monitor(resolve_run("puma560", tmp_path / "logs", tmp_path / "out", progress=False,
                                 context=ExecutionContext(stepper="gpu")))
    with pytest.raises(ValueError, match="'gpu' is not a stepper"):
        Twin("puma560", tmp_path / "program.csv", tmp_path / "cycles", stepper="gpu")
    assert list(tmp_path.iterdir()) == []
