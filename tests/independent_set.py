"""Calibration logs made by another simulator: roboticstoolbox-python's recursive Newton-Euler.

The test set of the calibration issue (docs/calibration.md, "Independent-simulator test set"): 28
logs, 14 per robot, of which 4 carry no effect. The "measured" torque is the toolbox's ``rne``
(its own code, and for the PUMA 560 its own parameters and friction: ``rtb.models.DH.Puma560``;
the IRB-6700-like arm as a ``DHRobot`` with the dynamics its README documents,
:mod:`toolbox_robots`) along a Fourier excitation (five harmonics of 0.1 Hz, random coefficients,
inside the middle 60 % of every joint range), with effects added in forms that differ from
faultgen's own (:class:`Hidden`):

* ``payload``: a solid box of random size and orientation whose centre of mass lies up to 0.15 m
  from the flange, added to the toolbox's last link (mass, centre of mass and inertia);
* ``coulomb_per_direction``: the Coulomb level of each direction changed by its own amount;
* ``stribeck_exponent``: a hump ``G f_s exp(-|v / v_s|^delta) sign(v)`` with ``delta`` in 1..2
  (faultgen's robots have the Gaussian, ``delta = 2``), ``f_s`` 0.5-0.8 of the Coulomb level and
  ``v_s`` 2-6 times the rest speed at the motor (``REST_SPEED`` G: a hump the log shows where the
  calibration fits, above the rest speed);
* ``load_gravity`` / ``load_total``: friction ``mu |load| sign(v)`` with the load the gravity torque
  (Bittencourt & Gunnarsson 2012) or the whole transmitted torque (Bittencourt, Wernholt,
  Sander-Tavallaey & Brogardh 2010), the load computed by the toolbox;
* ``warm_up``: the whole friction (Coulomb and viscous, as the toolbox has it) times
  ``1 + a exp(-t / T)``; faultgen's warm-up scales the dry friction only.

Sample rates 250-1000 Hz, 30-60 s, with or without velocity columns, 1 % torque noise (of each
axis's torque RMS) and 1e-5 rad encoder noise. Sizes, axes and the excitation are drawn from the
case's seed; which effect a case carries, at which rate and for how long is fixed in
:data:`CASES`, written before any case was run. The calibration gets the CSV and the robot name only.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np
import roboticstoolbox as rtb
import toolbox_robots

from faultgen.data import logfiles
from faultgen.effects import REST_SPEED
from faultgen.model import robots

#: What faultgen should name each hidden form (its effect ids).
NAMED_AS = {"payload": "payload", "coulomb_per_direction": "coulomb", "stribeck_exponent": "stribeck",
            "load_gravity": "load_dependent_friction", "load_total": "load_dependent_friction",
            "warm_up": "temperature"}
#: Largest joint speed of the excitation, rad/s, axes 1-3 and 4-6.
TOP_SPEED = {"puma560": (0.8, 1.5), "irb6700": (0.6, 1.2)}
#: Payload mass range, kg, and box edge range, m (PUMA 560 rated 2.5 kg, the IRB-6700-like 200 kg).
PAYLOAD = {"puma560": ((1.0, 3.0), (0.04, 0.15)), "irb6700": ((40.0, 160.0), (0.2, 0.6))}
#: Farthest centre of mass from the flange, m.
COM_REACH = 0.15
TORQUE_NOISE = 0.01
ENCODER_NOISE = 1e-5


@dataclass(frozen=True)
class Case:
    """One log: robot, hidden forms (empty: none), sample rate (Hz), duration (s), whether the
    CSV has velocity columns, seed of the draws."""

    name: str
    robot: str
    forms: tuple[str, ...]
    rate: float
    duration: float
    velocities: bool
    seed: int
    #: Share of each axis's half range the excitation spans (default 0.3 everywhere); a smaller one
    #: on the axes that carry gravity keeps their gravity load nearly constant (round 3 cases).
    range_share: tuple[float, ...] | None = None
    #: Fewest axes a per-axis form is hidden on (default 1; round 3: a multi-axis hump).
    min_axes: int = 1
    #: A designed excitation (:mod:`faultgen.calibrate.excitation`) instead of the random Fourier one.
    designed: bool = False


def _cases() -> list[Case]:
    plan = [  # forms, rate, duration, velocities
        ((), 250, 30, True),
        ((), 1000, 45, False),
        (("payload",), 500, 40, False),
        (("payload",), 250, 60, True),
        (("coulomb_per_direction",), 500, 40, True),
        (("coulomb_per_direction",), 1000, 30, False),
        (("stribeck_exponent",), 250, 40, False),
        (("stribeck_exponent",), 500, 60, True),
        (("load_gravity",), 500, 40, False),
        (("load_total",), 250, 50, True),
        (("warm_up",), 500, 60, False),
        (("payload", "stribeck_exponent"), 500, 40, True),
        (("coulomb_per_direction", "warm_up"), 1000, 45, False),
        (("load_total", "payload"), 250, 30, True),
    ]
    cases = []
    for robot_seed, robot in enumerate(("puma560", "irb6700")):
        for k, (forms, rate, duration, velocities) in enumerate(plan):
            label = "+".join(forms) or "none"
            cases.append(Case(f"{robot}-{k + 1:02d}-{label}", robot, forms, rate, duration, velocities,
                              seed=100 * robot_seed + k))
    # round 3 (issue 39), added after the 28 above: friction growing with a nearly constant gravity
    # load (the shoulder and elbow swing over 6 % of their half range around a pose where both
    # carry much of it: |gravity| changes by about 1 %, so the friction looks like a Coulomb level),
    # and a payload with a Stribeck hump on two or three axes
    narrow = (0.3, 0.06, 0.06, 0.3, 0.3, 0.3)
    for robot_seed, robot in enumerate(("puma560", "irb6700")):
        cases += [
            Case(f"{robot}-15-load_gravity-narrow", robot, ("load_gravity",), 500, 40, False,
                 seed=100 * robot_seed + 14, range_share=narrow),
            Case(f"{robot}-16-payload+stribeck_exponent-multi", robot, ("payload", "stribeck_exponent"), 500, 40,
                 True, seed=100 * robot_seed + 15, min_axes=2),
            Case(f"{robot}-17-load_gravity-narrow-designed", robot, ("load_gravity",), 500, 40, False,
                 seed=100 * robot_seed + 14, range_share=narrow, designed=True),
        ]
    return cases


CASES = _cases()


@dataclass
class Hidden:
    """What was added to a log: per form, the axes (0-based; all six for a payload) and values."""

    forms: dict = field(default_factory=dict)

    def named(self) -> list[tuple[str, list[int]]]:
        """The (effect id, axes) pairs faultgen should name, in the order of the case."""
        return [(NAMED_AS[form], sorted(p["axes"])) for form, p in self.forms.items()]


def excitation(robot: robots.Robot, rate: float, duration: float, rng: np.random.Generator,
               range_share: tuple[float, ...] | None = None, middle: np.ndarray | None = None):
    """Fourier excitation: t (n,), q, qd, qdd (n, 6), analytic derivatives.

    Per axis ``q0 + sum_l a_l sin(l w t) + b_l cos(l w t)``, w = 2 pi 0.1 rad/s, l = 1..5, with
    ``a_l, b_l ~ N(0, 1/l)``, scaled so the axis stays within 30 % (or ``range_share``, per axis) of
    its half range around the range's middle and its speed within :data:`TOP_SPEED`."""
    t = np.arange(0.0, duration, 1.0 / rate)
    w = 2 * np.pi * 0.1 * np.arange(1, 6)
    a, b = rng.normal(size=(2, 5, 6)) / np.arange(1, 6)[None, :, None]
    s, c = np.sin(np.outer(t, w)), np.cos(np.outer(t, w))
    shape = s @ a + c @ b
    speed = (c * w) @ a - (s * w) @ b
    accel = -(s * w**2) @ a - (c * w**2) @ b
    low, high = robot.joint_range[:, 0], robot.joint_range[:, 1]
    top = np.repeat(TOP_SPEED[robot.name], 3)
    share = np.full(6, 0.3) if range_share is None else np.asarray(range_share, dtype=float)
    scale = np.minimum(share * (high - low) / 2 / np.max(np.abs(shape), axis=0), top / np.max(np.abs(speed), axis=0))
    centre = (low + high) / 2 if middle is None else middle
    return t, centre + scale * shape, scale * speed, scale * accel


def heavy_pose(robot: robots.Robot, model: rtb.DHRobot) -> np.ndarray:
    """The middle of every joint range, with axes 2 and 3 where the smaller of their gravity
    torques (the toolbox's ``gravload``, relative to each axis's largest) is largest, on a 25 x 25
    grid over the middle 60 % of their ranges: a pose where both carry a large, steady gravity load."""
    low, high = robot.joint_range[:, 0], robot.joint_range[:, 1]
    middle = (low + high) / 2
    grid = [np.linspace(m - 0.3 * (h - lo), m + 0.3 * (h - lo), 25)
            for m, lo, h in zip(middle[1:3], low[1:3], high[1:3], strict=True)]
    poses = np.array([[*middle[:1], a, b, *middle[3:]] for a in grid[0] for b in grid[1]])
    load = np.abs(np.asarray(model.gravload(poses)))[:, 1:3]
    best = int(np.argmax(np.min(load / load.max(axis=0), axis=1)))
    return poses[best]


def toolbox(robot_name: str) -> rtb.DHRobot:
    """The toolbox's model of the robot (module docstring)."""
    return rtb.models.DH.Puma560() if robot_name == "puma560" else toolbox_robots.irb6700()


def flange_in_last_link(robot: robots.Robot, model: rtb.DHRobot) -> tuple[np.ndarray, np.ndarray]:
    """Rotation (3, 3) and origin (3,) of faultgen's flange frame (the ``flange`` site) in the
    toolbox's last link frame, taken at zero joint angles (a fixed transform)."""
    data = mujoco.MjData(robot.model)
    data.qpos[:], _ = robot.rigid_state(np.zeros(6))
    mujoco.mj_kinematics(robot.model, data)
    site = robot.model.site("flange").id
    last = model.fkine(np.zeros(6))
    R_last = last.R
    return R_last.T @ data.site_xmat[site].reshape(3, 3), R_last.T @ (data.site_xpos[site] - last.t)


def add_payload(robot: robots.Robot, model: rtb.DHRobot, mass: float, com: np.ndarray, inertia: np.ndarray) -> None:
    """Lump a rigid body (mass kg; centre of mass, m, and inertia at it, kg m^2, in the flange
    frame) into the toolbox's last link (parallel-axis theorem)."""
    R, origin = flange_in_last_link(robot, model)
    link = model.links[-1]
    r_body, I_body = origin + R @ com, R @ inertia @ R.T
    total = link.m + mass
    centre = (link.m * np.asarray(link.r) + mass * r_body) / total

    def shifted(d):
        return np.dot(d, d) * np.eye(3) - np.outer(d, d)

    link.I = np.asarray(link.I) + link.m * shifted(np.asarray(link.r) - centre) + I_body + mass * shifted(r_body - centre)
    link.m, link.r = total, centre


def draw_payload(robot_name: str, rng: np.random.Generator) -> dict:
    """Mass (kg), centre of mass (m, flange frame, at most :data:`COM_REACH` from the flange) and
    inertia at it (kg m^2, flange axes) of a solid box of random edges and orientation."""
    (m_low, m_high), (e_low, e_high) = PAYLOAD[robot_name]
    mass = rng.uniform(m_low, m_high)
    direction = rng.normal(size=3)
    com = direction / np.linalg.norm(direction) * rng.uniform(0.05, COM_REACH)
    com[2] = abs(com[2])  # the load sits in front of the flange
    edges = rng.uniform(e_low, e_high, 3)
    principal = mass / 12 * np.array([edges[1] ** 2 + edges[2] ** 2, edges[0] ** 2 + edges[2] ** 2,
                                      edges[0] ** 2 + edges[1] ** 2])
    rotation, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return {"axes": list(range(6)), "mass": mass, "com": com, "inertia": rotation @ np.diag(principal) @ rotation.T}


def _axes(rng: np.random.Generator, pool: list[int], most: int, least: int = 1) -> list[int]:
    return sorted(rng.choice(pool, size=rng.integers(least, most + 1), replace=False).tolist())


def designed_excitation(robot: robots.Robot, rate: float, duration: float):
    """The excitation :func:`faultgen.calibrate.excitation.design` makes for ``robot``, repeated over
    ``duration`` and sampled at ``rate``: t (n,), q, qd, qdd (n, 6), analytic derivatives."""
    from faultgen.calibrate import excitation as designed

    trajectory = designed.design(robot)
    t = np.arange(0.0, duration, 1.0 / rate)
    return (t, *trajectory.sample(t))


def make(case: Case, folder: str | Path) -> tuple[Path, Hidden]:
    """Write the case's log under ``folder``; returns its path and what was hidden in it."""
    robot = robots.load(case.robot)
    rng = np.random.default_rng(case.seed)
    model = toolbox(case.robot)
    middle = heavy_pose(robot, model) if case.range_share is not None else None
    t, q, qd, qdd = excitation(robot, case.rate, case.duration, rng, case.range_share, middle)
    if case.designed:  # the draws above keep the effect's sizes and axes those of the undesigned twin
        t, q, qd, qdd = designed_excitation(robot, case.rate, case.duration)
    G = robot.gear_ratio
    coulomb = np.array([link.Tc[0] - link.Tc[1] for link in model.links]) / 2  # mean level, motor side
    hidden = Hidden()
    if "payload" in case.forms:
        p = hidden.forms["payload"] = draw_payload(case.robot, rng)
        add_payload(robot, model, p["mass"], p["com"], p["inertia"])
    tau = np.asarray(model.rne(q, qd, qdd))
    rigid = np.asarray(model.nofriction(coulomb=True, viscous=True).rne(q, qd, qdd))
    if case.robot == "irb6700":  # the balancing spring and the README's static friction excess
        tau += toolbox_robots.irb6700_balance_torque(q)
        rigid += toolbox_robots.irb6700_balance_torque(q)
        f = robot.friction
        tau += G * f.static * np.exp(-np.abs(G * qd / f.stribeck_velocity) ** f.stribeck_exponent) * np.sign(qd)
    friction = tau - rigid
    v, direction = G * qd, np.sign(qd)
    for form in case.forms:
        if form == "coulomb_per_direction":
            axes = _axes(rng, list(range(6)), 2)
            up, down = rng.uniform(0.3, 0.6, len(axes)), rng.uniform(-0.1, 0.1, len(axes))
            hidden.forms[form] = {"axes": axes, "rise_pos": up * coulomb[axes], "rise_neg": down * coulomb[axes]}
            tau[:, axes] += G[axes] * coulomb[axes] * np.where(qd[:, axes] > 0, up, -down)
        elif form == "stribeck_exponent":
            axes = _axes(rng, [0, 1, 2], 3, case.min_axes)
            static = rng.uniform(0.5, 0.8, len(axes)) * coulomb[axes]
            velocity = rng.uniform(2, 6, len(axes)) * REST_SPEED * G[axes]  # shows above the rest speed
            exponent = rng.uniform(1.0, 2.0, len(axes))
            hidden.forms[form] = {"axes": axes, "static": static, "stribeck_velocity": velocity, "exponent": exponent}
            tau[:, axes] += G[axes] * static * np.exp(-np.abs(v[:, axes] / velocity) ** exponent) * direction[:, axes]
        elif form in ("load_gravity", "load_total"):
            axes = _axes(rng, [1, 2], 2)
            if form == "load_gravity":  # gravity and, on the IRB, the balancing spring
                load = np.asarray(model.gravload(q))
                if case.robot == "irb6700":
                    load = load + toolbox_robots.irb6700_balance_torque(q)
            else:  # the transmitted torque: the rigid-body torque (spring included), motor inertia left out
                load = rigid - G**2 * np.array([link.Jm for link in model.links]) * qdd
            # a coefficient that makes the added friction 20-40 % of the axis's Coulomb level (RMS)
            size = rng.uniform(0.2, 0.4, len(axes)) * G[axes] * coulomb[axes]
            mu = size / np.sqrt(np.mean(load[:, axes] ** 2, axis=0))
            hidden.forms[form] = {"axes": axes, "coefficient": mu}
            tau[:, axes] += mu * np.abs(load[:, axes]) * direction[:, axes]
        elif form == "warm_up":
            axes = _axes(rng, list(range(6)), 3)
            amplitude = rng.uniform(0.3, 0.6, len(axes))
            time_constant = rng.uniform(0.3, 0.6) * case.duration
            hidden.forms[form] = {"axes": axes, "amplitude": amplitude, "time_constant": time_constant}
            tau[:, axes] += friction[:, axes] * amplitude * np.exp(-t / time_constant)[:, None]
    tau += rng.normal(size=tau.shape) * TORQUE_NOISE * np.sqrt(np.mean(tau**2, axis=0))
    q_logged = q + rng.normal(size=q.shape) * ENCODER_NOISE
    path = Path(folder) / f"{case.name}.csv"
    logfiles.write_csv(path, t, q_logged, tau, qd=qd if case.velocities else None)
    return path, hidden


def judge(hidden: Hidden, result) -> dict:
    """Did the calibration name the hidden effects first, on their axes (any order), and halve
    the held-out gap; for a payload, its mass error (relative) and centre-of-mass error (m)."""
    want = sorted(hidden.named())
    got = [(step.effect.id, list(step.axes)) for step in result.steps]
    named = sorted(got[: len(want)]) == want and (bool(want) or not got)
    before, after = result.gap_before["total_nrmse"], result.gap_after["total_nrmse"]
    # round 3: a step the log cannot separate from another lists both; the truth among them counts
    tied = [sorted({step.effect.id, *step.evidence.get("ambiguous_with", [])}) for step in result.steps]
    first = list(zip(got, tied, strict=True))[: len(want)]

    def covered(effect, on):
        return any(on == axes and (effect == name or effect in names) for (name, axes), names in first)

    verdict = {"named": named, "halved": after <= 0.5 * before if want else None, "before": before,
               "after": after, "found": got, "hidden": want,
               "ambiguous": [f"{'/'.join(names)} {[a + 1 for a in axes]}" for (_, axes), names in zip(got, tied,
                                                                                                    strict=True)
                             if len(names) > 1],
               "named_or_ambiguous": named or (len(first) == len(want) and all(covered(e, on) for e, on in want)),
               # every hidden effect on all its axes, in any step (named, or among a step's inseparable candidates)
               "all_axes": all(any((name == e or e in names) and set(on) <= set(axes)
                                   for (name, axes), names in zip(got, tied, strict=True)) for e, on in want)}
    if "payload" in hidden.forms:
        p = hidden.forms["payload"]
        step = next((s for s in result.steps if s.effect.id == "payload"), None)
        if step is not None:
            com = np.array([step.effect.com_x, step.effect.com_y, step.effect.com_z], dtype=float)
            verdict["mass_error"] = abs(float(step.effect.mass) / p["mass"] - 1)
            verdict["com_error"] = float(np.linalg.norm(com - p["com"]))
    return verdict
