"""A robot is resolved once per command, at the boundary (issue 57, item 1; docs/architecture.md,
"One robot model, resolved once"): below it functions take the :class:`Robot`, never its name.

Counted by a wrapper put on the module attribute ``faultgen.model.robots.load``, which every caller
uses (checked here: no module holds a copy of the function). Before this change
``faultgen tasks show puma560 pick_place --check`` resolved the robot twice (``programs.builtin``
and the command) and ``faultgen simulate --robot puma560 --task pick_place --cycles 1`` once
(``RunConfig``, issue 47); ``tasks list`` and ``tasks export`` once, inside ``programs``.
"""

import ast
from pathlib import Path

import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.model import robots
from faultgen.operation import programs
from faultgen.simulation import prepare

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()


def _copies_of_load(path: Path) -> list[str]:
    """Where ``path`` binds the resolver to a name of its own (``from ... import load``, ``f = robots.load``,
    ``from faultgen import load_robot``): a copy a wrapper on the module attribute would not see."""
    tree = ast.parse(path.read_text(), str(path))
    called = {id(node.func) for node in ast.walk(tree) if isinstance(node, ast.Call)}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (
                (node.module == "faultgen.model.robots" and any(a.name == "load" for a in node.names))
                or (node.module == "faultgen" and any(a.name == "load_robot" for a in node.names))):
            found.append(f"{path.relative_to(ROOT)}:{node.lineno}")
        elif (isinstance(node, ast.Attribute) and node.attr == "load" and isinstance(node.value, ast.Name)
              and "robot" in node.value.id and id(node) not in called):
            found.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    return found


def test_every_caller_resolves_through_the_module_attribute():
    files = sorted((ROOT / "faultgen").rglob("*.py")) + sorted((ROOT / "analysis").rglob("*.py"))
    assert [where for path in files for where in _copies_of_load(path)] == []


def test_simulate_resolves_its_robot_once(loads, tmp_path):
    out = tmp_path / "one.h5"
    result = runner.invoke(app, ["simulate", "--robot", "puma560", "--task", "pick_place", "--cycles", "1",
                                 "--seed", "0", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert out.is_file()
    assert loads == ["puma560"]


@pytest.mark.parametrize("args", [["tasks", "show", "puma560", "pick_place", "--check"],  # was 2
                                  ["tasks", "list", "puma560"], ["tasks", "export", "puma560", "spot_weld"]])
def test_a_tasks_command_resolves_its_robot_once(loads, args):
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert loads == ["puma560"]


@pytest.mark.parametrize("call", [
    lambda: programs.load("puma560", "pick_place"),
    lambda: programs.builtin("puma560", "pick_place"),
    lambda: programs.export("puma560", "pick_place"),
    lambda: programs.identity("puma560", "pick_place"),
    lambda: programs.parse('name = "x"\n', "puma560"),
    lambda: programs.robot_limits("puma560"),
    lambda: programs.available("puma560"),
    lambda: prepare.prepared_for("puma560", "pick_place", "lugre"),
    lambda: prepare.cycle_duration("puma560", "pick_place"),
])
def test_below_the_boundary_a_name_is_a_type_error(loads, call):
    with pytest.raises(TypeError, match="expected a Robot, got str 'puma560'; resolve .* once"):
        call()
    assert loads == []  # refused, not resolved


@pytest.fixture(scope="module")
def kr210_fleet(tmp_path_factory):
    """``(spec, robot folder, logs)``: the independent KR 210 fleet both monitor tests below run on
    (two units: a second unit's twin and its cycles would each have resolved the robot again),
    written once for the module (each test wrote the same one before; the monitor reads the robot
    folder and the logs and writes only into its OUT)."""
    import independent_fleet

    spec = independent_fleet.FleetSpec(units=2, worn=1, days=14, seed=5, onset=(12, 13))
    robot, logs, _ = independent_fleet.write_fleet(tmp_path_factory.mktemp("kr210") / "fleet", spec)
    return spec, robot, logs


def test_the_monitor_resolves_its_robot_once(tmp_path, loads, kr210_fleet):
    """``faultgen monitor`` on the nominal model: the robot folder is resolved once, by the command
    (`monitor.run.resolve_run`), and the twins and their cycles take that Robot. Before: once by the command,
    once per unit's twin and once per simulated cycle's ``RunConfig`` (24 in all on the IRB 6700
    fleet of tests/test_monitor_shipped.py, 3 units, --no-calibrate; measured 2026-11-25)."""
    _, robot, logs = kr210_fleet
    loads.clear()  # nothing is loaded before the command (the fleet was built outside ``loads``)
    result = runner.invoke(app, ["monitor", str(logs), "--robot", str(robot), "-o", str(tmp_path / "out"),
                                 "--no-calibrate", "--train", "10", "--persistence", "3", "--no-progress"])
    assert result.exit_code == 0, result.output
    assert loads == [str(robot)]


#: The boundaries a robot may be resolved at below the command line: the public API (a library
#: entry documented to take a robot's name, folder or file), a worker (a process sent the robot as
#: a name: a RunConfig unpickled, loky, Dask), or an earlier run's state (a dataset or a cache file
#: it wrote, naming a robot).
BOUNDARIES = ("public API", "worker", "an earlier run's state")

#: The modules that call ``robots.load`` (besides the command line, ``faultgen/cli/``), how many
#: times, the boundary each is (:data:`BOUNDARIES`) and why. A model file faultgen writes is not
#: loaded again by its path: its writer returns the Robot (``robots.write``; a folder staged and
#: renamed into place: ``robots.moved``). A new caller fails this test: resolve at the boundary and
#: pass the Robot instead, or add it here with its boundary and why. Before issue 57's last part
#: (2026-11-26) the list also held calibrate/loop.py (1, the calibrated model just written),
#: calibrate/refit.py (2, the calibrated model written; the nominal by the name its result stores),
#: monitor/twin.py (1, a twin of a model file), model/folder.py (2, robots add loading the folder it
#: wrote), and one more call each in monitor/unit.py and bench/independent.py.
ALLOWED = {
    "faultgen/calibrate/__init__.py": (1, "public API", "calibrate() takes a name or a Robot, resolved once"),
    "faultgen/data/fleetlogs.py": (1, "public API", "import_logs() takes a name or a Robot, resolved once"),
    "faultgen/runs/grid.py": (1, "public API", "a Grid (sweep) names its robots; each resolved once for every run"),
    "faultgen/simulation/config.py": (1, "worker", ("RunConfig.model, once: a RunConfig unpickled (its robot sent "
                                                    "as the name) or built from a name; construction loads "
                                                    "nothing")),
    "faultgen/monitor/run.py": (2, "public API", ("resolve_run(), the monitor's entry (the command's and a library "
                                                 "caller's): the robot and the --calibrated model, once per run")),
    "faultgen/monitor/feed.py": (2, "worker", ("Context.new_source, where a worker (loky, Dask) sent the run as "
                                               "paths resolves the robot and the --calibrated model, once each")),
    "faultgen/monitor/remote.py": (1, "worker", "a Dask worker: the robot sent as a name, once (saying what to install)"),
    "faultgen/monitor/unit.py": (1, "an earlier run's state", ("a calibrated or twin model the monitor cached in "
                                                               "OUT/.cache (checked against its record), read once "
                                                               "(cached_model)")),
    "faultgen/data/robot_record.py": (1, "an earlier run's state", ("a dataset written before drivetrains were "
                                                                    "stored names its robot by its label only")),
    "faultgen/bench/make.py": (1, "an earlier run's state", ("bench make: the track's robot folder in its sweeps "
                                                            "folder (added by this make or kept from an earlier "
                                                            "one), read once per fleet with friction tests")),
    "faultgen/bench/independent.py": (1, "public API", ("write_fleet(), the bench's independent simulator's entry, "
                                                        "takes a robot folder; once per fleet")),
    "faultgen/simulation/resolve.py": (1, "public API", "resolve(spec): a run from its text, the robot once"),
    "faultgen/calibrate/synth.py": (1, "an earlier run's state", ("calibrate: the model hidden-log wrote beside its "
                                                                 "log, read once to see that nothing is hidden in it "
                                                                 "(simulator_remainder)")),
}


def test_robots_load_is_called_only_where_it_may_be():
    counts = {}
    for path in sorted((ROOT / "faultgen").rglob("*.py")) + sorted((ROOT / "analysis").rglob("*.py")):
        where = path.relative_to(ROOT).as_posix()
        if where.startswith("faultgen/cli/") or where == "faultgen/model/robots.py":
            continue
        calls = [node for node in ast.walk(ast.parse(path.read_text(), where)) if isinstance(node, ast.Call)
                 and isinstance(node.func, ast.Attribute) and node.func.attr == "load"
                 and isinstance(node.func.value, ast.Name) and node.func.value.id == "robots"]
        if calls:
            counts[where] = len(calls)
    assert counts == {where: n for where, (n, _, _) in ALLOWED.items()}
    assert {kind for _, kind, _ in ALLOWED.values()} <= set(BOUNDARIES)


# -- a model file faultgen writes: its writer returns the Robot (issue 57, item 1) ----------------


def test_a_written_model_is_the_robot_a_reload_gives_and_a_moved_one_too(tmp_path, loads):
    import mujoco

    from faultgen.calibrate import parameters

    text = robots.load("puma560").path.read_text()
    loads.clear()
    (tmp_path / "staged").mkdir()
    written = robots.write(tmp_path / "staged" / "arm.xml", text)
    assert loads == []  # read back by its writer, not resolved by name
    assert written is robots.load(tmp_path / "staged" / "arm.xml")  # the same object: what any reload gives
    (tmp_path / "staged").rename(tmp_path / "final")
    moved = robots.moved(written, tmp_path / "final" / "arm.xml")
    again = robots.load(tmp_path / "final" / "arm.xml")
    assert (moved.name, moved.path, moved.digest) == (again.name, again.path, again.digest)
    assert moved.model is written.model  # not compiled again
    assert parameters(moved) == parameters(again)
    assert moved.new_spec().modelfiledir == str(again.path.parent)
    assert mujoco.MjSpec.to_xml(moved.new_spec()) == mujoco.MjSpec.to_xml(again.new_spec())
    (tmp_path / "final" / "arm.xml").write_text(text.replace("puma", "Puma", 1))
    with pytest.raises(robots.ModelError, match="not the file the robot 'arm' was read from"):
        robots.moved(written, tmp_path / "final" / "arm.xml")


def test_a_calibration_resolves_its_robot_once_and_returns_the_model_it_wrote(coulomb_log, coulomb_calibration):
    """``calibrate`` resolves the nominal robot once (the public entry) and returns the calibrated
    robot it wrote (``Calibration.model``): before, ``calibrate.loop`` loaded the model file it had
    just written to make parameters.json, and ``refit`` loaded it again with the nominal by name."""
    import json

    from faultgen.calibrate import parameters, predict

    result, out, loads, _ = coulomb_calibration
    assert loads == ["puma560"]
    assert [(s.effect.id, s.axes) for s in result.steps] == [("coulomb", [2])]
    reloaded = robots.load(result.model_out)
    assert result.model.path == reloaded.path == result.model_out.resolve()
    assert result.model.digest == reloaded.digest and result.nominal_digest == robots.load("puma560").digest
    assert parameters(result.model) == parameters(reloaded)
    assert json.loads((out / "model" / "parameters.json").read_text()) == json.loads(
        json.dumps(parameters(reloaded)))
    assert (predict(result.model, coulomb_log) == result.calibrated).all()


def test_refit_takes_the_nominal_robot_and_checks_it_is_the_calibrations(coulomb_log, coulomb_calibration, tmp_path):
    from dataclasses import replace

    from faultgen.calibrate.refit import calibrated_from, refit

    result = coulomb_calibration[0]
    puma = robots.load("puma560")
    assert calibrated_from(result, puma) is puma
    with pytest.raises(TypeError, match="expected a Robot, got str 'puma560'"):
        refit(result, coulomb_log, "puma560")
    with pytest.raises(ValueError, match="the nominal robot given .irb6700.* is not the one the calibration started "
                                         "from .puma560"):
        calibrated_from(result, robots.load("irb6700"))
    (tmp_path / "puma560").mkdir()
    (tmp_path / "puma560" / "puma560.xml").write_text(puma.path.read_text().replace("puma", "Puma", 1))
    with pytest.raises(ValueError, match="its MJCF's SHA-1"):  # same name, another file
        calibrated_from(result, robots.load(tmp_path / "puma560"))
    with pytest.raises(ValueError, match="holds no calibrated robot"):
        calibrated_from(replace(result, model=None), puma)


def test_robots_add_loads_nothing_by_name(tmp_path, loads):
    """``robots add`` checks the folder it writes by reading its model back once, from its writer
    (``robots.write``), and names it by the folder it renames into place (``robots.moved``): before,
    it loaded the staged file and then the folder again."""
    from faultgen.model import folder

    source = robots.robots_dir() / "irb6700"
    loads.clear()
    added = folder.add("irb_copy", source / "arm.xml", tmp_path / "irb_copy", drivetrain=source / "drivetrain.toml",
                       payload=200.0)
    assert loads == []
    again = robots.load(tmp_path / "irb_copy")
    assert (added.robot.path, added.robot.digest, added.robot.name) == (again.path, again.digest, again.name)


def test_a_calibrating_monitor_resolves_its_robot_once(tmp_path, loads, kr210_fleet):
    """``faultgen monitor`` calibrating each unit's model on its first log: the robot is resolved once
    (the command), each unit's calibrated and twin models come from their writers; the second run
    on the same OUT reads what the first cached (``monitor.unit.cached_model``), each file once.
    The first run also opens every log file once, calibration, program, twin and scoring together
    (issue 57 item 2; tests/test_read_once.py's calibrated run, merged here: one calibrating run)."""
    import shutil

    import open_counter

    spec, robot, logs = kr210_fleet
    loads.clear()
    args = ["monitor", str(logs), "--robot", str(robot), "-o", str(tmp_path / "out"), "--train", "10",
            "--persistence", "3", "--no-progress"]
    with open_counter.opens_under(logs) as counts:
        result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert loads == [str(robot)]
    files = sorted(p.relative_to(logs).as_posix() for p in logs.glob("*/*.csv"))
    assert len(files) == 2 * spec.days
    assert {name: counts[name] for name in files} == {name: 1 for name in files}
    assert set(counts) <= set(files) | {"events.csv"}
    assert (tmp_path / "out" / "units.csv").read_text().count("calibrated") == 2
    cached = sorted((tmp_path / "out" / ".cache" / "calibrated").glob("*/model/*.xml"))
    assert len(cached) == 4  # each unit's calibrated model and its twin model
    shutil.rmtree(tmp_path / "out" / ".state")  # the units scored again, from the cached calibrations
    loads.clear()
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert loads[0] == str(robot) and sorted(loads[1:]) == [str(path) for path in cached]


# -- a run from its text: robot, task, friction model and stepper each looked up once -------------


@pytest.fixture
def looked_up():
    """Calls of the four look-ups (``robots.load``, ``programs.load``, ``friction_models.get``,
    ``backends.get``) while the test runs, counted by their code objects through ``sys.setprofile``:
    every call is seen, whatever name or alias (``from ... import load``, a stored reference) it
    goes through."""
    import sys
    from collections import Counter

    from faultgen.simulation import backends, friction_models

    codes = {robots.load.__code__: "robot", programs.load.__code__: "task",
             friction_models.get.__code__: "friction", backends.get.__code__: "stepper"}
    counts = Counter()

    def profile(frame, event, arg):
        if event == "call" and frame.f_code in codes:
            counts[codes[frame.f_code]] += 1

    sys.setprofile(profile)
    try:
        yield counts
    finally:
        sys.setprofile(None)


def _program_file(tmp_path) -> Path:
    """A program file of content no earlier test planned (the task cache is per process and content):
    spot_weld's first move and dwell, a cycle of 1.0 s (the whole program, 9.2 s a cycle,
    until 2026-11-27, r10: what is looked up, and how often, does not depend on the program's
    length; its simulation by the loop stepper was most of the tests' time)."""
    path = tmp_path / "weld.toml"
    text = programs.export(robots.load("puma560"), "spot_weld")
    first = "[[segment]]".join(text.split("[[segment]]")[:3])
    path.write_text(first.replace('name = "spot_weld"', 'name = "weld_resolve_once"'))
    return path


def test_a_run_from_its_spec_looks_each_name_up_once(tmp_path, looked_up):
    """``resolve(spec)`` and the simulation of the run: the robot, the task (a program file), the
    stepper once; the friction model twice (RunConfig's check, the model's build: not yet carried as
    an object, docs/architecture.md, "How a run is built")."""
    from faultgen.simulation import resolve, spec

    path = _program_file(tmp_path)
    looked_up.clear()
    run = resolve.resolve(spec.RunSpec("puma560", str(path), friction="stribeck", cycles=1, stepper="loop"))
    run.simulate(progress=False)
    assert dict(looked_up) == {"robot": 1, "task": 1, "stepper": 1, "friction": 2}
    looked_up.clear()  # the same run again in this process: the task read and planned once per content
    resolve.resolve(spec.RunSpec("puma560", str(path), friction="stribeck", cycles=1)).simulate(progress=False)
    assert looked_up["task"] == 0


def test_simulate_looks_its_robot_and_task_up_once(tmp_path, looked_up):
    """``faultgen simulate --task PROGRAM``: the robot, the program (checked, planned, its dataset's
    limits and record all from the one read) and the stepper once, by ``resolve(RunSpec)`` (issue 84
    item 5: the stepper rides on the resolved run, found by its spec's name, the default)."""
    path = _program_file(tmp_path)
    looked_up.clear()
    result = runner.invoke(app, ["simulate", "--robot", "puma560", "--task", str(path), "--cycles", "1",
                                 "-o", str(tmp_path / "one.h5")])
    assert result.exit_code == 0, result.output
    assert (looked_up["robot"], looked_up["task"], looked_up["stepper"]) == (1, 1, 1), dict(looked_up)
