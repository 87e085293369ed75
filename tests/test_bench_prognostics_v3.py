"""Issue 85: the prognostics track's version 3 (lives set by duty and unit, mixed growth laws, censored
and healthy units, test variants) made against its frozen manifest, its generator against hand
computations, and its scoring (scores at lambda, paired bootstrap verdicts, the load-life and oracle
baselines) against hand-built units; the twin emulated from its measured error (its readings' error,
its tests' factor, its alarm, its rows scored by the monitor's remaining life)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from faultgen.bench import files, make, prognosers, prognosers_v3, prognostics_v3, rul_v3, tracks, twin_emulator


@pytest.fixture(scope="module")
def v3_small(tmp_path_factory):
    """Version 3 at its test size, made by the command (it starts itself again in the numeric profile)."""
    folder = tmp_path_factory.mktemp("v3") / "v3"
    done = subprocess.run([sys.executable, "-m", "faultgen.cli", "bench", "make", "prognostics", "--version", "3",
                           "--size", "small", "--no-progress", "-o", str(folder)],
                          check=False, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return folder


def test_v3_small_is_made_identical_to_its_frozen_manifest_with_every_variant(v3_small):
    manifest = json.loads((v3_small / "manifest.json").read_text())
    assert (manifest["version"], manifest["status"]) == (3, "checked")
    frozen = json.loads(make.manifest_path("prognostics", 3, "small").read_text())["arrays"]
    assert manifest["arrays"] == frozen
    names = {p.name for p in v3_small.glob("test-*.h5")}
    assert names == {f"test-{v}.h5" for v in prognostics_v3.VARIANTS if v != prognostics_v3.DEFAULT_VARIANT}
    assert any(k.startswith("test-noscatter-none.h5:") for k in frozen)  # the variants are in the manifest
    test = files.attach_labels(files.read(v3_small / "test.h5"), v3_small / "test_labels.csv")
    assert all(u.fault_level is None for u in files.read(v3_small / "test-scatter-7.h5"))
    # the units a split holds are the generator's, in the make's shuffled order (small: 3 failing units per seed)
    spec = dict(tracks.load("prognostics").version(3).records("test", "small")[0][1])
    expected = prognostics_v3.split_units(spec)[prognostics_v3.DEFAULT_VARIANT]
    # made here, outside the make's numeric profile (faultgen.bench.profile): where NumPy runs its own AVX-512
    # loops the same units' levels differ from the make's in their last bits, so equal to rounding
    got, want = (sorted((np.asarray(u.fault_level, dtype=float) for u in units), key=lambda a: tuple(np.round(a, 6)))
                 for units in (test, expected))
    assert len(got) == len(want) and all(a.shape == b.shape for a, b in zip(got, want))
    assert all(np.allclose(a, b, rtol=1e-12, atol=1e-12) for a, b in zip(got, want))
    assert sum(u.worn_axis > 0 and (u.fault_level >= 40).any() for u in test) == 3
    for unit in test:  # what a method reads: the duty of the day beside the torques
        assert {"payload_mass", "speed_override", "operating_hours", "mean_abs_torque"} <= set(unit.arrays)
        assert not np.any(np.asarray(unit.arrays["cycles"]) % 7 == 0)  # no record on a day without work


def test_the_variants_hold_the_same_units_and_tests_and_differ_only_in_what_they_vary():
    spec = {"seed": 32, "failing": 2, "days": [60, 90], "onset": [3, 15], "life_days": 25.0}
    seen = prognostics_v3.split_units(spec, tuple(prognostics_v3.VARIANTS))
    for k, unit in enumerate(seen["scatter-14"]):
        for name, units in seen.items():
            other = units[k]
            np.testing.assert_array_equal(other.arrays["payload_mass"], unit.arrays["payload_mass"])
            np.testing.assert_array_equal(other.fault_level, unit.fault_level)
            assert ("friction_test" in other.arrays) == (not name.endswith("none"))
        days = unit.arrays["cycles"]
        on = np.asarray(unit.arrays["friction_test"], dtype=bool)
        assert list(days[on]) == [d for d in days if d % 14 == 1]
        # a day tested in two variants reads the same (day 29: every 7, 14 and 28 days)
        for name in ("scatter-7", "scatter-28"):
            row = list(seen[name][k].arrays["cycles"]).index(29)
            np.testing.assert_array_equal(seen[name][k].arrays["friction_test_coulomb"][row],
                                          unit.arrays["friction_test_coulomb"][list(days).index(29)])
        # without the daily scatter the torque moves, the duty does not
        assert not np.array_equal(seen["noscatter-14"][k].arrays["mean_abs_torque"], unit.arrays["mean_abs_torque"])


def test_consumption_growth_and_wear_follow_the_load_life_law_and_the_laws():
    payload, override, hours = 25.0, 0.9, 15.0
    by_hand = [hours * (prognostics_v3.SPEED[j] * override / prognostics_v3.RATED_SPEED[j])
               * ((prognostics_v3.BASE[j] + prognostics_v3.PER_KG[j] * payload + prognostics_v3.INERTIAL[j]
                   * override ** 2) / prognostics_v3.RATED_TORQUE[j]) ** (10 / 3 if j < 3 else 3.0) for j in range(6)]
    np.testing.assert_allclose(prognostics_v3.consumption([payload], [override], [hours])[0], by_hand, rtol=1e-12)
    np.testing.assert_allclose(prognostics_v3.relative_duty(*([v] for v in prognostics_v3.REFERENCE)), 1.0)
    assert prognostics_v3.growth("power2", 0.5) == 0.25 and prognostics_v3.growth("power1.5", 0.25) == 0.125
    for law in prognostics_v3.LAWS:
        assert prognostics_v3.growth(law, 1.0) == pytest.approx(1.0) and prognostics_v3.growth(law, 0.0) == 0.0
    with pytest.raises(ValueError, match="growth law 'cubic'"):
        prognostics_v3.growth("cubic", 0.5)
    unit = next(u for u in (prognostics_v3.truth(32, k) for k in range(20)) if u.eol is not None)
    duty = prognostics_v3.relative_duty(unit.payload, unit.override, unit.hours)[:, unit.axis - 1]
    age = unit.factor * np.cumsum(duty * (np.arange(1, unit.days + 1) >= unit.onset)) / prognostics_v3.LIFE_DAYS
    np.testing.assert_allclose(unit.wear, np.minimum(40.0 * prognostics_v3.growth(unit.law, age), 100.0))
    assert unit.eol == 1 + int(np.argmax(unit.wear >= 40.0)) and unit.onset >= 5


def test_the_full_test_split_has_the_lives_spread_and_units_the_card_states():
    """The card (docs/bench/prognostics.md, version 3) states these figures of the full size's seeds."""
    recipe = tracks.load("prognostics").version(3)
    test = prognostics_v3.fleet(32, 32)
    train = [u for seed in (30, 31) for u in prognostics_v3.fleet(seed, 20)]
    figures = prognostics_v3.lives_summary(test)
    assert figures["failing"] == 32 and figures["life_cv"] >= 0.3
    assert prognostics_v3.lives_summary(train)["failing"] == 40 and prognostics_v3.lives_summary(train)["life_cv"] >= 0.3
    assert figures["healthy"] > 0 and figures["censored"] > 0
    assert {u.law for u in test if u.eol} == set(prognostics_v3.LAWS)
    assert [s["seed"] for _, s in recipe.records("test")] == [32]
    card = (Path(__file__).parents[1] / tracks.load("prognostics").card).read_text()
    assert f"coefficient of variation {figures['life_cv']:.2f}" in card
    assert f"{figures['units']} units: {figures['failing']} run to failure, {figures['censored']} censored, " \
           f"{figures['healthy']} healthy" in card


def test_the_scores_at_lambda_are_the_hand_computed_ones():
    got = rul_v3.at_lambda(np.array([120.0, 130.0, 140.0, np.inf]), now=100.0, eol=130.0)
    # remaining lives 20, 30, 40 and 365 (no end of life: HORIZON after now): median 35 against the true 30
    assert got["median"] == 35.0 and got["rul"] == 30.0
    assert got["ra"] == pytest.approx(1 - 5 / 30) and got["ae"] == 5.0
    assert got["al"] == 0.0  # one of four within +-6
    assert got["late"] == 0.0 and got["phm"] == pytest.approx(np.expm1(0.5))
    assert rul_v3.at_lambda(np.array([150.0]), 100.0, 130.0)["late"] == 1.0


def _rows(values: dict, scale: float = 1.0) -> list[dict]:
    return [{"unit": f"u{k}", "kind": "failing", "wear25": {"ra": v * scale, "al": 1.0 if v > 0.5 else 0.0,
                                                             "late": 0.0 if v > 0.5 else 1.0, "phm": 1 - v,
                                                             "ae": 10 * (1 - v)}}
            for k, v in values.items()]


def test_paired_verdicts_take_each_score_on_its_better_side():
    good, bad = _rows(dict(enumerate([0.9, 0.8, 0.95, 0.85, 0.9]))), _rows(dict(enumerate([0.1, 0.2, 0.0, 0.3, 0.1])))
    out = rul_v3.compare(good, bad, bad, "wear25")
    assert {s: d["verdict"] for s, d in out.items()} == dict.fromkeys(rul_v3.SCORES, "better")
    assert out["ra"]["value"] == pytest.approx(np.mean([0.8, 0.6, 0.95, 0.55, 0.8]))
    assert out["skill"]["value"] == pytest.approx(1 - np.mean([1, 2, 0.5, 1.5, 1]) / np.mean([9, 8, 10, 7, 9]))
    assert {d["verdict"] for d in rul_v3.compare(bad, good, bad, "wear25").values()} == {"worse"}
    mixed = _rows({0: 0.9, 1: 0.1, 2: 0.9, 3: 0.1})
    assert rul_v3.compare(mixed, _rows({0: 0.1, 1: 0.9, 2: 0.1, 3: 0.9}), bad, "wear25")["ra"]["verdict"] == \
        "not distinguishable"
    summary = rul_v3.summary(good, bad, "wear25")
    assert summary["skill"]["value"] == pytest.approx(1 - 1.2 / 8.6)  # mean absolute errors 1.2 and 8.6 days
    low, high = summary["ra"]["ci95"]
    assert low < summary["ra"]["value"] < high


def _unit(days: int, wear, axis: int = 2) -> files.Unit:
    """A unit on the reference duty every day (relative duty 1 a day; Sundays too), with labels."""
    day = np.arange(1, days + 1)
    payload, override, hours = prognostics_v3.REFERENCE
    arrays = {"cycles": day, "mean_abs_torque": np.ones((days, 6)), "payload_mass": np.full(days, payload),
              "speed_override": np.full(days, override), "operating_hours": np.full(days, hours)}
    unit = files.Unit(id="u", robot="r", task="t", sample="day", arrays=arrays)
    unit.fault_level, unit.worn_axis, unit.fault = np.asarray(wear, dtype=float), axis, "friction_wear"
    return unit


def test_the_oracle_finds_the_law_and_the_load_life_the_consumption_left():
    day = np.arange(1, 201)
    age = np.clip(day - 9, 0, None) / 90.0  # onset day 10, end of life on day 99 at duty 1 a day
    for law in prognostics_v3.LAWS:
        unit = _unit(200, 40.0 * prognostics_v3.growth(law, age))
        assert prognosers_v3.fit_law(np.arange(1.0, 60.0), unit.fault_level[9:68], 40.0)[0] == law
        shown = rul_v3._shown(unit, 60, labelled=True)
        assert prognosers_v3.Oracle().fit([], 40.0).predict(shown)[0] == pytest.approx(99.0)
    healthy = _unit(50, np.zeros(50), axis=0)
    assert np.isinf(prognosers_v3.Oracle().predict(rul_v3._shown(healthy, 30, labelled=True))).all()
    with pytest.raises(ValueError, match="labels are needed"):
        prognosers_v3.Oracle().predict(rul_v3._shown(healthy, 30, labelled=False))
    # train units fail at a consumption of 80 and 120 relative days of axis 2: at day 50 of a unit at duty 1,
    # 30 and 70 days are left
    train = [_unit(200, np.where(day >= life, 40.0, 0.0)) for life in (80, 120)]
    model = prognosers_v3.LoadLife().fit(train, 40.0)
    np.testing.assert_allclose(model.consumed_, [80.0, 120.0])
    np.testing.assert_allclose(model.predict(rul_v3._shown(_unit(200, np.zeros(200)), 50, False)), [80.0, 120.0])
    # a unit past the first: only the second is left
    np.testing.assert_allclose(model.predict(rul_v3._shown(_unit(200, np.zeros(200)), 100, False)), [120.0])


def test_the_command_scores_v3_with_every_baseline_and_its_variants(v3_small, tmp_path):
    from typer.testing import CliRunner

    from faultgen.cli import app

    runner = CliRunner()
    result = runner.invoke(app, ["bench", "score", "prognostics", "--data", str(v3_small), "--baseline", "oracle",
                                 "--variant", "noscatter-none", "-o", str(tmp_path / "o")])
    assert result.exit_code == 0, result.output
    row = next(line for line in result.output.splitlines() if line.startswith("| prognostics v3"))
    assert row.startswith("| prognostics v3 (small) noscatter-none | oracle |")
    assert row.count("|") == rul_v3.HEADER.count("|")
    written = json.loads((tmp_path / "o.json").read_text())
    assert written["comparable"] is True and written["variant"] == "noscatter-none"
    assert set(written["baselines"]) == set(rul_v3.BASELINES) - {"oracle"}
    head = written["anchors"][rul_v3.HEADLINE]
    assert head["results"]["ra"]["units"] == 3 and head["best_other"] in ("load_life", "linear", "exponential", "tests_fit")
    # the naive against itself: a difference of 0 on every unit
    naive = written["baselines"]["mean_life"]["anchors"][rul_v3.HEADLINE]["vs_naive"]["ra"]
    assert naive["value"] == 0 and naive["verdict"] == "not distinguishable"
    result = runner.invoke(app, ["bench", "score", "prognostics", "--data", str(v3_small), "--baseline", "oracle",
                                 "--variant", "foggy"])
    assert result.exit_code != 0 and "--variant 'foggy': expected one of scatter-14" in result.output


def test_a_records_part_is_checked_when_the_track_is_read():
    base = {"name": "x", "summary": "s", "licence": "CC0-1.0"}
    part = {"name": "p", "kind": "records", "records": {"failing": 2}, "colour": "red"}
    with pytest.raises(ValueError, match="records part 'p': unknown key 'colour'"):
        tracks.parse({**base, "versions": [{"version": 1, "train_seeds": [0], "test_seeds": [1], "parts": [part]}]}, "x")
    del part["colour"]
    track = tracks.parse({**base, "versions": [{"version": 1, "train_seeds": [0], "test_seeds": [1], "parts": [part]}]},
                         "x")
    assert track.version(1).records("test") == [("p-1", {"failing": 2, "seed": 1})]
    assert track.version(1).grids("test") == []


def test_a_variant_of_another_version_and_a_unit_without_duty_are_refused_by_name(tmp_path):
    from typer.testing import CliRunner

    from faultgen.cli import app

    unit = _unit(20, np.zeros(20))
    unit.fault_level = unit.worn_axis = unit.fault = None
    files.write(tmp_path / "test.h5", [unit], {"track": "prognostics", "version": 2, "size": "small"})
    result = CliRunner().invoke(app, ["bench", "score", "prognostics", "--data", str(tmp_path), "--baseline",
                                      "mean_life", "--variant", "scatter-7"])
    assert result.exit_code != 0
    assert "--variant scatter-7: only the prognostics track's version 3 has test variants" in result.output
    bare = _unit(20, np.where(np.arange(20) >= 10, 40.0, 0.0))  # runs to failure on day 11
    del bare.arrays["speed_override"], bare.arrays["operating_hours"]
    with pytest.raises(ValueError, match="unit u: no speed_override, operating_hours: the load-based baselines"):
        prognosers_v3.LoadLife().fit([bare], 40.0)


def _tested(wear, axis: int = 2, every: int = 7) -> files.Unit:
    """:func:`_unit` with a noise-free friction test every ``every`` days: each axis's dry level
    (1 + wear/100) exp(-0.012 (T - 20)) at a joint temperature swinging over 14-26 degC."""
    unit = _unit(len(wear), wear, axis)
    n = len(wear)
    temp = np.repeat((20.0 + 6.0 * np.sin(np.arange(n) / 9.0))[:, None], 6, axis=1)
    dry = np.ones((n, 6)) * prognostics_v3.DRY
    dry[:, axis - 1] *= 1.0 + np.asarray(wear) / 100.0
    on = np.arange(n) % every == 0
    unit.arrays.update(friction_test=on.astype(np.int8), friction_test_coulomb=np.where(
        on[:, None], dry * np.exp(-0.012 * (temp - 20.0)), 0.0), friction_test_temperature=np.where(on[:, None], temp, 0.0))
    return unit


def test_the_tests_fit_learns_the_temperature_slope_and_finds_the_end_of_life_of_clean_tests():
    day = np.arange(1, 201)
    age = np.clip(day - 19, 0, None) / 90.0  # onset day 20, end of life on day 109 at duty 1 a day
    train = [_tested(40.0 * prognostics_v3.growth(law, age)) for law in prognostics_v3.LAWS]
    model = prognosers_v3.TestsFit().fit(train, 40.0)
    assert model.slope_ == pytest.approx(-0.012, rel=1e-6)
    unit = _tested(40.0 * prognostics_v3.growth("power1.5", age))
    assert model.predict(rul_v3._shown(unit, 25, False)) is None  # four tests, no wear yet
    drawn = model.predict(rul_v3._shown(unit, 80, False))  # wear 22 % on day 80
    assert np.median(drawn) == pytest.approx(109.0, abs=0.1 * (109 - 80))  # within 10 % of the 29 days left
    assert model.predict(rul_v3._shown(_unit(200, age * 0), 80, False)) is None  # no tests, no prediction


def _alarm_by_loop(wear: np.ndarray):
    """:func:`twin_emulator.known_alarm` written again as a loop over the logs (an independent reference)."""
    p, run = twin_emulator.PERSISTENCE, np.zeros(wear.shape[1], dtype=int)
    for i in range(p - 1, len(wear)):
        lower = wear[i - p + 1:i + 1].mean(axis=0) - twin_emulator.ALARM_Z * twin_emulator.FILTER_SD
        run = np.where(lower >= twin_emulator.WEAR_LIMIT, run + 1, 0)
        if (run >= p).any():
            return int(np.argmax(run >= p)) + 1, i - p + 1, i
    return None


def test_the_emulated_twins_readings_have_the_error_stated_from_the_monitors_measured_one(v3_small):
    test = files.attach_labels(files.read(v3_small / "test.h5"), v3_small / "test_labels.csv")
    error = np.concatenate([(twin_emulator.readings(u, 0) - twin_emulator.twin_scale(0, u.id)
                             * twin_emulator.true_wear(u)).ravel() for u in test])
    assert error.size > 1000 and abs(error.mean()) < 4 * twin_emulator.LOG_SD / np.sqrt(error.size)
    assert error.std() == pytest.approx(twin_emulator.LOG_SD, rel=0.08)
    scales = np.log([twin_emulator.twin_scale(0, f"unit-{k}") for k in range(2000)])
    assert abs(scales.mean()) < 0.02 and scales.std() == pytest.approx(twin_emulator.SCALE_LOG_SD, rel=0.06)
    for unit in test:  # a prefix reads what the whole record read on its days; the alarm as a loop finds it
        full = twin_emulator.readings(unit, 0)
        np.testing.assert_array_equal(twin_emulator.readings(rul_v3._shown(unit, 30, True), 0),
                                      full[:30])
        assert twin_emulator.known_alarm(full) == _alarm_by_loop(full)
        if unit.worn_axis and twin_emulator.known_alarm(full):
            assert twin_emulator.known_alarm(full)[0] == unit.worn_axis
    worn = next(u for u in test if u.worn_axis and (u.fault_level >= 40).any())
    n = int(np.argmax(worn.fault_level >= 40)) + 1
    f, error = twin_emulator.factor(rul_v3._shown(worn, n, True), 0, worn.worn_axis)
    # the tests take the twin's scale out: f times the scale is 1 within 3 of the factor's stated errors
    assert abs(f * twin_emulator.twin_scale(0, worn.id) - 1.0) < 3 * error < 3 * twin_emulator.FACTOR_PRIOR
    # the monitor's fit y = b + f x with its priors and forgetting, by the normal equations written out
    days = worn.arrays["cycles"][:n][(worn.arrays["cycles"][:n] - 1) % 14 == 0]
    truth = worn.fault_level[np.searchsorted(worn.arrays["cycles"], days)]
    x = twin_emulator.twin_scale(0, worn.id) * truth + twin_emulator.FILTER_SD * twin_emulator._rng(
        0, worn.id, 3).standard_normal(400)[days - 1]
    y = truth + twin_emulator.TEST_SD * twin_emulator._rng(0, worn.id, 2).standard_normal(400)[days - 1]
    w = 0.6 ** np.arange(len(days) - 1, -1, -1) / twin_emulator.TEST_SD ** 2
    normal = np.array([[w.sum() + 1 / 10.0 ** 2, w @ x], [w @ x, w @ x ** 2 + 1 / 0.5 ** 2]])
    b_f = np.linalg.solve(normal, [w @ y, w @ (x * y) + 1 / 0.5 ** 2])
    assert f == pytest.approx(b_f[1], rel=1e-9)
    assert error * f == pytest.approx(np.sqrt(np.linalg.inv(normal)[1, 1]), rel=1e-9)
    with pytest.raises(ValueError, match="emulated twin reads the true wear"):
        twin_emulator.readings(prognosers.prefix(worn, 5), 0)


def test_the_emulated_twins_rows_are_scored_with_the_monitors_remaining_life(v3_small):
    from faultgen.monitor import prognosis

    train = files.read(v3_small / "train.h5")
    test = files.attach_labels(files.read(v3_small / "test.h5"), v3_small / "test_labels.csv")
    twins = {"without tests": twin_emulator.EmulatedTwin(prognosis.remaining_life, samples=100),
             "with tests": twin_emulator.EmulatedTwin(prognosis.remaining_life, 14, samples=100)}
    per_method = {"mean_life": rul_v3.rows_of(prognosers.MeanLife(), "mean_life", train, test)}
    for name, twin in twins.items():
        per_method[name] = rul_v3.rows_of(twin, name, train, test, labelled=twin.reads_labels)
    for name in twins:
        results = {**rul_v3.results_for(name, per_method), "size": "small", "date": "2026-11-27"}
        assert results["anchors"][rul_v3.HEADLINE]["best_other"] == ({*twins} - {name}).pop()
        assert results["verdict"].endswith("(relative accuracy at lambda = wear25, paired 95 % intervals)")
        row = rul_v3.markdown_row(results, "cmd")
        assert row.startswith(f"| prognostics v3 (small) | {name} | ") and row.count("|") == rul_v3.HEADER.count("|")
        assert results["no_eol_share"]["value"] == 1.0  # the healthy unit never alarms
    for unit in test:  # before the known alarm no end of life; from it on, the remaining life's draws
        known = twin_emulator.known_alarm(twin_emulator.readings(unit, 0))
        if known:
            assert twins["with tests"].predict(rul_v3._shown(unit, known[2], True)) is None
            drawn = twins["with tests"].predict(rul_v3._shown(unit, known[2] + 1, True))
            assert drawn.shape == (100,) and (drawn >= unit.arrays["cycles"][known[2]]).all()
    with pytest.raises(ValueError, match="tests_every = -1"):
        twin_emulator.EmulatedTwin(prognosis.remaining_life, -1)
