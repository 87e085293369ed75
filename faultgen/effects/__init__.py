"""Physical effects, one class each, shared by the robot model, the simulation and the calibration.

The robot's nominal motor-side friction (``motor_friction``, :mod:`faultgen.effects.motor_friction`:
thesis eq. 6.3 and the LuGre bristles; every robot carries it) and the effects a robot may carry
beyond it, each in its own module and registered under a stable id (:mod:`faultgen.effects.base`
gives the template and the registry, :data:`REGISTRY`; :data:`EFFECTS` are the calibration's
candidates, all but ``motor_friction``; :mod:`faultgen.effects.friction` puts the friction into
MuJoCo as the simulation's LuGre or static model):

=========================  ===============================================  ======================
id                         parameters (SI)                                  MJCF
=========================  ===============================================  ======================
motor_friction             coulomb_pos, coulomb_neg, static,                numeric friction{i}
                           stribeck_velocity, stribeck_exponent, viscous,
                           bristle_stiffness, bristle_damping (motor side)
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
the calibration tries them (``motor_friction`` is not tried). Every module of this package but
``base`` and ``friction`` is one effect, imported (and so registered) with the package
(``motor_friction`` also holds :class:`FrictionParameter`, the base of the effects that change
part of it).
This is the lowest layer of faultgen: it imports nothing else of it (the robot it is given is
used through its attributes).
"""

import importlib
import pkgutil

import mujoco

from faultgen.effects.base import (
    EFFECTS,
    REGISTRY,
    REST_SPEED,
    Effect,
    ModelError,
    Motion,
    get,
    make,
    read_all,
    register,
)
from faultgen.effects.motor_friction import FrictionParameter, MotorFriction

# MuJoCo's default log handler appends each warning (a diverging simulation's "Nan, Inf or huge
# value in QACC") to MUJOCO_LOG.TXT in the current folder, which a refused or failed command then
# leaves behind. faultgen reports the failure itself, naming the run and axis; MuJoCo's
# console line stays, its file goes. Set here, in the lowest layer, so that every process that
# builds or steps a model (the command, its sweep workers, a library user's) has it.
_log = mujoco.MjLogConfig.get()
_log.logto_file = False
mujoco.MjLogConfig.set(_log)
del _log

# Every other module of this package defines one effect, registered when it is imported: adding
# an effect is adding a module.
for _module in pkgutil.iter_modules(__path__):
    if _module.name not in ("base", "friction"):
        importlib.import_module(f"{__name__}.{_module.name}")

__all__ = ["EFFECTS", "REGISTRY", "REST_SPEED", "Effect", "FrictionParameter", "ModelError", "MotorFriction", "Motion",
           "get", "make", "read_all", "register"]
