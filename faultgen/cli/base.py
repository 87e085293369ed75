"""What every command shares: its help layout, its one error handler, and the checks of outputs
and of the option values that several commands parse."""

from __future__ import annotations

from pathlib import Path

import click
import typer
from typer.core import TyperArgument, TyperCommand, TyperGroup, TyperOption


class _PlainHelp:
    """Help without type tags (``<bool>``, ``<list[int]>``): a flag shows nothing after its name,
    an option taking a value its metavar, by default the option's name in capitals as argparse
    writes it (``--cycles CYCLES``), and an argument its name in capitals (``FILE``)."""

    def get_params(self, ctx):
        params = super().get_params(ctx)
        for param in params:
            if isinstance(param, TyperOption) and param.metavar is None:
                long_name = max(param.opts, key=len).lstrip("-")
                param.metavar = "" if param.is_flag else long_name.upper().replace("-", "_")
            elif isinstance(param, TyperArgument) and param.metavar is None:
                param.metavar = param.name.upper()
                param.display_type_rich = _no_type_tag  # typer has no setting for the argument's tag
        return params


    def get_short_help_str(self, limit: int = 45) -> str:
        """The command's line in ``faultgen --help``: the first sentence of its help, whole (click
        cuts it at 45 characters with "...")."""
        return super().get_short_help_str(limit=1000)


def _no_type_tag(ctx) -> None:
    return None


class Command(_PlainHelp, TyperCommand):
    """A faultgen command: plain help, and the one error handler of the command line.

    An error the library raises for a user's input or file reaches the user as one line,
    ``error: <message>``, and an exit code: the exception's ``exit_code`` where it has one (a
    broken dataset 1, a simulation that diverged 1, an interrupted sweep 130, whose message is
    printed as it is), else 2 for a ``ValueError`` (refused input: nothing was done), 1 for an
    ``OSError`` (a full disk, a read-only folder: :func:`describe_os_error`). Any other exception is
    a defect and keeps its traceback.
    """

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except (click.exceptions.Exit, typer.Exit, click.exceptions.Abort, click.ClickException):
            raise
        except OSError as err:  # a full disk, a read-only folder, a file that vanished: no traceback
            typer.echo(f"error: {describe_os_error(err)}", err=True)
            raise typer.Exit(1) from err
        except Exception as err:
            code = getattr(err, "exit_code", None)
            if code is None and not isinstance(err, ValueError):
                raise
            prefix = getattr(err, "message_prefix", "error: ")
            typer.echo(f"{prefix}{err}", err=True)
            raise typer.Exit(2 if code is None else code) from err


def describe_os_error(err: OSError) -> str:
    """One line for an I/O failure: the file, what went wrong, and what to do about it."""
    import errno

    text = err.strerror or str(err)
    if err.filename and str(err.filename) not in text:
        text = f"{err.filename}: {text}"
    advice = {errno.ENOSPC: "free some space or choose another output",
              errno.EFBIG: "the file-size limit (ulimit -f) was reached; raise it or write less",
              errno.EROFS: "the file system is read-only; choose another output",
              errno.EACCES: "no permission; fix the folder's permissions or choose another output",
              errno.EDQUOT: "the disk quota is exceeded; free some space or choose another output"}.get(err.errno)
    return f"{text} ({advice})" if advice else text


class Group(_PlainHelp, TyperGroup):
    """A command group, with the same plain help."""


def check_outputs(files: list[Path], overwrite: bool) -> None:
    """Refuse, before any work, output files that exist (unless ``overwrite``), are folders, or
    whose folder does not exist (ValueError naming the file and what to do), or whose folder
    cannot be written (OSError naming the folder and the reason)."""
    for path in files:
        if path.is_dir():
            raise ValueError(f"{path} is a folder; --out expects a file name")
        if path.exists() and not overwrite:
            raise ValueError(f"{path} exists; pass --overwrite to replace it or choose another --out")
        folder = path.parent if str(path.parent) else Path(".")
        if not folder.is_dir():
            raise ValueError(f"cannot write {path}: folder {folder} does not exist")
        from faultgen.data import atomic

        atomic.check_writable(path)  # a read-only folder: OSError (exit 1) before any work


def check_output_folder(folder: Path, overwrite: bool) -> None:
    """Refuse an output folder that is a file, or holds files already (unless ``overwrite``)."""
    if folder.exists() and not folder.is_dir():
        raise ValueError(f"{folder} is a file; --out expects a folder to write the results into")
    if folder.is_dir() and any(folder.iterdir()) and not overwrite:
        raise ValueError(f"{folder} holds earlier results; pass --overwrite to replace them or choose another --out")
    from faultgen.data import atomic

    existing = folder.absolute().parent
    while not existing.exists():  # calibrate creates the missing folders
        existing = existing.parent
    atomic.check_writable(existing / folder.name)  # where the results are written first: OSError (exit 1)


def parse_window(text: str) -> tuple[float, float]:
    """'50,120' -> (50.0, 120.0); raises ValueError naming the text."""
    try:
        low, high = (float(x) for x in text.split(","))
    except ValueError:
        raise ValueError(f"--speed-window {text!r}: expected LOW,HIGH in rad/s, e.g. 50,120") from None
    if not 0 <= low < high:
        raise ValueError(f"--speed-window {text!r}: expected 0 <= LOW < HIGH")
    return low, high


def parse_cycles(text: str) -> tuple[int, ...]:
    """'1,50,90-100' -> (1, 50, 90, ..., 100); raises ValueError naming the bad part."""
    cycles: list[int] = []
    for part in text.split(","):
        part = part.strip()
        try:
            if "-" in part:
                first, last = (int(x) for x in part.split("-", 1))
                cycles.extend(range(first, last + 1))
            else:
                cycles.append(int(part))
        except ValueError:
            raise ValueError(f"--record part {part!r} is not a cycle number or range like 90-100") from None
    return tuple(cycles)
