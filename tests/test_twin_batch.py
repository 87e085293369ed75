"""A twin's signature cycles (the healthy cycle at the model's own friction and one per worn axis)
simulated together as one batch (``stepping.simulate``'s ``dry_multipliers``) are the bits of the
same cycles simulated one by one, as the twin did before (and still does for a cycle asked alone);
``dry_multipliers`` refuses what it cannot mean, by name. A twin reads (or simulates) each cycle
once and keeps it (issue 87 item 2: no re-read of the twin per log)."""

import json

import numpy as np
import pytest

from faultgen.calibrate import synth
from faultgen.model import robots
from faultgen.monitor.twin import REFERENCE_TEMPERATURE, Twin, setup
from faultgen.operation.wear import Schedule, WearPlan
from faultgen.simulation import stepping as sim
from resolved_runs import run_config


@pytest.fixture(scope="module")
def program(tmp_path_factory):
    robot = robots.load("puma560")
    log = synth.record(robot, synth.Hidden(None), tmp_path_factory.mktemp("program") / "log.csv", cycles=1, seed=1)
    return robot, log


def test_the_signature_cycles_of_one_batch_are_the_bits_of_one_by_one(program, tmp_path):
    robot, log = program
    together = Twin(robot, log, tmp_path / "together")  # made: its signature cycles in one batch
    apart = Twin(robot, log, tmp_path / "apart", cycles=False)
    own = float("nan")
    healthy = apart.cycle(own, 0.0)  # one at a time: nothing cached, each its own simulation
    worn = [apart.cycle(own, 0.0, axis) for axis in range(1, robot.n_axes + 1)]
    # the healthy expectation at the reference temperature is the cycle at the model's own friction
    np.testing.assert_array_equal(apart.cycle(REFERENCE_TEMPERATURE, 0.0), healthy)
    np.testing.assert_array_equal(together.cycle(own, 0.0), healthy)
    for axis, vector in enumerate(worn, start=1):
        np.testing.assert_array_equal(together.cycle(own, 0.0, axis), vector)
    np.testing.assert_array_equal(together.signatures, np.stack([(v - healthy) / 40.0 for v in worn]))
    assert np.all(np.abs(together.signatures).max(axis=1) > 0)  # every axis's wear moves some feature
    cached = sorted(p.name for p in (tmp_path / "together").glob("*.json"))
    assert len(cached) == robot.n_axes + 1  # the base cycles: healthy and one per worn axis, once each
    assert cached == sorted(p.name for p in (tmp_path / "apart").glob("*.json"))
    for name in cached:  # the cache files too: key and features
        assert (tmp_path / "together" / name).read_bytes() == (tmp_path / "apart" / name).read_bytes()


def test_dry_multipliers_are_refused_with_a_wear_plan_or_the_wrong_shape(program):
    robot, _ = program
    config = run_config(robot=robot, task="pick_place", friction="stribeck", cycles=2, seed=0)
    with pytest.raises(ValueError, match=r"^dry_multipliers of shape \(2, 5\): expected finite numbers > 0 of "
                                         r"shape \(2, 6\), one row per recorded cycle and a column per axis$"):
        sim.simulate(config, progress=False, dry_multipliers=np.ones((2, 5)))
    with pytest.raises(ValueError, match=r"^dry_multipliers of shape \(2, 6\): expected finite numbers > 0"):
        sim.simulate(config, progress=False, dry_multipliers=np.zeros((2, 6)))
    worn = run_config(robot=robot, task="pick_place", friction="stribeck", cycles=2, seed=0,
                         wear=WearPlan({2: Schedule("exp4", 0.2, 2)}))
    with pytest.raises(ValueError, match=r"^dry_multipliers are given instead of a wear plan and without daily "
                                         r"records; this run has friction wear \(a wear plan or a fault\)$"):
        sim.simulate(worn, progress=False, dry_multipliers=np.ones((2, 6)))


def test_the_reference_temperature_leaves_the_models_friction_as_it_is(program, tmp_path):
    """Why the twin reads its healthy expectation at REFERENCE_TEMPERATURE from the cycle at the
    model's own friction: simulated with the joints held at that temperature (the thermal condition
    and faultgen's temperature law on), the cycle is the same (bits here; 1e-12 asked)."""
    robot, log = program
    twin = Twin(robot, log, tmp_path / "cycles", cycles=False)
    held, plan = setup(REFERENCE_TEMPERATURE, 0.0)
    assert held.thermal is not None
    warm = sim.simulate(twin._config(REFERENCE_TEMPERATURE, 0.0, plan), progress=False)
    np.testing.assert_allclose(twin._features(warm), twin.cycle(float("nan"), 0.0), rtol=1e-12, atol=0)


def test_a_cycle_is_read_once_a_twin_and_a_new_twin_checks_the_file(program, tmp_path):
    robot, log = program
    cache = tmp_path / "cycles"
    twin = Twin(robot, log, cache, cycles=False)
    own = float("nan")
    first = twin.cycle(own, 0.0)  # simulated and cached
    (path,) = cache.glob("*.json")
    stored = json.loads(path.read_text())
    np.testing.assert_array_equal(first, stored["features"])
    first[:] = 0.0  # a caller's change to what it was handed stays its own
    stored["key"]["payload_kg"] = 1.0  # the file tampered with after it was read
    path.write_text(json.dumps(stored))
    again = twin.cycle(own, 0.0)
    np.testing.assert_array_equal(again, json.loads(path.read_text())["features"])
    assert again is not twin.cycle(own, 0.0)
    with pytest.raises(ValueError, match=rf"{path.name}: not the cached twin cycle of"):
        Twin(robot, log, cache, cycles=False).cycle(own, 0.0)  # read again by a new twin, and checked
