"""The independent fleet's plant (:mod:`faultgen.bench.independent`): Pinocchio's rigid-body
dynamics on the robot folder's URDF, the motions it drives (the folder's pick and place and its
variants, faultgen's friction test) and the motor-side friction law, ours (the independent module's
docstring says what is independent and what is ours); and the writer of one log.

Needs Pinocchio (``pin``, the ``bench`` extra: ``pip install 'faultgen-robots[bench]'``).
"""

from __future__ import annotations

import dataclasses
import os
from functools import lru_cache
from pathlib import Path

import numpy as np

from faultgen.bench import layouts
from faultgen.data import cells
from faultgen.model import robots
from faultgen.operation import programs

#: Stribeck speed and sign-smoothing speed of the motor-side friction, rad/s at the motor.
STRIBECK_SPEED = 8.0
SIGN_SPEED = 0.5
#: Torque noise per sample, a share of each axis's torque RMS; angle noise, rad.
NOISE = 0.005
ANGLE_NOISE = 1e-5
#: The parts are aluminium cubes hanging from the flange (their centre half an edge from it, along
#: the z axis of the URDF's ``tool0`` frame, as faultgen's payload condition places a part): the
#: load data a robot's program declares, which the monitor is told. Their masses (5-35 kg) keep
#: faultgen's twin of the motion within its drives' capacity (the KR210's axis 6: 366 N m at the arm,
#: which the twin reached with a 60 kg part, Pinocchio's dynamics needing about 230 N m).
PART_DENSITY = 2700.0
#: A changed program's pick and place targets lie this share of the way from its start pose to the old ones.
PROGRAM_SHRINK = 0.7
#: The flange frame of the URDF (ROS-Industrial's ``tool0``); faultgen's builder puts its ``flange`` site there.
FLANGE_FRAME = "tool0"
#: The rate the motion is planned at, Hz (the planner's 4 ms, the thesis's sampling period).
PLAN_RATE = 250.0


def pinocchio_module():
    """The ``pinocchio`` module; ImportError naming the extra that installs it."""
    try:
        import pinocchio
    except ImportError:
        raise ImportError("the independent simulator needs Pinocchio: pip install 'faultgen-robots[bench]' "
                          "(or: pip install pin)") from None
    return pinocchio


def pinocchio_model(urdf: Path, mass: float = 0.0, com=(0.0, 0.0, 0.0), size=(0.0, 0.0, 0.0)):
    """Pinocchio's model (``pin.Model``) of ``urdf``, with a solid box of ``mass`` kg, centre ``com``
    (m, flange frame) and edges ``size`` (m) added to the inertia of the body that carries the flange
    frame (:data:`FLANGE_FRAME`)."""
    pin = pinocchio_module()
    model = pin.buildModelFromUrdf(str(urdf))
    if mass > 0:
        frame = model.frames[model.getFrameId(FLANGE_FRAME)]
        box = pin.Inertia.FromBox(mass, *size)
        at_flange = pin.SE3(np.eye(3), np.asarray(com, dtype=float)).act(box)
        joint = frame.parentJoint
        model.inertias[joint] = model.inertias[joint] + frame.placement.act(at_flange)
    return model


def changed_program(program, shrink: float = PROGRAM_SHRINK):
    """``program`` (a :class:`faultgen.operation.programs.Program`) with every joint-space target
    ``to`` moved to ``start + shrink (to - start)``: the same cycle between other poses."""
    start = np.asarray(program.start, dtype=float)
    segments = tuple(
        dataclasses.replace(s, values={**s.values, "to": start + shrink * (np.asarray(s.values["to"]) - start)})
        if s.type == "move" and "to" in s.values else s for s in program.segments)
    return dataclasses.replace(program, segments=segments)


@lru_cache(maxsize=16)
def motion(robot: robots.Robot, rate: float, changed: bool = False, shrink: float = 1.0):
    """The pick-and-place cycle of ``robot`` (as :func:`faultgen.bench.independent.write_fleet`
    resolved its folder; ``changed``: :func:`changed_program`'s; ``shrink`` < 1: a variant, its
    targets drawn that share of the way to the start pose, on top of a change) planned at 250 Hz (the
    planner's 4 ms), taken at ``rate`` Hz (planned at ``rate`` for a whole multiple of 250 Hz:
    :func:`faultgen.bench.layouts.plan`): ``t, q, qd, qdd``, (n,) s and (n, N) rad, rad/s, rad/s^2."""
    dt, step = layouts.plan(rate, PLAN_RATE)
    program = programs.load(robot, "pick_place")
    if changed:
        program = changed_program(program)
    if shrink != 1.0:
        program = changed_program(program, shrink)
    path = program.trajectory(dt)
    q, qd, qdd = (x[::step] for x in (path.q, path.qd, path.qdd))
    return np.arange(len(q)) / rate, q, qd, qdd


@lru_cache(maxsize=256)
def rigid(robot: robots.Robot, rate: float, mass: float, changed: bool = False, shrink: float = 1.0) -> np.ndarray:
    """Pinocchio's RNEA torque (n, N) N m of :func:`motion`'s cycle with a part of ``mass`` kg
    (:data:`PART_DENSITY`), from the URDF in the robot's folder."""
    pin = pinocchio_module()
    _, q, qd, qdd = motion(robot, rate, changed, shrink)
    edge = (mass / PART_DENSITY) ** (1 / 3)
    model = pinocchio_model(robot.path.parent / "urdf_used.urdf", mass, (0.0, 0.0, edge / 2), (edge, edge, edge))
    data = model.createData()
    return np.array([pin.rnea(model, data, q[k], qd[k], qdd[k]) for k in range(len(q))])


def motor_friction(w: np.ndarray, coulomb, static, viscous) -> np.ndarray:
    """Motor-side friction torque, N m, at motor speed ``w`` rad/s:
    ``(Fc + Fs / (1 + (w / ws)^2)) (2 / pi) atan(w / we) + Fv w`` (:data:`STRIBECK_SPEED`,
    :data:`SIGN_SPEED`)."""
    hump = coulomb + static / (1.0 + (w / STRIBECK_SPEED) ** 2)
    return hump * (2.0 / np.pi) * np.arctan(w / SIGN_SPEED) + viscous * w


@lru_cache(maxsize=4)
def friction_test_motion(robot: robots.Robot, rate: float):
    """The friction test of ``robot`` (:func:`faultgen.operation.friction_test.program`, as ``faultgen
    tasks friction-test`` writes it) planned at 250 Hz and taken at ``rate`` Hz: ``t`` (n,) s, ``q``,
    ``qd``, ``qdd`` (n, N) rad, rad/s, rad/s^2, and Pinocchio's RNEA torque of it without a part
    (n, N) N m, from the URDF in the robot's folder. ValueError for a rate as :func:`motion`'s."""
    from faultgen.operation import friction_test

    dt, step = layouts.plan(rate, PLAN_RATE)
    program = programs.parse(friction_test.text(robot), robot, where=f"friction test of {robot.name}")
    path = program.trajectory(dt)
    q, qd, qdd = (x[::step] for x in (path.q, path.qd, path.qdd))
    pin = pinocchio_module()
    model = pinocchio_model(robot.path.parent / "urdf_used.urdf")
    data = model.createData()
    rigid_torque = np.array([pin.rnea(model, data, q[k], qd[k], qdd[k]) for k in range(len(q))])
    return np.arange(len(q)) / rate, q, qd, qdd, rigid_torque


def write_friction_test(path: Path, header, model: robots.Robot, rate: float, friction, temperature: np.ndarray,
                        rng: np.random.Generator) -> None:
    """Write one friction test log (:func:`friction_test_motion` at ``rate`` Hz) at ``path``: the arm-side torque
    Pinocchio's RNEA plus the reflected motor inertia plus ``G friction(G qd)`` (``friction``: the
    plant's motor-side law at motor speeds (n, N), N m), the noise model of the daily logs drawn from
    ``rng``, ``temperature`` (N,) deg C logged (rounded to 0.01) and payload 0."""
    G, jm = model.gear_ratio, model.motor_inertia
    t, q, qd, qdd, rigid_torque = friction_test_motion(model, rate)
    tau = rigid_torque + G**2 * jm * qdd + G * friction(G * qd)
    tau = tau + rng.normal(0.0, 1.0, tau.shape) * NOISE * np.sqrt(np.mean(tau**2, axis=0))
    angles = q + rng.normal(0.0, ANGLE_NOISE, q.shape)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_csv(path, header, t, angles, tau, np.round(temperature, 2), 0.0)


def write_csv(path: Path, header, t, q, tau, temperature, mass) -> None:
    """One log at ``path``, written atomically: ``t`` (n,) s, ``q`` and ``tau`` (n, N), the
    ``temperature`` (N,) deg C and the part's ``mass`` kg on every row, under ``header``."""
    rows = len(t)
    table = np.hstack([t[:, None], q, tau, np.broadcast_to(temperature, (rows, len(temperature))),
                       np.full((rows, 1), mass)])
    formats = ["%.4f"] + ["%.6f"] * q.shape[1] + ["%.4f"] * tau.shape[1] + ["%.2f"] * len(temperature) + ["%.1f"]
    part = path.with_name(path.name + ".part")  # no reader lists it (a log ends in .csv)
    np.savetxt(part, table, fmt=formats, delimiter=",", header=cells.line(header), comments="")
    os.replace(part, path)
