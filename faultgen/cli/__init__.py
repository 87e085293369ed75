"""The ``faultgen`` command: parse arguments, call the library, print. Nothing else lives here.

One module per command group, each adding its commands to :data:`app` when imported: ``robots``
(the robot models), ``programs`` (``tasks list|show|export``), ``runs`` (``simulate``, ``sweep``, ``fleet``), ``calibration``
(``calibrate``), ``data`` (``info``, ``validate``, ``export``, ``plot``), ``logs`` (``logs import``),
``monitoring`` (``monitor``), ``reporting`` (``report``: its page), ``analysis``
(``bench-isolators``, ``detect``, ``training-source``, ``classify``), ``bench`` (``bench list|make|score``)
and ``reproduce`` (every table of docs/reproduction.md); ``faultgen --help`` lists
them in that order. ``base`` holds the help layout and the one error handler every command
shares; ``options`` the options several commands declare; ``table`` which module defines each
command: a command line imports the module of the command it runs and no other (``faultgen
--help`` and ``--version`` none), and ``faultgen.cli.runs`` and the others are imported when first
used.

Importing it sets ``PYTHONSAFEPATH=1`` in this process's environment (:data:`faultgen.children.SAFE_PATH`)
before any library is imported: every Python a library starts from the command, however it starts
it (MuJoCo's import of ``glfw`` runs ``python -c`` to check its library's version; loky, Dask,
multiprocessing), then leaves the current folder off its path, as the children faultgen starts
itself with ``-P`` do (:mod:`faultgen.children`).
"""

import os

from faultgen import children

os.environ.update(children.SAFE_PATH)

from faultgen.cli.main import app  # noqa: E402  (after the environment is safe for the libraries' children)
from faultgen.cli.table import MODULES, import_module  # noqa: E402

__all__ = ["analysis", "app", "bench", "calibration", "data", "logs", "monitoring", "programs", "reporting",
           "reproduce", "robots", "runs"]


def __getattr__(name):  # ``faultgen.cli.runs`` without importing every command module first
    if name in MODULES:
        return import_module(name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
