"""Readers' first line of defence: every file a stranger may hand faultgen (a DH table, a drivetrain
or program file, a sweep config, a measured or replayed log, a dataset) is opened through here.

What is refused, before any parser sees the content (docs/reliability.md, "Threat model: data
files"):

* anything but a regular file (a device such as ``/dev/zero``, a FIFO, a folder, a symlink to
  one of these), and a file above the reader's size bound;
* a path that leads, through a symbolic link, out of the folder it must stay in (:func:`within`:
  a fleet's log folder; :func:`inside` for the folders a robot description may read);
* TOML nested deeper than :data:`TOML_MAX_DEPTH` brackets or with a dotted key of more than
  :data:`TOML_MAX_KEY_PARTS` parts (``tomllib`` is quadratic in a dotted key's length and recurses
  once per bracket: a 200 kB key of 10^5 parts took 19.6 GB, 5x10^4 brackets a RecursionError);
* an HDF5 file holding an external link, a soft link that does not resolve inside the file, a
  virtual dataset or a dataset whose raw data lives in an external file: each would make a
  reader open a file it was not given;
* an HDF5 dataset whose declared shape or element count is not the expected one (a 76 MB file
  can declare (10^10, 6) float64: 447 GiB on read), or whose type is not numeric;
* a gzip stream that inflates beyond :data:`GZIP_MAX_RATIO` times its compressed size (a bomb),
  checked while it is read, so at most a few MiB are inflated before the refusal;
* a CSV header line longer than :data:`CSV_HEADER_MAX_BYTES` or naming more than
  :data:`CSV_MAX_COLUMNS` columns (:func:`csv_header`), before the rows are parsed: a header of
  32 000 extra columns (477 kB) cost the whole-log reader 2.6 GB and ``std::bad_alloc``.

Every refusal is an :class:`InputError` (a ``ValueError``: the command line prints it as one
``error:`` line and exits 2) whose message starts with the file's path and names the key, link,
dataset or row at fault and what was expected.

A file read once and handed on as its bytes (:class:`Held`, :func:`hold`: ``faultgen monitor``
reads each log once) is taken by :func:`regular_file`, :func:`is_gzip`, :func:`open_bytes` and
what is built on them (:func:`open_text`, :func:`count_lines`, :func:`csv_header`) as its file,
with the same checks and messages, without opening the file again.

This module imports no other faultgen layer, so every layer may use it.
"""

from __future__ import annotations

import gzip
import hashlib
import io
import os
import re
import stat
import tomllib
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: Size bound of a TOML file (DH table, drivetrain, program, sweep config, tasks file), bytes. The
#: largest file the project writes (a program of a few hundred moves) is tens of kB.
TOML_MAX_BYTES = 4 * 2**20
#: Deepest bracket nesting (arrays and inline tables) a TOML file may have; the project's files use 2.
TOML_MAX_DEPTH = 32
#: Most parts of one dotted key (``a.b.c`` has 3) or table header; the project's files use at most 3.
TOML_MAX_KEY_PARTS = 32
#: A gzip stream inflating more than this many times its compressed size is refused as a bomb:
#: a CSV log of sensor readings compresses 3-6 times (docs/reliability.md), a bomb 1000 times.
GZIP_MAX_RATIO = 100
#: Inflated bytes a gzip stream may produce before the ratio is checked (short files compress worse).
GZIP_SLACK = 8 * 2**20
#: Elements one HDF5 dataset may hold before a reader refuses it outright (8 GiB of float64).
HDF5_MAX_ELEMENTS = 2**30


#: Most columns a CSV log's header may name: a log in the measured format has at most 31 of its own,
#: a Universal Robots RTDE recording with every output a few hundred.
CSV_MAX_COLUMNS = 1024
#: Longest header line of a CSV log, bytes (1024 names of 60 characters and their separators).
CSV_HEADER_MAX_BYTES = 64 * 2**10
#: Longest data row of a CSV log counted before it is parsed (:func:`count_lines`), bytes: as many
#: cells as the header names, each a number (a row of 1024 cells of 25 characters is 26 kB).
CSV_ROW_MAX_BYTES = CSV_HEADER_MAX_BYTES


class InputError(ValueError):
    """A file refused before it was read or parsed: the message names the file, the offending item
    (key, link, dataset, row) and what was expected."""


def _kind(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "a folder"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "not a plain file"


def inside(path: str | Path, root: str | Path) -> bool:
    """Whether ``path`` (resolved, symbolic links followed) lies in the folder ``root``; False for
    a path that does not resolve (a loop of symbolic links)."""
    try:
        Path(path).resolve().relative_to(Path(root).resolve())
    except (ValueError, RuntimeError, OSError):
        return False
    return True


def resolved(path: str | Path) -> Path:
    """``path`` with symbolic links followed, or as given when they loop."""
    try:
        return Path(path).resolve()
    except (RuntimeError, OSError):
        return Path(path)


def within(path: str | Path, root: str | Path, what: str = "folder") -> Path:
    """``path`` as a :class:`~pathlib.Path` after checking that it leads (symbolic links followed)
    inside the folder ``root`` (:func:`inside`).

    Raises
    ------
    InputError
        ``PATH: a symbolic link out of the WHAT ROOT; links must stay inside the folder``: ``path``
        as given (its place inside ``root``), never where the link leads nor anything read there.
    """
    path = Path(path)
    if not inside(path, root):
        raise InputError(f"{path}: a symbolic link out of the {what} {root} (or a loop of links); links must stay "
                         "inside the folder")
    return path


@dataclass(frozen=True, eq=False)
class Held:
    """A file's bytes as one read of it found them (:func:`hold`): ``path`` (named in messages: its
    ``str`` is the path's) and ``data``. The readers of this module take it for the file itself."""

    path: Path
    data: bytes

    def __str__(self) -> str:
        return str(self.path)

    @property
    def name(self) -> str:
        return self.path.name

    @property
    def size(self) -> int:
        """Bytes held (the file's size when it was read)."""
        return len(self.data)

    @property
    def sha256(self) -> str:
        """SHA-256 of the bytes, hex (the file's at the read)."""
        return hashlib.sha256(self.data).hexdigest()


def hold(path: str | Path, what: str, max_bytes: int) -> Held:
    """The regular file ``path`` read once into memory (:func:`read_bytes`: at most ``max_bytes``
    bytes), to be parsed and hashed from what was read.

    Raises
    ------
    InputError
        As :func:`read_bytes` (not a regular file, above ``max_bytes``).
    """
    return Held(Path(path), read_bytes(path, what, max_bytes))


def path_of(source: str | Path | Held) -> Path:
    """The path of a file given by name or held (:class:`Held`)."""
    return source.path if isinstance(source, Held) else Path(source)


def size_of(source: str | Path | Held) -> int:
    """Bytes of a file given by name (its size on disk: a stat) or held (:class:`Held`)."""
    return source.size if isinstance(source, Held) else Path(source).stat().st_size


def regular_file(path: str | Path | Held, what: str, max_bytes: int | None = None) -> Path | Held:
    """``path`` as a :class:`~pathlib.Path` after checking that it names a regular file (a symlink is
    followed) of at most ``max_bytes`` bytes (no bound when None); a :class:`Held` file checked on
    its bytes' count and returned as it is.

    Raises
    ------
    InputError
        "no such file", "not a regular file (a character device)" for ``/dev/zero`` or a symlink to
        it, or the size and the bound; each message starts with ``path`` and names ``what``.
    """
    if isinstance(path, Held):
        if max_bytes is not None and path.size > max_bytes:
            raise InputError(f"{path}: {path.size} bytes; a {what} is read up to {max_bytes} bytes")
        return path
    path = Path(path)
    try:
        info = path.stat()
    except FileNotFoundError:
        if path.is_symlink():
            raise InputError(f"{path}: the {what} is a symlink to {os.readlink(path)}, which does not "
                             "exist") from None
        raise InputError(f"{path}: no such file (the {what})") from None
    except OSError as err:
        raise InputError(f"{path}: cannot read the {what}: {err.strerror or err}") from None
    if not stat.S_ISREG(info.st_mode):
        kind = _kind(info.st_mode)
        if path.is_symlink():
            kind = f"a symlink to {os.readlink(path)}, {kind}"
        raise InputError(f"{path}: not a regular file ({kind}); the {what} must be a regular file")
    if max_bytes is not None and info.st_size > max_bytes:
        raise InputError(f"{path}: {info.st_size} bytes; a {what} is read up to {max_bytes} bytes")
    return path


def read_bytes(path: str | Path, what: str, max_bytes: int) -> bytes:
    """The content of the regular file ``path``, at most ``max_bytes`` bytes (checked on the size
    and again while reading, for a file that grows or misreports its size). The buffer is sized from
    the file's size, not the bound: ``read(max_bytes + 1)`` reserved ``max_bytes`` of address space
    for every file (512 MiB a log; a monitor's threads reading at once passed a 4 GB cap)."""
    path = regular_file(path, what, max_bytes)
    with open(path, "rb") as fh:
        size = os.fstat(fh.fileno()).st_size
        data = fh.read(min(size, max_bytes) + 1)
        if len(data) > size:  # it grew since: read on, up to the bound
            data += fh.read(max_bytes + 1 - len(data))
    if len(data) > max_bytes:
        raise InputError(f"{path}: more than {max_bytes} bytes; a {what} is read up to {max_bytes} bytes")
    return data


def sha256_of(path: str | Path | Held, what: str, max_bytes: int) -> str:
    """SHA-256 (hex) of the regular file ``path``'s bytes (of :class:`Held` bytes as held), its size
    checked on the file's size (``st_size``) before any read and read in blocks up to ``max_bytes``:
    a sparse file of terabytes apparent (``truncate -s 2T``, no disk) is refused by its size, never
    read, and one that grows past the bound while it is read is refused there.

    Raises
    ------
    InputError
        As :func:`regular_file` (no such file, not a regular file, above ``max_bytes``), or
        ``PATH: more than N bytes`` for a file that grew past the bound while it was hashed.
    """
    path = regular_file(path, what, max_bytes)
    if isinstance(path, Held):
        return path.sha256
    digest, left = hashlib.sha256(), max_bytes + 1
    with open(path, "rb") as fh:
        while left > 0 and (block := fh.read(min(2**20, left))):
            digest.update(block)
            left -= len(block)
    if left <= 0:
        raise InputError(f"{path}: more than {max_bytes} bytes; a {what} is read up to {max_bytes} bytes")
    return digest.hexdigest()


def read_text(path: str | Path, what: str, max_bytes: int) -> str:
    """:func:`read_bytes` decoded as UTF-8; a file that is not UTF-8 is refused with the byte offset."""
    data = read_bytes(path, what, max_bytes)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise InputError(f"{path}: byte {err.start} is not UTF-8 text; a {what} is a UTF-8 text file") from None


# Strings and comments are skipped whole (a bracket or dot inside them is text); everything else the
# scan needs is one structural character. Characters no alternative matches (bare keys, numbers)
# are skipped by finditer.
_TOML_TOKEN = re.compile(r'"""(?:[^"\\]|\\.|"(?!""))*"{3,5}|\'\'\'[\s\S]*?\'{3,5}|"(?:[^"\\\n]|\\.)*"'
                         r"|'[^'\n]*'|#[^\n]*|[\[\]{},=.\n]")


def check_toml_shape(text: str, source: str | Path, what: str) -> None:
    """Refuse TOML text nested deeper than :data:`TOML_MAX_DEPTH` brackets or with a key (or table
    header) of more than :data:`TOML_MAX_KEY_PARTS` dotted parts, before any parser sees it. A linear
    scan: a malformed file passes here and is refused by the parser with its own message."""
    stack: list[str] = []
    in_key, header, parts, line = True, False, 1, 1
    for match in _TOML_TOKEN.finditer(text):
        token = match.group()
        if token[0] in "\"'#":
            line += token.count("\n")
            continue
        if token == "\n":
            line += 1
            if not stack:
                in_key, header, parts = True, False, 1
        elif token == "." and in_key:
            parts += 1
            if parts > TOML_MAX_KEY_PARTS:
                raise InputError(f"{source}: line {line}: a dotted key of more than {TOML_MAX_KEY_PARTS} "
                                 f"parts; a {what} nests at most {TOML_MAX_KEY_PARTS} levels")
        elif token == "[" and in_key and not stack:
            header = True  # a table header [a.b] or [[a.b]]: its dots count as a key's
        elif token == "]" and header:
            in_key, header = False, False
        elif token == "=" and in_key and not header:
            in_key, parts = False, 1
        elif token in "[{":
            stack.append(token)
            in_key, parts = token == "{", 1
            if len(stack) > TOML_MAX_DEPTH:
                raise InputError(f"{source}: line {line}: brackets nested more than {TOML_MAX_DEPTH} "
                                 f"deep; a {what} nests at most {TOML_MAX_DEPTH} levels")
        elif token in "]}":
            if stack:
                stack.pop()
            in_key = False
        elif token == ",":
            in_key, parts = bool(stack) and stack[-1] == "{", 1


def loads_toml(text: str, source: str | Path, what: str) -> dict:
    """TOML text (read from ``source``, named in errors) as a table, its size and nesting bounded
    (:func:`check_toml_shape`) before it is parsed; a syntax error is an :class:`InputError` naming
    ``source``."""
    if len(text) > TOML_MAX_BYTES:
        raise InputError(f"{source}: {len(text)} characters; a {what} is read up to {TOML_MAX_BYTES}")
    check_toml_shape(text, source, what)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputError(f"{source}: not a valid TOML {what}: {err}") from None
    except RecursionError:  # not expected after the depth check; kept so no traceback escapes
        raise InputError(f"{source}: nested too deeply to read as a {what}") from None


def read_toml(path: str | Path, what: str, max_bytes: int = TOML_MAX_BYTES) -> dict:
    """The table in the TOML file ``path``: a regular UTF-8 file of at most ``max_bytes`` bytes,
    nesting bounded (:func:`check_toml_shape`), then parsed by ``tomllib``.

    Raises
    ------
    InputError
        Naming ``path`` and, for a nesting or syntax error, the line.
    """
    return loads_toml(read_text(path, what, max_bytes), path, what)


# --------------------------------------------------------------------------------------------------
# gzip


class _BoundedInflate(io.RawIOBase):
    """A raw reader over a gzip file that refuses to inflate beyond :data:`GZIP_MAX_RATIO` times the
    compressed bytes consumed so far (plus :data:`GZIP_SLACK`); ``path`` a file's name or :class:`Held`."""

    def __init__(self, path: Path | Held, what: str):
        self._path, self._what = path, what
        self._raw = io.BytesIO(path.data) if isinstance(path, Held) else open(path, "rb")
        self._gz = gzip.GzipFile(fileobj=self._raw, mode="rb")
        self._out = 0

    def readable(self) -> bool:
        return True

    def readinto(self, buffer) -> int:
        try:
            n = self._gz.readinto(buffer)
        except (OSError, EOFError, gzip.BadGzipFile) as err:
            raise InputError(f"{self._path}: not a readable gzip stream ({err}); a {self._what} "
                             "compressed with gzip is expected") from None
        self._out += n
        if self._out > GZIP_SLACK and self._out > GZIP_MAX_RATIO * max(self._raw.tell(), 1):
            raise InputError(f"{self._path}: inflates more than {GZIP_MAX_RATIO} times its compressed "
                             f"size ({self._out} bytes from {self._raw.tell()}); refused as a gzip bomb "
                             f"(a {self._what} compresses far less)")
        return n

    def close(self) -> None:
        if not self.closed:
            self._gz.close()
            self._raw.close()
        super().close()


def is_gzip(path: str | Path | Held) -> bool:
    """Whether the file (or :class:`Held` bytes) starts with gzip's magic bytes (RFC 1952), whatever
    its name."""
    if isinstance(path, Held):
        return path.data[:2] == b"\x1f\x8b"
    with open(path, "rb") as fh:
        return fh.read(2) == b"\x1f\x8b"


def open_bytes(path: str | Path | Held, what: str, max_bytes: int | None = None) -> io.BufferedIOBase:
    """A binary reader over the regular file ``path`` (of at most ``max_bytes`` bytes on disk; or
    over :class:`Held` bytes, the file not opened again), inflating it when it is gzip-compressed
    (recognised by content) with the bomb check of :class:`_BoundedInflate`. Close it (or use ``with``)."""
    path = regular_file(path, what, max_bytes)
    if is_gzip(path):
        return io.BufferedReader(_BoundedInflate(path, what), 2**20)
    return io.BytesIO(path.data) if isinstance(path, Held) else open(path, "rb")


def open_text(path: str | Path, what: str, max_bytes: int | None = None) -> io.TextIOWrapper:
    """:func:`open_bytes` as UTF-8 text (a byte-order mark skipped), newlines as in the file."""
    return io.TextIOWrapper(open_bytes(path, what, max_bytes), encoding="utf-8-sig", newline="")


def count_lines(path: str | Path, what: str, max_line: int | None = None) -> int:
    """Lines of the (possibly gzip-compressed) text file ``path``, a last line without a newline
    counted; read in blocks, so memory stays flat whatever the length (gzip bombs refused). A line
    of more than ``max_line`` bytes is refused at the block that shows it (the CSV parsers read a
    row whole: a sparse log's hole after its header, one row of 256 MiB, took 54 s and 3.9 GB)."""
    lines, last, run = 0, b"\n", 0  # run: bytes since the last line end
    with open_bytes(path, what) as fh:
        while block := fh.read(2**22):
            if max_line:
                ends = np.flatnonzero(np.frombuffer(block, dtype=np.uint8) == 10)
                # each line's bytes in this block: the one carried on, those between line ends, the last one so far
                parts = np.diff(np.concatenate(([-1 - run], ends, [len(block) - 1]))) - np.r_[np.ones(len(ends)), 0]
                over = np.flatnonzero(parts > max_line)
                if over.size:
                    raise InputError(f"{path}: line {lines + 1 + int(over[0])} is longer than {max_line} bytes; a "
                                     f"{what}'s rows are read up to {max_line} bytes (CSV_ROW_MAX_BYTES)")
                run = int(parts[-1])
            lines += block.count(b"\n")
            last = block[-1:]
    return lines + (last != b"\n")


def csv_header(path: str | Path, what: str, separator: str | None = ",", max_columns: int = CSV_MAX_COLUMNS,
               max_bytes: int = CSV_HEADER_MAX_BYTES) -> tuple[list[str], str]:
    """The column names of the (possibly gzip-compressed) CSV file ``path``'s first line and the
    separator, reading at most ``max_bytes`` of it and refusing more than ``max_columns`` names,
    before any row is parsed. ``separator`` None: ``,`` when the line holds one, else a space (an
    RTDE recording); ``,`` is parsed as CSV (quotes), a space split. An empty file: no names.

    Raises
    ------
    InputError
        ``PATH: the header line is longer than N bytes ...`` or ``PATH: the header names N columns;
        a WHAT has at most M (CSV_MAX_COLUMNS)``; as :func:`open_bytes` (not a regular file, a bomb).
    UnicodeDecodeError
        For a header that is not UTF-8 (the callers name the file).
    """
    import csv

    with open_bytes(path, what) as fh:
        raw = fh.readline(max_bytes + 1)
    if len(raw) > max_bytes:
        raise InputError(f"{path}: the header line is longer than {max_bytes} bytes (no line end within them); a "
                         f"{what}'s header is read up to {max_bytes} bytes (CSV_HEADER_MAX_BYTES)")
    line = raw.decode("utf-8-sig")
    if separator is None:
        separator = "," if "," in line else " "
    if separator == ",":
        names = next(csv.reader([line]), [])
    else:
        names = line.strip().split(separator) if line.strip() else []
    if len(names) > max_columns:
        raise InputError(f"{path}: the header names {len(names)} columns; a {what} has at most {max_columns} "
                         "(CSV_MAX_COLUMNS): export the columns faultgen reads")
    return names, separator


# --------------------------------------------------------------------------------------------------
# HDF5


def _link_refusal(f, name: str, link) -> str | None:
    """Why the link ``name`` (relative to the root of ``f``) is refused, or None."""
    import h5py

    if isinstance(link, h5py.ExternalLink):
        return f"/{name} is an external link to {link.filename}:{link.path}"
    if isinstance(link, h5py.SoftLink):
        if not _resolves_inside(f, f"/{name.rpartition('/')[0]}", link.path, 0):
            return f"/{name} is a soft link to {link.path}, which does not resolve inside the file"
        return None
    if not isinstance(link, h5py.HardLink):
        return f"/{name} is a user-defined link"
    return None


def _resolves_inside(f, base: str, target: str, depth: int) -> bool:
    """Whether the soft-link ``target`` (relative to the group ``base``) names an object of ``f``
    through hard and soft links only: resolved one link at a time, so an external link on the way
    is never followed (opening ``f[target]`` would follow it into the other file)."""
    import h5py

    if depth > 16:  # a soft-link loop
        return False
    group = f["/"] if target.startswith("/") else f[base]
    parts = [part for part in target.split("/") if part and part != "."]
    for i, part in enumerate(parts):
        if not isinstance(group, h5py.Group) or part == "..":
            return False
        link = group.get(part, getlink=True)
        if isinstance(link, h5py.SoftLink):
            rest = "/".join([link.path, *parts[i + 1:]])
            return _resolves_inside(f, group.name, rest, depth + 1)
        if not isinstance(link, h5py.HardLink):
            return False  # missing, external or user-defined
        group = group[part]
    return True


def _dataset_refusal(f, name: str) -> str | None:
    import h5py

    obj = f.get(name)
    if not isinstance(obj, h5py.Dataset):
        return None
    if obj.is_virtual:
        sources = sorted({source.file_name for source in obj.virtual_sources()})
        return f"/{name} is a virtual dataset reading {', '.join(sources)}"
    if obj.external:
        return f"/{name} keeps its data in external file(s) {', '.join(str(e[0]) for e in obj.external)}"
    return None


def check_hdf5_links(f, path: str | Path) -> None:
    """Refuse an open HDF5 file in which any link is external, a soft link fails to resolve inside
    the file, or a dataset is virtual or stored in external files: each would make a reader open a
    file it was not given. Every link below the root is walked once (``H5Lvisit``), none followed
    out of the file."""
    import h5py

    found: list[str] = []

    def visit(name: str, link) -> int | None:
        reason = _link_refusal(f, name, link)
        if reason is None and isinstance(link, h5py.HardLink):
            reason = _dataset_refusal(f, name)
        if reason is not None:
            found.append(reason)
            return 1  # stop the walk: one refusal is enough to name
        return None

    f.visititems_links(visit)
    if found:
        raise InputError(f"{path}: {found[0]}; faultgen reads only the file it is given (links and "
                         "virtual datasets that reach other files are refused)")


@contextmanager
def open_hdf5(path: str | Path, what: str = "HDF5 file") -> Iterator:
    """``h5py.File(path, "r")`` after checking that ``path`` is a regular file, that it is HDF5 and
    (:func:`check_hdf5_links`) that nothing in it reaches another file.

    Raises
    ------
    InputError
        Naming ``path``, and the link or dataset at fault.
    """
    import h5py

    path = regular_file(path, what)
    try:
        f = h5py.File(io.BytesIO(path.data) if isinstance(path, Held) else path, "r")
    except OSError as err:
        raise InputError(f"{path}: not a readable HDF5 file ({err}); a {what} is expected") from None
    try:
        check_hdf5_links(f, path)
        yield f
    finally:
        f.close()


def bounded_dataset(f, name: str, path: str | Path, shape: tuple[int | None, ...] | None = None,
                    kinds: str = "fiub", max_elements: int = HDF5_MAX_ELEMENTS):
    """The dataset ``name`` of the open HDF5 file ``f`` (not read yet) after checking, from its
    declared metadata only, that it is a dataset (not a group), that its type kind is one of
    ``kinds`` (NumPy kinds: f float, i/u integer, b bool, S/O/U text), that its shape matches
    ``shape`` (``None`` entries match any length; None skips the check) and that it holds at most
    ``max_elements`` elements.

    Raises
    ------
    InputError
        Naming ``path``, the dataset, and the declared versus the expected shape or type.
    """
    import h5py

    obj = f.get(name)
    if obj is None:
        raise InputError(f"{path}: no dataset {name}")
    if not isinstance(obj, h5py.Dataset):
        raise InputError(f"{path}: {obj.name} is a {type(obj).__name__.lower()}, not a dataset of numbers")
    if obj.dtype.kind not in kinds:
        raise InputError(f"{path}: {obj.name} holds {obj.dtype} values; numbers are expected")
    declared = obj.shape
    if declared is None:
        raise InputError(f"{path}: {obj.name} is an empty (null) dataspace; an array is expected")
    if shape is not None and (len(declared) != len(shape)
                              or any(want is not None and have != want for have, want in zip(declared, shape))):
        wanted = "(" + ", ".join("any" if n is None else str(n) for n in shape) + ("," if len(shape) == 1 else "") + ")"
        raise InputError(f"{path}: {obj.name} has shape {declared}; {wanted} is expected")
    if int(np.prod(declared, dtype=np.float64)) > max_elements:
        raise InputError(f"{path}: {obj.name} declares {declared} = {int(np.prod(declared, dtype=np.float64)):.3g} "
                         f"elements; at most {max_elements} are read")
    return obj
