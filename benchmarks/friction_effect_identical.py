"""Datasets bit-identical before and after motor friction became a registered effect and friction
wear a ``Fault`` (issue 37, item 3).

Runs the same small set of runs with two checkouts of faultgen (each first on ``PYTHONPATH``, the
same interpreter) and compares every array and attribute of every run of the resulting HDF5 files
with h5py. The runs: wear on two axes under both friction models (``lugre`` and ``stribeck``; the
four schedule kinds, one with an exp4 onset as a fleet's failing robots use), a growing fault
(``--fault``) beside wear on another axis, a small sweep grid, and a small fleet (its failing robots
wear from a drawn onset day).

Usage (about 80 s on the shared 2-core machine, both checkouts)::

    python benchmarks/friction_effect_identical.py --base /work/main --new . -o /tmp/fei

Exit status 0 when every dataset is identical, 1 otherwise (the differing arrays are printed).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np

from faultgen import children

#: The runs: output name and ``faultgen`` arguments.
RUNS = {
    "lugre_wear.h5": ["simulate", "--robot", "puma560", "--task", "pick_place", "--friction", "lugre",
                      "--wear", "2:exp4:50", "--wear", "3:logistic:20", "--cycles", "100",
                      "--record", "1,50,80,100", "--seed", "3"],
    "stribeck_wear.h5": ["simulate", "--robot", "puma560", "--task", "pick_place", "--friction", "stribeck",
                         "--wear", "2:linear:20", "--wear", "5:step:30", "--cycles", "100",
                         "--record", "1,60,100", "--seed", "4"],
    "onset_wear.h5": ["simulate", "--robot", "puma560", "--task", "spot_weld", "--friction", "lugre",
                      "--wear", "2:exp4:50:onset=40", "--cycles", "100", "--record", "1,40,70,100", "--seed", "5"],
    "fault_and_wear.h5": ["simulate", "--robot", "puma560", "--task", "pick_place", "--friction", "lugre",
                          "--fault", "backlash:2:width:0.01:kind=exp4", "--wear", "3:exp4:20", "--cycles", "100",
                          "--record", "1,100", "--seed", "6"],
    "sweep.h5": ["sweep", "--robot", "puma560", "--task", "pick_place", "--axis", "0", "--axis", "2",
                 "--axis", "3", "--wear-pct", "20", "--schedule", "exp4", "--friction", "stribeck",
                 "--cycles", "100", "--record", "1,100", "--seed", "1", "--jobs", "1", "--no-progress"],
    "fleet.h5": ["fleet", "--robots", "3", "--failing", "2", "--robot", "puma560", "--days", "6",
                 "--cycles-per-day", "2", "--seed", "2", "--jobs", "1", "--no-progress"],
}


def generate(checkout: Path, out: Path) -> None:
    """Write every run of :data:`RUNS` into ``out`` with the faultgen of ``checkout``."""
    out.mkdir(parents=True, exist_ok=True)
    env = children.environment({"PYTHONPATH": str(checkout.resolve())})
    for name, args in RUNS.items():
        target = out / name
        if target.exists():
            continue
        command = [*children.command("-m", "faultgen.cli"), *args, "-o", str(target)]
        print(" ".join(command[3:]), flush=True)
        subprocess.run(command, env=env, check=True, stdout=subprocess.DEVNULL)


def differences(a: Path, b: Path) -> list[str]:
    """Every dataset or attribute of ``a`` and ``b`` that differs (bit for bit, NaN equal to NaN),
    or is in one only; file-level provenance (code version, timestamps, host) is not compared."""
    found = []

    def attrs(x, y, where):
        for key in sorted(set(x.attrs) | set(y.attrs)):
            if key in SKIP_ATTRS:
                continue
            if key not in x.attrs or key not in y.attrs:
                found.append(f"{where}@{key}: in one file only")
                continue
            u, v = x.attrs[key], y.attrs[key]
            if not np.array_equal(np.asarray(u), np.asarray(v)):
                found.append(f"{where}@{key}: {u!r} != {v!r}"[:300])

    with h5py.File(a) as fa, h5py.File(b) as fb:
        names_a, names_b = [], []
        fa.visit(names_a.append)
        fb.visit(names_b.append)
        for name in sorted(set(names_a) ^ set(names_b)):
            found.append(f"{name}: in one file only")
        attrs(fa, fb, "/")
        for name in sorted(set(names_a) & set(names_b)):
            x, y = fa[name], fb[name]
            attrs(x, y, name)
            if isinstance(x, h5py.Dataset):
                u, v = x[()], y[()]
                same = u.shape == v.shape and u.dtype == v.dtype and (
                    np.array_equal(u, v, equal_nan=True) if u.dtype.kind == "f" else np.array_equal(u, v))
                if not same:
                    found.append(f"{name}: arrays differ")
    return found


#: Attributes that record how a file was written, not what it holds: the command line (it names the
#: output file) and the code's version string.
SKIP_ATTRS = {"command", "faultgen_version"}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", type=Path, required=True, help="checkout before the change (e.g. /work/main)")
    parser.add_argument("--new", type=Path, required=True, help="checkout after the change")
    parser.add_argument("-o", "--out", type=Path, required=True, help="folder for the two sets of datasets")
    args = parser.parse_args()
    generate(args.base, args.out / "base")
    generate(args.new, args.out / "new")
    bad = 0
    for name in RUNS:
        found = differences(args.out / "base" / name, args.out / "new" / name)
        with h5py.File(args.out / "new" / name) as f:
            n = []
            f.visit(n.append)
            arrays = sum(isinstance(f[k], h5py.Dataset) for k in n)
        print(f"{name}: {arrays} arrays, " + ("identical" if not found else f"{len(found)} differences"))
        for line in found:
            print("   ", line)
        bad += bool(found)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
