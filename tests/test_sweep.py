"""Sweeps: grid validation, resumability after SIGKILL, Dask on loopback, and broken files."""

import errno
import os
import signal
import subprocess
import sys
import time
import weakref
from pathlib import Path

import h5py
import numpy as np
import pytest
from test_reliability import wait_for
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.data import dataset
from faultgen.model import robots
from faultgen.runs import sweep, worker
from faultgen.runs.context import ExecutionContext
from faultgen.simulation import backends
from faultgen.simulation.resolve import Run

runner = CliRunner()

# Small but real: 2 tasks x (no wear + 2 worn axes) = 6 runs of 3 recorded cycles.
SMALL = dict(robots=["irb6700"], tasks=["pick_place", "spot_weld"], axes=[0, 2, 5], increases=[20.0],
             schedules=["exp4"], cycles=30, record=[1, 15, 30])
SMALL_ARGS = ["--robot", "irb6700", "--task", "pick_place", "--task", "spot_weld", "--axis", "0", "--axis", "2",
              "--axis", "5", "--wear-pct", "20", "--cycles", "30", "--record", "1,15,30"]

# the shared sweep "s" of tests/test_plot.py, test_cluster.py and this file (built once a session):
# 2 tasks x (no wear, axis 2 worn by 20 %), 20 cycles of which 3 recorded, 4 runs; and the command's
# options that make the same grid
GRID = dict(robots=["irb6700"], tasks=["pick_place", "spot_weld"], axes=[0, 2], increases=[20.0], cycles=20,
            record=[1, 10, 20])
GRID_ARGS = ["--robot", "irb6700", "--task", "pick_place", "--task", "spot_weld", "--axis", "0",
             "--axis", "2", "--wear-pct", "20", "--cycles", "20", "--record", "1,10,20"]


def assert_same_datasets(a: Path, b: Path) -> None:
    assert dataset.list_runs(a) == dataset.list_runs(b)
    for run_id in dataset.list_runs(a):
        arrays_a, labels_a = dataset.read_run(a, run_id)
        arrays_b, labels_b = dataset.read_run(b, run_id)
        assert labels_a["config"] == labels_b["config"]
        for name in dataset.ARRAYS:
            np.testing.assert_array_equal(arrays_a[name], arrays_b[name], err_msg=f"{run_id} {name}")


@pytest.fixture(scope="module")
def reference(shared_sweep) -> Path:
    """The small sweep, uninterrupted, on one local job."""
    return shared_sweep("sweep-reference", **SMALL)


def test_small_sweep_is_valid_and_labelled(reference):
    assert dataset.validate(reference) == []
    runs = dataset.labels(reference)
    assert len(runs) == 6  # no-wear runs are not repeated per wear level or schedule
    worn = sorted(tuple(int(a) for a in r["worn_axes"]) for r in runs)
    assert worn == [(), (), (2,), (2,), (5,), (5,)]
    arrays, labels = dataset.read_run(reference, "irb6700-spot_weld-axis5-exp420-seed0")
    np.testing.assert_allclose(arrays["friction_multiplier"][:, 4], np.exp(np.log(1.2) * (np.array([1, 15, 30]) / 30) ** 4))
    assert labels["model_sha256"] == dataset.model_hash(robots.load("irb6700").path)
    assert labels["task"] == "spot_weld" and labels["friction_model"] == "lugre"
    assert not sweep.parts_folder(reference).exists()  # parts are removed once merged


def test_parallel_jobs_give_the_same_dataset(reference, tmp_path):
    out = sweep.run(sweep.Grid(**SMALL), tmp_path / "two_jobs.h5", ExecutionContext(jobs=2), progress=False)
    assert_same_datasets(reference, out)


# A sweep on a Dask cluster on loopback equal to the same sweep on one local job: tests/test_cluster.py's
# `sweep_and_fleet_equal_the_local_ones` (the command on a `dask scheduler` and two `dask worker` processes
# on 127.0.0.1) and `a_worker_killed_mid_run_loses_only_that_run_to_another_worker` (the library's
# ExecutionContext(scheduler=...)), on tests/test_plot.py's 4-run sweep. A LocalCluster started here for the
# same check is gone.


def test_sigkill_then_same_command_finishes_without_redoing_finished_runs(reference, tmp_path, caplog):
    out = tmp_path / "killed.h5"
    command = [sys.executable, "-m", "faultgen.cli", "sweep", *SMALL_ARGS, "--jobs", "1", "--no-progress",
               "-o", str(out)]
    parts = sweep.parts_folder(out)
    proc = subprocess.Popen(command, cwd=tmp_path, start_new_session=True, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(list(parts.glob("*.h5"))) < 2:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)  # the CLI and any worker it started
    proc.wait()
    assert not out.exists()  # nothing that looks finished
    finished = sorted(p.name for p in parts.glob("*.h5"))
    assert 2 <= len(finished) < 6
    for name in finished:  # every part that exists is complete and valid
        assert dataset.validate(parts / name) == []

    again = runner.invoke(app, command[3:])  # the same command, in this process (the kill was of the first)
    assert again.exit_code == 0, again.output
    assert f"resuming: {len(finished)} of 6 runs already finished" in again.stdout
    # its stale lock, taken over with a warning (a `faultgen` process prints it on stderr, as it prints
    # the killed merge's below: Python's last-resort logging handler, the CLI sets none)
    (took,) = [r for r in caplog.records if r.name == "faultgen.runs.sweep" and "took over" in r.getMessage()]
    assert took.levelname == "WARNING" and "from a sweep that was killed" in took.getMessage()
    assert dataset.validate(out) == []
    assert_same_datasets(reference, out)  # loses nothing: equal to the uninterrupted sweep


def _sweep_command(out: Path, jobs: int = 1) -> list[str]:
    return [sys.executable, "-m", "faultgen.cli", "sweep", *SMALL_ARGS, "--jobs", str(jobs), "--no-progress",
            "-o", str(out)]


def test_a_killed_merge_leaves_debris_that_the_next_sweep_removes_and_reports(tmp_path):
    out = tmp_path / "merged.h5"
    killed_merge = (f"import os, signal\nfrom faultgen.data.atomic import atomic_path\n"
                    f"with atomic_path({str(out)!r}) as tmp:\n    tmp.write_bytes(bytes(10**6))\n"
                    f"    os.kill(os.getpid(), signal.SIGKILL)")
    subprocess.run([sys.executable, "-c", killed_merge], check=False)
    (debris,) = tmp_path.glob(".merged.h5.*.part")
    one_run = [sys.executable, "-m", "faultgen.cli", "sweep", "--axis", "0", "--cycles", "2", "--record", "1",
               "--no-progress", "-o", str(out)]
    again = subprocess.run(one_run, cwd=tmp_path, capture_output=True, text=True, timeout=300, check=False)
    assert again.returncode == 0, again.stdout + again.stderr
    assert not debris.exists()
    assert f"removed {debris} (1.0 MB), an unfinished write of merged.h5 left by a killed process" in again.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["merged.h5"]  # no lock file left beside it
    assert dataset.validate(out) == []


def _as_a_terminal_starts_it() -> None:
    """A shell starts a foreground command with SIGINT at its default action and unblocked. The
    test process may have inherited it ignored (an xdist worker once had: the sweep then ran to the
    end and exited 0), and an ignored signal stays ignored across exec, as ``nohup`` relies on."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def test_ctrl_c_stops_the_workers_and_says_what_is_kept_and_how_to_resume(tmp_path):
    out = tmp_path / "interrupted.h5"
    parts = sweep.parts_folder(out)
    proc = subprocess.Popen(_sweep_command(out, jobs=2), cwd=tmp_path, start_new_session=True,
                            preexec_fn=_as_a_terminal_starts_it,  # noqa: PLW1509 (no threads of ours here)
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wait_for(lambda: len(list(parts.glob("*.h5"))) >= 1, "a finished run", 120)
    os.killpg(proc.pid, signal.SIGINT)  # what Ctrl-C in a terminal does: every process of the group
    stdout, stderr = proc.communicate(timeout=60)
    kept = len(list(parts.glob("*.h5")))
    assert proc.returncode == 130, stdout + stderr
    assert stderr.strip() == f"interrupted: {kept} of 6 runs kept in {parts}; run the same command to resume"
    assert not out.exists() and not (parts / "sweep.json").exists()


@pytest.fixture
def ctrl_c_raises():
    """SIGINT at Python's default (KeyboardInterrupt), as in a terminal; an xdist worker may ignore it."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def test_a_ctrl_c_landing_in_a_weakref_callback_is_not_printed_but_stops_the_sweep(ctrl_c_raises, capfd):
    """The race behind a CI failure: the SIGINT of Ctrl-C reached the main process while it ran a
    weakref callback, and Python printed "Exception ignored ... KeyboardInterrupt" before the
    sweep's message. A callback raising KeyboardInterrupt is what that SIGINT becomes there."""

    class Part:
        pass

    def callback(_) -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt), sweep.CtrlC():
        part = Part()
        ref = weakref.ref(part, callback)
        del part  # the callback runs here and its KeyboardInterrupt cannot propagate
        time.sleep(10)  # the interrupt sent again 0.1 s later ends this
        pytest.fail("the interrupt swallowed in the weakref callback did not reach the main flow")
    assert ref() is None
    assert capfd.readouterr().err == ""


@pytest.mark.parametrize("in_a_worker", [True, False])
def test_a_worker_does_not_print_an_interrupt_it_cannot_raise(monkeypatch, in_a_worker):
    """The same race in a worker process (it gets the Ctrl-C too): there the interrupt is dropped,
    as the sweep's process stops the workers; other unraisable exceptions still reach the hook."""
    reached = []
    monkeypatch.setattr(sys, "unraisablehook", reached.append)  # stands for Python's printing hook
    monkeypatch.setattr(worker, "simulate_and_write", lambda *call: call)
    sweep_pid = os.getpid() + 1 if in_a_worker else os.getpid()
    assert worker.in_worker(sweep_pid, "run", "config") == ("run", "config")
    hook = sys.unraisablehook
    worker.in_worker(sweep_pid, "next run", "config")
    assert sys.unraisablehook == hook  # a worker's next run does not wrap the hook again

    class Part:
        pass

    for error in (KeyboardInterrupt(), ValueError("kept")):
        def callback(_, error=error) -> None:
            raise error

        part = Part()
        ref = weakref.ref(part, callback)
        del part
        assert ref() is None
    expected = [ValueError] if in_a_worker else [KeyboardInterrupt, ValueError]
    assert [type(u.exc_value) for u in reached] == expected


def test_once_the_sweep_stops_a_second_ctrl_c_is_not_raised_in_its_clean_up(ctrl_c_raises):
    try:
        with sweep.CtrlC() as ctrl_c:
            with pytest.raises(KeyboardInterrupt):
                signal.raise_signal(signal.SIGINT)
            try:
                signal.raise_signal(signal.SIGINT)
            except KeyboardInterrupt:
                signal.raise_signal(signal.SIGINT)  # while the first is handled: not raised
                ctrl_c.stopping = True
            signal.raise_signal(signal.SIGINT)  # once stopping: not raised
    except KeyboardInterrupt:
        pytest.fail("a second SIGINT was raised while the sweep was stopping")
    with pytest.raises(KeyboardInterrupt):  # outside the sweep SIGINT raises again
        signal.raise_signal(signal.SIGINT)


def test_a_second_sweep_on_the_same_output_refuses_at_once_naming_the_first(shared_sweep, tmp_path):
    out = tmp_path / "same.h5"
    command = [sys.executable, "-m", "faultgen.cli", "sweep", *GRID_ARGS, "--jobs", "1", "--no-progress",
               "-o", str(out)]
    first = subprocess.Popen(command, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                             text=True)
    wait_for(lambda: (sweep.parts_folder(out) / "sweep.json").exists(), "the first sweep to start", 120)
    second = runner.invoke(app, ["sweep", *GRID_ARGS, "--no-progress", "-o", str(out)])
    assert second.exit_code == 2, second.output
    assert f"error: another sweep is writing {out}: pid {first.pid} on " in second.output
    assert ", started 20" in second.output and "wait for it to finish or stop it" in second.output
    assert "runs ->" not in second.output  # refused before it planned or simulated anything
    output, _ = first.communicate(timeout=300)
    assert first.returncode == 0, output
    assert_same_datasets(shared_sweep("s", **GRID), out)  # the first, undisturbed: the same sweep on one job


def test_resume_simulates_only_the_missing_runs(tmp_path):
    grid = sweep.Grid(**SMALL)
    out = tmp_path / "partial.h5"
    parts = sweep.parts_folder(out)
    parts.mkdir()
    plan = dict(grid.runs())
    first = list(plan)[:3]
    for run_id in first:
        sweep.simulate_and_write(run_id, Run(plan[run_id], backends.DEFAULT_STEPPER), parts / f"{run_id}.h5")
    stamps = {run_id: (parts / f"{run_id}.h5").stat().st_mtime_ns for run_id in first}
    (parts / ".stale.h5.abc.part").write_text("left by a killed writer")
    simulated = []
    sweep.run(grid, out, progress=False,
              on_run=lambda stats: (simulated.append(stats.run_id),
                                    # finished parts are untouched while the others run
                                    [pytest.fail(f"{r} rewritten") for r in first
                                     if (parts / f"{r}.h5").stat().st_mtime_ns != stamps[r]]))
    assert sorted(simulated) == sorted(set(plan) - set(first))
    assert dataset.validate(out) == []


def test_a_part_of_another_configuration_is_redone(tmp_path):
    grid = sweep.Grid(**SMALL)
    out = tmp_path / "changed.h5"
    parts = sweep.parts_folder(out)
    parts.mkdir()
    run_id, _ = grid.runs()[0]
    other = sweep.Grid(**{**SMALL, "record": [1, 30]}).runs()[0][1]
    sweep.simulate_and_write(run_id, Run(other, backends.DEFAULT_STEPPER), parts / f"{run_id}.h5")
    assert run_id not in sweep.finished_runs(grid, out)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--axis", "7"], "worn axis 7 is out of range 0..6"),
        (["--task", "welding"], "unknown task 'welding'"),
        (["--wear-pct", "-5", "--axis", "1"], "--wear-pct '-5': expected 0..500"),
        (["--schedule", "cubic", "--axis", "1"], "unknown wear schedule 'cubic'"),
        (["--record", "0,5"], "recorded cycle 0 is out of range"),
        (["--preset", "huge"], "unknown preset 'huge'"),
        (["--preset", "quick", "--jobs", "0"], "--jobs '0': expected 1..1024"),  # typer's range, as one line
    ],
)
def test_invalid_grid_is_refused_before_any_simulation(tmp_path, args, message):
    out = tmp_path / "bad.h5"
    result = runner.invoke(app, ["sweep", *args, "--no-progress", "-o", str(out)])
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert list(tmp_path.iterdir()) == []


def test_grid_file_is_read_and_checked(tmp_path):
    good = tmp_path / "grid.toml"
    good.write_text('preset = "quick"\ntasks = ["arc_weld"]\naxes = [0, 4]\n')
    grid = sweep.Grid.from_toml(good)
    assert [run_id for run_id, _ in grid.runs()] == ["irb6700-arc_weld-nowear-seed0", "irb6700-arc_weld-axis4-exp420-seed0"]
    bad = tmp_path / "bad.toml"
    bad.write_text('robots = ["irb6700"]\ntasks = ["pick_place"]\naxes = [0]\nwear = 3\n')
    with pytest.raises(ValueError, match="unknown key 'wear'"):
        sweep.Grid.from_toml(bad)


def test_unwritable_output_folder_is_a_clear_error(tmp_path, monkeypatch):
    def refuse(self, *args, **kwargs):
        raise PermissionError(errno.EACCES, "Permission denied", str(self))

    monkeypatch.setattr(Path, "mkdir", refuse)
    with pytest.raises(sweep.SweepError, match=r"cannot write to .*: Permission denied; choose another output path"):
        sweep.run(sweep.Grid(**SMALL), tmp_path / "x.h5", progress=False)


def test_missing_output_folder_is_a_clear_error(tmp_path):
    with pytest.raises(sweep.SweepError, match="does not exist"):
        sweep.run(sweep.Grid(**SMALL), tmp_path / "nowhere" / "x.h5", progress=False)


def test_full_disk_keeps_earlier_runs_and_the_same_command_then_finishes(reference, tmp_path, monkeypatch):
    """The third run's write fails with ENOSPC (simulated: h5py raises as it would on a full disk)."""
    grid = sweep.Grid(**SMALL)
    out = tmp_path / "full.h5"
    real_write = dataset.write_run
    calls = []

    def write_until_full(path, *args, **kwargs):
        calls.append(path)
        if len(calls) == 3:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_write(path, *args, **kwargs)

    monkeypatch.setattr(dataset, "write_run", write_until_full)
    with pytest.raises(sweep.SweepError, match="No space left on device.*Finished runs are kept"):
        sweep.run(grid, out, progress=False)
    parts = sweep.parts_folder(out)
    kept = sorted(parts.glob("*.h5"))
    assert len(kept) == 2 and all(dataset.validate(p) == [] for p in kept)
    assert not list(parts.glob(".*.part")) and not out.exists()
    monkeypatch.setattr(dataset, "write_run", real_write)
    sweep.run(grid, out, progress=False)
    assert_same_datasets(reference, out)


def test_corrupted_truncated_and_unfinished_files_are_reported(reference, tmp_path):
    truncated = tmp_path / "truncated.h5"
    truncated.write_bytes(reference.read_bytes()[: reference.stat().st_size // 2])
    assert "truncated" in dataset.validate(truncated)[0]

    corrupted = tmp_path / "corrupted.h5"
    corrupted.write_bytes(reference.read_bytes())
    with h5py.File(corrupted, "r") as f:
        run_id = next(iter(f["runs"]))
        offset = f["runs"][run_id]["angle_hist"].id.get_chunk_info(0).byte_offset  # a gzip-compressed chunk
    with open(corrupted, "r+b") as f:
        f.seek(offset + 8)
        f.write(b"\xff" * 64)
    problems = dataset.validate(corrupted)
    assert problems and "corrupted" in " ".join(problems), problems

    unfinished = tmp_path / "unfinished.h5"
    unfinished.write_bytes(reference.read_bytes())
    with h5py.File(unfinished, "r+") as f:
        f.attrs["complete"] = False
    assert "incomplete" in dataset.validate(unfinished)[0]
    with pytest.raises(dataset.DatasetError, match="incomplete"):
        dataset.read_run(unfinished, run_id)

    result = runner.invoke(app, ["validate", str(truncated)])
    assert result.exit_code == 1 and "truncated" in result.output


def test_a_grid_files_seed_is_bounded(tmp_path):
    # issue 50: a grid file's seeds reached the runs unbounded (the CLI bounds --seed only)
    path = tmp_path / "grid.toml"
    path.write_text('preset = "quick"\nseeds = [0, 4294967296]\n')
    with pytest.raises(ValueError, match=r"grid seeds \(--seed\): 4294967296: expected a whole number in 0 \.\. 4294967295"):
        sweep.Grid.from_toml(path)
