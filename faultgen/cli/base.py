"""What every command shares: its help layout, its one error handler (a library's refusal and a
parsing error alike one line, ``error: ...``), and the checks of outputs and of the option values
that several commands parse."""

from __future__ import annotations

from pathlib import Path

import click
import typer
from typer.core import TyperArgument, TyperCommand, TyperGroup, TyperOption


#: The usage error the command line raises and catches: typer's own copy of click's where typer
#: carries one (typer >= 0.29), else click's.
_UsageError = next(cls for cls in typer.BadParameter.__mro__ if cls.__name__ == "UsageError")
_USAGE_ERRORS = (click.UsageError, _UsageError)


class OptionError(_UsageError):
    """A refused option value, a misspelt option, a missing argument or an unknown command, shown
    as the one line every refusal of the command line is (click showed a usage block and
    ``Error: ...``): ``error: --jobs '0': expected 1..1024; see faultgen sweep --help``, exit 2."""

    exit_code = 2

    def show(self, file=None) -> None:
        typer.echo(f"error: {self.message}", err=True)


def one_line(err: Exception, args: list[str] | None = None) -> OptionError:
    """The :class:`OptionError` of a click usage error: the option, the value given (found in
    ``args``), the reason, the expected range (a typer ``min``/``max``) and where help is."""
    param = getattr(err, "param", None)
    text = (getattr(err, "message", None) or str(err)).rstrip(".")
    if type(err).__name__ == "MissingParameter" and param is not None:
        kind = "option" if getattr(param, "opts", [""])[0].startswith("-") else "argument"
        name = max(param.opts, key=len) if kind == "option" else param.name.upper()
        text = f"missing {kind} {name}"
    elif param is not None:
        opts = list(getattr(param, "opts", []))
        names = [n for n in opts if n.startswith("--")] or opts
        name = max(names, key=len) if names else param.name.upper()
        given = _given(param, args or [])
        low, high = getattr(param, "min", None), getattr(param, "max", None)
        if low is not None or high is not None:  # typer's "Input should be less than ..." says half of it
            text = "" if text.startswith("Input should be ") and " than " in text else f"{text}; "
            text += f"expected {expected_range(low, high)}"
        text = f"{name}{'' if given is None else ' ' + repr(given)}: {text}"
    ctx = getattr(err, "ctx", None)
    if ctx is not None:
        text += f"; see {ctx.command_path} --help"
    return OptionError(" ".join(text.split()))


def expected_range(low, high) -> str:
    """'1..1024', 'at least 1' or 'at most 0.5': a numeric option's range as a message says it."""
    if low is not None and high is not None:
        return f"{low:g}..{high:g}" if isinstance(low, float) or isinstance(high, float) else f"{low}..{high}"
    return f"at least {low}" if low is not None else f"at most {high}"


def _given(param, args: list[str]) -> str | None:
    """The text given on the command line for ``param`` (its last occurrence), if any."""
    found = None
    for i, arg in enumerate(args):
        for opt in getattr(param, "opts", []):
            if arg == opt and i + 1 < len(args):
                found = args[i + 1]
            elif opt.startswith("--") and arg.startswith(opt + "="):
                found = arg[len(opt) + 1:]
    return found


class _PlainHelp:
    """Help without type tags (``<bool>``, ``<list[int]>``): a flag shows nothing after its name,
    an option taking a value its metavar, by default the option's name in capitals as argparse
    writes it (``--cycles CYCLES``), and an argument its name in capitals (``FILE``). And parsing
    errors as one line (:func:`one_line`)."""

    def make_context(self, info_name, args, parent=None, **extra):
        """Parse ``args``; a refused value or a misspelt option is one line (:func:`one_line`)."""
        given = list(args)
        try:
            return super().make_context(info_name, args, parent=parent, **extra)
        except _USAGE_ERRORS as err:
            if type(err).__name__ == "NoArgsIsHelpError":  # a bare command shows its help
                raise
            raise one_line(err, given) from None

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
    ``error: <message>`` (a message of several lines joined with "; "), and an exit code: the
    exception's ``exit_code`` where it has one (a broken dataset 1, a simulation that diverged 1,
    an interrupted sweep 130, whose message is printed as it is), else 2 for a ``ValueError``
    (refused input: nothing was done), 1 for an ``OSError`` (a full disk, a read-only folder:
    :func:`describe_os_error`). Any other exception is a defect and keeps its traceback.
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
            text = str(err)
            if prefix:  # one line, whatever the library below wrote (MuJoCo's compiler adds "\nElement ...")
                text = "; ".join(line.strip() for line in text.splitlines() if line.strip())
            typer.echo(f"{prefix}{text}", err=True)
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
    """A command group, with the same plain help and one-line usage errors."""

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except _USAGE_ERRORS as err:  # an unknown command
            if type(err).__name__ == "NoArgsIsHelpError":
                raise
            raise one_line(err) from None


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
