"""The flexible-gearbox correction against the closed-form response of a spring-mass-damper."""

import numpy as np
import pytest

from faultgen import effects
from faultgen.calibrate import gearbox
from faultgen.model import robots


class OneSpring:
    """Duck-typed robot: six identical axes with constant arm inertia M, stiffness K, damping D."""

    def __init__(self, inertia, stiffness, damping, backlash=0.0):
        self.gearbox_stiffness = np.full(6, stiffness)
        self.gearbox_damping = np.full(6, damping)
        self.effects = {"backlash": effects.make("backlash", width=backlash)}
        self._inertia = inertia

    def arm_mass_matrix(self, q):
        return np.tile(self._inertia * np.eye(6), (len(q), 1, 1))


@pytest.mark.parametrize("hz", [2.0, 12.0, 30.0])
def test_sinusoidal_load_gives_the_steady_state_of_the_oscillator(hz):
    M, K, D = 2.0, 2.0e4, 8.0  # resonance 15.9 Hz, damping ratio 0.02
    robot = OneSpring(M, K, D)
    t = np.arange(0, 20.0, 0.004)
    w = 2 * np.pi * hz
    load = np.outer(np.sin(w * t), np.ones(6)) * 50.0
    out = gearbox.compliance_torque(robot, t, np.zeros_like(load), load)
    # e = L / (K - M w^2 + i D w); drive torque change (K + i D w) e - L = L M w^2 / (K - M w^2 + i D w)
    response = 50.0 * M * w**2 / (K - M * w**2 + 1j * D * w)
    expected = np.imag(response * np.exp(1j * w * t))
    late = t > 15.0  # the start transient has decayed (time constant 2M/D = 0.5 s)
    error = out[late, 0] - expected[late]
    assert np.sqrt(np.mean(error**2)) <= 0.02 * np.sqrt(np.mean(expected[late] ** 2)) + 1e-9


def test_slow_load_is_carried_quasi_statically():
    """Far below the resonance (15.9 Hz) the arm follows the load through the spring, e = load / K,
    and the drive torque changes by -M e''."""
    M, K, D = 1.0, 1.0e4, 20.0
    t = np.arange(0, 5.0, 0.004)
    w = 2 * np.pi * 0.2
    load = np.outer(30.0 * np.sin(w * t), np.ones(6))
    out = gearbox.compliance_torque(OneSpring(M, K, D), t, np.zeros_like(load), load)
    expected = M * w**2 * load[:, 0] / K  # -M e'' with e = load / K, about 5e-3 N m
    late = t > 1.0  # after the start (0.1 s damping time constant)
    np.testing.assert_allclose(out[late, 0], expected[late], atol=0.05 * np.max(np.abs(expected)))


def test_stiff_gearbox_without_dead_band_is_rigid():
    """A resonance above :data:`gearbox.RESOLVED_HZ` (50 Hz here) is not integrated: without a dead
    band the drive torque is the rigid prediction."""
    robot = OneSpring(1.0, 1.0e5, 20.0)
    t = np.arange(0, 5.0, 0.004)
    load = np.outer(30.0 * np.sin(2 * np.pi * 3.0 * t), np.ones(6))
    assert not np.any(gearbox.dynamic_axes(robot, t, np.zeros_like(load)))
    assert not np.any(gearbox.compliance_torque(robot, t, np.zeros_like(load), load))


def dead_band_reference(M, K, D, b, t, load):
    """The dead-band oscillator M e'' + D e' + S(e) = load(t) by scipy's LSODA, dense output;
    returns the drive torque change S(e) + D e' - load = -M e''."""
    from scipy.integrate import solve_ivp

    def spring(e):
        return K * np.sign(e) * max(abs(e) - b / 2, 0.0)

    def rhs(time, state):
        e, v = state
        return [v, (np.interp(time, t, load) - D * v - spring(e)) / M]

    start = [load[0] / K + np.sign(load[0]) * b / 2, 0.0]
    solution = solve_ivp(rhs, (t[0], t[-1]), start, t_eval=t, method="LSODA", max_step=2e-4, rtol=1e-8,
                         atol=1e-12)
    e, v = solution.y
    return np.array([spring(x) for x in e]) + D * v - load


@pytest.mark.parametrize("hz", [1.0, 4.0])
def test_dead_band_against_an_ode_solver(hz):
    """A load that reverses: the arm crosses the dead band twice a period and lands on the other
    flank; the Newmark steps with the piecewise-linear spring against LSODA."""
    M, K, D, b = 50.0, 3.2e5, 800.0, 0.01  # resonance 12.7 Hz, damping ratio 0.1 (the IRB-6700-like axes 1-3)
    t = np.arange(0, 3.0, 0.004)
    load = 400.0 * np.sin(2 * np.pi * hz * t) + 100.0 * np.sin(2 * np.pi * 2.3 * hz * t)
    expected = dead_band_reference(M, K, D, b, t, load)
    out = gearbox.compliance_torque(OneSpring(M, K, D, b), t, np.zeros((len(t), 6)), np.outer(load, np.ones(6)))
    assert np.max(np.abs(expected)) > 50.0  # the crossings ring
    linear = gearbox.compliance_torque(OneSpring(M, K, D), t, np.zeros((len(t), 6)), np.outer(load, np.ones(6)))
    assert np.sqrt(np.mean((expected - linear[:, 0]) ** 2)) > 0.3 * np.sqrt(np.mean(expected**2))
    error = out[:, 0] - expected
    # 2 ms sub-steps: 0.7 % (1 Hz) and 0.4 % (4 Hz) of the RMS, from the impact timing (at a
    # resonance of 32 Hz, which the equation no longer integrates, it was 4.2 % and 2.6 %)
    assert np.sqrt(np.mean(error**2)) <= 0.02 * np.sqrt(np.mean(expected**2))


def test_dead_band_does_not_show_while_the_load_keeps_its_sign():
    """Resting on one flank, the gearbox is the linear spring moved by b/2: same torque."""
    M, K, D = 2.0, 2.0e4, 8.0
    t = np.arange(0, 5.0, 0.004)
    load = np.outer(30.0 + 20.0 * np.sin(2 * np.pi * 3.0 * t), np.ones(6))
    q = np.zeros_like(load)
    linear = gearbox.compliance_torque(OneSpring(M, K, D), t, q, load)
    batch = gearbox.compliance_torque(OneSpring(M, K, D), t, q, load, backlash=np.array([[0.0] * 6, [0.02] * 6]))
    assert batch.shape == (2,) + load.shape
    np.testing.assert_allclose(batch[0], linear)
    np.testing.assert_allclose(batch[1], linear, atol=1e-9)


def test_negative_backlash_is_refused():
    t = np.arange(0, 1.0, 0.004)
    load = np.zeros((len(t), 6))
    with pytest.raises(ValueError, match="backlash must be widths >= 0"):
        gearbox.compliance_torque(OneSpring(1.0, 1.0, 0.0), t, load, load, backlash=np.full(6, -0.01))


def test_arm_mass_matrix_against_recursive_newton_euler():
    """Column by column: unit arm acceleration, rotors not accelerating, no gravity."""
    import mujoco

    robot = robots.load("puma560")
    q = np.tile(robot.home, (2, 1))
    q[1, 2] += 0.5
    matrix = robot.arm_mass_matrix(q)
    model = robot.model.__copy__()
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER  # mj_inverse of qacc, not of a step map
    model.opt.gravity[:] = 0
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT  # at rest, springs are relaxed
    data = mujoco.MjData(model)
    for k in range(2):
        for axis in range(6):
            data.qpos[:], data.qvel[:] = robot.rigid_state(q[k])
            data.qvel[:] = 0
            data.qacc[:] = 0
            data.qacc[robot.arm_dof[axis]] = 1.0
            mujoco.mj_inverse(model, data)
            np.testing.assert_allclose(matrix[k, :, axis], data.qfrc_inverse[robot.arm_dof], rtol=1e-9,
                                       atol=1e-9 * np.max(np.abs(matrix[k])))
    np.testing.assert_allclose(matrix, np.swapaxes(matrix, 1, 2))


def contact_reference(M, D, b, t, load):
    """The stiff dead band by events: inside the gap ``M e'' + D e' = load`` by scipy's RK45 until
    ``|e| = b/2`` (then at rest on that flank), on a flank until the load changes sign."""
    from scipy.integrate import solve_ivp

    def force(time):
        return np.interp(time, t, load)

    def crossed(time, state):
        return abs(state[0]) - b / 2
    crossed.terminal, crossed.direction = True, 1

    now, e, v, side = t[0], np.sign(load[0]) * b / 2, 0.0, np.sign(load[0])
    times, values = [now], [e]
    while now < t[-1]:
        if side:  # on a flank: until the load reverses (linear between samples)
            later = np.flatnonzero((t > now) & (load * side < 0))
            if not len(later):
                break
            k = later[0]
            now = t[k - 1] + (t[k] - t[k - 1]) * load[k - 1] / (load[k - 1] - load[k])
            side = 0.0
            times.append(now), values.append(e)
            continue
        solution = solve_ivp(lambda time, y: [y[1], (force(time) - D * y[1]) / M], (now, t[-1]), [e, v],
                             events=crossed, max_step=1e-3, rtol=1e-9, atol=1e-12, dense_output=True)
        inside = np.linspace(now, solution.t[-1], max(2, int((solution.t[-1] - now) / 1e-4)))
        times.extend(inside), values.extend(solution.sol(inside)[0])
        now = solution.t[-1]
        e, v = np.sign(solution.y[0, -1]) * b / 2, 0.0
        side = np.sign(e)
        times.append(now), values.append(e)
    times.append(t[-1]), values.append(e)
    return np.interp(t, np.array(times), np.array(values))


def test_stiff_dead_band_against_an_event_solver():
    """Rigid contact: the arm crosses the dead band whenever the load reverses (damper only) and
    lands on the other flank at rest; against an event-located ODE solution."""
    M, D, b = 3.0, 57.0, 0.015  # the PUMA 560's waist: arm inertia, gearbox damping, a 15 mrad dead band
    t = np.arange(0, 6.0, 0.004)
    load = 20.0 * np.sin(2 * np.pi * 0.5 * t) + 8.0 * np.sin(2 * np.pi * 1.3 * t)
    expected = contact_reference(M, D, b, t, load)
    e = gearbox.contact_deflection(t, np.full((len(t), 2), M), np.full(2, D), np.array([b, 0.0]),
                                   np.column_stack([load, load]))
    assert np.ptp(expected) == pytest.approx(b)  # it crosses
    assert 0.1 < np.mean(np.abs(expected) < b / 2) < 0.9
    assert np.sqrt(np.mean((e[:, 0] - expected) ** 2)) <= 0.02 * b
    assert not np.any(e[:, 1])  # no dead band: the arm stays with the motor
