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
stribeck                   static (N m), stribeck_velocity (rad/s), motor   numeric friction{i}
load_dependent_friction    coefficient (1)                                  numeric load_dependent_friction{i}
temperature                amplitude (1), time_constant (s)                 numeric temperature{i}
payload                    mass (kg), robot-wide                            bodies payload{n} at the flange
cogging                    amplitude (N m, motor side), poles (1), phase    numeric cogging{i}
backlash                   width (rad, arm side)                            tendon gearbox{i} springlength
=========================  ===============================================  ======================

The table's order is the registration order, the order in which the calibration tries them.
This is the lowest layer of faultgen: it imports nothing else of it (the robot it is given is
used through its attributes).
"""

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

# Registration order is identification order: keep it (ties in the calibration go to the earlier).
# isort: off
from faultgen.effects.torque_offset import TorqueOffset
from faultgen.effects.coulomb import Coulomb
from faultgen.effects.viscous import Viscous
from faultgen.effects.stribeck import Stribeck
from faultgen.effects.load_dependent_friction import LoadDependentFriction
from faultgen.effects.temperature import Temperature
from faultgen.effects.payload import Payload
from faultgen.effects.cogging import Cogging
from faultgen.effects.backlash import Backlash
# isort: on

__all__ = [
    "EFFECTS", "REST_SPEED", "Backlash", "Cogging", "Coulomb", "Effect", "FrictionParameter",
    "LoadDependentFriction", "ModelError", "Motion", "Payload", "Stribeck", "Temperature", "TorqueOffset",
    "Viscous", "get", "make", "read_all", "register",
]
