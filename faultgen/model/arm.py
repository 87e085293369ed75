"""What every arm importer returns (:class:`Arm`), and the warning for geometry it drops
(:mod:`faultgen.model.importers` names the importers)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from faultgen.model.builder import ArmJoint


#: Mesh file types MuJoCo loads.
MESH_TYPES = (".stl", ".obj", ".msh")


class GeometryDropped(UserWarning):
    """Meshes of the source that could not be used were left out (the dynamics do not need them)."""


@dataclass
class Arm:
    """An arm read from a file, ready for :func:`faultgen.model.builder.build`.

    Attributes
    ----------
    spec : mujoco.MjSpec
        The arm; its joints keep the source's names.
    kind : str
        ``"URDF"``, ``"xacro"``, ``"MJCF"`` or ``"DH table"``.
    source : Path
        The file.
    joints : list of ArmJoint
        Its N revolute joints, base first (:func:`~faultgen.model.builder.check_arm`).
    speed_limit, effort_limit : ndarray of shape (N,)
        Joint speed limit in rad/s and torque limit in N m given by the source, NaN where it gives
        none (URDF ``<limit velocity effort>``; an effort of 0, as ROS-Industrial writes, is none).
    payload : float
        Rated payload in kg if the source gives one (a DH table's ``rated_payload``), else NaN.
    description : str
        One line naming the source.
    notes : list of str
        What the reader changed or dropped, for the robot's README.
    urdf : str
        For a URDF or xacro: the URDF as compiled (meshes left out, inertials filled in), the
        input of an independent check (tests/test_robot_import.py runs Pinocchio on it).
    mesh_inertials : list of str
        Links whose mass and inertia were computed from their meshes (no ``<inertial>`` in the
        source: uniform solids of 1000 kg/m^3), for the plausibility report
        (:mod:`faultgen.model.plausibility`).
    """

    spec: mujoco.MjSpec
    kind: str
    source: Path
    joints: list[ArmJoint]
    speed_limit: np.ndarray
    effort_limit: np.ndarray
    payload: float = math.nan
    description: str = ""
    notes: list[str] = field(default_factory=list)
    urdf: str = ""
    mesh_inertials: list[str] = field(default_factory=list)
