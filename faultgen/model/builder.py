"""Add a drivetrain to an arm: the one builder of every faultgen robot.

An *arm* is an ``mujoco.MjSpec`` of a serial chain of 5 to 7 limited revolute joints fixed to the
world, with link masses and inertias (:func:`check_arm` says what is refused). :func:`build` adds,
per axis i (1..N, from the base out), the elements :mod:`faultgen.model.robots` reads:

``joint{i}``
    the arm's i-th revolute joint, renamed;
``rotor{i}``
    a body and hinge joint on the link that carries the motor (the parent of ``joint{i}``'s body),
    coaxial with ``joint{i}``, placed just before that link in the tree, with armature = motor
    inertia Jm and a negligible mass (1e-9 kg, 1e-12 kg m^2);
``gearbox{i}``
    a fixed tendon ``L = rotor{i} / G - joint{i}`` (coefficients 1/G and -1, thesis eq. 6.2a) with
    the gearbox stiffness K and damping D;
``motor{i}``
    a torque actuator on ``rotor{i}``, ``ctrlrange`` +-motor torque limit;
``friction{i}``
    a custom numeric with the motor-side friction parameters (``faultgen.effects.friction.FIELDS``);

a ``home`` keyframe with the rotors at ``G q`` (undeflected gearboxes), and a site ``flange`` if the
arm has none (:func:`_add_flange`). The arm's actuators,
sensors, tendons and keyframes go (the drivetrain replaces them), its geoms stop colliding (the
robot moves in free space), and the physics step becomes faultgen's (0.5 ms, discrete-time
implicit integrator). ``puma560`` and ``irb6700`` are built this way from their ``arm.xml`` and
``drivetrain.toml`` (docs/robots.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from faultgen.axes import MAX_AXES, MIN_AXES
from faultgen.effects.motor_friction import MotorFriction
from faultgen.model.drivetrain import Drivetrain
from faultgen.model.drivetrain import read as read_drivetrain

#: faultgen's physics step, s, and integrator (docs/simulation.md).
TIMESTEP = 0.0005
#: Mass (kg) and principal inertia (kg m^2) of a rotor body: its inertia about its axis is the
#: joint's armature; the body only carries the joint.
ROTOR_MASS, ROTOR_INERTIA = 1e-9, 1e-12


class ArmError(ValueError):
    """An arm faultgen cannot model; the message names the offending element."""


@dataclass(frozen=True)
class ArmJoint:
    """One revolute joint of an arm as :func:`check_arm` finds it."""

    name: str
    body: str
    range: tuple[float, float]


def one_line(err: Exception) -> str:
    """MuJoCo's message of ``err`` on one line (it puts the element on a second one)."""
    return "; ".join(line.strip() for line in str(err).strip().splitlines() if line.strip())


def _compile(spec: mujoco.MjSpec, source: str) -> mujoco.MjModel:
    try:
        return spec.copy().compile()
    except ValueError as err:
        raise ArmError(f"{source}: {one_line(err)}") from None


def check_arm(spec: mujoco.MjSpec, source: str = "arm") -> list[ArmJoint]:
    """The arm's revolute joints from the base out, after checking that faultgen can model it.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The arm (not changed).
    source : str
        Name of the file it came from, for the messages.

    Returns
    -------
    list of ArmJoint
        N joints, 5 <= N <= 7, each on its own body, each body a descendant of the last.

    Raises
    ------
    ArmError
        Naming the element, if the arm does not compile, has a floating base (a free or ball
        joint), a prismatic (slide) joint, a closed chain (an equality constraint), fewer than 5 or
        more than 7 revolute joints, joints not in one serial chain, a revolute joint without
        limits, or a moving body with zero mass or an inertia that is not positive definite.
    """
    # the joint kinds first: a floating base often fails to compile for another reason (a massless base)
    for joint in spec.joints:
        label = joint.name or "(unnamed)"
        if joint.type == mujoco.mjtJoint.mjJNT_FREE:
            raise ArmError(
                f"{source}: joint {label!r} is a free joint: a floating base; a robot arm must be "
                "fixed to the world"
            )
        if joint.type == mujoco.mjtJoint.mjJNT_SLIDE:
            raise ArmError(f"{source}: joint {label!r} is prismatic; faultgen models revolute axes only")
    model = _compile(spec, source)
    joints = _serial_chain(model, source)
    _check_links(model, source)
    return [
        ArmJoint(
            _name(model, mujoco.mjtObj.mjOBJ_JOINT, j),
            _name(model, mujoco.mjtObj.mjOBJ_BODY, model.jnt_bodyid[j]),
            (float(model.jnt_range[j, 0]), float(model.jnt_range[j, 1])),
        )
        for j in joints
    ]


def _name(model: mujoco.MjModel, kind: mujoco.mjtObj, i: int) -> str:
    """The name of element ``i`` of ``kind`` in ``model``, or ``#i`` if it has none."""
    return mujoco.mj_id2name(model, kind, i) or f"#{i}"


def _serial_chain(model: mujoco.MjModel, source: str) -> list[int]:
    """The compiled arm's joint indices (depth first from the base), after checking they are
    MIN_AXES..MAX_AXES revolute joints with limits, one per body, in one open serial chain.

    Raises
    ------
    ArmError
        Naming the first joint, body or constraint that is not so.
    """
    def name(kind: mujoco.mjtObj, i: int) -> str:
        return _name(model, kind, i)

    for j in range(model.njnt):
        kind = model.jnt_type[j]
        jname = name(mujoco.mjtObj.mjOBJ_JOINT, j)
        if kind == mujoco.mjtJoint.mjJNT_FREE:
            raise ArmError(
                f"{source}: joint {jname!r} is a free joint: a floating base; a robot arm must be "
                "fixed to the world"
            )
        if kind == mujoco.mjtJoint.mjJNT_BALL:
            raise ArmError(f"{source}: joint {jname!r} is a ball joint; expected revolute joints only")
        if kind == mujoco.mjtJoint.mjJNT_SLIDE:
            raise ArmError(f"{source}: joint {jname!r} is prismatic; faultgen models revolute axes only")
    if model.neq:
        raise ArmError(
            f"{source}: equality constraint {name(mujoco.mjtObj.mjOBJ_EQUALITY, 0)!r} closes a chain; "
            "expected an open serial chain"
        )
    n = model.njnt
    if not MIN_AXES <= n <= MAX_AXES:
        raise ArmError(f"{source}: {n} revolute joints; expected {MIN_AXES} to {MAX_AXES} in a serial chain")
    joints = list(range(n))  # compiled order is depth first from the base
    for j in joints:
        if model.body_jntnum[model.jnt_bodyid[j]] != 1:
            raise ArmError(
                f"{source}: body {name(mujoco.mjtObj.mjOBJ_BODY, model.jnt_bodyid[j])!r} carries "
                f"{model.body_jntnum[model.jnt_bodyid[j]]} joints; expected one per link"
            )
    for a, b in zip(joints, joints[1:]):
        body, ancestor = model.jnt_bodyid[b], model.jnt_bodyid[a]
        while body and body != ancestor:
            body = model.body_parentid[body]
        if body != ancestor:
            raise ArmError(
                f"{source}: joint {name(mujoco.mjtObj.mjOBJ_JOINT, b)!r} is not on the chain through "
                f"joint {name(mujoco.mjtObj.mjOBJ_JOINT, a)!r}; expected one serial chain"
            )
    for j in joints:
        if not model.jnt_limited[j]:
            raise ArmError(
                f"{source}: joint {name(mujoco.mjtObj.mjOBJ_JOINT, j)!r} has no limits; give it a range"
            )
        low, high = model.jnt_range[j]
        if not low < high:
            raise ArmError(
                f"{source}: joint {name(mujoco.mjtObj.mjOBJ_JOINT, j)!r} has range {low!r}..{high!r}; "
                "expected lower < upper"
            )
    return joints


def _check_links(model: mujoco.MjModel, source: str) -> None:
    """Check every body that moves with the first joint: one carrying a joint has mass and a
    positive-definite inertia, any with mass a physical one (each moment <= the sum of the other two).

    Raises
    ------
    ArmError
        Naming the first body that has not.
    """
    first = model.jnt_bodyid[0]
    for body in range(1, model.nbody):
        moving = body == first
        b = body
        while b and not moving:
            b = model.body_parentid[b]
            moving = b == first
        if not moving:
            continue
        inertia = model.body_inertia[body]
        bname = _name(model, mujoco.mjtObj.mjOBJ_BODY, body)
        carries = model.body_jntnum[body] > 0
        if carries and (model.body_mass[body] <= 0 or np.any(inertia <= 0)):
            raise ArmError(
                f"{source}: body {bname!r} has mass {model.body_mass[body]!r} kg and principal inertia "
                f"{inertia.tolist()} kg m^2; a link needs mass and a positive-definite inertia"
            )
        if model.body_mass[body] > 0 and (
            np.any(inertia <= 0) or 2 * inertia.max() > inertia.sum() * (1 + 1e-9)
        ):
            raise ArmError(
                f"{source}: body {bname!r} has principal inertia {inertia.tolist()} kg m^2; expected a "
                "positive-definite tensor (each moment <= the sum of the other two)"
            )


def _name_everything(spec: mujoco.MjSpec) -> None:
    """Give unnamed bodies and joints a name: the builder finds them again by name after moving them."""
    taken = {b.name for b in spec.bodies} | {j.name for j in spec.joints}
    for kind, items in (("body", spec.bodies), ("joint", spec.joints)):
        for k, item in enumerate(items):
            if not item.name:
                label = f"{kind}{k}"
                while label in taken:
                    label += "_"
                item.name = label
                taken.add(label)


def build(
    arm: mujoco.MjSpec, drivetrain: Drivetrain, home: np.ndarray | None = None, source: str = "arm"
) -> mujoco.MjSpec:
    """A faultgen robot: the arm with its drivetrain (this module's docstring lists what is added).

    Parameters
    ----------
    arm : mujoco.MjSpec
        The arm; not changed (the robot is built on a copy).
    drivetrain : Drivetrain
        One :class:`~faultgen.model.drivetrain.AxisDrive` per revolute joint, base first.
    home : ndarray of shape (N,), optional
        Arm joint angles of the ``home`` keyframe, rad; by default the arm's own keyframe
        ``home`` if it has one, else zero clipped into each joint's range.
    source : str
        Name of the arm's file, for the messages.

    Returns
    -------
    mujoco.MjSpec
        The robot, ready for ``compile()`` or ``to_xml()``.

    Raises
    ------
    ArmError
        As :func:`check_arm`, or if the drivetrain has not one axis per joint, or the arm already
        uses a name the builder adds (``rotor{i}``, ``gearbox{i}``, ``motor{i}``, ``friction{i}``) for
        something else.
    """
    joints = check_arm(arm, source)
    n = len(joints)
    if len(drivetrain) != n:
        raise ArmError(f"{source}: the drivetrain has {len(drivetrain)} axes, the arm {n} revolute joints")
    spec = arm.copy()
    spec.copy_during_attach = True  # moving a link in its own spec takes a copy
    _name_everything(spec)
    arm_home = _strip(spec, n)
    _add_rotors(spec, joints, drivetrain, source)
    if not any(site.name == "flange" for site in spec.sites):
        _add_flange(spec, joints[-1].body)
    _add_drives(spec, drivetrain)
    _add_home(spec, joints, drivetrain, arm_home if home is None else np.asarray(home, dtype=float), source)
    return spec


def _strip(spec: mujoco.MjSpec, n: int) -> np.ndarray | None:
    """Remove from the arm's ``spec`` what the builder replaces (keyframes, actuators, sensors, tendons,
    contact pairs and excludes, equalities), switch contacts off and set the builder's timestep and
    integrator. Returns the arm's ``home`` keyframe of ``n`` angles (rad), or None if it has none."""
    arm_home = None
    keys = list(spec.keys)
    for key in keys:
        if key.name == "home" and len(key.qpos) == n:
            arm_home = np.array(key.qpos, dtype=float)
        spec.delete(key)
    for kind in ("actuators", "sensors", "tendons", "excludes", "pairs", "equalities"):
        for item in list(getattr(spec, kind)):
            spec.delete(item)
    for geom in spec.geoms:
        geom.contype, geom.conaffinity = 0, 0
    spec.option.timestep = TIMESTEP
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_DISCRETE
    return arm_home


def _add_rotors(spec: mujoco.MjSpec, joints: list[ArmJoint], drivetrain: Drivetrain, source: str) -> None:
    """Rename the arm's joints ``joint{i}`` and put each link after a rotor body ``rotor{i}`` (joint
    ``rotor{i}`` on the arm joint's axis, its armature the motor inertia).

    Raises
    ------
    ArmError
        If the arm already has an element named ``rotor{i}``.
    """
    n = len(joints)
    names = {b.name for b in spec.bodies} | {j.name for j in spec.joints}
    arm_names = [j.name for j in joints]
    for i in range(1, n + 1):
        for added in (f"rotor{i}",):
            if added in names and added not in arm_names:
                raise ArmError(f"{source}: the arm already has an element named {added!r}")
    # rename the arm joints joint{i} (in two passes, so joint2 -> joint1 style swaps cannot clash)
    for k, joint in enumerate(joints):
        spec.joint(joint.name).name = f"__arm_joint{k + 1}"
    for k in range(n):
        spec.joint(f"__arm_joint{k + 1}").name = f"joint{k + 1}"

    for k, (joint, drive) in enumerate(zip(joints, drivetrain.axes)):
        i = k + 1
        link = spec.body(joint.body)
        arm_joint = spec.joint(f"joint{i}")
        parent = link.parent
        frame = link.frame
        rotor = parent.add_body(name=f"rotor{i}", pos=link.pos, quat=link.quat)
        rotor.alt = link.alt
        if frame is not None:
            rotor.set_frame(frame)
        rotor.explicitinertial = True
        rotor.mass, rotor.inertia, rotor.ipos = ROTOR_MASS, [ROTOR_INERTIA] * 3, [0, 0, 0]
        rotor.add_joint(
            name=f"rotor{i}",
            type=mujoco.mjtJoint.mjJNT_HINGE,
            pos=arm_joint.pos,
            axis=arm_joint.axis,
            armature=drive.motor_inertia,
        )
        # the link goes after its rotor, as written by hand before (the tree order fixes qpos order)
        # (a link placed straight in its parent body goes into an identity frame, ``mount{i}``: MjSpec
        # attaches to frames only)
        target = frame if frame is not None else parent.add_frame(name=f"mount{i}")
        target.attach_body(link, "", "")
        spec.delete(link)


def _add_drives(spec: mujoco.MjSpec, drivetrain: Drivetrain) -> None:
    """Add each axis's gearbox (tendon ``gearbox{i}``: stiffness and damping between rotor and link),
    motor (actuator ``motor{i}`` on the rotor, limited to the motor torque) and motor friction."""
    for i, drive in enumerate(drivetrain.axes, start=1):
        tendon = spec.add_tendon(
            name=f"gearbox{i}",
            stiffness=[drive.gearbox_stiffness, 0, 0],
            damping=[drive.gearbox_damping, 0, 0],
            springlength=[0, 0],
        )
        tendon.wrap_joint(f"rotor{i}", 1.0 / drive.gear_ratio)
        tendon.wrap_joint(f"joint{i}", -1.0)
    for i, drive in enumerate(drivetrain.axes, start=1):
        motor = spec.add_actuator(name=f"motor{i}", target=f"rotor{i}", trntype=mujoco.mjtTrn.mjTRN_JOINT)
        motor.set_to_motor()
        motor.ctrlrange = [-drive.motor_torque_limit, drive.motor_torque_limit]
        motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
    # the motor friction is a registered effect: written by its own MJCF form (numerics friction{i})
    friction = MotorFriction.from_rows(np.array([drive.friction_row for drive in drivetrain.axes]))
    for axis in range(len(drivetrain.axes)):
        friction.apply(spec, None, axis, friction.values(axis))


def _add_home(spec: mujoco.MjSpec, joints: list[ArmJoint], drivetrain: Drivetrain, q: np.ndarray | None,
              source: str) -> None:
    """Add the keyframe ``home``: the arm at ``q`` (rad; None: zero clipped into each joint's range), each
    rotor at its gear ratio times its joint's angle."""
    model = _compile(spec, source)
    if q is None:
        q = np.array([np.clip(0.0, *j.range) for j in joints])
    qpos = np.zeros(model.nq)
    for i, drive in enumerate(drivetrain.axes, start=1):
        qpos[model.joint(f"joint{i}").qposadr[0]] = q[i - 1]
        qpos[model.joint(f"rotor{i}").qposadr[0]] = drive.gear_ratio * q[i - 1]
    spec.add_key(name="home", qpos=qpos.tolist())


#: Names of the tool flange body in ROS-Industrial and Menagerie descriptions, in order of preference.
FLANGE_BODIES = ("tool0", "flange", "attachment", "ee_link", "link_ee", "tool")


def _add_flange(spec: mujoco.MjSpec, last: str) -> None:
    """A site ``flange`` (the payload's mount and the tasks' tool point): on a joint-free body the
    last link carries that is named as a flange (:data:`FLANGE_BODIES`), else at the last link's
    origin."""
    body = spec.body(last)
    below = [b for b in body.find_all(mujoco.mjtObj.mjOBJ_BODY) if not b.joints]
    for wanted in FLANGE_BODIES:
        for candidate in below:
            if candidate.name.lower() == wanted or candidate.name.lower().endswith("_" + wanted):
                candidate.add_site(name="flange")
                return
    body.add_site(name="flange")


def to_xml(spec: mujoco.MjSpec) -> str:
    """The robot as MJCF text that compiles to the same model: numbers as written in the spec, at
    full precision (``savecompiled`` off; the default writes 6 digits)."""
    spec = spec.copy()
    spec.compiler.savecompiled = False
    text = spec.to_xml()
    # MJCF omits values equal to a default, and a class may default them otherwise: make sure
    # the text is the same model
    built, read = spec.compile(), mujoco.MjSpec.from_string(text).compile()
    for name in dir(built):
        ours = getattr(built, name)
        if isinstance(ours, np.ndarray) and not np.array_equal(ours, getattr(read, name)):
            raise RuntimeError(
                f"the MJCF text of {spec.modelname!r} compiles to a different {name}; "
                "this is a bug in faultgen.model.builder"
            )
    return text


def build_files(arm_path: str | Path, drivetrain_path: str | Path) -> str:
    """The MJCF text of the robot built from an arm MJCF file and a full ``drivetrain.toml``, with
    a header naming both (how ``robots/puma560/puma560.xml`` and ``robots/irb6700/irb6700.xml`` are
    made: ``python -m faultgen.model.builder robots/puma560``).

    Raises
    ------
    ArmError, DrivetrainError
        As :func:`build` and :func:`faultgen.model.drivetrain.read`.
    """
    arm_path = Path(arm_path)
    try:
        arm = mujoco.MjSpec.from_file(str(arm_path))
    except ValueError as err:
        raise ArmError(f"{arm_path}: {str(err).strip()}") from None
    n = len(check_arm(arm, str(arm_path)))
    spec = build(arm, read_drivetrain(drivetrain_path, n), source=str(arm_path))
    return (
        f"<!-- Built by faultgen.model.builder from {arm_path.name} (the arm) and "
        f"{Path(drivetrain_path).name} (its drivetrain); edit those and rebuild, not this file. -->\n"
        + to_xml(spec)
    )


if __name__ == "__main__":  # python -m faultgen.model.builder robots/NAME [...]: rebuild NAME.xml
    import sys

    for folder in map(Path, sys.argv[1:]):
        target = folder / f"{folder.resolve().name}.xml"
        target.write_text(build_files(folder / "arm.xml", folder / "drivetrain.toml"))
        print(f"wrote {target}")
