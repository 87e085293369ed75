"""Is an added robot's mass and payload plausible? The report ``faultgen robots add`` prints and writes
into the robot's README: the moving mass and rated payload against the arm's reach and axis count,
link masses that are not the maker's (computed from meshes, placeholders) and effort limits below
what the rated load needs, each finding with what to do.

The bands are those of industrial arms and cobots (makers' datasheets, total robot mass):

- rated payload / moving mass: 0.05-0.5 for arms of up to 6 axes, up to 1 for 7-axis arms
  (lightweight and collaborative): ABB IRB 140 6 kg / 98 kg, KUKA KR 16 16 kg / 235 kg, KUKA KR 210
  L150 150 kg / about 1070 kg, ABB IRB 6700-200 200 kg / 1170 kg, UR5 5 kg / 18.4 kg, KUKA LBR iiwa
  14 14 kg / 30 kg (0.06-0.47; the moving mass is below the total, so the ratios are higher);
- moving mass / reach^3: :data:`MASS_PER_REACH3` kg/m^3: UR5 30 (0.85 m), LBR iiwa 14 54 (0.82 m),
  IRB 6700-200 67 (2.6 m), PUMA 560 99 (63 kg, 0.86 m), IRB 140 184 (0.81 m), widened three-fold.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

#: Rated payload / moving mass of industrial arms: (lowest, highest for up to 6 axes, highest for 7).
PAYLOAD_RATIO = (0.05, 0.5, 1.0)
#: Moving mass over the reach cubed, kg/m^3: (lowest, highest) plausible (module docstring).
MASS_PER_REACH3 = (10.0, 600.0)
#: Links with masses equal to this relative tolerance count as identical.
IDENTICAL = 1e-9

FIX = ("give a URDF with the real inertials (mass, centre of mass, inertia of every link), or at least "
       "--payload and a --drivetrain with the drives you know")


def radial_reach(robot, poses: int = 256, seed: int = 0) -> float:
    """Largest distance of the flange from axis 1's line over ``poses`` poses within the joint limits,
    m: the horizontal reach datasheets give (axis 1 vertical)."""
    model, data = robot.model, mujoco.MjData(robot.model)
    rng = np.random.default_rng(seed)
    site, joint = model.site("flange").id, model.joint("joint1").id
    out = 0.0
    for _ in range(poses):
        data.qpos[:], _ = robot.rigid_state(rng.uniform(*robot.joint_range.T))
        mujoco.mj_kinematics(model, data)
        v = data.site_xpos[site] - data.xanchor[joint]
        axis = data.xaxis[joint]
        out = max(out, float(np.linalg.norm(v - np.dot(v, axis) * axis)))
    return out


def moving_links(spec: mujoco.MjSpec, first_joint: str) -> list[tuple[str, float, np.ndarray]]:
    """``(name, mass kg, principal inertia kg m^2)`` of each body with mass that ``first_joint``
    moves (its body and every body below it)."""
    model = spec.copy().compile()
    root = model.jnt_bodyid[model.joint(first_joint).id]
    out = []
    for body in range(model.nbody):
        b = body
        while b not in (0, root):
            b = model.body_parentid[b]
        if b == root and model.body_mass[body] > 0:
            out.append((model.body(body).name, float(model.body_mass[body]), model.body_inertia[body].copy()))
    return out


def placeholders(links: list[tuple[str, float, np.ndarray]]) -> list[str]:
    """Findings on placeholder link data: the same mass on every moving link (three or more), the same
    inertia on every moving link, or a unit inertia (1 kg m^2 about each principal axis)."""
    found = []
    masses = np.array([m for _, m, _ in links])
    inertias = np.array([i for _, _, i in links])
    same_mass = len(links) >= 3 and np.ptp(masses) <= IDENTICAL * masses.max()
    same_inertia = len(links) >= 3 and np.ptp(inertias, axis=0).max() <= IDENTICAL * inertias.max()
    inertia = f"the inertia {inertias[0][0]:.4g}, {inertias[0][1]:.4g}, {inertias[0][2]:.4g} kg m^2"
    if same_mass or same_inertia:
        what = " and ".join(([f"the mass {masses[0]:.4g} kg"] if same_mass else [])
                            + ([inertia] if same_inertia else []))
        found.append(f"every moving link ({len(links)}) has {what}: placeholder values, not the arm's; {FIX}")
    unit = [name for name, _, i in links if np.allclose(i, 1.0, rtol=IDENTICAL, atol=0)]
    if unit and not found:
        found.append(f"links {', '.join(unit)}: unit inertia (1 kg m^2 about each axis), a placeholder; {FIX}")
    return found


def report(arm, payload: float, guessed: bool, moving_mass: float, reach: float, loads=None,
           share: float = math.nan) -> tuple[str, list[str]]:
    """The plausibility of an added robot: a summary line and the findings, each naming the values
    and what to do.

    Parameters
    ----------
    arm : faultgen.model.importers.Arm
    payload : float
        Rated payload used, kg.
    guessed : bool
        Whether ``payload`` is the sizing's guess (``share`` of the moving mass).
    moving_mass : float
        Mass of the links the first joint moves, kg.
    reach : float
        The arm's reach, m (:func:`radial_reach`).
    loads : faultgen.model.sizing.Loads, optional
        The torque the rated load needs per axis (checked against the source's effort limits).
    share : float
        The guess's share of the moving mass.
    """
    n = len(arm.joints)
    ratio = payload / moving_mass if moving_mass > 0 else math.inf
    density = moving_mass / reach**3 if reach > 0 else math.inf
    summary = (f"{n} axes, reach {reach:.3g} m, moving mass {moving_mass:.4g} kg ({density:.3g} kg per m^3 of "
               f"reach cubed), rated payload {payload:.4g} kg ({ratio:.3g} of the moving mass)")
    found = []
    if guessed:
        found.append(f"rated payload {payload:.3g} kg GUESSED from {share * 100:g} % of the moving mass; give --payload "
                     "KG if you know it (the datasheet's rated payload): it sizes the drives and decides which "
                     "parts the monitor's twin can carry")
    links = moving_links(arm.spec, arm.joints[0].name)
    meshed = [name for name, _, _ in links if name in arm.mesh_inertials]
    if meshed:
        found.append(f"moving links {', '.join(meshed)}: masses computed from their meshes as solids of "
                     "1000 kg/m^3 (the source has no <inertial>): a mesh's volume, not the maker's mass; " + FIX)
    found += placeholders(links)
    low, high6, high7 = PAYLOAD_RATIO
    high = high7 if n >= 7 else high6
    if not guessed and not low <= ratio <= high:
        found.append(f"rated payload {payload:.4g} kg is {ratio:.3g} of the moving mass {moving_mass:.4g} kg; "
                     f"industrial arms of {n} axes carry {low:g}-{high:g} of theirs: if the payload is the "
                     f"datasheet's, the link masses are not ({FIX.replace('give', 'give then')}); else check "
                     "--payload")
    if not MASS_PER_REACH3[0] <= density <= MASS_PER_REACH3[1]:
        found.append(f"moving mass {moving_mass:.4g} kg for a reach of {reach:.3g} m is {density:.3g} kg per m^3 of "
                     f"reach cubed; industrial arms and cobots have {MASS_PER_REACH3[0]:g}-{MASS_PER_REACH3[1]:g} "
                     f"(UR5 30, IRB 140 184): the link masses are not the arm's; {FIX}")
    if loads is not None:
        for k, effort in enumerate(arm.effort_limit):
            if not math.isnan(effort) and effort < loads.need[k]:
                found.append(f"axis {k + 1}: the source's effort limit {effort:.4g} N m is below the "
                             f"{loads.need[k]:.4g} N m the rated load ({payload:.4g} kg, centre of mass "
                             f"{loads.offset:.3g} m from the flange) needs at full speed and acceleration: "
                             "the tasks are slowed to fit, parts near the rated payload may saturate the "
                             "drive; check --payload and the effort limit")
    return summary, found
