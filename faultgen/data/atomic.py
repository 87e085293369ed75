"""Write a file so that a crash or a kill never leaves one that looks complete but is not."""

from __future__ import annotations

import errno
import glob
import logging
import os
import re
import shutil
import socket
import sys
import tempfile
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import h5py

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
    path, part = _part_beside(path)
    try:
        fd, tmp = tempfile.mkstemp(**part)
    except OSError as err:  # a read-only folder: name the file asked for, not the hidden temporary one
        raise _naming(err, path) from None
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the file normal permissions
        os.replace(tmp, path)
    except OSError as err:
        Path(tmp).unlink(missing_ok=True)
        named = (err.strerror or "").startswith("cannot write")  # hdf5_writer's error already names it
        if (err.filename is None and not named) or (err.filename is not None and Path(err.filename) == Path(tmp)):
            raise _naming(err, path) from None  # a full disk names no file: name the one asked for
        raise
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _naming(err: OSError, path: Path | str) -> OSError:
    """``err`` as an OSError naming ``path`` (the output a user asked for) instead of a hidden
    temporary file or folder beside it, with the same errno."""
    reason = err.strerror or str(err)
    return OSError(err.errno, f"cannot write {path}: {reason}")


@contextmanager
def output_set(paths: Iterable[str | Path]) -> Iterator[Callable[[str | Path], Path]]:
    """Write the outputs of one command as a set: all of them appear, or none.

    Yields ``staged``: ``staged(target)`` is where to write ``target`` (any file in the folder of
    one of ``paths``; a stem a writer extends with suffixes works too): a hidden folder beside it
    (``.<name>.<pid>@<host>.<random>.part``, named after the first of ``paths`` in that folder).
    When the block succeeds, every file written there is renamed onto its target, each rename
    replacing an existing file; on any exception nothing is renamed (earlier outputs of the same
    names are untouched), the hidden folders are removed, and an ``OSError`` about a staged file
    names its target instead. A kill leaves only the hidden folders, which the next write of the
    same outputs removes (:func:`remove_stale`). Only a kill during the renames themselves (one
    system call per file, after every file is complete) can leave part of a set.

    Raises
    ------
    OSError
        If a folder does not exist or cannot be written, or a write failed (naming the target).
    """
    targets = [Path(p) for p in paths]
    stages: dict[Path, Path] = {}
    try:
        for target in targets:
            folder = target.parent if str(target.parent) else Path(".")
            if folder in stages:
                continue
            if not folder.is_dir():
                raise OSError(errno.ENOENT, f"cannot write {target}: folder {folder} does not exist")
            for other in targets:
                remove_stale(other)
            try:
                stage = Path(tempfile.mkdtemp(prefix=f".{target.name}.{os.getpid()}@{_host()}.", suffix=".part",
                                              dir=folder))
            except OSError as err:
                raise _naming(err, target) from None
            os.chmod(stage, 0o777 & ~_umask())
            stages[folder] = stage

        def staged(path: str | Path) -> Path:
            path = Path(path)
            folder = path.parent if str(path.parent) else Path(".")
            if folder not in stages:
                raise ValueError(f"{path} is not in the folder of an output of this set ({', '.join(map(str, targets))})")
            return stages[folder] / path.name

        try:
            yield staged
        except OSError as err:
            for folder, stage in stages.items():
                if err.filename is not None and Path(err.filename).parent == stage:
                    raise _naming(err, folder / Path(err.filename).name) from None
            if err.filename is None:  # a failed write names no file (ENOSPC, EFBIG): name the set
                raise _naming(err, ", ".join(map(str, targets))) from None
            raise
        for folder, stage in stages.items():
            for entry in sorted(stage.iterdir()):
                os.chmod(entry, 0o666 & ~_umask())
                os.replace(entry, folder / entry.name)
    finally:
        for stage in stages.values():
            shutil.rmtree(stage, ignore_errors=True)


@contextmanager
def atomic_folder(path: str | Path) -> Iterator[Path]:
    """Yield a new hidden folder to write into; when the block succeeds its entries become those of
    ``path``. A new ``path`` is staged beside it and renamed into place whole (one rename: all or
    nothing). An existing folder ``path`` is staged *inside* it (``path/.<name>.<pid>@<host>.<random>.part``),
    on its own file system: a folder that is a mount point of its own (a docker or k8s volume, NFS)
    or that lies in a read-only folder is written like any other (a rename out of it fails with
    EXDEV, a folder beside it cannot be made). Each entry written then replaces the entry of that
    name in ``path`` (other entries of ``path`` are kept) in one system call: a file by a rename, a
    folder (``OUT/.state``) by an exchange with the old one (:func:`exchange`) so that ``path`` has
    the old entry or the new one at every instant. Where a file system cannot exchange, the old
    folder is moved into ``.replaced`` in the stage and the new one renamed in its place: a kill
    between the two leaves the old one there, and the next write of ``path`` (:func:`remove_stale`)
    moves it back before anything reads ``path``. On any exception the stage is removed and ``path``
    is untouched; a kill leaves only the stage, which the next write of ``path`` removes.

    Raises
    ------
    OSError
        If the folder of a new ``path`` does not exist, or the stage cannot be made (naming ``path``).
    """
    path = Path(path)
    if path.is_dir():
        remove_stale(path)
        name = path.absolute().name
        part = {"prefix": f".{name}.{os.getpid()}@{_host()}.", "suffix": ".part", "dir": path}
    else:
        path, part = _part_beside(path)
    try:
        staging = Path(tempfile.mkdtemp(**part))
    except OSError as err:  # a read-only folder: name the folder asked for, not the hidden one
        raise _naming(err, path) from None
    try:
        os.chmod(staging, 0o777 & ~_umask())
        yield staging
        if part["dir"] == path:  # keep what else the folder holds: replace only what was written, entry by entry
            for entry in sorted(staging.iterdir()):
                _put(entry, path / entry.name, staging / REPLACED)
        else:
            os.replace(staging, path)
    finally:
        try:
            if part["dir"] == path:  # a rename that failed between the two of a folder: the old one back
                _give_back(staging / REPLACED, path)
        except OSError:  # kept in the stage, which the next write of path gives back (remove_stale)
            pass
        else:
            shutil.rmtree(staging, ignore_errors=True)


#: The folder of a stage (:func:`atomic_folder`) that keeps the entries it replaced where the file
#: system cannot exchange two folders: what :func:`remove_stale` moves back after a kill.
REPLACED = ".replaced"


def _put(entry: Path, target: Path, aside: Path) -> None:
    """``entry`` in place of ``target`` in one system call where the file system allows it
    (:func:`atomic_folder`); a replaced folder that cannot be exchanged goes to ``aside`` first."""
    def folder(p: Path) -> bool:
        return p.is_dir() and not p.is_symlink()

    if not (target.exists() or target.is_symlink()) or not (folder(entry) or folder(target)):
        os.replace(entry, target)  # nothing there, or a file onto a file or a link: one rename
    elif not exchange(entry, target):
        aside.mkdir(exist_ok=True)
        os.replace(target, aside / entry.name)
        os.replace(entry, target)


_RENAME_EXCHANGE, _AT_FDCWD = 2, -100
_renameat2 = None


def exchange(a: str | Path, b: str | Path) -> bool:
    """Swap the entries ``a`` and ``b`` (of one file system) in one system call: Linux's
    ``renameat2(RENAME_EXCHANGE)`` (glibc 2.28, kernel 3.15), through ctypes. True when swapped;
    False where the system or the file system has no such call (macOS, musl, NFS, some overlayfs), nothing
    done.

    Raises
    ------
    OSError
        Any other failure of the call (naming ``a`` and ``b``).
    """
    global _renameat2
    if _renameat2 is None:
        _renameat2 = False
        if sys.platform.startswith("linux"):
            import ctypes

            try:
                call = ctypes.CDLL(None, use_errno=True).renameat2
            except (AttributeError, OSError):
                pass
            else:
                call.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
                call.restype = ctypes.c_int
                _renameat2 = call
    if not _renameat2:
        return False
    import ctypes

    if _renameat2(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP, errno.ENOTSUP, errno.EXDEV):  # overlayfs: EXDEV
        return False
    raise OSError(code, os.strerror(code), str(a), None, str(b))


def remove_stale(path: str | Path) -> list[Path]:
    """Remove the temporary files and folders of ``path`` (:func:`atomic_path`, :func:`output_set`,
    :func:`atomic_folder`: beside ``path``, and inside it when it is a folder) whose writer was killed.

    A temporary entry is stale when its writer ran on this host and no process with its pid runs
    any more. Entries of a running writer, of another host (a shared file system), links (faultgen
    never makes one there: a link with such a name is passed over, never followed) and entries not
    named so are left alone. A stage of :func:`atomic_folder` killed between the two renames of a
    folder that could not be exchanged gives back what it replaced (:data:`REPLACED`) where
    ``path`` lacks it: a state a run had not replaced is never deleted. Each removal is logged
    (logger ``faultgen.data.atomic``, level WARNING, so it is printed unless logging is configured
    otherwise).

    Returns
    -------
    list of Path
        The files and folders removed.
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    places = [(folder, path.name)]
    if path.is_dir():  # an existing folder's stages lie inside it (atomic_folder)
        places.append((path, path.absolute().name))
    removed = []
    for where, name in places:
        pattern = re.compile(rf"\.{re.escape(name)}\.(\d+)@(.+)\.[^.]+\.part")
        for candidate in sorted(where.glob(f".{glob.escape(name)}.*.part")):
            match = pattern.fullmatch(candidate.name)
            if match is None or candidate.is_symlink() or match[2] != _host() or _running(int(match[1])):
                continue
            try:
                if candidate.is_dir():  # a folder written whole, or a stage (atomic_folder, output_set)
                    _give_back(candidate / REPLACED, path)
                    size = sum(f.lstat().st_size for f in candidate.rglob("*") if f.is_file() and not f.is_symlink())
                    shutil.rmtree(candidate)
                else:
                    size = candidate.stat().st_size
                    candidate.unlink()
            except FileNotFoundError:  # removed by another writer meanwhile
                continue
            log.warning("removed %s (%.1f MB), an unfinished write of %s left by a killed process (pid %s)",
                        candidate, size / 1e6, path.name, match[1])
            removed.append(candidate)
    return removed


def _give_back(replaced: Path, path: Path) -> None:
    """Move each entry of a killed stage's ``replaced`` folder (:data:`REPLACED`) back into the
    folder ``path`` where ``path`` has no entry of its name (the kill came between its two renames)."""
    if not replaced.is_dir() or replaced.is_symlink() or not path.is_dir():
        return
    for entry in sorted(replaced.iterdir()):
        target = path / entry.name
        if not (target.exists() or target.is_symlink()):
            os.replace(entry, target)
            log.warning("restored %s, which a process killed while replacing it had moved aside", target)


class _WriteSink:
    """An unbuffered file for h5py's ``fileobj`` driver that never reports a write failure to HDF5.

    HDF5 cannot recover from a failed write: when the disk is full (ENOSPC), a file-size limit is
    reached (EFBIG) or the device fails (EIO), closing the file fails part-way, HDF5 frees part of
    the file's state, and h5py's next close of the same id reads freed memory and crashes the
    interpreter with a segmentation fault (h5py issues 914 and 1642, seen here as rc 139 with
    148 KB free). So the first failed write is kept in :attr:`error` and every later write, seek
    or truncate only moves the position: HDF5 finishes and closes normally, and the caller
    (:func:`hdf5_writer`) raises the kept error and removes the unfinished file.
    """

    def __init__(self, path: Path) -> None:
        self._file = open(path, "r+b", buffering=0)
        self.error: OSError | None = None
        self._position = 0

    def write(self, data) -> int:
        size = len(memoryview(data).cast("B"))
        if self.error is None:
            try:
                self._file.seek(self._position)
                view = memoryview(data).cast("B")
                while view:  # a raw write may write part of the buffer
                    written = self._file.write(view)
                    view = view[written:]
            except OSError as err:
                self.error = err
        self._position += size
        return size

    def read(self, size: int = -1) -> bytes:
        self._file.seek(self._position)
        data = self._file.read(size)
        self._position += len(data)
        return data

    def readinto(self, buffer) -> int:
        self._file.seek(self._position)
        n = self._file.readinto(buffer)
        self._position += n or 0
        return n

    def seek(self, offset: int, whence: int = 0) -> int:
        if whence == 0:
            self._position = offset
        elif whence == 1:
            self._position += offset
        else:
            self._position = max(self._file.seek(0, 2), self._position) + offset
        return self._position

    def tell(self) -> int:
        return self._position

    def truncate(self, size: int | None = None) -> int:
        if self.error is None:
            try:
                self._file.truncate(self._position if size is None else size)
            except OSError as err:
                self.error = err
        return self._position if size is None else size

    def flush(self) -> None:
        pass

    def close(self) -> None:
        try:
            os.fsync(self._file.fileno())  # a delayed-allocation file system reports ENOSPC here
        except OSError as err:
            self.error = self.error or err
        finally:
            self._file.close()


@contextmanager
def hdf5_writer(path: str | Path) -> Iterator["h5py.File"]:
    """Open a new HDF5 file to be written at ``path``, atomically (:func:`atomic_path`), so that
    an I/O failure (full disk, file-size limit, failing device) raises an :class:`OSError` naming
    ``path`` and never crashes the interpreter (:class:`_WriteSink`); nothing is left at ``path``
    and the temporary file is removed.

    Raises
    ------
    OSError
        If the folder does not exist or cannot be written, or a write failed.
    """
    import h5py

    path = Path(path)
    with atomic_path(path) as tmp:
        sink = _WriteSink(tmp)
        try:
            with h5py.File(sink, "w", driver="fileobj") as f:
                yield f
        finally:
            sink.close()
        if sink.error is not None:
            err = sink.error
            raise OSError(err.errno, f"cannot write {path}: {err.strerror or err}") from None


def check_writable(path: str | Path, needed: int = 0) -> None:
    """Check, before any work, that a file can be written at ``path``: its folder exists, a file
    can be created in it (a probe file, created and removed: this sees a read-only file system, a
    folder without write permission and a full disk alike), and it has ``needed`` bytes free.

    Raises
    ------
    OSError
        Naming the folder and the reason (errno ENOENT, EROFS, EACCES, ENOSPC, ...).
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise OSError(errno.ENOENT, f"cannot write {path}: folder {folder} does not exist")
    try:
        fd, probe = tempfile.mkstemp(prefix=f".{path.name}.probe.", dir=folder)
    except OSError as err:
        reason = err.strerror
        if err.errno == errno.ENOENT:  # the folder exists, yet a file cannot be made in it (/proc)
            reason = "this folder takes no new files (a virtual file system such as /proc or /sys)"
        raise OSError(err.errno, f"cannot write in {folder}: {reason}") from None
    try:
        os.close(fd)
    finally:
        os.unlink(probe)
    free = shutil.disk_usage(folder).free
    if needed > free:
        raise OSError(errno.ENOSPC, f"cannot write {path}: it needs about {_size(needed)} and {folder} has "
                      f"{_size(free)} free")


def _size(n: float) -> str:
    for unit in ("bytes", "KB", "MB", "GB"):
        if n < 1000 or unit == "GB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1000
    return f"{n:.1f} TB"


def write_text(path: str | Path, text: str) -> None:
    """Write ``text`` to ``path`` atomically (:func:`atomic_path`)."""
    with atomic_path(path) as tmp:
        tmp.write_text(text)


def writer_of(path: str | Path) -> int | None:
    """The pid of the running process writing ``path``, if ``path`` is the temporary file of an
    atomic write (``.<name>.<pid>@<host>.<random>.part``, :func:`atomic_path`) of a process that
    still runs on this host; else None."""
    match = re.fullmatch(r"\.(.+)\.(\d+)@(.+)\.[^.]+\.part", Path(path).name)
    if match is None or match[3] != _host() or not _running(int(match[2])):
        return None
    return int(match[2])


def _part_beside(path: str | Path) -> tuple[Path, dict]:
    """``path`` as a :class:`~pathlib.Path` and the ``tempfile.mkstemp``/``mkdtemp`` arguments of its
    hidden part (``.<name>.<pid>@<host>.<random>.part`` in its folder), once the folder is checked and
    the parts a killed writer left are removed (:func:`remove_stale`).

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
    return path, {"prefix": f".{path.name}.{os.getpid()}@{_host()}.", "suffix": ".part", "dir": folder}


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


def check_apart(out: str | Path, folder: str | Path, what: str = "the logs folder") -> None:
    """Refuse, before any work, an output ``out`` that is the input ``folder`` itself, lies inside
    it or contains it (both resolved: symbolic links followed, ``..`` removed). An output inside a
    folder that a later run reads as a whole (a fleet's LOGS) is read back as one of its entries
    and breaks that run; an output that is or holds the folder would replace entries of it.

    Raises
    ------
    ValueError
        Naming ``out`` and ``folder`` as given, and what to do.
    """
    from faultgen import inputs

    here, there = inputs.resolved(Path(out).absolute()), inputs.resolved(Path(folder).absolute())
    if here == there:
        raise ValueError(f"{out} is {what} {folder} itself; write the results into a folder outside {folder}")
    if there in here.parents:
        raise ValueError(f"{out} lies inside {what} {folder}: a later run would read it as part of the folder; "
                         f"write it outside {folder}")
    if here in there.parents:
        raise ValueError(f"{out} contains {what} {folder}, whose entries its outputs could replace; write the "
                         f"results into a folder outside {folder}")
