"""The static friction model's per-step update compiled (faultgen.simulation.friction_kernel,
issue 87): ``friction_update.writer`` writes the bits of ``friction_update.apply`` on random
states (both signs, exact zeros of both signs, tiny and huge speeds, NaN), one and two Coulomb
levels, one level for the chunk and one per step, several runs, with and without transmitted-load
terms, compiled and through its NumPy fallback (compiled on a machine whose NumPy runs its own AVX-512
exp and pow, where the compiled update is not used: to within 4 ulp); when the compiled update is used; the boundary
checks. Whole runs (static-load terms, grips, the stepping loop) against the plain loop:
tests/test_backends.py, tests/test_friction_update.py, tests/test_sim_hot_paths.py."""

import numpy as np
import pytest

from faultgen.simulation import batch, friction_kernel, friction_update

NSIM, N, NSTEP, NV = 3, 6, 5, 14
#: Where NumPy dispatches exp and pow to its own AVX-512 code, the kernel's C-library calls differ from its
#: by rounding: at most this many units in the last place on each loss (a sum of positive terms; measured on
#: an AVX-512 Xeon, NumPy 2.4.6, numba 0.68.1, 2026-11-29: 26 of the values differ, by at most 2).
MAX_ULP = 4


def update(rng, one_coulomb: bool, per_step: bool, terms: int) -> friction_update.FrictionUpdate:
    """A random update of ``NSIM`` runs of ``N`` axes whose rotors are every second dof."""
    cp = rng.uniform(0.1, 2.0, N)
    cn = cp.copy() if one_coulomb else rng.uniform(0.1, 2.0, N)
    level = (rng.uniform(0.5, 2.0, (NSIM, NSTEP, N)) if per_step
             else np.broadcast_to(rng.uniform(0.5, 2.0, (NSIM, 1, N)), (NSIM, NSTEP, N)))
    return friction_update.FrictionUpdate(
        rotor_dof=np.arange(1, 2 * N, 2), rotor_qpos=np.arange(0, 2 * N, 2), arm_qpos=np.arange(1, 2 * N, 2),
        coulomb_pos=cp, coulomb_neg=cn, static_friction=rng.uniform(0.0, 1.0, N),
        stribeck_velocity=rng.choice([-1.0, 1.0], N) * rng.uniform(0.5, 20.0, N),
        stribeck_exponent=np.array([1.0, 2.0, 0.5, 1.3, 1.0, 0.7]), level=level,
        gear_ratio=rng.uniform(50.0, 150.0, N), stiffness=rng.uniform(1e3, 1e5, N),
        load_inner=rng.uniform(0.0, 0.1, (NSIM, terms, N)), load_outer=rng.uniform(0.5, 1.5, (NSIM, terms, N)),
        load_static=np.zeros((terms, N), bool), static_terms=())


def random_state(rng, state: np.ndarray) -> None:
    """Speeds of both signs over 600 decades, exact zeros of both signs, angles of a radian."""
    state[...] = rng.normal(0.0, 1.0, state.shape) * 10.0 ** rng.integers(-300, 300, state.shape)
    state[rng.random(state.shape) < 0.2] = 0.0
    state[rng.random(state.shape) < 0.1] = -0.0
    state[rng.random(state.shape) < 0.5] = rng.normal(0.0, 30.0)


@pytest.mark.parametrize("compiled", [True, False])
@pytest.mark.parametrize("one_coulomb, per_step, terms", [(False, False, 0), (True, True, 0), (False, True, 2),
                                                         (True, False, 1)])
def test_the_writer_writes_apply_bits_on_random_states(compiled, one_coulomb, per_step, terms, monkeypatch):
    monkeypatch.setattr(friction_kernel, "numpy_bits", lambda: compiled)
    rng = np.random.default_rng([one_coulomb, per_step, terms])
    u = update(rng, one_coulomb, per_step, terms)
    state = np.zeros((NSIM, 40))  # a batch's state: qvel and qpos strided views of its rows
    qvel, qpos = state[:, 3:3 + NV], state[:, 20:20 + 2 * N]
    loss = np.full((NSIM, NV), 7.0)
    write = friction_update.writer(u, qvel, qpos, None, loss)
    assert write.compiled == compiled and (write.rest is None) == compiled
    rounded = compiled and not friction_kernel.matches_numpy()  # NumPy's own AVX-512 exp and pow here
    for trial in range(60):
        random_state(rng, state)
        qvel[trial % NSIM, u.rotor_dof[trial % N]] = np.nan if trial % 7 == 3 else qvel[0, 0]
        k = trial % NSTEP
        with np.errstate(over="ignore"):  # |v / v_s| ^ 2 of a huge speed: inf, and no friction from it
            expected = friction_update.apply(u, k, qvel, qpos)
            write(k)
        got = loss[:, u.rotor_dof]
        np.testing.assert_array_equal(np.isnan(got), np.isnan(expected))
        finite = ~np.isnan(expected)
        if rounded:
            # NumPy's own SIMD exp and pow here (an AVX-512 target, not friction_kernel.LIBM_TARGETS): the
            # kernel, which the stepping loop does not use on such a machine, gives its values to rounding
            np.testing.assert_array_max_ulp(got[finite], expected[finite], maxulp=MAX_ULP)
            continue
        assert got[finite].tobytes() == expected[finite].tobytes(), (trial, got - expected)
    others = np.setdiff1d(np.arange(NV), u.rotor_dof)
    assert np.all(loss[:, others] == 7.0)  # only the rotors' columns written


def test_the_same_state_gives_the_same_bits_run_after_run():
    rng = np.random.default_rng(3)
    u = update(rng, False, True, 2)
    qvel, qpos = rng.normal(0.0, 5.0, (NSIM, NV)), rng.normal(0.0, 1.0, (NSIM, 2 * N))
    first, second = np.zeros((NSIM, NV)), np.zeros((NSIM, NV))
    friction_update.writer(u, qvel, qpos, None, first)(4)
    friction_update.writer(u, qvel.copy(), qpos.copy(), None, second)(4)
    assert first.tobytes() == second.tobytes() and np.count_nonzero(first) == NSIM * N


def test_the_compiled_update_is_used_only_where_numpy_calls_the_c_library():
    """NumPy's float64 exp and power on their scalar loops (x86-64 AVX2): compiled; on its
    AVX-512 code, another machine, with SVML in numba, or an unknown NumPy: not."""
    libm = {"exp": {"dd": {"current": "X86_V3"}}, "power": {"ddd": {"current": "baseline(X86_V2)"}}}
    assert friction_kernel.matches_numpy(libm, "x86_64", False)
    avx512 = {"exp": {"dd": {"current": "X86_V4"}}, "power": {"ddd": {"current": "baseline(X86_V2)"}}}
    assert not friction_kernel.matches_numpy(avx512, "x86_64", False)
    assert not friction_kernel.matches_numpy(libm, "aarch64", False)
    assert not friction_kernel.matches_numpy(libm, "x86_64", True)
    assert not friction_kernel.matches_numpy({"exp": {}}, "x86_64", False)
    assert friction_kernel.numpy_bits() == friction_kernel.matches_numpy()


def test_state_arrays_of_other_runs_or_columns_are_refused():
    u = update(np.random.default_rng(0), False, False, 0)
    with pytest.raises(ValueError, match=r"qvel has shape \(2, 14\); expected \(3, > 11\) for the update's 3 runs"):
        friction_update.writer(u, np.zeros((2, NV)), np.zeros((NSIM, 2 * N)), None, np.zeros((NSIM, NV)))
    with pytest.raises(ValueError, match=r"frictionloss has shape \(3, 8\)"):
        friction_update.writer(u, np.zeros((NSIM, NV)), np.zeros((NSIM, 2 * N)), None, np.zeros((NSIM, 8)))


def test_set_points_or_disturbances_short_of_the_steps_are_refused():
    drive = np.zeros((N, 3), np.int64)
    batch._check_inputs(np.zeros((11, N, 3)), np.zeros((2, 3, N)), drive, (2, 3, N), 11)
    with pytest.raises(ValueError, match=r"need \(11, 6, 3\) set-points .* got \(10, 6, 3\)"):
        batch._check_inputs(np.zeros((10, N, 3)), np.zeros((2, 3, N)), drive, (2, 3, N), 11)
    with pytest.raises(ValueError, match=r"\(2, 3, 6\) disturbances .* got \(11, 6, 3\) and \(2, 2, 6\)"):
        batch._check_inputs(np.zeros((11, N, 3)), np.zeros((2, 2, N)), drive, (2, 3, N), 11)
