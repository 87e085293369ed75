"""Read an arm from a DH table (TOML; the format is in :mod:`faultgen.model.importers`'s
docstring and docs/robots.md, "Your own robot"). One importer of :mod:`faultgen.model.importers`."""

from __future__ import annotations

import math
from pathlib import Path
from typing import NamedTuple

import mujoco
import numpy as np

from faultgen import inputs
from faultgen.axes import MAX_AXES, MIN_AXES
from faultgen.model import limits
from faultgen.model.builder import ArmError, check_arm
from faultgen.model.arm import Arm


DH_KEYS = {"d", "a", "alpha", "offset", "mass", "com", "inertia", "qlim", "speed", "effort"}
DH_TOP = {"convention", "link", "name", "description", "rated_payload", "gravity"}


def _quat_x(angle: float) -> list[float]:
    return [math.cos(angle / 2), math.sin(angle / 2), 0.0, 0.0]


def _quat_z(angle: float) -> list[float]:
    return [math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2)]


def _quat_mul(p: list[float], q: list[float]) -> list[float]:
    out = np.zeros(4)
    mujoco.mju_mulQuat(out, np.asarray(p, dtype=float), np.asarray(q, dtype=float))
    return out.tolist()


#: DH table key -> (low, high, unit): the physical bounds (:mod:`faultgen.model.limits`).
DH_BOUNDS = {
    "d": (-limits.MAX_LENGTH, limits.MAX_LENGTH, "m"),
    "a": (-limits.MAX_LENGTH, limits.MAX_LENGTH, "m"),
    "alpha": (-limits.MAX_ANGLE, limits.MAX_ANGLE, "rad"),
    "offset": (-limits.MAX_ANGLE, limits.MAX_ANGLE, "rad"),
    "mass": (0.0, limits.MAX_MASS, "kg"),
    "com": (-limits.MAX_LENGTH, limits.MAX_LENGTH, "m"),
    "inertia": (-limits.MAX_INERTIA, limits.MAX_INERTIA, "kg m^2"),
    "qlim": (-limits.MAX_ANGLE, limits.MAX_ANGLE, "rad"),
    "speed": (limits.MIN_SPEED, limits.MAX_SPEED, "rad/s"),
    "effort": (limits.MIN_EFFORT, limits.MAX_EFFORT, "N m"),
    "rated_payload": (0.0, limits.MAX_PAYLOAD, "kg"),
    "gravity": (-limits.MAX_GRAVITY, limits.MAX_GRAVITY, "m/s^2"),
}


def _number(path: Path, where: str, key: str, value, length: int | None = None) -> float | list[float]:
    low, high, unit = DH_BOUNDS[key]
    if length is None:
        return limits.number(path, where, key, value, low, high, unit)
    if not isinstance(value, list) or len(value) != length:
        raise ArmError(f"{path}: {where}: {key} = {value!r}; expected {length} numbers in {low:g} .. {high:g} {unit}")
    return [limits.number(path, where, key, v, low, high, unit) for v in value]


class _Link(NamedTuple):
    """One [[link]] row of a DH table, checked: lengths in m, angles in rad, mass in kg, the centre of
    mass in m and the inertia tensor (3, 3) in kg m^2 in the link's DH frame, speed and effort limits
    (NaN: not given)."""

    d: float
    a: float
    alpha: float
    offset: float
    mass: float
    com: list[float]
    tensor: np.ndarray
    qlim: list[float]
    speed: float
    effort: float


def read_dh(path: Path) -> Arm:
    """The arm a DH table (TOML) describes: one MuJoCo body per [[link]] row, standard or modified
    (Craig) convention.

    Raises
    ------
    ArmError
        If the file is not such a table, a value is missing or out of its bounds, or the arm fails
        :func:`check_arm`.
    """
    try:
        data = inputs.read_toml(path, "TOML DH table")
    except inputs.InputError as err:
        raise ArmError(str(err)) from None
    unknown = sorted(set(data) - DH_TOP)
    if unknown:
        raise ArmError(f"{path}: unknown key {unknown[0]!r}; expected some of: {', '.join(sorted(DH_TOP))}")
    convention = data.get("convention", "standard")
    if convention not in ("standard", "modified"):
        raise ArmError(f"{path}: convention = {convention!r}; expected 'standard' or 'modified'")
    links = data.get("link", [])
    if not isinstance(links, list) or not MIN_AXES <= len(links) <= MAX_AXES:
        count = len(links) if isinstance(links, list) else 0
        raise ArmError(f"{path}: {count} [[link]] rows (revolute joints); expected {MIN_AXES} to {MAX_AXES}")
    name = limits.text(path, "name", data.get("name", path.stem))
    spec = mujoco.MjSpec()
    spec.modelname = name
    spec.compiler.degree = False
    spec.compiler.autolimits = True
    if "gravity" in data:
        spec.option.gravity = _number(path, "top", "gravity", data["gravity"], 3)
    parent: mujoco.MjsBody | mujoco.MjsFrame = spec.worldbody.add_body(name="base")
    rows = [_link(path, i, row) for i, row in enumerate(links, start=1)]
    for i, link in enumerate(rows, start=1):
        parent = _add_link(parent, i, link, convention)
    arm_joints = check_arm(spec, str(path))
    payload = (
        _number(path, "top", "rated_payload", data["rated_payload"]) if "rated_payload" in data else math.nan
    )
    return Arm(
        spec=spec,
        kind="DH table",
        source=path,
        joints=arm_joints,
        speed_limit=np.array([link.speed for link in rows]),
        effort_limit=np.array([link.effort for link in rows]),
        payload=payload,
        description=limits.text(
            path, "description", data.get("description", f"{name} from the {convention} DH table {path.name}")
        ),
    )


def _link(path: Path, i: int, row) -> _Link:
    """Link ``i``'s row of the DH table at ``path``, checked.

    Raises
    ------
    ArmError
        If it is not a table, has an unknown key, misses one, a value is out of :data:`DH_BOUNDS`, its
        limits are not lower < upper, or its mass or inertia is not positive (definite).
    """
    where = f"link {i}"
    if not isinstance(row, dict):
        raise ArmError(f"{path}: {where} must be a table")
    bad = sorted(set(row) - DH_KEYS)
    if bad:
        raise ArmError(
            f"{path}: {where}: unknown key {bad[0]!r}; expected some of: {', '.join(sorted(DH_KEYS))}"
        )
    for key in ("d", "a", "alpha", "mass", "com", "inertia", "qlim"):
        if key not in row:
            raise ArmError(
                f"{path}: {where}: {key} is missing" + ("; a joint needs limits" if key == "qlim" else "")
            )
    d, a, alpha = (_number(path, where, k, row[k]) for k in ("d", "a", "alpha"))
    offset = _number(path, where, "offset", row.get("offset", 0.0))
    mass = _number(path, where, "mass", row["mass"])
    com = _number(path, where, "com", row["com"], 3)
    inertia = _number(path, where, "inertia", row["inertia"], 6)
    qlim = _number(path, where, "qlim", row["qlim"], 2)
    if not qlim[0] < qlim[1]:
        raise ArmError(f"{path}: {where}: qlim = {qlim!r}; expected lower < upper")
    tensor = np.array(
        [
            [inertia[0], inertia[3], inertia[4]],
            [inertia[3], inertia[1], inertia[5]],
            [inertia[4], inertia[5], inertia[2]],
        ]
    )
    if mass <= 0 or np.any(np.linalg.eigvalsh(tensor) <= 0):
        raise ArmError(
            f"{path}: {where}: mass {mass!r} kg, inertia {inertia!r} kg m^2; a link needs a positive "
            "mass and a positive-definite inertia"
        )
    speed = _number(path, where, "speed", row["speed"]) if "speed" in row else math.nan
    effort = _number(path, where, "effort", row["effort"]) if "effort" in row else math.nan
    return _Link(d, a, alpha, offset, mass, com, tensor, qlim, speed, effort)


def _add_link(parent, i: int, link: _Link, convention: str) -> mujoco.MjsFrame:
    """Add link ``i`` (body ``link{i}``, joint ``joint{i}``, DH frame ``dh{i}``) under ``parent`` in the
    ``convention`` ('standard' or 'modified'); return its DH frame, the next link's parent."""
    d, a, alpha, offset, qlim = link.d, link.a, link.alpha, link.offset, link.qlim
    if convention == "standard":
        # T_i = Rz(theta) Tz(d) Tx(a) Rx(alpha): the joint turns link i about z of frame i-1,
        # the fixed part is a frame dh{i} holding the link's inertial and the next link
        body = parent.add_body(name=f"link{i}", quat=_quat_z(offset))
        body.add_joint(name=f"joint{i}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], range=qlim)
        frame = body.add_frame(name=f"dh{i}", pos=[a, 0.0, d], quat=_quat_x(alpha))
    else:
        # Craig: T_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta) Tz(d): the body is frame i
        pos = [a, -d * math.sin(alpha), d * math.cos(alpha)]
        body = parent.add_body(name=f"link{i}", pos=pos, quat=_quat_mul(_quat_x(alpha), _quat_z(offset)))
        body.add_joint(name=f"joint{i}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], range=qlim)
        frame = body.add_frame(name=f"dh{i}")
    # the inertial is written in the DH frame of the link: a massless child body would add a
    # joint-free body; set the link's own inertial through the frame's pose instead
    _set_inertial(body, frame, link.mass, link.com, link.tensor)
    return frame


def _set_inertial(
    body: mujoco.MjsBody, frame: mujoco.MjsFrame, mass: float, com: list[float], tensor: np.ndarray
) -> None:
    """The body's inertial from a centre of mass and an inertia tensor given in ``frame`` (a child
    frame of the body)."""
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, np.asarray(frame.quat, dtype=float))
    rotation = rotation.reshape(3, 3)
    body.explicitinertial = True
    body.mass = mass
    body.ipos = (np.asarray(frame.pos) + rotation @ np.asarray(com)).tolist()
    full = rotation @ tensor @ rotation.T
    body.fullinertia = [full[0, 0], full[1, 1], full[2, 2], full[0, 1], full[0, 2], full[1, 2]]
