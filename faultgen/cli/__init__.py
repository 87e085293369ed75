"""The ``faultgen`` command: parse arguments, call the library, print. Nothing else lives here.

One module per command group, each adding its commands to :data:`app` when imported: ``robots``
(the robot models), ``programs`` (``tasks list|show|export``), ``runs`` (``simulate``, ``sweep``, ``fleet``), ``calibration``
(``calibrate``), ``data`` (``info``, ``validate``, ``export``, ``plot``), ``logs`` (``logs import``),
``monitoring`` (``monitor``), ``reporting`` (``report``: its page), ``analysis``
(``bench-isolators``, ``detect``, ``training-source``, ``classify``), ``bench`` (``bench list|make|score``)
and ``reproduce`` (every table of docs/reproduction.md); ``faultgen --help`` lists
them in that order. ``base`` holds the help layout and the one error handler every command
shares; ``options`` the options several commands declare.
"""

from faultgen.cli.main import app
from faultgen.cli import (robots, programs, runs, calibration, data, logs, monitoring, reporting, analysis, bench,
                          reproduce)

__all__ = ["analysis", "app", "bench", "calibration", "data", "logs", "monitoring", "programs", "reporting",
           "reproduce", "robots", "runs"]
