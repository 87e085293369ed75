"""``faultgen calibrate`` on a robot added from a URDF, against a log the project did not simulate:
the KR210 L150 of rtb-data added as a user would (``faultgen robots add``), its torque log made by
Pinocchio's recursive Newton-Euler on the same URDF with a hidden payload at the flange
(tests/pinocchio_log.py). Independent: the rigid-body dynamics and the payload (Pinocchio's). Ours:
the drivetrain terms added to the log (reflected motor inertia, nominal motor-side friction) and the
motion. The long version, with the payload-free floor, is ``benchmarks/calibration_pinocchio.py``
(docs/calibration.md, "A robot added from a URDF, against Pinocchio").
"""

import json

import pinocchio_log
import pytest

from faultgen.calibrate import calibrate


@pytest.fixture(scope="module")
def kr210(tmp_path_factory):
    return pinocchio_log.add_kr210(tmp_path_factory.mktemp("pinocchio") / "kr210")


def test_payload_hidden_in_a_pinocchio_log_is_named_and_the_gap_halved(kr210, tmp_path):
    hidden = pinocchio_log.HiddenPayload(mass=90.0)
    # one pick-and-place cycle, 7.24 s at 250 Hz
    log = pinocchio_log.write_log(kr210, tmp_path / "log.csv", cycles=1, payload=hidden, seed=3)
    calibrate(str(kr210), log, tmp_path / "calib", max_steps=2)
    report = json.loads((tmp_path / "calib" / "report.json").read_text())
    steps = report["steps"]
    assert steps and steps[0]["effect"] == "payload", [s["effect"] for s in steps]
    before, after = report["gap_before"]["total_nrmse"], report["gap_after"]["total_nrmse"]
    assert after <= 0.5 * before, (before, after)
    fitted = steps[0]["params"]["robot"]
    assert abs(fitted["mass"] / hidden.mass - 1) < 0.05, fitted["mass"]
    assert abs(fitted["com_x"] - hidden.com[0]) < 0.01, fitted["com_x"]
