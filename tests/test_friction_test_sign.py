"""A friction test whose torque channel has the wrong sign reads a negative dry friction: named
as a likely sign or side error, by ``faultgen friction-test`` and in the monitor's tests.csv
(issue 86, item 8: it read a negative level with exit 0 and no note)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pandas as pd
from typer.testing import CliRunner

sys.path.insert(0, str(Path(__file__).parent))
import friction_test_log

from faultgen.cli import app
from faultgen.monitor import friction_tests


def test_friction_test_names_a_negated_torque_channel(tmp_path):
    log = friction_test_log.write_log(tmp_path / "test.csv", 20.0, axes=[1])  # axis 2 only: the independent simulator
    frame = pd.read_csv(log)
    frame["tau2"] = -frame["tau2"]
    frame.to_csv(log, index=False)
    result = CliRunner().invoke(app, ["friction-test", str(log), "--robot", "irb6700", "-o", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    notes = [line for line in result.output.splitlines() if line.startswith("note: axis 2: dry friction read negative")]
    assert len(notes) == 1, result.output
    assert "likely sign error (tau2 or q2 negated" in notes[0] and "side error" in notes[0], notes[0]
    level = float(notes[0].split("negative (")[1].split(" N m")[0])
    dry = friction_test_log.truth(20.0)[0][1]  # the simulator's dry level of axis 2 at 20 degC
    assert math.isclose(level, -dry, rel_tol=0.15), (level, dry)  # the level read is the true one, negated


def _fit(axis: int, coulomb: float) -> dict:
    fit = dict.fromkeys(friction_tests.FIT_COLUMNS, math.nan)
    fit.update(axis=axis, coulomb_Nm=coulomb, coulomb_Nm_low=coulomb - 1.0, coulomb_Nm_high=coulomb + 1.0,
               temperature_degC=20.0)
    return fit


def test_the_monitors_tests_csv_names_a_negative_dry_level_as_a_sign_or_side_error():
    tests = [friction_tests.FrictionTest("2026-01-01", 1.0, "a" * 64, (_fit(1, 100.0), _fit(2, -120.0))),
             friction_tests.FrictionTest("2026-01-09", 9.0, "b" * 64, (_fit(1, 101.0), _fit(2, -118.0)))]
    rows, _ = friction_tests.tests_wear(tests, 2)
    axis2 = [r for r in rows if r.axis == 2]
    assert len(axis2) == 2 and all(math.isnan(r.wear) for r in axis2)
    for r in axis2:
        assert r.verdict.startswith("dry level read negative (-1") and "likely sign error (tau2 or q2" in r.verdict
        assert "side error" in r.verdict and r.verdict.endswith("no wear")
    assert [round(r.wear, 3) for r in rows if r.axis == 1] == [0.0, 1.0]  # the other axis read as before
