"""Hostile folders (issue 61, item 2): a Python that faultgen starts imports nothing from the
current folder or a reproduction's output folder. ``python -m`` and ``python -c`` put their
current folder first on ``sys.path``, so a planted ``typer.py``, ``h5py.py`` or ``joblib.py``
there ran in ``bench make``'s pinned restart, in every ``reproduce`` step (run in the output
folder), and in the loky workers and resource trackers of a local sweep and of ``classify``.
Children now start with ``-P`` and ``PYTHONSAFEPATH=1`` (``faultgen.children``). Each test plants
modules that leave a marker file when imported, runs the path, and checks that the child did its
work and no marker was left."""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import h5py
import pytest

from faultgen.bench import profile
from faultgen.reproduce import runner
from faultgen.reproduce.runner import Step

PROFILE = "x86-64-v3"
#: Modules a ``faultgen`` command imports (the command line, the data files) and those loky's
#: processes import first (``python -m joblib.externals.loky...``, ``python -c "from joblib..."``;
#: a multiprocessing.py alone was imported too).
PLANTED = ("typer", "h5py", "joblib", "multiprocessing")


def _plant(folder: Path) -> Path:
    """``folder`` made, with a module for each name of :data:`PLANTED` that, imported, writes
    ``MARKS/NAME``; returns MARKS (a folder beside ``folder``, empty)."""
    marks = folder.parent / f"{folder.name}-marks"
    folder.mkdir(exist_ok=True)
    marks.mkdir()
    for name in PLANTED:
        mark = marks / name
        (folder / f"{name}.py").write_text(f"open({str(mark)!r}, 'w').write('imported from {folder}')\n")
    return marks


def _env() -> dict:
    """This environment without a profile's variables or a safe path asked for."""
    drop = {*profile.PROFILES[PROFILE], "PYTHONSAFEPATH"}
    return {k: v for k, v in os.environ.items() if k not in drop and not k.startswith("_FAULTGEN")}


def _python(code: str, cwd: Path, env: dict) -> subprocess.CompletedProcess:
    """``code`` run by a Python that itself imports nothing from ``cwd`` (``-P``): only the children it
    starts are tested."""
    return subprocess.run([sys.executable, "-P", "-c", textwrap.dedent(code)], cwd=cwd, env=env, check=False,
                          capture_output=True, text=True, timeout=300)


def _help_step(folder: Path) -> tuple[str, str]:
    """`faultgen --help` run as a reproduce step in ``folder``: its status and its log."""
    try:
        (outcome,) = runner.execute([Step("help", ("--help",))], folder, jobs=1)
    except runner.StepFailed:
        return "failed", (folder / "logs" / "help.log").read_text()
    return outcome.status, (folder / "logs" / "help.log").read_text()


@pytest.mark.skipif(not profile.supported(PROFILE), reason="this processor cannot take the x86-64-v3 profile")
def test_bench_makes_pinned_restart_imports_nothing_from_the_current_folder(tmp_path):
    """`bench make` starts itself again (os.execve) in its numeric profile: that was `python -m
    faultgen.cli` in the current folder, which imported a typer.py or h5py.py planted there."""
    here = tmp_path / "here"
    marks = _plant(here)
    done = _python(f"""
        from faultgen.bench import profile
        profile.restart_pinned({PROFILE!r}, ["--help"])
        raise SystemExit("not restarted")
    """, here, _env())
    assert sorted(p.name for p in marks.iterdir()) == []
    assert done.returncode == 0, done.stderr
    assert "Usage" in done.stdout and "bench" in done.stdout


def test_a_reproduce_step_imports_nothing_from_the_output_folder(tmp_path, monkeypatch):
    """Each `reproduce` step is `faultgen ...` run in the output folder OUT: as `python -m
    faultgen.cli` it imported a typer.py or h5py.py planted in OUT."""
    monkeypatch.delenv("PYTHONSAFEPATH", raising=False)
    out = tmp_path / "out"
    marks = _plant(out)
    status, log = _help_step(out)
    assert sorted(p.name for p in marks.iterdir()) == []
    assert status == "ran" and "Usage" in log, log


def test_a_reproduce_step_with_an_empty_pythonpath_entry_imports_nothing_from_the_output_folder(
        tmp_path, monkeypatch):
    """An empty (or relative) PYTHONPATH entry, as `export PYTHONPATH=$PYTHONPATH:/x` leaves when the
    variable was unset, names the folder a process starts in: for a step, OUT, even with -P. The
    step's PYTHONPATH names the folders the user's command had (made absolute against its folder)."""
    monkeypatch.delenv("PYTHONSAFEPATH", raising=False)
    here, out = tmp_path / "here", tmp_path / "out"
    here.mkdir()
    monkeypatch.chdir(here)
    given = os.environ.get("PYTHONPATH")
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(["", *([given] if given else []), "."]))
    marks = _plant(out)
    status, log = _help_step(out)
    assert sorted(p.name for p in marks.iterdir()) == []
    assert status == "ran" and "Usage" in log, log


def test_a_local_sweeps_workers_import_nothing_from_the_current_folder(tmp_path):
    """`sweep --jobs 2` runs its runs in loky's worker processes (`python -m joblib.externals.loky...`)
    with loky's and multiprocessing's resource trackers (`python -c`), all in the current folder: a
    joblib.py or multiprocessing.py planted there ran in each."""
    here = tmp_path / "here"
    marks = _plant(here)
    sweep = ["sweep", "--robot", "puma560", "--task", "pick_place", "--axis", "0", "--axis", "1",
             "--cycles", "2", "--no-progress", "--jobs", "2", "-o", "s.h5"]
    done = subprocess.run([sys.executable, "-P", "-m", "faultgen.cli", *sweep], cwd=here, env=_env(),
                          check=False, capture_output=True, text=True, timeout=300)
    assert sorted(p.name for p in marks.iterdir()) == []
    assert done.returncode == 0, done.stderr
    with h5py.File(here / "s.h5") as f:
        assert len(f["runs"]) == 2


def test_classifys_parallel_pairs_import_nothing_from_the_current_folder(tmp_path):
    """`classify` fits its held-out pairs in loky's workers (joblib's default backend), started in the
    current folder like a sweep's: a joblib.py planted there ran in each."""
    here = tmp_path / "here"
    marks = _plant(here)
    done = _python("""
        from functools import partial
        import numpy as np
        from analysis import classify
        rng = np.random.default_rng(0)
        groups = np.repeat(["worn0", "worn1", "nowear0", "nowear1"], 20).astype(object)
        y = np.tile((np.arange(20) >= 10).astype(int), 4) * np.isin(groups, ["worn0", "worn1"])
        X = rng.normal(size=(80, 3)) + 3 * y[:, None]
        failed, normal = ["worn0", "worn1"], ["nowear0", "nowear1"]
        lr = partial(classify.make_pipeline, "lr")
        aucs = classify.leave_pair_out_auc(lr, X, y, groups, failed, normal, n_jobs=2)
        table = classify.evaluate(X, y, groups, failed, normal, classifiers=["lr"], preprocessing=["control"],
                                     n_jobs=2)
        print(len(aucs), aucs.min() > 0.9, table.shape)
    """, here, _env())
    assert sorted(p.name for p in marks.iterdir()) == []
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["4", "True", "(1,", "2)"], done.stdout
