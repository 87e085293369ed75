"""The numeric profile a benchmark track is made in, so that two machines give the same bits.

The same faultgen, packages and seed give different last bits on two x86-64 machines when the
libraries under NumPy pick their code by the processor: OpenBLAS chooses its kernels at load time
(the IK of the Cartesian tasks runs through it, so a weld path's joint reference moves), and
NumPy dispatches its loops and reductions to the widest vector unit it finds (AVX-512 on one
machine, AVX2 on another: the per-cycle features move). Measured: the conditions
track's small make (version 1) gave its frozen manifest with OpenBLAS's Haswell or Zen kernels and
40 of 155 differing arrays with its SkylakeX, Cooperlake, SapphireRapids or Sandybridge kernels, on
one processor; a spot-weld run's features changed again when NumPy's AVX-512 loops were switched
off (docs/bench.md, "Two machines").

A track version that names a profile (``profile = "x86-64-v3"`` in its recipe) is made with both
pinned through the environment the libraries read when they load: OpenBLAS's Haswell kernels (AVX2
and FMA, which every x86-64-v3 processor has: Intel since 2013, AMD since 2017) on one thread, and
NumPy without its dispatch targets above x86-64-v3. They must be set before NumPy is imported, so
``faultgen bench make`` starts itself again with them (:func:`restart_pinned`); a Python session
that imported NumPy without them is refused by :func:`check` with the variables to set. Other
processors (ARM, x86 without AVX2) or another BLAS (MKL) cannot take the profile: the make runs
as it is and its manifest check may fail there.
"""

from __future__ import annotations

import os
import platform
import sys
from importlib import metadata

from faultgen import children

#: Profiles by name: the environment variables that pin them (read by OpenBLAS and NumPy at load time).
PROFILES = {
    "x86-64-v3": {
        "OPENBLAS_CORETYPE": "Haswell",
        "OPENBLAS_NUM_THREADS": "1",
        # NumPy 2.4's dispatch targets above x86-64-v3, and the older releases' names of them
        "NPY_DISABLE_CPU_FEATURES": "X86_V4 AVX512_ICL AVX512_SPR AVX512F AVX512CD AVX512_SKX AVX512_CLX AVX512_CNL",
    },
}
#: What a profile needs of the processor (NumPy's names of its features).
NEEDS = {"x86-64-v3": ("AVX2", "FMA3")}
#: NumPy dispatch targets a profile leaves on (any other AVX-512 target means the profile did not take).
_ABOVE = {"x86-64-v3": ("AVX512", "X86_V4")}
#: The packages whose versions a manifest records (they compute the data).
PACKAGES = ("numpy", "scipy", "mujoco", "mink", "pandas", "pyarrow", "h5py", "pin")


def _blas() -> str:
    """The BLAS in this process and the kernels it chose, e.g. ``openblas SkylakeX``."""
    from threadpoolctl import threadpool_info

    found = [f"{i.get('internal_api')} {i.get('architecture') or ''}".strip() for i in threadpool_info()
             if i.get("user_api") == "blas"]
    return ", ".join(found) or "none found"


def _numpy_dispatch() -> str:
    """NumPy's dispatch targets this process runs, e.g. ``X86_V3 X86_V4`` (``baseline``: none)."""
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__

    return " ".join(f for f in __cpu_dispatch__ if __cpu_features__.get(f)) or "baseline"


def describe() -> dict:
    """This process's numeric environment: ``{"machine", "python", "blas", "numpy_dispatch",
    "packages"}``, written into a track's manifest and named when a check fails."""
    packages = {}
    for name in PACKAGES:
        try:
            packages[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            continue
    return {"machine": platform.machine(), "python": platform.python_version(), "blas": _blas(),
            "numpy_dispatch": _numpy_dispatch(), "packages": packages}


def supported(name: str) -> bool:
    """Whether this processor can run profile ``name`` (x86-64 with its features)."""
    from numpy._core._multiarray_umath import __cpu_features__

    return platform.machine().lower() in ("x86_64", "amd64") and all(__cpu_features__.get(f) for f in NEEDS[name])


def pinned(name: str) -> bool:
    """Whether this process runs in profile ``name``: its variables were set before NumPy loaded, and
    OpenBLAS took its kernels."""
    wanted = PROFILES[name]
    if any(os.environ.get(k) != v for k, v in wanted.items()):
        return False
    if any(target in _numpy_dispatch() for target in _ABOVE[name]):
        return False
    blas = [kernels.strip().lower() for kernels in _blas().split(",")]
    return all(kernels == f"openblas {wanted['OPENBLAS_CORETYPE']}".lower() for kernels in blas)


def unknown(name: str | None) -> None:
    """Refuse a profile name that is not in :data:`PROFILES` (a track file's typo)."""
    if name is not None and name not in PROFILES:
        raise ValueError(f"profile {name!r}: expected one of {', '.join(PROFILES)}")


def check(name: str | None) -> str:
    """How this process stands towards profile ``name``: ``"pinned"``, ``"native"`` (no profile asked),
    or ``"unsupported"`` (the processor cannot take it: the make goes on unpinned).

    Raises
    ------
    ValueError
        When the processor could take the profile but this process was started without it (NumPy is
        loaded: too late to pin); the message gives the variables to set, or says to use the command.
    """
    if name is None:
        return "native"
    unknown(name)
    if not supported(name):
        return "unsupported"
    if pinned(name):
        return "pinned"
    assignments = " ".join(f"{k}={v!r}" for k, v in PROFILES[name].items())
    raise ValueError(f"this track version is made in the numeric profile {name} (so that two machines give the "
                     f"same bits), which must be set before Python starts: run `faultgen bench make` (it sets it), "
                     f"or start Python with {assignments}")


def restart_pinned(name: str | None, argv: list[str], program: tuple[str, ...] = ("-m", "faultgen.cli")) -> None:
    """Start this command again in profile ``name`` (replacing this process) unless it runs in it
    already, no profile is asked, or the processor cannot take it. ``argv``: the command's arguments
    after the program (``sys.argv[1:]``); ``program`` what Python runs (default the CLI; a script's
    absolute path for a script). Started as ``python -P PROGRAM`` with
    ``PYTHONSAFEPATH=1`` (:mod:`faultgen.children`): ``python -m`` alone puts the current folder first
    on the path, and an ``h5py.py`` there would run in the make."""
    if name is None or not supported(name) or pinned(name):
        return
    if os.environ.get("_FAULTGEN_PROFILE_RESTART") == name:  # pinned variables that did not take: no loop
        return
    env = children.environment({**PROFILES[name], "_FAULTGEN_PROFILE_RESTART": name})
    sys.stdout.flush()
    sys.stderr.flush()
    command = children.command(*program, *argv)
    os.execve(command[0], command, env)
