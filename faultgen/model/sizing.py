"""Size a drivetrain from an arm's own data where ``drivetrain.toml`` is silent.

Each number of a :class:`~faultgen.model.drivetrain.AxisDrive` the user does not give is sized by
one rule (:data:`RULES`; docs/robots.md, "Your own robot", gives each rule, its numbers and their
sources). The rules are those the IRB-6700-like robot was designed with (robots/irb6700/README.md),
written as formulas of the arm's joint speed and torque limits and link masses, with the motor
inertia law fitted through the PUMA 560's measured motors:

- gear ratio ``G = 470 rad/s / qd_max`` (top motor speed about 4500 rpm);
- arm-side peak torque ``tau_peak``: the source's effort limit, else the torque to hold and
  accelerate the rated load along the planning limits with the arm's own: over 256 poses, every
  axis at its speed limit and its acceleration limit at once (directions drawn),
  ``need_i = max |tau_i(q, qd, qdd)|`` (rigid body, rated load: :func:`rated_load`, a cube of the
  rated payload with its centre of mass :func:`load_offset` out along the flange site's z axis;
  acceleration: the speed limit reached in 0.45 s, main axes, or 0.3 s, wrist: the generated tasks'
  ``[limits]``);
- motor torque limit ``T = 1.1 (need / G + Jm(T) G a + friction(T) at top speed)`` (the motor also
  accelerates its own rotor and overcomes its friction; solved by fixed point), at least 0.27 N m
  (unless the source gives the effort limit, then ``T = effort / G``);
- motor inertia ``Jm = 1.2e-4 kg m^2 (T_max / 1 N m)^1.05``;
- gearbox stiffness ``K = (2 pi f)^2 G^2 Jm``, f = 10 Hz (main axes) or 25 Hz (wrist axes), damping
  ``D = 0.2 sqrt(K G^2 Jm)`` (damping ratio 0.1);
- Coulomb friction 3 % of the motor torque limit in both directions, static excess 30 % of it,
  Stribeck velocity 10 rad/s, exponent 2, viscous ``Coulomb / 400 rad/s``, bristle stiffness
  ``Coulomb / 0.1 rad``, bristle damping 0.

These are sizing rule 2 (:data:`RULE`, the default). The rules are versioned (:data:`RULE_VERSIONS`),
so that a robot folder made with an earlier rule can be made again bit for bit (the benchmark's
frozen track versions add their third-party robots with the rule they were frozen with,
:mod:`faultgen.bench.tracks`): rule 1, faultgen's rule before the rated load sized the drives, differs
only in the arm-side peak torque where the source gives no effort limit:
``1.5 max_q |g_i(q)| + max_q M_ii(q) qd_max / 0.5 s`` (gravity with the rated payload as a solid
sphere of 1000 kg/m^3 one radius out along the last joint's axis from its origin, over 256 poses,
plus reaching top speed in half a second; :func:`arm_loads_rule1`), and motor torque limit
``tau_peak / G``, at least 0.27 N m. The robot folder records the rule that sized it
(``drivetrain.toml``'s header and README.md: :func:`faultgen.model.folder.sizing_rule`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from faultgen.effects.friction import FIELDS as FRICTION_FIELDS
from faultgen.model import builder
from faultgen.model.drivetrain import KEYS, Drivetrain

#: Top motor speed, rad/s (about 4500 rpm): G = this / joint speed limit.
MOTOR_SPEED = 470.0
#: Joint speed limit assumed where the source gives none, rad/s: main axes, wrist axes.
DEFAULT_SPEED = (2.0, 4.0)
#: Margin of the motor torque limit over the torque the rated load needs (the rest for the
#: controller's feedback and what 256 sampled states miss): chosen. The need is already the worst
#: sampled state with every axis at full speed and full acceleration at once, which a synchronised
#: point-to-point motion reaches only where it brakes from full speed; the generated tasks then use
#: about half of the capacity (the IRB-6700-like arm's tasks: within 70 %).
MARGIN = 1.1
#: Time to reach the joint speed limit, s (main axes, wrist axes): the planning limits the generated
#: tasks use (faultgen.operation.taskgen.RAMP, the IRB-6700-like arm's choices).
RAMP = (0.45, 0.3)
#: Distance of the rated load's centre of mass from the flange, m: ``LOAD_OFFSET_REF x (payload /
#: 10 kg)^(1/3)`` within LOAD_OFFSET_BOUNDS (a load of one density grows as the cube root of its
#: mass). Load diagrams rate the payload at 0.1 m (small arms: ABB IRB 120, 3 kg; KUKA KR AGILUS,
#: 6-10 kg) to 0.2-0.3 m (ABB IRB 4600-60: 60 kg at 0.2 m; KUKA KR QUANTEC, 120-300 kg: 0.24-0.27 m).
LOAD_OFFSET_REF, LOAD_OFFSET_BOUNDS = 0.1, (0.1, 0.3)
#: Poses sampled for the gravity and inertia maxima, and their seed.
POSES, SEED = 256, 0
#: Smallest motor torque limit the peak-torque rule gives, N m (the PUMA 560's wrist motors, 0.27-0.31
#: N m: light wrists would otherwise get motors no catalogue sells).
MIN_MOTOR_TORQUE = 0.27
#: Motor inertia law Jm = JM_SCALE * T_max ** JM_EXPONENT (kg m^2, T_max in N m).
JM_SCALE, JM_EXPONENT = 1.2e-4, 1.05
#: Locked-arm motor resonance, Hz: main axes, wrist axes; damping ratio of that mode.
RESONANCE, DAMPING_RATIO = (10.0, 25.0), 0.1
#: Friction as shares: Coulomb of the motor torque limit, static excess of Coulomb.
COULOMB_SHARE, STATIC_SHARE = 0.03, 0.30
STRIBECK_VELOCITY, STRIBECK_EXPONENT = 10.0, 2.0
#: Viscous friction = Coulomb / this speed (rad/s); presliding deflection (rad) of the bristles.
VISCOUS_SPEED, PRESLIDING = 400.0, 0.1
#: Payload share of the moving mass when the rated payload is unknown (a guess, said as one).
PAYLOAD_SHARE = 0.15

#: The sizing rules by number, as a robot folder records them; :data:`RULE` is the default.
RULE_VERSIONS = {
    1: "the peak-torque rule before issue 60 (1.5 x max gravity torque with the rated payload as a sphere at the "
    "last joint + max M_ii x speed limit / 0.5 s)",
    2: "the rated load held and accelerated along the planning limits (load diagram's offset, rotor inertia and "
    "motor friction included)",
}
RULE = 2
#: Rule 1's gravity margin and time to reach top speed, s (its peak-torque rule), and the density of
#: its rated payload, kg/m^3 (a solid sphere one radius out along the last axis).
GRAVITY_MARGIN, RAMP_TIME, PAYLOAD_DENSITY = 1.5, 0.5, 1000.0

#: The rule of each key, as the robot's README names it.
RULES = {
    "gear_ratio": f"G = {MOTOR_SPEED:g} rad/s / joint speed limit",
    "motor_torque_limit": f"effort limit / G, else {MARGIN:g} x (torque to hold and accelerate the rated "
    "load along the planning limits / G + rotor acceleration + motor friction)",
    "motor_inertia": f"Jm = {JM_SCALE:g} kg m^2 x (motor torque limit / N m)^{JM_EXPONENT:g}",
    "gearbox_stiffness": f"K = (2 pi f)^2 G^2 Jm, f = {RESONANCE[0]:g} Hz main / {RESONANCE[1]:g} Hz "
    "wrist axes",
    "gearbox_damping": f"D = 2 x {DAMPING_RATIO:g} x sqrt(K G^2 Jm)",
    "coulomb_pos": f"{COULOMB_SHARE:.0%} of the motor torque limit",
    "coulomb_neg": f"{COULOMB_SHARE:.0%} of the motor torque limit",
    "static": f"{STATIC_SHARE:.0%} of Coulomb",
    "stribeck_velocity": f"{STRIBECK_VELOCITY:g} rad/s at the motor",
    "stribeck_exponent": f"{STRIBECK_EXPONENT:g} (Gaussian Stribeck curve)",
    FRICTION_FIELDS[5]: f"Coulomb / {VISCOUS_SPEED:g} rad/s",  # viscous (a name the effects own)
    "bristle_stiffness": f"Coulomb / {PRESLIDING:g} rad presliding deflection",
    "bristle_damping": "0 (docs/simulation.md, 'Numerical convergence')",
}
#: Rule 1's rules, as its robots' READMEs name them (its motor torque limit's differs).
RULES_1 = {
    **RULES,
    "motor_torque_limit": f"arm-side peak torque / G; peak = effort limit, else {GRAVITY_MARGIN:g} x max "
    f"gravity torque (rated payload) + max M_ii x speed limit / {RAMP_TIME:g} s",
}


def main_axes(n_axes: int) -> int:
    """How many axes from the base count as main (arm) axes; the rest are wrist axes."""
    return max(3, n_axes - 3)


def output_peak(drive, axis: int, n_axes: int) -> float:
    """The peak torque the gear output of axis ``axis`` (1-based, of ``n_axes``) carries, N m, as the
    sizing rule set its motor (:func:`motor_torque` read backwards): ``G (T / MARGIN - Jm G a - (Fc +
    Fv G qd_max))`` with ``qd_max = MOTOR_SPEED / G`` and ``a = qd_max / RAMP`` (main or wrist axes):
    the rated load held and accelerated along the planning limits, without the rotor's acceleration
    and the motor's friction (motor side, not through the gear). ``drive`` an
    :class:`~faultgen.model.drivetrain.AxisDrive`; at least 0."""
    G = drive.gear_ratio
    speed = MOTOR_SPEED / G
    acceleration = speed / (RAMP[0] if axis <= main_axes(n_axes) else RAMP[1])
    motor_side = drive.motor_torque_limit / MARGIN - drive.motor_inertia * G * acceleration \
        - (drive.coulomb_pos + drive.viscous * G * speed)
    return max(float(G * motor_side), 0.0)


def load_offset(payload: float) -> float:
    """Distance of the rated load's centre of mass from the flange, m, for a payload of ``payload``
    kg (:data:`LOAD_OFFSET_REF`, :data:`LOAD_OFFSET_BOUNDS`: load diagrams' rating point)."""
    low, high = LOAD_OFFSET_BOUNDS
    return float(min(high, max(low, LOAD_OFFSET_REF * (max(payload, 0.0) / 10.0) ** (1 / 3))))


def rated_load(payload: float) -> dict[str, float]:
    """The rated load the drives are sized for, as :meth:`faultgen.operation.conditions.Payloads.
    parameters` gives a part: a uniform cube of ``payload`` kg and edge ``2 d`` hanging from the
    flange, its centre of mass ``d`` = :func:`load_offset` out along the flange's z axis, inertia
    ``m (2 d)^2 / 6`` about each axis. ``Payloads((m,), (2 d,))`` is a part of exactly this load."""
    d = load_offset(payload)
    moment = payload * (2 * d) ** 2 / 6
    return {"mass": float(payload), "com_x": 0.0, "com_y": 0.0, "com_z": d, "edge": 2 * d,
            "ixx": moment, "iyy": moment, "izz": moment}


@dataclass(frozen=True)
class Loads:
    """What the arm with its rated load needs per axis (arm side, rigid body, no drivetrain), shape (N,).

    Attributes
    ----------
    gravity : ndarray
        Largest gravity torque over the poses, N m.
    need : ndarray
        Largest rigid-body torque over the poses with every axis at its speed and acceleration limits
        at once (directions drawn): the torque to hold and accelerate the rated load along the
        planning limits, N m.
    speed, acceleration : ndarray
        The planning limits used, rad/s and rad/s^2.
    payload, offset : float
        The rated payload, kg, and its centre of mass's distance from the flange, m.
    """

    gravity: np.ndarray
    need: np.ndarray
    speed: np.ndarray
    acceleration: np.ndarray
    payload: float
    offset: float


def _pose_sampling(model: mujoco.MjModel, joints: list) -> tuple:
    """What both rules' load sampling starts from (constraints off in ``model``): its ``MjData``, the
    generator (seed :data:`SEED`), the joints' dof and qpos addresses, shape (N,), and their lower and
    upper limits, rad (or m), shape (N,)."""
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    dofs = np.array([model.joint(j.name).dofadr[0] for j in joints])
    qadr = np.array([model.joint(j.name).qposadr[0] for j in joints])
    low, high = np.array([j.range for j in joints]).T
    return mujoco.MjData(model), np.random.default_rng(SEED), dofs, qadr, low, high


def arm_loads_rule1(spec: mujoco.MjSpec, joints: list, payload: float) -> tuple[np.ndarray, np.ndarray]:
    """Rule 1's loads: largest gravity torque (rated payload at the last link's origin) and largest
    diagonal of the joint-space inertia over :data:`POSES` poses within the limits, N m and kg m^2,
    shape (N,). Kept as faultgen computed them before rule 2 (bit for bit)."""
    spec = spec.copy()
    last = spec.body(joints[-1].body)
    model = spec.copy().compile()
    if payload > 0:
        # a solid sphere of water's density, its centre one radius out along the last axis
        radius = (3 * payload / (4 * math.pi * PAYLOAD_DENSITY)) ** (1 / 3)
        axis = model.jnt_axis[model.joint(joints[-1].name).id]
        load = last.add_body(
            name="__payload", pos=(model.jnt_pos[model.joint(joints[-1].name).id] + radius * axis).tolist()
        )
        load.explicitinertial = True
        load.mass, load.inertia = payload, [0.4 * payload * radius**2] * 3
    model = spec.compile()
    data, rng, dofs, qadr, low, high = _pose_sampling(model, joints)
    gravity, inertia = np.zeros(len(joints)), np.zeros(len(joints))
    full = np.zeros((model.nv, model.nv))
    for _ in range(POSES):
        data.qpos[:] = 0
        data.qpos[qadr] = rng.uniform(low, high)
        data.qvel[:], data.qacc[:] = 0, 0
        mujoco.mj_inverse(model, data)
        gravity = np.maximum(gravity, np.abs(data.qfrc_inverse[dofs]))
        mujoco.mj_fullM(model, data, full)
        inertia = np.maximum(inertia, np.diag(full)[dofs])
    return gravity, inertia


def with_rated_load(spec: mujoco.MjSpec, joints: list, payload: float) -> mujoco.MjSpec:
    """A copy of the arm ``spec`` carrying :func:`rated_load` at its flange: the ``flange`` site the
    builder places (:func:`faultgen.model.builder._add_flange`, or the arm's own), the load's body
    in that site's frame."""
    spec = spec.copy()
    if not any(site.name == "flange" for site in spec.sites):
        builder._add_flange(spec, joints[-1].body)
    if payload <= 0:
        return spec
    site = next(s for s in spec.sites if s.name == "flange")
    load = rated_load(payload)
    body = site.parent.add_body(name="__rated_load", pos=site.pos.tolist(), quat=site.quat.tolist())
    body.explicitinertial = True
    body.mass, body.ipos = load["mass"], [0.0, 0.0, load["com_z"]]
    body.inertia = [load["ixx"], load["iyy"], load["izz"]]
    return spec


def planning_limits(arm) -> tuple[np.ndarray, np.ndarray]:
    """Joint speed limits (the source's, else :data:`DEFAULT_SPEED`) and accelerations (speed reached
    in :data:`RAMP`) of ``arm``, rad/s and rad/s^2: the generated tasks' ``[limits]``."""
    n = len(arm.joints)
    wrist = np.arange(n) >= main_axes(n)
    speed = np.asarray(arm.speed_limit, dtype=float)
    speed = np.where(np.isnan(speed), np.where(wrist, DEFAULT_SPEED[1], DEFAULT_SPEED[0]), speed)
    return speed, speed / np.where(wrist, RAMP[1], RAMP[0])


def arm_loads(arm, payload: float) -> Loads:
    """:class:`Loads` of ``arm`` (:class:`faultgen.model.importers.Arm`) with a rated load of
    ``payload`` kg, over :data:`POSES` poses within the joint limits (seed :data:`SEED`)."""
    joints = arm.joints
    speed, acceleration = planning_limits(arm)
    model = with_rated_load(arm.spec, joints, payload).compile()
    data, rng, dofs, qadr, low, high = _pose_sampling(model, joints)
    gravity, need = np.zeros(len(joints)), np.zeros(len(joints))
    for _ in range(POSES):
        data.qpos[:], data.qvel[:], data.qacc[:] = 0, 0, 0
        data.qpos[qadr] = rng.uniform(low, high)
        mujoco.mj_inverse(model, data)
        g = data.qfrc_inverse[dofs].copy()
        data.qvel[dofs] = speed * rng.choice([-1.0, 1.0], len(joints))
        data.qacc[dofs] = acceleration * rng.choice([-1.0, 1.0], len(joints))
        mujoco.mj_inverse(model, data)  # at full speed and full acceleration, directions drawn
        gravity = np.maximum(gravity, np.abs(g))
        need = np.maximum(need, np.abs(data.qfrc_inverse[dofs]))
    return Loads(gravity, need, speed, acceleration, float(payload), load_offset(payload))


def motor_torque(need: float, G: float, speed: float, acceleration: float, motor_inertia: float | None = None,
                 coulomb: float | None = None, viscous: float | None = None) -> float:
    """Motor torque limit, N m, of the rule: ``MARGIN x (need / G + Jm G a + friction at G x speed)``,
    with Jm, Coulomb and viscous friction of the rules (they grow with the limit; solved by fixed
    point) unless given."""
    torque = MARGIN * need / G
    for _ in range(100):
        jm = JM_SCALE * torque**JM_EXPONENT if motor_inertia is None else motor_inertia
        c = COULOMB_SHARE * torque if coulomb is None else coulomb
        v = c / VISCOUS_SPEED if viscous is None else viscous
        new = MARGIN * (need / G + jm * G * acceleration + c + v * G * speed)
        if abs(new - torque) <= 1e-12 * max(new, 1e-300):
            return float(new)
        torque = new
    return float(torque)


def moving_mass(spec: mujoco.MjSpec, joints: list) -> float:
    """Mass of the links the first joint moves, kg."""
    model = spec.copy().compile()
    return float(model.body_subtreemass[model.jnt_bodyid[model.joint(joints[0].name).id]])


def size(
    arm, given: dict[int, dict[str, float]] | None = None, payload: float | None = None, rule: int = RULE
) -> tuple[Drivetrain, dict[int, dict[str, str]], float]:
    """:func:`sized`'s drivetrain, provenance and rated payload (kg)."""
    out = sized(arm, given, payload, rule)
    return out.drivetrain, out.origin, out.payload


@dataclass(frozen=True)
class Sized:
    """What :func:`sized` gives: the drivetrain, ``origin[axis][key]`` (``"given"`` or ``"sized:
    <rule>"``), the rated payload used (kg), the :class:`Loads` the rules used (None under rule 1,
    which sizes from gravity and inertia alone), the arm's moving mass (kg) and the sizing rule
    (:data:`RULE_VERSIONS`)."""

    drivetrain: Drivetrain
    origin: dict
    payload: float
    loads: Loads | None
    moving_mass: float
    rule: int = RULE


def check_rule(rule) -> int:
    """``rule`` if it is a sizing rule's number (:data:`RULE_VERSIONS`).

    Raises
    ------
    ValueError
        Naming the rules there are.
    """
    if isinstance(rule, bool) or not isinstance(rule, int) or rule not in RULE_VERSIONS:
        raise ValueError(f"sizing rule {rule!r}: expected one of {', '.join(map(str, RULE_VERSIONS))}")
    return rule


def sized(arm, given: dict[int, dict[str, float]] | None = None, payload: float | None = None,
          rule: int = RULE) -> Sized:
    """A full drivetrain for ``arm`` (:class:`faultgen.model.importers.Arm`): the values ``given``
    (``{axis: {key: value}}``, e.g. a partial ``--drivetrain``) and the rest sized by :data:`RULES`
    (``rule`` 2) or :data:`RULES_1` (``rule`` 1: module docstring).

    Parameters
    ----------
    arm : faultgen.model.importers.Arm
    given : dict, optional
        Values to keep, by axis number (1..N) and key.
    payload : float, optional
        Rated payload in kg; by default the source's, else :data:`PAYLOAD_SHARE` of the moving mass.
    rule : int
        The sizing rule (:data:`RULE_VERSIONS`; default :data:`RULE`).

    Returns
    -------
    Sized
    """
    if check_rule(rule) == 1:
        return _sized_rule1(arm, given, payload)
    given = given or {}
    n = len(arm.joints)
    mass = moving_mass(arm.spec, arm.joints)
    if payload is None:
        payload = arm.payload if not math.isnan(arm.payload) else PAYLOAD_SHARE * mass
    loads = arm_loads(arm, payload)

    def torque_limit(k: int, G: float, speed: float, mine_k: dict) -> tuple[float, str]:
        effort = arm.effort_limit[k]
        if not math.isnan(effort):
            return effort / G, f"sized: the source's effort limit {effort:.4g} N m / G (arm side)"
        value = max(MIN_MOTOR_TORQUE, motor_torque(
            loads.need[k], G, speed, loads.acceleration[k], mine_k.get("motor_inertia"),
            mine_k.get("coulomb_pos"), mine_k.get(FRICTION_FIELDS[5])))
        return value, (
            f"sized: {MARGIN:g} x (need {loads.need[k]:.4g} N m / G + rotor acceleration + motor "
            f"friction), at least {MIN_MOTOR_TORQUE:g} N m; need = max |rigid-body torque| over "
            f"{POSES} poses with every axis at its speed and acceleration limits, a rated load of {payload:.4g} kg, centre of mass "
            f"{loads.offset:.3g} m out along the flange's z axis, acceleration = speed "
            f"limit / {RAMP[0]:g} s (main) or {RAMP[1]:g} s (wrist); gravity alone {loads.gravity[k]:.4g} N m"
        )

    table, origin = _size_axes(arm, given, RULES, lambda k, wrist: loads.speed[k], torque_limit)
    return Sized(Drivetrain.from_table(table, n, _source(arm)), origin, float(payload), loads, mass, 2)


def _source(arm) -> str:
    """The ``source`` line of a sized drivetrain."""
    return f"{arm.source}: the drivetrain sized for it (its speed and torque limits, masses, --drivetrain)"


def _size_axes(arm, given: dict[int, dict[str, float]], rules: dict[str, str], speed_of, torque_of) -> tuple[dict, dict]:
    """The per-axis steps every sizing rule shares: ``({axis: {key: value}}, {axis: {key: note}})``.

    Values in ``given`` are kept (noted "given"); the rest follow ``rules`` (``{key: note}``):
    the gear ratio from the arm speed ``speed_of(k, wrist)`` (rad/s, axis index ``k`` from 0), the motor
    torque limit and its note from ``torque_of(k, G, speed, given_k)`` (N m, motor side), and the rest
    from the torque limit (:func:`_put_from_torque`).
    """
    n = len(arm.joints)
    main = main_axes(n)
    table, origin = {}, {}
    for k in range(n):
        axis = k + 1
        wrist = k >= main
        mine_k = given.get(axis, {})
        mine = dict(mine_k)
        notes = {key: "given" for key in mine}

        def put(key: str, value: float, mine=mine, notes=notes) -> float:
            if key not in mine:
                mine[key] = float(value)
                notes[key] = "sized: " + rules[key]
            return mine[key]

        known_speed = not math.isnan(arm.speed_limit[k])
        speed = speed_of(k, wrist)
        G = put("gear_ratio", MOTOR_SPEED / speed)
        if "gear_ratio" not in mine_k:
            notes["gear_ratio"] += (
                f" ({speed:.4g} rad/s from the source)"
                if known_speed
                else f" (no speed limit in the source: {speed:g} rad/s assumed)"
            )
        value, note = torque_of(k, G, speed, mine_k)
        torque = put("motor_torque_limit", value)
        if "motor_torque_limit" not in mine_k:
            notes["motor_torque_limit"] = note
        _put_from_torque(put, torque, G, wrist)
        table[axis] = {key: mine[key] for key in KEYS}
        origin[axis] = notes
    return table, origin


def _put_from_torque(put, torque: float, G: float, wrist: int) -> None:
    """The rules of one axis that follow from its motor torque limit ``torque`` (N m) and gear ratio
    ``G``, the same under every sizing rule: motor inertia, gearbox stiffness and damping, motor
    friction (module docstring); ``put(key, value)`` keeps a value the user gave over the rule's."""
    jm = put("motor_inertia", JM_SCALE * torque**JM_EXPONENT)
    f = RESONANCE[wrist]
    stiffness = put("gearbox_stiffness", (2 * math.pi * f) ** 2 * G**2 * jm)
    put("gearbox_damping", 2 * DAMPING_RATIO * math.sqrt(stiffness * G**2 * jm))
    coulomb = put("coulomb_pos", COULOMB_SHARE * torque)
    put("coulomb_neg", COULOMB_SHARE * torque)
    put("static", STATIC_SHARE * coulomb)
    put("stribeck_velocity", STRIBECK_VELOCITY)
    put("stribeck_exponent", STRIBECK_EXPONENT)
    put(FRICTION_FIELDS[5], coulomb / VISCOUS_SPEED)
    put("bristle_stiffness", coulomb / PRESLIDING)
    put("bristle_damping", 0.0)


def _sized_rule1(arm, given: dict[int, dict[str, float]] | None, payload: float | None) -> Sized:
    """:func:`sized` under rule 1: faultgen's sizing before rule 2, kept as it was (bit for bit)."""
    given = given or {}
    n = len(arm.joints)
    model = arm.spec.copy().compile()
    first = model.joint(arm.joints[0].name).id
    moving_mass = float(model.body_subtreemass[model.jnt_bodyid[first]])
    if payload is None:
        payload = arm.payload if not math.isnan(arm.payload) else PAYLOAD_SHARE * moving_mass
    gravity, inertia = arm_loads_rule1(arm.spec, arm.joints, payload)

    def speed_of(k: int, wrist: bool) -> float:
        return arm.speed_limit[k] if not math.isnan(arm.speed_limit[k]) else DEFAULT_SPEED[wrist]

    def torque_limit(k: int, G: float, speed: float, mine_k: dict) -> tuple[float, str]:
        effort = arm.effort_limit[k]
        if not math.isnan(effort):
            return effort / G, f"sized: the source's effort limit {effort:.4g} N m / G"
        peak = GRAVITY_MARGIN * gravity[k] + inertia[k] * speed / RAMP_TIME
        return max(peak / G, MIN_MOTOR_TORQUE), (
            f"sized: peak {peak:.4g} N m / G; peak = {GRAVITY_MARGIN:g} x max "
            f"gravity torque {gravity[k]:.4g} N m (payload {payload:.4g} kg) + max "
            f"M_ii {inertia[k]:.4g} kg m^2 x speed limit / {RAMP_TIME:g} s, at least "
            f"{MIN_MOTOR_TORQUE:g} N m"
        )

    table, origin = _size_axes(arm, given, RULES_1, speed_of, torque_limit)
    return Sized(Drivetrain.from_table(table, n, _source(arm)), origin, float(payload), None, moving_mass, 1)


#: Fleet parts as shares of the rated payload: (small, big) mass ranges; their density, kg/m^3
#: (aluminium), sets the edge of a cube of that mass. The shares are those of the IRB-6700-like
#: arm's parts (faultgen.runs.fleet.PARTS: 10-40 and 60-120 kg of 200 kg).
PART_SHARES, PART_DENSITY = ((0.05, 0.2), (0.3, 0.6)), 2700.0


def fleet_parts(rated_payload: float) -> tuple:
    """Parts of two sizes for a fleet robot of this rated payload (kg), in the form of
    ``faultgen.runs.fleet.PARTS``: ``((small mass range kg, small edge range m), (big ..., big ...))``.

    Raises
    ------
    ValueError
        If the payload is not a finite number > 0.
    """
    if not (isinstance(rated_payload, (int, float)) and math.isfinite(rated_payload) and rated_payload > 0):
        raise ValueError(f"rated payload = {rated_payload!r} kg; expected a finite number > 0")
    out = []
    for shares in PART_SHARES:  # rounded to 3 significant digits
        masses = tuple(float(f"{share * rated_payload:.3g}") for share in shares)
        edges = tuple(float(f"{(m / PART_DENSITY) ** (1 / 3):.3g}") for m in masses)
        out.append((masses, edges))
    return tuple(out)
