"""The effect library: each effect's fitted torque is what the model it writes computes.

For every effect with a rigid-body torque, ``Phi @ theta + offset`` (what the workflow fits) must
equal the inverse dynamics of the MJCF the effect writes minus that of the nominal model: that is
what makes the written model reproduce the fit. Also: the optional numerics round-trip through
the robot loader, and the simulator builds the passive forces they describe.
"""

from pathlib import Path

import mujoco
import numpy as np
import pytest

from faultgen import calibrate, effects
from faultgen.calibrate import synth
from faultgen.effects import payload
from faultgen.model import robots
from faultgen.simulation import stepping as sim

ROBOTS = ("puma560", "irb6700")


@pytest.fixture(scope="module", params=ROBOTS)
def setup(request):
    robot = robots.load(request.param)
    motion, _ = synth.nominal_motion(robot, "pick_place", 1)
    return robot, motion


# One fitted change (theta, grid value) per effect, on axis 2 (index 1) unless robot-wide, and the
# absolute parameters it gives on the nominal robot (``None``: the nominal value plus theta).
CHANGES = {
    "torque_offset": (np.array([3.5]), None, {"offset": 3.5}),
    "coulomb": (np.array([0.05, 0.02]), None, None),  # both directions, then the positive one more
    "viscous": (np.array([2e-3]), None, None),
    "stribeck": (np.array([0.2]), (7.0, 1.3), {"static": 0.2, "stribeck_velocity": 7.0, "stribeck_exponent": 1.3}),
    "load_dependent_friction": (np.array([0.1]), 1, {"coefficient": 0.1, "gravity_load": 1}),  # the static form
    "temperature": (np.array([0.8]), 3.0, {"amplitude": 0.8, "time_constant": 3.0}),
    # 2 kg, centre of mass (0.02, -0.03, 0.05) m, inertia about it diag(0.01, 0.02, 0.015) kg m^2
    "payload": (payload.barycentric(2.0, [0.02, -0.03, 0.05], [0.01, 0.02, 0.015, 0, 0, 0]), None,
                {"mass": 2.0, "com_x": 0.02, "com_y": -0.03, "com_z": 0.05, "ixx": 0.01, "iyy": 0.02, "izz": 0.015,
                 "ixy": 0.0, "ixz": 0.0, "iyz": 0.0}),
    "cogging": (np.array([-0.05 * np.cos(0.4), -0.05 * np.sin(0.4)]), 6, {"amplitude": 0.05, "poles": 6, "phase": 0.4}),
}


def absolute(robot, effect_id, theta):
    """The absolute parameters of a friction change ``theta`` on axis 2, from the robot's friction."""
    f = robot.friction
    if effect_id == "coulomb":
        return {"coulomb_pos": f.coulomb_pos[1] + theta[0] + theta[1], "coulomb_neg": f.coulomb_neg[1] + theta[0]}
    return {"viscous": f.viscous[1] + theta[0]}


def augmented(robot, effect, axis, params, tmp_path):
    spec = mujoco.MjSpec.from_file(str(robot.path))
    effect.apply(spec, robot, axis, params)
    path = tmp_path / f"{robot.name}_{effect.id}.xml"
    path.write_text(spec.to_xml())
    return robots.load(path)


@pytest.mark.parametrize("effect_id", sorted(CHANGES))
def test_fitted_torque_is_the_written_models_torque(setup, effect_id, tmp_path):
    robot, motion = setup
    effect = effects.get(effect_id)
    axis = None if not effect.per_axis else 1
    theta, h, params = CHANGES[effect_id]
    params = params or absolute(robot, effect_id, theta)
    phi, offset = effect.columns(motion, axis, h)
    fitted = phi @ theta + offset
    assert effect.params(motion, axis, theta, h) == pytest.approx(params)

    new = augmented(robot, effect, axis, params, tmp_path)
    change = (new.inverse_dynamics(motion.q, motion.qd, motion.qdd, t=motion.t)
              - robot.inverse_dynamics(motion.q, motion.qd, motion.qdd, t=motion.t))
    scale = np.max(np.abs(change))
    assert scale > 0.1, "the effect must change the torque"
    # MjSpec.to_xml writes 6 significant digits, so the written gear ratios differ from the
    # nominal ones by up to ~3e-6 relative: that, not the effect, sets the tolerance.
    if effect.per_axis:
        np.testing.assert_allclose(change[:, axis], fitted, atol=3e-3 * scale)
        others = np.delete(change, axis, axis=1)
        assert np.max(np.abs(others)) < 3e-3 * scale
    else:
        np.testing.assert_allclose(change, fitted, atol=3e-3 * scale)


def test_optional_numerics_round_trip_through_the_loader(tmp_path):
    robot = robots.load("puma560")
    spec = mujoco.MjSpec.from_file(str(robot.path))
    effects.get("cogging").apply(spec, robot, 3, {"amplitude": 0.02, "poles": 8, "phase": -1.0})
    effects.get("torque_offset").apply(spec, robot, 0, {"offset": -2.0})
    effects.get("load_dependent_friction").apply(spec, robot, 2, {"coefficient": 0.05})
    effects.get("temperature").apply(spec, robot, 5, {"amplitude": 0.5, "time_constant": 30.0})
    effects.get("backlash").apply(spec, robot, 1, {"width": 0.004})
    effects.make("payload", mass=1.5).write(spec, robot)
    path = tmp_path / "p.xml"
    path.write_text(spec.to_xml())
    new = robots.load(path)
    assert new.effects["cogging"].values(3) == pytest.approx({"amplitude": 0.02, "poles": 8, "phase": -1.0})
    assert new.effects["torque_offset"].offset.tolist() == [-2.0, 0, 0, 0, 0, 0]
    assert new.effects["load_dependent_friction"].coefficient[2] == 0.05
    assert new.effects["temperature"].values(5) == pytest.approx({"amplitude": 0.5, "time_constant": 30.0})
    assert new.effects["temperature"].values(0) == {"amplitude": 0.0, "time_constant": 1.0}
    np.testing.assert_allclose(new.effects["backlash"].width, [0, 0.004, 0, 0, 0, 0])
    assert new.effects["payload"].mass == pytest.approx(1.5)
    # the numerics are named by the effect ids, and parameters.json uses the same names
    assert {"cogging4", "torque_offset1", "load_dependent_friction3", "temperature6"} <= {
        new.model.numeric(k).name for k in range(new.model.nnumeric)}
    table = calibrate.parameters(new)["effects"]
    assert table["temperature"]["time_constant"][5] == 30.0 and table["payload"]["mass"] == pytest.approx(1.5)
    # an offset written again is replaced by the new absolute value
    effects.get("torque_offset").apply(spec, robot, 0, {"offset": 0.5})
    path.write_text(spec.to_xml())
    assert robots.load(path).effects["torque_offset"].offset[0] == 0.5


def test_models_written_before_the_effect_names_were_unified_still_load(tmp_path):
    """``thermal{i}`` and ``load_friction{i}`` were the numerics' first names: still read, and
    replaced by the current name when the effect is written again."""
    robot = robots.load("puma560")
    spec = mujoco.MjSpec.from_file(str(robot.path))
    spec.add_numeric(name="thermal2", data=[0.4, 20.0])
    spec.add_numeric(name="load_friction3", data=[0.07])
    path = tmp_path / "old.xml"
    path.write_text(spec.to_xml())
    old = robots.load(path)
    assert old.effects["temperature"].values(1) == {"amplitude": 0.4, "time_constant": 20.0}
    assert old.effects["load_dependent_friction"].values(2) == {"coefficient": 0.07, "gravity_load": 0}
    effects.get("temperature").apply(spec, old, 1, {"amplitude": 0.1, "time_constant": 5.0})
    assert spec.numeric("thermal2") is None and list(spec.numeric("temperature2").data) == [0.1, 5.0]


def test_bad_optional_numeric_is_refused(tmp_path):
    robot = robots.load("puma560")
    spec = mujoco.MjSpec.from_file(str(robot.path))
    spec.add_numeric(name="temperature2", data=[0.5, 0.0])
    path = tmp_path / "bad.xml"
    path.write_text(spec.to_xml())
    with pytest.raises(robots.ModelError, match="temperature.*time constant > 0"):
        robots.load(path)
    spec = mujoco.MjSpec.from_file(str(robot.path))
    spec.add_numeric(name="cogging1", data=[0.5, 2.0])
    path.write_text(spec.to_xml())
    with pytest.raises(robots.ModelError, match="cogging1.*2 values, expected 3: amplitude poles phase"):
        robots.load(path)
    spec = mujoco.MjSpec.from_file(str(robot.path))
    spec.add_numeric(name="load_dependent_friction3", data=[0.1, 0.5])
    path.write_text(spec.to_xml())
    with pytest.raises(robots.ModelError, match="load_dependent_friction.*gravity_load = 0.5; expected 0 or 1"):
        robots.load(path)


def test_simulator_builds_the_passive_forces(tmp_path):
    robot = robots.load("puma560")
    spec = mujoco.MjSpec.from_file(str(robot.path))
    effects.get("cogging").apply(spec, robot, 1, {"amplitude": 0.03, "poles": 4, "phase": 0.2})
    effects.get("torque_offset").apply(spec, robot, 4, {"offset": 1.5})
    path = tmp_path / "p.xml"
    path.write_text(spec.to_xml())
    written = robots.load(path)
    built = sim.build(written, "lugre")
    model, data = built.model, mujoco.MjData(built.model)
    rotor2, rotor5 = robot.rotor_dof[1], robot.rotor_dof[4]
    data.qpos[robot.rotor_qpos[1]] = 0.3
    mujoco.mj_forward(model, data)
    cog = model.actuator("cogging2").id
    assert data.actuator_force[cog] == pytest.approx(0.03 * np.sin(4 * 0.3 + 0.2), rel=1e-9)
    offset = model.actuator("torque_offset5").id
    assert data.actuator_force[offset] == pytest.approx(-1.5 / written.gear_ratio[4], rel=1e-12)
    assert model.actuator_trnid[cog, 0] == model.dof_jntid[rotor2]
    assert model.actuator_trnid[offset, 0] == model.dof_jntid[rotor5]


def test_lugre_refuses_state_dependent_friction(tmp_path):
    robot = robots.load("puma560")
    spec = mujoco.MjSpec.from_file(str(robot.path))
    effects.get("temperature").apply(spec, robot, 0, {"amplitude": 0.5, "time_constant": 30.0})
    path = tmp_path / "p.xml"
    path.write_text(spec.to_xml())
    with pytest.raises(ValueError, match="--friction stribeck"):
        sim.build(robots.load(path), "lugre")
    sim.build(robots.load(path), "stribeck")


def test_unknown_effect_lists_the_known_ones():
    with pytest.raises(ValueError, match="unknown effect 'gravity'.*coulomb"):
        effects.get("gravity")


def test_library_holds_the_design_ids_in_the_search_order():
    # the calibration breaks near ties in this order (simpler effects first): changing it changes results
    assert list(effects.EFFECTS)[:9] == ["torque_offset", "coulomb", "viscous", "stribeck", "load_dependent_friction",
                                         "temperature", "payload", "cogging", "backlash"]


def test_every_module_of_the_effects_package_is_a_registered_effect():
    """The package imports its modules itself: a new effect is one new file."""
    folder = Path(effects.__file__).parent
    modules = {p.stem for p in folder.glob("*.py")} - {"__init__", "base", "friction"}
    registered = {type(e).__module__.rpartition(".")[2] for e in effects.REGISTRY.values()}
    assert modules == registered
    # the calibration's candidates are every registered effect but the nominal motor friction
    assert list(effects.EFFECTS) == [k for k in effects.REGISTRY if k != effects.MotorFriction.id]


def test_an_effect_id_is_registered_once():
    class Again(effects.Effect):
        id = "cogging"

    with pytest.raises(ValueError, match="'cogging' is already registered to Cogging"):
        effects.register(Again)


def prediction(robot, motion):
    """:func:`faultgen.calibrate.predict` along a motion (it reads the ``t, q, qd, qdd`` a
    :class:`Motion` has as a measured file has them)."""
    return calibrate.predict(robot, motion)


#: The axis per robot whose load reverses along the task, so that its arm crosses a dead band:
#: the IRB-6700-like axis 2 (resonance resolved: the gearbox equation) and the PUMA 560's waist
#: (stiff: rigid contact; its axis 2 carries gravity and stays on one flank).
BACKLASH_AXIS = {"puma560": 0, "irb6700": 1}


def test_backlash_torque_is_the_written_models_torque(setup, tmp_path):
    """The dead band's torque (gearbox equation or rigid contact, plus quasi-static shift) is what
    the model it writes predicts, up to the first-order treatment of the shift."""
    robot, motion = setup
    effect = effects.get("backlash")
    axis, b = BACKLASH_AXIS[robot.name], 0.01
    phi, offset = effect.columns(motion, axis, b)
    assert phi.shape == (len(motion.t), 0)
    new = augmented(robot, effect, axis, {"width": b}, tmp_path)
    assert new.effects["backlash"].width[axis] == pytest.approx(b, rel=1e-5)
    nominal = prediction(robot, motion)
    change = prediction(new, motion) - nominal
    scale = np.max(np.abs(change[:, axis]))
    assert np.sqrt(np.mean(change[:, axis] ** 2)) > 0.05 * np.sqrt(np.mean(nominal[:, axis] ** 2))
    np.testing.assert_allclose(change[:, axis], offset, atol=0.02 * scale)


def test_backlash_search_recovers_the_width(setup, tmp_path):
    """Round trip: the residual is what a written dead band of known width on one axis changes
    (on every axis: they are coupled), plus noise; the search finds that width to 1 % on that
    axis and adds no dead band on the other axes (the coupled change there is explained by the
    first one)."""
    robot, motion = setup
    effect = effects.get("backlash")
    axis, b = BACKLASH_AXIS[robot.name], 0.0123
    new = augmented(robot, effect, axis, {"width": b}, tmp_path)
    nominal = prediction(robot, motion)
    change = prediction(new, motion) - nominal
    rng = np.random.default_rng(0)
    scale = np.sqrt(np.mean(nominal**2, axis=0))
    residual = change + 0.01 * scale * rng.normal(size=change.shape)  # 1 % torque noise
    found = effect.search(motion, residual, np.ones_like(residual, dtype=bool), scale)
    assert found[axis][0] == pytest.approx(b, rel=0.01)
    assert found[axis][1].shape == (0,)
    np.testing.assert_allclose(found[axis][2], change[:, axis], atol=0.05 * np.max(np.abs(change[:, axis])))
    others = [a for a in range(6) if a != axis]
    assert [found[a][0] for a in others] == [0.0] * len(others)
    # a jackknife replicate starts from its fit (here 15 % off, beyond one span) and refines
    # locally to the same width as the full search, changing no other axis
    start = effect.fitted(robot, {axis: {"width": 1.15 * found[axis][0]}})
    again = start.replicate(motion, residual, np.ones_like(residual, dtype=bool), scale, [axis])
    assert again[axis][0] == pytest.approx(found[axis][0], rel=2e-3)
    assert [again[a][0] for a in others] == [0.0] * len(others)




def test_payload_barycentric_parameters_round_trip_through_the_mjcf(tmp_path):
    """A payload with its centre of mass off the flange and a full inertia, written into the IRB's
    MJCF (whose flange frame is turned against its link) and read back; and the barycentric
    parameters against the parallel-axis theorem worked by hand."""
    robot = robots.load("irb6700")
    values = {"mass": 12.0, "com_x": 0.05, "com_y": -0.02, "com_z": 0.15,
              "ixx": 0.3, "iyy": 0.4, "izz": 0.2, "ixy": 0.01, "ixz": -0.02, "iyz": 0.03}
    spec = mujoco.MjSpec.from_file(str(robot.path))
    effects.make("payload", **values).write(spec, robot)
    path = tmp_path / "payload.xml"
    path.write_text(spec.to_xml())
    assert effects.get("payload").of(robots.load(path)).values() == pytest.approx(values, abs=1e-6)
    phi = payload.barycentric(2.0, [0.0, 0.0, 0.1], [0.0] * 6)
    assert phi.tolist() == pytest.approx([2.0, 0.0, 0.0, 0.2, 0.02, 0.02, 0.0, 0.0, 0.0, 0.0])
    assert payload.consistent(2.0, np.zeros(3), [0.1, 0.1, 0.3, 0, 0, 0]) is False  # triangle inequality
    assert payload.consistent(2.0, np.array([0.0, 0.0, 0.6]), [0.0] * 6) is False  # too far from the flange
