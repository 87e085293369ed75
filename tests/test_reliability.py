"""Reliability (issue 42): what a kill, a full or read-only disk and bad input leave behind.

Tests that wait on another process synchronise on what it does (a file appearing, a process
ending), polling with a generous deadline, never on a fixed sleep: they pass on a loaded machine.
"""

import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import psutil
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.data import dataset
from faultgen.runs import sweep

runner = CliRunner()
CLI = [sys.executable, "-m", "faultgen.cli"]
# 4 runs of 40 cycles (each keeps a worker busy for over 10 s): a sweep killed once its two workers
# have started has runs under way. Its workers end at once and write nothing more (before issue 42
# they finished their runs): the tests check the runs kept once every process has ended, not a clock
GRID_ARGS = ["--robot", "irb6700", "--task", "pick_place", "--task", "spot_weld", "--axis", "0", "--axis", "2",
             "--cycles", "40", "--no-progress"]


def wait_for(condition, what: str, seconds: float = 180) -> None:
    """Poll ``condition`` until it holds; fail naming ``what`` after ``seconds`` (a deadline, not a delay)."""
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > deadline:
            pytest.fail(f"waited {seconds} s for {what}")
        time.sleep(0.05)


def marked(mark: str) -> list[psutil.Process]:
    """Every running process whose environment carries ``FAULTGEN_TEST_MARK=mark``: a process the
    test started and all its descendants, whoever their parent is now (an orphan's is init)."""
    found = []
    for p in psutil.process_iter():
        try:
            if p.environ().get("FAULTGEN_TEST_MARK") == mark and p.status() != psutil.STATUS_ZOMBIE:
                found.append(p)
        except (psutil.NoSuchProcess, psutil.AccessDenied, psutil.ZombieProcess):
            pass
    return found


def workers(mark: str) -> list[psutil.Process]:
    out = []
    for p in marked(mark):
        try:
            if "popen_loky_posix" in " ".join(p.cmdline()):
                out.append(p)
        except (psutil.NoSuchProcess, psutil.ZombieProcess):
            pass
    return out


# -- group 1: a killed sweep stops its workers; SIGTERM is handled like Ctrl-C ---------------------

@pytest.mark.parametrize("how", [signal.SIGKILL, signal.SIGTERM], ids=["SIGKILL", "SIGTERM"])
def test_a_killed_sweep_leaves_no_worker_running(tmp_path, how):
    out = tmp_path / "killed.h5"
    parts = sweep.parts_folder(out)
    mark = str(tmp_path)
    proc = subprocess.Popen([*CLI, "sweep", *GRID_ARGS, "--jobs", "2", "-o", str(out)], cwd=tmp_path,
                            env={**os.environ, "FAULTGEN_TEST_MARK": mark}, start_new_session=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        wait_for(lambda: (parts / "sweep.json").exists() and len(workers(mark)) >= 2, "two workers")
        proc.send_signal(how)  # the sweep's own process only, as `kill PID` does
        stdout, stderr = proc.communicate(timeout=120)
        # its workers stopped (SIGTERM: before the sweep ends) or were sent SIGKILL as it ended
        # (PR_SET_PDEATHSIG): what is kept now is all there will be
        at_the_end = sorted(parts.glob("*.h5"))
        # every process the sweep started (workers, resource trackers) ends: none is left orphaned
        wait_for(lambda: not marked(mark), "every process of the sweep to end")
    finally:
        for p in marked(mark):
            p.kill()
    assert sorted(parts.glob("*.h5")) == at_the_end  # no worker went on to finish its run
    assert not out.exists()
    if how == signal.SIGTERM:
        kept = len(list(parts.glob("*.h5")))
        assert proc.returncode == 143, stdout + stderr
        assert stderr.strip() == (f"terminated (SIGTERM): {kept} of 4 runs kept in {parts}; run the same command "
                                  "to resume" if kept else
                                  "terminated (SIGTERM): none of the 4 runs had finished; run the same command to "
                                  "start again")
        assert kept or not parts.exists()  # no empty part folder
        assert not (tmp_path / ".killed.h5.lock").exists()


# -- group 2: a full disk (a file-size limit: EFBIG, as ENOSPC for the writer) ---------------------

def limited(size: int):
    """``preexec_fn`` of a child whose files may not grow past ``size`` bytes (RLIMIT_FSIZE; Python
    ignores SIGXFSZ, so a write past it fails with EFBIG as one on a full disk fails with ENOSPC)."""
    return lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (size, size))


def run_limited(args: list[str], size: int, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([*CLI, *args], cwd=cwd, capture_output=True, text=True, timeout=300,
                          preexec_fn=limited(size))  # noqa: PLW1509 (the test starts no threads)


def assert_clean_error(run: subprocess.CompletedProcess, folder: Path, *kept: str) -> None:
    """One error line, no traceback, no crash, and nothing left in ``folder`` but ``kept``."""
    assert run.returncode == 1, run.stdout + run.stderr  # not 139 (segfault), not a traceback's 1 with pages
    assert "Traceback" not in run.stderr and "Exception ignored" not in run.stderr, run.stderr
    assert run.stderr.startswith("error: ") and run.stderr.count("\n") == 1, run.stderr
    assert sorted(p.name for p in folder.iterdir()) == sorted(kept)  # no debris, no file that looks complete


@pytest.mark.parametrize("size", [30_000, 300_000])
def test_simulate_on_a_full_disk_says_so_and_leaves_nothing(tmp_path, size):
    """The h5py segfault (rc 139) of a write failing inside an open HDF5 file cannot happen."""
    run = run_limited(["simulate", "--cycles", "2", "--record", "2", "--no-progress", "-o", "run.h5"], size, tmp_path)
    assert_clean_error(run, tmp_path)
    assert "File too large" in run.stderr


def test_a_sweep_on_a_full_disk_says_so_and_leaves_no_empty_part_folder(tmp_path):
    for size in (100, 200_000):  # sweep.json cannot be written; a run's part cannot be written
        run = run_limited(["sweep", "--axis", "0", "--cycles", "1", "--no-progress", "-o", "s.h5"], size, tmp_path)
        assert run.returncode == 1, run.stdout + run.stderr
        assert "Traceback" not in run.stderr and "too large" in run.stderr.lower(), run.stderr
        assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_export_on_a_full_disk_says_so_and_leaves_nothing(small_run, tmp_path):
    run = run_limited(["export", str(small_run), "-o", "t.csv"], 1000, tmp_path)
    assert_clean_error(run, tmp_path)


# -- group 3: a read-only output folder: refused before any work ------------------------------------

@pytest.fixture
def read_only(tmp_path) -> Path:
    """A folder this process cannot create files in: chmod 555, or for root (whom permissions do
    not stop) /sys, which the kernel keeps read-only."""
    if os.geteuid() == 0:
        return Path("/sys")
    folder = tmp_path / "read-only"
    folder.mkdir()
    folder.chmod(0o555)
    return folder


def test_simulate_into_a_read_only_folder_is_refused_before_simulating(read_only):
    result = runner.invoke(app, ["simulate", "--cycles", "50", "-o", str(read_only / "run.h5")])
    assert result.exit_code == 1, result.output
    assert f"cannot write in {read_only}" in result.output and "simulat" not in result.output.lower()


def test_export_plot_into_a_read_only_folder_give_one_line(small_run, read_only):
    for args in (["export", str(small_run), "-o", str(read_only / "t.csv")],
                 ["plot", str(small_run), "-o", str(read_only / "p.png")]):
        result = runner.invoke(app, args)
        assert result.exit_code == 1, result.output
        assert result.output.startswith("error: ") and "Traceback" not in result.output, result.output


# -- groups 4 and 5: calibrate -----------------------------------------------------------------------

@pytest.fixture(scope="module")
def moving_log(tmp_path_factory) -> Path:
    """10 s at 250 Hz of the PUMA 560 along the excitation, its torque from the model, 1 % noise."""
    from faultgen.calibrate import predict, synth
    from faultgen.logs import measured
    from faultgen.data import logfiles
    from faultgen.model import robots

    puma = robots.load("puma560")
    t, q, qd, _ = synth.excitation([puma], 10.0, 0.004)
    tau = predict(puma, measured.from_arrays(t, q, np.zeros_like(q), robot=puma, qd=qd))
    tau += np.random.default_rng(0).normal(size=tau.shape) * 0.01 * np.sqrt(np.mean(tau**2, axis=0))
    path = tmp_path_factory.mktemp("logs") / "moving.csv"
    logfiles.write_csv(path, t, q, tau)
    return path


def test_calibrate_refuses_a_log_without_motion_naming_the_joints_and_writes_nothing(tmp_path):
    from faultgen.data import logfiles
    from faultgen.model import robots

    puma = robots.load("puma560")
    t = np.arange(0, 10, 0.004)
    q = np.tile(puma.joint_range.mean(axis=1), (len(t), 1))
    tau = puma.inverse_dynamics(q, np.zeros_like(q), np.zeros_like(q), t=t)
    logfiles.write_csv(tmp_path / "still.csv", t, q, tau)
    result = runner.invoke(app, ["calibrate", "--robot", "puma560", "--measured", str(tmp_path / "still.csv"),
                                 "--out", str(tmp_path / "out")])
    assert result.exit_code == 2, result.output
    assert "no joint moves: joints 1 (largest |qd| 0 rad/s), 2" in result.output
    assert "ZeroDivisionError" not in result.output and sorted(p.name for p in tmp_path.iterdir()) == ["still.csv"]


def full_pipe() -> tuple[int, int]:
    """A pipe (read end, write end) whose buffer is already full: a child given the write end blocks
    in its first write to it, there and nowhere else, until the test reads the read end. The
    writer is halted at a known point whatever the machine's load."""
    read, write = os.pipe()
    os.set_blocking(write, False)
    for size in (65536, 1):  # then byte by byte: the last page too
        try:
            while True:
                os.write(write, b"\0" * size)
        except BlockingIOError:
            pass
    os.set_blocking(write, True)  # the child's writes wait
    return read, write


def as_a_terminal_starts_it() -> None:
    """``preexec_fn``: SIGINT at its default action, as a shell starts a foreground command. A test
    process started in the background by a non-interactive shell has SIGINT ignored, and an ignored
    signal stays ignored across exec: the child would not stop on it (tests/test_sweep.py)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def test_an_interrupted_calibrate_leaves_nothing_that_blocks_a_rerun(moving_log, tmp_path):
    """Interrupted inside the staging folder, at a known point: calibrate's first write to stderr
    is its progress bar, after the staging folder holds model/tasks.toml (the point at which main
    left OUT/model/tasks.toml); with stderr a full pipe it waits there, so it cannot finish before
    the interrupt, however loaded the machine (on this log the search takes about a second)."""
    import threading

    out = tmp_path / "out"
    read, write = full_pipe()
    proc = subprocess.Popen([*CLI, "calibrate", "--robot", "puma560", "--measured", str(moving_log), "--out", str(out)],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=write, text=True,
                            env={k: v for k, v in os.environ.items() if not k.startswith("TQDM_")},  # the bar shown
                            preexec_fn=as_a_terminal_starts_it)  # noqa: PLW1509 (no threads of ours here)
    os.close(write)
    stderr: list[bytes] = []
    try:
        wait_for(lambda: any(tmp_path.glob(".out.*.part/model/tasks.toml")) or proc.poll() is not None,
                 "calibrate to write model/tasks.toml into its staging folder")
        assert proc.poll() is None, "calibrate ended before it wrote model/tasks.toml"
        proc.send_signal(signal.SIGINT)
        drain = threading.Thread(target=lambda: stderr.extend(iter(lambda: os.read(read, 65536), b"")), daemon=True)
        drain.start()  # what it writes as it stops, then end of file
        stdout, _ = proc.communicate(timeout=120)
        drain.join(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    os.close(read)
    message = b"".join(stderr).lstrip(b"\0").decode(errors="replace")
    assert proc.returncode == 130, stdout + message  # interrupted (SIGINT), not failed
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # OUT absent: a rerun is not refused


def test_a_long_log_is_averaged_down_and_keeps_the_relation_between_its_columns(moving_log):
    from faultgen import calibrate
    from faultgen.logs import measured
    from faultgen.model import robots

    data = measured.read(moving_log, robots.load("puma560"))
    short = calibrate.decimate(data, 1000)
    k = -(-len(data) // 1000)
    assert len(short) == len(data) // k <= 1000
    np.testing.assert_allclose(short.tau[0], data.tau[:k].mean(axis=0))
    np.testing.assert_allclose(short.q[-1], data.q[(len(short) - 1) * k:len(short) * k].mean(axis=0))
    assert "decimated" in short.notes[-1] and calibrate.decimate(data, len(data)) is data
    assert calibrate.MAX_ROWS * 90_000 < 3e9  # about 86 kB a row at the peak (docs/calibration.md)


# -- group 6: corrupt attributes and files are refused with the reason ----------------------------

@pytest.fixture(scope="module")
def small_run(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("runs") / "run.h5"
    result = runner.invoke(app, ["simulate", "--cycles", "2", "--record", "2", "--no-progress", "-o", str(path)])
    assert result.exit_code == 0, result.output
    return path


def broken(small_run: Path, folder: Path, edit) -> Path:
    path = folder / "broken.h5"
    path.write_bytes(small_run.read_bytes())
    with h5py.File(path, "a") as f:
        edit(f)
    return path


@pytest.mark.parametrize("edit, reason", [
    (lambda f: f["runs/run"].attrs.__setitem__("worn_axes", "garbage"), "attribute 'worn_axes' is 'garbage'"),
    (lambda f: f["runs/run"].attrs.__setitem__("config", "{not json"), "attribute 'config' is not JSON"),
    (lambda f: f["runs/run"].attrs.__setitem__("cycles", -3), "attribute 'cycles' is -3"),
    (lambda f: f.attrs.__setitem__("format_version", 99), "format_version 99"),
    (lambda f: f["runs/run/mean_abs_torque"].__setitem__((0, 0), np.nan), "mean_abs_torque"),
])
def test_validate_export_and_plot_refuse_a_corrupt_file_with_the_reason(small_run, tmp_path, edit, reason):
    path = broken(small_run, tmp_path, edit)
    checked = runner.invoke(app, ["validate", str(path)])
    assert checked.exit_code == 1 and reason in checked.output, checked.output
    assert "error: 1" not in checked.output
    for args in (["export", str(path), "-o", str(tmp_path / "t.csv")], ["plot", str(path), "-o", str(tmp_path / "p.png")]):
        result = runner.invoke(app, args)
        assert result.exit_code == 1 and reason in result.output, (args, result.output)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["broken.h5"]


def test_info_on_an_empty_runs_group_and_on_a_file_being_written(small_run, tmp_path):
    def empty(f):
        del f["runs/run"]
        f.attrs["n_runs"] = 0

    result = runner.invoke(app, ["info", str(broken(small_run, tmp_path, empty))])
    assert result.exit_code == 1 and "has no runs" in result.output, result.output
    busy = tmp_path / "busy.h5"
    writer = subprocess.Popen([sys.executable, "-c", f"import h5py, sys\nf = h5py.File({str(busy)!r}, 'w')\n"
                               "print('open', flush=True)\nsys.stdin.read()"],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert writer.stdout.readline().strip() == "open"  # synchronised on the writer's word
        result = runner.invoke(app, ["info", str(busy)])
    finally:
        writer.communicate("", timeout=60)
    assert result.exit_code == 1 and f"{busy} is in use" in result.output, result.output


# -- group 7: every numeric option and grid key checked at the boundary, named ---------------------

@pytest.mark.parametrize("args, named", [
    (["detect", "x.h5", "--period", "0"], "--period"),
    (["detect", "x.h5", "--first", "0"], "--first"),
    (["bench-isolators", "x.h5", "--levels", "abc"], "--levels"),
    (["fleet", "--cycles-per-day", "0"], "--cycles-per-day"),
    (["fleet", "--days", "5"], "--days"),
    (["sweep", "--start-day", "-1e300", "--temperature"], "--start-day"),
    (["sweep", "--jobs", "100000"], "--jobs"),
    (["sweep", "--wear-pct", "1e9", "--axis", "2"], "--wear-pct"),
    (["simulate", "--wear", "2:exp4:1e9"], "beyond the bound of 5 (+500 %"),
    (["simulate", "--cycles", "0"], "--cycles"),
])
def test_an_option_out_of_range_is_refused_naming_it(tmp_path, args, named):
    result = runner.invoke(app, [*args, "-o", str(tmp_path / "out.h5")] if args[0] in ("fleet", "sweep", "simulate")
                           else args)
    assert result.exit_code == 2, result.output
    assert named in result.output, result.output
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("text, named", [
    ('robots = ["irb6700"]\ntasks = ["pick_place"]\naxes = [0]\nsignals = "false"\n', "signals"),
    ("", "'robots'"),
    ('preset = ""\ncycles = 3\n', "'robots'"),
    ('robots = ["irb6700"]\ntasks = ["pick_place"]\naxes = [2]\nincreases = [1e12]\n', "increases"),
    ('robots = ["irb6700"]\ntasks = ["pick_place"]\naxes = [0]\ncycles = 0\n', "cycles"),
])
def test_a_grid_file_key_out_of_range_is_refused_naming_it(tmp_path, text, named):
    config = tmp_path / "grid.toml"
    config.write_text(text)
    result = runner.invoke(app, ["sweep", "--config", str(config), "-o", str(tmp_path / "out.h5")])
    assert result.exit_code == 2, result.output
    assert named in result.output and "Traceback" not in result.output and "TypeError" not in result.output


def test_a_run_whose_motor_saturates_is_labelled_and_flagged_by_validate(tmp_path):
    out = tmp_path / "saturated.h5"
    result = runner.invoke(app, ["simulate", "--fault", "torque_offset:2:offset:1e4", "--cycles", "1", "--no-progress",
                                 "-o", str(out)])
    assert result.exit_code == 0, result.output
    (labels,) = dataset.labels(out)
    assert 2 in list(labels["saturated"])
    checked = runner.invoke(app, ["validate", str(out)])
    # valid (a fleet's hardest moves may touch a limit), but named
    assert checked.exit_code == 0 and "warning: run" in checked.output and "axes 2, 3: the motor saturated" in checked.output
    assert "saturated:     1 run(s)" in runner.invoke(app, ["info", str(out)]).output


# -- group 8: inputs the commands did not expect ----------------------------------------------------

def test_a_model_copied_without_its_tasks_file_is_named(tmp_path):
    from faultgen.model import robots

    model = tmp_path / "copy.xml"
    model.write_text(robots.load("irb6700").path.read_text())
    result = runner.invoke(app, ["simulate", "--model", str(model), "--cycles", "1", "-o", str(tmp_path / "r.h5")])
    assert result.exit_code == 2, result.output
    assert f"{tmp_path / 'tasks.toml'}: no tasks file" in result.output


def test_analyses_refuse_a_dataset_without_worn_runs(small_run, tmp_path):
    for command in ("detect", "classify", "bench-isolators"):
        result = runner.invoke(app, [command, str(small_run), "--no-progress", "-o", str(tmp_path / command)]
                               if command != "bench-isolators" else [command, str(small_run), "-o", str(tmp_path / command)])
        assert result.exit_code == 2, (command, result.output)
        assert "has no worn run" in result.output, (command, result.output)


# -- group 9: --jobs capped at the runs; no lock file left -----------------------------------------

def test_jobs_are_capped_at_the_runs_and_warned_above_the_cores_and_no_lock_is_left(tmp_path):
    out = tmp_path / "one.h5"
    result = runner.invoke(app, ["sweep", "--axis", "0", "--cycles", "1", "--jobs", str((os.cpu_count() or 1) + 1),
                                 "--no-progress", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert f"1 runs -> {out} with 1 job(s) (one per run)" in result.output
    assert "CPU cores" in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["one.h5"]
