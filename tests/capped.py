"""Run faultgen's command line in a child process under a memory cap, as an attacker's repro runs it.

The hostile-input findings are judged "within a 4 GB address-space cap" (``RLIMIT_AS``): a reader
whose memory is not bounded by the file's declared sizes dies there with ``MemoryError`` (a
traceback) or is killed, where a bounded one refuses in one line. The child is started with ``-P``
(no current folder on its path, :func:`faultgen.children.command`) in ``cwd``.
"""

from __future__ import annotations

import resource
import subprocess
from pathlib import Path

from faultgen import children

#: The address-space cap the findings were tried under.
CAP_BYTES = 4 * 2**30


def run(*args: str, cwd: str | Path | None = None, cap: int = CAP_BYTES, timeout: float = 300,
        env: dict | None = None) -> subprocess.CompletedProcess:
    """``faultgen ARGS`` in a child process whose address space is capped at ``cap`` bytes; its
    output as text (``stdout``, ``stderr``) and its ``returncode``."""

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))

    return subprocess.run(children.command("-m", "faultgen.cli", *map(str, args)), cwd=cwd, env=children.environment(env),
                          capture_output=True, text=True, timeout=timeout, preexec_fn=limit, check=False)


def one_line_refusal(done: subprocess.CompletedProcess, *names: str) -> str:
    """The error line of a refused run, after checking it is exit 2, no traceback, and names each of ``names``."""
    text = done.stdout + done.stderr
    assert done.returncode == 2, text[-3000:]
    assert "Traceback" not in text and "MemoryError" not in text, text[-3000:]
    for name in names:
        assert str(name) in text, (name, text[-3000:])
    return text
