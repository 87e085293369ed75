"""``faultgen monitor`` on a small fleet made by a simulator that is not faultgen
(tests/independent_fleet.py: Pinocchio's dynamics of rtb-data's KR210 URDF, our own motor-side
friction, seasons, payload changes, noise, wear on one unit). The full check, 12 units x 120
days, is ``benchmarks/monitor_loop.py`` (docs/analysis.md, "Monitor your own robots")."""

import csv
import filecmp
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import independent_fleet
import numpy as np
import pytest

from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import loop, scoring, steps
from faultgen.monitor.run import resolve_run
from faultgen.monitor.scoring import Settings
from faultgen.runs.context import ExecutionContext
from resolved_runs import run_config

# three units, 40 days, one of them worn from day 16-17 (10 % on day 20-21, 40 % on day 32-33)
SPEC = independent_fleet.FleetSpec(units=3, worn=1, days=40, seed=5, onset=(16, 17))
SETTINGS = Settings(train=14, persistence=3)
#: The units of the killed run and of the planted folder: unit01, whose program the twin replays, and the
#: worn unit02 (unit03, healthy like unit01, would only add its 40 logs and its charts to their runs).
KEPT = ("unit01", "unit02")


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    root = tmp_path_factory.mktemp("fleet")
    robot, logs, truth = independent_fleet.write_fleet(root, SPEC)
    return robot, logs, truth


@pytest.fixture(scope="module")
def monitored(fleet, tmp_path_factory):
    robot, logs, truth = fleet
    out = tmp_path_factory.mktemp("monitor") / "out"
    loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False))
    return out


def with_cycles_of(monitored: Path, out: Path) -> Path:
    """``out`` holding the twin's simulated cycles of ``monitored`` (content-addressed: the same
    model, program and conditions give the same file), so that a test of the loop's bookkeeping
    does not simulate them again."""
    shutil.copytree(monitored / ".cache" / "cycles", out / ".cache" / "cycles")
    return out


def test_the_worn_unit_alarms_in_its_window_with_the_worn_axis_first_and_the_healthy_do_not(fleet, monitored):
    _, _, truth = fleet
    outcome = independent_fleet.evaluate(truth, monitored / "alarms.csv")
    worn = [u for u, o in outcome.items() if o["axis"]]
    assert len(worn) == 1, outcome
    for unit, o in outcome.items():
        if o["axis"]:
            assert o["in_window"], (unit, o)  # 10 % <= wear at the first alarm < 40 %
            assert o["source"] == o["axis"], (unit, o)
        else:
            assert not o["alarm"], (unit, o)
    assert {p.name for p in monitored.glob("*.png")} == {f"{u}.png" for u in outcome}


def test_same_seed_gives_identical_outputs(fleet, monitored, tmp_path):
    """The fleet again from the same seed: identical logs, byte for byte. Identical outputs from the
    same logs (alarms, scores, rul, wear, life, units and charts, byte for byte) are
    test_two_jobs_give_the_outputs_of_one's assertions (a run of its own that simulates four of the
    twin's cycles again in its workers); two runs each on an empty cache, every output but the cache
    the same bytes, are tests/test_monitor_cluster.py's (the local run and the cluster's); a run here
    on logs equal to the fleet's checked nothing more (docs/performance.md)."""
    robot, first_logs, _ = fleet
    _, logs, _ = independent_fleet.write_fleet(tmp_path / "again", SPEC, robot=robot)
    assert sorted(p.relative_to(logs) for p in logs.rglob("*.csv")) == \
        sorted(p.relative_to(first_logs) for p in first_logs.rglob("*.csv"))
    for path in logs.rglob("*.csv"):
        assert filecmp.cmp(path, first_logs / path.relative_to(logs), shallow=False), path


def test_rul_csv_gives_the_worn_axis_an_end_of_life_and_the_healthy_units_none(fleet, monitored):
    """rul.csv: every unit and axis at its last log; the worn axis (wear 60 % on the last day, still
    growing) a remaining life with its interval, the healthy
    units no end of life within the horizon (faultgen.monitor.prognosis; tests/test_prognosis.py)."""
    from faultgen.monitor import prognosis, trends

    _, _, truth_path = fleet
    truth = independent_fleet.read_truth(truth_path)
    with open(monitored / "rul.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert {(r["unit"], int(r["axis"])) for r in rows} == {(u, a) for u in truth for a in range(1, 7)}
    for r in rows:
        t = truth[r["unit"]]
        assert r["stamp"] == t["stamps"][-1] and r["time_unit"] == "days", r
        if t["axis"] and int(r["axis"]) == t["axis"]:
            assert r["model"] in trends.MODELS and r["logs_fitted"] != "", r
            assert 0 <= float(r["rul_5"]) <= float(r["rul"]) <= float(r["rul_95"]) < prognosis.HORIZON, r
        elif not t["axis"]:
            assert r["rul"] == "" and "no end of life within the horizon (365 days)" in r["verdict"], r


def test_life_csv_gives_each_axis_the_life_its_load_consumed_and_the_page_shows_it(fleet, monitored):
    """life.csv (faultgen.monitor.life): a row per unit and axis; one log's load in the state gives
    that log's consumption by the formula (test_life.py checks the formula by hand), the consumed % the sum
    of each log's % per day times the days since the log before it, and the page shows each unit's."""
    import csv
    import json
    from datetime import datetime

    from faultgen.logs import measured
    from faultgen.model import robots
    from faultgen.monitor import life

    robot, logs, _ = fleet
    nominal = robots.load(robot)
    with open(monitored / "life.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    units = sorted(p.name for p in logs.iterdir() if p.is_dir())
    assert [(r["unit"], int(r["axis"])) for r in rows] == [(u, a) for u in units for a in range(1, nominal.n_axes + 1)]
    page = (monitored / "report.html").read_text()
    assert "Rated life consumed by load (life.csv)" in page and "service by" in page
    for unit in units:
        entries = json.loads((monitored / ".state" / f"{unit}.json").read_text())["logs"]
        first = sorted((logs / unit).iterdir())[0]
        data = measured.read(first, nominal)
        ratings = life.ratings_of(nominal)
        shares = life.consumed(np.reshape(entries[0]["load"], (2, -1)), ratings)
        assert shares == pytest.approx(life.consumption(data.t, data.qd, data.tau, ratings), rel=1e-12, nan_ok=True)
        assert entries[0]["duration_s"] == data.t[-1] - data.t[0]
        mine = [r for r in rows if r["unit"] == unit]
        for r in mine:
            k = int(r["axis"]) - 1
            g = ratings[k]
            if g.unrated:  # no catalogue size carries the KR210's main axes (issue 90): no consumption, no date
                assert r["consumed_pct"] == r["days_left"] == "" and r["verdict"] == g.unrated
                continue
            p = 0 if g.gearbox_type == "strain-wave" else 1  # the row of that exponent's integral
            shares = [e["load"][p * nominal.n_axes + k] / (g.rated_speed * g.rated_torque ** g.exponent * g.rated_life
                                                           * 3600) for e in entries]
            per_day = [share / e["duration_s"] * 16 * 3600 * 100 for share, e in zip(shares, entries)]  # 16 h a day
            stamps = [datetime.fromisoformat(e["stamp"]) for e in entries]
            days = [(b - a).total_seconds() / 86400 for a, b in zip(stamps, stamps[1:])]
            assert float(r["consumed_pct"]) == pytest.approx(sum(p * d for p, d in zip(per_day[1:], days)), rel=1e-5)
            assert float(r["duty_pct_per_day"]) == pytest.approx(np.mean(per_day[-life.WINDOW:]), rel=1e-5)
            assert float(r["consumed_pct"]) > 0 and r["since"] == entries[0]["stamp"] and r["stamp"] == entries[-1]["stamp"]
        assert life.table_cell(mine).split(":")[0] in page


def test_a_log_older_than_the_last_scored_is_named_and_not_scored(fleet, monitored, tmp_path):
    robot, logs, _ = fleet
    out = with_cycles_of(monitored, tmp_path / "out")
    folder = tmp_path / "logs" / "unit01"
    folder.mkdir(parents=True)
    units = sorted(logs.iterdir())
    files = sorted(units[0].iterdir())
    for log in [files[0], *files[2:16]]:
        os.link(log, folder / log.name)
    loop.monitor(resolve_run(robot, folder.parent, out, calibrate=False, settings=SETTINGS, progress=False))
    os.link(files[1], folder / files[1].name)
    again = loop.monitor(resolve_run(robot, folder.parent, out, calibrate=False, settings=SETTINGS, progress=False))
    assert f"not scored (logs are scored in stamp order): unit01/{files[1].name}" in again.statuses[0].reason
    assert again.statuses[0].logs_scored == 15 and again.statuses[0].status == "degraded"


def test_a_killed_monitor_leaves_no_output_and_the_rerun_finishes(fleet, monitored, tmp_path):
    """On the fleet's :data:`KEPT` units."""
    import json

    robot, whole, _ = fleet
    logs = tmp_path / "logs"
    for unit in KEPT:
        (logs / unit).mkdir(parents=True)
        for log in (whole / unit).iterdir():
            os.link(log, logs / unit / log.name)
    out = with_cycles_of(monitored, tmp_path / "out")
    cycles = out / ".cache" / "cycles"
    shared = [p for p in sorted(cycles.iterdir()) if json.loads(p.read_text())["key"]["payload_kg"] == 0.0]
    for path in shared[:2]:  # two of the twin's cycles to simulate again (without a part: every run needs them)
        path.unlink()
    left = len(list(cycles.iterdir()))
    command = [sys.executable, "-m", "faultgen.cli", "monitor", str(logs), "--robot", str(robot), "-o", str(out),
               "--no-calibrate", "--train", "14", "--persistence", "3"]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path(__file__).parents[1]), os.environ.get("PYTHONPATH", "")])}
    process = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while len(list(cycles.iterdir())) == left:  # killed once it has simulated one of them
        assert process.poll() is None and time.monotonic() < deadline, "the monitor ended before it was killed"
        time.sleep(0.02)
    process.send_signal(signal.SIGKILL)
    process.wait()
    assert not (out / "alarms.csv").exists() and not (out / "scores.csv").exists()
    assert not list(out.glob("*.png")) and not (out / ".state").exists()
    from typer.testing import CliRunner  # the rerun is not killed: the same command, in this process

    from faultgen.cli import app

    result = CliRunner().invoke(app, command[3:])
    assert result.exit_code == 0, result.output[-2000:]
    kept = [line for line in (monitored / "alarms.csv").read_text().splitlines()
            if not line.startswith("unit03,")]
    assert (out / "alarms.csv").read_text().splitlines() == kept and len(kept) == 3


def test_bad_settings_and_an_empty_folder_are_refused(fleet, tmp_path):
    robot, _, _ = fleet
    with pytest.raises(ValueError, match="protocol = 'magic'"):
        Settings(protocol="magic")
    (tmp_path / "logs").mkdir()
    with pytest.raises(ValueError, match="no unit folders"):
        loop.monitor(resolve_run(robot, tmp_path / "logs", tmp_path / "out", calibrate=False, progress=False))
    assert not (tmp_path / "out").exists()


def _synthetic_unit(seed: int, wear: float, interval: bool) -> bool:
    """A unit whose 12 features follow the joint temperature linearly (drawn slopes, unit noise);
    it learns on 28 logs at 20-24 deg C and is then scored at 26-34 deg C (summer after a spring
    start), from log 40 on with a wear growing along a drawn direction (``wear`` = 0: healthy).
    Returns whether it raised a persistent alarm."""
    rng = np.random.default_rng(seed)
    slope, direction = rng.normal(0, 1, 12), np.abs(rng.normal(0, 1, 12))
    unit = steps.start("u", Settings(protocol="own"), n_axes=6)
    if not interval:
        unit.stages.baseline.prediction_factor = lambda conditions: 1.0
    for i in range(90):
        temperature = rng.uniform(*((20, 24) if i < 28 else (26, 34)))
        residual = slope * temperature + rng.normal(0, 1, 12) + wear * 0.2 * max(i - 40, 0) * direction
        steps.add(unit, f"{i:03d}", residual, temperature, 100.0)
    return unit.stages.alarm.first_alarm is not None


def test_warmer_logs_than_the_learning_ones_do_not_alarm_a_healthy_unit_and_a_worn_one_still_alarms():
    # the slope learned over 4 K and extrapolated 2-10 K beyond it is known only to its standard
    # error: scored against the regression's prediction interval a healthy unit stays quiet, scored
    # against the noise alone about half of them alarm (the fleet's warm-day false alarms)
    seeds = range(20)
    assert sum(_synthetic_unit(s, 0.0, interval=True) for s in seeds) <= 1
    assert sum(_synthetic_unit(s, 0.0, interval=False) for s in seeds) >= 5
    assert all(_synthetic_unit(s, 1.0, interval=True) for s in seeds)


def test_the_prediction_interval_is_one_plus_the_learning_mean_inside_and_grows_outside():
    rng = np.random.default_rng(0)
    unit = steps.start("u", Settings(protocol="own", train=10), n_axes=1)
    temperatures = np.linspace(20.0, 24.0, 10)
    for i, t in enumerate(temperatures):
        steps.add(unit, f"{i:02d}", rng.normal(0, 1, 3) + t, t, 100.0)
    sxx = np.sum((temperatures - temperatures.mean()) ** 2)
    assert unit.stages.baseline.prediction_factor(np.array([22.0, 100.0])) == pytest.approx(np.sqrt(1 + 1 / 10))
    assert unit.stages.baseline.prediction_factor(np.array([30.0, 100.0])) == pytest.approx(np.sqrt(1 + 1 / 10 + 8.0**2 / sxx))


def test_the_wear_estimate_is_weighted_least_squares_of_the_friction_torques_along_each_signature():
    # known values: a residual that is 7 % of axis 3's signature is estimated at exactly 7 % on
    # axis 3, with standard error 1 / sqrt(sum(s^2 / variance)) over the friction torques (the
    # last 6 of the 18 features, scoring.WEAR_FEATURES); scaling every variance by 4 doubles the
    # error and keeps the estimate; the RMS and average load torques do not move it
    assert scoring.FEATURES[2] == "friction_torque" and scoring.WEAR_FEATURES == ("friction_torque",)
    rng = np.random.default_rng(1)
    signatures = rng.normal(0, 1, (6, 18))
    unit = steps.start("u", Settings(), n_axes=6, signatures=signatures)
    np.testing.assert_array_equal(unit.stages.baseline.wear_columns(), np.arange(12, 18))
    variance = rng.uniform(0.5, 2.0, 18)
    estimate, error = unit.stages.baseline.wear_estimate(7.0 * signatures[2], variance)
    assert estimate[2] == pytest.approx(7.0)
    assert error[2] == pytest.approx(1.0 / np.sqrt(np.sum(signatures[2, 12:] ** 2 / variance[12:])))
    estimate4, error4 = unit.stages.baseline.wear_estimate(7.0 * signatures[2], 4.0 * variance)
    np.testing.assert_allclose(estimate4, estimate)
    np.testing.assert_allclose(error4, 2.0 * error)
    other = np.where(np.arange(18) < 12, rng.normal(0, 1, 18), 0.0)  # only the RMS and load torques change
    np.testing.assert_allclose(unit.stages.baseline.wear_estimate(7.0 * signatures[2] + other, variance)[0], estimate, rtol=1e-12)
    assert steps.start("u", Settings(protocol="own"), n_axes=6).stages.baseline.wear_estimate(signatures[2], variance) is None
    with pytest.raises(ValueError, match=r"wear signatures of shape \(6, 12\); expected \(6, 18\)"):
        steps.start("u", Settings(), n_axes=6, signatures=signatures[:, :12]).stages.baseline.wear_estimate(np.zeros(12), np.ones(12))


def test_a_twin_unit_alarms_when_the_lower_bound_of_its_wear_reaches_the_limit():
    # 40 learning logs of noise, then axis 2 wearing 0.5 % a log: the alarm comes once the lower
    # 90 % bound has stayed at or above the limit (the default, 8 %: issue 90) for 5 logs, on axis 2, and
    # not before the true wear itself is at the limit
    rng = np.random.default_rng(2)
    signatures = np.abs(rng.normal(0, 1, (6, 18))) * 0.05  # feature units per %
    unit = steps.start("u", Settings(train=40), n_axes=6, signatures=signatures)
    for i in range(200):
        wear = max(i - 60, 0) * 0.5
        steps.add(unit, f"{i:03d}", rng.normal(0, 0.1, 18) + wear * signatures[1], 30.0, 100.0, np.zeros(18))
    assert unit.stages.alarm.first_alarm is not None and unit.stages.alarm.source_axis == 2 and unit.stages.alarm.statistic == "wear"
    first = int(unit.stages.alarm.first_alarm)
    rows = {r.stamp: r for r in unit.rows}
    limit = unit.stages.settings.wear_limit
    assert limit == 8.0
    assert all(max(rows[f"{k:03d}"].wear.lower) >= limit for k in range(first, first + 5))
    assert max(rows[f"{first - 1:03d}"].wear.lower) < limit  # else it began earlier
    true_wear = (first - 60) * 0.5
    assert limit <= true_wear < limit + 10.0, true_wear
    assert "axis 2 wear estimate" in steps.alarm_row(unit)["evidence"]


@pytest.mark.parametrize(("temperature", "payload", "worn_axis"), [(None, 0.0, 0), (20.0, 0.0, 3), (0.0, 12.5, 0),
                                                                    (40.0, 3.0, 6)])
def test_a_twin_cycle_is_set_up_from_typed_objects_as_from_its_former_texts(temperature, payload, worn_axis):
    """The twin's conditions and wear plan (issue 47, item 5): made as objects, equal to what the
    table and the wear text it was built from before gave, so every twin cycle is the same."""
    from faultgen.monitor import twin
    from faultgen.operation import conditions, wear

    held, plan = twin.setup(temperature, payload, worn_axis)
    table: dict = {}
    if temperature is not None:
        table["thermal"] = {"ambient": temperature, "seasonal": 0.0, "daily": 0.0, "rise": 0.0}
    if payload > 0:
        table["payloads"] = {"masses": [payload], "sizes": [round(twin.part_edge(payload), 4)]}
    assert held == conditions.Conditions.from_dict(table)
    texts = [f"{worn_axis}:exp4:{twin.WEAR:g}"] if worn_axis else []
    assert plan == wear.WearPlan.from_specs(texts, last_cycle=1)
    assert plan.multipliers(1, 6).tolist() == wear.WearPlan.from_specs(texts, last_cycle=1).multipliers(1, 6).tolist()


# -- an output folder from someone else (issue 61, item 1) -------------------------------------------

class _Planted:
    """Unpickled, it makes the folder ``marker``: what a planted pickle would run."""

    def __init__(self, marker: Path):
        self.marker = marker

    def __reduce__(self):
        return os.mkdir, (str(self.marker),)


def _copy_of(monitored: Path, out: Path) -> Path:
    shutil.copytree(monitored, out)
    return out


def test_a_planted_pickle_in_the_state_is_refused_unread(fleet, monitored, tmp_path):
    import pickle

    robot, logs, _ = fleet
    out = _copy_of(monitored, tmp_path / "out")
    marker = tmp_path / "ran"
    for path in (out / ".state").iterdir():
        path.unlink()
    (out / ".state" / "unit01.pkl").write_bytes(pickle.dumps(_Planted(marker)))
    with pytest.raises(ValueError, match=r"unit01\.pkl.*pickle.*not read"):
        loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False))
    assert not marker.exists()


def test_the_state_is_json_and_one_of_other_settings_is_refused_naming_the_setting(fleet, monitored, tmp_path):
    import json

    robot, logs, _ = fleet
    files = sorted((monitored / ".state").iterdir())
    assert files and all(p.suffix == ".json" for p in files)
    state = json.loads(files[0].read_text())
    assert state["settings"]["train"] == SETTINGS.train and len(state["logs"]) == SPEC.days
    assert all(len(log["sha256"]) == 64 for log in state["logs"])
    out = _copy_of(monitored, tmp_path / "out")
    with pytest.raises(ValueError, match=r"unit01\.json: holds a monitor run with other settings.*persistence 3 \(now 4\)"):
        loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=Settings(train=14, persistence=4),
                                 progress=False))
    state["logs"][3]["residual"] = state["logs"][3]["residual"][:-1]
    (out / ".state" / files[0].name).write_text(json.dumps(state))
    n_features = len(fleet_logs.FEATURES) * 6  # per axis of the KR210
    with pytest.raises(ValueError, match=rf"unit01\.json: logs\[3\]\.residual is not a list of {n_features} numbers"):
        loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False))
    # a state an earlier faultgen wrote (format 1: two features per axis) is refused, saying what to do
    state["format"] = "faultgen-monitor-state/1"
    (out / ".state" / files[0].name).write_text(json.dumps(state))
    with pytest.raises(ValueError, match=r"unit01\.json: format 'faultgen-monitor-state/1', expected "
                                         r"'faultgen-monitor-state/3' \(a state written by another version of "
                                         r"faultgen.*score the logs into a new OUT"):
        loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False))


def test_a_states_log_load_is_checked_and_a_state_written_without_loads_still_loads(fleet, monitored, tmp_path):
    """Each log's load in the state (faultgen.monitor.life.load_integrals) is refused when it is not
    2 x N numbers >= 0; a state whose logs have none (written before life.csv) is continued, its
    logs left out of life.csv and counted in the verdict."""
    import json

    robot, logs, _ = fleet
    out = _copy_of(monitored, tmp_path / "out")
    path = out / ".state" / "unit01.json"
    state = json.loads(path.read_text())
    for load, match in (([1.0], r"logs\[2\]\.load is not a list of 12 numbers"),
                        ([-1.0] * 12, r"logs\[2\]: load below 0")):
        bad = json.loads(json.dumps(state))
        bad["logs"][2]["load"] = load
        path.write_text(json.dumps(bad))
        with pytest.raises(ValueError, match=rf"unit01\.json: {match}"):
            loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False))
    for log in state["logs"]:
        del log["load"], log["duration_s"]
    path.write_text(json.dumps(state))
    loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False))
    with open(out / "life.csv", newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["unit"] == "unit01"]
    rated = [r for r in rows if r["consumed_pct"] != ""]  # the KR210's main axes have no rating (issue 90)
    assert len(rows) == 6 and rated and all(r["days_left"] == "" for r in rows)
    assert all("no rating given" in r["verdict"] for r in rows if r not in rated)
    assert all(float(r["consumed_pct"]) == 0 for r in rated)
    assert f"{SPEC.days} logs without a load record left out" in rated[0]["verdict"]
    assert (out / "alarms.csv").read_bytes() == (monitored / "alarms.csv").read_bytes()


def test_a_scored_log_that_changed_since_is_named_and_its_score_kept(fleet, monitored, tmp_path):
    robot, logs, _ = fleet
    copied = tmp_path / "logs"
    shutil.copytree(logs, copied)
    out = _copy_of(monitored, tmp_path / "out")
    log = sorted((copied / "unit02").iterdir())[5]
    log.write_text(log.read_text().replace("\n1", "\n2", 1))
    again = loop.monitor(resolve_run(robot, copied, out, calibrate=False, settings=SETTINGS, progress=False))
    status = next(s for s in again.statuses if s.unit == "unit02")
    assert f"1 logs changed since an earlier run scored or skipped them (its results kept): unit02/{log.name}" \
        in status.reason and status.status == "degraded"
    assert (out / "scores.csv").read_text() == (monitored / "scores.csv").read_text()


def test_a_cached_cycle_of_another_key_or_leading_outside_is_refused_and_never_echoed(fleet, monitored, tmp_path):
    import json

    robot, logs, _ = fleet
    out = _copy_of(monitored, tmp_path / "out")
    (out / ".state").rename(tmp_path / "state")  # a fresh run over the cached cycles
    for name in ("alarms.csv", "scores.csv"):
        (out / name).unlink()
    cycles = sorted((out / ".cache" / "cycles").iterdir())
    assert cycles and all(p.suffix == ".json" for p in cycles)
    cycle = json.loads(cycles[0].read_text())
    cycle["key"]["payload_kg"] = 1.0 + cycle["key"]["payload_kg"]
    cycles[0].write_text(json.dumps(cycle))
    with pytest.raises(ValueError, match=rf"{cycles[0].name}: not the cached twin cycle of"):
        loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False))
    secret = tmp_path / "secret.json"
    secret.write_text('{"format": "MARKER-4f1c", "key": {}}')
    cycles[0].unlink()
    cycles[0].symlink_to(secret)
    with pytest.raises(ValueError, match="a link leading outside") as refused:
        loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False))
    assert "MARKER" not in str(refused.value)


def test_a_cached_calibration_is_checked_against_its_record(tmp_path):
    from faultgen.inputs import InputError
    from faultgen.monitor import state

    model = tmp_path / "calibrated" / "m.xml"
    model.parent.mkdir()
    model.write_text("<mujoco/>")
    key = {"robot": "a" * 64, "log": "b" * 64, "steps": 3}
    record = tmp_path / "calibrated.json"
    state.write_calibration(record, tmp_path, key, model)
    state.read_calibration(record, tmp_path, key, model)
    with pytest.raises(InputError, match="not the calibration of this robot and log"):
        state.read_calibration(record, tmp_path, {**key, "log": "c" * 64}, model)
    model.write_text("<mujoco><worldbody/></mujoco>")
    with pytest.raises(InputError, match="m.xml: not the calibrated model its record"):
        state.read_calibration(record, tmp_path, key, model)


# -- no unit stops the fleet (issue 60) -----------------------------------------------------------------

def _planted(logs: Path, root: Path) -> Path:
    """A copy of the fleet's :data:`KEPT` units (hard links) with two more units made of unit01's logs:
    unit98's declare an 8000 kg part, which the log reader refuses (its bound is 1000 kg), and unit99's run
    three times faster (9 times the accelerations) 2 mrad off unit01's angles, a motion no KR210
    model's drives follow (its replay is refused above the planning limits), with three times its
    torque (the calibration's plausibility check, which the monitor runs on every first log since
    issue 88, refuses unit01's torque along that motion: 0.12-0.14 x the model's)."""
    copy = root / "logs"
    for unit in (logs / name for name in KEPT):
        (copy / unit.name).mkdir(parents=True)
        for log in unit.iterdir():
            os.link(log, copy / unit.name / log.name)
    for name in ("unit98", "unit99"):
        (copy / name).mkdir()
    for log in (logs / "unit01").iterdir():
        header, *rows = log.read_text().splitlines()
        names = header.split(",")
        assert names[-1] == "payload" and names[0] == "t"
        heavy = [row.rsplit(",", 1)[0] + ",8000" for row in rows]
        (copy / "unit98" / log.name).write_text("\n".join([header, *heavy]) + "\n")
        fast = []
        torque = [k for k, name in enumerate(names) if name.startswith("tau")]
        for row in rows:
            cells = row.split(",")
            cells[0] = repr(float(cells[0]) / 3)
            cells[1] = repr(float(cells[1]) + 0.002)
            for k in torque:  # three times the torque: one the arm could give that motion (issue 88: else refused)
                cells[k] = repr(3 * float(cells[k]))
            fast.append(",".join(cells))
        (copy / "unit99" / log.name).write_text("\n".join([header, *fast]) + "\n")
    return copy


def test_units_no_model_can_simulate_are_named_and_every_other_unit_is_scored_as_without_them(fleet, monitored,
                                                                                              tmp_path):
    import csv

    from typer.testing import CliRunner

    from faultgen.cli import app

    robot, logs, _ = fleet
    copy = _planted(logs, tmp_path)
    out = with_cycles_of(monitored, tmp_path / "out")
    result = CliRunner().invoke(app, ["monitor", str(copy), "--robot", str(robot), "-o", str(out), "--no-calibrate",
                                      "--train", "14", "--persistence", "3"])
    assert result.exit_code == loop.EXIT_SOME_UNITS_NOT_MONITORED, result.output
    with open(out / "units.csv", newline="") as f:
        units = {row["unit"]: row for row in csv.DictReader(f)}
    assert (units["unit98"]["status"], units["unit98"]["logs_scored"]) == ("not monitored", "0")
    assert f"{SPEC.days} logs skipped" in units["unit98"]["reason"] and "payload mass = 8000" in units["unit98"]["reason"]
    assert (units["unit99"]["status"], units["unit99"]["protocol"]) == ("degraded", "own"), units["unit99"]["reason"]
    assert "the twin of the nominal model failed" in units["unit99"]["reason"]
    assert "protocol own used" in units["unit99"]["reason"]
    assert units["unit99"]["logs_scored"] == str(SPEC.days)
    assert {u: r["status"] for u, r in units.items() if u not in ("unit98", "unit99")} == \
        dict.fromkeys(KEPT, "monitored")
    assert "unit98" in result.output and "exit status 3" in result.output
    # every other unit: its rows of alarms.csv and scores.csv as in the run without the planted units
    for name in ("alarms.csv", "scores.csv"):
        kept = [line for line in (out / name).read_text().splitlines() if not line.startswith(("unit98,", "unit99,"))]
        assert kept == [line for line in (monitored / name).read_text().splitlines()
                        if not line.startswith("unit03,")], name
    # the rerun keeps the skipped logs and the fallback: nothing to do, the same verdicts
    again = loop.monitor(resolve_run(robot, copy, out, calibrate=False, settings=SETTINGS, progress=False))
    assert {s.unit: s.status for s in again.statuses if s.unit in ("unit98", "unit99")} == \
        {"unit98": "not monitored", "unit99": "degraded"}
    assert again.exit_status == loop.EXIT_SOME_UNITS_NOT_MONITORED


def test_the_twin_of_a_log_with_faultgens_own_encoder_noise_does_not_saturate(tmp_path):
    """An irb6700 pick and place logged with faultgen's default encoder noise (1e-4 rad) replayed
    as it is saturates the drive of axis 2 (`simulate --task log.csv` says so); the twin replays the
    log's angles through the derivative filter and carries it, its drives below 0.8 of their limit
    as on the noise-free log (issue 60)."""
    from typer.testing import CliRunner

    from faultgen.cli import app
    from faultgen.model import robots
    from faultgen.monitor.twin import REFERENCE_TEMPERATURE, Twin
    from faultgen.operation import wear
    from faultgen.simulation import sensors
    from faultgen.simulation import stepping as sim

    robot = robots.load("irb6700")
    run = sim.simulate(run_config(robot="irb6700", task="pick_place", friction="stribeck", wear=wear.WearPlan({}),
                                     cycles=1, seed=1, noise=sensors.NoiseConfig(encoder=1e-4), nthread=1,
                                     signals=True), progress=False)
    assert run.saturated.size == 0
    log = tmp_path / "noisy.csv"
    names = ["t", *(f"q{i}" for i in range(1, 7)), *(f"tau{i}" for i in range(1, 7))]
    np.savetxt(log, np.column_stack([run.t, run.q_a[0], run.tau_m[0] * robot.gear_ratio]), delimiter=",",
               header=",".join(names), comments="", fmt="%.9g")
    # one cycle: the replay saturates in its first (simulate's default of 100 cycles gave the same warning
    # in 18 s of CPU against 1.5 s)
    result = CliRunner().invoke(app, ["simulate", "--robot", "irb6700", "--task", str(log), "--friction", "stribeck",
                                      "--encoder-noise", "0", "--disturbance", "0", "--cycles", "1",
                                      "-o", str(tmp_path / "r.h5")])
    assert result.exit_code == 0, result.output
    assert "warning: the drive of axis 2 reached its torque limit" in result.output
    twin = Twin(robot, log, tmp_path / "cache")
    replayed = sim.simulate(run_config(robot="irb6700", task=twin._reference, friction="stribeck",
                                          wear=wear.WearPlan({}), cycles=1, seed=0,
                                          noise=sensors.NoiseConfig(disturbance=0.0, encoder=0.0), nthread=1,
                                          signals=True), progress=False)
    peak = np.max(np.abs(replayed.tau_m[0]), axis=0) / robot.motor_torque_limit
    assert replayed.saturated.size == 0 and peak.max() < 0.8, peak
    assert np.all(np.isfinite(twin.expected(REFERENCE_TEMPERATURE, 0.0)))  # the monitor's healthy expectation


def test_an_implausible_calibration_does_not_become_the_twin():
    """A calibration that put the Stribeck hump at 216 rad/s (nominal 10; issue 60's KR210), a dry
    friction above half the drive's torque or a Coulomb level beyond 3 x nominal either way is
    named, so the monitor falls back (faultgen.monitor.unit.FALLBACK)."""
    from types import SimpleNamespace

    from faultgen.calibrate import plausibility
    from faultgen.model import robots

    nominal = robots.load("irb6700")
    assert plausibility.implausible_parameters(nominal, nominal) == []
    v = np.array(nominal.friction.stribeck_velocity, dtype=float)
    static = np.array(nominal.friction.static, dtype=float)
    v[0] = 21.6 * v[0]
    static[3] = 0.6 * nominal.motor_torque_limit[3]
    friction = SimpleNamespace(**{name: np.array(getattr(nominal.friction, name), dtype=float)
                                  for name in ("coulomb_pos", "coulomb_neg")}, stribeck_velocity=v, static=static)
    edited = SimpleNamespace(friction=friction, motor_torque_limit=nominal.motor_torque_limit, n_axes=nominal.n_axes)
    found = plausibility.implausible_parameters(nominal, edited)
    assert len(found) == 2, found
    assert found[0].startswith("axis 1: Stribeck velocity") and "21.6 x its nominal" in found[0]
    assert found[1].startswith("axis 4: dry friction") and "0.6 of the motor's torque limit" in found[1]
    # a Coulomb level traded for a viscous one (a KR210 L150's own friction on its nominal model: 0.16 x)
    for factor, refused in ((0.16, True), (0.61, False), (1.59, False), (3.2, True)):
        friction.coulomb_pos = np.array(nominal.friction.coulomb_pos, dtype=float)
        friction.coulomb_neg = np.array(nominal.friction.coulomb_neg, dtype=float)
        friction.coulomb_pos[1] *= factor
        friction.coulomb_neg[1] *= factor
        found = [f for f in plausibility.implausible_parameters(nominal, edited) if f.startswith("axis 2")]
        assert bool(found) == refused, (factor, found)
        if refused:
            assert found[0].startswith("axis 2: Coulomb friction") and f"{factor:.3g} x its nominal" in found[0], found


def test_a_gearbox_change_closes_the_alarm_and_the_unit_learns_its_offset_again(fleet, monitored, tmp_path):
    """The worn unit's logs until three days after its alarm, then a gearbox change on the worn
    axis and a healthy unit's logs (a new part, and another unit's spread): the alarm stays in
    alarms.csv, closed by the change; the unit learns its offset again and stays quiet; a rerun
    replays the event from the state (issue 60, part 4)."""
    import csv

    robot, logs, truth = fleet
    outcome = independent_fleet.evaluate(truth, monitored / "alarms.csv")
    worn = next(u for u, o in outcome.items() if o["axis"])
    healthy = next(u for u, o in outcome.items() if not o["axis"])
    change = outcome[worn]["day"] + 3
    copy = tmp_path / "logs"
    (copy / worn).mkdir(parents=True)
    before = sorted((logs / worn).iterdir())[:change]
    after = sorted((logs / healthy).iterdir())[change:]
    for log in [*before, *after]:
        os.link(log, copy / worn / log.name)
    (copy / "events.csv").write_text(f"unit,stamp,event,axis\n{worn},{after[0].stem},gearbox_change,"
                                     f"{outcome[worn]['axis']}\n")
    out = with_cycles_of(monitored, tmp_path / "out")
    loop.monitor(resolve_run(robot, copy, out, calibrate=False, settings=SETTINGS, progress=False))
    with open(out / "alarms.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 2, rows
    assert rows[0]["first_alarm"] == outcome[worn]["alarm"] and rows[0]["closed"] == after[0].stem
    assert rows[0]["closed_by"] == f"gearbox_change of axis {outcome[worn]['axis']}"
    assert rows[1]["first_alarm"] == "" and "no persistent alarm" in rows[1]["evidence"], rows[1]
    with open(out / "scores.csv", newline="") as f:
        phases = [row["phase"] for row in csv.DictReader(f)]
    assert phases.count("relearning") == max(5, SETTINGS.train // 4)
    # the same outputs when the logs arrive in two runs, the event between them
    split = tmp_path / "split"
    (split / worn).mkdir(parents=True)
    for log in before:
        os.link(log, split / worn / log.name)
    shutil.copy(copy / "events.csv", split / "events.csv")
    # the first run's cycles: its twin replays the worn unit's program, which the fixture's run (its twin on
    # unit01's) never simulated; content-addressed, so the split runs read the cycles they would simulate
    again = with_cycles_of(out, tmp_path / "again")
    loop.monitor(resolve_run(robot, split, again, calibrate=False, settings=SETTINGS, progress=False))
    for log in after:
        os.link(log, split / worn / log.name)
    loop.monitor(resolve_run(robot, split, again, calibrate=False, settings=SETTINGS, progress=False))
    for name in ("alarms.csv", "scores.csv"):
        assert (again / name).read_text() == (out / name).read_text(), name


def test_ur_rtde_recordings_are_monitored_with_their_joint_temperatures(fleet, tmp_path):
    """The fleet's logs written as Universal Robots' RTDE recordings (space-separated,
    ``timestamp, actual_q_i, target_moment_i, joint_temperatures_i``) and as measured logs with the
    same numbers: `monitor --format ur-rtde` scores them as the measured ones, the temperature
    included (the state's temperatures are the logged ones), and says which torque it took
    (issue 60, part 5: the adapter dropped the temperatures, and monitor had no --format)."""
    import csv
    import json

    from typer.testing import CliRunner

    from faultgen.cli import app

    robot, logs, _ = fleet
    rtde, plain = tmp_path / "rtde", tmp_path / "plain"
    for log in sorted(logs.glob("unit0[12]/*.csv"))[::2]:  # two units, every other day: 20 logs a unit
        header, *rows = log.read_text().splitlines()
        names = header.split(",")
        table = np.array([[float(c) for c in row.split(",")] for row in rows])
        keep = [names.index(n) for n in names if n != "payload"]
        for folder in (rtde, plain):
            (folder / log.parent.name).mkdir(parents=True, exist_ok=True)
        np.savetxt(plain / log.parent.name / log.name, table[:, keep], delimiter=",",
                   header=",".join(names[k] for k in keep), comments="", fmt="%.17g")
        order = ["t", *(f"q{i}" for i in range(1, 7)), *(f"tau{i}" for i in range(1, 7)),
                 *(f"temperature{i}" for i in range(1, 7))]
        ur = ["timestamp", *(f"actual_q_{i}" for i in range(6)), *(f"target_moment_{i}" for i in range(6)),
              *(f"joint_temperatures_{i}" for i in range(6))]
        np.savetxt(rtde / log.parent.name / log.name, table[:, [names.index(n) for n in order]], delimiter=" ",
                   header=" ".join(ur), comments="", fmt="%.17g")
    common = ["--robot", str(robot), "--protocol", "own", "--train", "10", "--persistence", "3"]
    runs = {}
    for name, folder, extra in (("plain", plain, []), ("rtde", rtde, ["--format", "ur-rtde"])):
        result = CliRunner().invoke(app, ["monitor", str(folder), "-o", str(tmp_path / f"out-{name}"), *common, *extra])
        assert result.exit_code == 0, result.output
        runs[name] = tmp_path / f"out-{name}"
    for name in ("alarms.csv", "scores.csv"):
        assert (runs["rtde"] / name).read_text() == (runs["plain"] / name).read_text(), name
    state = json.loads((runs["rtde"] / ".state" / "unit01.json").read_text())
    first = np.loadtxt(sorted((rtde / "unit01").iterdir())[0], skiprows=1)
    assert state["logs"][0]["temperature_C"] == pytest.approx(first[:, 13:19].mean(), rel=1e-12)
    with open(runs["rtde"] / "units.csv", newline="") as f:
        reasons = {row["unit"]: row["reason"] for row in csv.DictReader(f)}
    assert all("torque from target_moment_i (the controller's commanded moment" in r for r in reasons.values())


def test_two_jobs_give_the_outputs_of_one(fleet, monitored, tmp_path):
    """`--jobs 2` scores groups of units in two processes; the outputs are those of one job, bit
    for bit, and a rerun after more logs arrived scores only those (issue 60, part 6): the old rows
    kept as they were, the new ones equal a run over the whole folder at once, no simulated cycle
    redone (this test took over test_new_logs_are_scored_without_redoing_the_old). The first run
    starts on a cache missing two of the shared twin's cycles (worn axes 1 and 2) and two of its
    cycles with a part: it simulates the two shared ones in its two worker processes
    (faultgen.monitor.parallel.prepare_twins), not one after another, the others where a unit
    needs them, and they are the one-job run's cycle files, byte for byte (this test took over
    test_two_jobs_on_an_empty_cache_simulate_the_shared_twin_in_both_and_give_the_outputs_of_one; until
    2026-11-28 this run started on an empty cache and simulated all 15 cycles again on the same paths)."""
    import json

    robot, logs, _ = fleet
    partial = tmp_path / "logs"
    for unit in logs.iterdir():
        (partial / unit.name).mkdir(parents=True)
        for log in sorted(unit.iterdir())[:30]:
            os.link(log, partial / unit.name / log.name)
    out = with_cycles_of(monitored, tmp_path / "out")
    keys = {p: json.loads(p.read_text())["key"] for p in (out / ".cache" / "cycles").iterdir()}
    shared = [p for p, key in keys.items() if key["worn_axis"] in (1, 2) and key["payload_kg"] == 0.0]
    parts = sorted((p for p, key in keys.items() if key["payload_kg"] > 0.0),
                   key=lambda p: keys[p]["payload_kg"])
    assert len(shared) == 2 and len(parts) >= 2, keys
    for path in [*shared, *parts[:2]]:
        path.unlink()
    loop.monitor(resolve_run(robot, partial, out, calibrate=False, settings=SETTINGS, progress=False,
                             context=ExecutionContext(jobs=2)))
    assert len((out / "scores.csv").read_text().splitlines()) == 1 + SPEC.units * 30
    for unit in logs.iterdir():  # the rest of the month arrives
        for log in sorted(unit.iterdir())[30:]:
            os.link(log, partial / unit.name / log.name)
    before = {p: p.stat().st_mtime_ns for p in (out / ".cache" / "cycles").iterdir()}
    outcome = loop.monitor(resolve_run(robot, partial, out, calibrate=False, settings=SETTINGS, progress=False,
                                       context=ExecutionContext(jobs=2)))
    assert all(len(m.rows) == SPEC.days for m in outcome.units)
    assert {p: p.stat().st_mtime_ns for p in before} == before  # no simulated cycle redone
    cycles = {p.name: p.read_bytes() for p in (out / ".cache" / "cycles").iterdir()}
    assert cycles == {p.name: p.read_bytes() for p in (monitored / ".cache" / "cycles").iterdir()}
    charts = tuple(p.name for p in monitored.glob("*.png"))
    assert charts
    for name in (*charts, "alarms.csv", "scores.csv", "units.csv", "rul.csv", "wear.csv", "life.csv"):
        assert (out / name).read_bytes() == (monitored / name).read_bytes(), name
    # a rerun with no new log: every unit's chart and remaining life made again in the workers, the same bytes
    for name in charts:
        (out / name).unlink()
    loop.monitor(resolve_run(robot, partial, out, calibrate=False, settings=SETTINGS, progress=False,
                             context=ExecutionContext(jobs=2)))
    for name in (*charts, "alarms.csv", "scores.csv", "units.csv", "rul.csv", "wear.csv", "life.csv"):
        assert (out / name).read_bytes() == (monitored / name).read_bytes(), name


def test_an_unlogged_program_change_rebuilds_the_twin_and_the_unit_learns_again(fleet, monitored, tmp_path):
    """From day 21 a healthy unit runs its program turned 0.3 rad about the base (axis 1, whose
    dynamics do not depend on its angle): nobody logged it. The monitor finds the motion left the
    twin's program, rebuilds the twin on that day's log and learns the unit again (units.csv says
    so; no wear alarm); a run in two parts around the change gives the same outputs (issue 60,
    part 4)."""
    import csv

    robot, logs, truth = fleet
    outcome = independent_fleet.evaluate(truth, monitored / "alarms.csv")
    healthy = next(u for u, o in outcome.items() if not o["axis"])
    copy = tmp_path / "logs"
    (copy / healthy).mkdir(parents=True)
    files = sorted((logs / healthy).iterdir())
    for day, log in enumerate(files, start=1):
        if day <= 20:
            os.link(log, copy / healthy / log.name)
            continue
        header, *rows = log.read_text().splitlines()
        k = header.split(",").index("q1")
        turned = []
        for row in rows:
            cells = row.split(",")
            cells[k] = repr(float(cells[k]) + 0.3)
            turned.append(",".join(cells))
        (copy / healthy / log.name).write_text("\n".join([header, *turned]) + "\n")
    out = with_cycles_of(monitored, tmp_path / "out")
    loop.monitor(resolve_run(robot, copy, out, calibrate=False, settings=SETTINGS, progress=False))
    with open(out / "units.csv", newline="") as f:
        row = next(csv.DictReader(f))
    assert row["status"] == "monitored" and f"program changed at {files[20].stem}" in row["reason"], row
    with open(out / "scores.csv", newline="") as f:
        phases = [(r["stamp"], r["phase"]) for r in csv.DictReader(f)]
    # the new program's learning logs: relearning, listed from the change on (issue 72); it learns its offset
    # alone, on relearn_logs of them, the unit's slopes, noise and PCA model borrowed (issue 90)
    relearn = max(5, SETTINGS.train // 4)
    assert [p for s, p in phases if s >= files[20].stem][:relearn + 1] == ["relearning"] * relearn + ["monitoring"]
    assert "no persistent alarm" in (out / "alarms.csv").read_text()
    split = tmp_path / "split"
    (split / healthy).mkdir(parents=True)
    for log in sorted((copy / healthy).iterdir())[:25]:
        os.link(log, split / healthy / log.name)
    # the first run's cycles, the rebuilt twin's among them (content-addressed: the cycles the split runs
    # would simulate again)
    again = with_cycles_of(out, tmp_path / "again")
    loop.monitor(resolve_run(robot, split, again, calibrate=False, settings=SETTINGS, progress=False))
    for log in sorted((copy / healthy).iterdir())[25:]:
        os.link(log, split / healthy / log.name)
    loop.monitor(resolve_run(robot, split, again, calibrate=False, settings=SETTINGS, progress=False))
    for name in ("alarms.csv", "scores.csv", "units.csv"):
        assert (again / name).read_text() == (out / name).read_text(), name


def test_a_unit_whose_twin_cannot_be_built_falls_back_through_its_own_friction_then_nominal_then_own(
        fleet, tmp_path, monkeypatch):
    """The fallback chain of a calibrated unit (faultgen.monitor.unit.FALLBACK): each kind's failure
    is noted and the next is tried, the unit's own friction on the nominal model before the nominal
    model (issue 59: a calibration refused as implausible kept none of the unit's own friction)."""
    from faultgen.logs import formats
    from faultgen.model import robots
    from faultgen.monitor import feed, prognosis
    from faultgen.monitor import unit as units_module

    robot, logs, _ = fleet
    nominal = robots.load(robot)
    units = fleet_logs.fleet(logs)
    source = fleet_logs.Source(nominal)
    tried = []

    def failing(source, kind, *args):
        tried.append(kind)
        raise ValueError(f"the {kind} twin refused for this test")

    monkeypatch.setattr(units_module, "model_of", failing)
    name = sorted(units)[0]
    unit = units_module.new_unit(name, units, nominal, SETTINGS, None, True, [], source)
    assert unit.model == "calibrated"
    context = feed.Context(nominal.path, SETTINGS, None, tmp_path, False, formats.MEASURED, units, {},
                           prognosis.FAILURE_WEAR)  # the fleet's logs, the cache's folder, the default stepper
    assert units_module.twin_of(unit, context, {}, False, source) is None
    assert tried == ["calibrated", "friction", "nominal"] and unit.model == "none"
    assert unit.notes == [
        "the twin of the calibrated model failed (the calibrated twin refused for this test); nominal model with "
        "the unit's own friction used",
        "the twin of the nominal model with the unit's own friction failed (the friction twin refused for this "
        "test); nominal model used",
        "the twin of the nominal model failed (the nominal twin refused for this test); protocol own used"]


def test_the_own_friction_fallback_fits_every_moving_axis_dry_and_viscous_level_on_the_nominal_model(fleet, tmp_path):
    """Kind "friction": no search, the nominal model's Stribeck hump and direction skew kept, every
    moving axis's dry (Coulomb) and viscous level fitted to the unit's first log (the fleet's units
    spread 15 % about the nominal friction), cached under its own key and read back the same, and not
    read back for the logs read in another format."""
    from faultgen.model import robots
    from faultgen.monitor import state as stored
    from faultgen.monitor import unit as units_module

    robot, logs, _ = fleet
    nominal = robots.load(robot)
    units = fleet_logs.fleet(logs)
    source = fleet_logs.Source(nominal)
    first = units[sorted(units)[0]][0]
    key = (first.stamp, source.get(first).sha256)
    made = units_module.model_of(source, "friction", key, first, tmp_path, False)
    f, g = made.friction, nominal.friction
    np.testing.assert_array_equal(f.stribeck_velocity, g.stribeck_velocity)
    np.testing.assert_allclose(np.subtract(f.coulomb_neg, f.coulomb_pos), np.subtract(g.coulomb_neg, g.coulomb_pos),
                               atol=1e-9)
    ratio = np.asarray(f.coulomb_pos) / np.asarray(g.coulomb_pos)
    assert np.all(np.abs(ratio - 1.0) > 1e-3) and np.all((ratio > 0.5) & (ratio < 1.5)), ratio
    digest = stored.key_name(units_module.calibration_key(stored.sha256_file(nominal.path), key[1], "friction"))
    assert (tmp_path / ".cache" / "calibrated" / f"{digest}.json").is_file()
    cached = tmp_path / ".cache" / "calibrated" / digest
    # the model and its report, not the calibration's figure (nothing reads it there; 1.6 s a unit)
    assert (cached / "report.json").is_file() and not (cached / "calibration.png").exists()
    again = units_module.model_of(source, "friction", key, None, tmp_path, False)  # the cache, not the log
    assert again.path == made.path
    np.testing.assert_array_equal(again.friction.coulomb_pos, f.coulomb_pos)
    # the logs read in another format (other torque columns of the same files): not that calibration
    from faultgen.logs import formats

    other = fleet_logs.Source(nominal, formats.make("ur-rtde", torque_constants=(1.0,) * nominal.n_axes))
    with pytest.raises(ValueError, match="its calibration is not cached"):
        units_module.model_of(other, "friction", key, None, tmp_path, False)
