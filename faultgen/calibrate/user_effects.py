"""A user's own effect class for ``faultgen calibrate --effects module:Class``: loaded, checked and
added to the effect library for one calibration (:func:`loaded`).

The class follows the template of :mod:`faultgen.effects` (:class:`faultgen.effects.Effect`,
faultgen/effects/base.py): an ``id``, its parameters' ``units`` and ``absent`` values, the MJCF
numeric it is stored in, its drive torque along a motion (:meth:`~faultgen.effects.Effect.torque`),
and its regressors (:meth:`~faultgen.effects.Effect.columns`, :meth:`~faultgen.effects.Effect.params`,
optionally :meth:`~faultgen.effects.Effect.grid`). docs/examples/arm_ripple.py is one: a torque
ripple periodic in the arm angle. ``module`` is an importable module name (on ``PYTHONPATH``) or a
path to a ``.py`` file.
"""

from __future__ import annotations

import contextlib
import importlib
import importlib.util
import inspect
from collections.abc import Iterator
from pathlib import Path

from faultgen.effects import base

#: What a user's class must define itself (not inherit from the template).
REQUIRED = ("id", "summary", "units", "absent", "columns", "params")


class UserEffectError(ValueError):
    """A ``--effects`` value that does not name a usable effect class; the message names the
    module, the class and what was expected."""


def load(spec: str) -> type[base.Effect]:
    """The effect class ``spec`` (``module:Class`` or ``path/to/file.py:Class``) names.

    Raises
    ------
    UserEffectError
        When ``spec`` is not ``module:Class``, the module cannot be imported (not found, or it
        raises), it has no such class, or the class is not an effect class (not a subclass of
        :class:`faultgen.effects.Effect`, or missing one of :data:`REQUIRED`).
    """
    module_name, sep, class_name = str(spec).rpartition(":")
    if not sep or not module_name or not class_name:
        raise UserEffectError(f"--effects {spec!r}: expected module:Class or path/to/file.py:Class, "
                              "e.g. arm_ripple:ArmRipple")
    module = _module(spec, module_name)
    found = getattr(module, class_name, None)
    if found is None:
        offered = sorted(n for n, v in vars(module).items()
                         if inspect.isclass(v) and issubclass(v, base.Effect) and v is not base.Effect)
        raise UserEffectError(f"--effects {spec!r}: module {module_name!r} has no class {class_name!r}"
                              + (f"; its effect classes: {', '.join(offered)}" if offered else "; it defines no effect class"))
    if not inspect.isclass(found) or not issubclass(found, base.Effect) or found is base.Effect:
        raise UserEffectError(f"--effects {spec!r}: {module_name}.{class_name} is not an effect class: expected a "
                              "subclass of faultgen.effects.Effect (the template in faultgen/effects/base.py, "
                              "example docs/examples/arm_ripple.py)")
    missing = [name for name in REQUIRED if not any(name in vars(k) for k in found.__mro__ if k is not base.Effect
                                                    and issubclass(k, base.Effect))]
    if missing:
        raise UserEffectError(f"--effects {spec!r}: effect class {module_name}.{class_name} does not define "
                              f"{', '.join(missing)} (faultgen/effects/base.py says what each is)")
    if found.id in base.REGISTRY and type(base.REGISTRY[found.id]) is not found:
        raise UserEffectError(f"--effects {spec!r}: effect id {found.id!r} of {module_name}.{class_name} is the "
                              f"library's {type(base.REGISTRY[found.id]).__name__}; give the class another id")
    return found


def _module(spec: str, name: str):
    if name.endswith(".py") or "/" in name or "\\" in name:
        path = Path(name)
        if not path.is_file():
            raise UserEffectError(f"--effects {spec!r}: no file {name!r}")
        loader = importlib.util.spec_from_file_location(f"faultgen_user_effect_{path.stem}", path)
        module = importlib.util.module_from_spec(loader)
        try:
            loader.loader.exec_module(module)
        except Exception as err:  # the user's code: say where it failed
            raise UserEffectError(f"--effects {spec!r}: importing {name!r} failed: {type(err).__name__}: {err}") from err
        return module
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as err:
        if err.name and name.split(".")[0] != err.name.split(".")[0]:
            raise UserEffectError(f"--effects {spec!r}: importing module {name!r} failed: {err}") from err
        raise UserEffectError(f"--effects {spec!r}: no module named {name!r}: put its folder on PYTHONPATH or give "
                              "the file's path, e.g. docs/examples/arm_ripple.py:ArmRipple") from None
    except Exception as err:
        raise UserEffectError(f"--effects {spec!r}: importing module {name!r} failed: {type(err).__name__}: "
                              f"{err}") from err


@contextlib.contextmanager
def loaded(specs: list[str] | tuple[str, ...] | None) -> Iterator[list[type[base.Effect]]]:
    """The classes of ``specs`` (:func:`load`) in the effect library (:data:`faultgen.effects.REGISTRY`,
    and as calibration candidates :data:`faultgen.effects.EFFECTS`) while the block runs; the
    library as it was afterwards. Raises :class:`UserEffectError` (:func:`load`)."""
    classes = [load(s) for s in specs or ()]
    registry, effects = dict(base.REGISTRY), dict(base.EFFECTS)
    try:
        for cls in classes:
            base.register(cls)
        yield classes
    finally:
        base.REGISTRY.clear()
        base.REGISTRY.update(registry)
        base.EFFECTS.clear()
        base.EFFECTS.update(effects)
