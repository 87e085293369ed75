"""Physical bounds on the numbers a robot description gives, checked where it is read.

A value outside them is refused with the file, the element (joint, link, DH row) and the
expected range named (:class:`~faultgen.model.builder.ArmError`): no industrial arm comes near
them, and past them the sizing and the trajectory generator overflow (``1e300``) or divide by
nothing. docs/reliability.md, "Threat model: robot descriptions", lists them.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np

from faultgen.model.builder import ArmError

#: m: link lengths, offsets, positions, geometry sizes (the largest arms reach about 4 m).
MAX_LENGTH = 100.0
#: rad: joint limits, DH angles, URDF rpy (16 turns; a wrist axis may turn a few).
MAX_ANGLE = 100.0
#: rad/s: joint speed limits (small arms' wrists reach about 20).
MAX_SPEED = 100.0
#: N m: joint torque limits (a 2 t payload arm's axis 2: about 1e5).
MAX_EFFORT = 1e6
#: rad/s and N m: the smallest speed and torque limits a source may give (0 in a URDF: none given);
#: below them the sizing's gear ratio and motor overflow.
MIN_SPEED, MIN_EFFORT = 1e-3, 1e-3
#: kg: one link's mass (a heavy arm's base: about 2 t).
MAX_MASS = 1e5
#: kg m^2: one link's principal inertia.
MAX_INERTIA = 1e6
#: kg: rated payload (the largest arms carry 2.3 t).
MAX_PAYLOAD = 1e4
#: m/s^2: the gravity vector's components.
MAX_GRAVITY = 100.0
#: characters: a robot's name or description (one line, written into the robot's MJCF).
MAX_TEXT = 1000

#: URDF element path under a joint or link -> {attribute: (low, high, unit)}; values are lists
#: (xyz, rpy, size) or one number; each is checked to be a finite number in [low, high].
URDF = {
    "origin": {"xyz": (-MAX_LENGTH, MAX_LENGTH, "m"), "rpy": (-MAX_ANGLE, MAX_ANGLE, "rad")},
    "axis": {"xyz": (-MAX_LENGTH, MAX_LENGTH, "1")},
    "limit": {
        "lower": (-MAX_ANGLE, MAX_ANGLE, "rad"),
        "upper": (-MAX_ANGLE, MAX_ANGLE, "rad"),
        "velocity": (0.0, MAX_SPEED, "rad/s"),
        "effort": (0.0, MAX_EFFORT, "N m"),
    },
    "inertial/origin": {"xyz": (-MAX_LENGTH, MAX_LENGTH, "m"), "rpy": (-MAX_ANGLE, MAX_ANGLE, "rad")},
    "inertial/mass": {"value": (0.0, MAX_MASS, "kg")},
    "inertial/inertia": {
        key: (-MAX_INERTIA, MAX_INERTIA, "kg m^2") for key in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
    },
    "*/geometry/box": {"size": (0.0, MAX_LENGTH, "m")},
    "*/geometry/cylinder": {"radius": (0.0, MAX_LENGTH, "m"), "length": (0.0, MAX_LENGTH, "m")},
    "*/geometry/sphere": {"radius": (0.0, MAX_LENGTH, "m")},
    "*/geometry/mesh": {"scale": (0.0, MAX_LENGTH, "1")},
    "*/origin": {"xyz": (-MAX_LENGTH, MAX_LENGTH, "m"), "rpy": (-MAX_ANGLE, MAX_ANGLE, "rad")},
}


def number(path: Path | str, where: str, key: str, value, low: float, high: float, unit: str) -> float:
    """``value`` as a float in [low, high], or an ArmError naming the file, place and key."""
    ok = isinstance(value, (int, float)) and not isinstance(value, bool)
    if ok:
        value = float(value)
        ok = math.isfinite(value) and low <= value <= high
    if not ok:
        raise ArmError(f"{path}: {where}: {key} = {value!r}; expected a number in {low:g} .. {high:g} {unit}")
    return value


def check_urdf(root: ET.Element, path: Path) -> None:
    """Every number of the URDF's joints and links a finite number within :data:`URDF`'s bounds,
    and each revolute joint's lower limit below its upper."""
    for element in [*root.iter("joint"), *root.iter("link")]:
        where = f"{element.tag} {element.get('name', '?')!r}"
        for sub, keys in URDF.items():
            for node in element.findall(sub):
                for key, (low, high, unit) in keys.items():
                    text = node.get(key)
                    if text is None or (sub == "limit" and key in ("velocity", "effort") and not text.strip()):
                        continue
                    for word in text.split() or [text]:
                        try:
                            value = float(word)
                        except ValueError:
                            value = word
                        number(path, where, f'<{sub.rsplit("/", 1)[-1]} {key}>', value, low, high, unit)
        limit = element.find("limit")
        for key, low, unit in (("velocity", MIN_SPEED, "rad/s"), ("effort", MIN_EFFORT, "N m")):
            value = float((limit.get(key) or "0").strip() or 0) if limit is not None else 0.0
            if 0 < value < low:
                raise ArmError(
                    f"{path}: {where}: <limit {key}> = {value!r}; expected 0 (not given) or a number in "
                    f"{low:g} .. {MAX_SPEED if key == 'velocity' else MAX_EFFORT:g} {unit}"
                )
        if element.tag == "joint" and element.get("type") == "revolute" and limit is not None:
            lower, upper = limit.get("lower"), limit.get("upper")
            if lower is not None and upper is not None and not float(lower) < float(upper):
                raise ArmError(
                    f"{path}: {where}: <limit lower={lower} upper={upper}>; expected lower < upper"
                )


def check_model(spec: mujoco.MjSpec, path: Path | str) -> None:
    """The compiled arm's masses, inertias, positions and joint ranges within the bounds (what a
    source of any kind gives; MJCF values reach MuJoCo unchecked otherwise)."""
    check_compiled(spec.copy().compile(), path)


def check_compiled(model: mujoco.MjModel, path: Path | str) -> None:
    """As :func:`check_model`, on an arm already compiled (a robot folder's MJCF, read by
    :func:`faultgen.model.robots.load`).

    Raises
    ------
    ArmError
        Naming the file, the body or joint, the value and the bound.
    """
    for value in model.opt.gravity:
        number(path, "<option gravity>", "gravity", float(value), -MAX_GRAVITY, MAX_GRAVITY, "m/s^2")
    for body in range(1, model.nbody):
        name = model.body(body).name or f"#{body}"
        number(path, f"body {name!r}", "mass", float(model.body_mass[body]), 0.0, MAX_MASS, "kg")
        for value in model.body_inertia[body]:
            number(path, f"body {name!r}", "inertia", float(value), 0.0, MAX_INERTIA, "kg m^2")
        for value in np.concatenate([model.body_pos[body], model.body_ipos[body]]):
            number(path, f"body {name!r}", "position", float(value), -MAX_LENGTH, MAX_LENGTH, "m")
    for joint in range(model.njnt):
        for value in model.jnt_range[joint]:
            number(path, f"joint {model.joint(joint).name!r}", "range", float(value), -MAX_ANGLE, MAX_ANGLE, "rad")


def text(path: Path | str, what: str, value: str) -> str:
    """A name or description to be written into the robot: one line of printable text, without
    ``]]>`` (MuJoCo writes custom text as XML CDATA, which that string would end)."""
    value = str(value)
    bad = "]]>" if "]]>" in value else next((c for c in value if not c.isprintable()), None)
    if bad is not None or len(value) > MAX_TEXT:
        raise ArmError(
            f"{path}: {what} {value[:80]!r}: "
            + (f"contains {bad!r}" if bad is not None else f"{len(value)} characters")
            + f"; expected one line of printable text without ']]>', at most {MAX_TEXT} characters"
        )
    return value
