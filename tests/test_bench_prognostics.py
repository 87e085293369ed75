"""Issue 59 part 3: the prognostics track (run-to-failure units; train by faultgen, test by the
independent simulator with its truth apart), made against its frozen manifest, and its scoring with
ProgPy's metrics beside the naive prognoser; the degradation baselines on units whose end of life is
known in closed form; the prognoser contract's errors."""

from __future__ import annotations

import json
from typing import ClassVar

import numpy as np
import pytest
from typer.testing import CliRunner

from faultgen.bench import baselines, files, independent, make, prognosers, prognostics
from faultgen.cli import app


@pytest.fixture(scope="module")
def small(shared_bench):
    """The latest version (2: version 1 with friction tests) at its test size, made by the command (in its
    numeric profile) once a session (conftest.py)."""
    folder = shared_bench("prognostics")
    return folder, json.loads((folder / "manifest.json").read_text())


def test_the_track_is_made_again_identical_to_its_frozen_manifest_with_run_to_failure_units(small):
    folder, manifest = small
    assert manifest["status"] == "checked"  # faultgen/bench/manifests/prognostics-<latest>-small.json
    frozen = make.manifest_path("prognostics", manifest["version"], "small")
    assert manifest["arrays"] == json.loads(frozen.read_text())["arrays"]
    train, test = files.read(folder / "train.h5"), files.read(folder / "test.h5")
    assert {(u.robot, u.sample) for u in train} == {("kr210", "cycle")}
    assert {(u.robot, u.sample) for u in test} == {("kr210", "log")}
    assert all(u.fault_level is None for u in test)
    failure = prognostics.FAILURE_WEAR[1]
    # every unit of both splits runs to failure within its record
    assert all(u.worn_axis and prognosers.end_of_life(u, failure) is not None for u in train)
    labelled = files.attach_labels(test, folder / "test_labels.csv")
    assert all(u.worn_axis and prognosers.end_of_life(u, failure) is not None for u in labelled)
    # the labels apart are the independent simulator's truth (small fleet part: 3 units, all worn)
    spec = independent.FleetSpec(units=3, worn=3, days=24, onset=(3, 6), final_wear=60.0, seed=2)
    truth = {}
    for unit, _, axis, wear in independent.truth_rows(spec):
        truth.setdefault(unit, (axis, []))[1].append(float(wear))
    got = sorted((u.worn_axis, tuple(np.round(u.fault_level, 4))) for u in labelled)
    assert got == sorted((axis, tuple(wear)) for axis, wear in truth.values())


def test_the_naive_prognosers_relative_accuracy_matches_a_hand_computation(small):
    """mean_life scored against itself: the verdict says so, and its relative accuracy at lambda is
    ``1 - |RUL - mean predicted RUL| / RUL`` computed here without ProgPy."""
    folder, _ = small
    results = prognostics.score(folder, prognostics.baseline("mean_life"), "mean_life")
    assert results["verdict"].startswith("not distinguishable") and results["ra_lambda_minus_naive"]["value"] == 0
    train = files.read(folder / "train.h5")
    lives = np.array([prognosers.end_of_life(u, 40.0) for u in train])
    test = {u.id: u for u in files.attach_labels(files.read(folder / "test.h5"), folder / "test_labels.csv")}
    assert len(results["per_unit"]) == len(test) == 3
    for row in results["per_unit"]:
        cycles = test[row["unit"]].arrays["cycles"].astype(float)
        at = cycles[cycles >= row["lambda"]][0]
        rul = row["eol"] - at
        assert row["ra_lambda"] == pytest.approx(1 - abs(rul - (np.maximum(lives, at).mean() - at)) / rul)
        # alpha-lambda by hand: at least half the samples within +-20 % of the true remaining life
        inside = np.abs(np.maximum(lives, at) - row["eol"]) <= 0.2 * rul
        assert row["alpha_lambda"] == (inside.mean() >= 0.5)


class Oracle:
    """Knows each test unit's end of life (from the labels, given by the test): exact predictions."""

    lives: ClassVar[dict] = {}

    def fit(self, units, failure_wear):
        return self

    def predict(self, unit):
        return np.full(10, self.lives[unit.id])


class NaN:
    def fit(self, units, failure_wear):
        return self

    def predict(self, unit):
        return np.array([np.nan])


class Raising(NaN):
    def predict(self, unit):
        raise KeyError("torque")


def test_an_exact_prognoser_meets_every_metric_and_is_judged_above_the_naive_one(small):
    folder, _ = small
    test = files.attach_labels(files.read(folder / "test.h5"), folder / "test_labels.csv")
    Oracle.lives = {u.id: prognosers.end_of_life(u, 40.0) for u in test}
    results = prognostics.score(folder, Oracle(), "oracle")
    r = results["results"]
    assert r["alpha_lambda_share"]["value"] == 1.0 and r["ra_lambda"]["value"] == 1.0
    # prognostic horizon: the whole span predicted, end of life minus the first prediction (the onset)
    assert [row["ph"] for row in results["per_unit"]] == [row["eol"] - row["onset"] for row in results["per_unit"]]
    assert results["verdict"].startswith("above the naive prognoser")
    with pytest.raises(ValueError, match="nan: predict\\(\\) at time .* NaN"):
        prognostics.score(folder, NaN(), "nan")
    with pytest.raises(ValueError, match="raising: predict\\(\\) on unit test-00\\d at time .* failed: KeyError"):
        prognostics.score(folder, Raising(), "raising")


def test_the_command_writes_the_row_and_the_verdict(small, tmp_path):
    folder, _ = small
    runner = CliRunner()  # in this process, as the other `bench score` tests run it
    done = runner.invoke(app, ["bench", "score", "prognostics", "--data", str(folder), "--baseline", "linear",
                               "-o", str(tmp_path / "lin")])
    assert done.exit_code == 0, done.output
    assert "| prognostics v2 (small) | linear |" in done.stdout and "verdict: " in done.stdout
    saved = json.loads((tmp_path / "lin.json").read_text())
    assert saved["naive"]["ra_lambda"]["units"] == 3 and saved["verdict"] in done.stdout
    refused = runner.invoke(app, ["bench", "score", "prognostics", "--data", str(folder),
                                  "--baseline", "pca"])
    assert refused.exit_code != 0 and "unknown prognostics baseline 'pca'" in refused.stderr


def _unit(uid, law, days, axis, rng, failure=40.0):
    """A synthetic unit: wear ``law(day)`` % on ``axis`` (1-based) raising its mean absolute torque by
    0.1 % per % of wear over 20 N m, plus 0.3 N m per kg of a weekly payload and small noise."""
    cycles = np.arange(1, days + 1)
    wear = law(cycles.astype(float))
    payload = np.where((cycles // 7) % 2, 30.0, 10.0)
    torque = 20.0 + 0.3 * payload[:, None] + rng.normal(0, 0.01, (days, 3))
    torque[:, axis - 1] += 20.0 * 0.001 * wear
    unit = files.Unit(id=uid, robot="r", task="t", sample="log",
                      arrays={"cycles": cycles, "mean_abs_torque": torque, "payload_mass": payload})
    unit.fault_level, unit.worn_axis, unit.fault = wear, axis, "friction_wear"
    return unit


@pytest.mark.parametrize("name, law", [
    ("linear", lambda slope: (lambda d: slope * d)),
    ("exponential", lambda slope: (lambda d: slope * 30.0 * np.expm1(d / 30.0))),
])
def test_a_degradation_baseline_finds_the_end_of_life_of_its_own_law(name, law):
    """Train units of one law at two speeds; a test unit at a third: the median prediction half-way
    to the end of life is within 5 % of the true end of life (closed form), on the worn axis."""
    rng = np.random.default_rng(0)
    train = [_unit(f"train-{k}", law(s), 120, 2, rng) for k, s in enumerate((0.5, 0.8))]
    test = _unit("test", law(0.6), 120, 2, rng)
    eol = prognosers.end_of_life(test, 40.0)
    prognoser = baselines.make(name)[1].fit(train, 40.0)
    # 0.8 N m at 40 % wear over the level of 20 N m with no part
    assert prognoser.levels_[2] == pytest.approx(0.04, rel=0.05)
    now = int(eol // 2)
    predicted = prognoser.predict(prognosers.prefix(test, now))
    assert prognoser._axis(prognosers.prefix(test, now))[0] == 1
    assert np.median(predicted) == pytest.approx(eol, rel=0.05)
    again = baselines.make(name)[1].fit(train, 40.0).predict(prognosers.prefix(test, now))
    assert np.array_equal(predicted, again)  # same records, same draws


def test_a_prognoser_spec_is_checked_by_name():
    with pytest.raises(ValueError, match="expected package.module:Class"):
        prognosers.load("nocolon")
    with pytest.raises(ValueError, match="has no class 'Nope'"):
        prognosers.load("faultgen.bench.prognosers:Nope")
    with pytest.raises(ValueError, match="no fit and no predict"):
        prognosers.load("collections:OrderedDict")
    assert isinstance(prognosers.load("faultgen.bench.prognosers:MeanLife"), prognosers.MeanLife)
