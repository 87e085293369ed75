"""What a robot description may read: its own folder and the package folders the user names.

A URDF, xacro or MJCF from a stranger names other files (includes, meshes, textures); the readers
check each against :func:`roots` (:func:`faultgen.inputs.inside`, links followed) before anything
reads it, and read only regular files of a bounded size (:func:`read_bytes`), so a description
cannot pull in ``/etc/passwd``, ``~/.ssh`` or ``/dev/zero``.
"""

from __future__ import annotations

import hashlib
import xml.etree.ElementTree as ET
from pathlib import Path

from faultgen import inputs


#: Deepest element nesting of a description's XML: a 7-axis MJCF arm nests about 20 deep; the
#: readers (copying, writing) recurse once per level.
MAX_XML_DEPTH = 200
#: Largest robot description (URDF, xacro, MJCF file) read, bytes (rtb-data's largest URDF has 8 kB).
MAX_DESCRIPTION_BYTES = 10_000_000


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
    """The bytes of a regular file of at most ``limit`` bytes (:func:`faultgen.inputs.read_bytes`).

    Raises
    ------
    ValueError
        (``error``) If ``path`` is missing, not a regular file (a device, a pipe, a folder) or larger.
    """
    try:
        return inputs.read_bytes(path, what, limit)
    except inputs.InputError as err:
        raise error(str(err)) from None


def sha1_of(path: str | Path, error: type[ValueError] = ValueError, what: str = "robot MJCF") -> str:
    """SHA-1 (hex) of a description's bytes, read by :func:`read_bytes` (a regular file of at most
    :data:`MAX_DESCRIPTION_BYTES`, its size checked first: a 20 GiB sparse MJCF was read whole)."""
    return hashlib.sha1(read_bytes(path, what=what, error=error)).hexdigest()


def read_text(
    path: str | Path, limit: int = MAX_DESCRIPTION_BYTES, what: str = "file", error: type[ValueError] = ValueError
) -> str:
    """:func:`read_bytes` decoded as UTF-8, the error naming the file and the byte offset."""
    try:
        return inputs.read_text(path, what, limit)
    except inputs.InputError as err:
        raise error(str(err)) from None


def parse_xml(data: str | bytes, path: str | Path, error: type[ValueError] = ValueError) -> ET.Element:
    """The root element of XML ``data`` (read from ``path``), nested at most :data:`MAX_XML_DEPTH`.

    Raises
    ------
    ValueError
        (``error``) Naming ``path``: not XML, or nested deeper.
    """
    parser = ET.XMLPullParser(events=("start", "end"))
    depth, root = 0, None
    try:
        for start in range(0, len(data), 1 << 16):
            parser.feed(data[start : start + (1 << 16)])
            for event, element in parser.read_events():
                root = element if root is None else root
                depth += 1 if event == "start" else -1
                if depth > MAX_XML_DEPTH:
                    raise error(f"{path}: elements nested more than {MAX_XML_DEPTH} deep; a robot description "
                                "nests a few tens")
        parser.close()
        for _, element in parser.read_events():
            root = element if root is None else root
    except ET.ParseError as err:
        raise error(f"{path}: not XML: {err}") from None
    return root


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
