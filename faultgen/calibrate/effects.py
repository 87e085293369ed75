"""The library of physical effects the calibration workflow can add to a robot model.

Each effect is one small class (the candidate-term library of PySINDy, one term family per
class) that knows

* its stable ``id`` (the design document's effect ids; never renamed),
* the regressors it adds to the arm-side torque of one axis, given the measured motion
  (``q, qd, qdd``, time ``t``) and the robot's parameters (gear ratio, friction, masses): columns
  ``Phi`` and a known part ``offset`` such that the effect's torque is ``Phi @ theta + offset``,
  linear in ``theta``; a nonlinear parameter (a Stribeck velocity, a pole count, a time
  constant) is a small ``grid`` searched outside the linear least squares,
* how ``theta`` maps to its physical parameters, in SI units at the side the MJCF stores them,
* how it writes itself into the robot's MJCF (:meth:`Effect.apply` on a ``mujoco.MjSpec``).

The torque an effect predicts and the torque the augmented model gives in
:meth:`faultgen.robots.Robot.inverse_dynamics` are the same function (backlash: to first order in
b; tests/test_calibrate_effects.py checks every effect), so the model the workflow writes
reproduces what was fitted. The thesis has no calibration chapter: the friction effects refine
its eq. 6.3 (Coulomb, viscous, Stribeck) and its wear model of eq. 6.6 (friction that changes
with time); the others are the standard unmodelled effects of robot identification.

All torques here are arm-side drive torques in N m (motor torque times the gear ratio G), the
unit of the measured ``tau`` columns.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import mujoco
import numpy as np

from faultgen import robots
from faultgen.friction import FIELDS as FRICTION_FIELDS

_COULOMB_POS, _COULOMB_NEG, _STATIC, _STRIBECK_VELOCITY = (FRICTION_FIELDS.index(f) for f in (
    "coulomb_pos", "coulomb_neg", "static", "stribeck_velocity"))
_VISCOUS = FRICTION_FIELDS.index("viscous")

#: Arm-side speed (rad/s) below which an axis counts as at rest: its friction is then stiction,
#: any value up to the breakaway torque, which no kinetic model predicts, so those samples of
#: that axis are neither fitted nor scored (:class:`faultgen.calibrate.search.Split`).
REST_SPEED = 0.05


@dataclass(frozen=True)
class Motion:
    """Measured motion and what the current model says about it; every array ``(n, 6)``.

    Attributes
    ----------
    robot : Robot
        The current model (nominal, or with the effects added so far).
    t : ndarray of shape (n,)
        Time since the first sample, s.
    q, qd, qdd : ndarray of shape (n, 6)
        Arm-side angles (rad), velocities (rad/s), accelerations (rad/s^2).
    load : ndarray of shape (n, 6)
        Arm-side gearbox load: the rigid-body torque of the arm joints without motor inertia
        and friction, N m.
    """

    robot: robots.Robot
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    load: np.ndarray

    @classmethod
    def of(cls, robot: robots.Robot, t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> Motion:
        """Evaluate ``robot``'s rigid-body load along a measured motion."""
        rigid = robot.inverse_dynamics(q, qd, qdd, friction=False)
        load = rigid - robot.gear_ratio**2 * robot.motor_inertia * qdd
        return cls(robot, np.asarray(t, dtype=float) - float(t[0]), q, qd, qdd, load)

    @property
    def motor_velocity(self) -> np.ndarray:
        """Motor-side velocity ``G qd`` in rad/s, shape (n, 6)."""
        return self.robot.gear_ratio * self.qd


class Effect:
    """One family of physical effects. Subclasses set the class attributes and the methods.

    Attributes
    ----------
    id : str
        Stable effect id used in ``report.json``.
    summary : str
        One line: the physics, for ``--help`` and the report.
    per_axis : bool
        True when the effect has its own parameters on each axis; False for a robot-wide
        effect (payload), fitted on all axes at once.
    n_parameters : int
        Linear parameters per axis (per robot when not ``per_axis``), for the report.
    """

    id: ClassVar[str]
    summary: ClassVar[str]
    per_axis: ClassVar[bool] = True
    n_parameters: ClassVar[int] = 1
    #: True when the grid samples a continuous parameter, refined by a bounded scalar search
    continuous: ClassVar[bool] = False

    def grid(self, motion: Motion, axis: int) -> list:
        """Values of the nonlinear parameter to search; ``[None]`` when the effect is linear."""
        return [None]

    def columns(self, motion: Motion, axis: int, h) -> tuple[np.ndarray, np.ndarray]:
        """Regressors ``Phi`` (n, k) and known part ``offset`` (n,) of the torque of ``axis``
        (0-based), or of all axes ``(n, 6, k)`` / ``(n, 6)`` when not ``per_axis``."""
        raise NotImplementedError

    def params(self, motion: Motion, axis: int, theta: np.ndarray, h) -> dict[str, float]:
        """Physical parameters, named with their unit, from the fitted ``theta``."""
        raise NotImplementedError

    def admissible(self, motion: Motion, axis: int | None, params: dict[str, float]) -> bool:
        """False when ``params`` are not physical for the current model (a negative mass or
        backlash, a friction level that would go below zero); such a fit is never selected."""
        return True

    def apply(self, spec: mujoco.MjSpec, robot: robots.Robot, axis: int | None, params: dict[str, float]) -> None:
        """Write the effect with ``params`` on ``axis`` (0-based; None for robot-wide) into ``spec``."""
        raise NotImplementedError


def _friction_row(spec: mujoco.MjSpec, axis: int) -> np.ndarray:
    return np.array(spec.numeric(f"friction{axis + 1}").data, dtype=float)


def _set_friction_row(spec: mujoco.MjSpec, axis: int, row: np.ndarray) -> None:
    spec.numeric(f"friction{axis + 1}").data = [float(v) for v in row]


def _set_numeric(spec: mujoco.MjSpec, name: str, values) -> None:
    values = [float(v) for v in np.atleast_1d(values)]
    existing = spec.numeric(name)
    if existing is None:
        spec.add_numeric(name=name, data=values)
    else:
        existing.data = values


def _get_numeric(spec: mujoco.MjSpec, name: str, default) -> np.ndarray:
    existing = spec.numeric(name)
    return np.array(default if existing is None else existing.data, dtype=float)


class Coulomb(Effect):
    """Extra Coulomb friction: ``G df_c sign(qd)``, df_c in N m at the motor side (thesis eq. 6.3)."""

    id = "coulomb"
    summary = "Coulomb friction level differs (constant torque against the motion)"

    def columns(self, motion, axis, h):
        G = motion.robot.gear_ratio[axis]
        return G * np.sign(motion.qd[:, axis])[:, None], np.zeros(len(motion.t))

    def params(self, motion, axis, theta, h):
        return {"coulomb_change_Nm_motor": float(theta[0])}

    def admissible(self, motion, axis, params):
        f = motion.robot.friction
        return min(f.coulomb_pos[axis], f.coulomb_neg[axis]) + params["coulomb_change_Nm_motor"] >= 0

    def apply(self, spec, robot, axis, params):
        row = _friction_row(spec, axis)
        for k in (_COULOMB_POS, _COULOMB_NEG):
            row[k] = max(row[k] + params["coulomb_change_Nm_motor"], 0.0)
        _set_friction_row(spec, axis, row)


class Viscous(Effect):
    """Extra viscous friction: ``G^2 df_v qd``, df_v in N m s/rad at the motor side (eq. 6.3)."""

    id = "viscous"
    summary = "viscous friction differs (torque proportional to speed)"

    def columns(self, motion, axis, h):
        G = motion.robot.gear_ratio[axis]
        return (G**2 * motion.qd[:, axis])[:, None], np.zeros(len(motion.t))

    def params(self, motion, axis, theta, h):
        return {"viscous_change_Nm_s_per_rad_motor": float(theta[0])}

    def admissible(self, motion, axis, params):
        return motion.robot.friction.viscous[axis] + params["viscous_change_Nm_s_per_rad_motor"] >= 0

    def apply(self, spec, robot, axis, params):
        row = _friction_row(spec, axis)
        row[_VISCOUS] = max(row[_VISCOUS] + params["viscous_change_Nm_s_per_rad_motor"], 0.0)
        _set_friction_row(spec, axis, row)


class Stribeck(Effect):
    """Stribeck hump of other size and velocity: thesis eq. 6.3's ``f_s exp(-|v/v_s|^gamma)``.

    The model's term ``f_s exp(-|v/v_s|^gamma) sign(v)`` is replaced by one with a new static
    excess f_s (linear) and Stribeck velocity v_s, searched up to 0.3 times the 95th-percentile
    motor speed (so a hump is never a disguised Coulomb step), down to a tenth of that or three
    times the rest speed (:data:`REST_SPEED`, below which nothing is fitted); gamma is kept.
    """

    id = "stribeck"
    summary = "Stribeck friction (extra friction at low speed, fading with speed) differs"
    continuous = True

    def grid(self, motion, axis):
        v = np.abs(motion.motor_velocity[:, axis])
        top = 0.3 * float(np.percentile(v, 95))
        low = max(3 * REST_SPEED * motion.robot.gear_ratio[axis], top / 10)
        return list(np.geomspace(low, top, 12)) if top > 2 * low else [None]

    def _shape(self, motion, axis, v_s):
        gamma = motion.robot.friction.stribeck_exponent[axis]
        v = motion.motor_velocity[:, axis]
        return np.exp(-np.abs(v / v_s) ** gamma) * np.sign(v)

    def columns(self, motion, axis, h):
        G = motion.robot.gear_ratio[axis]
        f = motion.robot.friction
        if h is None:
            return np.zeros((len(motion.t), 1)), np.zeros(len(motion.t))
        old = G * f.static[axis] * self._shape(motion, axis, f.stribeck_velocity[axis])
        return (G * self._shape(motion, axis, h))[:, None], -old

    def params(self, motion, axis, theta, h):
        return {"static_Nm_motor": float(theta[0]), "stribeck_velocity_rad_per_s_motor": float(h or 1.0)}

    def admissible(self, motion, axis, params):
        return params["static_Nm_motor"] >= 0

    def apply(self, spec, robot, axis, params):
        row = _friction_row(spec, axis)
        row[_STATIC] = max(params["static_Nm_motor"], 0.0)
        row[_STRIBECK_VELOCITY] = params["stribeck_velocity_rad_per_s_motor"]
        _set_friction_row(spec, axis, row)


class Payload(Effect):
    """An unmodelled point mass at the flange (tool or workpiece), in kg: robot-wide.

    Its torque is linear in the mass: the difference between the inverse dynamics with and
    without a unit point mass at the ``flange`` site, which is exactly what :meth:`apply` adds.
    """

    id = "payload"
    summary = "an unmodelled payload (mass at the flange)"
    per_axis = False

    def columns(self, motion, axis, h):
        unit = _with(motion.robot, lambda spec: self.apply(spec, motion.robot, None, {"mass_kg": 1.0}))
        with_mass = unit.inverse_dynamics(motion.q, motion.qd, motion.qdd, friction=False)
        without = motion.robot.inverse_dynamics(motion.q, motion.qd, motion.qdd, friction=False)
        return (with_mass - without)[:, :, None], np.zeros_like(with_mass)

    def params(self, motion, axis, theta, h):
        return {"mass_kg": float(theta[0])}

    def admissible(self, motion, axis, params):
        return params["mass_kg"] > 0

    def apply(self, spec, robot, axis, params):
        flange = spec.site("flange")
        count = sum(1 for b in spec.bodies if b.name.startswith("payload"))
        # the compiled site position is in the link's frame (the MJCF may nest it in a <frame>)
        position = robot.model.site("flange").pos
        body = flange.parent.add_body(name=f"payload{count + 1}", pos=[float(v) for v in position])
        mass = max(float(params["mass_kg"]), 0.0)
        # a point mass: MuJoCo needs a positive inertia, 1e-9 kg m^2 per kg changes no torque
        body.mass = mass
        body.inertia = [1e-9 * max(mass, 1e-3)] * 3
        body.ipos = [0.0, 0.0, 0.0]
        body.explicitinertial = True


class Cogging(Effect):
    """Cogging: a motor torque periodic in the motor angle, ``A sin(p G q + phase)`` at the
    motor side with p periods per motor revolution (MuJoCo ``dcmotor`` ``cogging``); the drive
    holds against it, so the arm-side drive torque gains ``-G A sin(p G q + phase)``."""

    id = "cogging"
    summary = "cogging torque (periodic in the motor angle)"
    n_parameters = 2
    POLES = tuple(range(1, 25))

    def grid(self, motion, axis):
        return list(self.POLES)

    def columns(self, motion, axis, h):
        G = motion.robot.gear_ratio[axis]
        angle = h * G * motion.q[:, axis]
        return G * np.stack([np.sin(angle), np.cos(angle)], axis=1), np.zeros(len(motion.t))

    def params(self, motion, axis, theta, h):
        # -A sin(x + phi) = -A cos(phi) sin(x) - A sin(phi) cos(x)
        amplitude = float(np.hypot(*theta))
        phase = float(np.arctan2(-theta[1], -theta[0]))
        return {"amplitude_Nm_motor": amplitude, "poles": int(h), "phase_rad": phase}

    def apply(self, spec, robot, axis, params):
        _set_numeric(spec, f"cogging{axis + 1}",
                     [params["amplitude_Nm_motor"], params["poles"], params["phase_rad"]])


class Backlash(Effect):
    """Gearbox backlash b (rad, arm side): a dead band in the gearbox spring (tendon
    ``springlength="-b/2 b/2"``), taken quasi-statically.

    With the angle logged at the motor (``q = theta_m / G``, what a robot's encoders give), the
    arm rests on the loaded flank, ``b/2`` behind the motor against the gearbox load, so its
    rigid-body torque is that at ``q - (b/2) sign(tau_load)`` (what
    :meth:`faultgen.robots.Robot.inverse_dynamics` computes for a model with backlash); to first
    order the torque changes by ``-(b/2) sign(tau_load) d(tau_load)/dq_i``, linear in b. The
    transients of crossing the dead band (the motor swinging through the gap, the arm landing
    on the other flank) are not modelled: docs/calibration.md shows that they, not this
    quasi-static shift, dominate the torque trace of a simulated dead band, so hidden backlash is
    not found.
    """

    id = "backlash"
    summary = "gearbox backlash (dead band between motor and arm)"

    def columns(self, motion, axis, h):
        step = 1e-4
        q = motion.q.copy()
        q[:, axis] += step
        shifted = motion.robot.inverse_dynamics(q, motion.qd, motion.qdd, friction=False)
        rigid = motion.robot.inverse_dynamics(motion.q, motion.qd, motion.qdd, friction=False)
        slope = (shifted - rigid)[:, axis] / step
        return (-0.5 * np.sign(motion.load[:, axis]) * slope)[:, None], np.zeros(len(motion.t))

    def params(self, motion, axis, theta, h):
        return {"backlash_rad": float(theta[0])}

    def admissible(self, motion, axis, params):
        return params["backlash_rad"] > 0

    def apply(self, spec, robot, axis, params):
        half = max(params["backlash_rad"], 0.0) / 2
        spec.tendon(f"gearbox{axis + 1}").springlength = [-half, half]


class LoadDependentFriction(Effect):
    """Coulomb friction growing with the gearbox load, ``mu |tau_load| sign(qd)`` at the arm side
    (tooth-contact friction in the gearbox; mu dimensionless)."""

    id = "load_dependent_friction"
    summary = "friction that grows with the gearbox load"

    def columns(self, motion, axis, h):
        regressor = np.abs(motion.load[:, axis]) * np.sign(motion.qd[:, axis])
        return regressor[:, None], np.zeros(len(motion.t))

    def params(self, motion, axis, theta, h):
        return {"load_friction_coefficient": float(theta[0])}

    def admissible(self, motion, axis, params):
        return motion.robot.load_friction[axis] + params["load_friction_coefficient"] >= 0

    def apply(self, spec, robot, axis, params):
        old = _get_numeric(spec, f"load_friction{axis + 1}", [0.0])[0]
        _set_numeric(spec, f"load_friction{axis + 1}", [max(old + params["load_friction_coefficient"], 0.0)])


class Temperature(Effect):
    """Warm-up: the dry friction (Coulomb plus Stribeck, eq. 6.3) times ``1 + a exp(-t / T)``, t
    from the first sample; a (fraction) is linear, T (s) is searched from 0.3 to 5 times
    the record length, so the drift is visible within the record."""

    id = "temperature"
    summary = "friction drifting with time (a gearbox warming up)"
    continuous = True

    def grid(self, motion, axis):
        duration = float(motion.t[-1])
        return list(np.geomspace(0.3 * duration, 5 * duration, 12))

    def columns(self, motion, axis, h):
        G = motion.robot.gear_ratio[axis]
        v = motion.motor_velocity
        dry = motion.robot.friction.stribeck_level(v)[:, axis] * np.sign(v[:, axis])
        return (G * dry * np.exp(-motion.t / h))[:, None], np.zeros(len(motion.t))

    def params(self, motion, axis, theta, h):
        return {"amplitude": float(theta[0]), "time_constant_s": float(h)}

    def admissible(self, motion, axis, params):
        return params["amplitude"] > -1

    def apply(self, spec, robot, axis, params):
        _set_numeric(spec, f"thermal{axis + 1}", [params["amplitude"], params["time_constant_s"]])


class TorqueOffset(Effect):
    """A constant offset of the measured drive torque (current-sensor offset, unmodelled static
    load), N m at the arm side."""

    id = "torque_offset"
    summary = "a constant torque offset"

    def columns(self, motion, axis, h):
        return np.ones((len(motion.t), 1)), np.zeros(len(motion.t))

    def params(self, motion, axis, theta, h):
        return {"offset_Nm": float(theta[0])}

    def apply(self, spec, robot, axis, params):
        old = _get_numeric(spec, f"torque_offset{axis + 1}", [0.0])[0]
        _set_numeric(spec, f"torque_offset{axis + 1}", [old + params["offset_Nm"]])


#: Every effect, by id, in the order they are tried (ties go to the earlier, simpler one).
EFFECTS: dict[str, Effect] = {e.id: e for e in (
    TorqueOffset(), Coulomb(), Viscous(), Stribeck(), LoadDependentFriction(), Temperature(), Payload(),
    Cogging(), Backlash())}


def get(effect_id: str) -> Effect:
    """The effect with ``effect_id``; raises ``ValueError`` listing the known ids otherwise."""
    try:
        return EFFECTS[effect_id]
    except KeyError:
        raise ValueError(f"unknown effect {effect_id!r}; known effects: {', '.join(EFFECTS)}") from None


def _with(robot: robots.Robot, edit) -> robots.Robot:
    """A copy of ``robot`` with ``edit(spec)`` applied to its MJCF, compiled in memory."""
    spec = mujoco.MjSpec.from_file(str(robot.path))
    edit(spec)
    return robots.from_spec(spec, robot.path)
