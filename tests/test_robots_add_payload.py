"""`faultgen robots add` sizes the drives from what the user knows (issue 60, part 3): the rated
payload given with ``--payload`` is carried on every built-in task, a guessed one is said to be a
guess, a URDF's effort limits are the drives' torque limits, and implausible masses (from meshes,
placeholders) are flagged at add time with what to do.

The robots: rtb-data's ROS-Industrial KUKA KR210 L150 URDF (datasheet: rated payload 150 kg for the
L150 variant) and LBR iiwa 14 R820 URDF (14 kg), the URDFs tests/test_robot_import.py checks
against Pinocchio. The part carried is the sizing's rated load (``sizing.rated_load``): a cube of the
rated payload whose centre of mass lies ``sizing.load_offset`` out along the flange's z axis,
attached as ``faultgen.operation.conditions.Payloads`` attaches every part.
"""

import re
import time
import warnings

import numpy as np
import pytest
from test_robot_import import PACKAGES, UR5, URDFS
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.model import importers, plausibility, robots, sizing
from faultgen.operation import conditions, taskgen, wear
from faultgen.operation.tasks import TASKS
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim
from resolved_runs import run_config

#: Robot, rated payload (kg, the makers' datasheets) and the ROS package its meshes name.
RATED = {"kr210": (150.0, "kuka_kr210_support"), "iiwa14": (14.0, "kuka_lbr_iiwa_support")}


def run(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


@pytest.mark.parametrize("name", sorted(RATED))
def test_the_rated_payload_given_is_carried_on_every_task_without_saturating(name, tmp_path):
    payload, package = RATED[name]
    out = tmp_path / name
    started = time.perf_counter()
    result = run("robots", "add", name, "--from", URDFS[name], "--package", f"{package}={PACKAGES[package]}",
                 "--payload", payload, "-o", out)
    assert result.exit_code == 0, result.output
    assert f"rated payload {payload:g} kg, given with --payload" in result.output
    assert "GUESSED" not in result.output
    robot = robots.load(out)
    assert robot.rated_payload == payload
    load = sizing.rated_load(payload)
    part = conditions.Payloads((payload,), (load["edge"],))
    assert part.parameters(0)["com_z"] == load["com_z"] == sizing.load_offset(payload)  # the documented offset
    peaks = {}
    for task in TASKS:  # one cycle of each, the rated load at the flange
        config = run_config(robot=str(out), task=task, friction="lugre", wear=wear.WearPlan({}), cycles=1,
                               seed=0, noise=sensors.NoiseConfig(disturbance=0.0, encoder=0.0), nthread=1,
                               conditions=conditions.Conditions(payloads=part))
        simulated = sim.simulate(config, progress=False)
        peaks[task] = np.max(np.abs(simulated.tau_m), axis=(0, 1)) / robot.motor_torque_limit
        assert simulated.saturated.size == 0, (name, task, simulated.saturated, peaks[task])
    print(f"\n{name} --payload {payload:g}: capacity G x T [N m] "
          f"{np.array2string(robot.gear_ratio * robot.motor_torque_limit, precision=4)}; peak |tau_m| / limit "
          + "; ".join(f"{t} {np.array2string(p, precision=2)}" for t, p in peaks.items())
          + f" ({time.perf_counter() - started:.1f} s)")


def test_the_payload_sizes_the_wrist_with_its_inertia_not_gravity_alone():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", importers.GeometryDropped)
        arm = importers.read(URDFS["kr210"], PACKAGES)
    light, heavy = sizing.sized(arm, payload=50.0), sizing.sized(arm, payload=150.0)
    # every drive grows with the payload, the wrist's most
    capacity = [np.array([a.gear_ratio * a.motor_torque_limit for a in s.drivetrain.axes]) for s in (light, heavy)]
    assert np.all(capacity[1] > capacity[0]) and capacity[1][5] > 2 * capacity[0][5]
    # axis 6 must accelerate the load, not only hold it
    assert heavy.loads.need[5] > 3 * heavy.loads.gravity[5]
    assert heavy.loads.offset == pytest.approx(0.2466, abs=1e-4) and light.loads.offset == pytest.approx(0.171, abs=1e-3)
    assert "rated load of 150 kg" in heavy.origin[6]["motor_torque_limit"]
    # the planning limits the sizing assumes are the generated tasks'
    assert sizing.RAMP == taskgen.RAMP
    speed, acceleration = sizing.planning_limits(arm)
    np.testing.assert_allclose(speed, arm.speed_limit)
    np.testing.assert_allclose(acceleration, speed / [0.45, 0.45, 0.45, 0.3, 0.3, 0.3])


def test_load_offset_follows_the_load_diagrams():
    assert sizing.load_offset(3.0) == 0.1 and sizing.load_offset(10.0) == pytest.approx(0.1)
    assert sizing.load_offset(60.0) == pytest.approx(0.182, abs=1e-3)  # ABB IRB 4600-60: 0.2 m
    assert sizing.load_offset(210.0) == pytest.approx(0.276, abs=1e-3)  # KUKA KR QUANTEC: 0.24-0.27 m
    assert sizing.load_offset(2000.0) == 0.3


def test_a_guessed_payload_is_said_and_placeholder_masses_are_flagged(tmp_path):
    text = UR5.read_text().replace("rated_payload = 5.0\n", "")
    text = re.sub(r"(?m)^effort = .*\n", "", text)  # no effort limits: the drives are sized
    text = re.sub(r"(?m)^mass = .*$", "mass = 2.0", text)
    text = re.sub(r"(?m)^inertia = .*$", "inertia = [0.01, 0.01, 0.01, 0.0, 0.0, 0.0]", text)
    source = tmp_path / "arm.toml"
    source.write_text(text)
    out = tmp_path / "ph"
    result = run("robots", "add", "ph", "--from", source, "-o", out)
    assert result.exit_code == 0, result.output
    assert ("warning: rated payload 1.8 kg GUESSED from 15 % of the moving mass; give --payload KG if you know it "
            "(the datasheet's rated payload): it sizes the drives and decides which parts the monitor's twin "
            "can carry") in result.output
    assert ("warning: every moving link (6) has the mass 2 kg and the inertia 0.01, 0.01, 0.01 kg m^2: placeholder "
            "values, not the arm's; give a URDF with the real inertials") in result.output
    assert re.search(r"plausibility: 6 axes, reach 0\.9\d* m, moving mass 12 kg .* rated payload 1\.8 kg "
                     r"\(0\.15 of the moving mass\): 2 finding\(s\)", result.output), result.output
    readme = (out / "README.md").read_text()
    assert "## Plausibility" in readme and "GUESSED" in readme and "placeholder values" in readme
    # the same arm with the payload given: no guess; the payload against the mass flagged
    given = run("robots", "add", "ph", "--from", source, "--payload", 10, "-o", tmp_path / "ph10")
    assert given.exit_code == 0, given.output
    assert "GUESSED" not in given.output
    assert ("rated payload 10 kg is 0.833 of the moving mass 12 kg; industrial arms of 6 axes carry 0.05-0.5 "
            "of theirs") in given.output


def test_masses_from_meshes_and_an_arm_too_light_for_its_reach_are_flagged():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", importers.GeometryDropped)
        iiwa = importers.read(URDFS["iiwa14"], PACKAGES)
        kr210 = importers.read(URDFS["kr210"], PACKAGES)
    assert iiwa.mesh_inertials == ["base_link", "link_1", "link_2", "link_3", "link_4", "link_5", "link_6", "link_7"]
    summary, found = plausibility.report(iiwa, 14.0, False, 18.55, 0.82)
    assert "7 axes, reach 0.82 m, moving mass 18.55 kg" in summary
    assert len(found) == 1 and found[0].startswith("moving links link_1, link_2, link_3, link_4, link_5, link_6, link_7: masses computed from their meshes") and "1000 kg/m^3" in found[0]
    # a 7-axis arm may carry up to its own moving mass; a 6-axis one half of it
    _, found = plausibility.report(kr210, 150.0, False, 3306.0, 3.1)
    assert found == [] or "0.0454 of the moving mass 3306 kg" in found[0]
    _, found = plausibility.report(kr210, 150.0, False, 100.0, 3.1)
    assert any("1.5 of the moving mass" in f for f in found)
    assert any("100 kg for a reach of 3.1 m is 3.36 kg per m^3" in f for f in found)


def test_urdf_effort_limits_are_the_drives_torque_limits_at_the_arm_side(tmp_path):
    efforts = [80000.0, 90000.0, 40000.0, 4000.0, 4000.0, 30.0]  # axis 6 below what 150 kg needs
    text = URDFS["kr210"].read_text()
    for effort, joint in zip(efforts, [f"joint_a{k}" for k in range(1, 7)]):
        text = re.sub(rf'(<joint name="{joint}".*?<limit) effort="0"', rf'\1 effort="{effort:g}"', text,
                      flags=re.DOTALL)
    path = tmp_path / "kr210.urdf"
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", importers.GeometryDropped)
        arm = importers.read(path, PACKAGES)
    np.testing.assert_array_equal(arm.effort_limit, efforts)
    out = sizing.sized(arm, payload=150.0)
    G = np.array([a.gear_ratio for a in out.drivetrain.axes])
    np.testing.assert_allclose(np.array([a.motor_torque_limit for a in out.drivetrain.axes]) * G, efforts,
                               rtol=1e-12)
    assert out.origin[6]["motor_torque_limit"] == "sized: the source's effort limit 30 N m / G (arm side)"
    _, found = plausibility.report(arm, 150.0, False, out.moving_mass, 3.1, out.loads)
    low = [f for f in found if f.startswith("axis ")]
    assert len(low) == 1 and low[0].startswith("axis 6: the source's effort limit 30 N m is below the ")
    assert f"{out.loads.need[5]:.4g} N m the rated load (150 kg" in low[0]
