"""faultgen: labelled wear-fault data for industrial robots, simulated in MuJoCo.

Data flows one way, through sub-packages by layer (docs/architecture.md; the order is a contract
that ``lint-imports`` checks in the test suite):
``effects`` (friction and the other physical effects, one class each) -> ``model`` (robots)
-> ``operation`` (tasks, paths, wear) -> ``simulation`` (drives,
sensors, stepping) -> ``data`` (datasets, measured logs) -> ``runs`` (sweeps), ``calibrate`` and
``plot`` -> ``cli``; the ``analysis`` package reads the datasets.

The public API, what a user imports from ``faultgen`` (loaded on first use, so ``import
faultgen`` stays cheap): :data:`PUBLIC` names each, e.g. ``faultgen.open(path)`` (a typed
:class:`~faultgen.data.reader.Dataset`), ``faultgen.simulate(config)``, ``faultgen.load_robot(name)``.

One module is public by name too: ``faultgen.robots`` is :mod:`faultgen.model.robots`, so that
``faultgen.robots.load(DIR)`` loads a robot folder (docs/robots.md). It is an attribute, not an
import path (``import faultgen.robots`` fails); the library and its tests use the layered name.
The other first-round module names (``sim``, ``dataset``, ``sweep``, ... before the sub-packages)
are gone; docs/architecture.md says where each module lives.
"""

import importlib
from importlib.metadata import PackageNotFoundError, version

#: The distribution name (pyproject.toml): ``faultgen`` on PyPI is an unrelated project.
DISTRIBUTION = "faultgen-robots"

try:
    __version__ = version(DISTRIBUTION)
except PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0.0.0+unknown"

#: The public API: name -> (module, attribute), imported when first used; attribute ``None``
#: names the module itself.
PUBLIC = {
    "open": ("faultgen.data.reader", "open"),
    "Dataset": ("faultgen.data.reader", "Dataset"),
    "Run": ("faultgen.data.reader", "Run"),
    "DatasetError": ("faultgen.data.schema", "DatasetError"),
    "validate": ("faultgen.data.validator", "validate"),
    "load_robot": ("faultgen.model.robots", "load"),
    "available_robots": ("faultgen.model.robots", "available"),
    "RunConfig": ("faultgen.simulation.config", "RunConfig"),
    "simulate": ("faultgen.simulation.stepping", "simulate"),
    "write_run": ("faultgen.data.writer", "write_run"),
    "Grid": ("faultgen.runs.grid", "Grid"),
    "run_sweep": ("faultgen.runs.sweep", "run"),
    "ExecutionContext": ("faultgen.runs.context", "ExecutionContext"),
    "Fleet": ("faultgen.runs.fleet", "Fleet"),
    "robots": ("faultgen.model.robots", None),
}
__all__ = ["__version__", *PUBLIC]


def __dir__():
    return sorted({*globals(), *PUBLIC})


def __getattr__(name):  # ``faultgen.open`` without importing the reader first
    if name in PUBLIC:
        module, attribute = PUBLIC[name]
        module = importlib.import_module(module)
        return module if attribute is None else getattr(module, attribute)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

