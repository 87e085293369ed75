"""Read an arm from a plain MJCF file. One importer of :mod:`faultgen.model.importers`."""

from __future__ import annotations

import math
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np

from faultgen.model import limits
from faultgen.model.builder import ArmError, ArmJoint, check_arm, one_line
from faultgen.model.arm import Arm, GeometryDropped


def read_mjcf(path: Path) -> Arm:
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except ValueError as err:
        raise ArmError(f"{path}: {one_line(err)}") from None
    try:
        spec.copy().compile()
    except ValueError as err:  # check_arm names any other error, after the joint kinds
        message = str(err).strip()
        if "error opening file" in message.lower() or "mesh" in message.lower():
            spec = _mjcf_without_meshes(path, message)  # an asset it cannot load: read without mesh files
    for text in spec.texts:
        limits.text(path, f"<text name={text.name!r}>", text.data)
    notes = []
    joints = check_arm(spec, str(path))
    for joint in spec.joints:
        changed = [
            k for k in ("damping", "frictionloss", "armature") if np.any(np.asarray(getattr(joint, k)) != 0)
        ]
        if changed:
            notes.append(f"joint {joint.name!r}: {', '.join(changed)} set to 0 (the drivetrain models them)")
            joint.damping, joint.frictionloss, joint.armature = 0.0 * np.asarray(joint.damping), 0.0, 0.0
    return Arm(
        spec=spec,
        kind="MJCF",
        source=path,
        joints=joints,
        speed_limit=np.full(len(joints), math.nan),
        effort_limit=_mjcf_effort(spec, joints),
        description=limits.text(path, "model name", f"{spec.modelname or path.stem} from MJCF {path.name}"),
        notes=notes,
    )


def _mjcf_effort(spec: mujoco.MjSpec, joints: list[ArmJoint]) -> np.ndarray:
    """Joint torque limits an MJCF gives: the joint's ``actuatorfrcrange``, else the force range of
    an actuator on it times its gear (Menagerie's position servos); NaN where neither."""
    model = spec.copy().compile()
    effort = np.full(len(joints), math.nan)
    for k, joint in enumerate(joints):
        j = model.joint(joint.name).id
        if model.jnt_actfrclimited[j] and model.jnt_actfrcrange[j, 1] > 0:
            effort[k] = float(model.jnt_actfrcrange[j, 1])
    for a in range(model.nu):
        if model.actuator_trntype[a] != mujoco.mjtTrn.mjTRN_JOINT or not model.actuator_forcelimited[a]:
            continue
        k = next(
            (k for k, joint in enumerate(joints) if model.joint(joint.name).id == model.actuator_trnid[a, 0]),
            None,
        )
        if k is not None and math.isnan(effort[k]) and model.actuator_forcerange[a, 1] > 0:
            effort[k] = float(model.actuator_forcerange[a, 1] * abs(model.actuator_gear[a, 0]))
    return effort


def _mjcf_without_meshes(path: Path, message: str) -> mujoco.MjSpec:
    tree = ET.parse(path)
    root = tree.getroot()
    meshes = {m.get("name") or Path(m.get("file", "")).stem for m in root.iter("mesh")}
    for parent in list(root.iter()):
        for child in list(parent):
            if child.tag == "mesh" or (
                child.tag == "geom" and (child.get("mesh") in meshes or child.get("type") == "mesh")
            ):
                parent.remove(child)
    warnings.warn(
        f"{path}: meshes left out (dynamics need no geometry): {message}", GeometryDropped, stacklevel=4
    )
    try:
        return mujoco.MjSpec.from_string(ET.tostring(root, encoding="unicode"))
    except ValueError as err:
        raise ArmError(f"{path}: {one_line(err)}") from None


# ---------------------------------------------------------------------------------------- DH --
