"""What a plain MJCF arm may name, checked before MuJoCo reads it: files inside its own folder (or
a ``--package`` folder) only, no plugin, a bounded number of bodies.

MuJoCo's parser follows ``<include file>`` and reads every ``file`` of an asset (mesh, texture,
height field, skin, model) wherever it points, and loads ``<extension><plugin>`` (code); so the
MJCF text, and every file it includes, is walked here first and refused with the element named.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from faultgen.inputs import inside, resolved
from faultgen.model.builder import ArmError
from faultgen.model.sources import parse_xml, read_text, roots

#: Most bodies (links) an arm description may have: a 7-axis arm with its tool and sensor frames
#: has tens; a description with more is refused before MuJoCo compiles it.
MAX_LINKS = 500
#: Most files one MJCF may include, in all.
MAX_INCLUDES = 100

_DIRS = {"mesh": "meshdir", "skin": "meshdir", "hfield": "assetdir", "texture": "texturedir"}


def check_files(path: Path, root: ET.Element, packages: dict[str, Path]) -> None:
    """Refuse an MJCF (already parsed as ``root``) that includes or names a file outside the
    allowed folders (:func:`faultgen.model.sources.roots`), has a plugin, or more than
    :data:`MAX_LINKS` bodies, counting what its includes add.

    Raises
    ------
    ArmError
        Naming the file, the element and the attribute.
    """
    allowed = roots(path, packages)
    compiler = {}
    bodies = 0
    pending = [(path, root)]
    seen = 0
    while pending:
        current, element = pending.pop()
        for node in element.iter():
            if not isinstance(node.tag, str):
                continue
            if node.tag in ("extension", "plugin", "instance"):
                raise ArmError(
                    f"{current}: <{node.tag}> refused: MuJoCo plugins are code; a robot description may not "
                    "load one"
                )
            if node.tag == "body":
                bodies += 1
                if bodies > MAX_LINKS:
                    raise ArmError(f"{path}: more than {MAX_LINKS} bodies; a robot arm has tens")
            if node.tag == "compiler":
                compiler.update({k: v for k, v in node.attrib.items() if k in ("meshdir", "texturedir", "assetdir")})
            for key, value in node.attrib.items():
                if key == "file" or (key.startswith("file") and node.tag == "texture"):
                    folder = compiler.get(_DIRS.get(node.tag, ""), compiler.get("assetdir", ""))
                    if node.tag in ("include", "model", "attach"):
                        folder = ""
                    # MuJoCo takes every relative name (includes' too) from the main file's folder
                    target = Path(value) if Path(value).is_absolute() else path.parent / folder / value
                    _check_inside(current, f'<{node.tag} {key}="{value}">', target, allowed)
                    if node.tag == "include":
                        seen += 1
                        if seen > MAX_INCLUDES:
                            raise ArmError(f"{path}: more than {MAX_INCLUDES} includes")
                        text = read_text(target, what="MJCF include", error=ArmError)
                        pending.append((target, parse_xml(text, target, ArmError)))
            for key in ("meshdir", "texturedir", "assetdir"):
                if node.tag == "compiler" and key in node.attrib:
                    construct = f'<compiler {key}="{node.get(key)}">'
                    _check_inside(current, construct, path.parent / node.get(key), allowed)


def _check_inside(current: Path, construct: str, target: Path, allowed: list[Path]) -> None:
    if not any(inside(target, root) for root in allowed):
        raise ArmError(
            f"{current}: {construct} names {resolved(target)}, outside the folder {allowed[0]} and the "
            "--package folders; a robot description may read only those"
        )
