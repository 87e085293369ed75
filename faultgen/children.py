"""How faultgen starts Python again: with no folder of the user's on the child's import path.

``python -m MODULE`` and ``python -c CODE`` put the current folder first on ``sys.path``, so a
child started in a folder that holds a ``joblib.py`` or ``typer.py`` (a folder from a stranger, a
reproduction's output folder) imports that file instead of the package: its code runs with the
user's rights. Python 3.11's ``-P`` (``PYTHONSAFEPATH=1`` in the environment) leaves that folder
out; every Python faultgen starts gets the variable, and the flag where faultgen writes the command
line:

- ``faultgen bench make``'s restart in a numeric profile (:func:`faultgen.bench.profile.restart_pinned`)
  and every ``faultgen reproduce`` step run as a command (:mod:`faultgen.reproduce.runner`, in the
  output folder): :func:`command` (``-P``) and :func:`environment`;
- the processes joblib (loky) and multiprocessing start themselves (a local sweep's workers,
  ``classify``'s, their resource trackers), which take this process's environment:
  :func:`safe_path` sets ``PYTHONSAFEPATH=1`` while they are started. The variable also reaches
  whatever a child started by :func:`command` starts in turn.

``PYTHONPATH`` keeps its folders, but an empty or relative entry is made absolute against this
process's current folder: Python resolves it against the folder a process starts in, which for a
reproduce step is the output folder (``PYTHONPATH=:/x``, the usual result of appending to an unset
variable, would put the output folder ahead of the installed packages). Resolved here, it names
the folder it named for this process, which has imported through it already; dropping it would
break ``PYTHONPATH=.`` in a source checkout and protect nothing.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator, Mapping
from contextlib import contextmanager

#: What keeps a Python 3.11+ process from putting its current (or script's) folder on ``sys.path``.
SAFE_PATH = {"PYTHONSAFEPATH": "1"}


def command(*args: str) -> list[str]:
    """This Python run with ``args`` (``"-m", "faultgen.cli", ...``) and ``-P``: no current or
    script folder on its path."""
    return [sys.executable, "-P", *args]


def python_path(value: str, here: str | None = None) -> str:
    """``PYTHONPATH`` ``value`` with every empty or relative entry made absolute against ``here``
    (default: the current folder), the others as they are."""
    here = here or os.getcwd()
    return os.pathsep.join(os.path.normpath(os.path.join(here, entry)) if not os.path.isabs(entry) else entry
                           for entry in value.split(os.pathsep))


def environment(extra: Mapping[str, str] | None = None) -> dict[str, str]:
    """The environment for a child Python: this process's with ``extra``, ``PYTHONSAFEPATH=1`` and
    ``PYTHONPATH``'s entries absolute (:func:`python_path`)."""
    env = {**os.environ, **(extra or {}), **SAFE_PATH}
    if env.get("PYTHONPATH"):
        env["PYTHONPATH"] = python_path(env["PYTHONPATH"])
    return env


@contextmanager
def safe_path() -> Iterator[None]:
    """Set ``PYTHONSAFEPATH=1`` in this process's environment while the block runs, for the Python
    processes libraries start from it (loky's workers run ``python -m``, its and multiprocessing's
    resource trackers ``python -c``, all in this process's folder); the value before is restored."""
    before = os.environ.get("PYTHONSAFEPATH")
    os.environ.update(SAFE_PATH)
    try:
        yield
    finally:
        if before is None:
            os.environ.pop("PYTHONSAFEPATH", None)
        else:
            os.environ["PYTHONSAFEPATH"] = before
