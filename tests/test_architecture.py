"""The package layout as a contract: layers checked by import-linter, first-round names kept."""

import ast
import importlib
import shutil
import subprocess
import sys
from pathlib import Path

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
    assert "Contracts: 3 kept, 0 broken." in result.stdout


@pytest.mark.parametrize(("module", "back_import", "contract"), [
    ("faultgen/effects/friction.py", "from faultgen.model import robots", "faultgen layers, top to bottom BROKEN"),
    ("faultgen/simulation/sensors.py", "import analysis.features", "only the command line"),
    ("analysis/features.py", "from faultgen.runs import sweep", "does not drive the generator BROKEN"),
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


def _imports(path: Path) -> list[str]:
    """Modules a source file imports, as written (``from a import b`` gives ``a.b``)."""
    names = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module:
            names += [f"{node.module}.{alias.name}" for alias in node.names]
    return names


def test_the_library_imports_modules_by_their_layered_names():
    # import-linter sees `from faultgen import robots` as an import of the package root, so a
    # first-round name would hide a back-running import from the contract.
    old = {f"faultgen.{name}" for name in faultgen.MOVED}
    for path in sorted([*(ROOT / "faultgen").rglob("*.py"), *(ROOT / "analysis").rglob("*.py")]):
        stale = [name for name in _imports(path) if name in old or name.rsplit(".", 1)[0] in old]
        assert stale == [], f"{path.relative_to(ROOT)} imports {stale}; use the names in faultgen.MOVED"


@pytest.mark.parametrize("old", sorted(faultgen.MOVED))
def test_first_round_module_names_are_the_moved_modules(old):
    moved = importlib.import_module(faultgen.MOVED[old])
    assert importlib.import_module(f"faultgen.{old}") is moved
    assert getattr(faultgen, old) is moved
    assert moved.__spec__.name == faultgen.MOVED[old]  # the module keeps its own identity


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
