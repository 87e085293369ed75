"""Size a drivetrain from an arm's own data where ``drivetrain.toml`` is silent.

Each number of a :class:`~faultgen.model.drivetrain.AxisDrive` the user does not give is sized by
one rule (:data:`RULES`; docs/robots.md, "Your own robot", gives each rule, its numbers and their
sources). The rules are those the IRB-6700-like robot was designed with (robots/irb6700/README.md),
written as formulas of the arm's joint speed and torque limits and link masses, with the motor
inertia law fitted through the PUMA 560's measured motors:

- gear ratio ``G = 470 rad/s / qd_max`` (top motor speed about 4500 rpm);
- arm-side peak torque ``tau_peak``: the source's effort limit, else
  ``1.5 max_q |g_i(q)| + max_q M_ii(q) qd_max / 0.5 s`` (gravity with the rated payload at the last
  link over 256 poses, plus reaching top speed in half a second);
- motor torque limit ``tau_peak / G``, at least 0.27 N m (unless the source gives the effort limit);
- motor inertia ``Jm = 1.2e-4 kg m^2 (T_max / 1 N m)^1.05``;
- gearbox stiffness ``K = (2 pi f)^2 G^2 Jm``, f = 10 Hz (main axes) or 25 Hz (wrist axes), damping
  ``D = 0.2 sqrt(K G^2 Jm)`` (damping ratio 0.1);
- Coulomb friction 3 % of the motor torque limit in both directions, static excess 30 % of it,
  Stribeck velocity 10 rad/s, exponent 2, viscous ``Coulomb / 400 rad/s``, bristle stiffness
  ``Coulomb / 0.1 rad``, bristle damping 0.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from faultgen.effects.friction import FIELDS as FRICTION_FIELDS
from faultgen.model.drivetrain import KEYS, Drivetrain

#: Top motor speed, rad/s (about 4500 rpm): G = this / joint speed limit.
MOTOR_SPEED = 470.0
#: Joint speed limit assumed where the source gives none, rad/s: main axes, wrist axes.
DEFAULT_SPEED = (2.0, 4.0)
#: Gravity margin and the time to reach top speed, s, of the peak-torque rule.
GRAVITY_MARGIN, RAMP_TIME = 1.5, 0.5
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
#: Payload share of the moving mass when the rated payload is unknown; the payload's density, kg/m^3
#: (a solid sphere one radius out along the last axis).
PAYLOAD_SHARE, PAYLOAD_DENSITY = 0.15, 1000.0

#: The rule of each key, as the robot's README names it.
RULES = {
    "gear_ratio": f"G = {MOTOR_SPEED:g} rad/s / joint speed limit",
    "motor_torque_limit": f"arm-side peak torque / G; peak = effort limit, else {GRAVITY_MARGIN:g} x max "
    f"gravity torque (rated payload) + max M_ii x speed limit / {RAMP_TIME:g} s",
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


def main_axes(n_axes: int) -> int:
    """How many axes from the base count as main (arm) axes; the rest are wrist axes."""
    return max(3, n_axes - 3)


def arm_loads(spec: mujoco.MjSpec, joints: list, payload: float) -> tuple[np.ndarray, np.ndarray]:
    """Largest gravity torque (rated payload at the last link's origin) and largest diagonal of the
    joint-space inertia over :data:`POSES` poses within the limits, N m and kg m^2, shape (N,)."""
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
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    data = mujoco.MjData(model)
    rng = np.random.default_rng(SEED)
    dofs = np.array([model.joint(j.name).dofadr[0] for j in joints])
    qadr = np.array([model.joint(j.name).qposadr[0] for j in joints])
    low, high = np.array([j.range for j in joints]).T
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


def size(
    arm, given: dict[int, dict[str, float]] | None = None, payload: float | None = None
) -> tuple[Drivetrain, dict[int, dict[str, str]], float]:
    """A full drivetrain for ``arm`` (:class:`faultgen.model.importers.Arm`): the values ``given``
    (``{axis: {key: value}}``, e.g. a partial ``--drivetrain``) and the rest sized by :data:`RULES`.

    Parameters
    ----------
    arm : faultgen.model.importers.Arm
    given : dict, optional
        Values to keep, by axis number (1..N) and key.
    payload : float, optional
        Rated payload in kg; by default the source's, else :data:`PAYLOAD_SHARE` of the moving mass.

    Returns
    -------
    drivetrain : Drivetrain
    origin : dict
        ``origin[axis][key]`` is ``"given"`` or ``"sized: <rule>"``.
    payload : float
        The rated payload used, kg.
    """
    given = given or {}
    n = len(arm.joints)
    model = arm.spec.copy().compile()
    first = model.joint(arm.joints[0].name).id
    moving_mass = float(model.body_subtreemass[model.jnt_bodyid[first]])
    if payload is None:
        payload = arm.payload if not math.isnan(arm.payload) else PAYLOAD_SHARE * moving_mass
    gravity, inertia = arm_loads(arm.spec, arm.joints, payload)
    main = main_axes(n)
    table, origin = {}, {}
    for k in range(n):
        axis = k + 1
        wrist = k >= main
        mine = dict(given.get(axis, {}))
        notes = {key: "given" for key in mine}

        def put(key: str, value: float, mine=mine, notes=notes) -> float:
            if key not in mine:
                mine[key] = float(value)
                notes[key] = "sized: " + RULES[key]
            return mine[key]

        known_speed = not math.isnan(arm.speed_limit[k])
        speed = arm.speed_limit[k] if known_speed else DEFAULT_SPEED[wrist]
        G = put("gear_ratio", MOTOR_SPEED / speed)
        if "gear_ratio" not in given.get(axis, {}):
            notes["gear_ratio"] += (
                f" ({speed:.4g} rad/s from the source)"
                if known_speed
                else f" (no speed limit in the source: {speed:g} rad/s assumed)"
            )
        effort = arm.effort_limit[k]
        peak = (
            effort if not math.isnan(effort) else GRAVITY_MARGIN * gravity[k] + inertia[k] * speed / RAMP_TIME
        )
        torque = put(
            "motor_torque_limit", peak / G if not math.isnan(effort) else max(peak / G, MIN_MOTOR_TORQUE)
        )
        if "motor_torque_limit" not in given.get(axis, {}):
            notes["motor_torque_limit"] = (
                f"sized: the source's effort limit {effort:.4g} N m / G"
                if not math.isnan(effort)
                else f"sized: peak {peak:.4g} N m / G; peak = {GRAVITY_MARGIN:g} x max "
                f"gravity torque {gravity[k]:.4g} N m (payload {payload:.4g} kg) + max "
                f"M_ii {inertia[k]:.4g} kg m^2 x speed limit / {RAMP_TIME:g} s, at least "
                f"{MIN_MOTOR_TORQUE:g} N m"
            )
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
        table[axis] = {key: mine[key] for key in KEYS}
        origin[axis] = notes
    source = f"{arm.source}: the drivetrain sized for it (its speed and torque limits, masses, --drivetrain)"
    return Drivetrain.from_table(table, n, source), origin, float(payload)


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
