"""Reading and writing under a folder that may come from someone else, never through it.

A monitor's ``OUT`` (its ``.state`` and ``.cache``) is kept between runs and may be handed over or
planted (docs/reliability.md, "Threat model"): a link in it (``.cache/programs -> DIR``,
``.cache -> DIR``, a cache file linked to another file) must not make faultgen write into DIR or
read DIR's files as its own. :class:`Confined` is the one way the monitor, its workers and its
cache reach a path under such a folder: every path is checked (links followed, the folder's own
path resolved once) to lead inside the folder before anything is created, read, written or
removed there, and a path that does not is refused by name with what to do. The check runs again
after each folder it creates, so a link that appears between the check and the write is caught
where it stands.
"""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from faultgen import inputs
from faultgen.data import atomic


class Confined:
    """The folder ``root`` (``what`` names it in messages: "monitor output folder") and the paths
    under it that faultgen may use. Refusals are ``error`` (an :class:`faultgen.inputs.InputError`
    subclass by default), a one-line message naming the path as given, never what the link leads to.
    """

    def __init__(self, root: str | Path, what: str = "output folder",
                 error: type[inputs.InputError] = inputs.InputError):
        self.root = Path(root)
        self.what = what
        self.error = error

    def path(self, path: str | Path) -> Path:
        """``path`` after checking that it leads inside :attr:`root` (:func:`faultgen.inputs.inside`:
        every link on the way followed; a path that does not exist yet is checked through the part
        that does).

        Raises
        ------
        error
            ``PATH: a link leading outside ROOT; ...``.
        """
        path = Path(path)
        if not inputs.inside(path, self.root):
            if ".." in path.parts:
                raise self.error(f"{path}: a name leading outside the {self.what} {self.root} ('..')")
            raise self.error(f"{self._link_of(path)}: a link leading outside the {self.what} {self.root}; faultgen never "
                             "writes links into its output folders: delete it")
        return path

    def _link_of(self, path: Path) -> Path:
        """The first part of ``path`` (from :attr:`root` down) that leads outside: the link to delete."""
        try:
            parts = path.relative_to(self.root).parts
        except ValueError:
            return path
        current = self.root
        for part in parts:
            current = current / part
            if not inputs.inside(current, self.root):
                return current
        return path

    def mkdir(self, folder: str | Path) -> Path:
        """Create ``folder`` (and its missing parents up to :attr:`root`, which is made if missing)
        under :attr:`root`, each checked first, and check it again once made; an existing folder is
        checked and kept."""
        folder = self.path(folder)
        self.root.mkdir(parents=True, exist_ok=True)  # the folder itself: the user's to name
        try:
            parts = folder.relative_to(self.root).parts
        except ValueError:  # named another way (absolute, the root relative): checked whole, made as one
            folder.mkdir(parents=True, exist_ok=True)
            return self.path(folder)
        current = self.root
        for part in parts:
            current = self.path(current / part)
            if not current.is_dir():
                current.mkdir(exist_ok=True)
        return self.path(folder)

    def read_bytes(self, path: str | Path, what: str, max_bytes: int) -> bytes:
        """The regular file ``path`` under :attr:`root`, at most ``max_bytes`` bytes
        (:func:`faultgen.inputs.read_bytes`, its refusals as :attr:`error`)."""
        try:
            return inputs.read_bytes(self.path(path), what, max_bytes)
        except inputs.InputError as err:
            raise err if isinstance(err, self.error) else self.error(str(err)) from None

    def read_text(self, path: str | Path, what: str, max_bytes: int) -> str:
        """:meth:`read_bytes` decoded as UTF-8 (a file that is not UTF-8 refused with the byte offset)."""
        data = self.read_bytes(path, what, max_bytes)
        try:
            return data.decode("utf-8")
        except UnicodeDecodeError as err:
            raise self.error(f"{path}: byte {err.start} is not UTF-8 text; a {what} is a UTF-8 text file") from None

    @contextmanager
    def writing(self, path: str | Path) -> Iterator[Path]:
        """:func:`faultgen.data.atomic.atomic_path` for ``path`` under :attr:`root`, its folder made
        (:meth:`mkdir`) and the path checked before the temporary file is created and again before
        it is renamed into place."""
        path = self.path(path)
        self.mkdir(path.parent)
        with atomic.atomic_path(path) as tmp:
            yield tmp
            self.path(path)

    def write_bytes(self, path: str | Path, data: bytes) -> None:
        """Write ``data`` to ``path`` under :attr:`root` (:meth:`writing`)."""
        with self.writing(path) as tmp:
            Path(tmp).write_bytes(data)

    def write_text(self, path: str | Path, text: str) -> None:
        """Write ``text`` (UTF-8) to ``path`` under :attr:`root` (:meth:`writing`)."""
        self.write_bytes(path, text.encode("utf-8"))

    def remove(self, path: str | Path) -> None:
        """Remove the file or folder ``path`` under :attr:`root` (a link inside it is removed, never
        followed; nothing when there is none)."""
        path = self.path(path)
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        elif path.exists() or path.is_symlink():
            path.unlink()
