"""Issue 50 item 5, fuzzed: every numeric option of every command, given generated text (huge,
tiny, negative, NaN, inf, "1e20", non-numeric, empty, unicode), either passes its option check or
is refused with one line ``error: ...`` and exit 2, never a traceback. The rest of each command
line is refused before any work (an input that does not exist, an output folder that does not
exist), so a value the option takes costs milliseconds too: the fuzz covers the checks, not the
simulations. docs/reliability.md gives the number of cases.
"""

from __future__ import annotations

import types
import typing

import pytest
import typer
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from faultgen.cli import app

runner = CliRunner()

#: The rest of each command line: refused before any work, after the options are checked.
MISSING = "/nonexistent-faultgen-folder"
BASE = {
    "simulate": ["-o", f"{MISSING}/x.h5"],
    "sweep": ["--preset", "quick", "-o", f"{MISSING}/x.h5"],
    "fleet": ["-o", f"{MISSING}/x.h5"],
    "calibrate": ["--robot", "puma560", "--measured", f"{MISSING}/log.csv", "-o", f"{MISSING}/c"],
    "excitation": ["puma560", "-o", f"{MISSING}/e.csv"],
    "robots": ["add", "x", "--from", f"{MISSING}/arm.urdf", "-o", f"{MISSING}/r"],
    "bench-isolators": [f"{MISSING}/d.h5"],
    "detect": [f"{MISSING}/d.h5"],
    "training-source": [f"{MISSING}/d.h5"],
    "classify": [f"{MISSING}/d.h5"],
    "monitor": [f"{MISSING}/LOGS", "--robot", "irb6700", "-o", f"{MISSING}/m"],
    "hidden-log": ["puma560", "--effect", "stribeck", "-o", f"{MISSING}/log.csv"],
    "reproduce": ["--tiny", "-o", f"{MISSING}/repro"],
    "bench make": ["thesis", "-o", f"{MISSING}/bench"],
    "tasks friction-test": ["puma560", "-o", f"{MISSING}/test.toml"],
}
#: Examples per option; with the options found, the total the docs give (test_the_fuzz_covers_...).
EXAMPLES = 50


def _numeric(annotation) -> bool:
    """Whether an option's type is int or float (or a list or an optional of one)."""
    if typing.get_origin(annotation) in (typing.Union, types.UnionType, list):
        return any(_numeric(arg) for arg in typing.get_args(annotation) if arg is not type(None))
    return annotation in (int, float)


def numeric_options() -> list[tuple[str, str]]:
    """(command, --option) of every int or float option of every command and of every command of a
    group ("bench make"), from the signatures."""
    found = []
    commands = [(c.name, c) for c in app.registered_commands]
    commands += [(f"{g.name} {c.name}", c) for g in app.registered_groups for c in g.typer_instance.registered_commands]
    for name, command in commands:
        hints = typing.get_type_hints(command.callback, include_extras=True)
        for option_name, hint in hints.items():
            if typing.get_origin(hint) is not typing.Annotated:
                continue
            base, *extras = typing.get_args(hint)
            option = next((e for e in extras if isinstance(e, typer.models.OptionInfo)), None)
            if option is None or not _numeric(base):
                continue
            # in Annotated form typer keeps the first name given in ``default``
            names = [option.default, *(option.param_decls or ())]
            flags = [d for d in names if isinstance(d, str) and d.startswith("--")]
            found.append((name, flags[0] if flags else "--" + option_name.replace("_", "-")))
    return found


OPTIONS = numeric_options()


VALUES = st.one_of(
    st.integers(min_value=-(10**40), max_value=10**40).map(str),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.floats(allow_nan=True, allow_infinity=True).map(lambda x: f"{x:g}"),
    st.sampled_from(["1e20", "-1e20", "1e-300", "1e308", "1e309", "nan", "NaN", "inf", "-inf", "+0", "-0", "0",
                     "", " ", "0x10", "1_000", "1,5", "1.5.2", "abc", "١٢", "ⅷ", "1e", "True", "None", "--help"]),
    st.text(max_size=12),
)


def test_every_command_with_a_numeric_option_is_fuzzed():
    commands = {command for command, _ in OPTIONS}
    assert commands == set(BASE), commands ^ set(BASE)
    assert len(OPTIONS) >= 40  # the options found: a regression in the discovery would fuzz nothing


@pytest.mark.parametrize(("command", "option"), OPTIONS, ids=[f"{c} {o}" for c, o in OPTIONS])
@settings(max_examples=EXAMPLES, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(value=VALUES)
def test_a_numeric_option_is_taken_or_refused_in_one_line(command, option, value):
    result = runner.invoke(app, [*command.split(), *BASE[command], option, value])
    assert result.exception is None or isinstance(result.exception, SystemExit), (value, result.output)
    assert "Traceback" not in result.output, (value, result.output)
    assert result.exit_code == 2, (value, result.output)  # the value, or the rest of the line, is refused
    lines = result.output.strip().splitlines()  # a progress line ("reading FILE") may come first
    errors = [line for line in lines if line.startswith("error: ")]
    assert len(errors) == 1 and lines[-1] == errors[0], (value, lines)


def test_a_library_message_of_several_lines_is_one_line(tmp_path):
    model = tmp_path / "negative_mass.xml"  # MuJoCo's compiler error has a second line, "Element name ..."
    model.write_text('<mujoco><worldbody><body><joint type="hinge"/><geom size="0.1" mass="-1"/></body>'
                     "</worldbody></mujoco>")
    result = runner.invoke(app, ["robots", str(model)])
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {model}: ") and "negative" in lines[0], lines
