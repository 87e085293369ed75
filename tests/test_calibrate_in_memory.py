"""Calibration tries its effects on models held in memory and writes the model file once (issue 47,
item 1: "calibration tries effects on in-memory specs").

Before, every trial (an effect added, taken out for backfitting, re-searched on more axes) was
written to a model file and loaded back, and a trial was undone by writing the file again: the
calibration of the log below wrote MJCF text twice (the forward step's trial, then the result), a
log with two effects many more times (the backfitting and extension trials and their undoing).
"""

import numpy as np
import pytest

from faultgen import effects
from faultgen.calibrate import predict
from faultgen.model import robots


def test_one_calibration_writes_the_model_file_once(coulomb_log, coulomb_calibration):
    """The Coulomb log's calibration (conftest.py's ``coulomb_calibration``, which counts the MJCF
    files written during it, whatever their name) writes one model file."""
    result, _, _, writes = coulomb_calibration
    assert [(s.effect.id, s.axes) for s in result.steps] == [("coulomb", [2])]
    assert len(writes) == 1, [str(p) for p in writes]
    # the file written is the model the search judged: loaded back, it predicts what the search kept
    written = robots.load(result.model_out)
    np.testing.assert_array_equal(predict(written, coulomb_log), result.calibrated)
    assert written.friction.coulomb_pos[2] - robots.load("puma560").friction.coulomb_pos[2] == pytest.approx(
        0.07, rel=0.02)


def test_a_trial_compiled_in_memory_is_the_model_its_text_loads(tmp_path):
    from faultgen.calibrate.trial import Model, compiled

    nominal = robots.load("puma560")
    held = Model.nominal(nominal)
    assert held.text == nominal.path.read_text() and held.robot is nominal
    effect = effects.get("coulomb").current(nominal)
    raised = effect.fitted(nominal, {2: {"coulomb_pos": 0.5, "coulomb_neg": 0.4}})
    trial = held.with_effect(raised, [2], tmp_path / "trial.xml")
    assert not (tmp_path / "trial.xml").exists()  # named as the file, not written
    assert trial.robot.name == "trial" and trial.text == trial.xml
    (tmp_path / "trial.xml").write_text(trial.text)
    loaded = robots.load(tmp_path / "trial.xml")
    assert loaded.friction.coulomb_pos[2] == trial.robot.friction.coulomb_pos[2] == 0.5
    for name in ("body_mass", "dof_armature", "tendon_stiffness", "numeric_data", "actuator_ctrlrange"):
        np.testing.assert_array_equal(getattr(loaded.model, name), getattr(trial.robot.model, name))
    again = compiled(trial.spec(), tmp_path / "trial.xml")  # an edit starts from the text kept
    assert again.text == trial.text
