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

The modules' first-round names keep working: ``faultgen.robots`` is ``faultgen.model.robots``
(the same module object), and likewise for :data:`MOVED`.
"""

import importlib
import importlib.abc
import importlib.util
import sys
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("faultgen")
except PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0.0.0+unknown"

#: First-round module names -> where the module lives now.
MOVED = {
    "robots": "faultgen.model.robots",
    "friction": "faultgen.effects.friction",
    "tasks": "faultgen.operation.tasks",
    "ik": "faultgen.operation.ik",
    "wear": "faultgen.operation.wear",
    "control": "faultgen.simulation.control",
    "sensors": "faultgen.simulation.sensors",
    "sim": "faultgen.simulation.stepping",
    "dataset": "faultgen.data.dataset",
    "measured": "faultgen.data.measured",
    "atomic": "faultgen.data.atomic",
    "sweep": "faultgen.runs.sweep",
}


class _MovedModules(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Import ``faultgen.<old name>`` as the module it moved to (:data:`MOVED`), loaded once."""

    def find_spec(self, fullname, path=None, target=None):
        prefix, _, name = fullname.partition(".")
        if prefix == __name__ and name in MOVED:
            return importlib.util.spec_from_loader(fullname, self)
        return None

    def create_module(self, spec):
        module = importlib.import_module(MOVED[spec.name.partition(".")[2]])
        spec.loader_state = module.__spec__  # importlib sets the alias's spec on the module next
        return module

    def exec_module(self, module):  # executed under its own name by create_module
        module.__spec__ = module.__spec__.loader_state


#: The public API: name -> (module, attribute), imported when first used.
PUBLIC = {
    "open": ("faultgen.data.reader", "open"),
    "Dataset": ("faultgen.data.reader", "Dataset"),
    "Run": ("faultgen.data.reader", "Run"),
    "DatasetError": ("faultgen.data.dataset", "DatasetError"),
    "validate": ("faultgen.data.dataset", "validate"),
    "load_robot": ("faultgen.model.robots", "load"),
    "available_robots": ("faultgen.model.robots", "available"),
    "RunConfig": ("faultgen.simulation.stepping", "RunConfig"),
    "simulate": ("faultgen.simulation.stepping", "simulate"),
    "write_run": ("faultgen.data.dataset", "write_run"),
    "Grid": ("faultgen.runs.sweep", "Grid"),
    "run_sweep": ("faultgen.runs.sweep", "run"),
    "Fleet": ("faultgen.runs.fleet", "Fleet"),
}
__all__ = ["__version__", *PUBLIC]


def __dir__():
    return sorted({*globals(), *PUBLIC})


def __getattr__(name):  # ``faultgen.robots`` without importing it first
    if name in PUBLIC:
        module, attribute = PUBLIC[name]
        return getattr(importlib.import_module(module), attribute)
    if name in MOVED:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


sys.meta_path.append(_MovedModules())
