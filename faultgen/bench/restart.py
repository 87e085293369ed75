"""``faultgen bench make`` started again in its track version's numeric profile before the command
line's modules load (:mod:`faultgen.bench.profile`: the profile's variables must be set before NumPy
loads, so a make started without them starts itself again with them).

``faultgen.cli`` calls :func:`restart_early` as it loads, before it imports its command modules
(``python -m faultgen.cli`` imports the package before it runs ``__main__``): the new process imports
them once. The command's own restart (:func:`faultgen.bench.profile.restart_pinned`, from its body)
stays behind it for what this one leaves.
"""

from __future__ import annotations

import os
import sys

from faultgen.bench import profile, tracks

#: ``faultgen bench make``'s options (faultgen/cli/bench.py) that take a value, and its flags, as
#: :func:`restart_early` reads them.
_MAKE_VALUED = frozenset({"--out", "-o", "--version", "--size", "--jobs"})
_MAKE_FLAGS = frozenset({"--freeze", "--no-freeze", "--progress", "--no-progress"})


def command_line() -> list[str] | None:
    """This process's arguments after the program when the process is faultgen's command line itself:
    ``python -m faultgen.cli ARGS`` (while Python imports the package to run it, ``sys.argv[0]`` is
    ``-m``) or the ``faultgen`` script; None in a program that imports ``faultgen.cli``."""
    if (sys.argv[0] == "-m" and "faultgen.cli" in sys.orig_argv) or os.path.basename(sys.argv[0]) == "faultgen":
        return sys.argv[1:]
    return None


def restart_early(argv: list[str] | None) -> None:
    """:func:`~faultgen.bench.profile.restart_pinned` for ``faultgen bench make TRACK [OPTIONS]``
    (``argv``: the arguments after the program, :func:`command_line`; None: not the command line,
    nothing to do), called by ``faultgen.cli`` before its command modules are imported: the restarted process imports them
    once, where a restart from the command's body imported them twice (about 2 s of CPU). The track
    and ``--version`` are read from ``argv`` with the command's options; anything else (``--help``, an
    option it does not know, a second argument, a track or version that does not load) returns
    without a restart, and the command itself restarts or names the problem as before."""
    if argv is None or argv[:2] != ["bench", "make"]:
        return
    track, version, words = None, None, iter(argv[2:])
    for word in words:
        name, eq, attached = word.partition("=")
        if name in _MAKE_VALUED:
            value = attached if eq else next(words, None)
            if value is None:
                return
            version = value if name == "--version" else version
        elif word.startswith("-") and word not in _MAKE_FLAGS:
            return
        elif not word.startswith("-"):
            if track is not None:
                return
            track = word
    if track is None:
        return
    try:
        wanted = tracks.load(track).version(None if version is None else int(version)).profile
    except ValueError:
        return
    profile.restart_pinned(wanted, argv)
