"""Write a robot folder from an arm file: what ``faultgen robots add`` does below the task layer.

:func:`add` reads the arm (:mod:`faultgen.model.importers`), completes its drivetrain from
``--drivetrain`` and the sizing rules (:mod:`faultgen.model.sizing`), builds the robot
(:mod:`faultgen.model.builder`) and writes ``NAME.xml``, ``scene.xml``, ``drivetrain.toml``,
``README.md`` (provenance of every number) and ``tasks.toml`` from a callable
of the layer above (:mod:`faultgen.operation.taskgen`), which gets the staged robot. Everything is
written into a hidden folder beside ``out`` and renamed to ``out`` only when all of it is written
and the robot loads: an error or a kill leaves no folder that looks complete.
"""

from __future__ import annotations

import contextlib
import glob
import math
import os
import re
import socket
import shutil
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from faultgen import inputs
from faultgen.model import builder, importers, limits, plausibility, rating, robots, sizing
from faultgen.model.drivetrain import KEYS, UNITS, read_table

NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_-]{0,63}$")
#: How ``drivetrain.toml`` and README.md record the sizing rule (:func:`sizing_rule` reads it back).
RULE_LINE = "Sized where not given by sizing rule {rule} (faultgen.model.sizing.RULE_VERSIONS)"
RULE_RECORD = re.compile(r"by sizing rule (\d+) \(faultgen\.model\.sizing\.RULE_VERSIONS\)")


@dataclass(frozen=True)
class Added:
    """What :func:`add` wrote: the folder, the loaded robot, the arm as read, the payload used, where
    that payload came from, and the plausibility report (:mod:`faultgen.model.plausibility`: a
    summary line and the findings, each with what to do)."""

    folder: Path
    robot: robots.Robot
    arm: importers.Arm
    payload: float
    payload_origin: str = ""
    plausibility: str = ""
    findings: tuple[str, ...] = ()
    rule: int = sizing.RULE


SCENE = """<mujoco model="{name} scene">
  <!-- Include-only scene: the robot comes from {name}.xml; this file adds only surroundings. -->
  <include file="{name}.xml"/>

  <statistic center="0 0 {center:.3g}" extent="{extent:.3g}"/>

  <visual>
    <headlight diffuse="0.6 0.6 0.6" ambient="0.3 0.3 0.3" specular="0 0 0"/>
    <global azimuth="120" elevation="-20"/>
  </visual>

  <asset>
    <texture name="groundplane" type="2d" builtin="checker" rgb1="0.2 0.3 0.4" rgb2="0.1 0.2 0.3"
      mark="edge" markrgb="0.8 0.8 0.8" width="300" height="300"/>
    <material name="groundplane" texture="groundplane" texuniform="true" texrepeat="5 5" reflectance="0.2"/>
  </asset>

  <worldbody>
    <light name="sun" pos="0 0 4" dir="0 0 -1" directional="true"/>
    <geom name="floor" size="0 0 0.05" type="plane" material="groundplane" contype="0" conaffinity="0"/>
  </worldbody>
</mujoco>
"""


def add(
    name: str,
    source: str | Path,
    out: str | Path,
    drivetrain: str | Path | None = None,
    payload: float | None = None,
    tasks: Callable[[robots.Robot, importers.Arm, float], str] | None = None,
    packages: dict[str, str | Path] | None = None,
    rule: int = sizing.RULE,
) -> Added:
    """Write the robot folder ``out`` for the arm in ``source``.

    Parameters
    ----------
    name : str
        Robot name: a letter, then letters, digits, ``_`` or ``-`` (at most 64).
    source : str or Path
        URDF, xacro, MJCF or DH table (:func:`faultgen.model.importers.read`).
    out : str or Path
        The folder to write; must not exist or be empty.
    drivetrain : str or Path, optional
        A ``drivetrain.toml`` with some or all numbers; the others are sized.
    payload : float, optional
        Rated payload in kg (sizing and fleet parts); by default the source's, else sized.
    tasks : callable, optional
        ``tasks(robot, arm, payload) -> str``: the ``tasks.toml`` text for the staged robot.
    packages : dict of str to path, optional
        ROS package name -> folder, for ``package://`` meshes and xacro's ``$(find NAME)``; the
        source may read only its own folder and these (:func:`faultgen.model.importers.read`).
    rule : int
        The sizing rule (:data:`faultgen.model.sizing.RULE_VERSIONS`; default the latest): the
        benchmark's frozen track versions add their robots with the rule they were frozen with.
        ``drivetrain.toml`` and README.md record it (:func:`sizing_rule`).

    Returns
    -------
    Added

    Raises
    ------
    ValueError
        (``ArmError``, ``DrivetrainError``, ``ModelError`` or the task generator's) naming the bad
        name, element, axis or key; nothing is written then.
    """
    out = Path(out)
    _check_request(name, payload, rule, out)
    if out.parent.is_dir():
        remove_stale(out)  # a killed add's staging folder, before anything can fail
    arm = importers.read(source, packages)
    n = len(arm.joints)
    given = read_table(drivetrain, n, partial=True) if drivetrain is not None else {}
    guessed, payload_origin = _payload_origin(payload, arm)
    result = sizing.sized(arm, given, payload, rule)
    drive, origin, payload = result.drivetrain, result.origin, result.payload
    text = _robot_xml(name, source, arm, drive, payload)
    with _staged(out) as stage:
        robot = robots.write(stage / f"{name}.xml", text)  # the robot as written: it loads, or nothing is added
        size = reach(robot)
        summary, findings = plausibility.report(arm, payload, guessed, result.moving_mass,
                                                plausibility.radial_reach(robot), result.loads,
                                                sizing.PAYLOAD_SHARE)
        (stage / "scene.xml").write_text(SCENE.format(name=name, center=0.4 * size, extent=1.5 * size))
        (stage / "drivetrain.toml").write_text(_drivetrain_toml(name, source, rule, drive, origin, drivetrain, n))
        if arm.urdf:
            (stage / "urdf_used.urdf").write_text(arm.urdf)
        if tasks is not None:
            (stage / "tasks.toml").write_text(tasks(robot, arm, payload))
        (stage / "README.md").write_text(
            readme(name, arm, drive, origin, payload, drivetrain, robot, payload_origin, (summary, findings),
                   result.loads, rule)
        )
    # the robot read from the staged file, named by the folder it was renamed to (not read again)
    return Added(out, robots.moved(robot, out / f"{name}.xml"), arm, payload, payload_origin, summary,
                 tuple(findings), rule)


def _payload_origin(payload: float | None, arm: importers.Arm) -> tuple[bool, str]:
    """(whether the rated payload is to be guessed, where it comes from, in words) for a ``payload``
    given in kg or None, and the arm's own (NaN if its source gives none)."""
    guessed = payload is None and math.isnan(arm.payload)
    return guessed, (
        "given with --payload"
        if payload is not None
        else "from the source"
        if not guessed
        else f"GUESSED: {sizing.PAYLOAD_SHARE * 100:g} % of the moving mass; give --payload KG"
    )


def _check_request(name: str, payload: float | None, rule: int, out: Path) -> None:
    """Check :func:`add`'s name, payload (kg), sizing rule and output folder before anything is read.

    Raises
    ------
    ValueError
        Naming the value and what was expected.
    """
    if not NAME.match(name):
        raise ValueError(f"robot name {name!r}; expected a letter, then letters, digits, '_' or '-'")
    if payload is not None and not (math.isfinite(payload) and 0 <= payload <= limits.MAX_PAYLOAD):
        raise ValueError(f"payload = {payload!r} kg; expected a number in 0 .. {limits.MAX_PAYLOAD:g} kg")
    sizing.check_rule(rule)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise ValueError(f"{out}: exists and is not an empty folder; choose a new one")


def _robot_xml(name: str, source: str | Path, arm: importers.Arm, drive, payload: float) -> str:
    """The MJCF text of robot ``name``: the arm's meshes replaced by a skeleton (a note in ``arm.notes``),
    built with ``drive``, its description and rated ``payload`` (kg) recorded in it."""
    dropped = _skeleton(arm.spec, str(source))
    if dropped:
        arm.notes.append(
            f"{dropped} meshes replaced by a capsule skeleton (massless, no contacts): the robot's "
            "MJCF must load wherever faultgen copies it, and dynamics need no geometry"
        )
    spec = builder.build(arm.spec, drive, source=str(source))
    spec.modelname = name
    if not any(t.name == "description" for t in spec.texts):
        spec.add_text(name="description", data=arm.description)
    spec.add_numeric(name=robots.RATED_PAYLOAD, data=[payload])  # kg: the fleet's parts (sizing.fleet_parts)
    return builder.to_xml(spec)


def _drivetrain_toml(name: str, source: str | Path, rule: int, drive, origin: dict, drivetrain, n: int) -> str:
    """The ``drivetrain.toml`` of an added robot: every number of ``drive`` with its provenance from
    ``origin``, the sizing rule, and the gearbox ratings given in the ``drivetrain`` file (if any)."""
    header = (
        f"Drivetrain of {name}: every number the model uses. Provenance per number in README.md.\n"
        f"{RULE_LINE.format(rule=rule)}\n"
        f"Edit and rebuild: faultgen robots add {name} --from {Path(source).name} "
        f"--drivetrain drivetrain.toml -o NEW_FOLDER"
    )
    notes = {
        axis: {k: ("given in --drivetrain" if v == "given" else v) for k, v in keys.items()}
        for axis, keys in origin.items()
    }
    rated = rating.given(drivetrain, n) if drivetrain is not None else {}  # the gearbox ratings given, kept
    return drive.to_toml(notes=notes, header=header, ratings=rated)


@contextlib.contextmanager
def _staged(out: Path):
    """A hidden staging folder beside ``out`` (``.NAME.partial-PID@HOST-*``, :func:`remove_stale`'s
    pattern), renamed to ``out`` when the block ends, removed when it raises or is interrupted."""
    out.parent.mkdir(parents=True, exist_ok=True)
    prefix = f".{out.name}.partial-{os.getpid()}@{socket.gethostname()}-"  # remove_stale's pattern
    stage = Path(tempfile.mkdtemp(prefix=prefix, dir=out.parent))
    try:
        yield stage
        if out.exists():
            out.rmdir()
        stage.rename(out)
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise


def sizing_rule(folder: str | Path) -> int | None:
    """The sizing rule that sized the robot folder ``folder`` (:data:`faultgen.model.sizing.
    RULE_VERSIONS`), as its ``drivetrain.toml`` records it; None for a folder that records none (a
    shipped robot, or one added before the rules were versioned)."""
    path = Path(folder) / "drivetrain.toml"
    if not path.is_file():
        return None
    for line in inputs.read_text(path, "drivetrain file", inputs.TOML_MAX_BYTES).splitlines():  # size first
        if not line.startswith("#"):
            break
        match = RULE_RECORD.search(line)
        if match:
            return int(match[1])
    return None


def remove_stale(out: Path) -> list[Path]:
    """Remove the hidden staging folders of ``out`` (``.NAME.partial-PID@HOST-*``) that a killed
    ``robots add`` left: those of this host whose process no longer runs. Return them."""
    pattern = re.compile(rf"\.{re.escape(out.name)}\.partial-(\d+)@(.+)-[^-]+")
    removed = []
    for candidate in out.parent.glob(f".{glob.escape(out.name)}.partial-*"):
        match = pattern.fullmatch(candidate.name)
        if match is None or match[2] != socket.gethostname() or not candidate.is_dir():
            continue
        try:
            os.kill(int(match[1]), 0)
            continue  # its writer still runs
        except ProcessLookupError:
            pass
        except PermissionError:
            continue  # a running process of another user
        shutil.rmtree(candidate, ignore_errors=True)
        removed.append(candidate)
    return removed


def _drop_files(spec: mujoco.MjSpec) -> None:
    """Leave no file name in the robot: unused meshes, height fields, skins and file textures go
    (materials keep their colours), and the asset folders are cleared."""
    for geom in [g for g in spec.geoms if g.type == mujoco.mjtGeom.mjGEOM_HFIELD]:
        spec.delete(geom)
    textures = {t.name for t in spec.textures if t.file or any(getattr(t, "cubefiles", []) or [])}
    for material in spec.materials:
        if any(name in textures for name in material.textures):
            material.textures = [""] * len(material.textures)
    for element in [*spec.hfields, *spec.skins, *(t for t in spec.textures if t.name in textures)]:
        spec.delete(element)
    spec.meshdir = spec.texturedir = ""
    spec.compiler.meshdir = spec.compiler.texturedir = ""


def _skeleton(spec: mujoco.MjSpec, source: str) -> int:
    """Replace the arm's mesh geoms by capsules from each link's origin to the next link's (a
    skeleton to look at, massless and without contacts); return how many meshes went. A robot
    folder's MJCF is copied elsewhere by other commands (calibration, convergence studies), where
    mesh files named relative to it would not be found; dynamics need no geometry."""
    meshes = [g for g in spec.geoms if g.type == mujoco.mjtGeom.mjGEOM_MESH]
    _drop_files(spec)
    if not meshes:
        return 0
    for geom in meshes:
        spec.delete(geom)
    for mesh in list(spec.meshes):
        spec.delete(mesh)
    model = spec.copy().compile()
    extent = float(np.max(np.linalg.norm(model.body_pos, axis=1))) or 0.1
    for body in range(1, model.nbody):
        parent = model.body_parentid[body]
        offset = model.body_pos[body]
        if parent == 0 or np.linalg.norm(offset) < 1e-6:
            continue
        geom = spec.body(model.body(parent).name).add_geom(
            type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[0, 0, 0, *offset.tolist()], size=[0.15 * extent, 0, 0]
        )
        geom.contype, geom.conaffinity, geom.group, geom.mass = 0, 0, 2, 0.0
        geom.rgba = [0.75, 0.75, 0.78, 1.0]
    return len(meshes)


def reach(robot: robots.Robot) -> float:
    """Largest distance from the first joint's anchor to the flange over 64 poses, m."""
    model = robot.model
    data = mujoco.MjData(model)
    rng = np.random.default_rng(0)
    site = model.site("flange").id
    base = None
    reach = 0.0
    for _ in range(64):
        qpos, _ = robot.rigid_state(rng.uniform(*robot.joint_range.T))
        data.qpos[:] = qpos
        mujoco.mj_kinematics(model, data)
        if base is None:
            base = data.xanchor[model.joint("joint1").id].copy()
        reach = max(reach, float(np.linalg.norm(data.site_xpos[site] - base)))
    return reach


def readme(
    name: str,
    arm: importers.Arm,
    drive,
    origin: dict,
    payload: float,
    drivetrain,
    robot,
    payload_origin: str = "",
    checked: tuple[str, list[str]] | None = None,
    loads: sizing.Loads | None = None,
    rule: int | None = None,
) -> str:
    """README.md of an added robot: where the arm came from, and per axis where every drivetrain
    number came from (the source file, ``--drivetrain``, or which sizing rule)."""
    n = len(arm.joints)
    lines = _readme_arm(name, arm, payload, drivetrain, payload_origin, loads)
    if checked is not None:
        summary, findings = checked
        lines += ["", "## Plausibility", "", f"{summary}: "
                  + (f"{len(findings)} finding(s)." if findings else "nothing implausible found."), ""]
        lines += [f"- {finding}" for finding in findings]
    lines += _readme_drivetrain(n, drive, origin, rule)
    lines += [
        "",
        "## Model",
        "",
        f"{robot.n_axes} axes. Per axis i: `joint{{i}}` (arm joint), `rotor{{i}}` (motor rotor, "
        "armature = Jm), "
        "`gearbox{i}` (fixed tendon, coefficients 1/G and -1, thesis eq. 6.2a), `motor{i}` (torque "
        "actuator), "
        "`friction{i}` (motor-side friction numerics); a `home` keyframe and a `flange` site.",
        "",
    ]
    return "\n".join(lines)


def _readme_arm(name: str, arm: importers.Arm, payload: float, drivetrain, payload_origin: str,
                loads: sizing.Loads | None) -> list[str]:
    """README.md's lines up to the arm's section: its title, how it was added, its files, the arm's
    source, rated payload (kg) and joint table, and the changes made while reading it."""
    lines = [
        f"# {name}",
        "",
        f"{arm.description}. Added by `faultgen robots add {name} --from {arm.source.name}"
        + (f" --drivetrain {Path(drivetrain).name}" if drivetrain else "")
        + '` (docs/robots.md, "Your own robot").',
        "",
        "Files: `"
        + name
        + ".xml` (the robot: arm + drivetrain, built by `faultgen.model.builder`), `scene.xml` "
        "(include-only: floor and light), `drivetrain.toml` (every drivetrain number, with its provenance "
        "as a "
        "comment), `tasks.toml` (the three thesis tasks, generated; edit freely), this README"
        + (
            ", `urdf_used.urdf` (the URDF as compiled: unusable meshes left out, missing inertials filled in)"
            if arm.urdf
            else ""
        )
        + ".",
        "",
        "## Arm (from the source file)",
        "",
        f"Kinematics, joint limits, link masses, centres of mass and inertias are the {arm.kind} file's "
        f"`{arm.source.name}`, as MuJoCo's compiler reads it. Rated payload: {payload:.4g} kg "
        f"({payload_origin})"
        + (
            f"; the drives are sized to hold and accelerate it with its centre of mass {loads.offset:.3g} m "
            "out along the flange's z axis (sizing.rated_load)"
            if loads is not None
            else ""
        )
        + ".",
        "",
        "| axis | joint | source joint | range (rad) | speed limit (rad/s) | effort limit (N m) |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for k, joint in enumerate(arm.joints):
        lines.append(
            f"| {k + 1} | `joint{k + 1}` | `{joint.name}` | {joint.range[0]:.6g} .. {joint.range[1]:.6g} | "
            f"{_cell(arm.speed_limit[k])} | {_cell(arm.effort_limit[k])} |"
        )
    if arm.notes:
        lines += ["", "Changes made while reading:", ""] + [f"- {note}" for note in arm.notes]
    return lines


def _readme_drivetrain(n: int, drive, origin: dict, rule: int | None) -> list[str]:
    """README.md's drivetrain section: the table of ``drive``'s numbers for ``n`` axes and each one's
    provenance from ``origin`` (given or the sizing ``rule``)."""
    lines = [
        "",
        "## Drivetrain (gear ratio, motor inertia, gearbox stiffness and damping, motor torque limit, "
        "motor-side friction)",
        "",
        "Per axis: the value, then where it came from: `given` (from `--drivetrain`) or `sized` with the "
        "rule "
        '(docs/robots.md, "Your own robot", gives each rule\'s numbers and sources). Units: '
        + "; ".join(f"{k}: {u}" for k, u in UNITS.items())
        + "."
        + (f" {RULE_LINE.format(rule=rule)}: {sizing.RULE_VERSIONS[rule]}." if rule is not None else ""),
        "",
        "| quantity | " + " | ".join(f"axis {i}" for i in range(1, n + 1)) + " |",
        "| --- |" + " --- |" * n,
    ]
    for key in KEYS:
        lines.append(f"| {key} | " + " | ".join(f"{getattr(a, key):.6g}" for a in drive.axes) + " |")
    lines += ["", "Provenance:", ""]
    for key in KEYS:
        labels = [origin[i][key] for i in range(1, n + 1)]
        if len(set(labels)) == 1:
            lines.append(f"- {key}, all axes: {labels[0].replace('given', 'given in --drivetrain')}")
        else:
            for i, label in enumerate(labels, start=1):
                lines.append(f"- {key}, axis {i}: {label.replace('given', 'given in --drivetrain')}")
    return lines


def _cell(value: float) -> str:
    return "-" if math.isnan(value) else f"{value:.4g}"
