"""The import graph of faultgen and analysis in figures: modules, imports between them, import
circles, imports between the sub-packages (the layers of docs/architecture.md), and the largest
modules in lines. The graph is grimp's (the one tests/test_architecture.py checks: an import inside
a function counts); circles are its strongly connected components of two modules or more (scipy).

    python benchmarks/import_graph.py              # this checkout
    python benchmarks/import_graph.py --rev 698aaa3   # the tree of a git revision (git archive)

Prints figures only; run it from anywhere (it reads the tree it measures, never the installed
faultgen). Folders without an ``__init__.py`` (data only: bench/tracks, bench/manifests) are
not modules here.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import tarfile
import tempfile
from io import BytesIO
from pathlib import Path

from faultgen import children

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("faultgen", "analysis")
#: The most lines a module may have (tests/test_architecture.py).
MAX_LINES = 600

_MEASURE = """
import json, sys
import grimp
import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components
from pathlib import Path

root, packages = Path(sys.argv[1]), sys.argv[2].split(",")
graph = grimp.build_graph(*packages, cache_dir=None)

def path_of(module):
    base = root.joinpath(*module.split("."))
    return base / "__init__.py" if base.is_dir() else base.with_suffix(".py")

# a folder without __init__.py is a namespace package to grimp: data only here (bench/tracks), no code
modules = sorted(m for m in graph.modules if path_of(m).is_file())
index = {m: i for i, m in enumerate(modules)}
edges = sorted((a, b) for a in modules for b in graph.find_modules_directly_imported_by(a) if b in index)
rows, cols = zip(*((index[a], index[b]) for a, b in edges)) if edges else ((), ())
matrix = csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(len(modules), len(modules)))
_, component = connected_components(matrix, directed=True, connection="strong")
groups = {}
for m, c in zip(modules, component):
    groups.setdefault(int(c), []).append(m)
circles = sorted(sorted(g) for g in groups.values() if len(g) > 1)

lines = {m: len(path_of(m).read_text().splitlines()) for m in modules}
print(json.dumps({"modules": modules, "edges": edges, "circles": circles, "lines": lines}))
"""


def measure(root: Path) -> dict:
    """The graph of the tree at ``root`` (a child process whose import path starts there)."""
    done = subprocess.run(children.command("-c", _MEASURE, str(root), ",".join(PACKAGES)), cwd=root,
                          env={**children.SAFE_PATH, "PYTHONPATH": str(root), "PATH": "/usr/bin:/bin"}, capture_output=True, text=True,
                          check=False)
    if done.returncode:
        raise SystemExit(f"measuring {root} failed:\n{done.stderr}")
    return json.loads(done.stdout)


def layer(module: str) -> str:
    """The sub-package (faultgen.model, analysis, ...) or top-level module a module belongs to."""
    parts = module.split(".")
    return ".".join(parts[:2]) if parts[0] == "faultgen" and len(parts) > 1 else parts[0]


def report(graph: dict, what: str, top: int) -> str:
    modules, edges, lines = graph["modules"], graph["edges"], graph["lines"]
    layers = sorted({layer(m) for m in modules})
    between = sorted({(layer(a), layer(b)) for a, b in edges if layer(a) != layer(b)})
    per_package = {p: sum(1 for m in modules if m.split(".")[0] == p) for p in PACKAGES}
    over = sorted((m for m in modules if lines[m] > MAX_LINES), key=lambda m: -lines[m])
    largest = sorted(modules, key=lambda m: (-lines[m], m))[:top]
    out = [f"{what}:",
           (f"  modules: {len(modules)} ({', '.join(f'{p} {n}' for p, n in per_package.items())}), "
            f"{sum(lines.values())} lines"),
           f"  imports between modules: {len(edges)}",
           f"  import circles: {len(graph['circles'])}" + "".join(f"\n    {' <-> '.join(c)}" for c in graph["circles"]),
           f"  sub-packages and top modules: {len(layers)}, imports between them: {len(between)}",
           f"  modules over {MAX_LINES} lines: {len(over)}" + (f" ({', '.join(f'{m} {lines[m]}' for m in over)})"
                                                              if over else ""),
           f"  largest {top}: " + ", ".join(f"{m} {lines[m]}" for m in largest)]
    return "\n".join(out)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rev", help="a git revision to measure instead of this checkout")
    parser.add_argument("--top", type=int, default=10, help="how many of the largest modules to list")
    args = parser.parse_args()
    if args.rev is None:
        print(report(measure(ROOT), "this checkout", args.top))
        return
    archive = subprocess.run(["git", "archive", args.rev, *PACKAGES], cwd=ROOT, capture_output=True, check=True)
    with tempfile.TemporaryDirectory() as folder:
        with tarfile.open(fileobj=BytesIO(archive.stdout)) as tar:
            tar.extractall(folder, filter="data")
        print(report(measure(Path(folder)), f"revision {args.rev}", args.top))


if __name__ == "__main__":
    main()
