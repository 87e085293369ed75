"""What a robot description may read: its own folder and the package folders the user names.

A URDF, xacro or MJCF from a stranger names other files (includes, meshes, textures); the readers
check each against :func:`allowed` before anything reads it, and read only regular files of a
bounded size (:func:`read_bytes`), so a description cannot pull in ``/etc/passwd``, ``~/.ssh`` or
``/dev/zero``.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path


#: Largest robot description or drivetrain table read, bytes (the largest rtb-data URDF is 60 kB).
MAX_DESCRIPTION_BYTES = 10_000_000


def inside(path: Path, root: Path) -> bool:
    """Whether ``path`` (resolved, symbolic links followed) lies in the folder ``root``."""
    try:
        Path(path).resolve().relative_to(Path(root).resolve())
    except ValueError:
        return False
    return True


def roots(source: Path, packages: dict[str, Path] | None) -> list[Path]:
    """The folders a description in ``source`` may read: its own and the named packages'."""
    return [Path(source).resolve().parent, *(Path(p).resolve() for p in (packages or {}).values())]


def check_packages(packages: dict[str, str | Path] | None) -> dict[str, Path]:
    """``--package NAME=DIR`` values: each an existing folder."""
    out = {}
    for name, folder in (packages or {}).items():
        folder = Path(folder)
        if not name or not folder.is_dir():
            raise ValueError(f"--package {name}={folder}: expected NAME=DIR with DIR an existing folder")
        out[name] = folder
    return out


def read_bytes(
    path: str | Path, limit: int = MAX_DESCRIPTION_BYTES, what: str = "file", error: type[ValueError] = ValueError
) -> bytes:
    """The bytes of a regular file of at most ``limit`` bytes.

    Raises
    ------
    ValueError
        (``error``) If ``path`` is missing, not a regular file (a device, a pipe, a folder) or larger.
    """
    path = Path(path)
    try:
        info = os.stat(path)
    except OSError as err:
        raise error(f"{path}: cannot read the {what}: {err.strerror}") from None
    if not stat.S_ISREG(info.st_mode):
        raise error(f"{path}: not a regular file; expected a {what}")
    if info.st_size > limit:
        raise error(f"{path}: {info.st_size} bytes; a {what} may have at most {limit}")
    with open(path, "rb") as handle:
        data = handle.read(limit + 1)
    if len(data) > limit:
        raise error(f"{path}: more than {limit} bytes; a {what} may have at most {limit}")
    return data


def read_text(
    path: str | Path, limit: int = MAX_DESCRIPTION_BYTES, what: str = "file", error: type[ValueError] = ValueError
) -> str:
    """:func:`read_bytes` decoded as UTF-8, the error naming the file and the byte offset."""
    data = read_bytes(path, limit, what, error)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise error(f"{path}: not UTF-8 text (byte {err.start}: {data[err.start:err.start + 1]!r})") from None


def find_package(package: str, start: Path) -> Path | None:
    """A folder near ``start`` (in or two levels below the three folders above it) named as ROS
    package ``package``, both names compared without a ``_support`` / ``_description`` suffix: a
    hint for the ``--package`` a refused description needs (only folder names are listed)."""

    def stem(name: str) -> str:
        for suffix in ("_support", "_description"):
            if name.endswith(suffix):
                return name[: -len(suffix)]
        return name

    for folder in [f for f in [start, *start.parents][:3] if f.parent != f]:
        candidates = [c for c in [*folder.glob("*"), *folder.glob("*/*")] if c.is_dir()]
        for candidate in candidates:
            if candidate.name == package:
                return candidate
        for candidate in candidates:
            if stem(candidate.name) == stem(package):
                return candidate
    return None


def hint(package: str, start: Path) -> str:
    """`` (a folder X is near the file)`` if :func:`find_package` finds one, else ``""``."""
    found = find_package(package, start)
    return f" (a folder {found} is near the file)" if found is not None else ""
