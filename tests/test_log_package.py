"""Issue 74, item 2: one log package (``faultgen.logs``) with one registry of formats, the measured
format its default entry, and no "no format given means measured" branch left in faultgen; issue 72's
leftover: the ``ur-rtde`` format reads RTDE's ``actual_current_as_torque`` (e-Series, PolyScope
>= 5.23; N m per joint, the measured current as torque by the controller's own constants) when a
log has it, before current x --torque-constants and the commanded ``target_moment``.

The reference of each read is independent of the format's mapping: the same signals written in the
measured format (t, q, qd, tau) and read by the measured format's reader."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

import fleetlog_folder
from faultgen.cli import app
from faultgen.data import logfiles
from faultgen.logs import formats, measured
from faultgen.model import robots

ROOT = Path(__file__).resolve().parents[1]
CONSTANTS = (2.0, 2.5, 3.0, 1.5, 1.0, 0.5)  # the test's, N m/A: not Universal Robots' numbers


@pytest.fixture(scope="module")
def puma():
    return robots.load("puma560")


def _rtde_log(path: Path, puma, columns=("as_torque", "current", "moment")) -> tuple:
    """An RTDE recorder log (space-separated, the recorder's names) of a few cycles at 250 Hz: the
    arm torque ``tau`` as ``actual_current_as_torque_i``, ``tau / CONSTANTS`` as ``actual_current_i``
    and ``tau`` x 0.5 + 1 as ``target_moment_i`` (commanded: another array, so the test sees which
    was read), as ``columns`` asks. Returns (t, q, qd, tau)."""
    t, q, qd, tau, _ = fleetlog_folder.log_signals(puma, 3, 0, np.zeros(6))
    table = {"timestamp": t, **{f"actual_q_{k}": q[:, k] for k in range(6)},
             **{f"actual_qd_{k}": qd[:, k] for k in range(6)}, "robot_mode": np.full(len(t), 7)}
    if "moment" in columns:
        table.update({f"target_moment_{k}": tau[:, k] * 0.5 + 1.0 for k in range(6)})
    if "current" in columns:
        table.update({f"actual_current_{k}": tau[:, k] / CONSTANTS[k] for k in range(6)})
    if "as_torque" in columns:
        table.update({f"actual_current_as_torque_{k}": tau[:, k] for k in range(6)})
    pd.DataFrame(table).to_csv(path, sep=" ", index=False, float_format="%.17g")
    return t, q, qd, tau


@pytest.mark.parametrize("constants", [None, CONSTANTS])
def test_ur_rtde_reads_the_current_as_torque_first_as_the_measured_format_reads_the_same_signals(
        tmp_path, puma, constants):
    """With ``actual_current_as_torque_i`` in the log it is the torque read, with or without torque
    constants and beside ``actual_current_i`` and ``target_moment_i``; the read equals the measured
    format's read of the same signals, and the note names the source."""
    t, q, qd, tau = _rtde_log(tmp_path / "ur.csv", puma)
    reference = measured.read(logfiles.write_csv(tmp_path / "m.csv", t, q, tau, qd), puma)
    data = formats.make("ur-rtde", **({} if constants is None else {"torque_constants": constants})).read(
        tmp_path / "ur.csv", puma)
    for name in ("t", "q", "qd", "qdd", "tau"):
        np.testing.assert_allclose(getattr(data, name), getattr(reference, name), rtol=1e-12, atol=1e-12)
    assert formats.torque_source(data.notes) == formats.CURRENT_AS_TORQUE
    assert formats.CURRENT_AS_TORQUE == "current as torque (controller's own constants)"
    assert ("the torque constants given are not used" in data.notes[0]) == (constants is not None)


def test_without_current_as_torque_the_order_is_kept(tmp_path, puma):
    """A log without ``actual_current_as_torque_i``: current x the constants given, else the
    commanded moment, else refused naming all three sources."""
    t, q, qd, tau = _rtde_log(tmp_path / "ur.csv", puma, ("current", "moment"))
    with_constants = formats.make("ur-rtde", torque_constants=CONSTANTS).read(tmp_path / "ur.csv", puma)
    np.testing.assert_allclose(with_constants.tau, tau, rtol=1e-12, atol=1e-12)
    assert formats.torque_source(with_constants.notes) == formats.MEASURED_CURRENT
    commanded = formats.make("ur-rtde").read(tmp_path / "ur.csv", puma)
    np.testing.assert_allclose(commanded.tau, tau * 0.5 + 1.0, rtol=1e-12, atol=1e-12)
    assert formats.torque_source(commanded.notes) == formats.COMMANDED_MOMENT
    _rtde_log(tmp_path / "none.csv", puma, ())
    with pytest.raises(measured.MeasuredDataError, match="no joint torque: expected actual_current_as_torque_0..5"):
        formats.make("ur-rtde").read(tmp_path / "none.csv", puma)


def test_current_as_torque_read_in_blocks_as_whole(tmp_path, puma):
    """The block reader (a log too long to read whole) gives the whole read's torque, block by block."""
    _rtde_log(tmp_path / "ur.csv", puma)
    fmt = formats.make("ur-rtde")
    whole, _, notes = fmt.columns(tmp_path / "ur.csv", puma)
    parts = list(fmt.blocks(tmp_path / "ur.csv", puma, 300))
    assert len(parts) > 2 and all(p[2] == notes for p in parts)
    np.testing.assert_array_equal(np.concatenate([p[0]["tau3"] for p in parts]), whole["tau3"])


def test_the_import_states_the_current_as_torque(tmp_path, puma):
    """`logs import --format ur-rtde` of such a log says its torque source."""
    (tmp_path / "UR" / "cell1").mkdir(parents=True)
    _rtde_log(tmp_path / "UR" / "cell1" / "2026-03-01.csv", puma)
    result = CliRunner().invoke(app, ["logs", "import", str(tmp_path / "UR"), "--robot", "puma560", "--format",
                                      "ur-rtde", "-o", str(tmp_path / "ur.h5"), "--no-progress"])
    assert result.exit_code == 0, result.output
    assert f"torque:        {formats.CURRENT_AS_TORQUE}" in result.output


def test_measured_is_the_registry_default_entry(tmp_path, puma):
    """The registry's first entry is the measured format; ``make`` gives it as every command's
    default (:data:`formats.MEASURED`), and it reads a measured log as the measured reader does."""
    assert list(formats.FORMATS)[:3] == [formats.DEFAULT, "ur-rtde", "voraus"] and formats.DEFAULT == "measured"
    assert formats.make("measured") == formats.MEASURED and formats.MEASURED.key == "measured"
    t, q, qd, tau, _ = fleetlog_folder.log_signals(puma, 3, 0, np.zeros(6))
    path = logfiles.write_csv(tmp_path / "m.csv", t, q, tau, qd)
    np.testing.assert_array_equal(formats.MEASURED.read(path, puma).tau, measured.read(path, puma).tau)
    with pytest.raises(ValueError, match=r"unknown log format 'x'; expected measured \(the default\) or one of ur-"):
        formats.make("x")


def _none_branches(tree: ast.AST) -> list[int]:
    """Lines comparing a log format's name (``adapter``, ``log_format``, ``fmt``) with None, or
    defaulting it to None."""
    names = {"adapter", "log_format", "fmt"}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare) and isinstance(node.left, ast.Name) and node.left.id in names and any(
                isinstance(c, ast.Constant) and c.value is None for c in node.comparators):
            found.append(node.lineno)
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            args = node.args.args + node.args.kwonlyargs
            defaults = [None] * (len(node.args.args) - len(node.args.defaults)) + list(node.args.defaults) \
                + list(node.args.kw_defaults)
            found += [node.lineno for a, d in zip(args, defaults)
                      if a.arg in names and isinstance(d, ast.Constant) and d.value is None]
    return found


def test_no_branch_reads_a_missing_format_as_measured():
    """No module of faultgen compares a log format with None or defaults one to None: the format is
    looked up in the registry (``measured`` its default entry). The check finds such a branch."""
    assert _none_branches(ast.parse("def f(adapter=None):\n    return 1 if adapter is None else 2\n")) == [1, 2]
    found = {str(path.relative_to(ROOT)): lines for path in sorted((ROOT / "faultgen").rglob("*.py"))
             if (lines := _none_branches(ast.parse(path.read_text())))}
    assert found == {}
