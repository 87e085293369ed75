"""The stepping backends against each other, and the signal set defined once.

The plain backend (a Python loop of ``mujoco.mj_step`` over one ``MjData`` and ``MjModel`` copy per
run) is the reference every other registered backend is held to: on every built-in robot and
both friction models, a short stretch of a task with every per-run model field the simulation
writes (dry and viscous friction, link masses, a unit's gear loss, a gripped mass mid-run) gives
the same true signals to float tolerance; and with the static friction model on a robot carrying
both kinds of stepped effect (a drift in time, load-dependent friction in both forms) and a gear
loss per run, where the per-step friction update is handed to ``rollout`` as arrays
(tests/backend_kernel.py's backend applies it with its own kernel; ``batch`` steps it from Python).
"""

import dataclasses

import backend_kernel  # noqa: F401  (registers the test-only backend "kernel": held to loop below)
import numpy as np
import pytest
import stepped_robot
from tqdm.auto import tqdm

from faultgen.data import dataset
from faultgen.effects import friction
from faultgen.model import robots
from faultgen.operation.wear import WearPlan
from faultgen.simulation import backends, batch, friction_models, prepare, results, signals
from faultgen.simulation import stepping as sim
from resolved_runs import run_config

PERIODS = 12  # log periods stepped (48 ms): a few seconds for the whole file


def short_work(name, model_name, backend, gear_loss=0.01):
    """Two runs of the first ``PERIODS`` log periods of pick_place, each with its own plant (a gear
    loss of ``gear_loss``, (N,) or per run (2, N))."""
    prepared = prepare.prepared_for(robots.load(name), "pick_place", model_name)
    model, robot, per_log = prepared.sim.model, prepared.sim.robot, prepared.per_log
    n_steps = PERIODS * per_log
    n = robot.n_axes
    plant = batch.Plant(dry=np.array([np.full(n, 1.0), np.linspace(1.2, 2.0, n)]),
                        viscous=np.array([np.ones(n), np.full(n, 1.3)]),
                        link_mass=np.linspace(0.95, 1.1, n), gear_loss=np.broadcast_to(gear_loss, (n,)).copy()
                        if np.ndim(gear_loss) < 2 else gear_loss)
    dist = np.random.default_rng(5).normal(0.0, 2.0, (2, PERIODS, n))
    # a part gripped half way: the last link's mass and inertia grow (the chunk breaks there)
    body = model.jnt_bodyid[model.joint(robot.joint_names[-1]).id]
    grip = (body, 1.5 * model.body_mass[body], 1.5 * model.body_inertia[body], model.body_ipos[body].copy(),
            model.body_iquat[body].copy())
    return prepared.sim, batch.Work(np.array([1, 7]), plant, prepared.path.q[0], prepared.inputs[: n_steps + 1],
                                    dist, per_log, 1, grips=((PERIODS // 2 * per_log, grip),),
                                    qd0=prepared.path.qd[0], qdd0=prepared.path.qdd[0], stepper=backends.get(backend))


def step(name, model_name, backend, **plant):
    model, work = short_work(name, model_name, backend, **plant)
    with tqdm(disable=True) as bar:
        return model, batch.step(model, work, bar)


def assert_as_loop(model, ours, plain):
    for signal in signals.TRUE_SIGNALS:
        a, b = getattr(ours, signal), getattr(plain, signal)
        assert a.shape == (2, PERIODS, model.robot.n_axes)
        assert np.all(np.isfinite(a))
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9 * np.max(np.abs(b)), err_msg=signal)
    # not a trivial agreement: the robot moves and the two runs' plants differ
    assert np.ptp(ours.q_m[0], axis=0).max() > 1e-3
    assert not np.allclose(ours.tau_f[0], ours.tau_f[1])


@pytest.mark.parametrize("name", sorted(robots.available()))
@pytest.mark.parametrize("model_name", friction.MODELS)
@pytest.mark.parametrize("backend", [b for b in backends.STEPPERS if b != "loop"])
def test_backend_steps_as_the_plain_loop(name, model_name, backend):
    model, plain = step(name, model_name, "loop")
    _, ours = step(name, model_name, backend)
    assert_as_loop(model, ours, plain)


@pytest.fixture(scope="module")
def stepped(tmp_path_factory):
    """The path of tests/stepped_robot.py's robot."""
    return str(stepped_robot.write(tmp_path_factory.mktemp("stepped")))


@pytest.mark.parametrize("backend", [b for b in backends.STEPPERS if b != "loop"])
def test_backend_steps_the_static_friction_update_as_the_plain_loop(stepped, backend):
    """The per-step update with every kind of term (a drift in time, a transmitted-load and a
    static-load term, a gear loss per run), a grip mid-run: the loop backend and ``kernel`` apply it
    inside ``rollout``, from its arrays; ``batch`` before each step from Python."""
    assert {e.id for e in friction_models.stepped_effects(robots.load(stepped))} == {
        "temperature", "load_dependent_friction"}
    loss = np.array([np.linspace(0.01, 0.05, 6), np.linspace(0.08, 0.02, 6)])
    model, plain = step(stepped, "stribeck", "loop", gear_loss=loss)
    _, ours = step(stepped, "stribeck", backend, gear_loss=loss)
    assert_as_loop(model, ours, plain)
    _, nominal = step("puma560", "stribeck", "loop", gear_loss=loss)
    assert not np.allclose(plain.tau_f, nominal.tau_f)  # the stepped effects act


def test_backends_are_different_steppers():
    model = prepare.prepared_for(robots.load("puma560"), "pick_place", "lugre").sim.model
    assert isinstance(backends.get("loop").new(model, 2, 1), backends.LoopRuns)
    assert not isinstance(backends.get("batch").new(model, 2, 1), backends.LoopRuns)


def test_unknown_backend_is_named():
    config = run_config(robot="puma560", task="pick_place", wear=WearPlan({}), cycles=1, seed=0)
    with pytest.raises(ValueError, match=r"unknown stepping backend 'gpu'; expected one of batch, loop"):
        backends.get("gpu")
    with pytest.raises(ValueError, match=r"'gpu' is not a stepper \(a Stepper object"):
        sim.simulate(config, progress=False, stepper="gpu")


def test_signal_set_is_defined_once():
    assert dataset.ARRAYS is signals.ARRAYS and dataset.SIGNAL_AXES == signals.SIGNAL_AXES
    assert [f.name for f in dataclasses.fields(batch.Raw)] == list(signals.TRUE_SIGNALS)
    assert signals.SIGNALS == (*signals.TRUE_SIGNALS, "tau_dist")
    result_fields = {f.name for f in dataclasses.fields(results.RunResult)}
    assert set(signals.SIGNALS + signals.TRUTHS) <= result_fields
    assert set(signals.TRUTHS) <= set(signals.ARRAYS)
