"""A unit's friction tests in ``faultgen monitor`` (issue 75, item 3; faultgen.monitor.friction_tests):
the folder ``LOGS/<unit>/friction-test``, each test's wear against the plant's own dry level (a tiny
fleet of the independent simulator, tests/independent_fleet.py, with its friction tests), the
logs' wear on the tests' scale, the cache, and a fleet without tests giving today's outputs.
The full-size figures: ``benchmarks/monitor_wear_scale.py --friction-test-every 14``."""

import csv
import filecmp
import json
import math
import shutil
from pathlib import Path

import independent_fleet
import numpy as np
import pytest

from faultgen.calibrate import friction_report
from faultgen.data import logfolder
from faultgen.monitor import friction_tests, loop, scale_prior
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import state as stored
from faultgen.monitor.run import resolve_run
from faultgen.monitor.scoring import Settings

# two units, 18 days, one worn from day 11 (60 % on day 18); tests on days 1, 9 and 17
SPEC = independent_fleet.FleetSpec(units=2, worn=1, days=18, seed=3, onset=(11, 11), friction_test_every=8)
SETTINGS = Settings(train=10, persistence=3)
BAD_TEST = "2026-01-06.csv"  # a file in a unit's test folder that is no log: named, never stops the run


def rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    root = tmp_path_factory.mktemp("fleet")
    robot, logs, truth = independent_fleet.write_fleet(root, SPEC)
    (logs / "unit01" / "friction-test" / BAD_TEST).write_text("t,q1\n0,0\n")
    return root, robot, logs, truth


@pytest.fixture(scope="module")
def monitored(fleet, tmp_path_factory):
    _, robot, logs, _ = fleet
    out = tmp_path_factory.mktemp("monitor") / "out"
    loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False))
    return out


def test_a_units_test_folder_is_no_log_and_its_files_are_checked_as_logs(tmp_path):
    logs = tmp_path / "logs"
    (logs / "u1" / "friction-test").mkdir(parents=True)
    (logs / "u1" / "2026-03-01.csv").write_text("t\n")
    (logs / "u1" / "friction-test" / "2026-03-01.csv").write_text("t\n")
    units = fleet_logs.fleet(logs)
    assert [g.name for g in units["u1"]] == ["u1/2026-03-01.csv"]
    found = friction_tests.find(logs, units, fleet_logs.reader_of()[1])
    assert [(g.unit, g.stamp, g.name) for g in found["u1"]] == [("u1", "2026-03-01", "u1/friction-test/2026-03-01.csv")]
    # any other folder in a unit folder is still no log, as before
    (logs / "u1" / "other").mkdir()
    with pytest.raises(ValueError, match="u1/other: not a log"):
        fleet_logs.fleet(logs)
    (logs / "u1" / "other").rmdir()
    # a file there that is no test, a test stamped as the logs are not, a folder linked out: refused, named
    (logs / "u1" / "friction-test" / "notes.txt").write_text("x")
    with pytest.raises(ValueError, match="u1/friction-test/notes.txt: not a friction test"):
        friction_tests.find(logs, units, fleet_logs.reader_of()[1])
    (logs / "u1" / "friction-test" / "notes.txt").unlink()
    (logs / "u1" / "friction-test" / "17.csv").write_text("t\n")
    with pytest.raises(ValueError, match="mix dates and sequence numbers"):
        friction_tests.find(logs, units, fleet_logs.reader_of()[1])
    shutil.rmtree(logs / "u1" / "friction-test")
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    (logs / "u1" / "friction-test").symlink_to(outside)
    with pytest.raises(ValueError, match="symbolic link out of the logs folder"):
        friction_tests.find(logs, fleet_logs.fleet(logs), fleet_logs.reader_of()[1])


def test_each_test_reads_the_plants_dry_level_change_over_the_first_test(fleet, monitored):
    root, *_ = fleet
    plant = {(r["unit"], r["stamp"], int(r["axis"])): float(r["coulomb_Nm"]) for r in rows(root / "truth_tests.csv")}
    got = rows(monitored / "tests.csv")
    assert tuple(got[0]) == friction_tests.COLUMNS
    stamps = sorted({r["stamp"] for r in got})
    assert len(got) == 2 * 3 * 6 and len(stamps) == 3  # 2 units x 3 tests x 6 axes; the bad file is none
    errors, covered = [], []
    for r in got:
        unit, axis = r["unit"], int(r["axis"])
        first = plant[(unit, stamps[0], axis)]
        # the first law's dry friction does not move with temperature: the plant's ratio is the truth
        truth = 100 * (plant[(unit, r["stamp"], axis)] / first - 1)
        if r["stamp"] == stamps[0]:
            assert float(r["wear"]) == 0.0 and r["verdict"].startswith("reference")
        else:
            errors.append(abs(float(r["wear"]) - truth))
            covered.append(float(r["wear_lower"]) <= truth <= float(r["wear_upper"]))
        assert abs(float(r["coulomb_Nm"]) / plant[(unit, r["stamp"], axis)] - 1) < 0.02, r
    assert np.median(errors) < 1.5 and np.mean(covered) >= 0.8, (np.median(errors), np.mean(covered))
    worn = next(r for r in got if r["unit"] == "unit02" and r["stamp"] == stamps[-1] and r["axis"] == "1")
    assert float(worn["wear"]) > 40  # 51 % true wear on day 17


def test_units_and_wear_say_which_scale_and_an_unread_test_is_named(fleet, monitored):
    units = rows(monitored / "units.csv")
    assert [u["wear_scale"] for u in units] == [friction_tests.TESTS_SCALE] * 2
    assert f"1 friction tests not read: {BAD_TEST[:-4]}" in units[0]["reason"]
    wear = rows(monitored / "wear.csv")
    assert {r["wear_scale"] for r in wear} == {friction_tests.TESTS_SCALE}
    scores = rows(monitored / "scores.csv")
    assert len(wear) == 6 * len(scores)
    rul = rows(monitored / "rul.csv")
    assert sorted((r["unit"], r["axis"]) for r in rul) == sorted((u, str(k)) for u in ("unit01", "unit02")
                                                                  for k in range(1, 7))


def test_a_test_is_read_once_and_a_tampered_reading_is_refused(fleet, monitored, tmp_path, monkeypatch):
    _, robot, logs, _ = fleet
    out = tmp_path / "out"
    shutil.copytree(monitored, out)

    def never(*args, **kwargs):
        raise AssertionError("a cached test was read again")

    monkeypatch.setattr(friction_report, "read", never)
    loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False))
    for name in ("tests.csv", "wear.csv", "units.csv", "alarms.csv", "rul.csv"):
        assert filecmp.cmp(out / name, monitored / name, shallow=False), name
    cached = sorted((out / ".cache" / friction_tests.CACHE).glob("*.json"))
    assert len(cached) == 2 * 3 + 1  # every test of both units, and the bad one with its reason
    cached[0].write_text(cached[0].read_text().replace('"fits"', '"fitz"'))
    with pytest.raises(stored.StateError, match=cached[0].name):
        loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False))


def test_without_tests_every_output_is_that_of_a_fleet_with_an_empty_test_folder(fleet, monitored, tmp_path):
    _, robot, logs, _ = fleet
    outs = []
    for name, empty in (("without", False), ("empty", True)):
        copy = tmp_path / name / "logs"
        shutil.copytree(logs, copy, ignore=shutil.ignore_patterns("friction-test"))
        if empty:
            for unit in ("unit01", "unit02"):
                (copy / unit / "friction-test").mkdir()
        out = tmp_path / name / "out"
        shutil.copytree(monitored / ".cache" / "cycles", out / ".cache" / "cycles")  # the twin's cycles, not simulated again
        loop.monitor(resolve_run(robot, copy, out, calibrate=False, settings=SETTINGS, progress=False))
        outs.append(out)
    files = sorted(p.relative_to(outs[0]) for p in outs[0].rglob("*") if p.is_file() and ".cache" not in p.parts)
    assert files == sorted(p.relative_to(outs[1]) for p in outs[1].rglob("*") if p.is_file() and ".cache" not in p.parts)
    for name in files:
        assert filecmp.cmp(outs[0] / name, outs[1] / name, shallow=False), name
    assert not (outs[0] / "tests.csv").exists()
    assert "wear_scale" not in (outs[0] / "units.csv").read_text() + (outs[0] / "wear.csv").read_text()


def _fit(axis: int, coulomb: float, temperature: float, spread: float = 0.002) -> dict:
    fit = dict.fromkeys(friction_tests.FIT_COLUMNS, math.nan)
    half = friction_tests.FIT_Z * spread * coulomb
    fit.update(axis=axis, coulomb_Nm=coulomb, coulomb_Nm_low=coulomb - half, coulomb_Nm_high=coulomb + half,
               temperature_degC=temperature)
    return fit


def test_the_temperature_law_is_learned_past_a_worn_axis_and_corrects_each_test():
    """A planted law, dry friction falling 0.6 %/K on every axis (Bittencourt's trend), axis 2 worn
    as the season warms: the median slope ignores the worn axis; each test's wear is the formula's."""
    rng = np.random.default_rng(4)
    beta, levels = -0.006, np.array([300.0, 250.0, 120.0, 40.0, 30.0, 10.0])
    temperatures = np.linspace(15.0, 35.0, 9) + rng.normal(0.0, 2.0, 9)
    wear = np.clip(np.linspace(-20.0, 60.0, 9), 0.0, None)  # % on axis 2, growing with the season
    tests = []
    for j, (t, w) in enumerate(zip(temperatures, wear)):
        c = levels * np.exp(beta * (t - 20.0) + rng.normal(0.0, 0.01, 6))
        c[1] *= 1 + w / 100
        tests.append(friction_tests.FrictionTest(f"2026-0{1 + j // 4}-{10 + j:02d}", float(j), "",
                                                 tuple(_fit(k + 1, c[k], t) for k in range(6))))
    got, law = friction_tests.tests_wear(tests, 6)
    assert abs(law.beta - beta) < 2.5 * law.error and law.error < 0.002, law
    assert abs(law.repeatability - 0.01) < 0.005, law
    by = {(r.key, r.axis): r for r in got}
    for j in range(1, 9):
        for k in range(1, 7):
            fit, ref = tests[j].fits[k - 1], tests[0].fits[k - 1]
            expected = 100 * (fit["coulomb_Nm"] / ref["coulomb_Nm"]
                              * math.exp(-law.beta * (fit["temperature_degC"] - ref["temperature_degC"])) - 1)
            assert by[(float(j), k)].wear == pytest.approx(expected, rel=1e-9, abs=1e-9)
    worn = [by[(float(j), 2)] for j in range(9)]
    assert all(r.lower <= w <= r.upper for r, w in zip(worn[1:], wear[1:])), [(r.lower, r.upper) for r in worn]
    # the worn axis's stated scatter is that of its three tests before the wear (1 % planted), not its wear
    # (main 15a11aa: every test counted, 8.5 %)
    assert {r.scatter for r in worn} == {law.scatter[2]} and law.scatter[2] < 0.03, law.scatter
    # a gearbox change of axis 2 at the 6th test starts its tests again there
    change = logfolder.Event("unit", "x", 5.0, logfolder.TIME, "gearbox_change", 2, 2)
    after, _ = friction_tests.tests_wear(tests, 6, [change])
    assert [r.reference for r in after if r.axis == 2] == [True, False, False, False, False, True, False, False, False]


def test_the_logs_are_put_on_the_tests_scale_by_the_factor_their_tests_give():
    """The twin's wear reads 1.25 times the tests' (a factor 0.8) with a test's offset of 3 points:
    the fitted factor is 0.8 within its error, and the prior's 1 -+ its doubt where the tests say nothing."""
    true = np.array([0.0, 0.0, 5.0, 12.0, 20.0, 28.0, 37.0, 45.0])
    rng = np.random.default_rng(1)
    stamps = [f"2026-01-{2 * j + 1:02d}" for j in range(len(true))]
    wears = []
    for j, (stamp, w) in enumerate(zip(stamps, true)):
        y = w + 3.0 + rng.normal(0.0, 1.0) if j else 0.0
        wears.append(friction_tests.AxisWear(stamp, logfolder.parse_stamp(stamp, "u")[0], 1, {}, y, y - 2, y + 2,
                                             0.02, 0.01, "", j == 0, 0.01))
    scale = friction_tests.Rescale("u", 2, wears)
    for stamp, w in zip(stamps, true):
        f, error, names = scale.at(stamp, np.array([1.25 * w, 0.3]), np.array([0.5, 0.5]))
    assert abs(f[0] - 0.8) < 2 * error[0] and error[0] < 0.08, (f, error)
    # an axis no test told: the prior's factor with the prior's doubt (issue 90: the bound carries it)
    assert names == [friction_tests.TESTS_SCALE, friction_tests.TWIN_SCALE] and f[1] == 1.0
    assert error[1] == friction_tests.SCALE_PRIOR


def test_the_rul_benchmark_replays_the_monitors_rows_with_their_factors(fleet, monitored):
    """benchmarks/monitor_rul.py's ``replayed_rows`` (the twin-scale columns and factors scores.csv does
    not keep): the state replayed with the tests from the cache gives the wear the run wrote."""
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    import monitor_rul

    root, robot, logs, _ = fleet
    assert robot == root / "kr210" and logs == root / "logs"
    replayed = monitor_rul.replayed_rows(root, monitored)
    written = {(r["unit"], r["stamp"], int(r["axis"])): float(r["wear"]) for r in rows(monitored / "wear.csv")}
    pairs = []
    for unit, unit_rows in replayed.items():
        for r in unit_rows:
            if r.wear is not None and r.wear.tests is not None:
                pairs += [(written[(unit, r.stamp, k + 1)], float(r.wear.estimate[k])) for k in range(6)]
    assert len(pairs) >= 12 * 6 and all(math.isclose(a, b, rel_tol=1e-5, abs_tol=1e-4) for a, b in pairs), pairs[:5]
    assert {r.wear.tests.scale[0] for r in replayed["unit02"] if r.wear is not None and r.wear.tests is not None} == \
        {friction_tests.TESTS_SCALE}


def test_a_fleets_scale_prior_sets_the_untold_factor_and_belongs_to_the_state(fleet, monitored, tmp_path):
    """wear.csv gives each log-axis's factor onto the tests' scale and its error (the default prior's 1 -+ 0.3
    where no test has told it); a run given a fleet's prior (``--scale-prior``,
    :mod:`faultgen.monitor.scale_prior`) starts there instead and says so in settings.json; continuing its
    folder without it, or learning a prior from a run with one worn unit, is refused by name."""
    _, robot, logs, _ = fleet
    first = {r["axis"]: r for r in reversed(rows(monitored / "wear.csv")) if r["unit"] == "unit02"}
    assert {(r["scale_factor"], r["scale_factor_sd"]) for r in first.values()} == {("1", "0.3")}
    out = tmp_path / "prior"
    loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False,
                             scale_prior=scale_prior.ScalePrior(1.2, 0.1)))
    first = {r["axis"]: r for r in reversed(rows(out / "wear.csv")) if r["unit"] == "unit02"}
    assert {(r["scale_factor"], r["scale_factor_sd"]) for r in first.values()} == {("1.2", "0.1")}
    settings = json.loads((out / "settings.json").read_text())
    assert (settings["scale_prior_mean"], settings["scale_prior_sd"]) == (1.2, 0.1)
    with pytest.raises(stored.StateError, match=r"other settings or inputs: scale_prior_mean 1\.2 \(now"):
        loop.monitor(resolve_run(robot, logs, out, calibrate=False, settings=SETTINGS, progress=False))
    with pytest.raises(ValueError, match="0 units' axes whose friction tests saw their wear.*at least 3"):
        resolve_run(robot, logs, tmp_path / "again", calibrate=False, settings=SETTINGS,
                    scale_prior=monitored)
    with pytest.raises(ValueError, match="the run's own output folder; expected another run's"):
        resolve_run(robot, logs, monitored, calibrate=False, settings=SETTINGS, scale_prior=monitored)
