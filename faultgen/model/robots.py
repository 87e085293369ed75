"""Resolve a robot by name, folder or MJCF file to its :class:`~faultgen.model.robot.Robot`, once.

A robot is a folder ``robots/<name>/`` (or any folder given by path) holding ``<name>.xml`` (the
MJCF), ``scene.xml``, ``tasks.toml``, ``drivetrain.toml`` and a README giving the source of every
number. ``<name>.xml`` is built by :func:`faultgen.model.builder.build` from an arm and its
drivetrain (``faultgen robots add``; the built-in robots from their ``arm.xml``). The MJCF is the
single source of the parameters: :mod:`faultgen.model.robot` reads them back from the compiled
model, so an edited or augmented MJCF is picked up without code changes.

The boundary (the command line, a public call) resolves a robot here once and hands the
:class:`Robot` down (docs/architecture.md, "One robot model, resolved once"); :class:`Robot`,
:func:`from_spec` and :func:`drivetrain_of` live in :mod:`faultgen.model.robot` and are named here
too.
"""

from __future__ import annotations

import dataclasses
import functools
import re
import shutil
from collections.abc import Callable
from pathlib import Path

import mujoco

from faultgen import inputs
from faultgen.effects.base import ModelError
from faultgen.model import drivetrain, limits, mjcf, sources
from faultgen.model.builder import ArmError
from faultgen.model.robot import RATED_PAYLOAD, Robot, from_model, drivetrain_of, from_spec


class UnknownRobotError(ValueError):
    """Raised by :func:`load` for a name that is neither a known robot nor an MJCF file or robot folder."""


__all__ = ["RATED_PAYLOAD", "ModelError", "Robot", "UnknownRobotError", "available", "drivetrain_of", "from_spec", "load",
           "moved", "require", "robots_dir", "source_of", "with_timestep", "write"]


def robots_dir() -> Path:
    """Folder holding the robot folders: packaged copy in a wheel, ``robots/`` in a checkout."""
    package = Path(__file__).resolve().parents[1]  # faultgen/
    packaged = package / "_robots"
    return packaged if packaged.is_dir() else package.parent / "robots"


def available() -> dict[str, Path]:
    """Known robots: name -> path of its MJCF, sorted by name."""
    root = robots_dir()
    found = {}
    if root.is_dir():
        for folder in sorted(root.iterdir()):
            xml = folder / f"{folder.name}.xml"
            if xml.is_file():
                found[folder.name] = xml
    return found


def load(name: str | Path) -> Robot:
    """Load a robot by name (see :func:`available`), from a robot folder or from an MJCF file.

    Parameters
    ----------
    name : str or Path
        A known robot name such as ``"puma560"`` or ``"irb6700"``; the path of a robot folder
        (``faultgen robots add`` writes one: ``<folder name>.xml`` in it is the robot, or else its
        only ``.xml`` file other than ``scene.xml`` and ``arm.xml``); or the path of an MJCF file
        with the elements listed in this module's docstring.

    Returns
    -------
    Robot
        Compiled once per process for each MJCF path and content (its bytes' SHA-1; files it
        includes are not hashed): later calls return the same object, whose arrays are read-only
        (do not change its ``model`` either; :meth:`Robot.edited` makes a changed copy).

    Raises
    ------
    UnknownRobotError
        If ``name`` is neither a known robot nor an existing file or robot folder; the message
        lists the known robots.
    ModelError
        If the MJCF does not compile (the message names the file and MuJoCo's line) or lacks a
        required element. (A folder's ``drivetrain.toml`` records the numbers its MJCF was built
        with; the MJCF is what loads, so rebuild it after editing the table.)
    """
    known = available()
    if str(name) in known:
        path = known[str(name)]
    elif Path(name).is_file():
        path = Path(name)
    elif Path(name).is_dir():
        path = _folder_model(Path(name))
    else:
        listing = ", ".join(known) or "(none found in " + str(robots_dir()) + ")"
        raise UnknownRobotError(f"unknown robot {str(name)!r}; known robots: {listing}")
    path = path.resolve()
    return _cached(path, _digest(path))


def write(path: str | Path, text: str, writer: Callable[[Path, str], object] | None = None) -> Robot:
    """Write the robot MJCF ``text`` to ``path`` and return the :class:`Robot` it is: the writer of a
    model file (a calibration, the monitor's twin model, ``robots add``) hands on the robot it
    wrote, so nobody loads that file again by its path (docs/architecture.md, "One robot model,
    resolved once").

    The robot is read back from the file as written, once, with :func:`load`'s checks and cache
    (its bytes' SHA-1): it is what any later ``load(path)`` gives, the same object while the file
    is unchanged. ``writer(path, text)`` writes the file (an atomic writer such as
    :func:`faultgen.data.atomic.write_text`; default :meth:`pathlib.Path.write_text`).

    Raises
    ------
    ModelError
        If the file written does not load as a robot (as :func:`load`).
    """
    path = Path(path)
    (writer or Path.write_text)(path, text)
    path = path.resolve()
    return _cached(path, _digest(path))


def moved(robot: Robot, path: str | Path) -> Robot:
    """``robot``, read from a file that has since been moved to ``path`` unchanged (a folder staged
    hidden and renamed into place once complete: :func:`faultgen.calibrate.calibrate`,
    ``robots add``): the same compiled model, named by its new path (its spec now resolving files
    beside it), without reading it again. Equal to what :func:`load` of ``path`` gives (tests/test_resolve_once.py).

    Raises
    ------
    ModelError
        If ``robot`` was not read from a file or ``path`` does not hold that file's bytes (its SHA-1).
    """
    path = Path(path).resolve()
    digest = _digest(path) if path.is_file() else None
    if robot.digest is None or digest != robot.digest:
        raise ModelError(f"{path}: not the file the robot {robot.name!r} was read from ({robot.path}), unchanged; "
                         "load it with faultgen.model.robots.load")
    spec = robot.new_spec()
    spec.modelfiledir = str(path.parent)
    return dataclasses.replace(robot, name=path.stem, path=path, _spec=spec)


def require(robot: Robot, where: str) -> Robot:
    """``robot`` if it is a :class:`Robot`; below the boundary a name is never resolved again.

    Raises
    ------
    TypeError
        For anything else (a name, a path), naming ``where`` and saying to resolve it once with
        :func:`load`.
    """
    if not isinstance(robot, Robot):
        raise TypeError(f"{where}: expected a Robot, got {type(robot).__name__} {robot!r}; resolve a robot "
                        "name, folder or MJCF file once with faultgen.model.robots.load and pass the Robot")
    return robot


def source_of(robot: Robot) -> str:
    """The string that names ``robot`` for :func:`load` and in a dataset's provenance: its name when
    it is that known robot's file as read (:attr:`Robot.digest`), else its MJCF path (a robot
    edited in memory is named by the file it was derived from)."""
    known = available().get(robot.name)
    same = known is not None and robot.digest is not None and known.resolve() == robot.path.resolve()
    return robot.name if same else str(robot.path)


def _folder_model(folder: Path) -> Path:
    """The robot MJCF of a robot folder (see :func:`load`)."""
    own = folder / f"{folder.resolve().name}.xml"
    if own.is_file():
        return own
    candidates = sorted(p for p in folder.glob("*.xml") if p.name not in ("scene.xml", "arm.xml"))
    if len(candidates) != 1:
        found = ", ".join(p.name for p in candidates) or "none"
        raise UnknownRobotError(f"{folder}: not a robot folder; expected {own.name} or exactly one robot "
                                f".xml (found: {found})")
    return candidates[0]


def _digest(path: Path) -> str:
    """SHA-1 of a robot MJCF's bytes through :mod:`faultgen.inputs` (:func:`faultgen.model.sources.sha1_of`:
    its size checked before the read; a 20 GiB sparse MJCF was read whole, a MemoryError). ModelError otherwise."""
    return sources.sha1_of(path, ModelError)


@functools.lru_cache(maxsize=32)
def _cached(path: Path, digest: str) -> Robot:
    """One compiled robot per MJCF path and content (``digest``): an edited file is read again."""
    return _from_file(path, digest)


def with_timestep(name: str | Path, timestep: float, folder: str | Path) -> Path:
    """Copy a robot's folder into ``folder`` with only its physics step changed.

    For convergence studies (``benchmarks/convergence.py``): the copy is the robot's own MJCF with
    ``<option timestep=...>`` rewritten and nothing else (no re-serialisation, so every other
    number keeps its digits), beside the robot's ``tasks.toml`` (and its ``meshes`` folder, if any).

    Parameters
    ----------
    name : str or Path
        As :func:`load`.
    timestep : float
        Physics step in s; 4 ms (the logging period) must be a whole number of steps.
    folder : str or Path
        Where the copy goes, as ``folder/<name>/<name>.xml``; created if missing.

    Returns
    -------
    Path
        The copied MJCF, loadable by :func:`load`.

    Raises
    ------
    ValueError
        If ``timestep`` is not positive or does not divide 4 ms, or the MJCF has no
        ``<option timestep="...">`` to change.
    """
    per_log = 0.004 / timestep if timestep > 0 else 0.0
    if not (timestep > 0 and abs(per_log - round(per_log)) < 1e-9 * per_log and round(per_log) >= 1):
        raise ValueError(f"timestep = {timestep!r} s; expected a positive step that divides 4 ms")
    source = load(name).path
    text, count = re.subn(r'(<option\b[^>]*\btimestep=")[^"]*(")', rf"\g<1>{timestep!r}\g<2>",
                          sources.read_text(source, what="robot MJCF", error=ModelError), count=1)  # bounded
    if not count:
        raise ValueError(f"{source}: no <option timestep=\"...\"> to change")
    target = Path(folder) / source.stem
    target.mkdir(parents=True, exist_ok=True)
    (target / "tasks.toml").write_bytes(sources.read_bytes(source.parent / "tasks.toml", inputs.TOML_MAX_BYTES,
                                                           "tasks file", ModelError))  # bounded, not copied whole
    if (source.parent / "meshes").is_dir():  # an added robot's meshes, named relative to its MJCF
        shutil.copytree(source.parent / "meshes", target / "meshes", dirs_exist_ok=True)
    (target / source.name).write_text(text)
    return target / source.name


def _from_file(path: Path, digest: str | None = None) -> Robot:
    """Compile a robot MJCF after the checks a robot description from a stranger gets
    (docs/reliability.md, threat model): a bounded regular file that names no file outside its own
    folder and loads no plugin (:func:`faultgen.model.mjcf.check_files`), then, compiled, masses,
    inertias, positions and ranges (:func:`faultgen.model.limits.check_compiled`) and its
    drivetrain's values (:class:`faultgen.model.drivetrain.AxisDrive`) within their bounds."""
    try:
        text = sources.read_text(path, what="robot MJCF", error=ArmError)
        mjcf.check_files(path, sources.parse_xml(text, path, ArmError), {})
    except ArmError as err:
        raise ModelError(str(err)) from err
    try:  # the parsed spec stays with the robot: simulation models are derived from it in memory
        spec = mujoco.MjSpec.from_file(str(path))
        model = spec.compile()
    except ValueError as err:
        raise ModelError(f"{path}: {str(err).strip()}") from err
    try:
        limits.check_compiled(model, path)
    except ArmError as err:
        raise ModelError(str(err)) from err
    robot = from_model(model, path, spec, digest)
    try:
        drivetrain_of(robot)
    except drivetrain.DrivetrainError as err:
        raise ModelError(f"{path}: {err}") from err
    return robot

