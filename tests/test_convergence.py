"""Numerical convergence: the simulation's answers must not depend on the physics step.

The references here are not faultgen's own: Newton's law for a rotor sliding under a known torque
(an analytic acceleration), and the same simulation at half the step (docs/simulation.md,
"Numerical convergence"; ``benchmarks/convergence.py`` is the full study).
"""

import mujoco
import numpy as np
import pytest

from faultgen.effects import friction
from faultgen.model import robots
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim
from resolved_runs import run_config

JM = 0.006  # kg m^2, the IRB-6700-like arm's axis-1 rotor
H = 0.0005


def sliding_rotor_acceleration(bristle_damping: float) -> float:
    """A rotor sliding at 100 rad/s under MuJoCo's LuGre (F_c = 1 N m) and a 2 N m torque."""
    spec = mujoco.MjSpec()
    spec.option.timestep = H
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    body = spec.worldbody.add_body(name="rotor", mass=1e-9, inertia=[1e-12] * 3, explicitinertial=True)
    body.add_joint(name="rotor", type=mujoco.mjtJoint.mjJNT_HINGE, armature=JM)
    actuator = spec.add_actuator(name="lugre", target="rotor")
    actuator.trntype = mujoco.mjtTrn.mjTRN_JOINT
    actuator.set_to_dcmotor(motorconst=[0.0, 0.0], resistance=1.0, lugre=[1000.0, bristle_damping, 1.0, 1.3, 10.0],
                            ctrlspec=16)
    model = spec.compile()
    data = mujoco.MjData(model)
    data.qvel[0], data.qfrc_applied[0] = 100.0, 2.0
    for _ in range(100):  # bristles settle (time constant g / (sigma_0 |v|) = 10 us)
        mujoco.mj_step(model, data)
    v0 = data.qvel[0]
    for _ in range(200):
        mujoco.mj_step(model, data)
    return (data.qvel[0] - v0) / (200 * H)


def test_bristle_damping_adds_phantom_rotor_inertia_in_mujoco():
    """Why faultgen's lugre model needs sigma_1 = 0: Newton says (2 - 1) / Jm; with sigma_1 > 0
    MuJoCo's implicit step moves the rotor as if it weighed Jm + h sigma_1."""
    newton = (2.0 - 1.0) / JM
    assert sliding_rotor_acceleration(0.0) == pytest.approx(newton, rel=1e-6)
    assert sliding_rotor_acceleration(4.9) == pytest.approx(1.0 / (JM + H * 4.9), rel=1e-6)


def test_lugre_refuses_bristle_damping_and_too_stiff_bristles():
    robot = robots.load("irb6700")
    rows = robot.friction.as_rows()
    rows[2, friction.FIELDS.index("bristle_damping")] = 6.2
    damped = friction.MotorFriction.from_rows(rows)
    with pytest.raises(ValueError, match="axis 3: bristle_damping = 6.2 N m s/rad; the lugre model needs 0"):
        friction.check_lugre_step(damped, H, np.full(6, 1.0))
    with pytest.raises(ValueError, match=r"axis 1: bristle_stiffness = 10.0 N m/rad is too stiff for the 0.5 ms"):
        friction.check_lugre_step(robot.friction, H, np.full(6, 0.001))  # 10 * 0.5 ms > 0.001 + 3e-3
    friction.check_lugre_step(robot.friction, H, np.full(6, 0.02))  # 10 N m/rad * 0.5 ms < 0.02 + 1e-3


def cycle_features(robot: str, friction_model: str, timestep: float, folder) -> dict[str, np.ndarray]:
    path = robots.with_timestep(robot, timestep, folder / f"{robot}_{timestep}")
    config = run_config(robot=str(path), task="pick_place", friction=friction_model, cycles=1,
                           noise=sensors.NoiseConfig(0.0, 0.0), nthread=1)
    run = sim.simulate(config, progress=False)
    return {"mean|tau|": np.mean(np.abs(run.tau_m[0]), axis=0),
            "rms_tau": np.sqrt(np.mean(run.tau_m[0] ** 2, axis=0)),
            "mean|f|": run.mean_friction_torque[0],
            "track": run.tracking_error[0]}


#: The issue's bounds: 1 % for the torques, 5 % for the largest tracking error.
BOUND = {"mean|tau|": 0.01, "rms_tau": 0.01, "mean|f|": 0.01, "track": 0.05}


@pytest.mark.parametrize("robot", ["irb6700", "puma560"])
@pytest.mark.parametrize("friction_model", friction.MODELS)
def test_one_cycle_at_half_the_step_agrees(robot, friction_model, tmp_path):
    """Pick and place (stops and reversals: the hardest cycle), default step against half of it,
    every axis: measured at most 0.5 % for the torques (before the fix the default lugre model
    moved by up to 26 % here). The largest tracking error is held to 5 % with lugre only: the
    static model tracks the wrists exactly in the step -> 0 limit, so its error there is all
    step error (tens of urad; docs/simulation.md, "Numerical convergence")."""
    h = robots.load(robot).model.opt.timestep
    coarse = cycle_features(robot, friction_model, h, tmp_path)
    fine = cycle_features(robot, friction_model, h / 2, tmp_path)
    names = BOUND if friction_model == "lugre" else [n for n in BOUND if n != "track"]
    for name in names:
        relative = np.abs(coarse[name] - fine[name]) / np.abs(fine[name])
        print(robot, friction_model, name, np.round(100 * relative, 2), "%")
        assert np.all(relative < BOUND[name]), f"{name}: {np.round(100 * relative, 2)} %"


@pytest.mark.parametrize("integrator", ["implicitfast", "discrete"])
def test_applied_drive_torque_obeys_newton(integrator):
    """A PID drive (MuJoCo's dcmotor, as faultgen's drives) alone on a rotor: the torque the step
    applied, J (v+ - v) / h, against sim.applied_drive_torque of what MuJoCo reports. The reported
    start-of-step value misses by kd (v+ - v) (+ kp h v+ under discrete)."""
    kp, kd = 2.0, 0.05
    model = mujoco.MjModel.from_xml_string(f"""
      <mujoco><option timestep="{H}" integrator="{integrator}" gravity="0 0 0"/>
        <worldbody><body><joint name="rotor" type="hinge" armature="{JM}"/>
          <geom type="sphere" size="0.01" mass="1e-9"/></body></worldbody>
        <actuator><dcmotor name="drive" joint="rotor" motorconst="1 1" resistance="1"
          controller="{kp} 0 {kd} 0 0 0" input="pos vel ff"/></actuator></mujoco>""")
    data = mujoco.MjData(model)
    data.ctrl[:] = [1.0, 20.0, 0.3]
    for _ in range(3):
        mujoco.mj_step(model, data)
    before = data.qvel.copy()
    mujoco.mj_step(model, data)
    newton = JM * (data.qvel[0] - before[0]) / H
    applied = sim.applied_drive_torque(data.actuator_force, data.qvel, before, np.array([kp]), np.array([kd]),
                                       np.array([100.0]), H, integrator == "discrete")
    assert applied[0] == pytest.approx(newton, rel=1e-9)
    assert abs(data.actuator_force[0] - newton) > 1e-3  # what MuJoCo reports is not it
