"""The static friction model's per-step update as arrays (faultgen.simulation.friction_update):
the same numbers, bit for bit, as the Python closure it replaced (``Stribeck.before_step`` of
4bca61f, kept below as the reference), handed to ``rollout`` a chunk at a time on a backend that
applies it, and a plug-in's extra friction that is not in the arrays still added from Python."""

import numpy as np
import pytest
import stepped_robot
from test_backends import short_work
from tqdm.auto import tqdm

from faultgen.effects.base import Effect
from faultgen.effects.load_dependent_friction import LoadDependentFriction
from faultgen.simulation import backends, batch, friction_models, friction_update


@pytest.fixture(scope="module")
def stepped(tmp_path_factory):
    """The path of tests/stepped_robot.py's robot (a drift in time, load-dependent friction in
    both forms)."""
    return str(stepped_robot.write(tmp_path_factory.mktemp("stepped")))


#: A gear loss per run (a growing load-dependent fault beside the unit's), (2, N).
GEAR_LOSS = np.array([np.linspace(0.01, 0.05, 6), np.linspace(0.08, 0.02, 6)])


class _PerSimulation:  # 4bca61f's, for the reference closure
    def __init__(self, unit, coefficient):
        self.unit, self.coefficient = unit, coefficient

    def dry_friction_extra(self, robot, deflection, static_load):
        return self.coefficient * self.unit.dry_friction_extra(robot, deflection, static_load)


def old_before_step(sim, work, runs):
    """``Stribeck.before_step`` of 4bca61f, verbatim but for the names it imports."""
    robot, dt = sim.robot, sim.model.opt.timestep
    dry, n_steps = work.plant.dry, len(work.inputs) - 1
    frictionloss, qvel, qpos = runs.expand("dof_frictionloss"), runs.bind("qvel"), runs.bind("qpos")
    rotor, G = robot.rotor_dof, robot.gear_ratio
    run_start = (work.cycles[:, None] - 1) * n_steps * dt
    stepped = friction_models.stepped_effects(robot)
    factors = [e for e in stepped if type(e).dry_friction_factor is not Effect.dry_friction_factor]
    extras = [e for e in stepped if type(e).dry_friction_extra is not Effect.dry_friction_extra]
    gear_loss = work.plant.gear_loss
    if np.any(gear_loss):
        extras.append(LoadDependentFriction(coefficient=gear_loss) if np.ndim(gear_loss) == 1 else
                      _PerSimulation(LoadDependentFriction(coefficient=np.ones(robot.n_axes)), gear_loss))
    if extras:
        kinematics = [runs.bind(name) for name in ("subtree_com", "xanchor", "xaxis")]
        runs.forward()

        def static_load():
            return robot.static_load_of(*kinematics, qpos)

    def set_level(step):
        level = dry
        for effect in factors:
            level = level * effect.dry_friction_factor(run_start + step * dt)
        frictionloss[:, rotor] = robot.friction.stribeck_level(qvel[:, rotor], level)
        if extras:
            deflection = qpos[:, robot.rotor_qpos] / G - qpos[:, robot.arm_qpos]
            for effect in extras:
                frictionloss[:, rotor] += effect.dry_friction_extra(robot, deflection, static_load)

    return set_level


class OldSchedule:
    """The reference closure in the place of a :class:`friction_update.Schedule` (stepped one step
    at a time by the stepping loop: not in arrays)."""

    in_arrays, reads_start_state = False, False

    def __init__(self, sim, work):
        self.sim, self.work, self.set_level = sim, work, None

    def chunk(self, start, stop):
        return start

    def setter(self, runs, start):
        if self.set_level is None:
            self.set_level = old_before_step(self.sim, self.work, runs)
        return lambda k: self.set_level(start + k)


def run(robot, backend, gear_loss=GEAR_LOSS):
    sim, work = short_work(robot, "stribeck", backend, gear_loss=gear_loss)
    with tqdm(disable=True) as bar:
        return batch.step(sim, work, bar)


def assert_identical(a, b):
    for name in vars(a):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


@pytest.mark.parametrize("backend", ["loop", "batch"])
def test_the_update_steps_as_the_old_closure_bit_for_bit(stepped, backend, monkeypatch):
    """A drift in time, a transmitted- and a static-load term, a gear loss per run, two plants, a
    grip mid-run: the update (inside ``rollout`` on ``loop``, from Python on ``batch``) gives the
    true signals of the old closure stepped one step at a time, bit for bit."""
    new = run(stepped, backend)
    with monkeypatch.context() as patch:
        patch.setattr(friction_models.Stribeck, "schedule", lambda self, sim, work: OldSchedule(sim, work))
        old = run(stepped, "batch")
    assert_identical(new, old)
    assert not np.allclose(new.tau_f[0], new.tau_f[1])


def test_apply_is_the_effects_formula_bit_for_bit(stepped):
    """:func:`friction_update.apply` against the stepped effects' own methods at a random state
    with the start's kinematics, at three steps of a chunk and for one run taken apart."""
    sim, work = short_work(stepped, "stribeck", "batch", gear_loss=GEAR_LOSS)
    runs = batch.new_runs(sim, work)
    rng = np.random.default_rng(3)
    qvel = runs.bind("qvel")
    qvel[...] = rng.normal(0.0, 30.0, qvel.shape)
    qvel[0, sim.robot.rotor_dof[4]] = 0.0  # at rest: the larger Coulomb level
    runs.forward()
    schedule = sim.stepping.schedule(sim, work)
    assert schedule.in_arrays and schedule.base.load_static.shape == (2, 6)
    update = schedule.chunk(10, 30)
    set_level = old_before_step(sim, work, runs)
    kinematics = tuple(runs.bind(name) for name in friction_update.KINEMATICS)
    for k in (0, 7, 19):
        set_level(10 + k)
        expected = runs.expand("dof_frictionloss")[:, sim.robot.rotor_dof].copy()
        got = friction_update.apply(update, k, runs.bind("qvel"), runs.bind("qpos"), kinematics)
        np.testing.assert_array_equal(got, expected)
        one = friction_update.apply(update.take([1]), k, qvel[1:], runs.bind("qpos")[1:],
                                    tuple(x[1:] for x in kinematics))
        np.testing.assert_array_equal(one, expected[1:])
    assert update.level.shape == (2, 20, 6) and update.reads_kinematics


def test_a_static_friction_run_is_handed_to_rollout_a_chunk_at_a_time(stepped, monkeypatch):
    """On a backend that applies the update (``loop``), the stepping loop never steps one step at
    a time: every chunk is one ``rollout`` call carrying its :class:`FrictionUpdate`."""
    calls = []
    rollout = backends.LoopRuns.rollout

    def spy(self, nstep, control, control_spec, record, out, update=None):
        calls.append((nstep, update))
        return rollout(self, nstep, control, control_spec, record, out, update=update)

    monkeypatch.setattr(backends.LoopRuns, "rollout", spy)
    monkeypatch.setattr(backends.LoopRuns, "step", lambda self: pytest.fail("stepped from Python"))
    run(stepped, "loop")
    assert len(calls) == 2  # the chunk breaks at the grip
    assert all(isinstance(u, friction_update.FrictionUpdate) and u.nstep == n for n, u in calls)


def test_a_plug_in_extra_not_in_arrays_is_added_from_python(stepped, monkeypatch):
    """A stepped effect that does not export its extra friction as arrays keeps the per-step
    Python path (on every backend), with the same numbers."""
    arrays = run(stepped, "loop", gear_loss=0.0)
    monkeypatch.setattr(LoadDependentFriction, "dry_friction_load_terms", lambda self: None)
    sim, work = short_work(stepped, "stribeck", "loop", gear_loss=0.0)
    schedule = sim.stepping.schedule(sim, work)
    assert not schedule.in_arrays and [e.id for e in schedule.python_extras] == ["load_dependent_friction"]
    monkeypatch.setattr(backends.LoopRuns, "rollout", lambda *a, **k: pytest.fail("handed to rollout"))
    assert_identical(run(stepped, "loop", gear_loss=0.0), arrays)


def test_a_lugre_run_has_no_update():
    sim, work = short_work("puma560", "lugre", "loop")
    assert sim.stepping.schedule(sim, work) is None
