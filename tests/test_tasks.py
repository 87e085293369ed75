"""Task cycles (thesis ch. 6.3.1, tasks 1-3, the programs of each robot folder's tasks.toml):
rest-to-rest cycles within the limits, weld stops at the weld points, a seam followed at constant
speed with the configured weave; programs and replayed logs are one kind of task.

Flange positions are measured independently of the planner: MuJoCo forward kinematics of the
full robot model (rotors included) at ``robot.rigid_state(q)``.
"""

import itertools
import shutil

import mujoco
import numpy as np
import pytest

from faultgen.model import robots
from faultgen.operation import programs, replay, tasks

ROBOTS = ["puma560", "irb6700"]
CASES = [(r, t) for r in ROBOTS for t in tasks.TASKS]
DT = 0.004  # s
SEAM_LIMIT_SLACK = 0.01  # relative: the IK-based seam may exceed a limit by numerical noise only
MM = 1e-3


@pytest.fixture(scope="module")
def loaded():
    """{robot name: Robot}, loaded once."""
    return {name: robots.load(name) for name in ROBOTS}


@pytest.fixture(scope="module")
def cycles(loaded):
    """{(robot, task): (Program, JointPath)} at DT, planned once for the module."""
    out = {}
    for robot, name in CASES:
        task = programs.load(loaded[robot], name)
        out[robot, name] = task, task.trajectory(DT)
    return out


def weld_points(task):
    """The weld points (m, 3) of a spot weld program: the Cartesian poses it moves to."""
    return np.array([s.values["pose"] for s in task.segments if s.type == "move" and "pose" in s.values])


def weld_dwell(task):
    """The stop at each weld point, s."""
    (time,) = {s.values["time"] for s in task.segments if s.label == "weld"}
    return time


def seam(task):
    """The values of an arc weld program's seam segment (vertices, corner_radius, speed, ...)."""
    (segment,) = [s for s in task.segments if s.type == "seam"]
    return segment.values


def flange_positions(robot, q):
    """Flange positions (n, 3) in m by forward kinematics of the full model."""
    data = mujoco.MjData(robot.model)
    site = robot.model.site("flange").id
    out = np.empty((len(q), 3))
    for k, qk in enumerate(q):
        data.qpos[:], _ = robot.rigid_state(qk)
        mujoco.mj_kinematics(robot.model, data)
        out[k] = data.site_xpos[site]
    return out


def rest_runs(path, tol=1e-12):
    """(first, last) sample indices of maximal runs at rest (zero velocity and acceleration)."""
    rest = np.all(np.abs(path.qd) <= tol, axis=1) & np.all(np.abs(path.qdd) <= tol, axis=1)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], rest.astype(int), [0]])))
    return list(zip(edges[::2], edges[1::2] - 1))


def seam_segment(path):
    (segment,) = [s for s in path.segments if s[0] == "seam"]
    return segment[1], segment[2]


def straight_parts(task, positions, margin=0.01):
    """Per straight seam segment: (keep, along, across) for the positions (n, 3), m.

    ``along`` and ``across`` are the coordinates along the segment line and across it in the
    seam plane; ``keep`` marks the positions beside the segment at least
    ``corner_radius + margin`` from its ends (clear of the rounded corners).
    """
    vertices = seam(task)["vertices"]
    normal = np.cross(vertices[1] - vertices[0], vertices[2] - vertices[1])
    normal /= np.linalg.norm(normal)
    parts = []
    for a, b in itertools.pairwise(vertices):
        length = np.linalg.norm(b - a)
        direction = (b - a) / length
        lateral = np.cross(normal, direction)
        along = (positions - a) @ direction
        across = (positions - a) @ lateral
        near = (np.abs(across) < 0.02) & (np.abs((positions - a) @ normal) < 0.02)
        radius = seam(task)["corner_radius"]
        keep = near & (along > radius + margin) & (along < length - radius - margin)
        parts.append((keep, along, across))
    return parts


@pytest.mark.parametrize("robot,name", CASES)
def test_cycle_starts_and_ends_at_the_same_rest_state(cycles, robot, name):
    task, path = cycles[robot, name]
    n = len(path.t)
    assert path.q.shape == path.qd.shape == path.qdd.shape == (n, 6)
    assert path.t[0] == 0.0
    np.testing.assert_allclose(np.diff(path.t), DT, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(path.q[0], task.start)
    np.testing.assert_array_equal(path.q[-1], path.q[0])
    for arr in (path.qd, path.qdd):
        np.testing.assert_array_equal(arr[[0, -1]], 0.0)
    assert path.duration == pytest.approx(path.t[-1])
    assert (
        task.process
        == {"pick_place": "point-to-point", "spot_weld": "discontinuous", "arc_weld": "continuous"}[name]
    )


@pytest.mark.parametrize("robot,name", CASES)
def test_joint_velocity_and_acceleration_limits_hold(cycles, loaded, robot, name):
    task, path = cycles[robot, name]
    low, high = loaded[robot].joint_range.T
    assert np.all(path.q >= low) and np.all(path.q <= high)
    slack = SEAM_LIMIT_SLACK if name == "arc_weld" else 1e-9
    assert np.all(np.abs(path.qd) <= task.velocity_limit * (1 + slack))
    assert np.all(np.abs(path.qdd) <= task.acceleration_limit * (1 + slack))
    # the limits are the file's: IRB-6700 speeds as published by ABB
    if robot == "irb6700":
        np.testing.assert_allclose(np.degrees(task.velocity_limit), [110, 110, 110, 190, 150, 210])


@pytest.mark.parametrize("robot,name", CASES)
def test_cycle_lasts_6_to_12_s(cycles, robot, name):
    assert 6.0 <= cycles[robot, name][1].duration <= 12.0


@pytest.mark.parametrize("robot", ROBOTS)
def test_pick_place_covers_a_large_part_of_every_range(cycles, loaded, robot):
    _, path = cycles[robot, "pick_place"]
    low, high = loaded[robot].joint_range.T
    span = np.ptp(path.q, axis=0) / (high - low)
    assert np.all((span >= 0.5) & (span <= 0.8)), span
    # clear of the limits
    assert np.all(path.q.min(axis=0) - low >= 0.05 * (high - low))
    assert np.all(high - path.q.max(axis=0) >= 0.05 * (high - low))
    # a move at full speed on at least one axis
    assert np.max(np.abs(path.qd) / cycles[robot, "pick_place"][0].velocity_limit) > 0.99


@pytest.mark.parametrize("robot", ROBOTS)
def test_spot_weld_stops_at_every_weld_point(cycles, loaded, robot):
    task, path = cycles[robot, "spot_weld"]
    points, dwell = weld_points(task), weld_dwell(task)
    assert 8 <= len(points) <= 12
    dwell_steps = round(dwell / DT)
    stops = [(a, b) for a, b in rest_runs(path) if b - a >= dwell_steps]
    assert len(stops) == len(points)
    for (first, last), point in zip(stops, points):
        assert (last - first) * DT == pytest.approx(dwell, abs=DT / 2)
        flange = flange_positions(loaded[robot], path.q[[first, (first + last) // 2, last]])
        assert np.max(np.linalg.norm(flange - point, axis=1)) <= 0.5 * MM
        np.testing.assert_array_equal(path.target[first : last + 1], np.tile(point, (last - first + 1, 1)))
    # short moves between neighbouring weld points, at high acceleration
    moves = [s for s in path.segments if s[0] == "move"][1:-1]
    assert all((last - first) * DT < 1.0 for _, first, last in moves)
    assert np.max(np.abs(path.qdd) / task.acceleration_limit) > 0.8


def arc_weld_seam(cycles, loaded, robot):
    """``robot``'s arc weld: its task, its path, its seam segment's first and last sample, and the
    flange positions (m, shape (samples, 3)) along that segment."""
    task, path = cycles[robot, "arc_weld"]
    first, last = seam_segment(path)
    return task, path, (first, last), flange_positions(loaded[robot], path.q[first : last + 1])


@pytest.mark.parametrize("robot", ROBOTS)
def test_arc_weld_flange_follows_the_seam(cycles, loaded, robot):
    task, path, (first, last), flange = arc_weld_seam(cycles, loaded, robot)
    target = path.target[first : last + 1]
    assert not np.any(np.isnan(target))
    assert np.max(np.linalg.norm(flange - target, axis=1)) <= 0.5 * MM
    # and the seam runs from the first to the last vertex (the weave starts and ends at zero)
    np.testing.assert_allclose(flange[0], seam(task)["vertices"][0], atol=0.5 * MM)
    np.testing.assert_allclose(flange[-1], seam(task)["vertices"][-1], atol=0.5 * MM)
    # the approach and retract are not on the seam
    assert np.all(np.isnan(path.target[:first])) and np.all(np.isnan(path.target[last + 1 :]))


@pytest.mark.parametrize("robot", ROBOTS)
def test_arc_weld_tool_speed_is_constant_along_the_seam(cycles, loaded, robot):
    task, _, _, flange = arc_weld_seam(cycles, loaded, robot)
    v = seam(task)
    velocity = np.gradient(flange, DT, axis=0)
    t = np.arange(len(flange)) * DT
    cruise = (t > v["ramp_time"] + 0.05) & (t < t[-1] - v["ramp_time"] - 0.05)
    checked = 0
    for keep, along, _ in straight_parts(task, flange):
        sel = keep & cruise
        direction = np.gradient(along, DT)[sel]  # speed along the seam line
        assert np.all(np.abs(direction / v["speed"] - 1) < 0.03), (direction.min(), direction.max())
        checked += sel.sum()
    assert checked > 0.5 * len(flange)
    # the weave adds its lateral speed, and on the outside of a corner arc the offset path is longer
    weave_speed = 2 * np.pi * v["weave_frequency"] * v["weave_amplitude"]
    bound = np.hypot(v["speed"], weave_speed) * (1 + v["weave_amplitude"] / v["corner_radius"])
    assert np.max(np.linalg.norm(velocity, axis=1)) <= 1.02 * bound


@pytest.mark.parametrize("robot", ROBOTS)
def test_arc_weld_weave_has_the_configured_amplitude_and_frequency(cycles, loaded, robot):
    task, _, _, flange = arc_weld_seam(cycles, loaded, robot)
    v = seam(task)
    assert 1 * MM <= v["weave_amplitude"] <= 5 * MM and 1.0 <= v["weave_frequency"] <= 3.0
    for keep, _, across in straight_parts(task, flange):
        lateral = across[keep]
        assert np.max(np.abs(lateral)) == pytest.approx(v["weave_amplitude"], rel=0.03)
        assert np.max(np.abs(lateral)) <= v["weave_amplitude"] + 0.5 * MM
    # frequency from the zero crossings of the lateral deviation on the longest straight part
    keep, _, across = max(straight_parts(task, flange), key=lambda part: part[0].sum())
    idx = np.flatnonzero(keep)
    crossings = np.sum(np.diff(np.sign(across[idx])) != 0)
    frequency = crossings / 2 / (len(idx) * DT)
    assert frequency == pytest.approx(v["weave_frequency"], rel=0.1)


@pytest.mark.parametrize("robot,name", CASES)
def test_the_same_call_gives_bit_identical_arrays(cycles, robot, name):
    task, path = cycles[robot, name]
    again = task.trajectory(DT)
    for field in ("t", "q", "qd", "qdd"):
        assert np.array_equal(getattr(path, field), getattr(again, field))
    assert np.array_equal(path.target, again.target, equal_nan=True)
    assert path.segments == again.segments


@pytest.mark.parametrize("robot,name", CASES)
def test_a_finer_step_samples_the_same_path(cycles, robot, name):
    """Every segment lasts whole 4 ms planning periods, so a finer step gives the same path at
    more instants: the physics step must not change the cycle (a convergence study refines the
    step and compares; docs/simulation.md)."""
    task, coarse = cycles[robot, name]
    fine = task.trajectory(DT / 8)
    assert fine.duration == pytest.approx(coarse.duration, abs=1e-12)
    assert [(label, 8 * a, 8 * b) for label, a, b in coarse.segments] == list(fine.segments)
    for field in ("q", "qd", "qdd"):
        np.testing.assert_allclose(getattr(fine, field)[::8], getattr(coarse, field), rtol=0, atol=1e-9,
                                   err_msg=field)
    np.testing.assert_array_equal(fine.q[-1], task.start)


def test_unknown_task_lists_the_known_ones(loaded):
    with pytest.raises(ValueError) as err:
        programs.load(loaded["puma560"], "welding")
    message = str(err.value)
    assert "'welding'" in message
    for name in tasks.TASKS:
        assert name in message


def test_bad_time_step_is_refused(cycles):
    task, _ = cycles["puma560", "pick_place"]
    for dt in (0.0, -0.004, float("nan")):
        with pytest.raises(ValueError, match="dt"):
            task.trajectory(dt)
    with pytest.raises(ValueError, match=r"dt = 0.003 s does not divide the 4 ms planning period"):
        task.trajectory(0.003)


def copy_robot_folder(tmp_path, name):
    """Copy a robot's MJCF and tasks.toml to tmp_path; return the MJCF path and the toml text."""
    source = robots.available()[name]
    shutil.copy(source, tmp_path / source.name)
    text = (source.parent / "tasks.toml").read_text()
    return tmp_path / source.name, text


@pytest.mark.parametrize(
    "old,new,task,key",
    [
        ("velocity = [100, 95, 100, 150, 130, 110]", "velocity = [100, 95, 100, 150, 130]", "pick_place", "velocity"),
        ('{type = "dwell", time = 0.4, label = "weld"}', '{type = "dwell", tme = 0.4, label = "weld"}', "spot_weld",
         "tme"),
        ("speed = 0.1,", "speed = -0.1,", "arc_weld", "speed"),
        ("start = [0, 92, -122, 30, 0, 0]", "start = [0, 92, -122, 30, 120, 0]", "pick_place", "start"),
        ('{type = "dwell", time = 0.5}', '{type = "dwell", time = -0.5}', "pick_place", "time"),
        ("[0.65, -0.30, 0.30], [0.65, 0.00", "[0.65, -0.30, 0.31], [0.65, 0.00", "arc_weld", "vertices"),
        ("[pick_place]\n", "[pick_place]\nname = \"mine\"\n", "pick_place", "name"),
    ],
)
def test_malformed_tasks_file_names_the_file_and_the_key(tmp_path, old, new, task, key):
    mjcf, text = copy_robot_folder(tmp_path, "puma560")
    assert old in text
    (tmp_path / "tasks.toml").write_text(text.replace(old, new, 1))
    with pytest.raises(ValueError) as err:
        programs.load(robots.load(mjcf), task).trajectory(DT)
    message = str(err.value)
    assert str(tmp_path / "tasks.toml") in message and key in message, message


def test_missing_or_unparsable_tasks_file_is_reported(tmp_path):
    mjcf, text = copy_robot_folder(tmp_path, "puma560")
    robot = robots.load(mjcf)
    with pytest.raises(ValueError, match="tasks.toml"):
        programs.load(robot, "pick_place")
    (tmp_path / "tasks.toml").write_text(text.replace("\n[limits]\n", "\n[limits\n", 1))
    with pytest.raises(ValueError, match="tasks.toml"):
        programs.load(robot, "pick_place")


def test_a_seam_too_fast_for_the_limits_names_the_axis_and_a_speed_that_fits(tmp_path):
    mjcf, text = copy_robot_folder(tmp_path, "irb6700")
    (tmp_path / "tasks.toml").write_text(text.replace("speed = 0.15,", "speed = 1.5,", 1))
    task = programs.load(robots.load(mjcf), "arc_weld")
    with pytest.raises(ValueError, match=r"axis \d.*a speed of about [0-9.]+ m/s would fit"):
        task.trajectory(DT)


def test_a_new_builtin_task_is_a_table_of_the_robot_folders_tasks_file(tmp_path):
    """Adding a task to a robot takes its table in tasks.toml, nothing else: it loads, plans, exports."""
    mjcf, text = copy_robot_folder(tmp_path, "puma560")
    (tmp_path / "tasks.toml").write_text(text + (
        '\n[wave]\nprocess = "handling"\nstart = [0, 92, -122, 30, 0, 0]\nsegment = [\n'
        '    {type = "move", to = [20, 92, -122, 30, 0, 0]},\n    {type = "move", to = [0, 92, -122, 30, 0, 0]},\n]\n'))
    robot = robots.load(mjcf)
    task = programs.builtin(robot, "wave")
    path = task.trajectory(DT)
    assert task.name == "wave" and task.process == "handling" and [s[0] for s in path.segments] == ["move"] * 2
    assert np.degrees(path.q[:, 0].max()) == pytest.approx(20.0)
    assert "Task wave (handling) of puma560" in programs.export(robot, "wave")
    with pytest.raises(ValueError, match=r"unknown task 'wav'; known tasks of puma560: pick_place, .*wave"):
        programs.builtin(robot, "wav")


def test_programs_and_replayed_logs_are_one_kind_of_task(cycles, tmp_path):
    """The built-in tasks are programs, a joint log replays as a task: both satisfy tasks.Task, the
    protocol the simulation reads (programs.load's return type)."""
    task, path = cycles["puma560", "pick_place"]
    log = tmp_path / "log.csv"
    columns = np.column_stack([path.t, path.q])
    np.savetxt(log, columns, delimiter=",", header="t," + ",".join(f"q{k + 1}" for k in range(6)), comments="",
               fmt="%.17g")
    logged = programs.load(task.robot, str(log))
    assert isinstance(task, programs.Program) and isinstance(logged, replay.Replay)
    for each in (task, logged):
        assert isinstance(each, tasks.Task)
        assert each.trajectory(DT).q.shape[1] == len(each.start) == len(each.velocity_limit) == 6
    assert not isinstance(path, tasks.Task)  # a path is no task: the protocol checks what it names
