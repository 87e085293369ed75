"""``faultgen calibrate`` on a robot added from a URDF, against a log the project did not simulate:
the KR210 L150 of rtb-data added as a user would (``faultgen robots add``), its torque log made by
Pinocchio's recursive Newton-Euler on the same URDF with a hidden payload at the flange
(tests/pinocchio_log.py). Independent: the rigid-body dynamics and the payload (Pinocchio's). Ours:
the drivetrain terms added to the log (reflected motor inertia, nominal motor-side friction) and the
motion. The long version, with the payload-free floor, is ``benchmarks/calibration_pinocchio.py``
(docs/calibration.md, "A robot added from a URDF, against Pinocchio").
"""

import dataclasses
import json

import numpy as np
import pinocchio_log
import pytest

from faultgen.calibrate import calibrate, gearbox
from faultgen.logs import measured
from faultgen.model import robots


@pytest.fixture(scope="module")
def kr210(tmp_path_factory):
    return pinocchio_log.add_kr210(tmp_path_factory.mktemp("pinocchio") / "kr210")


def test_payload_hidden_in_a_pinocchio_log_is_named_and_the_gap_halved(kr210, tmp_path):
    hidden = pinocchio_log.HiddenPayload(mass=90.0)
    # one pick-and-place cycle, 7.24 s at 250 Hz
    log = pinocchio_log.write_log(kr210, tmp_path / "log.csv", cycles=1, payload=hidden, seed=3)
    calibrate(str(kr210), log, tmp_path / "calib", max_steps=2, figure=False)
    report = json.loads((tmp_path / "calib" / "report.json").read_text())
    steps = report["steps"]
    assert steps and steps[0]["effect"] == "payload", [s["effect"] for s in steps]
    before, after = report["gap_before"]["total_nrmse"], report["gap_after"]["total_nrmse"]
    assert after <= 0.5 * before, (before, after)
    fitted = steps[0]["params"]["robot"]
    assert abs(fitted["mass"] / hidden.mass - 1) < 0.05, fitted["mass"]
    assert abs(fitted["com_x"] - hidden.com[0]) < 0.01, fitted["com_x"]


def test_payload_comes_back_exactly_from_exact_derivatives_on_a_rigid_model(kr210, tmp_path, monkeypatch):
    """The same, noise-free, with the log's exact velocities and accelerations (instead of the
    derivative filter's) and every gearbox rigid (Pinocchio's arm is): what is left is the payload
    identification itself against Pinocchio's dynamics, and all ten parameters come back."""
    monkeypatch.setattr(gearbox, "RESOLVED_HZ", 0.0)  # no axis gets the flexible-gearbox equation
    hidden = pinocchio_log.HiddenPayload(mass=120.0)
    t, q, qd, qdd = pinocchio_log.motion(kr210, cycles=1)
    tau = pinocchio_log.arm_torque(kr210, q, qd, qdd, hidden)
    data = dataclasses.replace(measured.from_arrays(t, q, tau, robots.load(kr210), qd=qd), qdd=qdd)
    result = calibrate(str(kr210), data, tmp_path / "calib", max_steps=1, figure=False)
    assert [s.effect.id for s in result.steps] == ["payload"]
    assert result.gap_after["total_nrmse"] < 1e-4 * result.gap_before["total_nrmse"]
    fitted = result.steps[0].record()["params"]["robot"]
    a, b, c = hidden.size
    inertia = hidden.mass / 12 * np.array([b * b + c * c, a * a + c * c, a * a + b * b, 0, 0, 0])
    expected = {"mass": hidden.mass, **dict(zip(("com_x", "com_y", "com_z"), hidden.com)),
                **dict(zip(("ixx", "iyy", "izz", "ixy", "ixz", "iyz"), inertia))}
    for name, value in expected.items():
        assert fitted[name] == pytest.approx(value, rel=1e-4, abs=1e-4), (name, fitted[name], value)
