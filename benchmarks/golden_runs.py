"""Golden outputs of the commands that simulate: `simulate`, `sweep --preset quick`, a small `fleet`
(with friction tests) and `hidden-log` + `calibrate` on its hidden-effect log, run in a temporary
folder; a manifest of one SHA-256 per output (HDF5 files by content: every dataset's dtype, shape
and bytes and every attribute, in name order), so that a refactoring can show it changed no output.

    python benchmarks/golden_runs.py --write benchmarks/golden_runs.json   # record (unchanged code)
    python benchmarks/golden_runs.py --check benchmarks/golden_runs.json   # compare; exit 1 on a difference

The commands run with the temporary folder as their working directory and relative output paths,
so the command line a dataset records is the same on every run. Volatile content, excluded by
name (:data:`VOLATILE`): a run's stepping time and a sweep's or fleet's wall and CPU times (timers,
different on every run). Everything else must be equal bit for bit. Each command's wall and CPU
time (its process and children) is printed, not compared.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from faultgen import children  # noqa: E402  (the checkout's own, before any installed copy)

#: The commands, each ``(name, arguments after faultgen)``, run in this order in one folder.
COMMANDS = [
    ("simulate", ["simulate", "--robot", "irb6700", "--task", "pick_place", "--wear", "1:exp4:20", "--cycles", "20",
                  "--record", "1,10,20", "--no-progress", "-o", "simulate.h5"]),
    ("sweep", ["sweep", "--preset", "quick", "--jobs", "2", "--no-progress", "-o", "quick.h5"]),
    ("fleet", ["fleet", "--robots", "3", "--failing", "1", "--days", "6", "--cycles-per-day", "2",
               "--friction-test-every", "2", "--jobs", "2", "--no-progress", "-o", "fleet.h5"]),
    ("hidden-log", ["hidden-log", "puma560", "--effect", "coulomb", "--cycles", "2", "--seed", "1", "-o", "log.csv"]),
    ("calibrate", ["calibrate", "--robot", "puma560", "--measured", "log.csv", "--max-steps", "2", "--out", "calib"]),
]

#: HDF5 datasets and attributes whose content is a timer, different on every run: excluded from the
#: hashes by their last name component (the names are listed in the manifest).
VOLATILE = ("stepping_time", "wall_time", "cpu_time", "wall_s", "cpu_s", "elapsed", "started", "finished")


def h5_digest(path: Path) -> str:
    """SHA-256 of an HDF5 file's content: names, dtypes, shapes, bytes and attributes, less :data:`VOLATILE`."""
    digest = hashlib.sha256()

    def attrs(name: str, obj) -> None:
        for key in sorted(obj.attrs):
            if key in VOLATILE:
                continue
            value = np.asarray(obj.attrs[key])
            digest.update(f"{name}@{key}:{value.dtype.str}:{value.shape}".encode())
            digest.update(value.tobytes() if value.dtype.kind != "O" else repr(value.tolist()).encode())

    def visit(name: str, obj) -> None:
        if name.rsplit("/", 1)[-1] in VOLATILE:
            return
        attrs(name, obj)
        if isinstance(obj, h5py.Dataset):
            value = obj[()]
            value = np.asarray(value)
            digest.update(f"{name}:{value.dtype.str}:{value.shape}".encode())
            digest.update(value.tobytes() if value.dtype.kind != "O" else repr(value.tolist()).encode())

    with h5py.File(path, "r") as f:
        attrs("/", f)
        names = []
        f.visit(names.append)
        for name in sorted(names):
            visit(name, f[name])
    return digest.hexdigest()


def file_digest(path: Path) -> str:
    """SHA-256 of ``path``: by content for HDF5 (:func:`h5_digest`), of its bytes otherwise."""
    if path.suffix == ".h5":
        return h5_digest(path)
    return hashlib.sha256(path.read_bytes()).hexdigest()


def run_all(folder: Path) -> dict:
    """Run :data:`COMMANDS` in ``folder``; the manifest of its files and the commands' times."""
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1"}
    times = {}
    for name, args in COMMANDS:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        started = time.perf_counter()
        done = subprocess.run(children.command("-m", "faultgen.cli", *args), cwd=folder, env=env,
                              capture_output=True, text=True)
        wall = time.perf_counter() - started
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        (folder / f"{name}.stdout").write_text(done.stdout)
        if done.returncode:
            raise SystemExit(f"faultgen {' '.join(args)} failed ({done.returncode}):\n{done.stderr[-3000:]}")
        times[name] = {"wall_s": round(wall, 2), "cpu_s": round(cpu, 2)}
        print(f"{name}: wall {wall:.1f} s, cpu {cpu:.1f} s", flush=True)
    files = {str(p.relative_to(folder)): file_digest(p) for p in sorted(folder.rglob("*")) if p.is_file()}
    return {"commands": [" ".join(["faultgen", *a]) for _, a in COMMANDS], "volatile_excluded": list(VOLATILE),
            "files": files}, times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("--write", type=Path, help="write the manifest here")
    group.add_argument("--check", type=Path, help="compare with this manifest")
    parser.add_argument("--keep", type=Path, help="run in this (new) folder and keep it, instead of a temporary one")
    args = parser.parse_args()
    if args.keep:
        args.keep.mkdir(parents=True)
        manifest, times = run_all(args.keep.absolute())
    else:
        with tempfile.TemporaryDirectory(prefix="golden-") as tmp:
            manifest, times = run_all(Path(tmp))
    if args.write:
        args.write.write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n")
        print(f"{len(manifest['files'])} files recorded in {args.write}; verdict: recorded")
        return
    expected = json.loads(args.check.read_text())
    old, new = expected["files"], manifest["files"]
    differ = sorted(k for k in old.keys() & new.keys() if old[k] != new[k])
    missing, extra = sorted(old.keys() - new.keys()), sorted(new.keys() - old.keys())
    for label, names in (("differ", differ), ("missing", missing), ("new", extra)):
        for name in names:
            print(f"{label}: {name}")
    same = not (differ or missing or extra)
    print(f"{len(new)} files, {len(differ)} differ, {len(missing)} missing, {len(extra)} new; "
          f"verdict: {'identical' if same else 'DIFFERENT'}")
    sys.exit(0 if same else 1)


if __name__ == "__main__":
    main()
