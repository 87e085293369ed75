"""Physical effects, one class each, shared by the robot model, the simulation and the calibration.

The motor-side friction models (:mod:`faultgen.effects.friction`: thesis eq. 6.3, LuGre) and the
effects a robot may carry beyond them, each in its own module and registered under a stable id
(:mod:`faultgen.effects.base` gives the template and the registry):

=========================  ===============================================  ======================
id                         parameters (SI)                                  MJCF
=========================  ===============================================  ======================
torque_offset              offset (N m, arm side)                           numeric torque_offset{i}
coulomb                    coulomb_pos, coulomb_neg (N m, motor side)       numeric friction{i}
viscous                    viscous (N m s/rad, motor side)                  numeric friction{i}
stribeck                   static, stribeck_velocity, stribeck_exponent     numeric friction{i}
load_dependent_friction    coefficient (1), gravity_load (0 or 1)           numeric load_dependent_friction{i}
temperature                amplitude (1), time_constant (s)                 numeric temperature{i}
payload                    mass, com, inertia (kg, m, kg m^2), robot-wide   body payload1 at the flange
cogging                    amplitude (N m, motor side), poles (1), phase    numeric cogging{i}
backlash                   width (rad, arm side)                            tendon gearbox{i} springlength
=========================  ===============================================  ======================

The table's order is the effects' :attr:`~faultgen.effects.base.Effect.rank`, the order in which
the calibration tries them. Every module of this package but ``base`` and ``friction`` is one
effect, imported (and so registered) with the package.
This is the lowest layer of faultgen: it imports nothing else of it (the robot it is given is
used through its attributes).
"""

import importlib
import pkgutil

from faultgen.effects.base import (
    EFFECTS,
    REST_SPEED,
    Effect,
    FrictionParameter,
    ModelError,
    Motion,
    get,
    make,
    read_all,
    register,
)

# Every other module of this package defines one effect, registered when it is imported: adding
# an effect is adding a module.
for _module in pkgutil.iter_modules(__path__):
    if _module.name not in ("base", "friction"):
        importlib.import_module(f"{__name__}.{_module.name}")

__all__ = ["EFFECTS", "REST_SPEED", "Effect", "FrictionParameter", "ModelError", "Motion", "get", "make", "read_all",
           "register"]
