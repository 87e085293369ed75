"""Round 10 (helper sbench): `faultgen bench make` restarts in its version's numeric profile before
the command line's modules load (faultgen.bench.restart.restart_early, called by ``python -m
faultgen.cli``); the command's own restart stays behind it for what the early one leaves."""

from __future__ import annotations

import subprocess
import sys

import pytest

from faultgen import children
from faultgen.bench import profile, restart, tracks


@pytest.mark.parametrize(("argv", "restarted"), [
    (["bench", "make", "thesis", "-o", "x"], "x86-64-v3"),
    (["bench", "make", "-o", "x", "--size", "small", "prognostics", "--no-progress", "--jobs", "2"], "x86-64-v3"),
    (["bench", "make", "thesis", "--out=x", "--version", "2", "--freeze"], "x86-64-v3"),
    (["bench", "make", "thesis", "--version", "1", "-o", "x"], None),  # version 1: no profile, no restart
    (["bench", "make", "thesis", "--version=1"], None),
    # left to the command (which restarts or names the problem): help, unknown words, bad values
    (["bench", "make", "--help"], "left"),
    (["bench", "make", "thesis", "--help"], "left"),
    (["bench", "make", "thesis", "-ox"], "left"),
    (["bench", "make", "thesis", "extra"], "left"),
    (["bench", "make", "nope", "-o", "x"], "left"),
    (["bench", "make", "thesis", "--version", "x"], "left"),
    (["bench", "make", "thesis", "--version", "9"], "left"),
    (["bench", "make", "thesis", "--version"], "left"),
    (["bench", "make", "-o", "x"], "left"),
    (["bench", "score", "thesis"], "left"),
    (["simulate", "bench", "make"], "left"),
])
def test_the_early_restart_reads_the_track_and_version_as_the_command_does(monkeypatch, argv, restarted):
    """``restarted``: the profile handed to restart_pinned (None: the version has none), or "left" when
    restart_early hands nothing and leaves the command to it."""
    calls = []
    monkeypatch.setattr(profile, "restart_pinned", lambda name, args: calls.append((name, args)))
    restart.restart_early(argv)
    assert calls == ([] if restarted == "left" else [(restarted, argv)])
    if restarted not in (None, "left"):  # the same profile the command reads from the track file
        assert tracks.load(next(w for w in argv[2:] if w in tracks.names())).version().profile == restarted


def test_python_m_faultgen_cli_restarts_a_profiled_make_before_the_commands_load(tmp_path):
    """``python -m faultgen.cli bench make thesis ...`` in a shell without the profile, as runpy runs it
    (the package imported with ``sys.argv[0] == "-m"``, then its ``__main__``): the process is replaced
    (os.execve, stubbed here to report) by ``python -P -m faultgen.cli`` with the profile's variables
    while none of the command modules is loaded. Where this processor cannot take the profile, nothing
    restarts (the make goes on unpinned, as before)."""
    stub = ("import os, runpy, sys\n"
            "def execve(path, args, env):\n"
            "    loaded = sorted(m for m in sys.modules if m.startswith('faultgen.cli.'))\n"
            "    print('restart', args[1:], env.get('OPENBLAS_CORETYPE'), env.get('PYTHONSAFEPATH'), loaded)\n"
            "    sys.exit(0)\n"
            "os.execve = execve\n"
            "args = ['bench', 'make', 'thesis', '--size', 'small', '-o', 'never']\n"
            "sys.argv, sys.orig_argv = ['-m', *args], [sys.executable, '-P', '-m', 'faultgen.cli', *args]\n"
            "runpy.run_module('faultgen.cli', run_name='__main__', alter_sys=True)\n"
            "print('no restart')\n")
    env = children.environment()
    for name in (*profile.PROFILES["x86-64-v3"], "_FAULTGEN_PROFILE_RESTART"):
        env.pop(name, None)
    done = subprocess.run(children.command("-c", stub), env=env, cwd=tmp_path, capture_output=True, text=True,
                          timeout=120, check=False)
    if profile.supported("x86-64-v3"):
        expected = ("restart ['-P', '-m', 'faultgen.cli', 'bench', 'make', 'thesis', '--size', 'small', '-o', "
                    "'never'] Haswell 1 []")
        assert done.stdout.strip() == expected, done.stdout + done.stderr
    else:
        assert done.stdout.strip() == "no restart", done.stdout + done.stderr
    assert not (tmp_path / "never").exists()


@pytest.mark.parametrize(("argv", "orig", "command"), [
    (["-m", "bench", "make"], ["python", "-P", "-m", "faultgen.cli", "bench", "make"], ["bench", "make"]),
    (["/venv/bin/faultgen", "bench", "make"], ["python", "/venv/bin/faultgen", "bench", "make"], ["bench", "make"]),
    # a program that imports faultgen.cli, with the same arguments: not the command line
    (["my_script.py", "bench", "make"], ["python", "my_script.py", "bench", "make"], None),
    (["-m", "bench", "make"], ["python", "-m", "pytest", "bench", "make"], None),
    (["-c", "bench", "make"], ["python", "-c", "import faultgen.cli", "bench", "make"], None),
])
def test_only_the_command_line_itself_restarts(monkeypatch, argv, orig, command):
    monkeypatch.setattr(sys, "argv", argv)
    monkeypatch.setattr(sys, "orig_argv", orig)
    assert restart.command_line() == command
