"""Write a file so that a crash or a kill never leaves one that looks complete but is not."""

from __future__ import annotations

import glob
import logging
import os
import re
import socket
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

log = logging.getLogger(__name__)


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it onto ``path`` if the block succeeds.

    On any exception (or a kill before the rename) ``path`` is untouched, and the temporary
    file is removed when the block raises. The temporary file is hidden and named after
    ``path`` and its writer (``.<name>.<pid>@<host>.<random>.part``), so that the next write of
    ``path`` finds the ones a killed writer left and removes them (:func:`remove_stale`).

    Raises
    ------
    OSError
        If the folder of ``path`` does not exist.
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise OSError(f"cannot write {path}: folder {folder} does not exist")
    remove_stale(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.{os.getpid()}@{_host()}.", suffix=".part", dir=folder)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the file normal permissions
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def remove_stale(path: str | Path) -> list[Path]:
    """Remove the temporary files of ``path`` (:func:`atomic_path`) whose writer was killed.

    A temporary file is stale when its writer ran on this host and no process with its pid runs
    any more. Files of a running writer, of another host (a shared file system) or not named by
    :func:`atomic_path` are left alone. Each removal is logged (logger ``faultgen.atomic``,
    level WARNING, so it is printed unless logging is configured otherwise).

    Returns
    -------
    list of Path
        The files removed.
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    pattern = re.compile(rf"\.{re.escape(path.name)}\.(\d+)@(.+)\.[^.]+\.part")
    removed = []
    for candidate in folder.glob(f".{glob.escape(path.name)}.*.part"):
        match = pattern.fullmatch(candidate.name)
        if match is None or match[2] != _host() or _running(int(match[1])):
            continue
        try:
            size = candidate.stat().st_size
            candidate.unlink()
        except FileNotFoundError:  # removed by another writer meanwhile
            continue
        log.warning("removed %s (%.1f MB), an unfinished write of %s left by a killed process (pid %s)",
                    candidate, size / 1e6, path.name, match[1])
        removed.append(candidate)
    return removed


def write_text(path: str | Path, text: str) -> None:
    """Write ``text`` to ``path`` atomically (:func:`atomic_path`)."""
    with atomic_path(path) as tmp:
        tmp.write_text(text)


def _host() -> str:
    return socket.gethostname().replace("/", "_")


def _running(pid: int) -> bool:
    """True if a process with this pid exists on this host (it may be one the pid was reused for)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by another user
        return True
    return True


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
