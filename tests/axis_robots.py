"""Robots of five and seven axes that follow faultgen's MJCF naming, made from the PUMA 560 with
``mujoco.MjSpec`` for the tests of the axis count (the arms ``faultgen robots add`` builds from
URDFs replace them in the end-to-end checks).

- ``puma5``: the PUMA 560 without its last axis: joint 6 removed (link 6 rides on link 5), with
  rotor 6, gearbox 6, motor 6 and friction 6.
- ``puma7``: the PUMA 560 with a seventh wrist axis after joint 6: a link of 0.2 kg on a joint
  about the flange's x axis, its rotor, gearbox tendon, motor and friction numerics copied from
  axis 6's (gear ratio, rotor inertia, stiffness, damping, torque limit), the flange moved onto it.

``puma6`` is the PUMA 560 written the same way (``MjSpec.to_xml`` keeps 6 significant digits), the
reference of the other two. Each folder holds ``<name>.xml`` and a ``tasks.toml`` with a pick and place only (a minimal task:
the start and two waypoints of the PUMA 560's, axis 7 swinging +-60 deg).
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from faultgen.model import robots

#: tasks.toml limits and pick-and-place angles of the PUMA 560 (its own file), per axis 1..7.
_VELOCITY = [100, 95, 100, 150, 130, 110, 110]
_ACCELERATION = [300, 300, 300, 600, 500, 450, 450]
_JERK = [3000, 3000, 3000, 6000, 5000, 4500, 4500]
_START = [0, 92, -122, 30, 0, 0, 0]
_PICK = [-95, 15, -200, -50, -60, -160, -60]
_PLACE = [95, 170, -45, 115, 60, 160, 60]


def _drop_last_axis(spec: mujoco.MjSpec) -> None:
    # what refers to a joint first; each element looked up just before it goes
    for kind, name in (("actuator", "motor6"), ("tendon", "gearbox6"), ("numeric", "friction6"), ("joint", "joint6"),
                       ("body", "rotor6")):
        spec.delete(getattr(spec, kind)(name))


def _add_wrist_axis(spec: mujoco.MjSpec) -> None:
    link6 = spec.body("link6")
    spec.delete(spec.site("flange"))
    rotor = link6.add_body(name="rotor7", mass=1e-9, inertia=[1e-12] * 3, ipos=[0, 0, 0], iquat=[1, 0, 0, 0],
                           explicitinertial=True)  # to_xml writes an inertial only with ipos set
    rotor.add_joint(name="rotor7", default=spec.find_default("rotor"), armature=spec.joint("rotor6").armature)
    link = link6.add_body(name="link7", pos=[0, 0, 0.05])
    link.add_joint(name="joint7", default=spec.find_default("arm"), axis=[1, 0, 0],
                   range=[-np.pi / 2, np.pi / 2])
    link.mass, link.ipos, link.inertia, link.explicitinertial = 0.2, [0, 0, 0.03], [2e-4, 2e-4, 1e-4], True
    link.add_site(name="flange", pos=[0, 0, 0.06])
    six = spec.tendon("gearbox6")
    tendon = spec.add_tendon(name="gearbox7", stiffness=six.stiffness, damping=six.damping, springlength=[0, 0])
    tendon.wrap_joint("rotor7", 1.0 / robots.load("puma560").gear_ratio[5])
    tendon.wrap_joint("joint7", -1.0)
    motor = spec.actuator("motor6")
    spec.add_actuator(name="motor7", target="rotor7", trntype=mujoco.mjtTrn.mjTRN_JOINT,
                      ctrlrange=motor.ctrlrange, ctrllimited=motor.ctrllimited, gear=motor.gear)
    spec.add_numeric(name="friction7", data=list(spec.numeric("friction6").data))


def _home(spec: mujoco.MjSpec, q: np.ndarray, G: np.ndarray) -> None:
    """The ``home`` keyframe at arm angles ``q`` with the rotors at ``G q``."""
    model = spec.compile()
    qpos = np.zeros(model.nq)
    for k in range(len(q)):
        qpos[model.joint(f"joint{k + 1}").qposadr[0]] = q[k]
        qpos[model.joint(f"rotor{k + 1}").qposadr[0]] = G[k] * q[k]
    spec.add_key(name="home", qpos=qpos.tolist())


def make(folder: str | Path, n_axes: int) -> Path:
    """Write ``puma5`` (``n_axes`` 5) or ``puma7`` (7) into ``folder/puma{n}/``; the MJCF's path.
    ``puma6`` is the PUMA 560 itself written by ``MjSpec.to_xml`` (which rounds numbers to 6
    digits), the reference the others are compared with."""
    puma = robots.load("puma560")
    spec = mujoco.MjSpec.from_file(str(puma.path))
    for key in list(spec.keys):  # its qpos no longer fits; made again below
        spec.delete(key)
    if n_axes == 5:
        _drop_last_axis(spec)
        G = puma.gear_ratio[:5]
    elif n_axes == 7:
        _add_wrist_axis(spec)
        G = np.append(puma.gear_ratio, puma.gear_ratio[5])
    elif n_axes == 6:  # the PUMA 560 as MjSpec writes it, the reference of the others
        G = puma.gear_ratio
    else:
        raise ValueError(f"n_axes = {n_axes}: this fixture makes 5, 6 or 7 axes")
    _home(spec, np.append(puma.home, 0.0)[:n_axes], G)
    target = Path(folder) / f"puma{n_axes}"
    target.mkdir(parents=True, exist_ok=True)
    path = target / f"puma{n_axes}.xml"
    path.write_text(spec.to_xml())

    def row(values):
        return "[" + ", ".join(str(v) for v in values[:n_axes]) + "]"

    (target / "tasks.toml").write_text(
        f"# Minimal tasks of the {n_axes}-axis test arm (tests/axis_robots.py)\n[limits]\n"
        f"velocity = {row(_VELOCITY)}\nacceleration = {row(_ACCELERATION)}\njerk = {row(_JERK)}\n\n"
        f'[pick_place]\nprocess = "point-to-point"\nstart = {row(_START)}\nvelocity_scale = 1.0\n'
        f'acceleration_scale = 1.0\nsegment = [\n    {{type = "move", to = {row(_PICK)}}},\n'
        f'    {{type = "dwell", time = 0.5}},\n    {{type = "move", to = {row(_PLACE)}}},\n'
        f'    {{type = "dwell", time = 0.5}},\n    {{type = "move", to = {row(_START)}}},\n]\n')
    return path
