"""The library of physical effects the calibration workflow can add to a robot model.

Each effect is one small class (the candidate-term library of PySINDy, one term family per
class) that knows

* its stable ``id`` (the design document's effect ids; never renamed),
* the regressors it adds to the arm-side torque of one axis, given the measured motion
  (``q, qd, qdd``, time ``t``) and the robot's parameters (gear ratio, friction, masses): columns
  ``Phi`` and a known part ``offset`` such that the effect's torque is ``Phi @ theta + offset``,
  linear in ``theta``; a nonlinear parameter (a Stribeck velocity, a pole count, a time
  constant) is a small ``grid`` searched outside the linear least squares (an effect with no
  linear parameter, backlash, brings its own :meth:`Effect.search`),
* how ``theta`` maps to its physical parameters, in SI units at the side the MJCF stores them,
* how it writes itself into the robot's MJCF (:meth:`Effect.apply` on a ``mujoco.MjSpec``).

The torque an effect predicts and the torque the augmented model gives in
:meth:`faultgen.robots.Robot.inverse_dynamics` are the same function (backlash: in
:func:`faultgen.calibrate.predict`, which adds the flexible-gearbox equation, with its
quasi-static part to first order in b; tests/test_calibrate_effects.py checks every effect), so
the model the workflow writes reproduces what was fitted. The thesis has no calibration chapter: the friction effects refine
its eq. 6.3 (Coulomb, viscous, Stribeck) and its wear model of eq. 6.6 (friction that changes
with time); the others are the standard unmodelled effects of robot identification.

All torques here are arm-side drive torques in N m (motor torque times the gear ratio G), the
unit of the measured ``tau`` columns.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import mujoco
import numpy as np

from faultgen.calibrate import gearbox
from faultgen.model import robots
from faultgen.model.friction import FIELDS as FRICTION_FIELDS

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
        and friction, the arm at the motor angle, N m.
    """

    robot: robots.Robot
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    load: np.ndarray
    #: Results an effect computes once per motion for all its grid values (backlash).
    memo: dict = field(default_factory=dict, compare=False, repr=False)

    @classmethod
    def of(cls, robot: robots.Robot, t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> Motion:
        """Evaluate ``robot``'s rigid-body load along a measured motion
        (:meth:`faultgen.robots.Robot.gearbox_load`)."""
        return cls(robot, np.asarray(t, dtype=float) - float(t[0]), q, qd, qdd, robot.gearbox_load(q, qd, qdd))

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

    def search(self, motion: Motion, residual: np.ndarray, rows: np.ndarray, scale: np.ndarray) -> list | None:
        """The effect's own fit of all axes to ``residual`` (n, 6) on the samples of ``rows``
        (n, 6), axis a weighted by ``1 / scale[a]**2`` (its torque RMS, N m): per axis
        ``(h, theta, predicted torque (n,))``. None (the default): the generic per-axis least
        squares over :meth:`grid` and :meth:`columns`."""
        return None

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
    """Gearbox backlash b (rad, arm side): a dead band of width b in the gearbox spring (tendon
    ``springlength="-b/2 b/2"``), fitted per axis by a search over b.

    The torque of a dead band is not linear in b. Two parts, both what a model with backlash
    predicts (:func:`faultgen.calibrate.predict`):

    * the gearbox with the dead band (:func:`faultgen.calibrate.gearbox.compliance_torque`):
      when the load reverses, the arm crosses the gap and lands on the other flank, and while it
      crosses the motor's motion does not reach it. On the soft axes whose resonance the
      measured accelerations resolve (the IRB-6700-like axes 1-3) the gearbox equation carries
      it, with the dead band in its spring: the drive torque loses the ringing of the linear
      model. On the stiff axes (the PUMA 560's) it is rigid contact: the floating arm's load is
      missing from the drive torque while it crosses;
    * quasi-statically, the arm rests on the loaded flank ``b/2`` behind the motor, so its
      rigid-body terms are those at ``q - (b/2) sign(load)``
      (:meth:`faultgen.robots.Robot.inverse_dynamics`), taken here to first order in b.

    The effect has no linear parameter, and the axes are coupled: a dead band on the
    IRB-6700-like axis 2 changes the torque of axis 3 through the arm's inertia. :meth:`search`
    therefore adds dead bands one axis at a time (coordinate-wise): every axis not yet chosen
    is tried at every width of :data:`GRID` (geometric, steps of 6 %; all in one pass), the best
    is refined over :data:`REFINE` widths between its neighbours (steps of 0.4 %), and it is
    kept when it lowers the fitting part's error over all axes (each weighted by its torque
    RMS) by at least :data:`MIN_DROP` and lies inside the searched range; then the next axis.
    The held-out error is sharp in b (an IRB-6700-like log with b = 19.3 mrad on axis 2: total
    nrmse 0.080 at 17.1 mrad, 0.047 at 18.4, 0.124 at 19.9), so a coarse grid alone misses it.
    """

    id = "backlash"
    summary = "gearbox backlash (dead band between motor and arm)"
    n_parameters = 0
    #: Dead-band widths searched first, rad at the arm side: 0.2 mrad (0.7 arcmin) to 50 mrad (2.9 deg).
    GRID = tuple(float(b) for b in np.geomspace(2e-4, 0.05, 96))
    #: Widths in the second pass, between the best grid width's neighbours.
    REFINE = 33
    #: Smallest relative drop of the weighted fitting error for which a dead band on one more
    #: axis is kept. A dead band on one axis leaves coupled ringing on its neighbours that a
    #: small dead band there stands in for: at 0.01 a hidden-backlash log of the IRB-6700-like
    #: arm with dead bands on axes 1 and 2 got a third, of 0.9 mrad, on axis 3 (7 % drop); at 0.1,
    #: on the back-to-back log of seed 4 (19.2 / 12.7 mrad on axes 1 / 2), one of 3.7 mrad on
    #: axis 3, which 0.2 leaves out (held-out total nrmse 0.0600 with it, 0.0599 without).
    MIN_DROP = 0.2

    def grid(self, motion, axis):
        return list(self.GRID)

    def _change(self, motion: Motion, widths: np.ndarray) -> np.ndarray:
        """Torque change, (m, n, 6) N m, of the dead-band widths ``widths`` (m, 6) rad over the
        current model: the gearbox equation's and, to first order, the quasi-static shift's."""
        robot = motion.robot
        if "backlash" not in motion.memo:
            current = gearbox.compliance_torque(robot, motion.t, motion.q, motion.load)
            step = 1e-4
            rigid = robot.inverse_dynamics(motion.q, motion.qd, motion.qdd, friction=False)
            slope = np.empty_like(rigid)
            for axis in range(6):  # d(rigid torque of the axis)/d(its angle), the arm moved alone
                q = motion.q.copy()
                q[:, axis] += step
                shifted = robot.inverse_dynamics(q, motion.qd, motion.qdd, friction=False)
                slope[:, axis] = (shifted - rigid)[:, axis] / step
            motion.memo["backlash"] = current, -0.5 * np.sign(motion.load) * slope
        current, shift = motion.memo["backlash"]
        change = gearbox.compliance_torque(robot, motion.t, motion.q, motion.load, widths) - current
        return change + (widths - robot.backlash)[:, None, :] * shift

    def columns(self, motion, axis, h):
        widths = motion.robot.backlash.copy()
        widths[axis] = h
        return np.zeros((len(motion.t), 0)), self._change(motion, widths[None])[0, :, axis]

    def search(self, motion, residual, rows, scale):
        robot = motion.robot
        weights = 1.0 / scale**2

        def cost(change):  # (k, n, 6) -> (k,): weighted squared error on the fitting part
            return np.sum(np.where(rows, residual - change, 0.0) ** 2, axis=1) @ weights

        widths = robot.backlash.copy()
        change = np.zeros_like(residual)
        error = float(cost(change[None])[0])
        free = list(range(6))
        grid = np.array(self.GRID)
        while free:
            trials = np.tile(widths, (len(free) * len(grid), 1))
            for block, axis in enumerate(free):
                trials[block * len(grid):(block + 1) * len(grid), axis] = grid
            k = int(np.argmin(cost(self._change(motion, trials))))
            axis, k = free[k // len(grid)], k % len(grid)
            fine = np.tile(widths, (self.REFINE, 1))
            fine[:, axis] = np.geomspace(grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)], self.REFINE)
            changes = self._change(motion, fine)
            costs = cost(changes)
            j = int(np.argmin(costs))
            if costs[j] > (1 - self.MIN_DROP) * error or not self._identified(fine[j, axis]):
                break
            widths, change, error = fine[j], changes[j], float(costs[j])
            free.remove(axis)
        return [(float(widths[a]), np.zeros(0), change[:, a]) for a in range(6)]

    def params(self, motion, axis, theta, h):
        return {"backlash_rad": float(h)}

    def admissible(self, motion, axis, params):
        # an axis whose width the search left as it was only carries the others' coupling; a
        # width at either end of the range is not identified (in the logs with no dead band,
        # the smallest width's ringing at load reversals stood in for stick-slip ringing, and
        # took axis 2 of the IRB-6700-like arm from 0.046 to 0.032)
        b = params["backlash_rad"]
        return self._identified(b) and b != motion.robot.backlash[axis]

    def _identified(self, width: float) -> bool:
        """False for a width at either end of :data:`GRID` (the optimum may lie outside it)."""
        return self.GRID[1] < width < self.GRID[-2]

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
