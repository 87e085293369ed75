"""A measured-torque log of a robot added from a URDF, made with Pinocchio's rigid-body dynamics
of the same URDF and a payload the robot's model does not have (issue 37: ``faultgen calibrate
--robot kr210`` on such a log must name the payload and halve the gap).

Independent of faultgen: the rigid-body dynamics (Pinocchio's recursive Newton-Euler, ``pin.rnea``,
on the folder's ``urdf_used.urdf``, the URDF as faultgen compiled it, read by Pinocchio's own URDF
parser) and the payload (a box added to the last link's inertia with ``pin.Inertia`` at the URDF's
``tool0`` frame, placed by Pinocchio). Ours, so that only the payload is missing from the model:
the drivetrain terms added to Pinocchio's torque, the reflected motor inertia
``G^2 (Jm + rotor body inertia) qdd`` and the nominal motor-side friction of thesis eq. 6.3
(:meth:`faultgen.effects.friction.MotorFriction.stribeck_torque` at the motor speed ``G qd``,
referred to the arm through ``G``), with the numbers of the folder's ``drivetrain.toml``; and the
motion (the folder's generated ``pick_place`` task). Used by ``tests/test_calibrate_pinocchio.py``
and ``benchmarks/calibration_pinocchio.py``.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
import rtbdata

from faultgen.bench import independent
from faultgen.data import logfiles
from faultgen.model import builder, importers, robots
from faultgen.model.folder import add as add_robot
from faultgen.operation import programs, taskgen

KR210_URDF = Path(rtbdata.__file__).parent / "xacro/kuka_description/kuka_kr210/urdf/kr210l150.urdf"
FLANGE_FRAME = independent.FLANGE_FRAME
#: Log rate, Hz (the thesis's 4 ms sampling period).
RATE = 250.0


@dataclass(frozen=True)
class HiddenPayload:
    """A solid box fixed to the flange: ``mass`` kg, centre ``com`` (m, flange frame), edges
    ``size`` (m, along the flange axes)."""

    mass: float = 120.0
    com: tuple[float, float, float] = (0.15, 0.02, 0.0)
    size: tuple[float, float, float] = (0.30, 0.40, 0.25)


def pinocchio_model(urdf: Path, payload: HiddenPayload | None) -> pin.Model:
    """Pinocchio's model of ``urdf``, with ``payload`` added to the inertia of the body that
    carries the flange frame (:func:`faultgen.bench.independent.pinocchio_model`)."""
    if payload is None:
        return independent.pinocchio_model(urdf)
    return independent.pinocchio_model(urdf, payload.mass, payload.com, payload.size)


def arm_torque(folder: Path, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
               payload: HiddenPayload | None) -> np.ndarray:
    """Arm-side drive torque, N m, shape (n, N): Pinocchio's RNEA on the folder's URDF with the
    payload, plus the drivetrain terms of the folder's model (reflected motor inertia and nominal
    motor-side friction, ours)."""
    robot = robots.load(folder)
    model = pinocchio_model(Path(folder) / "urdf_used.urdf", payload)
    data = model.createData()
    if model.nq != robot.n_axes or model.nv != robot.n_axes:
        raise ValueError(f"Pinocchio's model has nq = {model.nq}, the robot {robot.n_axes} axes")
    rigid = np.array([pin.rnea(model, data, q[k], qd[k], qdd[k]) for k in range(len(q))])
    G = robot.gear_ratio
    reflected = G**2 * (robot.motor_inertia + builder.ROTOR_INERTIA) * qdd
    friction = G * robot.friction.stribeck_torque(G * qd)
    return rigid + reflected + friction


def motion(folder: Path, cycles: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``cycles`` back-to-back cycles of the folder's ``pick_place`` task at :data:`RATE`:
    ``t`` (n,) s and ``q``, ``qd``, ``qdd`` (n, N) in rad, rad/s, rad/s^2."""
    path = programs.load(robots.load(folder), "pick_place").trajectory(1.0 / RATE)
    # the last sample of a cycle is the first of the next (same angles, at rest)
    q, qd, qdd = (np.concatenate([x[:-1]] * cycles + [x[-1:]]) for x in (path.q, path.qd, path.qdd))
    return np.arange(len(q)) / RATE, q, qd, qdd


def add_kr210(out: Path) -> Path:
    """``faultgen robots add kr210 --from <rtb-data's kr210l150.urdf> --package
    kuka_kr210_support=<its folder> -o out``, as the library call (:func:`faultgen.model.folder.add`
    with the generated tasks, as the command makes it)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", importers.GeometryDropped)
        add_robot("kr210", KR210_URDF, Path(out), tasks=taskgen.generate,
                  packages={"kuka_kr210_support": KR210_URDF.parents[1]})
    return Path(out)


def write_log(folder: Path, path: Path, cycles: int, payload: HiddenPayload | None, noise: float = 0.005,
              seed: int = 0) -> Path:
    """Write the log (:func:`faultgen.logs.measured.write_csv`: ``t``, ``q1..qN`` rad,
    ``tau1..tauN`` N m at the arm side) of ``cycles`` pick-and-place cycles with the hidden
    ``payload``; Gaussian torque noise of ``noise`` times each axis's torque RMS (seeded)."""
    t, q, qd, qdd = motion(folder, cycles)
    tau = arm_torque(folder, q, qd, qdd, payload)
    rng = np.random.default_rng(seed)
    tau = tau + rng.normal(0.0, 1.0, tau.shape) * noise * np.sqrt(np.mean(tau**2, axis=0))
    return logfiles.write_csv(path, t, q, tau)
