"""PUMA 560 inverse dynamics against roboticstoolbox-python, an independent implementation.

The toolbox's ``Puma560`` is the published parameter set (Corke & Armstrong-Helouvry 1994); its
``rne`` keeps the reflected motor inertia G^2 Jm and, unless removed, the motor friction
referred through G. Our model differs from it only in the link-3 inertia (made physically
valid, see robots/puma560/README.md) and in the static-friction (Stribeck) term, which the
toolbox does not have and which vanishes away from zero velocity.
"""

import numpy as np
import pytest
import roboticstoolbox as rtb  # test dependency, declared in pyproject.toml [test]

from faultgen.model import robots

N_SAMPLES = 1000


@pytest.fixture(scope="module")
def puma():
    return robots.load("puma560")


@pytest.fixture(scope="module")
def toolbox():
    return rtb.models.DH.Puma560()


@pytest.fixture(scope="module")
def samples(puma):
    rng = np.random.default_rng(560)
    q = rng.uniform(puma.joint_range[:, 0], puma.joint_range[:, 1], (N_SAMPLES, 6))
    qd = rng.uniform(-2.0, 2.0, (N_SAMPLES, 6))
    qdd = rng.uniform(-5.0, 5.0, (N_SAMPLES, 6))
    return q, qd, qdd


def relative_rms_difference(ours, ref):
    return np.sqrt(np.mean((ours - ref) ** 2, axis=0)) / np.sqrt(np.mean(ref**2, axis=0))


def test_rigid_body_dynamics_match_toolbox_without_friction(puma, toolbox, samples):
    q, qd, qdd = samples
    ours = puma.inverse_dynamics(q, qd, qdd, friction=False)
    ref = toolbox.nofriction(coulomb=True, viscous=True).rne(q, qd, qdd)
    rel = relative_rms_difference(ours, ref)
    print("per-axis relative RMS difference, no friction:", np.array2string(rel, precision=6))
    assert np.all(rel[:3] <= 0.01), rel
    assert np.all(rel[3:] <= 0.03), rel


def test_link3_inertia_fix_is_the_only_difference(puma, toolbox, samples):
    """With our link-3 inertia put into the toolbox, the two agree to round-off."""
    fixed = toolbox.nofriction(coulomb=True, viscous=True)
    fixed.links[2].I = np.diag([0.0685, 0.0835, 0.015])
    q, qd, qdd = samples
    ours = puma.inverse_dynamics(q, qd, qdd, friction=False)
    ref = fixed.rne(q, qd, qdd)
    np.testing.assert_allclose(ours, ref, rtol=1e-6, atol=1e-6)


def test_gravity_torque_at_nominal_pose(puma, toolbox):
    zeros = np.zeros((1, 6))
    tau = puma.inverse_dynamics(toolbox.qn[None], zeros, zeros, friction=False)[0]
    assert tau[1] == pytest.approx(31.64, rel=0.005)
    assert tau[2] == pytest.approx(6.04, rel=0.005)


def test_dynamics_with_friction_match_toolbox_away_from_zero_velocity(puma, toolbox, samples):
    q, _, qdd = samples
    rng = np.random.default_rng(561)
    # |qd| >= 0.1 rad/s puts every motor above 6 Stribeck velocities, where exp(-36) ~ 0.
    speed = rng.uniform(0.1, 2.0, (N_SAMPLES, 6)) * rng.choice([-1.0, 1.0], (N_SAMPLES, 6))
    assert np.all(np.abs(speed * puma.gear_ratio) >= 6 * puma.friction.stribeck_velocity)
    ours = puma.inverse_dynamics(q, speed, qdd, friction=True)
    ref = toolbox.rne(q, speed, qdd)
    rel = relative_rms_difference(ours, ref)
    print("per-axis relative RMS difference, with friction:", np.array2string(rel, precision=6))
    assert np.all(rel[:3] <= 0.01), rel
    assert np.all(rel[3:] <= 0.03), rel
    # friction matters here: without it the torques differ by far more than the tolerance
    frictionless = puma.inverse_dynamics(q, speed, qdd, friction=False)
    assert np.all(relative_rms_difference(frictionless, ref)[[0, 1, 2]] > 0.05)


def test_friction_uses_toolbox_conventions(puma, toolbox):
    """Coulomb by sign of joint velocity, viscous through G^2, Coulomb through G."""
    q = np.tile(toolbox.qn, (2, 1))
    qd = np.array([[1.0] * 6, [-1.0] * 6])
    zeros = np.zeros((2, 6))
    friction = puma.inverse_dynamics(q, qd, zeros) - puma.inverse_dynamics(q, qd, zeros, friction=False)
    G = puma.gear_ratio
    expected_pos = G * (puma.friction.coulomb_pos + puma.friction.viscous * G)
    expected_neg = -G * (puma.friction.coulomb_neg + puma.friction.viscous * G)
    np.testing.assert_allclose(friction[0], expected_pos, rtol=1e-12)
    np.testing.assert_allclose(friction[1], expected_neg, rtol=1e-12)
    for k, link in enumerate(toolbox.links):
        assert friction[0, k] == pytest.approx(-link.friction(1.0), rel=1e-12)
        assert friction[1, k] == pytest.approx(-link.friction(-1.0), rel=1e-12)
