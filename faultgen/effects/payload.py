"""An unmodelled payload: a rigid body fixed to the flange (tool or workpiece), given by its mass,
centre of mass and inertia, and identified as the standard barycentric parameters."""

from __future__ import annotations

import weakref
from typing import ClassVar

import mujoco
import numpy as np

from faultgen.effects.base import Effect, register

#: Largest distance of a payload's centre of mass from the flange, m (a physical-consistency bound
#: of the identification; a tool or workpiece of an industrial arm sits well inside it).
MAX_COM = 0.5
#: Inertia entries in the order of MuJoCo's ``fullinertia``: xx, yy, zz, xy, xz, yz.
INERTIA = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
#: Smallest principal moment MuJoCo is given, kg m^2 per kg: a point mass has none, MuJoCo needs
#: a positive one, and 1e-9 kg m^2 per kg changes no torque.
POINT_INERTIA = 1e-9
#: Each robot object's probe models (:meth:`Payload._probe_models`), dropped with the robot.
_PROBE_MODELS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _matrix(six) -> np.ndarray:
    xx, yy, zz, xy, xz, yz = six
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], dtype=float)


def _six(matrix: np.ndarray) -> np.ndarray:
    return np.array([matrix[0, 0], matrix[1, 1], matrix[2, 2], matrix[0, 1], matrix[0, 2], matrix[1, 2]])


def _shift(mass: float, com: np.ndarray) -> np.ndarray:
    """``m (|c|^2 1 - c c^T)``: what the parallel-axis theorem adds moving an inertia from the
    centre of mass to the flange origin."""
    return mass * (np.dot(com, com) * np.eye(3) - np.outer(com, com))


def barycentric(mass: float, com, inertia) -> np.ndarray:
    """The standard barycentric parameters ``(m, m c_x, m c_y, m c_z, I_xx, I_yy, I_zz, I_xy,
    I_xz, I_yz)`` of a body of ``mass`` (kg) with centre of mass ``com`` (3,) m and inertia
    ``inertia`` (6,) kg m^2 about the centre of mass, the inertia taken about the flange origin:
    the drive torques are linear in them (Atkeson, An & Hollerbach 1986; Khalil & Dombre 2002,
    ch. 9). Shape (10,)."""
    com = np.asarray(com, dtype=float)
    return np.concatenate([[mass], mass * com, _six(_matrix(inertia) + _shift(mass, com))])


def from_barycentric(phi: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Inverse of :func:`barycentric`: ``(mass, com (3,), inertia about the com (6,))``; a body
    without mass has its centre of mass at the flange."""
    mass = float(phi[0])
    com = phi[1:4] / mass if mass > 0 else np.zeros(3)
    return mass, com, _six(_matrix(phi[4:10]) - _shift(mass, com))


def consistent(mass: float, com: np.ndarray, inertia: np.ndarray) -> bool:
    """Physical consistency: positive mass, centre of mass within :data:`MAX_COM` of the flange,
    an inertia about the centre of mass that is positive semi-definite and whose principal
    moments satisfy the triangle inequality (each at most the sum of the other two)."""
    if not mass > 0 or np.linalg.norm(com) > MAX_COM:
        return False
    moments = np.linalg.eigvalsh(_matrix(inertia))
    tolerance = 1e-9 * max(mass, 1.0)
    return bool(moments[0] >= -tolerance and moments[2] <= moments[0] + moments[1] + tolerance)


@register
class Payload(Effect):
    """A rigid body at the ``flange`` site, robot-wide: ``mass`` (kg), centre of mass ``com_x``,
    ``com_y``, ``com_z`` (m, in the flange frame) and inertia about the centre of mass ``ixx`` ..
    ``iyz`` (kg m^2, flange axes), as industrial load identification reports them (mass, centre of
    gravity, inertia). MJCF: a body ``payload1`` at the flange with ``mass``, ``pos`` of its
    inertial frame and ``fullinertia``; several ``payload{n}`` bodies (first-round models) are read
    as their combination.

    Its torque is the rigid-body model's (the body is part of the MJCF, so the simulation and the
    inverse dynamics carry it). Identified by its barycentric parameters (:func:`barycentric`), in
    which the torque is linear: the regressor of each is the inverse dynamics with ten bodies of
    known parameters added one at a time, solved for the unit changes; fitted at three
    :attr:`levels` (mass; mass and centre of mass, the inertia about it kept; all ten), of which the calibration's optimiser
    keeps the most detailed one that is admissible (physically consistent, :func:`consistent`, and
    within the drives' torque) and that the motion excites (Bayesian information criterion).
    """

    id = "payload"
    rank = 70
    excited_by = (
        "poses and accelerations of the forearm and wrist that change the payload's gravity and inertia "
        "torques")
    summary = "an unmodelled payload (mass, centre of mass and inertia at the flange)"
    units: ClassVar[dict[str, str]] = {
        "mass": "kg", "com_x": "m (flange frame)", "com_y": "m (flange frame)", "com_z": "m (flange frame)",
        **{name: "kg m^2 (at the com)" for name in INERTIA}}
    absent = (0.0,) * 10
    per_axis = False
    n_parameters = 10
    levels = (1, 4, 10)  # mass; with the centre of mass; with the inertia

    # -- the MJCF ------------------------------------------------------------------------------

    @classmethod
    def read(cls, model, path):
        site = model.site("flange")
        link = site.bodyid[0]
        site_rotation = _rotation(site.quat)
        phi = np.zeros(10)
        for b in range(model.nbody):
            body = model.body(b)
            if not body.name.startswith("payload") or model.body_parentid[b] != link:
                continue
            rotation = _rotation(model.body_quat[b])
            # centre of mass and inertia in the link's frame, then in the flange's
            com = model.body_pos[b] + rotation @ model.body_ipos[b]
            principal = rotation @ _rotation(model.body_iquat[b])
            inertia = principal @ np.diag(model.body_inertia[b]) @ principal.T
            com = site_rotation.T @ (com - site.pos)
            inertia = site_rotation.T @ inertia @ site_rotation
            phi += barycentric(float(model.body_mass[b]), com, _six(inertia))
        mass, com, inertia = from_barycentric(phi)
        return cls(**_named(mass, com, inertia))

    def apply(self, spec, robot, axis, params):
        """Replace any ``payload{n}`` bodies by one body ``payload1`` at the flange carrying
        ``params`` (none when the mass is 0). A point mass gets :data:`POINT_INERTIA`."""
        for body in [b for b in spec.bodies if b.name.startswith("payload")]:
            spec.delete(body)
        mass, com, inertia = _inertial(params)
        if mass <= 0:
            return
        self._add_body(spec, robot, "payload1", mass, com, inertia)

    @staticmethod
    def _add_body(spec, robot, name, mass, com, inertia) -> None:
        flange = spec.site("flange")
        # the compiled site pose is in the link's frame (the MJCF may nest it in a <frame>)
        site = robot.model.site("flange")
        body = flange.parent.add_body(name=name, pos=[float(v) for v in site.pos],
                                      quat=[float(v) for v in site.quat])
        body.mass = mass
        body.ipos = [float(v) for v in com]
        if np.any(inertia):
            body.fullinertia = [float(v) for v in inertia]
        else:
            body.inertia = [POINT_INERTIA * max(mass, 1e-3)] * 3
        body.explicitinertial = True

    # -- identification ------------------------------------------------------------------------

    #: Bodies of known parameters (mass kg, centre of mass m, inertia about it kg m^2) whose
    #: barycentric parameters span all ten; their torques give the regressors.
    PROBES = (
        (1.0, (0.0, 0.0, 0.0), (0.0,) * 6),
        (1.0, (0.1, 0.0, 0.0), (0.0,) * 6),
        (1.0, (0.0, 0.1, 0.0), (0.0,) * 6),
        (1.0, (0.0, 0.0, 0.1), (0.0,) * 6),
        (1.0, (0.0, 0.0, 0.0), (0.1, 0.06, 0.06, 0.0, 0.0, 0.0)),
        (1.0, (0.0, 0.0, 0.0), (0.06, 0.1, 0.06, 0.0, 0.0, 0.0)),
        (1.0, (0.0, 0.0, 0.0), (0.06, 0.06, 0.1, 0.0, 0.0, 0.0)),
        (1.0, (0.0, 0.0, 0.0), (0.1, 0.1, 0.1, 0.03, 0.0, 0.0)),
        (1.0, (0.0, 0.0, 0.0), (0.1, 0.1, 0.1, 0.0, 0.03, 0.0)),
        (1.0, (0.0, 0.0, 0.0), (0.1, 0.1, 0.1, 0.0, 0.0, 0.03)),
    )

    def columns(self, motion, axis, h):
        """The torque per unit change of each barycentric parameter, N m per unit, shape (n, 6, 10).

        Taken with the model's friction and effects: friction growing with the gearbox load grows
        with the payload's share of it too, ``c sign(tau_load) sign(qd)`` times the payload's
        own torque (linear while the load keeps its sign, which the probes' 1 kg barely moves)."""
        if "payload" not in motion.memo:  # the fit, the bound and the drawing all need it
            robot = motion.robot
            without = robot.inverse_dynamics(motion.q, motion.qd, motion.qdd, t=motion.t)
            changes, probes = [], []
            for (mass, com, inertia), probe in zip(self.PROBES, self._probe_models(robot), strict=True):
                changes.append(probe.inverse_dynamics(motion.q, motion.qd, motion.qdd, t=motion.t) - without)
                probes.append(barycentric(mass, com, inertia))
            # changes[k] = Y @ probes[k] for every probe: solve for Y
            solved = np.linalg.solve(np.array(probes), np.stack(changes, axis=-1).reshape(-1, 10).T)
            motion.memo["payload"] = solved.T.reshape(*without.shape, 10)
        phi = motion.memo["payload"]
        return phi, np.zeros(phi.shape[:2])

    def _probe_models(self, robot) -> list:
        """The robot with each of :data:`PROBES` added, compiled once per robot object (an
        excitation design evaluates the regressors along thousands of motions of one robot)."""
        if robot not in _PROBE_MODELS:
            _PROBE_MODELS[robot] = [robot.edited(lambda spec, m=mass, c=com, i=inertia, k=k:
                                                 self._add_body(spec, robot, f"probe{k}", m, c, i))
                                    for k, (mass, com, inertia) in enumerate(self.PROBES)]
        return _PROBE_MODELS[robot]

    def params(self, motion, axis, theta, h):
        return _named(*from_barycentric(barycentric(*self._current_inertial(motion.robot)) + theta))

    def complete(self, motion, axis, theta, level):
        """At the mass level the current centre of mass and inertia are kept, at the centre-of-mass
        level the current inertia about the centre of mass: the flange inertia (and first
        moments) those imply, not zero (zero flange inertia would leave a centre of mass off the
        flange with a negative inertia about itself)."""
        if level >= len(theta):
            return theta
        current_mass, current_com, current_inertia = self._current_inertial(motion.robot)
        current = barycentric(current_mass, current_com, current_inertia)
        mass = float(current[0] + theta[0])
        if not mass > 0:
            return theta
        com = current_com if level < 4 else (current[1:4] + theta[1:4]) / mass
        return barycentric(mass, com, current_inertia) - current

    def admissible(self, motion, axis, params):
        """A payload adds mass; it is physically consistent (:func:`consistent`); and the drives can
        carry it along the motion: its torque stays within every motor's torque limit."""
        current = self._current_inertial(motion.robot)
        mass, com, inertia = _inertial(params)
        if not mass > current[0] or not consistent(mass, com, inertia):
            return False
        phi, _ = self.columns(motion, None, None)
        change = phi @ (barycentric(mass, com, inertia) - barycentric(*current))
        peak = np.max(np.abs(change), axis=0) / motion.robot.gear_ratio  # motor side, N m
        return bool(np.all(peak <= motion.robot.motor_torque_limit))

    def draw_direction(self, rng):
        """Hidden payloads of the own-simulator checks are point masses at the flange."""
        return np.eye(10)[0]

    def _current_inertial(self, robot) -> tuple[float, np.ndarray, np.ndarray]:
        return _inertial(self.current(robot).values())


def _inertial(values: dict[str, float]) -> tuple[float, np.ndarray, np.ndarray]:
    """``(mass, com (3,), inertia (6,))`` from the named parameters."""
    return (float(values["mass"]), np.array([values[k] for k in ("com_x", "com_y", "com_z")], dtype=float),
            np.array([values[k] for k in INERTIA], dtype=float))


def _named(mass: float, com: np.ndarray, inertia: np.ndarray) -> dict[str, float]:
    """The named parameters of ``(mass, com, inertia)``, inverse of :func:`_inertial`."""
    return {"mass": float(mass), **{k: float(v) for k, v in zip(("com_x", "com_y", "com_z"), com, strict=True)},
            **{k: float(v) for k, v in zip(INERTIA, inertia, strict=True)}}


def _rotation(quat) -> np.ndarray:
    matrix = np.zeros(9)
    mujoco.mju_quat2Mat(matrix, np.asarray(quat, dtype=float))
    return matrix.reshape(3, 3)
