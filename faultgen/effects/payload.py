"""An unmodelled payload: a point mass at the flange (tool or workpiece)."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from faultgen.effects.base import Effect, register


@register
class Payload(Effect):
    """A point mass ``mass`` (kg) at the ``flange`` site, robot-wide; MJCF: bodies ``payload{n}``
    at the flange, whose masses add up.

    Its torque is the rigid-body model's (the body is part of the MJCF, so the simulation and the
    inverse dynamics carry it); identified by the torque of a unit mass, which it is linear in:
    the inverse dynamics with and without a unit point mass at the flange, exactly what
    :meth:`apply` adds.
    """

    id = "payload"
    rank = 70
    summary = "an unmodelled payload (mass at the flange)"
    units: ClassVar[dict[str, str]] = {"mass": "kg"}
    absent = (0.0,)
    per_axis = False

    @classmethod
    def read(cls, model, path):
        masses = [float(model.body_mass[b]) for b in range(model.nbody) if model.body(b).name.startswith("payload")]
        return cls(mass=sum(masses))

    def columns(self, motion, axis, h):
        if "payload" not in motion.memo:  # the fit and the torque bound both need it
            robot = motion.robot
            unit = robot.edited(lambda spec: self.apply(spec, robot, None, {"mass": self.current(robot).mass + 1.0}))
            with_mass = unit.inverse_dynamics(motion.q, motion.qd, motion.qdd, friction=False)
            without = robot.inverse_dynamics(motion.q, motion.qd, motion.qdd, friction=False)
            motion.memo["payload"] = (with_mass - without)[:, :, None]
        phi = motion.memo["payload"]
        return phi, np.zeros(phi.shape[:2])

    def params(self, motion, axis, theta, h):
        return {"mass": float(self.current(motion.robot).mass + theta[0])}

    def admissible(self, motion, axis, params):
        """A payload adds mass, and no more than the drives can carry along the motion: the
        added mass's torque stays within every motor's torque limit."""
        added = params["mass"] - self.current(motion.robot).mass
        if added <= 0:
            return False
        phi, _ = self.columns(motion, None, None)
        peak = np.max(np.abs(phi[:, :, 0]), axis=0) * added / motion.robot.gear_ratio  # motor side, N m
        return bool(np.all(peak <= motion.robot.motor_torque_limit))

    def apply(self, spec, robot, axis, params):
        """Add a body ``payload{n}`` at the flange carrying the mass ``params["mass"]`` exceeds the
        robot's payload by (a point mass: MuJoCo needs a positive inertia, 1e-9 kg m^2 per kg
        changes no torque)."""
        flange = spec.site("flange")
        count = sum(1 for b in spec.bodies if b.name.startswith("payload"))
        # the compiled site position is in the link's frame (the MJCF may nest it in a <frame>)
        position = robot.model.site("flange").pos
        body = flange.parent.add_body(name=f"payload{count + 1}", pos=[float(v) for v in position])
        mass = max(float(params["mass"] - self.current(robot).mass), 0.0)
        body.mass = mass
        body.inertia = [1e-9 * max(mass, 1e-3)] * 3
        body.ipos = [0.0, 0.0, 0.0]
        body.explicitinertial = True
