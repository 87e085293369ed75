"""Read an arm from a URDF (or xacro), a plain MJCF or a DH table into an ``mujoco.MjSpec``: the
importer registry (:data:`IMPORTERS`, by file suffix) over import_urdf, import_mjcf and import_dh.

Every reader returns an :class:`Arm`: the spec (checked by
:func:`faultgen.model.builder.check_arm`) and the data the drivetrain sizing needs that the
spec does not hold (joint speed and effort limits of a URDF or DH table). What faultgen cannot
use is refused with the element named (:class:`~faultgen.model.builder.ArmError`), before anything
is written; geometry that cannot be loaded (COLLADA meshes, ``package://`` paths that do not
resolve) is dropped with one warning, since dynamics need no geometry.

URDF goes through MuJoCo's own URDF compiler (``MjSpec.from_string``); xacro is expanded to URDF
by faultgen's own expander first (:mod:`faultgen.model.xacro`: no code runs). A DH table is a
TOML file (docs/robots.md, "Your own robot")::

    convention = "standard"        # or "modified" (Craig)
    [[link]]                       # one per axis, base first
    d = 0.089159                   # m
    a = 0.0                        # m
    alpha = 1.5707963267948966     # rad
    offset = 0.0                   # rad, joint angle at which theta = offset (optional)
    mass = 3.7                     # kg
    com = [0.0, -0.02561, 0.00193] # m, in the link's DH frame
    inertia = [0.0102, 0.0102, 0.00666, 0.0, 0.0, 0.0]  # kg m^2 about the COM: Ixx Iyy Izz Ixy Ixz Iyz
    qlim = [-6.283, 6.283]         # rad
    speed = 3.14                   # rad/s, joint speed limit (optional, sizes the gear ratio)
    effort = 150.0                 # N m, joint torque limit (optional, sizes the motor)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

from faultgen.model import limits, mjcf, sources, xacro
from faultgen.model.arm import MESH_TYPES, Arm, GeometryDropped
from faultgen.model.builder import ArmError
from faultgen.model.import_dh import read_dh
from faultgen.model.import_mjcf import read_mjcf
from faultgen.model.import_urdf import read_urdf

__all__ = ["IMPORTERS", "MESH_TYPES", "Arm", "GeometryDropped", "read"]


def read(path: str | Path, packages: dict[str, str | Path] | None = None) -> Arm:
    """Read an arm from ``path``: ``.urdf``, ``.xacro`` (``.urdf.xacro``), ``.xml`` (MJCF, or URDF
    when its root is ``<robot>``) or ``.toml`` (a DH table, this module's docstring).

    Only ``path``'s folder and the ``packages`` folders are read (:mod:`faultgen.model.sources`):
    includes, meshes and other files named outside them are refused, and ``package://NAME/...``
    and ``$(find NAME)`` resolve only through ``packages``.

    Parameters
    ----------
    path : str or Path
        The arm file, a regular file of at most ``sources.MAX_DESCRIPTION_BYTES``.
    packages : dict of str to path, optional
        ROS package name -> folder (``faultgen robots add --package NAME=DIR``).

    Raises
    ------
    ArmError
        If the file is missing or of another type, or describes an arm faultgen cannot model
        (:func:`faultgen.model.builder.check_arm`; URDF: also a floating, planar, prismatic or
        continuous joint, or a revolute joint without ``<limit>``), or a value is out of the
        bounds of :mod:`faultgen.model.limits`, naming the element; or it names a file outside the
        folders it may read, an MJCF plugin or a xacro construct that would run code.
    """
    path = Path(path)
    arm = _read(path, sources.check_packages(packages))
    limits.check_model(arm.spec, path)
    for k, joint in enumerate(arm.joints):
        where = f"joint {joint.name!r}"
        for key, values, low, high, unit in (
            ("speed limit", arm.speed_limit, limits.MIN_SPEED, limits.MAX_SPEED, "rad/s"),
            ("effort limit", arm.effort_limit, limits.MIN_EFFORT, limits.MAX_EFFORT, "N m"),
        ):
            if not math.isnan(values[k]):
                limits.number(path, where, key, float(values[k]), low, high, unit)
    return arm


#: The importers by file suffix: ``reader(path, packages) -> Arm``. ``.xml`` is MJCF, or URDF when
#: its root is ``<robot>``; ``.xacro`` is expanded to URDF first (no code runs).
IMPORTERS: dict[str, Callable[[Path, dict[str, Path]], Arm]] = {
    ".urdf": lambda path, packages: read_urdf(sources.read_text(path, what="robot description", error=ArmError),
                                              path, "URDF", packages),
    ".xacro": lambda path, packages: _read_xacro(path, packages),
    ".toml": lambda path, packages: read_dh(path),
    ".xml": lambda path, packages: _read_xml(path, packages),
}


def _read(path: Path, packages: dict[str, Path]) -> Arm:
    suffix = path.suffix.lower()
    if suffix not in IMPORTERS:
        raise ArmError(
            f"{path}: unknown arm file type {suffix!r}; expected .urdf, .xacro, .xml (MJCF) or .toml (DH table)"
        )
    return IMPORTERS[suffix](path, packages)


def _read_xacro(path: Path, packages: dict[str, Path]) -> Arm:
    sources.read_bytes(path, what="xacro file", error=ArmError)
    return read_urdf(xacro.expand(path, packages), path, "xacro", packages)


def _read_xml(path: Path, packages: dict[str, Path]) -> Arm:
    text = sources.read_text(path, what="robot description", error=ArmError)
    root = sources.parse_xml(text, path, ArmError)
    if root.tag == "robot":
        return read_urdf(text, path, "URDF", packages)
    mjcf.check_files(path, root, packages)
    return read_mjcf(path)
