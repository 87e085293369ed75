"""`faultgen logs import` (faultgen.data.fleetlogs, issue 46 item 1): a fleet's measured logs as a
dataset, its records computed by the code of a simulated fleet's, labels from events, bad files,
growing folders, changed files, and a kill."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.data import dataset, fleetlogs, logfolder, reader
from faultgen.logs import measured
from faultgen.data import logfiles
from faultgen.model import robots
from faultgen.operation import programs
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim

sys.path.insert(0, str(Path(__file__).parent))
import fleetlog_folder  # noqa: E402
from resolved_runs import run_config

runner = CliRunner()
FEATURES = ("mean_abs_torque", "rms_torque", "average_speed", "average_load_torque", "angle_hist", "speed_hist",
            "torque_hist")


@pytest.fixture(scope="module")
def puma():
    return robots.load("puma560")


@pytest.fixture
def logs(tmp_path, puma):
    return fleetlog_folder.write_fleet(tmp_path / "LOGS", puma, units=2, days=6, worn={0: (2, 2, 0.3)})


def features_of(path: Path, robot) -> dict[str, np.ndarray]:
    """A log's record computed here from the shared functions: its cycles through
    sensors.cycle_features, reduced by sensors.daily_features."""
    data = measured.read(path, robot)
    tau_m = data.tau / robot.gear_ratio
    speed_limit = programs.robot_limits(robot)[0]
    cycles = [data.cycle == c for c in np.unique(data.cycle)]
    per_cycle = [sensors.cycle_features(data.q[None, m], data.qd[None, m], tau_m[None, m], robot.joint_range,
                                        speed_limit, robot.motor_torque_limit) for m in cycles]
    return sensors.daily_features({k: np.concatenate([f[k] for f in per_cycle]) for k in per_cycle[0]}, len(cycles))


def test_the_records_are_the_shared_functions_features_of_each_log(logs, tmp_path, puma):
    out = tmp_path / "fleet.h5"
    summary = fleetlogs.import_logs(logs, out, robot="puma560", progress=False)
    assert summary.units == 2 and len(summary.imported) == 12 and summary.kept == 0
    assert dataset.validate(out) == []
    with reader.open(out) as data:
        assert data.kind == "fleet" and [r.id for r in data] == ["u1", "u2"]
        for run in data:
            assert run.measured and run.sample == "log" and not run.has_signals
            stamps = [s.decode() for s in run.array("stamp")]
            assert stamps == sorted(stamps) and len(stamps) == 6
            assert np.all(run.array("log_cycles") == 2)
            for i, stamp in enumerate(stamps):
                expected = features_of(logs / run.id / f"{stamp}.csv", puma)
                for name in FEATURES:
                    np.testing.assert_array_equal(run.array(name)[i:i + 1], expected[name], err_msg=name)
    # the speed histogram's range is the one the robot's simulated thesis tasks use
    np.testing.assert_array_equal(programs.robot_limits(puma)[0], programs.load(puma, "pick_place").velocity_limit)


def test_a_simulated_cycle_imported_as_a_log_has_the_simulated_features(tmp_path, puma):
    """The same code, checked end to end: a cycle simulated with its signals, written as a measured
    log (arm-side torque = motor torque x gear ratio), imported, gives the features the simulation
    recorded for it (up to the rounding of the torque's product and quotient)."""
    result = sim.simulate(run_config(robot="puma560", task="pick_place", cycles=1), progress=False)
    folder = tmp_path / "LOGS" / "sim"
    folder.mkdir(parents=True)
    logfiles.write_hdf5(folder / "1.h5", result.t, result.q_a[0], result.tau_m[0] * puma.gear_ratio, result.qd_a[0])
    fleetlogs.import_logs(tmp_path / "LOGS", tmp_path / "sim.h5", robot=puma, progress=False)
    with reader.open(tmp_path / "sim.h5") as data:
        run = data["sim"]
        for name in FEATURES:
            np.testing.assert_allclose(run.array(name), result.features[name], rtol=1e-12, atol=1e-12, err_msg=name)


def test_events_label_the_logs(tmp_path, puma):
    logs = fleetlog_folder.write_fleet(tmp_path / "LOGS", puma, units=3, days=8)
    (logs / "events.csv").write_text(
        "unit,stamp,event,axis\n"
        "u1,2026-03-03,onset,2\n"        # worn from day 3 ...
        "u1,2026-03-06,repair,2\n"       # ... to day 5; healthy again from day 6
        "u2,2026-03-05T12:00:00,failure,4\n"  # the log at or before the failure and all after: worn
        "u3,2026-03-04,healthy,\n")      # every axis healthy up to day 4
    fleetlogs.import_logs(logs, tmp_path / "fleet.h5", robot="puma560", progress=False)
    U, H, W = logfolder.UNKNOWN, logfolder.HEALTHY, logfolder.WORN
    with reader.open(tmp_path / "fleet.h5") as data:
        label = {run.id: run.array("label") for run in data}
        assert data["u1"].worn_axes == (2,) and data["u2"].worn_axes == (4,) and data["u3"].worn_axes == ()
        np.testing.assert_array_equal(label["u1"][:, 1], [U, U, W, W, W, H, H, H])
        np.testing.assert_array_equal(label["u2"][:, 3], [U, U, U, U, W, W, W, W])
        np.testing.assert_array_equal(label["u3"], np.repeat([[H], [H], [H], [H], [U], [U], [U], [U]], 6, axis=1))
        assert np.all(np.delete(label["u1"], 1, axis=1) == U)
        np.testing.assert_array_equal(data["u1"].array("friction_multiplier")[:, 1],
                                      np.where(label["u1"][:, 1] == W, fleetlogs.WORN_MARK, 1.0))
        assert data["u1"].fault_begins == 2


@pytest.mark.parametrize("row, message", [
    ("u9,2026-03-01,repair,2", "line 2: unit 'u9' has no folder"),
    ("u1,3,repair,2", "line 2: stamp '3' is a sequence stamp, but the logs of u1 have time stamps"),
    ("u1,2026-03-01,exploded,2", "line 2: event 'exploded'; expected one of"),
    ("u1,2026-03-01,repair,7", "line 2: axis '7'; expected an axis 1..6"),
    ("u1,2026-03-01,repair,", "line 2: axis ''; expected an axis 1..6"),
])
def test_a_bad_event_is_refused_naming_the_line(logs, tmp_path, row, message):
    (logs / "events.csv").write_text(f"unit,stamp,event,axis\n{row}\n")
    result = runner.invoke(app, ["logs", "import", str(logs), "--robot", "puma560", "-o", str(tmp_path / "f.h5")])
    assert result.exit_code == 2 and message in result.output and "events.csv" in result.output, result.output
    assert not (tmp_path / "f.h5").exists()


def test_a_bad_log_is_refused_with_its_file_and_row_and_skip_bad_lists_it(logs, tmp_path):
    bad = logs / "u2" / "2026-03-04.csv"
    lines = bad.read_text().splitlines()
    cells = lines[10].split(",")
    cells[3] = "nan"
    lines[10] = ",".join(cells)
    bad.write_text("\n".join(lines) + "\n")
    (logs / "u1" / "notes.txt").write_text("not a log")
    out = tmp_path / "f.h5"
    result = runner.invoke(app, ["logs", "import", str(logs), "--robot", "puma560", "-o", str(out), "--no-progress"])
    assert result.exit_code == 2 and "u1/notes.txt: not a log" in result.output, result.output
    (logs / "u1" / "notes.txt").unlink()
    result = runner.invoke(app, ["logs", "import", str(logs), "--robot", "puma560", "-o", str(out), "--no-progress"])
    assert result.exit_code == 2, result.output
    assert f"{bad}: data row 10 (line 11), column q3: value 'nan' (NaN)" in result.output
    assert not out.exists() and not list(tmp_path.glob(".f.h5*"))
    (logs / "u1" / "notes.txt").write_text("not a log")
    result = runner.invoke(app, ["logs", "import", str(logs), "--robot", "puma560", "-o", str(out), "--no-progress",
                                 "--skip-bad"])
    assert result.exit_code == 0, result.output
    assert "skipped:       2 bad file(s)" in result.output and "u2/2026-03-04.csv: data row 10" in result.output
    assert "u1/notes.txt: not a log" in result.output and "imported now:  11" in result.output
    with reader.open(out) as data:
        assert len(data["u2"].array("stamp")) == 5 and b"2026-03-04" not in list(data["u2"].array("stamp"))


def test_a_grown_folder_imports_only_its_new_logs_and_equals_a_fresh_import(tmp_path, puma):
    logs = fleetlog_folder.write_fleet(tmp_path / "LOGS", puma, units=2, days=4)
    out = tmp_path / "f.h5"
    fleetlogs.import_logs(logs, out, robot="puma560", progress=False)
    again = fleetlogs.import_logs(logs, out, robot="puma560", progress=False)
    assert not again.written and again.kept == 8 and again.imported == []
    fleetlog_folder.write_fleet(tmp_path / "LOGS", puma, units=3, days=6)  # two more days, a new unit
    (logs / "events.csv").write_text("unit,stamp,event,axis\nu1,2026-03-05,failure,3\n")
    grown = fleetlogs.import_logs(logs, out, robot="puma560", progress=False)
    assert grown.kept == 8 and sorted(grown.imported) == sorted(
        [f"u{u}/2026-03-0{d}.csv" for u in (1, 2) for d in (5, 6)] + [f"u3/2026-03-0{d}.csv" for d in range(1, 7)])
    fleetlogs.import_logs(logs, tmp_path / "fresh.h5", robot="puma560", progress=False)
    with h5py.File(out) as a, h5py.File(tmp_path / "fresh.h5") as b:
        assert list(a["runs"]) == list(b["runs"]) == ["u1", "u2", "u3"]
        for unit in a["runs"]:
            assert set(a["runs"][unit]) == set(b["runs"][unit])
            for name in a["runs"][unit]:
                np.testing.assert_array_equal(a["runs"][unit][name][()], b["runs"][unit][name][()], err_msg=name)
        np.testing.assert_array_equal(a["import"]["sha256"][()], b["import"]["sha256"][()])
    # a log gone from the folder keeps its record
    (logs / "u2" / "2026-03-01.csv").unlink()
    fleetlog_folder.write_log(logs / "u2" / "2026-03-07.csv", puma, 6, 1, np.zeros(6))
    later = fleetlogs.import_logs(logs, out, robot="puma560", progress=False)
    assert later.gone == ["u2/2026-03-01.csv"] and later.imported == ["u2/2026-03-07.csv"]
    with reader.open(out) as data:
        assert [s.decode() for s in data["u2"].array("stamp")][:2] == ["2026-03-01", "2026-03-02"]
        assert len(data["u2"].array("stamp")) == 7


def test_a_changed_log_is_named_and_reimported_only_when_asked(logs, tmp_path, puma):
    out = tmp_path / "f.h5"
    fleetlogs.import_logs(logs, out, robot="puma560", progress=False)
    before = out.read_bytes()
    changed = logs / "u1" / "2026-03-02.csv"
    fleetlog_folder.write_log(changed, puma, 1, 0, np.full(6, 0.5))
    result = runner.invoke(app, ["logs", "import", str(logs), "--robot", "puma560", "-o", str(out), "--no-progress"])
    assert result.exit_code == 2 and f"{changed} changed since it was imported" in result.output, result.output
    assert out.read_bytes() == before
    again = fleetlogs.import_logs(logs, out, robot="puma560", progress=False, reimport_changed=True)
    assert again.reimported == ["u1/2026-03-02.csv"] and again.imported == ["u1/2026-03-02.csv"]
    with reader.open(out) as data:
        np.testing.assert_array_equal(data["u1"].array("mean_abs_torque")[1:2],
                                      features_of(changed, puma)["mean_abs_torque"])
    result = runner.invoke(app, ["logs", "import", str(logs), "--robot", "irb6700", "-o", str(out), "--no-progress"])
    assert result.exit_code == 2 and "holds logs of robot 'puma560'" in result.output, result.output


def test_a_killed_import_leaves_no_complete_looking_file_and_the_rerun_finishes(tmp_path, puma):
    logs = fleetlog_folder.write_fleet(tmp_path / "LOGS", puma, units=2, days=12, suffix=".csv.gz")
    out = tmp_path / "f.h5"
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).parents[1]))
    command = [sys.executable, "-m", "faultgen.cli", "logs", "import", str(logs), "--robot", "puma560", "-o", str(out)]
    child = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not list(tmp_path.glob(".f.h5.*.part")) and child.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    child.send_signal(signal.SIGKILL)
    child.wait()
    assert child.returncode == -signal.SIGKILL, "the import ended before it could be killed"
    assert not out.exists()
    summary = fleetlogs.import_logs(logs, out, robot="puma560", progress=False)
    assert len(summary.imported) == 24 and dataset.validate(out) == []
    assert not list(tmp_path.glob(".f.h5.*.part"))


def test_a_failure_mid_import_keeps_the_previous_dataset(logs, tmp_path, puma, monkeypatch):
    out = tmp_path / "f.h5"
    fleetlogs.import_logs(logs, out, robot="puma560", progress=False)
    before = out.read_bytes()
    fleetlog_folder.write_fleet(logs, puma, units=2, days=8, worn={0: (2, 2, 0.3)})
    calls = []

    def failing(path, robot):
        calls.append(path)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return measured.read(path, robot)

    with pytest.raises(KeyboardInterrupt):
        fleetlogs.import_logs(logs, out, robot="puma560", progress=False, reader=failing)
    assert out.read_bytes() == before and not list(tmp_path.glob(".f.h5.*.part"))


@pytest.fixture(scope="module")
def imported(tmp_path_factory, puma):
    """An imported fleet of 6 units x 24 daily logs, units 1, 3 and 5 wearing axis 2, 4 and 3 from day 9
    (events.csv: onset), the others inspected healthy on day 8."""
    folder = tmp_path_factory.mktemp("imported")
    worn = {0: (2, 8, 0.2), 2: (4, 8, 0.2), 4: (3, 8, 0.2)}
    logs = fleetlog_folder.write_fleet(folder / "LOGS", puma, units=6, days=24, worn=worn, suffix=".h5")
    rows = [f"u{u + 1},2026-03-09,onset,{axis}" for u, (axis, _, _) in worn.items()]
    rows += [f"u{u},2026-03-08,healthy," for u in (2, 4, 6)]
    (logs / "events.csv").write_text("unit,stamp,event,axis\n" + "\n".join(rows) + "\n")
    fleetlogs.import_logs(logs, folder / "fleet.h5", robot="puma560", progress=False)
    return folder / "fleet.h5"


@pytest.mark.parametrize("args", [
    ["validate"], ["info"], ["info", "--card"], ["plot", "-o", "{stem}.png"], ["export", "-o", "{stem}.csv"],
    ["detect", "-o", "{stem}", "--no-progress"],
    ["classify", "-o", "{stem}", "--no-progress", "--jobs", "1", "--pairs", "3", "--classifier", "lr"],
    ["bench-isolators", "-o", "{stem}", "--no-progress"],
    ["training-source", "-o", "{stem}", "--no-progress", "--training-days", "10", "--test-days", "8", "--gap-days", "2"],
], ids=lambda a: a[0] + ("-card" if "--card" in a else ""))
def test_every_command_reads_an_imported_fleet(imported, tmp_path, args):
    stem = tmp_path / "out"
    command = [args[0], str(imported), *(a.format(stem=stem) for a in args[1:])]
    result = runner.invoke(app, command)
    assert result.exit_code == 0, result.output
    written = sorted(p.name for p in tmp_path.iterdir())
    assert args[0] in ("validate", "info") or written, written


@pytest.fixture(scope="module")
def other(tmp_path_factory, puma):
    """A second imported fleet of the same robot (other units: other noise, other worn axes)."""
    folder = tmp_path_factory.mktemp("other")
    worn = {1: (1, 6, 0.25), 3: (5, 6, 0.25)}
    logs = fleetlog_folder.write_fleet(folder / "LOGS", puma, units=5, days=20, worn=worn, suffix=".h5",
                                       start=fleetlog_folder.date(2025, 1, 1))
    rows = [f"u{u + 1},2025-01-07,onset,{axis}" for u, (axis, _, _) in worn.items()]
    (logs / "events.csv").write_text("unit,stamp,event,axis\n" + "\n".join(rows) + "\n")
    fleetlogs.import_logs(logs, folder / "other.h5", robot="puma560", progress=False)
    return folder / "other.h5"


def test_detect_trained_on_another_dataset_states_it_and_finds_the_wear(imported, other, tmp_path):
    result = runner.invoke(app, ["detect", str(imported), "--train", str(other), "--first", "6", "--no-progress",
                                 "-o", str(tmp_path / "d")])
    assert result.exit_code == 0, result.output
    table = pd.read_csv(tmp_path / "d.csv")
    assert list(table["run"]) == ["u1", "u3", "u5"]
    assert table["protocol"].str.startswith("another dataset (other.h5), each unit's features centred and scaled by "
                                            "its own first 6 records").all()
    assert (table["trained_on"] == "3 runs without wear of other.h5").all()
    assert table["detected"].all() and (table["onset_cycle"] >= table["fault_begins_cycle"]).all()
    result = runner.invoke(app, ["detect", str(imported), "--train", str(other), "--protocol", "same-run"])
    assert result.exit_code == 2 and "drop --protocol" in result.output


def test_classify_and_bench_isolators_trained_on_another_dataset(imported, other, tmp_path):
    result = runner.invoke(app, ["classify", str(imported), "--train", str(other), "--classifier", "lr",
                                 "--preprocessing", "control", "--no-progress", "-o", str(tmp_path / "c")])
    assert result.exit_code == 0, result.output
    assert "protocol: another dataset (other.h5)" in result.output and "tested on 3 worn and 3 unworn runs" in result.output
    table = pd.read_csv(tmp_path / "c.csv", header=[0, 1], index_col=0)
    cell = table.loc["control", "lr"]  # other axes wear in the training fleet: no claim on the AUC's size here
    assert 0 <= cell["auc"] <= 1 and 0 <= cell["null"] <= 1 and 0 < cell["p"] <= 1
    result = runner.invoke(app, ["bench-isolators", str(imported), "--train", str(other), "--baseline", "6",
                                 "--no-progress", "-o", str(tmp_path / "i")])
    assert result.exit_code == 0, result.output
    assert "protocol: pca_contribution: another dataset (other.h5)" in result.output
    result = runner.invoke(app, ["bench-isolators", str(imported), "--no-progress", "-o", str(tmp_path / "j")])
    assert "protocol: own history" in result.output


def test_a_training_set_of_another_robot_is_refused(imported, tmp_path):
    irb = robots.load("irb6700")
    logs = fleetlog_folder.write_fleet(tmp_path / "LOGS", irb, units=2, days=8, suffix=".h5")
    fleetlogs.import_logs(logs, tmp_path / "irb.h5", robot=irb, progress=False)
    result = runner.invoke(app, ["detect", str(imported), "--train", str(tmp_path / "irb.h5"), "--first", "4",
                                 "--no-progress", "-o", str(tmp_path / "d")])
    assert result.exit_code == 2, result.output
    assert "robots 'irb6700' and 'puma560'" in result.output and "differ in their joint range" in result.output


def _signals_frame(puma, day=3):
    t, q, qd, tau, cycle = fleetlog_folder.log_signals(puma, day, 0, np.zeros(6))
    return t, q, qd, tau, cycle


@pytest.mark.parametrize("layout", ["moment", "current"])
def test_a_ur_rtde_recording_imports_as_the_same_signals_in_the_measured_format(tmp_path, puma, layout):
    """The test writes the RTDE recorder's layout (space-separated; timestamp, actual_q_0..5,
    actual_qd_0..5, target_moment_0..5 or actual_current_0..5, other columns beside) and the same
    signals in the measured format: the two imports' records are equal."""
    t, q, qd, tau, _ = _signals_frame(puma)
    constants = np.array([2.0, 2.5, 3.0, 1.5, 1.0, 0.5])
    columns = {"timestamp": t, **{f"actual_q_{k}": q[:, k] for k in range(6)},
               **{f"actual_qd_{k}": qd[:, k] for k in range(6)}, "robot_mode": np.full(len(t), 7)}
    if layout == "moment":
        columns.update({f"target_moment_{k}": tau[:, k] for k in range(6)})
    else:
        columns.update({f"actual_current_{k}": tau[:, k] / constants[k] for k in range(6)})
    (tmp_path / "UR" / "cell1").mkdir(parents=True)
    pd.DataFrame(columns).to_csv(tmp_path / "UR" / "cell1" / "2026-03-01.csv", sep=" ", index=False)
    (tmp_path / "M" / "cell1").mkdir(parents=True)
    logfiles.write_csv(tmp_path / "M" / "cell1" / "2026-03-01.csv", t, q, tau, qd)
    command = ["logs", "import", str(tmp_path / "UR"), "--robot", "puma560", "--format", "ur-rtde", "-o",
               str(tmp_path / "ur.h5"), "--no-progress"]
    if layout == "current":
        result = runner.invoke(app, command)
        assert result.exit_code == 2 and "no joint torque" in result.output and "--torque-constants" in result.output
        command += ["--torque-constants", ",".join(map(str, constants))]
    result = runner.invoke(app, command)
    assert result.exit_code == 0, result.output
    fleetlogs.import_logs(tmp_path / "M", tmp_path / "m.h5", robot="puma560", progress=False)
    with reader.open(tmp_path / "ur.h5") as ur, reader.open(tmp_path / "m.h5") as ref:
        for name in FEATURES:
            np.testing.assert_allclose(ur["cell1"].array(name), ref["cell1"].array(name), rtol=1e-12, atol=1e-12)


def test_a_voraus_ad_parquet_imports_with_its_motor_torque_referred_to_the_arm(tmp_path, puma):
    """The test writes the voraus-AD layout (time, sample, joint_position_1..6, joint_velocity_1..6,
    motor_torque_1..6 at the motor, other columns beside) and the same signals in the measured format."""
    t, q, qd, tau, cycle = _signals_frame(puma)
    table = {"time": t, "sample": cycle, "anomaly": np.zeros(len(t), bool), "category": np.zeros(len(t), int),
             **{f"joint_position_{k + 1}": q[:, k] for k in range(6)},
             **{f"joint_velocity_{k + 1}": qd[:, k] for k in range(6)},
             **{f"motor_torque_{k + 1}": tau[:, k] / puma.gear_ratio[k] for k in range(6)},
             **{f"motor_position_{k + 1}": q[:, k] * puma.gear_ratio[k] for k in range(6)}}
    (tmp_path / "V" / "run7").mkdir(parents=True)
    pd.DataFrame(table).to_parquet(tmp_path / "V" / "run7" / "1.parquet")
    (tmp_path / "M" / "run7").mkdir(parents=True)
    fleetlog_folder.write_log(tmp_path / "M" / "run7" / "1.csv", puma, 3, 0, np.zeros(6))
    result = runner.invoke(app, ["logs", "import", str(tmp_path / "V"), "--robot", "puma560", "--format", "voraus",
                                 "-o", str(tmp_path / "v.h5"), "--no-progress"])
    assert result.exit_code == 0, result.output
    fleetlogs.import_logs(tmp_path / "M", tmp_path / "m.h5", robot="puma560", progress=False)
    with reader.open(tmp_path / "v.h5") as voraus, reader.open(tmp_path / "m.h5") as ref:
        assert voraus["run7"].array("log_cycles")[0] == 2
        for name in FEATURES:
            np.testing.assert_allclose(voraus["run7"].array(name), ref["run7"].array(name), rtol=1e-9, atol=1e-12)
    bad = pd.DataFrame(table).drop(columns=["motor_torque_4"])
    bad.to_parquet(tmp_path / "V" / "run7" / "1.parquet")
    result = runner.invoke(app, ["logs", "import", str(tmp_path / "V"), "--robot", "puma560", "--format", "voraus",
                                 "-o", str(tmp_path / "v2.h5"), "--no-progress"])
    assert result.exit_code == 2 and "missing column(s) motor_torque_4 of the voraus-AD layout" in result.output


def test_stamps_sort_as_numbers_or_times_and_a_unit_mixing_them_is_refused(tmp_path, puma):
    unit = tmp_path / "LOGS" / "press7"
    unit.mkdir(parents=True)
    for seq in (10, 2, 1):
        fleetlog_folder.write_log(unit / f"{seq}.csv.gz", puma, seq, 0, np.zeros(6))
    fleetlogs.import_logs(tmp_path / "LOGS", tmp_path / "f.h5", robot="puma560", progress=False)
    with reader.open(tmp_path / "f.h5") as data:
        assert [s.decode() for s in data["press7"].array("stamp")] == ["1", "2", "10"]
        np.testing.assert_array_equal(data["press7"].array("stamp_key"), [1.0, 2.0, 10.0])
    timed = tmp_path / "T" / "cell"
    timed.mkdir(parents=True)
    for stamp in ("2026-03-01T14-00-00", "2026-03-01T08:30:00", "2026-03-01"):
        fleetlog_folder.write_log(timed / f"{stamp}.h5", puma, 1, 0, np.zeros(6))
    fleetlogs.import_logs(tmp_path / "T", tmp_path / "t.h5", robot="puma560", progress=False)
    with reader.open(tmp_path / "t.h5") as data:
        assert [s.decode() for s in data["cell"].array("stamp")] == ["2026-03-01", "2026-03-01T08:30:00",
                                                                    "2026-03-01T14-00-00"]
    fleetlog_folder.write_log(unit / "2026-03-01.csv", puma, 1, 0, np.zeros(6))
    with pytest.raises(ValueError, match="mix dates and sequence numbers"):
        fleetlogs.import_logs(tmp_path / "LOGS", tmp_path / "g.h5", robot="puma560", progress=False)
    (unit / "2026-03-01.csv").unlink()
    fleetlog_folder.write_log(unit / "2.h5", puma, 1, 0, np.zeros(6))
    with pytest.raises(ValueError, match="have the same stamp"):
        fleetlogs.import_logs(tmp_path / "LOGS", tmp_path / "g.h5", robot="puma560", progress=False)


def test_training_source_with_another_dataset_as_the_one_to_many_source(imported, other, tmp_path):
    result = runner.invoke(app, ["training-source", str(imported), "--train", str(other), "--training-days", "10",
                                 "--test-days", "8", "--gap-days", "2", "--no-progress", "-o", str(tmp_path / "t")])
    assert result.exit_code == 0, result.output
    assert "protocol: OTO, own history" in result.output and f"another dataset (each normal robot of {other}" in \
        result.output
    cases = pd.read_csv(tmp_path / "t-cases.csv")
    otm = cases[cases["source"] == "OTM"]
    assert set(otm["reference"]) == {"other.h5:u1", "other.h5:u3", "other.h5:u5"}
    assert len(otm) == 3 * 6 * 3 and (cases[cases["source"] == "OTO"]["reference"] == cases[cases["source"] == "OTO"]["robot"]).all()


def test_a_log_replaced_mid_import_is_stored_under_the_digest_of_the_content_parsed(logs, tmp_path, puma):
    """The log is read once: its digest is that of the bytes parsed, even when the file is replaced
    between the hash and the parse (two reads stored the new content under the old one's digest)."""
    import hashlib

    victim = logs / "u1" / "2026-03-03.csv"
    parsed: dict[str, bytes] = {}

    def replaced_meanwhile(path, robot):
        if Path(path).name == victim.name and not parsed:
            fleetlog_folder.write_log(victim, puma, 2, 1, np.full(puma.n_axes, 0.5))  # another log, same name
            parsed[victim.name] = Path(path).read_bytes()
        return measured.read(path, robot, accelerations=False)

    out = tmp_path / "f.h5"
    fleetlogs.import_logs(logs, out, robot=puma, progress=False, reader=replaced_meanwhile)
    with h5py.File(out, "r") as f:
        manifest = dict(zip((n.decode() for n in f["import"]["file"][()]), (h.decode() for h in f["import"]["sha256"][()])))
    assert manifest["u1/2026-03-03.csv"] == hashlib.sha256(parsed[victim.name]).hexdigest()
    # what was parsed is what was there when the import began: the file now holds another content
    assert fleetlogs.sha256(victim) != manifest["u1/2026-03-03.csv"]
    result = runner.invoke(app, ["logs", "import", str(logs), "--robot", "puma560", "-o", str(out), "--no-progress"])
    assert result.exit_code == 2 and f"{victim} changed since it was imported" in result.output, result.output


def test_a_refusal_of_a_log_names_the_log(logs, tmp_path):
    bad = logs / "u2" / "2026-03-02.csv"
    bad.write_text("t,q1\n0,1\n")
    with pytest.raises(ValueError) as err:
        fleetlogs.import_logs(logs, tmp_path / "f.h5", robot="puma560", progress=False)
    assert str(err.value).startswith(f"{bad}: ") and "faultgen-log-" not in str(err.value)
