"""Count the files opened under a folder while a block runs (tests/test_read_once.py, issue 57 item 2).

Every open the interpreter makes is seen through its ``open`` audit event (``builtins.open``,
``io.open``, ``os.open``, ``gzip.open``, ``Path.open``, pandas given a path: PEP 578), and HDF5
files, which h5py opens in C, through a wrapper around ``h5py.File``; pyarrow's own file opens (a
Parquet path) are not seen, which the measured format does not use.
"""

from __future__ import annotations

import os
import sys
from collections import Counter
from contextlib import contextmanager
from pathlib import Path

_ACTIVE: list[tuple[Path, Counter]] = []  # the running counts (an audit hook cannot be removed)
_HOOKED = False


def _record(name) -> None:
    if isinstance(name, int) or not _ACTIVE:
        return
    path = Path(os.fsdecode(name)).resolve()
    for root, counts in _ACTIVE:
        if path.is_relative_to(root):
            counts[path.relative_to(root).as_posix()] += 1


def _hook(event: str, args: tuple) -> None:
    if event == "open" and _ACTIVE:
        _record(args[0])


@contextmanager
def opens_under(root: str | Path):
    """A :class:`collections.Counter` of ``relative path -> times opened`` of the files under ``root``
    opened (by this process) while the ``with`` block runs."""
    global _HOOKED
    import h5py

    if not _HOOKED:
        sys.addaudithook(_hook)
        _HOOKED = True
    counts: Counter = Counter()
    entry = (Path(root).resolve(), counts)
    original = h5py.File

    class File(original):  # an HDF5 file by name is opened in C, without an audit event
        def __init__(self, name, *args, **kwargs):
            if isinstance(name, (str, bytes, os.PathLike)):
                _record(name)
            super().__init__(name, *args, **kwargs)

    _ACTIVE.append(entry)
    h5py.File = File
    try:
        yield counts
    finally:
        h5py.File = original
        _ACTIVE.remove(entry)
