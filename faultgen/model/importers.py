"""Read an arm from a URDF (or xacro), a plain MJCF or a DH table into an ``mujoco.MjSpec``.

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

import copy
import math
import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from faultgen import inputs
from faultgen.axes import MAX_AXES, MIN_AXES
from faultgen.model import limits, mjcf, sources, xacro
from faultgen.model.builder import ArmError, ArmJoint, check_arm, one_line

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


def _read(path: Path, packages: dict[str, Path]) -> Arm:
    suffix = path.suffix.lower()
    if suffix not in (".xacro", ".urdf", ".toml", ".xml"):
        raise ArmError(
            f"{path}: unknown arm file type {suffix!r}; expected .urdf, .xacro, .xml (MJCF) or .toml (DH table)"
        )
    if suffix == ".xacro":
        sources.read_bytes(path, what="xacro file", error=ArmError)
        return _read_urdf(xacro.expand(path, packages), path, "xacro", packages)
    if suffix == ".toml":
        return _read_dh(path)
    text = sources.read_text(path, what="robot description", error=ArmError)
    if suffix == ".urdf":
        return _read_urdf(text, path, "URDF", packages)
    root = sources.parse_xml(text, path, ArmError)
    if root.tag == "robot":
        return _read_urdf(text, path, "URDF", packages)
    mjcf.check_files(path, root, packages)
    return _read_mjcf(path)


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
        if not any(sources.inside(candidate, root) for root in allowed):
            raise ArmError(
                f'{path}: <mesh filename="{filename}"> is outside the folder {base.resolve()} and the '
                "--package folders; a robot description may read only those"
            )
    for candidate in candidates:
        if candidate.is_file():
            return candidate.resolve()
    return None


def _read_urdf(text: str, path: Path, kind: str, packages: dict[str, Path]) -> Arm:
    root = sources.parse_xml(text, path, ArmError)
    if root.tag != "robot":
        raise ArmError(f"{path}: root element <{root.tag}>; a URDF has <robot>")
    links = sum(1 for _ in root.iter("link"))
    if links > mjcf.MAX_LINKS:
        raise ArmError(f"{path}: {links} links; a robot arm description may have at most {mjcf.MAX_LINKS}")
    limits.check_urdf(root, path)
    notes = []
    speed, effort, names = {}, {}, []
    children: dict[str, list[str]] = {}
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
    for link, parent in parents.items():
        children.setdefault(parent, []).append(link)
    if not MIN_AXES <= len(names) <= MAX_AXES:
        raise ArmError(
            f"{path}: {len(names)} revolute joints ({', '.join(names) or 'none'}); expected "
            f"{MIN_AXES} to {MAX_AXES} in a serial chain"
        )
    # geometry MuJoCo cannot load goes, with one warning
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
            stacklevel=3,
        )
        notes.append(f"{len(dropped)} meshes left out: COLLADA or unresolvable (dynamics need no geometry)")
    # MuJoCo options for the URDF compiler: keep visual geoms, full mesh paths, every link a body;
    # of the source's own <mujoco> only compiler settings that read no file are kept
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
    spec = _urdf_spec(root, path)
    filled = _fill_inertials(root, spec, path)
    if filled:
        warnings.warn(
            f"{path}: links {', '.join(filled)} have no <inertial>; theirs are computed from their meshes "
            f"at {DENSITY:g} kg/m^3 (MuJoCo's compiler)",
            GeometryDropped,
            stacklevel=3,
        )
        notes.append(
            f"links {', '.join(filled)}: no <inertial> in the URDF; mass, centre of mass and inertia "
            f"computed from their meshes as uniform solids of {DENSITY:g} kg/m^3 by MuJoCo's compiler "
            "(written into urdf_used.urdf)"
        )
        spec = _urdf_spec(root, path)
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
    )


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


def _read_mjcf(path: Path) -> Arm:
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


def _read_dh(path: Path) -> Arm:
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
    speed, effort = [], []
    for i, row in enumerate(links, start=1):
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
        speed.append(_number(path, where, "speed", row["speed"]) if "speed" in row else math.nan)
        effort.append(_number(path, where, "effort", row["effort"]) if "effort" in row else math.nan)
        if convention == "standard":
            # T_i = Rz(theta) Tz(d) Tx(a) Rx(alpha): the joint turns link i about z of frame i-1,
            # the fixed part is a frame dh{i} holding the link's inertial and the next link
            body = parent.add_body(name=f"link{i}", quat=_quat_z(offset))
            body.add_joint(name=f"joint{i}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], range=qlim)
            frame = body.add_frame(name=f"dh{i}", pos=[a, 0.0, d], quat=_quat_x(alpha))
            inertial_in = frame
        else:
            # Craig: T_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta) Tz(d): the body is frame i
            pos = [a, -d * math.sin(alpha), d * math.cos(alpha)]
            body = parent.add_body(name=f"link{i}", pos=pos, quat=_quat_mul(_quat_x(alpha), _quat_z(offset)))
            body.add_joint(name=f"joint{i}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], range=qlim)
            frame = body.add_frame(name=f"dh{i}")
            inertial_in = frame
        # the inertial is written in the DH frame of the link: a massless child body would add a
        # joint-free body; set the link's own inertial through the frame's pose instead
        _set_inertial(body, inertial_in, mass, com, tensor)
        parent = frame
    arm_joints = check_arm(spec, str(path))
    payload = (
        _number(path, "top", "rated_payload", data["rated_payload"]) if "rated_payload" in data else math.nan
    )
    return Arm(
        spec=spec,
        kind="DH table",
        source=path,
        joints=arm_joints,
        speed_limit=np.array(speed),
        effort_limit=np.array(effort),
        payload=payload,
        description=limits.text(
            path, "description", data.get("description", f"{name} from the {convention} DH table {path.name}")
        ),
    )


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
