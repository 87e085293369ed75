"""The friction models of the simulation: how a robot's motor-side friction
(:class:`~faultgen.effects.motor_friction.MotorFriction`, the registered effect ``motor_friction``)
enters MuJoCo as LuGre (a ``dcmotor`` actuator per rotor) or as the static Stribeck map (the
rotors' friction loss, set every step). :data:`FIELDS`, :data:`UNITS` and :class:`MotorFriction`
are the effect's, importable from here as before.
"""

from __future__ import annotations

import mujoco
import numpy as np

from faultgen.effects.motor_friction import FIELDS, UNITS, MotorFriction

__all__ = ["FIELDS", "MODELS", "UNITS", "MotorFriction", "add_lugre", "add_passive_dcmotor", "add_stribeck",
           "check_lugre_step", "check_model", "lugre_parameters"]


#: Friction models a simulation can use (``faultgen simulate --friction``).
MODELS = ("lugre", "stribeck")


def check_model(name: str) -> str:
    """Return ``name`` if it is a friction model in :data:`MODELS`, else raise ValueError."""
    if name not in MODELS:
        raise ValueError(f"unknown friction model {name!r}; expected one of: {', '.join(MODELS)}")
    return name


def lugre_parameters(friction: MotorFriction, timestep: float) -> np.ndarray:
    """MuJoCo ``dcmotor`` ``lugre`` attribute per axis, ``ndarray of shape (n_axes, 5)``.

    Columns: bristle stiffness sigma_0 (N m/rad), MuJoCo's damping slot (N m s/rad, see below),
    Coulomb level F_c (N m), breakaway level F_s = F_c + f_s (N m) and Stribeck velocity (rad/s).
    MuJoCo's LuGre is direction-symmetric with a Gaussian Stribeck curve: its steady state is
    F_c + (F_s - F_c) exp(-(v / v_s)^2), thesis eq. 6.3 with gamma = 2 (checked in
    tests/test_friction_models.py). The Coulomb level is the mean of the two directions.

    The damping slot is not the model's bristle damping (which must be 0,
    :func:`check_lugre_step`) but ``sigma_0 h / 2`` for the physics step ``timestep`` = h: MuJoCo
    applies ``-sigma_0 z - sigma_1 dz/dt`` with the bristle state z and its rate at the start of
    the step, so this makes the force ``-sigma_0 (z + h/2 dz/dt)``, the bristle force at the
    step's midpoint. In presliding (dz/dt = v) it is the midpoint rule, whose error is second
    order in h where the start-of-step force's is first order; in sliding dz/dt is about 0 and
    the force is the steady state. Its side effect, the implicit step's ``h sigma_1`` of rotor
    inertia (see :func:`check_lugre_step`), is ``sigma_0 h^2 / 2``: second order too, 0.02-0.07 %
    of the robots' rotor inertias at 0.5 ms (0.26 % on the PUMA 560's axis 1).
    docs/simulation.md, "Numerical convergence", items 1 and 6.

    Raises
    ------
    ValueError
        If an axis has a Stribeck exponent other than 2, which MuJoCo's LuGre cannot represent.
    """
    bad = np.flatnonzero(friction.stribeck_exponent != 2.0)
    if bad.size:
        axis = int(bad[0])
        raise ValueError(
            f"axis {axis + 1}: stribeck_exponent = {float(friction.stribeck_exponent[axis])!r}; the "
            "lugre friction model needs 2 (use --friction stribeck for other exponents)"
        )
    coulomb = (friction.coulomb_pos + friction.coulomb_neg) / 2
    return np.stack(
        [friction.bristle_stiffness, friction.bristle_stiffness * timestep / 2, coulomb, coulomb + friction.static,
         friction.stribeck_velocity],
        axis=1,
    )


def check_lugre_step(friction: MotorFriction, timestep: float, speed_damping: np.ndarray) -> None:
    """Refuse LuGre parameters that MuJoCo's implicit step cannot integrate to convergence.

    Two conditions, both measured in docs/simulation.md ("Numerical convergence"):

    * bristle damping sigma_1 must be 0. MuJoCo's ``dcmotor`` treats ``-sigma_1 dz/dt`` as a
      damping ``-sigma_1 v`` in the implicit step at every speed, but in sliding the bristle sits
      at its steady state and the force's true speed derivative is about 0: the rotor moves as if
      its inertia were ``Jm + h sigma_1`` (40-145 % too heavy at 0.5 ms with the earlier
      ``sigma_1 = 2 sqrt(sigma_0 Jm)``), a first-order step error. Canudas de Wit, Olsson, Astrom
      & Lischinsky (1995) let sigma_1 vanish away from zero speed; MuJoCo has one constant, so it
      is 0 and the presliding mode is damped by the drive's speed loop and viscous friction;
    * ``sigma_0 h < kd + f_v``: the bristle state is advanced with the speed at the start of the
      step, so at rest the rotor on its bristles is an explicit (forward-Euler) oscillator whose
      energy grows by ``(1 + h^2 sigma_0 / Jm)`` per step unless the implicit damping removes more
      (the drive's kd, f_v and the midpoint term ``sigma_0 h / 2`` of :func:`lugre_parameters`:
      with it, ``sigma_0 h < 2 (kd + f_v)`` would do; the bound keeps a factor 2 in hand). Inside
      the bound it is stable, not yet accurate: the robots' 100 mrad presliding deflection keeps
      ``sigma_0 h`` at 0.6-5.5 % of ``kd + f_v`` (robots/<robot>/README.md).

    Parameters
    ----------
    friction : MotorFriction
    timestep : float
        Physics step h in s.
    speed_damping : ndarray of shape (n_axes,)
        Damping of each rotor by its drive, the speed-loop gain kd in N m s/rad at the motor side.

    Raises
    ------
    ValueError
        Naming the axis, the value and the largest one allowed.
    """
    for k in range(len(friction.bristle_damping)):
        if friction.bristle_damping[k] > 0:
            raise ValueError(
                f"axis {k + 1}: bristle_damping = {float(friction.bristle_damping[k])!r} N m s/rad; the lugre model "
                "needs 0 (MuJoCo integrates it as damping at every speed, which adds h * sigma_1 of rotor "
                "inertia; docs/simulation.md, 'Numerical convergence'), or use --friction stribeck"
            )
        limit = (speed_damping[k] + friction.viscous[k]) / timestep
        if friction.bristle_stiffness[k] >= limit:
            raise ValueError(
                f"axis {k + 1}: bristle_stiffness = {float(friction.bristle_stiffness[k])!r} N m/rad is too stiff for "
                f"the {timestep * 1e3:g} ms physics step; expected below (kd + viscous) / timestep = {limit:.4g} "
                "N m/rad (a longer presliding deflection), or a smaller timestep"
            )


def add_lugre(spec, robot) -> None:
    """Add a passive LuGre friction actuator ``lugre{i}`` on every rotor joint, in place.

    Each is a ``dcmotor`` with no input and no electrical branch, whose only force is the LuGre
    friction (Astrom & Canudas-de-Wit 2008) of :func:`lugre_parameters`, with the viscous term
    f_v as the actuator's damping. The bristle deflection is its activation state, integrated by
    MuJoCo at the physics rate. Wear scales ``actuator_biasprm[:, 3:5]`` (F_c and F_s).
    """
    table = lugre_parameters(robot.friction, spec.option.timestep)
    for k, rotor in enumerate(robot.rotor_names):
        actuator = add_passive_dcmotor(spec, f"lugre{k + 1}", rotor, lugre=[float(v) for v in table[k]])
        actuator.damping[0] = float(robot.friction.viscous[k])


def add_passive_dcmotor(spec, name: str, rotor: str, **terms):
    """Add a ``dcmotor`` actuator ``name`` on the joint ``rotor`` with no input (``ctrlspec`` 16,
    "none") and no electrical branch, whose only force is its ``terms`` (``lugre=...``,
    ``cogging=...``: MuJoCo computes them in C at the physics rate); returns the actuator."""
    actuator = spec.add_actuator(name=name, target=rotor)
    actuator.trntype = mujoco.mjtTrn.mjTRN_JOINT
    actuator.set_to_dcmotor(motorconst=[0.0, 0.0], resistance=1.0, ctrlspec=16, **terms)
    return actuator


def add_stribeck(spec, robot) -> None:
    """Prepare the rotor joints for the static Stribeck model, in place.

    The viscous term f_v becomes the rotor joint's damping (integrated implicitly). The
    Coulomb-plus-Stribeck level is MuJoCo's joint friction loss, a dry-friction constraint that
    can stick (stiction-capable, no regularised sign): the simulator sets it before every step to
    :meth:`MotorFriction.stribeck_level` of the rotor's current speed. The constraint is made
    nearly hard (time constant of two physics steps, impedance 0.9999): with MuJoCo's default
    soft friction loss a rotor held at 90 % of breakaway creeps ~0.2 rad/s; with these it creeps
    ~1e-5 rad/s (tests/test_friction_models.py).
    """
    timestep = spec.option.timestep
    for k, rotor in enumerate(robot.rotor_names):
        joint = spec.joint(rotor)
        joint.damping[0] = float(robot.friction.viscous[k])
        joint.frictionloss = float(robot.friction.coulomb_pos[k] + robot.friction.static[k])
        joint.solref_friction = [2 * timestep, 1.0]
        joint.solimp_friction = [0.9999, 0.9999, 0.001, 0.5, 2.0]
