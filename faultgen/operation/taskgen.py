"""The three thesis tasks for a new robot, generated from its workspace (``faultgen robots add``).

:func:`generate` writes the ``tasks.toml`` of a robot folder, each task a program table as
:func:`faultgen.operation.programs.builtin` reads it (robots/irb6700/tasks.toml shows it with comments):

- ``[limits]``: joint speed limits of the source (else the sizing's assumption,
  :data:`faultgen.model.sizing.DEFAULT_SPEED`); full speed reached in 0.45 s (main axes) or 0.3 s
  (wrist), full acceleration built up in 0.2 s (jerk = 5 x acceleration per second): the
  IRB-6700-like arm's choices;
- ``[pick_place]``: start at the middle of every joint range, pick and place 29 % of each range
  either side of it (58 % of every range between them, 21 % clear of each limit);
- ``[spot_weld]`` and ``[arc_weld]``: a U-shaped flange of a horizontal panel (ten weld points; the
  seam through its corners) centred under the flange of a posture found by a seeded search over
  the joint ranges: flange 40-75 % of the reach out from axis 1, between half the reach below and
  30 % of it above the first joint's anchor, tool axis within 35 deg of straight down; weld
  spacing 3.5 % of the reach, within 0.02-0.1 m.

Each candidate is held to today's task checks before it is kept: the tasks load and plan
(:meth:`Program.trajectory`: joint limits, IK within tolerance along the seam and at every weld
point) and the drive torque of every cycle, rigid body plus motor inertia and friction
(:meth:`Robot.inverse_dynamics`), stays within :data:`TORQUE_SHARE` of the motors' capacity (peak
motor torque x G), the speed and acceleration scales lowered step by step until it does.
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np

from faultgen.model import folder, sizing
from faultgen.model.robots import Robot
from faultgen.operation import programs
from faultgen.operation.ik import FLANGE
from faultgen.operation.tasks import TASKS

#: Share of the motor torque capacity the tasks may use.
TORQUE_SHARE = 0.9
#: Time to full speed, s (main, wrist axes); jerk = JERK_RATE x acceleration per second.
RAMP, JERK_RATE = (0.45, 0.3), 5.0
#: Pick and place lie this share of each range either side of its middle.
PICK_SHARE = 0.29
#: Speed and acceleration scales tried in turn until the torque fits.
SCALES = (1.0, 0.7, 0.5, 0.35, 0.25, 0.15, 0.1)
#: Weld spacing as a share of the reach, and its bounds, m.
SPACING_SHARE, SPACING_BOUNDS = 0.035, (0.02, 0.1)
#: U-shaped weld pattern: (radial, tangential) offsets from the panel centre in weld spacings.
PATTERN = [
    (-1, -2.5),
    (0, -2.5),
    (1, -2.5),
    (1, -1.5),
    (1, -0.5),
    (1, 0.5),
    (1, 1.5),
    (1, 2.5),
    (0, 2.5),
    (-1, 2.5),
]
#: Posture candidates searched, and the seed of the search.
CANDIDATES, SEED = 400, 0


def _deg(values: np.ndarray, digits: int = 4) -> str:
    return "[" + ", ".join(f"{round(float(v), digits):g}" for v in np.degrees(values)) + "]"


def _vec(values, digits: int = 5) -> str:
    return "[" + ", ".join(f"{round(float(v), digits):g}" for v in values) + "]"


def _flange_poses(robot: Robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    model, data = robot.model, mujoco.MjData(robot.model)
    site = model.site(FLANGE).id
    positions, rotations = [], []
    for row in q:
        data.qpos[:], _ = robot.rigid_state(row)
        mujoco.mj_kinematics(model, data)
        positions.append(data.site_xpos[site].copy())
        rotations.append(data.site_xmat[site].reshape(3, 3).copy())
    return np.array(positions), np.array(rotations)


def _weld_postures(robot: Robot, reach: float, base: np.ndarray) -> list[np.ndarray]:
    """Postures whose flange is 40-75 % of the reach out from axis 1 with the tool axis within
    35 deg of straight down, best (most downward, then mid-reach) first."""
    rng = np.random.default_rng(SEED)
    low, high = robot.joint_range.T
    middle, half = (low + high) / 2, (high - low) / 2
    q = middle + rng.uniform(-0.6, 0.6, (CANDIDATES, robot.n_axes)) * half
    positions, rotations = _flange_poses(robot, q)
    radial = np.linalg.norm(positions[:, :2] - base[:2], axis=1) / reach
    down = -rotations[:, 2, 2]  # tool (flange z) axis against world -z
    height = positions[:, 2] - base[2]
    fits = (
        (radial > 0.4)
        & (radial < 0.75)
        & (down > math.cos(math.radians(35)))
        & (height > -0.5 * reach)
        & (height < 0.3 * reach)
    )
    order = np.lexsort((np.abs(radial - 0.55), -down))
    return [q[k] for k in order if fits[k]]


def _panel(robot: Robot, q: np.ndarray, reach: float, base: np.ndarray) -> dict:
    (position,), (rotation,) = _flange_poses(robot, q[None])
    spacing = float(np.clip(SPACING_SHARE * reach, *SPACING_BOUNDS))
    out = position[:2] - base[:2]
    u = np.append(out / np.linalg.norm(out), 0.0)
    v = np.array([-u[1], u[0], 0.0])
    points = [position + spacing * (a * u + b * v) for a, b in PATTERN]
    seam = [points[0], points[2], points[7], points[9]]
    seam_length = sum(np.linalg.norm(b - a) for a, b in zip(seam, seam[1:]))
    return {
        "rotation": rotation,
        "points": points,
        "seam": seam,
        "spacing": spacing,
        "tool_speed": float(np.clip(seam_length / 6.0, 0.01, 0.15)),
    }


def _text(robot: Robot, velocity, acceleration, start_pp, pick, place, q_weld, panel, scale) -> str:
    s = panel["spacing"]
    points = panel["points"]
    seam = "[" + ", ".join(_vec(p) for p in panel["seam"]) + "]"
    tool = f"tool = {{z = {_vec(panel['rotation'][:, 2])}, x = {_vec(panel['rotation'][:, 0])}}}"
    standoff = f"{round(0.5 * s, 4):g}"
    lines = [
        f"# Task cycles of {robot.name} (thesis ch. 6.3.1, tasks 1-3), generated by `faultgen robots add`",
        "# (faultgen.operation.taskgen: its docstring gives every rule). Edit freely; faultgen checks them",
        "# when it plans a cycle. Each table below is a program (docs/simulation.md, \"Your own",
        "# programs\"; its name is the table's, its robot this folder's, its [limits] the ones below).",
        "#",
        "# Units: joint angles in deg, positions in m (world frame: z up, robot base at the origin),",
        "# times in s. Every cycle starts and ends at `start`, at rest.",
        "",
        "[limits]",
        f"velocity = {_deg(velocity)}  # deg/s, the source's joint speed limits (or the sizing's assumption)",
        (f"acceleration = {_deg(acceleration)}  # deg/s^2: full speed in {RAMP[0]:g} s (main), "
         f"{RAMP[1]:g} s (wrist)"),
        f"jerk = {_deg(JERK_RATE * acceleration)}  # deg/s^3: full acceleration in {1 / JERK_RATE:g} s",
        "",
        "[pick_place]",
        f"# start at the middle of every range; pick and place {PICK_SHARE:.0%} of each range either side",
        'process = "point-to-point"',
        f"start = {_deg(start_pp)}",
        f"velocity_scale = {scale['pick_place']:g}",
        f"acceleration_scale = {scale['pick_place']:g}",
        "segment = [",
        f'    {{type = "move", to = {_deg(pick)}}},  # pick',
        '    {type = "dwell", time = 0.6},',
        f'    {{type = "move", to = {_deg(place)}}},  # place',
        '    {type = "dwell", time = 0.6},',
        f'    {{type = "move", to = {_deg(start_pp)}}},',
        "]",
        "",
        "[spot_weld]",
        f"# ten weld points {s:.3g} m apart on a U-shaped flange of a horizontal panel under the start pose",
        'process = "discontinuous"',
        f"start = {_deg(q_weld)}",
        f"velocity_scale = {scale['spot_weld']:g}",
        f"acceleration_scale = {scale['spot_weld']:g}",
        tool,
        "segment = [",
        *[f'    {{type = "move", pose = {_vec(p)}}}, {{type = "dwell", time = 0.4, label = "weld"}},' for p in points],
        f'    {{type = "move", to = {_deg(q_weld)}}},',
        "]",
        "",
        "[arc_weld]",
        "# a U-shaped fillet seam on the same panel, constant tool speed with a weave",
        'process = "continuous"',
        f"start = {_deg(q_weld)}",
        f"velocity_scale = {min(0.5, scale['arc_weld']):g}",
        f"acceleration_scale = {min(0.5, scale['arc_weld']):g}",
        tool,
        "segment = [",
        f'    {{type = "move", pose = {_vec(panel["seam"][0])}, standoff = {standoff}, label = "approach"}},',
        f'    {{type = "move", pose = {_vec(panel["seam"][0])}, label = "approach"}},',
        (f'    {{type = "seam", vertices = {seam}, corner_radius = {round(0.3 * s, 4):g}, '
         f"speed = {round(panel['tool_speed'] * scale['arc_weld'], 4):g}, ramp_time = 0.3, "
         f"weave_amplitude = {round(min(0.003, 0.03 * s), 5):g}, weave_frequency = 2.0}},"),
        f'    {{type = "move", standoff = {standoff}, label = "retract"}},',
        f'    {{type = "move", to = {_deg(q_weld)}, label = "retract"}},',
        "]",
        "",
    ]
    return "\n".join(lines)


def _checked(robot: Robot, name: str) -> float:
    """Plan task ``name`` from the robot folder's tasks.toml; return its peak drive torque as a
    share of the motor capacity (raises ValueError if it does not plan)."""
    task = programs.builtin(robot, name)
    path = task.trajectory(robot.model.opt.timestep)  # as the simulation plans it, so both check alike
    tau = robot.inverse_dynamics(path.q, path.qd, path.qdd)
    return float(np.max(np.abs(tau) / (robot.motor_torque_limit * robot.gear_ratio)))


def generate(robot: Robot, arm=None, payload: float | None = None) -> str:
    """``tasks.toml`` text for ``robot``, checked as this module's docstring says.

    The robot must be loaded from its folder (``robot.path.parent``), where the candidates are
    written while they are checked.

    Parameters
    ----------
    robot : Robot
    arm : faultgen.model.importers.Arm, optional
        The arm as read, for its joint speed limits.
    payload : float, optional
        Unused by the tasks themselves (the fleet's parts use it); accepted for ``folder.add``.

    Raises
    ------
    ValueError
        If no posture of the search gives weld tasks that plan within the torque capacity.
    """
    n = robot.n_axes
    wrist = np.arange(n) >= sizing.main_axes(n)
    speed = np.full(n, np.nan) if arm is None else np.asarray(arm.speed_limit, dtype=float)
    velocity = np.where(
        np.isnan(speed), np.where(wrist, sizing.DEFAULT_SPEED[1], sizing.DEFAULT_SPEED[0]), speed
    )
    acceleration = velocity / np.where(wrist, RAMP[1], RAMP[0])
    low, high = robot.joint_range.T
    middle = (low + high) / 2
    sign = np.array([(-1) ** k for k in range(n)])
    pick = middle - PICK_SHARE * (high - low) * sign
    place = middle + PICK_SHARE * (high - low) * sign
    reach = folder.reach(robot)
    data = mujoco.MjData(robot.model)
    data.qpos[:], _ = robot.rigid_state(robot.home)
    mujoco.mj_kinematics(robot.model, data)
    base = data.xanchor[robot.model.joint("joint1").id].copy()
    target = Path(robot.path).parent / "tasks.toml"
    failures = []
    for q_weld in _weld_postures(robot, reach, base)[:12]:
        panel = _panel(robot, q_weld, reach, base)
        scale = dict.fromkeys(TASKS, 1.0)
        try:
            for name in TASKS:
                why = f"drive torque above {TORQUE_SHARE:.0%} of capacity"
                for value in SCALES:
                    scale[name] = value
                    target.write_text(
                        _text(robot, velocity, acceleration, middle, pick, place, q_weld, panel, scale)
                    )
                    try:  # a limit the path exceeds at this speed: slower, as for the torque
                        if _checked(robot, name) <= TORQUE_SHARE:
                            break
                    except ValueError as err:
                        why = str(err)
                else:
                    raise ValueError(f"{name} even at speed scale {SCALES[-1]}: {why}")
        except ValueError as err:
            failures.append(str(err))
            continue
        return _text(robot, velocity, acceleration, middle, pick, place, q_weld, panel, scale)
    reason = failures[-1] if failures else "no posture puts the tool down within 40-75 % of the reach"
    raise ValueError(
        f"{robot.name}: no weld tasks found that plan within the limits and torque capacity ({reason}); "
        "write tasks.toml by hand (robots/irb6700/tasks.toml shows the format)"
    )
