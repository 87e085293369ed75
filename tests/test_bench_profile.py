"""Issue 48: a track version made on two machines gives the same bits (faultgen/bench/profile.py).

What differs between two x86-64 machines is the code the libraries pick by the processor: OpenBLAS's
kernels and NumPy's dispatch. The first test shows the difference on this one processor (two kernel
sets every AVX2 processor can run); the others show that a version with a numeric profile is made in
it whatever the shell chose, and what a failed check names. The independent check across machines
is the make of the same version on CI and in a session (docs/bench.md, "Two machines")."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import h5py
import numpy as np
import pytest

from faultgen.bench import make, profile, tracks

PROFILE = "x86-64-v3"


def _env(**over: str) -> dict:
    """This environment without the profile's variables, with ``over`` set."""
    env = {k: v for k, v in os.environ.items() if k not in profile.PROFILES[PROFILE] and not k.startswith("_FAULTGEN")}
    return {**env, **over}


def _faultgen(args: list[str], env: dict, cwd) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "faultgen.cli", *args], env=env, cwd=cwd, check=False,
                          capture_output=True, text=True, timeout=600)


def test_without_a_profile_the_blas_kernels_move_a_weld_paths_last_bits(tmp_path):
    """The problem: one spot-weld cycle under OpenBLAS's Haswell and Sandybridge kernels (both run on
    any AVX2 processor): the same path to 1e-12 rad, not the same bits (the IK runs through BLAS)."""
    refs = []
    for kernels in ("Haswell", "Sandybridge"):
        out = tmp_path / f"{kernels}.h5"
        done = _faultgen(["simulate", "--task", "spot_weld", "--cycles", "1", "-o", str(out)],
                         _env(OPENBLAS_CORETYPE=kernels), tmp_path)
        assert done.returncode == 0, done.stderr
        with h5py.File(out) as f:
            refs.append(f["runs/run/q_ref"][()])
    assert refs[0].shape == refs[1].shape and np.abs(refs[0] - refs[1]).max() < 1e-12
    assert not np.array_equal(refs[0], refs[1])


def _profiled(manifest: dict) -> None:
    """A manifest made in the profile: checked against the frozen one, the environment recorded."""
    assert manifest["profile"] == PROFILE and manifest["status"] == "checked"
    assert manifest["environment"]["blas"].startswith("openblas Haswell")
    assert "AVX512" not in manifest["environment"]["numpy_dispatch"]
    assert manifest["environment"]["packages"]["numpy"] == np.__version__


def test_a_profiled_version_gives_its_frozen_bits_whatever_kernels_the_shell_chose(shared_bench, tmp_path):
    """conditions version 2 (spot-weld blocks) made from a shell with OpenBLAS's Sandybridge kernels and
    NumPy's baseline loops restarts in the profile and equals the manifest frozen in the package; the
    manifest records the environment. From a shell with the default kernels: the thesis track that
    conftest.py's shared_bench made by the same command (a make refuses data that differs from the
    frozen manifest), its manifest read here instead of a second make of conditions (15 s)."""
    frozen = json.loads(make.manifest_path("conditions", 2, "small").read_text())
    env = _env(OPENBLAS_CORETYPE="Sandybridge", NPY_DISABLE_CPU_FEATURES="X86_V3 X86_V4 AVX512_ICL AVX512_SPR")
    out = tmp_path / "other-kernels"
    done = _faultgen(["bench", "make", "conditions", "--size", "small", "--no-progress", "-o", str(out)], env, tmp_path)
    assert done.returncode == 0, done.stderr
    assert "identical to the frozen manifest; numeric profile x86-64-v3" in done.stdout, done.stdout
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["arrays"] == frozen["arrays"]
    _profiled(manifest)
    default = json.loads((shared_bench("thesis") / "manifest.json").read_text())
    assert tracks.load("thesis").version(default["version"]).profile == PROFILE
    assert default["arrays"] == json.loads(make.manifest_path("thesis", default["version"], "small").read_text())["arrays"]
    _profiled(default)


def test_a_python_session_started_without_the_profile_is_refused_with_what_to_set(tmp_path):
    assert not profile.pinned(PROFILE)  # the test process: NumPy loaded with this processor's own kernels
    with pytest.raises(ValueError, match=r"numeric profile x86-64-v3 .*run `faultgen bench make`.*"
                                         r"OPENBLAS_CORETYPE='Haswell'"):
        make.make("conditions", tmp_path / "out", size="small", progress=False)
    assert list(tmp_path.iterdir()) == []


def test_a_failed_check_names_what_moved_in_the_environment_and_the_profiled_version():
    here = profile.describe()
    frozen = {**here, "blas": "openblas Zen", "packages": {**here["packages"], "numpy": "2.3.0"}}
    track = tracks.load("conditions")
    why = make._why(track, track.version(2), "pinned", frozen, here)
    assert f"blas 'openblas Zen' -> {here['blas']!r}" in why and f"numpy 2.3.0 -> {np.__version__}" in why
    assert "add version 3 to faultgen/bench/tracks/conditions.toml" in why
    old = make._why(track, track.version(1), "native", None, here)
    assert "version 1 was frozen before tracks pinned their numeric profile" in old and old.endswith("make version 2")


def test_a_version_like_another_takes_its_recipe_and_a_bad_profile_or_like_is_refused():
    for name, old, new in (("thesis", 1, 2), ("faults", 1, 2), ("conditions", 1, 2), ("transfer", 2, 3),
                           ("sim-to-real", 1, 2)):
        track = tracks.load(name)
        assert track.version(new).profile == PROFILE and track.version(old).profile is None
        assert track.latest == (3 if name == "faults" else new)  # faults 3: a fourth fault type
        for split in tracks.SPLITS:
            for size in tracks.SIZES:
                assert track.version(new).grids(split, size) == track.version(old).grids(split, size)
                assert track.version(new).fleets(split, size) == track.version(old).fleets(split, size)
    base = {"version": 1, "train_seeds": [0], "test_seeds": [1], "parts": [{"robots": ["irb6700"]}]}
    with pytest.raises(ValueError, match=r"version 2: profile 'x86-64-v9': expected one of x86-64-v3"):
        tracks.parse({"name": "x", "summary": "s", "licence": "CC0-1.0",
                      "versions": [base, {"version": 2, "like": 1, "profile": "x86-64-v9"}]}, "x.toml")
    with pytest.raises(ValueError, match=r"version 2: like = 3: expected an earlier version of this file \(1\)"):
        tracks.parse({"name": "x", "summary": "s", "licence": "CC0-1.0",
                      "versions": [base, {"version": 2, "like": 3}]}, "x.toml")
