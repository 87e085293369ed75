"""The fleet: its draws, daily records (the day's maximum), features-only files, the same seed
giving the same fleet bit for bit, and refusals of bad settings."""

import json

import h5py
import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.data import dataset
from faultgen.operation import conditions as c
from faultgen.operation import wear
from faultgen.runs.fleet import Fleet
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim
from resolved_runs import run_config


def test_the_fleet_draws_half_failing_robots_of_both_models():
    fleet = Fleet()
    robots = fleet.robots()
    assert len(robots) == 26 and sum(r["failing"] for r in robots) == 13
    assert {r["model"] for r in robots} == {"irb6700", "puma560"}
    assert len({r["task"] for r in robots}) == 3
    for run_id, config in fleet.runs():
        robot = next(r for r in robots if r["run"] == run_id)
        assert config.daily and not config.signals and config.cycles == 60 * 2
        assert config.wear.worn_axes == ((robot["axis"],) if robot["failing"] else ())
        if robot["failing"]:  # wear starts on the drawn day and reaches failure on the last one
            k = np.array([(robot["onset_day"] - 1) * 2, config.cycles])
            assert config.wear.multipliers(k, 6)[:, robot["axis"] - 1] == pytest.approx([1.0, 1.5])
            assert 10 <= robot["onset_day"] <= 35
    assert fleet.to_json() == Fleet().to_json()
    assert fleet.to_json() != Fleet(seed=1).to_json()
    assert len({r["seed"] for r in robots}) == 26


def test_a_fleet_with_a_task_mix_keeps_every_other_draw():
    """--task-mix adds each robot's second task (another task, drawn last) and changes nothing else
    the fleet draws, so fleets measured before it existed stay as they were."""
    plain, mixed = Fleet().robots(), Fleet(task_mix=True).robots()
    for one, other in zip(plain, mixed, strict=True):
        mix = other["conditions"].pop("task_mix")
        assert one == other and "task_mix" not in one["conditions"]
        assert mix["tasks"][0] == one["task"] and mix["tasks"][1] != one["task"] and mix["pattern"] == "random"
    configs = dict(Fleet(task_mix=True).runs())
    assert all(config.conditions.task_mix is not None and not config.signals for config in configs.values())


@pytest.mark.parametrize(("settings", "message"), [
    ({"failing": 26}, r"fleet failing = 26: expected a whole number within 1..25"),
    ({"days": 3}, r"fleet days \(--days\) = 3"),
    ({"onset": (40, 30)}, r"first <= last"),
    ({"onset": (0, 30)}, r"fleet onset day = 0"),
    ({"cycles_per_day": 0}, r"fleet cycles_per_day \(--cycles-per-day\) = 0"),
    ({"models": ("kuka",)}, r"kuka"),
    ({"models": ()}, r"fleet models = \(\): expected one or more different robot model names"),
    ({"models": ("irb6700", "irb6700")}, r"fleet models = \('irb6700', 'irb6700'\): expected one or more different"),
    ({"models": "irb6700"}, r"fleet models = 'irb6700': expected"),
    ({"dry_share": 1.5}, r"fleet dry_share = 1.5: expected a number within 0..1"),
    ({"without": ("humidity",)}, r"fleet without = \('humidity',\): expected some of thermal, payloads, spread"),
    ({"without": "thermal"}, r"fleet without = 'thermal': expected some of"),
    ({"without": None}, r"fleet without = None: expected some of"),
    ({"without": ("thermal",), "conditions": False}, r"which are all off \(conditions = False\)"),
    ({"without": ("spread",), "gear_loss": 0.1, "friction": "stribeck"}, r"fleet without 'spread' and gear_loss = 0.1"),
    ({"without": ("thermal",), "dry_share": 0.0}, r"fleet without 'thermal' and dry_share = 0.0"),
    ({"dry_share": 0.0, "conditions": False}, r"fleet dry_share = 0.0 sets how friction follows the joint temperature"),
    ({"friction": "coulomb"}, r"unknown friction model 'coulomb'"),
    ({"gear_loss": 0.7, "friction": "stribeck"}, r"fleet gear_loss = 0.7: expected a number within 0..0.5"),
    ({"gear_loss": 0.1}, r"fleet gear_loss = 0.1 needs friction 'stribeck' \(--friction stribeck; got 'lugre'\)"),
    ({"gear_loss": 0.1, "friction": "stribeck", "conditions": False}, r"and the conditions \(got conditions = False\)"),
    ({"fault": "backlash:each:width:0.01:kind=linear"}, r"fleet fault 'backlash:each:width:0.01:kind=linear': the fleet sets"),
    ({"fault": "backlash:each:gap:0.01"}, r"fleet fault 'backlash:each:gap:0.01': .*backlash has no parameter 'gap'"),
])
def test_bad_fleet_settings_are_refused_with_the_value_named(settings, message):
    with pytest.raises(ValueError, match=message):
        Fleet(**settings)


def test_exp4_with_an_onset_at_known_cycles():
    schedule = wear.Schedule("exp4", 0.5, 100, {"onset": 40})
    m = schedule.multiplier(np.array([0, 40, 70, 100]))
    assert m == pytest.approx([1.0, 1.0, 1.5 ** (1 / 16), 1.5])
    assert schedule.to_dict()["onset"] == 40
    assert "onset" not in wear.Schedule("exp4", 0.5, 100).to_dict()  # labels of runs without one unchanged


def test_a_daily_record_is_the_days_maximum():
    """Two cycles a day: each daily value is the larger of the two cycles' values (histograms
    scaled back to a sum of 1), the wear that of the day's last cycle, the temperature their mean."""
    conditions = c.Conditions(thermal=c.Temperature(), spread=c.UnitSpread(), cycles_per_day=2)
    plan = wear.WearPlan.from_specs(["2:exp4:40:onset=1"], last_cycle=6)
    common = {"robot": "puma560", "task": "spot_weld", "wear": plan, "cycles": 6, "nthread": 1, "seed": 4,
              "conditions": conditions}
    cycles = sim.simulate(run_config(**common), progress=False)
    days = sim.simulate(run_config(**common, signals=False, daily=True), progress=False)
    assert days.cycles.tolist() == [1, 2, 3] and days.tau_m.shape == (3, 0, 6)

    def pairs(a):
        return a.reshape(3, 2, *a.shape[1:])

    np.testing.assert_array_equal(days.features["mean_abs_torque"], pairs(cycles.features["mean_abs_torque"]).max(axis=1))
    np.testing.assert_array_equal(days.friction_multiplier, cycles.friction_multiplier[1::2])
    hist = pairs(cycles.features["speed_hist"]).max(axis=1)
    np.testing.assert_allclose(days.features["speed_hist"], hist / hist.sum(axis=-1, keepdims=True))
    np.testing.assert_allclose(days.conditions.joint_temperature,
                               pairs(cycles.conditions.joint_temperature).mean(axis=1))


def test_a_small_fleet_runs_validates_and_repeats_bit_for_bit(tmp_path, shared_fleet):
    """The command's fleet, and the same fleet made again (by the library, once a session: conftest.py's
    shared_fleet, which tests/test_cluster.py compares its cluster's fleet with) hold the same bits."""
    out = tmp_path / "a.h5"
    result = CliRunner().invoke(app, ["fleet", "--robots", "2", "--failing", "1", "--days", "6", "--cycles-per-day",
                                      "1", "--jobs", "1", "--no-progress", "-o", str(out)])
    assert result.exit_code == 0, result.output
    files = [out, shared_fleet("fleet-small", size=2, failing=1, days=6, cycles_per_day=1)]
    assert dataset.validate(files[0]) == []
    labels = dataset.labels(files[0])
    assert sorted(len(row["worn_axes"]) for row in labels) == [0, 1]
    assert all(row["sample"] == "day" and not row["signals"] for row in labels)
    with h5py.File(files[0]) as f:
        assert json.loads(f.attrs["grid"])["fleet"]["size"] == 2
        assert "tau_m" not in f["runs"][labels[0]["run"]]
    for row in labels:
        first, _ = dataset.read_run(files[0], row["run"])
        again, _ = dataset.read_run(files[1], row["run"])
        assert first.keys() == again.keys()
        for name in first:
            np.testing.assert_array_equal(first[name], again[name], err_msg=name)


def test_a_fleet_with_a_gear_loss_keeps_every_other_draw_and_labels_it(shared_fleet_command):
    """--gear-loss adds each unit's gear loss to its spread and changes nothing else the fleet
    draws; the default fleet's settings are stored as before; each robot's file carries its
    unit's draw, and the small fleet validates."""
    plain, lossy = Fleet(friction="stribeck").robots(), Fleet(friction="stribeck", gear_loss=0.1).robots()
    for one, other in zip(plain, lossy, strict=True):
        assert other["conditions"]["spread"].pop("gear_loss") == 0.1
        assert one == other
    assert "gear_loss" not in json.loads(Fleet().to_json())["fleet"]
    # the command (--jobs 1), run once for this test and the fleet page's example (test_help_examples.py);
    # 2 robots: 1 failing
    out, _ = shared_fleet_command("--robots", "2", "--days", "6", "--cycles-per-day", "1", "--friction", "stribeck",
                                  "--gear-loss", "0.1")
    assert dataset.validate(out) == []
    fleet = Fleet(size=2, failing=1, days=6, cycles_per_day=1, friction="stribeck", gear_loss=0.1)
    for run_id, config in fleet.runs():
        arrays, _ = dataset.read_run(out, run_id, names=("gear_loss",))
        np.testing.assert_array_equal(arrays["gear_loss"], config.conditions.spread.draw(config.seed, 6)["gear_loss"])
        assert config.friction == "stribeck" and np.all(arrays["gear_loss"] > 0)


def test_a_fleet_with_another_fault_grows_it_from_the_onset_day_and_labels_it(shared_fleet_command):
    """--fault: each failing robot's drawn axis gets the fault instead of friction wear, growing on
    exp4 from its drawn onset day to FINAL on the failure day; the healthy robots, every draw and
    the default fleet's stored settings are unchanged; the file validates and labels the fault's
    value per day."""
    plain, faulty = Fleet(), Fleet(fault="backlash:each:width:0.01")
    assert plain.robots() == faulty.robots() and "fault" not in json.loads(plain.to_json())["fleet"]
    for (run_id, config), robot in zip(faulty.runs(), faulty.robots(), strict=True):
        assert not config.wear.schedules
        if not robot["failing"]:
            assert config.fault is None
            continue
        onset = (robot["onset_day"] - 1) * 2
        assert (config.fault.effect, config.fault.axis, config.fault.kind) == ("backlash", robot["axis"], "exp4")
        assert config.fault.values(np.array([0, onset, config.cycles])) == pytest.approx([0.0, 0.0, 0.01])
    # the command (--jobs 1), run once for this test and the fleet page's example; 2 robots: 1 failing
    out, _ = shared_fleet_command("--robots", "2", "--days", "6", "--cycles-per-day", "1",
                                  "--fault", "backlash:each:width:0.01")
    assert dataset.validate(out) == []
    small = Fleet(size=2, failing=1, days=6, cycles_per_day=1, fault="backlash:each:width:0.01")
    failing = next((run_id, config) for run_id, config in small.runs() if config.fault is not None)
    arrays, attrs = dataset.read_run(out, failing[0], names=("fault_value",))
    np.testing.assert_allclose(arrays["fault_value"], failing[1].fault.values(np.arange(1, 7)), rtol=1e-12)
    assert arrays["fault_value"][-1] == pytest.approx(0.01) and json.loads(attrs["fault"]) == failing[1].fault.to_dict()


def test_features_only_runs_say_what_they_lack(tmp_path):
    config = run_config("puma560", "pick_place", cycles=2, nthread=1, signals=False,
                           noise=sensors.NoiseConfig(0.0, 0.0))
    dataset.write_run(tmp_path / "f.h5", sim.simulate(config, progress=False))
    assert dataset.validate(tmp_path / "f.h5") == []
    with pytest.raises(dataset.DatasetError, match="recorded without signals"):
        dataset.read_run(tmp_path / "f.h5", names=("tau_m",))
    with pytest.raises(ValueError, match="daily records need every cycle recorded, no signals and whole days"):
        run_config("puma560", "pick_place", cycles=3, daily=True, signals=False,
                      conditions=c.Conditions(spread=c.UnitSpread(), cycles_per_day=2))


@pytest.fixture(scope="module")
def with_and_without_signals(tmp_path_factory):
    """One small sweep made twice, with its signals and features-only (``signals=False``): the PUMA 560's
    spot weld, no wear and axes 0 and 2 worn +60 % over 12 cycles, all recorded; (full, light) paths,
    read only (the features-only tests below both read it: before, each made a pair of its own)."""
    from faultgen.runs import sweep

    folder = tmp_path_factory.mktemp("signals")
    common = {"robots": ["puma560"], "tasks": ["spot_weld"], "axes": [0, 2], "cycles": 12, "increases": [60.0]}
    full, light = folder / "full.h5", folder / "light.h5"
    sweep.run(sweep.Grid(**common), full, progress=False)
    sweep.run(sweep.Grid(**common, signals=False), light, progress=False)
    return full, light


def test_a_features_only_sweep_is_small_and_isolates(with_and_without_signals):
    """`faultgen sweep --features-only`: no signals in the file, a fraction of the size, and the
    isolation benchmark runs on the stored per-cycle features."""
    from analysis import benchmark

    full, light = with_and_without_signals
    assert dataset.validate(light) == []
    assert light.stat().st_size < 0.2 * full.stat().st_size
    table = benchmark.isolation_table(light, progress=False)
    assert set(table["worn_axis"]) == {0, 2}
    same = benchmark.isolation_table(full, progress=False)
    assert table["predicted"].tolist() == same["predicted"].tolist()


def test_the_c2_preset_keeps_features_only_unless_asked_for_signals(tmp_path):
    small = ["--preset", "c2", "--task", "spot_weld", "--axis", "0", "--cycles", "2", "--record", "2", "--no-progress"]
    for flag, has_signals in (([], False), (["--signals"], True), (["--features-only"], False)):
        out = tmp_path / f"c2{''.join(flag)}.h5"
        result = CliRunner().invoke(app, ["sweep", *small, *flag, "-o", str(out)])
        assert result.exit_code == 0, result.output
        with h5py.File(out) as f:
            run = f["runs"][next(iter(f["runs"]))]
            assert ("tau_m" in run) is has_signals and "torque_counts" in run, flag


def test_detection_gives_the_same_table_with_and_without_signals(with_and_without_signals, tmp_path):
    """The stored fine torque counts equal those computed from the stored signals, bit for bit, so
    `faultgen detect` gives the same table on a features-only sweep as on the same sweep with signals
    (the scale of its bins rounded to whole percent of the peak torque, the training maximum inside
    the last bin)."""
    from analysis import benchmark
    from faultgen.model import robots

    full, light = with_and_without_signals
    peak = robots.load("puma560").motor_torque_limit
    for run_id in dataset.list_runs(full):
        signals, _ = dataset.read_run(full, run_id, names=("tau_m", "torque_counts"))
        stored, _ = dataset.read_run(light, run_id, names=("torque_counts",))
        np.testing.assert_array_equal(stored["torque_counts"], sensors.torque_counts(signals["tau_m"], peak))
        np.testing.assert_array_equal(stored["torque_counts"], signals["torque_counts"])
        assert stored["torque_counts"].sum(axis=-1).min() == signals["tau_m"].shape[1]
    scale = benchmark.detection_scale([stored["torque_counts"]])
    largest = np.abs(signals["tau_m"].astype(np.float64)).max(axis=(0, 1))
    assert np.all((scale - 1) / 100 * peak <= largest) and np.all(largest < scale / 100 * peak)
    old = tmp_path / "old.h5"  # signals without stored counts, as written before they existed
    old.write_bytes(full.read_bytes())
    with h5py.File(old, "r+") as f:
        for run_id in f["runs"]:
            del f["runs"][run_id]["torque_counts"]
    assert dataset.validate(old) == []
    from_signals = benchmark.detection_table(old, protocol="same-run", progress=False)
    features_only = benchmark.detection_table(light, protocol="same-run", progress=False)
    pd.testing.assert_frame_equal(features_only, from_signals)
    pd.testing.assert_frame_equal(benchmark.detection_table(full, protocol="same-run", progress=False), from_signals)
    assert from_signals["detected"].all()  # 60 % wear in 12 cycles: a table worth comparing


def test_the_fleet_command_refuses_bad_settings_before_simulating(tmp_path):
    result = CliRunner().invoke(app, ["fleet", "--robots", "2", "--failing", "2", "-o", str(tmp_path / "f.h5")])
    assert result.exit_code == 2
    assert "error: fleet failing = 2: expected a whole number within 1..1" in result.output
    assert not (tmp_path / "f.h5").exists() and not list(tmp_path.iterdir())


def test_the_fleet_command_passes_its_robot_models_and_left_out_conditions(tmp_path, monkeypatch):
    """--robot (repeated) sets the fleet's models: every robot of a one-model fleet is that model,
    and with two the order given is the order taken; every other draw is the default fleet's.
    --without (repeated) reaches the fleet too."""
    from faultgen.cli import runs as run_commands

    plans = []
    monkeypatch.setattr(run_commands, "run_sweep", lambda plan, out, **kwargs: plans.append(plan))
    for robots in (["irb6700"], ["puma560", "irb6700"]):
        args = ["fleet", "-o", str(tmp_path / "f.h5")] + [x for r in robots for x in ("--robot", r)]
        assert CliRunner().invoke(app, args).exit_code == 0
    one, two = (plan.robots() for plan in plans)
    assert plans[0].models == ("irb6700",) and {r["model"] for r in one} == {"irb6700"}
    assert [r["model"] for r in two[:4]] == ["puma560", "irb6700", "puma560", "irb6700"]
    default = Fleet().robots()
    assert [(r["task"], r["failing"], r["axis"]) for r in one] == [(r["task"], r["failing"], r["axis"]) for r in default]
    assert CliRunner().invoke(app, ["fleet", "--without", "payloads", "--without", "spread", "-o",
                                    str(tmp_path / "f.h5")]).exit_code == 0
    assert plans[2].without == ("payloads", "spread")
    result = CliRunner().invoke(app, ["fleet", "--robot", "kuka", "-o", str(tmp_path / "k.h5")])
    assert result.exit_code == 2 and "kuka" in result.output and not (tmp_path / "k.h5").exists()


def test_a_fleet_with_another_dry_share_keeps_every_other_draw():
    """--dry-share sets how every robot's dry friction follows its joint temperature; every other
    draw is the default fleet's, and the default fleet's stored settings do not name it."""
    plain, flat = Fleet().robots(), Fleet(dry_share=0.0).robots()
    for one, other in zip(plain, flat, strict=True):
        assert other["conditions"]["thermal"].pop("dry_share") == 0.0
        assert one == other
    assert "dry_share" not in json.loads(Fleet().to_json())["fleet"]
    assert json.loads(Fleet(dry_share=0.0).to_json())["fleet"]["dry_share"] == 0.0
    config = dict(Fleet(dry_share=0.0).runs())[flat[0]["run"]]
    assert config.conditions.thermal.dry_share == 0.0


def test_a_fleet_without_one_condition_keeps_the_others_as_drawn():
    """--without leaves the named conditions out of every robot; the kept ones, and every other
    draw, are the full fleet's, and the full fleet's stored settings do not name it."""
    full = Fleet().robots()
    for without in (("thermal",), ("payloads",), ("spread", "thermal")):
        for one, other in zip(full, Fleet(without=without).robots(), strict=True):
            kept = {k: v for k, v in one["conditions"].items() if k not in without}
            assert other["conditions"] == kept and {**one, "conditions": kept} == other
    assert Fleet(without=("spread", "thermal")).without == ("thermal", "spread")
    assert "without" not in json.loads(Fleet().to_json())["fleet"]
    config = dict(Fleet(without=("payloads",)).runs())[full[0]["run"]]
    assert config.conditions.payloads is None and config.conditions.thermal is not None
    assert config.conditions.spread is not None


def test_a_daily_run_is_stepped_in_blocks_of_days_with_the_same_arrays(monkeypatch):
    """A fleet robot's cycles are stepped a block of whole days at a time, each reduced to its days
    before the next (its memory does not grow with its days), and give the arrays of one block."""
    config = dict(Fleet(size=2, failing=1, days=6, onset=(1, 3), task_mix=True, seed=2).runs())
    run_id = next(r for r in config if "failing" in r)
    stepped = []
    step = sim._simulate_task
    monkeypatch.setattr(sim, "_simulate_task", lambda c, task, cycles, *rest: stepped.append(len(cycles)) or step(
        c, task, cycles, *rest))
    monkeypatch.setattr(sim, "DAILY_BLOCK_CYCLES", 1000)
    whole = sim.simulate(config[run_id], progress=False)
    assert sum(stepped) == 12
    stepped.clear()
    monkeypatch.setattr(sim, "DAILY_BLOCK_CYCLES", 5)  # two days of two cycles at a time
    blocks = sim.simulate(config[run_id], progress=False)
    assert sum(stepped) == 12 and max(stepped) <= 4
    assert blocks.cycles.tolist() == whole.cycles.tolist() == [1, 2, 3, 4, 5, 6]
    for name in ("friction_multiplier", "mean_friction_torque", "tracking_error", "tau_m"):
        assert np.array_equal(getattr(blocks, name), getattr(whole, name)), name
    assert blocks.features.keys() == whole.features.keys()
    for name, value in whole.features.items():
        assert np.array_equal(blocks.features[name], value), name
    for name in ("day", "joint_temperature", "payload_mass", "task_index", "link_mass_factor"):
        assert np.array_equal(getattr(blocks.conditions, name), getattr(whole.conditions, name)), name
