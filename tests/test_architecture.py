"""The package layout as a contract: layers checked by import-linter, modules by their layered
names only, an explicit public API."""

import ast
import importlib
import re
import shutil
import subprocess
import sys
from pathlib import Path

import grimp
import pytest

import faultgen

ROOT = Path(__file__).resolve().parents[1]
LINT_IMPORTS = Path(sys.executable).parent / "lint-imports"


def lint_imports(cwd: Path) -> subprocess.CompletedProcess:
    env = {"PYTHONPATH": str(cwd), "PATH": str(LINT_IMPORTS.parent), "LC_ALL": "C.UTF-8", "LANG": "C.UTF-8"}
    return subprocess.run([str(LINT_IMPORTS), "--config", str(cwd / "pyproject.toml"), "--no-cache"], cwd=cwd,
                          env=env, capture_output=True, text=True, timeout=300, check=False)


def test_the_layers_contract_holds():
    result = lint_imports(ROOT)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Contracts: 6 kept, 0 broken." in result.stdout


@pytest.mark.parametrize(("module", "back_import", "contract"), [
    ("faultgen/effects/friction.py", "from faultgen.model import robots", "faultgen layers, top to bottom BROKEN"),
    ("faultgen/simulation/sensors.py", "import analysis.features", "only the command line"),
    ("analysis/features.py", "from faultgen.runs import sweep", "does not drive the generator BROKEN"),
    ("faultgen/data/schema.py", "from faultgen.data import reader", "data flowing one way (docs/architecture.md) BROKEN"),
    ("analysis/benchmark/truth.py", "from analysis.benchmark import figures",
     "the analysis tables' modules, one way (docs/architecture.md) BROKEN"),
    ("analysis/classify/classifiers.py", "from analysis.classify import evaluation",
     "the classification modules, one way (docs/architecture.md) BROKEN"),
])
def test_an_import_that_runs_back_up_breaks_the_contract(tmp_path, module, back_import, contract):
    for tree in ("faultgen", "analysis"):
        shutil.copytree(ROOT / tree, tmp_path / tree, ignore=shutil.ignore_patterns("__pycache__", "_robots"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path)
    target = tmp_path / module
    target.write_text(target.read_text() + f"\n{back_import}  # runs back up\n")
    result = lint_imports(tmp_path)
    assert result.returncode == 1, result.stdout + result.stderr
    assert contract in result.stdout.replace("\n", " "), result.stdout


def _import_graph() -> dict[str, set[str]]:
    """faultgen's and analysis's modules -> the modules of the two each imports (at the top, inside
    functions or under TYPE_CHECKING alike: a lazy import is still a dependency), from grimp."""
    graph = grimp.build_graph("faultgen", "analysis", cache_dir=None)
    return {module: set(graph.find_modules_directly_imported_by(module)) for module in graph.modules}


def _cycles(imports: dict[str, set[str]], allowed: frozenset = frozenset()) -> list[list[str]]:
    """The import cycles of ``imports``: each group of modules that reach each other through
    imports (a strongly connected component of more than one module, Tarjan's algorithm), sorted;
    an import between the two modules of an ``allowed`` pair is left out."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found = []

    def visit(module: str) -> None:
        index[module] = low[module] = len(index)
        stack.append(module)
        for other in sorted(imports.get(module, ())):
            if frozenset({module, other}) in allowed:
                continue
            if other not in index:
                visit(other)
                low[module] = min(low[module], low[other])
            elif other in stack:
                low[module] = min(low[module], index[other])
        if low[module] == index[module]:
            group = []
            while not group or group[-1] != module:
                group.append(stack.pop())
            if len(group) > 1:
                found.append(sorted(group))

    for module in sorted(imports):
        if module not in index:
            visit(module)
    return sorted(found)


def test_no_modules_import_each_other():
    """No circle of imports between the modules of faultgen and analysis, of two modules or more (a
    package's ``__init__`` is a module too): none (issues 47, 57)."""
    imports = _import_graph()
    assert _cycles(imports) == [], "modules that import each other (docs/architecture.md)"


def test_the_cycle_check_finds_a_cycle():
    """The check above can fail: a circle of three modules, and one import added back up the data
    modules' one-way flow (schema importing the reader), are found; an allowed pair is not."""
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": {"a"}}, frozenset({frozenset({"a", "b"})})) == []
    imports = _import_graph()
    imports["faultgen.data.schema"].add("faultgen.data.reader")
    assert any({"faultgen.data.schema", "faultgen.data.reader"} <= set(group)
               for group in _cycles(imports))


#: The most lines a module of faultgen, analysis or benchmarks may have (issue 57): a reader takes in
#: a module whole, and a longer one does more than one job (docs/architecture.md).
MAX_LINES = 600
#: Modules known to be longer, each being split: remove one as its split is merged.
#: None: faultgen/monitor/loop.py was split by job in branch `scale` (issue 60: unit, feed, parallel, remote).
LONG_MODULES: set[str] = set()


def _long_modules(root: Path, trees=("faultgen", "analysis", "benchmarks"), most: int = MAX_LINES) -> dict[str, int]:
    """The Python files under ``trees`` of ``root`` with more than ``most`` lines -> their lines
    (a robot folder's files, faultgen/_robots, left out)."""
    found = {}
    for tree in trees:
        for path in sorted((root / tree).rglob("*.py")):
            lines = len(path.read_text().splitlines())
            if lines > most and "_robots" not in path.parts:
                found[path.relative_to(root).as_posix()] = lines
    return found


def test_no_module_is_over_600_lines():
    long = _long_modules(ROOT)
    assert {name: n for name, n in long.items() if name not in LONG_MODULES} == {}, \
        f"modules over {MAX_LINES} lines: split each by job (docs/architecture.md)"
    assert set(long) == LONG_MODULES, f"no longer over {MAX_LINES} lines: {sorted(LONG_MODULES - set(long))}; " \
                                      "take them out of LONG_MODULES"


def test_the_line_check_finds_a_long_module(tmp_path):
    """The check above can fail: a module of 601 lines is found, one of 600 is not, in any of the
    trees, and a robot folder's files are left out."""
    for tree, lines in (("faultgen", 601), ("analysis", 600), ("benchmarks", 700)):
        (tmp_path / tree).mkdir()
        (tmp_path / tree / "m.py").write_text("x = 1\n" * lines)
    (tmp_path / "faultgen" / "_robots").mkdir()
    (tmp_path / "faultgen" / "_robots" / "r.py").write_text("x = 1\n" * 900)
    assert _long_modules(tmp_path) == {"faultgen/m.py": 601, "benchmarks/m.py": 700}


def _imports(path: Path) -> list[str]:
    """Modules a source file imports, as written (``from a import b`` gives ``a.b``)."""
    names = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module:
            names += [f"{node.module}.{alias.name}" for alias in node.names]
    return names


#: The first-round module names (before the sub-packages) and where each module lives now.
FIRST_ROUND = {
    "robots": "faultgen.model.robots",
    "friction": "faultgen.effects.friction",
    "tasks": "faultgen.operation.tasks",
    "ik": "faultgen.operation.ik",
    "wear": "faultgen.operation.wear",
    "control": "faultgen.simulation.control",
    "sensors": "faultgen.simulation.sensors",
    "sim": "faultgen.simulation.stepping",
    "dataset": "faultgen.data.dataset",
    "measured": "faultgen.logs.measured",
    "atomic": "faultgen.data.atomic",
    "sweep": "faultgen.runs.sweep",
}


def _sources() -> list[Path]:
    return sorted(path for tree in ("faultgen", "analysis", "tests", "benchmarks", "docs")
                  for path in (ROOT / tree).rglob("*.py") if "_robots" not in path.parts)


def test_nothing_imports_a_first_round_module_name():
    # import-linter sees `from faultgen import robots` as an import of the package root, so even the
    # public alias faultgen.robots would hide a back-running import from the contract.
    old = {f"faultgen.{name}" for name in FIRST_ROUND}
    for path in _sources():
        stale = [name for name in _imports(path) if name in old or name.rsplit(".", 1)[0] in old]
        assert stale == [], f"{path.relative_to(ROOT)} imports {stale}; use the layered names ({FIRST_ROUND})"


def test_no_code_or_document_names_a_first_round_module():
    """Docstrings, comments and documents name modules by their layered names too; only the user
    documents may show the public alias ``faultgen.robots`` (``faultgen.robots.load(DIR)``)."""
    anywhere = re.compile(r"faultgen\.(" + "|".join(sorted(set(FIRST_ROUND) - {"robots"})) + r")\b")
    alias = re.compile(r"faultgen\.robots\b")
    found = []
    for path in [*_sources(), *(ROOT / "docs").glob("*.md"), ROOT / "README.md"]:
        if path == Path(__file__).resolve():
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            code = path.suffix == ".py" and path != ROOT / "faultgen" / "__init__.py"
            if anywhere.search(line) or (code and alias.search(line)):
                found.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()}")
    assert not found, "first-round module names:\n" + "\n".join(found)


@pytest.mark.parametrize("old", sorted(FIRST_ROUND))
def test_first_round_module_names_no_longer_import(old):
    importlib.import_module(FIRST_ROUND[old])  # the layered name does
    with pytest.raises(ModuleNotFoundError, match=f"faultgen.{old}"):
        importlib.import_module(f"faultgen.{old}")
    if old != "robots":  # the one public module alias, below
        with pytest.raises(AttributeError, match=old):
            getattr(faultgen, old)


def test_faultgen_installs_no_import_hook():
    hooks = [finder for finder in sys.meta_path if type(finder).__module__.startswith("faultgen")]
    assert hooks == []


def test_the_public_names_resolve_to_the_layered_modules():
    for name, (module, attribute) in faultgen.PUBLIC.items():
        module = importlib.import_module(module)
        assert getattr(faultgen, name) is (module if attribute is None else getattr(module, attribute)), name
    from faultgen.model import robots  # issue 37's `faultgen.robots.load(DIR)`

    assert faultgen.robots is robots and faultgen.robots.load is robots.load is faultgen.load_robot
    assert set(faultgen.PUBLIC) <= set(dir(faultgen)) and set(faultgen.__all__) == {"__version__", *faultgen.PUBLIC}
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        faultgen.nothing  # noqa: B018


def _string_constants(path: Path) -> list[tuple[int, str]]:
    return [(node.lineno, node.value) for node in ast.walk(ast.parse(path.read_text()))
            if isinstance(node, ast.Constant) and isinstance(node.value, str)]


def test_no_code_outside_the_effects_package_names_an_effect():
    """One definition per effect: outside ``faultgen/effects/`` no code holds an effect id as a
    string (user-facing text aside: ids inside longer strings are not matched). ``stribeck`` is
    also the static friction model's name (``--friction stribeck``), so it is left out here."""
    from faultgen.effects import REGISTRY
    from faultgen.effects.friction import MODELS

    ids = set(REGISTRY) - set(MODELS)
    assert len(ids) >= 8
    found = []
    for tree in ("faultgen", "analysis"):
        for path in sorted((ROOT / tree).rglob("*.py")):
            if "effects" in path.relative_to(ROOT).parts[:2] and tree == "faultgen":
                continue
            found += [f"{path.relative_to(ROOT)}:{line}: {value!r}" for line, value in _string_constants(path)
                      if value in ids]
    assert not found, "effect ids outside faultgen/effects/:\n" + "\n".join(found)


def test_the_id_check_finds_an_id(tmp_path):
    """The check above can fail: a branch on an effect id is a string constant it finds."""
    source = tmp_path / "branch.py"
    source.write_text('def share(effect):\n    return 1.0 if effect.id == "cogging" else 0.0\n')
    assert (2, "cogging") in _string_constants(source)
