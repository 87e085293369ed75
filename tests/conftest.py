"""Test-session set-up.

Each pytest-xdist worker (``-n auto`` in pyproject.toml) keeps numpy's BLAS to one thread: two
workers on two cores, each with a BLAS pool as wide as the machine, contend for the cores
(2026-11-22, three calibration test files on two workers: 118 s with two BLAS threads each,
101 s with one; 161 s in one process).
"""

import compileall
import os
import sys
from pathlib import Path

import numpy  # noqa: F401  (load the BLAS library before limiting it)
import pytest
import typer.testing
from filelock import FileLock
from threadpoolctl import threadpool_limits

# Compiled code is kept (``__pycache__``, ignored by git) even where the environment says not to
# (``PYTHONDONTWRITEBYTECODE=1`` on the machine that runs CI): the packages' modules are compiled here
# once, and the test files' rewritten asserts kept while the tests are collected, so the other
# pytest-xdist worker and every child Python the tests start (the command line, loky's and Dask's
# workers), which read what is there, do not compile them again (2026-11-27: collecting the tests
# 20 s -> 10 s of CPU once cached). The environment's choice holds again once the tests are
# collected: a plug-in a test writes into its temporary folder and imports leaves no ``__pycache__``
# there; the children keep the environment: they read, they do not write.
_DONT_WRITE_BYTECODE = sys.dont_write_bytecode
sys.dont_write_bytecode = False
for _package in ("faultgen", "analysis"):  # quiet=2: a read-only checkout says nothing (its children compile)
    compileall.compile_dir(Path(__file__).resolve().parents[1] / _package, quiet=2)


def pytest_collection_finish(session):
    sys.dont_write_bytecode = _DONT_WRITE_BYTECODE


if os.environ.get("PYTEST_XDIST_WORKER"):
    threadpool_limits(1)


def _registered(app) -> list:
    """What a typer app's click command is built from: the app, its callback, commands and groups
    (and theirs), the objects themselves (a command a test registers, or a list it swaps in, is
    another build)."""
    parts = [app, app.registered_callback, *app.registered_commands]
    for group in app.registered_groups:
        parts += [group, *(_registered(group.typer_instance) if group.typer_instance else [])]
    return parts


def _built_once(build):
    """typer's ``CliRunner.invoke`` builds the click command from the typer app at every call
    (``typer.testing._get_command``: 0.09 s of CPU for faultgen's app, 2026-11-27, load 10; the suite
    invokes it several hundred times). The same app with the same registrations gives the same
    command, and a click command keeps no state between its runs (each run has its own
    ``click.Context``): built once, here, as tests/test_help_examples.py and tests/test_cli_fuzz.py
    did for their own loops. ``typer.main.get_command`` itself still builds afresh."""
    built = {}

    def get(app):
        parts = _registered(app)
        key = tuple(map(id, parts))
        if key not in built:
            built[key] = (parts, build(app))  # the objects kept alive: no other takes their ids
        return built[key][1]

    return get


typer.testing._get_command = _built_once(typer.testing._get_command)


def shared_folder(tmp_path_factory, worker_id: str, name: str) -> Path:
    """The folder ``name`` that every pytest-xdist worker of this session sees (the xdist recipe: the
    parent of the workers' temporary folders), created if needed; what is built in it is built once,
    under a file lock in it."""
    root = tmp_path_factory.getbasetemp()
    if worker_id != "master":
        root = root.parent
    folder = root / name
    folder.mkdir(exist_ok=True)
    return folder


@pytest.fixture(scope="session")
def shared_sweep(tmp_path_factory, worker_id):
    """``shared_sweep(name, **grid)``: the path of a sweep dataset built once per test session and
    read by every pytest-xdist worker (module fixtures would be built once per worker: the 40-cycle
    analysis dataset took 20 s on each). The xdist recipe: a file lock in the folder the workers'
    temporary folders share. Tests only read these files; one that edits a dataset copies it."""
    from faultgen.runs import sweep

    folder = shared_folder(tmp_path_factory, worker_id, "shared-sweeps")

    def build(name: str, **grid) -> Path:
        out = folder / f"{name}.h5"
        with FileLock(folder / f"{name}.build-lock"):
            if not out.exists():
                sweep.run(sweep.Grid(**grid), out, progress=False)
        return out

    return build


@pytest.fixture(scope="session")
def shared_fleet(tmp_path_factory, worker_id):
    """``shared_fleet(name, **settings)``: the path of a fleet (``faultgen.runs.fleet.Fleet``)
    built once per test session, as :func:`shared_sweep` builds sweeps."""
    from faultgen.runs import sweep
    from faultgen.runs.fleet import Fleet

    folder = shared_folder(tmp_path_factory, worker_id, "shared-sweeps")

    def build(name: str, **settings) -> Path:
        out = folder / f"{name}.h5"
        with FileLock(folder / f"{name}.build-lock"):
            if not out.exists():
                sweep.run(Fleet(**settings), out, progress=False)
        return out

    return build


@pytest.fixture(scope="session")
def shared_bench(tmp_path_factory, worker_id):
    """``shared_bench(track)``: the folder of a bench track's latest version at its test size, made by
    the command (tests/bench_plugins.py's ``make_small``) once per test session, as
    :func:`shared_sweep` builds sweeps (the thesis track's was made by three test files, each on
    every worker that ran one of its tests). Tests read its files; `bench score` without ``-o``
    adds its ``score-NAME`` outputs beside them, which no test reads from another."""
    import bench_plugins

    folder = shared_folder(tmp_path_factory, worker_id, "shared-bench")

    def build(track: str) -> Path:
        out = folder / track
        with FileLock(folder / f"{track}.build-lock"):
            if not (out / "manifest.json").exists():
                bench_plugins.make_small(track, out)
        return out

    return build


@pytest.fixture
def loads(monkeypatch):
    """The names ``faultgen.model.robots.load`` is called with while the test runs (a counting
    wrapper on the module attribute, which every caller resolves through: tests/test_resolve_once.py)."""
    from faultgen.model import robots

    calls = []
    load = robots.load

    def counting(name):
        calls.append(str(name))
        return load(name)

    monkeypatch.setattr(robots, "load", counting)
    return calls


@pytest.fixture
def figures(monkeypatch):
    """The figures plot() draws, kept for inspection when it saves them."""
    from matplotlib.figure import Figure

    drawn, save = [], Figure.savefig

    def spy(self, *args, **kwargs):
        drawn.append(self)
        return save(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", spy)
    return drawn


@pytest.fixture(scope="session")
def coulomb_log():
    """One pick-and-place cycle of the PUMA 560 by its inverse dynamics, a Coulomb level raised
    on axis 3 and 1 % torque noise: the calibration adds one effect (read only). Three cycles until
    2026-11-27 (r10, scal): one gives the same step, the level 0.07001 N m higher (three: 0.06997)."""
    from faultgen import effects
    from faultgen.calibrate import synth
    from faultgen.logs import measured
    from faultgen.model import robots

    robot = robots.load("puma560")
    motion, tau = synth.nominal_motion(robot, "pick_place", 1)
    phi, _ = effects.get("coulomb").columns(motion, 2, None)
    rng = numpy.random.default_rng(3)
    tau = tau + rng.normal(size=tau.shape) * 0.01 * numpy.sqrt(numpy.mean(tau**2, axis=0))
    tau[:, 2] += phi[:, 0] * 0.07
    return measured.from_arrays(motion.t, motion.q, tau, robot=robot, qd=motion.qd)


# -- scal (r9): the Coulomb log's calibration, run once per worker ------------------------------
@pytest.fixture(scope="session")
def coulomb_calibration(coulomb_log, tmp_path_factory):
    """``calibrate("puma560", coulomb_log, OUT, use_sysid=False)`` run once per worker for the tests
    that only read its result and OUT (tests/test_resolve_once.py, tests/test_calibrate_in_memory.py;
    before, each file ran it): (the result, OUT, the names ``robots.load`` was called with during
    it, the MJCF files written during it, whatever their name: atomic writes go to a .part file)."""
    import pathlib

    from faultgen.calibrate import calibrate
    from faultgen.model import robots

    out = tmp_path_factory.mktemp("coulomb") / "out"
    calls, writes = [], []
    load, write_text = robots.load, pathlib.Path.write_text

    def counted(self, data, *args, **kwargs):
        if "<mujoco" in data:
            writes.append(self)
        return write_text(self, data, *args, **kwargs)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(robots, "load", lambda name: calls.append(str(name)) or load(name))
        patch.setattr(pathlib.Path, "write_text", counted)
        result = calibrate("puma560", coulomb_log, out, use_sysid=False)
    return result, out, calls, writes


# -- shelp (r9): a fleet made by the `faultgen fleet` command, once per session ------------------------

@pytest.fixture(scope="session")
def shared_fleet_command(tmp_path_factory, worker_id):
    """``shared_fleet_command(*options)``: ``(path, output)``: the fleet ``faultgen fleet OPTIONS
    --jobs 1 --no-progress -o PATH`` writes, and what the command printed, run in the test process
    once per test session, as :func:`shared_sweep` builds sweeps. ``options``: pairs of an option
    and its value, each option once; their order does not matter (the same fleet). The fleets that
    two test files made with the same command (test_new_user.py and test_reader.py; test_fleet.py
    and the fleet page of test_help_examples.py) are made once. Tests only read the file; one that
    writes beside it copies it."""
    import hashlib
    import re

    from typer.testing import CliRunner

    from faultgen.cli import app

    folder = shared_folder(tmp_path_factory, worker_id, "shared-fleet-commands")

    def build(*options: str) -> tuple[Path, str]:
        pairs = dict(zip(options[::2], options[1::2], strict=True))
        assert len(pairs) * 2 == len(options) and all(name.startswith("--") for name in pairs), options
        argv = [word for name in sorted(pairs) for word in (name, pairs[name])]
        digest = hashlib.sha256("\0".join(argv).encode()).hexdigest()[:12]  # names that fold alike stay apart
        name = "fleet" + re.sub(r"[^A-Za-z0-9.]+", "-", " ".join(argv))[:80] + "-" + digest
        out, printed = folder / f"{name}.h5", folder / f"{name}.out"
        with FileLock(folder / f"{name}.build-lock"):
            if not printed.exists():
                result = CliRunner().invoke(app, ["fleet", *argv, "--jobs", "1", "--no-progress", "-o", str(out)])
                assert result.exit_code == 0, result.output
                printed.write_text(result.output)
        return out, printed.read_text()

    return build


@pytest.fixture(scope="module")
def puma():
    """The shipped PUMA 560, loaded once per test file (a file may define its own ``puma``)."""
    from faultgen.model import robots

    return robots.load("puma560")
