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


@pytest.fixture
def loads(monkeypatch):
    """The names ``robots.load`` is called with while the test runs."""
    calls = []
    load = robots.load

    def counting(name):
        calls.append(str(name))
        return load(name)

    monkeypatch.setattr(robots, "load", counting)
    return calls


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


def test_the_monitor_resolves_its_robot_once(tmp_path, loads):
    """``faultgen monitor`` on the nominal model: the robot folder is resolved once, by the command
    (`monitor.loop`), and the twins and their cycles take that Robot. Before: once by the command,
    once per unit's twin and once per simulated cycle's ``RunConfig`` (24 in all on the IRB 6700
    fleet of tests/test_monitor_shipped.py, 3 units, --no-calibrate; measured 2026-11-25)."""
    import independent_fleet

    robot, logs, _ = independent_fleet.write_fleet(
        tmp_path / "fleet", independent_fleet.FleetSpec(units=3, worn=1, days=14, seed=5, onset=(12, 13)))
    loads.clear()  # what building the fleet loaded (robots add checks the folder it writes)
    result = runner.invoke(app, ["monitor", str(logs), "--robot", str(robot), "-o", str(tmp_path / "out"),
                                 "--no-calibrate", "--train", "10", "--persistence", "3", "--no-progress"])
    assert result.exit_code == 0, result.output
    assert loads == [str(robot)]


#: The modules that call ``robots.load`` (besides the command line, ``faultgen/cli/``), how many
#: times, and why each may: a boundary (the public API or a worker resolving what it was sent as a
#: name), a model file the code itself just wrote or calibrated, or a name stored in a record.
#: A new caller fails this test: resolve at the boundary and pass the Robot instead, or add it
#: here with its reason.
ALLOWED = {
    "faultgen/calibrate/__init__.py": (1, "public calibrate(): a name or a Robot, resolved once"),
    "faultgen/data/fleetlogs.py": (1, "public import_logs(): a name or a Robot, resolved once"),
    "faultgen/runs/grid.py": (1, "public Grid: each robot once for every run"),
    "faultgen/simulation/config.py": (2, "public RunConfig: a name once on construction, or after unpickling"),
    "faultgen/monitor/loop.py": (1, "monitor(): the library entry, once per run"),
    "faultgen/monitor/feed.py": (1, "Context.new_source: a worker without the run's source (loky, Dask), once"),
    "faultgen/monitor/remote.py": (1, "a Dask worker: once"),
    "faultgen/monitor/twin.py": (1, "a twin of a model file (the calibrated model, a given one)"),
    "faultgen/monitor/unit.py": (2, "the calibrated model the monitor just wrote"),
    "faultgen/calibrate/loop.py": (1, "the calibrated model just written (its parameters.json)"),
    "faultgen/calibrate/refit.py": (2, "the calibrated model written; the nominal by the name its result stores"),
    "faultgen/model/folder.py": (2, "robots add: the folder just written, checked by loading it"),
    "faultgen/data/robot_record.py": (1, "a dataset written before drivetrains were stored: its robot label"),
    "faultgen/bench/independent.py": (2, "the independent simulator's own entry: a robot folder"),
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
    assert counts == {where: n for where, (n, _) in ALLOWED.items()}
