"""Issue 74 item 4, the function-length check beside tests/test_architecture.py's 600-line one: no
function of faultgen, analysis or benchmarks over 80 lines (its docstring included) and no CLI
command whose body (its signature and docstring aside) is over 40 lines, but the ones listed here,
each to be split: a new long one fails, and one that got short must leave its list (a ratchet, as
test_architecture.py's LONG_MODULES)."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: The most lines a function may have, from its ``def`` to its last line (issue 74: "functions over
#: 80 lines <= 8, docstrings included").
MAX_FUNCTION_LINES = 80
#: The most lines a CLI command's body may have, its signature and docstring aside (issue 74: 0 over 40).
MAX_COMMAND_LINES = 40

#: Functions known to be longer (main a355838, 2026-11-26: 31), each to be split: remove one as its
#: split is merged.
LONG_FUNCTIONS = {
    "faultgen/calibrate/loop.py::run",
    "faultgen/cli/monitoring.py::monitor_command",
    "faultgen/monitor/unit_chart.py::figure",
    "faultgen/runs/sweep.py::run",
}
#: CLI commands whose body is known to be longer: none (6 on 2026-11-26, each since moved its policy
#: into the library); a command added here needs a reason.
LONG_COMMANDS: set[str] = set()


def _functions(path: Path):
    """(qualified name, node) of every function and method of a module, nested ones included."""
    def walk(node, prefix):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef):
                yield prefix + child.name, child
                yield from walk(child, f"{prefix}{child.name}.")
            elif isinstance(child, ast.ClassDef):
                yield from walk(child, f"{prefix}{child.name}.")
            else:
                yield from walk(child, prefix)

    yield from walk(ast.parse(path.read_text()), "")


def _is_command(node) -> bool:
    """Decorated by a typer app's ``.command(...)``."""
    return any(isinstance(d, ast.Call) and isinstance(d.func, ast.Attribute) and d.func.attr == "command"
               for d in node.decorator_list)


def _body_lines(node) -> int:
    """The lines of a function's body after its docstring."""
    body = node.body
    if len(body) > 1 and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
            and isinstance(body[0].value.value, str):
        body = body[1:]
    return node.end_lineno - body[0].lineno + 1


def long_functions(root: Path, trees=("faultgen", "analysis", "benchmarks")) -> tuple[dict[str, int], dict[str, int]]:
    """(functions over MAX_FUNCTION_LINES -> their lines, CLI commands whose body is over
    MAX_COMMAND_LINES -> its lines) under ``trees`` of ``root``, ``path::qualified.name`` (a robot
    folder's files, faultgen/_robots, left out)."""
    functions, commands = {}, {}
    for tree in trees:
        for path in sorted((root / tree).rglob("*.py")):
            if "_robots" in path.parts:
                continue
            name = path.relative_to(root).as_posix()
            for qualified, node in _functions(path):
                if (lines := node.end_lineno - node.lineno + 1) > MAX_FUNCTION_LINES:
                    functions[f"{name}::{qualified}"] = lines
                if _is_command(node) and (lines := _body_lines(node)) > MAX_COMMAND_LINES:
                    commands[f"{name}::{qualified}"] = lines
    return functions, commands


def test_no_function_is_over_80_lines_and_no_command_body_over_40_but_the_listed():
    functions, commands = long_functions(ROOT)
    assert {k: n for k, n in functions.items() if k not in LONG_FUNCTIONS} == {}, \
        f"functions over {MAX_FUNCTION_LINES} lines: split each (docs/architecture.md)"
    assert {k: n for k, n in commands.items() if k not in LONG_COMMANDS} == {}, \
        f"CLI command bodies over {MAX_COMMAND_LINES} lines: move the policy into the library"
    assert set(functions) == LONG_FUNCTIONS, f"no longer long: {sorted(LONG_FUNCTIONS - set(functions))}; " \
                                             "take them out of LONG_FUNCTIONS"
    assert set(commands) == LONG_COMMANDS, f"no longer long: {sorted(LONG_COMMANDS - set(commands))}; " \
                                           "take them out of LONG_COMMANDS"


def test_the_function_check_finds_a_long_function_and_a_long_command(tmp_path):
    """The check above can fail: a function of 81 lines is found (a method and a nested one too), one
    of 80 is not; a command of 41 body lines is found whatever its docstring, one of 40 is not."""
    def function(name: str, lines: int, indent: str = "", docstring: bool = False, decorator: str = "") -> str:
        head = [f"{indent}{decorator}\n"] if decorator else []
        body = [f'{indent}    """{name}."""\n'] if docstring else []
        body += [f"{indent}    x = {k}\n" for k in range(lines - 1 - len(body))]
        return "".join([*head, f"{indent}def {name}():\n", *body])

    (tmp_path / "faultgen" / "cli").mkdir(parents=True)
    (tmp_path / "faultgen" / "m.py").write_text(
        function("long", 81) + function("short", 80) + "class C:\n" + function("method", 81, "    ")
        + "def outer():\n" + function("inner", 81, "    "))
    command = "@app.command('x')"
    (tmp_path / "faultgen" / "cli" / "c.py").write_text(
        function("long_command", 43, docstring=True, decorator=command)  # def + docstring + 41 lines
        + function("short_command", 42, docstring=True, decorator=command)
        + function("not_a_command", 60))
    (tmp_path / "faultgen" / "_robots").mkdir()
    (tmp_path / "faultgen" / "_robots" / "r.py").write_text(function("robot", 200))
    functions, commands = long_functions(tmp_path, trees=("faultgen",))
    assert functions == {"faultgen/m.py::long": 81, "faultgen/m.py::C.method": 81, "faultgen/m.py::outer": 82,
                         "faultgen/m.py::outer.inner": 81}
    assert commands == {"faultgen/cli/c.py::long_command": 41}
