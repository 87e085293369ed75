"""The command line imports what its command needs (issue 87): ``faultgen --help`` and
``faultgen --version`` import no command module and none of the heavy libraries, the command
table (faultgen/cli/table.py) lists the commands the modules define with their first sentences,
and the help a fresh process prints, each command's module imported when it is looked up, is the
text of the app with every module imported (the help the other tests check)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import click
import pytest
import typer.main

import faultgen
from faultgen import children
from faultgen.cli import app
from faultgen.cli.table import COMMANDS, MODULES

#: What ``faultgen --help`` must not import: the libraries that take seconds on a loaded machine.
HEAVY = {"scipy", "pandas", "mujoco", "h5py", "sklearn", "matplotlib", "plotly", "dask"}

#: In a fresh interpreter: every help page (and an unknown command's error) as ``faultgen`` prints
#: them, first lazily (the app run as the console script runs it: one command's module imported
#: when it is looked up), then eagerly (typer's own build of the app with every module imported,
#: as typer's CliRunner in the other tests builds it), the same way captured.
PAGES = r"""
import contextlib, io, json, sys
import typer.main
from faultgen.cli import app
paths = json.loads(sys.argv[1])

def printed(run):
    out = {}
    for path in paths:
        stdout, stderr = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
            try:
                run(path)
            except SystemExit as done:
                code = done.code
        out[" ".join(path)] = [stdout.getvalue(), stderr.getvalue(), code]
    return out

lazy = printed(lambda path: app([*path], prog_name="faultgen"))
eager = printed(lambda path: typer.main.get_command(app)([*path], prog_name="faultgen"))
print(json.dumps([lazy, eager]))
"""


#: ``python -m faultgen.cli ARGS``, printing at its exit (on stderr, last) the modules it imported.
RUN_MAIN = r"""
import atexit, json, runpy, sys
atexit.register(lambda: print(json.dumps(sorted(sys.modules)), file=sys.stderr))
sys.argv = ["faultgen", *sys.argv[1:]]
runpy.run_module("faultgen.cli", run_name="__main__", alter_sys=True)
"""


def imported_by(*args: str) -> set[str]:
    """The modules ``python -m faultgen.cli ARGS`` imports (``sys.modules`` at its exit: ``-X
    importtime`` misses ``importlib.import_module``), its output checked."""
    done = subprocess.run(children.command("-c", RUN_MAIN, *args), capture_output=True, text=True,
                          env=children.environment(), check=True)
    assert done.stdout.startswith(("faultgen ", "Usage: ")), done.stdout
    return set(json.loads(done.stderr.splitlines()[-1]))


@pytest.mark.parametrize("option", ["--help", "--version"])
def test_help_and_version_import_no_command_module_and_no_heavy_library(option):
    modules = imported_by(option)
    assert "typer" in modules  # the measurement sees the imports
    assert not {m.split(".")[0] for m in modules} & HEAVY, sorted(m for m in modules if m.split(".")[0] in HEAVY)
    assert not {f"faultgen.cli.{m}" for m in MODULES} & modules


def test_a_command_imports_its_own_module_only():
    modules = imported_by("info", "--help")
    assert "faultgen.cli.data" in modules
    assert not {f"faultgen.cli.{m}" for m in MODULES if m != "data"} & modules


def test_the_table_lists_every_command_its_module_and_first_sentence_in_order():
    group = typer.main.get_command(app)  # every module imported: the app as typer builds it
    ctx = click.Context(group)
    names = group.list_commands(ctx)
    assert names == list(COMMANDS), "faultgen/cli/table.py's COMMANDS: a command added, renamed or moved"
    for name in names:
        command = group.commands[name]
        callback = command.callback
        assert callback.__module__ == f"faultgen.cli.{COMMANDS[name][0]}", name
        assert command.get_short_help_str(1000) == COMMANDS[name][1], (
            f"faultgen/cli/table.py's line for {name!r} is not the first sentence of its help")


def test_an_unknown_name_is_no_command():
    group = typer.main.get_command(app)
    assert group.get_command(click.Context(group), "no-such-command") is None
    assert app.click_command("no-such-command") is None


def test_a_command_the_table_does_not_name_is_still_found(monkeypatch):
    monkeypatch.setattr(app, "_commands", list(app.registered_commands))  # restored after the test

    @app.command("not-in-the-table")
    def added() -> None:
        """Added without its line in the table."""

    assert app.click_command("not-in-the-table").callback.__name__ == "added"


def pages() -> list[list[str]]:
    """Every command path's ``--help``, the bare ``faultgen``, and unknown and misspelt commands."""
    group = typer.main.get_command(app)
    paths = [["--help"], [], ["--version"], ["simulat"], ["no-such-command"], ["bench", "scor"]]
    for name in COMMANDS:
        paths.append([name, "--help"])
        sub = group.commands[name]
        if isinstance(sub, click.Group):
            paths += [[name, s, "--help"] for s in sub.list_commands(click.Context(sub))]
    return paths


def test_a_fresh_process_prints_the_same_help_as_the_whole_app():
    """Lazy (one module imported per command looked up) and eager (every module imported, typer's
    own build) print the same bytes, exit codes and errors."""
    paths = pages()
    done = subprocess.run(children.command("-c", PAGES, json.dumps(paths)), capture_output=True, text=True,
                          env=children.environment({"COLUMNS": "80"}), check=True)
    lazy, eager = json.loads(done.stdout)
    for path in paths:
        assert lazy[" ".join(path)] == eager[" ".join(path)], path
    assert lazy["simulat"][1] == "error: No such command 'simulat'. Did you mean 'simulate'?; see faultgen --help\n"
    assert lazy["bench scor"][1].startswith("error: No such command 'scor'")
    assert lazy["--version"] == [f"faultgen {faultgen.__version__}\n", "", 0]
    assert all(lazy[f"{name} --help"][0].startswith(f"Usage: faultgen {name} ") for name in COMMANDS)


def test_command_modules_are_attributes_of_the_package():
    import faultgen.cli

    assert faultgen.cli.runs.__name__ == "faultgen.cli.runs"
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        faultgen.cli.nothing  # noqa: B018
    assert set(faultgen.cli.__all__) == {*MODULES, "app"}
    assert os.environ.get("PYTHONSAFEPATH") == "1"
