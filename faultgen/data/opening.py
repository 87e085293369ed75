"""The one gate every read of a dataset passes: :func:`open_file` opens a finished faultgen file
or raises :class:`~faultgen.data.schema.DatasetError` saying why not.

A file is written under a temporary name in its target folder and renamed into place once
complete (:mod:`faultgen.data.atomic`), so a crash or kill never leaves a file at the target path
that looks finished; :func:`open_file` refuses a file whose ``complete`` attribute is not set, one
another process is writing, and (:func:`faultgen.data.structure.check_runs`) runs whose labels or
declared shapes are wrong, before any array is read.
"""

from __future__ import annotations

import errno
from contextlib import contextmanager
from pathlib import Path

import h5py

from faultgen import inputs
from faultgen.data import atomic, structure
from faultgen.data.schema import BINS, FORMAT, FORMAT_VERSION, SHAPES, DatasetError, kinds


@contextmanager
def open_file(path: str | Path):
    """Open a finished faultgen file for reading, or raise DatasetError saying why not."""
    writer = atomic.writer_of(Path(path))
    if writer is not None:
        raise DatasetError(f"{path} is in use: process {writer} is writing it (the finished file appears under "
                           "its own name when it is done)")
    if Path(path).exists() and not Path(path).is_dir():
        inputs.regular_file(path, "dataset")  # /dev/zero, a FIFO: refused before h5py waits on it
    try:
        f = h5py.File(path, "r")
    except FileNotFoundError:
        raise DatasetError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise DatasetError(f"{path} is a folder, not a dataset file") from None
    except OSError as err:
        if err.errno == errno.EAGAIN or "unable to lock file" in str(err).lower():
            raise DatasetError(f"{path} is in use: another process has it open for writing; wait for it to "
                               "finish") from None
        raise DatasetError(f"{path}: cannot be opened as HDF5 (truncated or not HDF5): {err}") from None
    try:
        inputs.check_hdf5_links(f, path)  # before anything is read through a link to another file
        if f.attrs.get("format") != FORMAT:
            raise DatasetError(f"{path} is not a faultgen file (format attribute {f.attrs.get('format')!r})")
        if not f.attrs.get("complete", False):
            raise DatasetError(f"{path} is incomplete: its writer did not finish")
        if "runs" not in f:
            raise DatasetError(f"{path} has no /runs group")
        if f.attrs.get("format_version") != FORMAT_VERSION:
            raise DatasetError(f"{path} has format_version {attr(f.attrs.get('format_version')).item() if hasattr(f.attrs.get('format_version'), 'item') else f.attrs.get('format_version')!r}; this faultgen "
                               f"reads version {FORMAT_VERSION}")
        if len(f["runs"]) == 0:
            raise DatasetError(f"{path} has no runs (its /runs group is empty)")
        structure.check_runs(f, path, SHAPES, BINS, kinds)
        yield f
    finally:
        f.close()


def attr(value):
    """An HDF5 attribute as Python: stored text (bytes) decoded, anything else as read."""
    return value.decode() if isinstance(value, bytes) else value
