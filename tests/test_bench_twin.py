"""Issue 59, part 4: `faultgen monitor`'s twin on the leaderboard. Its answers per test unit (read from
the monitor's scores.csv and alarms.csv, faultgen.bench.twin) are scored by faultgen.bench.score's own
code through the detector and isolator contracts (faultgen.bench.recorded); the test split's raw logs
are written again from the track's recipe (faultgen.bench.rawlogs)."""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import bench_plugins
import numpy as np
import pytest

from faultgen.bench import files, rawlogs, recorded, score, twin
from faultgen.operation.conditions import Conditions, Payloads, TaskMix
from faultgen.simulation import stepping
from resolved_runs import run_config

ROOT = Path(__file__).resolve().parents[1]
N = 6


def _unit(uid: str, n: int, rng, level=None, axis=None) -> files.Unit:
    arrays = {"cycles": np.arange(1, n + 1)}
    for name in files.FEATURES:
        arrays[name] = rng.normal(size=(n, N))
    unit = files.Unit(id=uid, robot="kr210", task="pick_place", sample="log", arrays=arrays)
    if level is not None:
        unit.fault_level, unit.worn_axis, unit.fault = level, axis, "friction_wear" if axis else "none"
    return unit


def _write_csv(path: Path, columns, rows) -> None:
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(columns)
        writer.writerows(rows)


@pytest.fixture
def injected(tmp_path):
    """A benchmark folder of 3 test units (20 logs each: a healthy unit, and units wearing axes 2 and 4
    from log 7, 10 % at log 11), and the monitor's output of a known outcome: the wear bounds rise on
    the worn units from log 11 (alarms on logs 13-20 of the first, 15-20 of the second), the healthy
    unit alarms on its logs 17 and 19 only; the first worn unit's alarm names axis 2, the second's
    axis 5 (wrong); the second worn unit's logs 1-3 have no row (the monitor gave none)."""
    rng = np.random.default_rng(0)
    n = 20
    level = np.clip((np.arange(1, n + 1) - 6) * 2.0, 0, None)  # 0 up to log 6, 2 % at log 7, 10 % at log 11
    truth = {"test-000": (level, 2), "test-001": (np.zeros(n), 0), "test-002": (level, 4)}
    units = [_unit(uid, n, rng, *truth[uid]) for uid in truth]
    data = tmp_path / "data"
    data.mkdir()
    attrs = {"track": "sim-to-real", "version": 2, "size": "small"}
    files.write(data / "train.h5", [_unit("train-000", n, rng, np.zeros(n), 0)], {**attrs, "split": "train"})
    files.write_labels(data / "test_labels.csv", units)
    for unit in units:
        unit.fault_level = unit.worn_axis = unit.fault = None
    files.write(data / "test.h5", units, {**attrs, "split": "test"})
    logs, out = tmp_path / "logs", tmp_path / "monitor"
    out.mkdir()
    names = {"test-000": "unit03", "test-001": "unit01", "test-002": "unit02"}
    stamps = [f"2026-01-{d:02d}" for d in range(5, 5 + n)]
    score_rows, columns = [], ["unit", "stamp", "phase", "alarm"] + [f"wear{i}_lower" for i in range(1, N + 1)]
    for uid, name in names.items():
        (logs / name).mkdir(parents=True)
        for stamp in stamps:
            (logs / name / f"{stamp}.csv").write_text("")
        for k, stamp in enumerate(stamps, start=1):
            if uid == "test-002" and k <= 3:
                continue
            bounds = [-5.0 + 0.01 * k] * N
            if uid != "test-001" and k >= 11:
                bounds[truth[uid][1] - 1] = 3.0 * (k - 10)  # reaches 10 % at log 14
            alarm = {"test-000": k >= 13, "test-001": k in (17, 19), "test-002": k >= 15}[uid]
            score_rows.append([name, stamp, "training" if k <= 10 else "monitoring", int(alarm), *bounds])
    _write_csv(out / "scores.csv", columns, score_rows)
    _write_csv(out / "alarms.csv", ["unit", "first_alarm", "source_axis"],
               [["unit03", stamps[12], 2], ["unit01", "", ""], ["unit02", stamps[14], 5]])
    written = rawlogs.Written(logs, "kr210", {uid: {name: np.arange(n)} for uid, name in names.items()})
    return data, out, written, units


def test_an_injected_outcome_gives_the_expected_figures_through_the_scorer(injected):
    data, out, written, units = injected
    scores, alarms, named, answered = twin.answers(out, written, {u.id: 20 for u in units})
    assert answered["test-000"].all() and answered["test-002"].tolist() == [False] * 3 + [True] * 17
    # the score is the largest bound of a log; a log without a row gets one below every score of the run
    assert scores["test-000"][13] == pytest.approx(12.0) and scores["test-001"][0] == pytest.approx(-4.99)
    assert np.all(scores["test-002"][:3] == pytest.approx(-5.0 + 0.04 - 1.0 - 0.03))  # the run's lowest (-4.96) - 1
    assert named == {"test-000": 2, "test-001": 0, "test-002": 5}
    detector = score.score(data, recorded.RecordedDetector(recorded.detector_answers(units, scores, alarms)),
                           twin.__name__, "detector", track="sim-to-real", allow_modified=True)["results"]
    # positives: logs 11-20 of the two worn units; negatives: the healthy unit's 20 logs and logs 1-6 of
    # the worn ones (0 %). Every positive's score (3-30) is above every negative's (< 0): AUROC 1
    assert detector["auroc"]["value"] == pytest.approx(1.0)
    assert detector["false_alarm_rate"]["value"] == pytest.approx(2 / 20)  # logs 17 and 19 of 20
    assert detector["detected_share"]["value"] == 1.0
    # onset the first of 3 alarms in a row: log 13 and 15, 10 % reached at log 11: delays 2 and 4, median 3
    assert detector["delay_after_10pct_logs"]["value"] == pytest.approx(3.0)
    assert [u["after_start"] for u in detector["per_unit"]] == [6.0, 8.0]  # the fault starts at log 7 (2 %)
    isolator = score.score(data, recorded.RecordedIsolator(recorded.isolator_answers(units, named)),
                           "twin", "isolator", track="sim-to-real", allow_modified=True)
    assert isolator["results"]["top1_accuracy"]["value"] == 0.5  # axis 2 right, axis 5 for 4 wrong
    assert isolator["results"]["undecided_on_healthy"]["value"] == 1.0
    row = score.markdown_row(isolator, "python benchmarks/twin_baseline.py --track sim-to-real --data d")
    assert row.startswith("| sim-to-real v2 (small) | twin | - | - | - | - | - | 50.0 [")


def test_a_unit_without_answers_is_refused_not_left_undecided(injected):
    data, out, written, units = injected
    scores, alarms, named, _ = twin.answers(out, written, {u.id: 20 for u in units})
    with pytest.raises(ValueError, match="no recorded answer for test unit test-001"):
        recorded.detector_answers(units, {k: v for k, v in scores.items() if k != "test-001"}, alarms)
    partial = recorded.RecordedIsolator(recorded.isolator_answers(units[:2], named))
    with pytest.raises(recorded.MissingAnswer):  # not the ValueError the scorer reads as "undecided"
        score.score(data, partial, "twin", "isolator", track="sim-to-real", allow_modified=True)
    with pytest.raises(ValueError, match="records, recorded scores of shape"):
        recorded.detector_answers(units, {**scores, "test-001": scores["test-001"][:5]}, alarms)


def test_a_task_mix_run_simulated_task_by_task_gives_the_tracks_cycles():
    """The conditions track's runs keep no signals (a task mix); each task's cycles simulated alone,
    with their signals, are the same cycles: the same features as the mixed run's."""
    mix = Conditions(payloads=Payloads(masses=(30.0, 90.0), sizes=(0.3, 0.4), pattern="random"),
                     task_mix=TaskMix(tasks=("pick_place", "spot_weld"), pattern="alternate"), cycles_per_day=10)
    config = run_config(robot="irb6700", task="pick_place", cycles=3, seed=3, nthread=1, conditions=mix,
                                signals=False)
    mixed = stepping.simulate(config, progress=False)
    parts = rawlogs._simulate(config, stepping)
    assert {k: v["rows"].tolist() for k, v in parts.items()} == {"pick_place": [0, 2], "spot_weld": [1]}
    for task, part in parts.items():
        assert part["q"].shape[0] == len(part["rows"]) and part["tau"].shape == part["q"].shape
        np.testing.assert_array_equal(part["payload_mass"], mixed.conditions.payload_mass[part["rows"]])
        for name in files.FEATURES:
            np.testing.assert_allclose(part["features"][name], mixed.features[name][part["rows"]], rtol=1e-9, atol=1e-9)


def test_the_twin_on_the_small_sim_to_real_fleet_goes_through_the_scorer_to_a_row(shared_bench, tmp_path,
                                                                                  monkeypatch, capsys):
    """The small sim-to-real track as `faultgen bench make` made it (conftest.py's shared_bench: its test
    split the independent simulator's fleet, in make's seeded order) and the script on it: the fleet
    written again, tied by features, `faultgen monitor --no-calibrate`, scored against the frozen
    manifest; both rows printed and their JSON written. The script runs in this process, as `python
    SCRIPT` runs it (its `faultgen monitor` is a process of its own, as before)."""
    import runpy

    data = shared_bench("sim-to-real")
    labelled = files.attach_labels(files.read(data / "test.h5"), data / "test_labels.csv")
    truth = {u.id: u.worn_axis for u in labelled}
    script = ROOT / "benchmarks/twin_baseline.py"
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(score, "RESAMPLES", bench_plugins.FEW_RESAMPLES)  # the script's scorer; no interval read
    monkeypatch.setattr(sys, "argv", [str(script), "--track", "sim-to-real", "--data", str(data), "--work",
                                      str(tmp_path / "work"), "--no-calibrate", "-o", str(tmp_path / "score-twin")])
    capsys.readouterr()
    runpy.run_path(str(script), run_name="__main__")  # raises SystemExit if the script or its monitor fails
    rows = [line for line in capsys.readouterr().out.splitlines() if line.startswith("| sim-to-real v2 (small) | twin")]
    assert len(rows) == 2 and rows[0].split(" | ")[2] != "-" and rows[1].split(" | ")[7].endswith("(chance 16.7)")
    written = [json.loads((tmp_path / f"score-twin-{role}.json").read_text())
               for role in ("detector", "isolator")]
    assert all(w["comparable"] is True for w in written)  # the folder is the track's frozen version
    detector, isolator = (w["results"] for w in written)
    assert sorted(u["unit"] for u in detector["per_unit"]) == sorted(k for k, v in truth.items() if v)
    assert {a["unit"]: a["worn_axis"] for a in isolator["per_unit"]} == truth
    # what the twin does on this fleet (seed 2: units wearing axes 1 and 3, one healthy): it names both
    # worn axes, alarms on no healthy log, and ranks the worn logs above the healthy ones
    assert isolator["top1_accuracy"]["value"] == 1.0 and isolator["undecided_on_healthy"]["value"] == 1.0
    assert detector["false_alarm_rate"]["value"] == 0.0 and detector["auroc"]["value"] > 0.8
