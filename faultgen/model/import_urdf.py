"""Read an arm from a URDF (or expanded xacro) through MuJoCo's own URDF compiler
(``MjSpec.from_string``): meshes resolved within the allowed folders or dropped, missing
inertials filled in. One importer of :mod:`faultgen.model.importers`."""

from __future__ import annotations

import copy
import math
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np

from faultgen import inputs
from faultgen.axes import MAX_AXES, MIN_AXES
from faultgen.model import limits, mjcf, sources
from faultgen.model.builder import ArmError, check_arm, one_line
from faultgen.model.arm import MESH_TYPES, Arm, GeometryDropped


def _resolve_mesh(filename: str, path: Path, packages: dict[str, Path]) -> Path | None:
    """The mesh file a URDF names, or None if it cannot be found: ``package://pkg/rest`` is
    ``rest`` in the folder named for ``pkg`` (``--package``), else in the URDF's folder; ``file://``
    and relative paths from the URDF's folder.

    Raises
    ------
    ArmError
        If the name leads outside the URDF's folder and the package folders (an absolute path,
        ``..``, a symbolic link out).
    """
    base = path.parent
    allowed = sources.roots(path, packages)
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://") :].partition("/")
        candidates = [packages[package] / rest] if package in packages else []
        candidates.append(base / rest)
    else:
        name = filename[len("file://") :] if filename.startswith("file://") else filename
        candidates = [Path(name) if Path(name).is_absolute() else base / name]
    for candidate in candidates:
        if not any(inputs.inside(candidate, root) for root in allowed):
            raise ArmError(
                f'{path}: <mesh filename="{filename}"> is outside the folder {base.resolve()} and the '
                "--package folders; a robot description may read only those"
            )
    for candidate in candidates:
        if candidate.is_file():
            return candidate.resolve()
    return None


def read_urdf(text: str, path: Path, kind: str, packages: dict[str, Path]) -> Arm:
    """The arm a URDF (or expanded xacro) ``text`` read from ``path`` describes, compiled by MuJoCo.

    Raises
    ------
    ArmError
        If it is not a serial chain of 2 to 7 revolute joints with limits, or MuJoCo cannot compile it.
    """
    root = sources.parse_xml(text, path, ArmError)
    if root.tag != "robot":
        raise ArmError(f"{path}: root element <{root.tag}>; a URDF has <robot>")
    links = sum(1 for _ in root.iter("link"))
    if links > mjcf.MAX_LINKS:
        raise ArmError(f"{path}: {links} links; a robot arm description may have at most {mjcf.MAX_LINKS}")
    limits.check_urdf(root, path)
    notes = []
    names, speed, effort = _revolute_joints(root, path, notes)
    dropped, named, unnamed = _drop_meshes(root, path, packages, notes)
    _compiler_options(root)
    spec, filled = _spec_with_inertials(root, path, notes)
    try:
        joints = check_arm(spec, str(path))
    except ArmError as err:
        if dropped and unnamed:  # the likely cause: link masses came from meshes left out
            raise ArmError(
                f"{err}; {len(dropped)} meshes were left out, those of package {unnamed[0]!r} as no "
                f"--package {unnamed[0]}=DIR names its folder" + sources.hint(unnamed[0], path.parent)
            ) from None
        raise
    extension = root.find("mujoco")
    root.remove(extension)
    for mesh, filename in named.items():  # the written URDF keeps the source's names, no local path
        mesh.set("filename", filename)
    urdf = ET.tostring(root, encoding="unicode")
    return Arm(
        spec=spec,
        kind=kind,
        source=path,
        joints=joints,
        speed_limit=np.array([speed.get(j.name, math.nan) for j in joints]),
        effort_limit=np.array([effort.get(j.name, math.nan) for j in joints]),
        description=limits.text(path, "robot name", f"{root.get('name', path.stem)} from {kind} {path.name}"),
        notes=notes,
        urdf=urdf,
        mesh_inertials=filled,
    )


def _revolute_joints(
    root: ET.Element, path: Path, notes: list[str]
) -> tuple[list[str], dict[str, float], dict[str, float]]:
    """(the revolute joints' names, their speed limits in rad/s, their effort limits in N m; NaN where
    not given) of a URDF's serial chain; each joint's ``<dynamics>`` is removed (a note in ``notes``).

    Raises
    ------
    ArmError
        On a closed chain, a floating, planar, prismatic or continuous joint, a revolute one without
        limits, a mimic joint, or fewer than MIN_AXES or more than MAX_AXES revolute joints.
    """
    speed, effort, names = {}, {}, []
    parents: dict[str, str] = {}
    for joint in root.iter("joint"):
        name, kind_ = joint.get("name", "?"), joint.get("type", "?")
        parent, child = joint.find("parent"), joint.find("child")
        if parent is not None and child is not None:
            if child.get("link") in parents:
                raise ArmError(
                    f"{path}: link {child.get('link')!r} has two parent joints: a closed chain; "
                    "expected a serial chain"
                )
            parents[child.get("link")] = parent.get("link")
        if kind_ == "floating":
            raise ArmError(f"{path}: joint {name!r} is floating: a floating base; a robot arm must be fixed")
        if kind_ == "planar":
            raise ArmError(f"{path}: joint {name!r} is planar; expected revolute joints only")
        if kind_ == "prismatic":
            raise ArmError(f"{path}: joint {name!r} is prismatic; faultgen models revolute axes only")
        if kind_ == "continuous":
            raise ArmError(
                f"{path}: joint {name!r} is continuous (no joint limits); give it type revolute "
                "with <limit lower upper>"
            )
        if kind_ == "revolute":
            limit = joint.find("limit")
            if limit is None or limit.get("lower") is None or limit.get("upper") is None:
                raise ArmError(
                    f"{path}: joint {name!r} has no joint limits; expected <limit lower=... upper=...>"
                )
            names.append(name)
            # 0 or absent: not given (ROS-Industrial writes effort="0"); limits.check_urdf bounds them
            v, e = (float(limit.get(key) or 0) for key in ("velocity", "effort"))
            speed[name] = v if v > 0 else math.nan
            effort[name] = e if e > 0 else math.nan
        if joint.find("mimic") is not None:
            raise ArmError(
                f"{path}: joint {name!r} mimics another joint: a coupled (closed) chain; expected "
                "independent joints"
            )
        dynamics = joint.find("dynamics")
        if dynamics is not None:
            joint.remove(dynamics)
            notes.append(f"joint {name!r}: <dynamics> dropped (the drivetrain models damping and friction)")
    if not MIN_AXES <= len(names) <= MAX_AXES:
        raise ArmError(
            f"{path}: {len(names)} revolute joints ({', '.join(names) or 'none'}); expected "
            f"{MIN_AXES} to {MAX_AXES} in a serial chain"
        )
    return names, speed, effort


def _drop_meshes(
    root: ET.Element, path: Path, packages: dict[str, Path], notes: list[str]
) -> tuple[list[str], dict[ET.Element, str], list[str]]:
    """Remove the visual and collision elements whose mesh MuJoCo cannot load (not found, or not one of
    MESH_TYPES), with one GeometryDropped warning and a note; point the others at their resolved files.
    Return (the dropped file names, each kept ``<mesh>`` -> its name in the source, the packages of
    dropped meshes no ``--package`` names)."""
    dropped, named, unnamed = [], {}, []
    for link in root.iter("link"):
        for tag in ("visual", "collision"):
            for element in list(link.findall(tag)):
                mesh = element.find("geometry/mesh")
                if mesh is None:
                    continue
                resolved = _resolve_mesh(mesh.get("filename", ""), path, packages)
                if resolved is None or resolved.suffix.lower() not in MESH_TYPES:
                    dropped.append(mesh.get("filename", ""))
                    link.remove(element)
                else:
                    named[mesh] = mesh.get("filename", "")
                    mesh.set("filename", str(resolved))
    if dropped:
        unnamed = sorted(
            {f[len("package://") :].partition("/")[0] for f in dropped if f.startswith("package://")} - set(packages)
        )
        warnings.warn(
            f"{path}: {len(dropped)} meshes left out (dynamics need no geometry; MuJoCo loads "
            f"{', '.join(MESH_TYPES)} files that resolve), e.g. {dropped[0]}"
            + (
                f"; name the folder of package {unnamed[0]!r} with --package {unnamed[0]}=DIR"
                + sources.hint(unnamed[0], path.parent)
                if unnamed
                else ""
            ),
            GeometryDropped,
            stacklevel=4,
        )
        notes.append(f"{len(dropped)} meshes left out: COLLADA or unresolvable (dynamics need no geometry)")
    return dropped, named, unnamed


def _compiler_options(root: ET.Element) -> None:
    """Set MuJoCo's options for the URDF compiler in ``root``: keep visual geoms, full mesh paths, every
    link a body; of the source's own ``<mujoco>`` only compiler settings that read no file are kept."""
    extension = root.find("mujoco")
    if extension is None:
        extension = ET.SubElement(root, "mujoco")
    for child in list(extension):
        if child.tag != "compiler":
            extension.remove(child)
    compiler = extension.find("compiler")
    if compiler is None:
        compiler = ET.SubElement(extension, "compiler")
    for key in ("meshdir", "texturedir", "assetdir"):
        compiler.attrib.pop(key, None)
    compiler.set("strippath", "false")
    compiler.set("discardvisual", "false")
    compiler.set("fusestatic", "false")


def _spec_with_inertials(root: ET.Element, path: Path, notes: list[str]) -> tuple[mujoco.MjSpec, list[str]]:
    """(MuJoCo's spec of ``root``, the links whose missing ``<inertial>`` was computed from their meshes
    at DENSITY, with a GeometryDropped warning and a note)."""
    spec = _urdf_spec(root, path)
    filled = _fill_inertials(root, spec, path)
    if filled:
        warnings.warn(
            f"{path}: links {', '.join(filled)} have no <inertial>; theirs are computed from their meshes "
            f"at {DENSITY:g} kg/m^3 (MuJoCo's compiler)",
            GeometryDropped,
            stacklevel=4,
        )
        notes.append(
            f"links {', '.join(filled)}: no <inertial> in the URDF; mass, centre of mass and inertia "
            f"computed from their meshes as uniform solids of {DENSITY:g} kg/m^3 by MuJoCo's compiler "
            "(written into urdf_used.urdf)"
        )
        spec = _urdf_spec(root, path)
    return spec, filled


#: Density of the solids a link without <inertial> is taken to be, kg/m^3 (MuJoCo's default).
DENSITY = 1000.0


def _urdf_spec(root: ET.Element, path: Path) -> mujoco.MjSpec:
    try:
        return mujoco.MjSpec.from_string(ET.tostring(root, encoding="unicode"))
    except ValueError as err:
        raise ArmError(f"{path}: MuJoCo's URDF compiler: {one_line(err)}") from None


def _fill_inertials(root: ET.Element, spec: mujoco.MjSpec, path: Path) -> list[str]:
    """Write an ``<inertial>`` into each link that has none but has collision geometry MuJoCo can
    weigh (uniform solids of :data:`DENSITY`); return those links' names. A link with neither stays
    massless (and :func:`check_arm` refuses it if it moves)."""
    # weigh the collision geometry only: a URDF's visual meshes repeat it (and would count twice)
    solids = copy.deepcopy(root)
    for link in solids.iter("link"):
        for visual in link.findall("visual"):
            link.remove(visual)
    try:
        model = mujoco.MjSpec.from_string(ET.tostring(solids, encoding="unicode")).compile()
    except ValueError:
        return []  # check_arm names the body
    from scipy.spatial.transform import Rotation

    filled = []
    for link in root.iter("link"):
        name = link.get("name", "")
        if link.find("inertial") is not None or mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name) < 0:
            continue
        body = model.body(name).id
        if model.body_mass[body] <= 0:
            continue
        w, x, y, z = model.body_iquat[body]
        rpy = Rotation.from_quat([x, y, z, w]).as_euler("xyz")
        inertial = ET.SubElement(link, "inertial")
        ET.SubElement(
            inertial,
            "origin",
            xyz=" ".join(repr(float(v)) for v in model.body_ipos[body]),
            rpy=" ".join(repr(float(v)) for v in rpy),
        )
        ET.SubElement(inertial, "mass", value=repr(float(model.body_mass[body])))
        ixx, iyy, izz = (repr(float(v)) for v in model.body_inertia[body])
        ET.SubElement(inertial, "inertia", ixx=ixx, iyy=iyy, izz=izz, ixy="0", ixz="0", iyz="0")
        filled.append(name)
    return filled
