"""faultgen's xacro expander (faultgen.model.xacro) against xacro's own processor (through
xacrodoc) on every xacro file rtb-data ships: one line per file, SAME / DIFF, or which of the two
could not expand it and why; a summary at the end. An independent check: xacro's code is not
faultgen's.

    python benchmarks/xacro_vs_xacrodoc.py
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import rtbdata
import xacrodoc
import xacrodoc.packages

from faultgen.model import xacro

ROOT = Path(rtbdata.__file__).parent / "xacro"
KUKA = ROOT / "kuka_description"
#: The ROS packages the files name, as `--package NAME=DIR` would give them.
PACKAGES = {
    "kuka_resources": KUKA / "kuka_resources",
    "abb_irb140": ROOT / "abb_irb140_description",
    "qut_frankie_description": ROOT / "qut_frankie_description",
    **{f"kuka_{k}_support": KUKA / f"kuka_{k}" for k in "kr3 kr5 kr6 kr10 kr16 kr120 kr150 kr210 lbr_iiwa".split()},
}


def canonical(element: ET.Element):
    """Tag, attributes (numbers rounded to 12 digits), text and children, comments left out."""

    def number(text: str) -> str:
        try:
            return repr(round(float(text), 12))
        except ValueError:
            return text

    attrs = tuple(sorted((k, " ".join(number(w) for w in v.split())) for k, v in element.attrib.items()))
    children = tuple(canonical(c) for c in element if isinstance(c.tag, str))
    return element.tag, attrs, (element.text or "").strip(), children


def main() -> None:
    xacrodoc.packages.update_package_cache({k: str(v) for k, v in PACKAGES.items()})
    counts: dict[str, int] = {}
    for path in sorted(ROOT.rglob("*.xacro")):
        try:
            ours = canonical(ET.fromstring(xacro.expand(path, PACKAGES)))
        except ValueError as err:
            ours, why = None, str(err).splitlines()[0]
        try:
            theirs = canonical(ET.fromstring(
                xacrodoc.XacroDoc.from_file(str(path), resolve_packages=False).to_urdf_string()))
        except Exception as err:  # noqa: BLE001 - xacro raises many kinds; report its message
            theirs, why = None, str(err).splitlines()[0]
        verdict = ("SAME" if ours == theirs else "DIFF") if ours and theirs else (
            "both failed" if ours is None and theirs is None else "faultgen failed" if ours is None else "xacro failed")
        counts[verdict] = counts.get(verdict, 0) + 1
        print(f"{verdict:15} {path.relative_to(ROOT)}" + ("" if ours and theirs else f": {why[:120]}"))
    print(", ".join(f"{k}: {v}" for k, v in counts.items()), f"of {sum(counts.values())} files")


if __name__ == "__main__":
    main()
