"""Sweeps and fleets on a real Dask cluster that shares no folder with the client.

A ``dask scheduler`` and two ``dask worker`` processes run on 127.0.0.1, each started in its own
temporary folder (its working directory and local directory). The client runs in another one
and names OUT relative to it (``out/s.h5``): a worker given that path would look for
``<its folder>/out/``, which does not exist (the failure of issue 41), and no task carries a
path, so the workers cannot reach OUT's folder. Every wait is on an event (a file appearing,
the scheduler's or a worker's state), never a sleep of a guessed length.
"""

import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
from test_monitor_cluster import (
    a_monitor_without_a_shared_folder_gives_one_local_jobs_outputs as monitor_case,
    local_monitor_run,
)
from test_sweep import GRID, GRID_ARGS, assert_same_datasets
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.data import dataset
from faultgen.runs import sweep
from faultgen.runs.context import ExecutionContext

REPO = Path(__file__).resolve().parents[1]
FLEET = dict(size=2, failing=1, days=6, cycles_per_day=1)
FLEET_ARGS = ["--robots", "2", "--failing", "1", "--days", "6", "--cycles-per-day", "1"]


def wait_for(condition, what: str, seconds: float = 120):
    """Poll ``condition`` (an event: a file, a process's or the cluster's state) until it holds."""
    deadline = time.monotonic() + seconds
    while not (value := condition()):
        if time.monotonic() > deadline:
            pytest.fail(f"waited {seconds} s for {what}")
        time.sleep(0.05)
    return value


class Cluster:
    """A scheduler and its workers, each a process in its own folder under ``root``."""

    def __init__(self, root: Path):
        self.root = root
        self.env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]),
                    "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
        self.processes: dict[str, subprocess.Popen] = {}
        folder = self._start("scheduler", "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                             "--scheduler-file", "scheduler.json")
        self.address = wait_for(lambda: self._address(folder / "scheduler.json"), "the scheduler's address")
        from distributed import Client

        self.client = Client(self.address, timeout="30s", set_as_default=False)

    def _start(self, name: str, *command: str) -> Path:
        folder = self.root / name
        folder.mkdir()
        with open(folder / "log.txt", "w") as log:
            self.processes[name] = subprocess.Popen([sys.executable, "-m", "dask", *command], cwd=folder, env=self.env,
                                                    stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        return folder

    @staticmethod
    def _address(file: Path) -> str | None:
        try:
            return json.loads(file.read_text())["address"]
        except (OSError, ValueError, KeyError):  # not there yet, or being written
            return None

    def start_worker(self, name: str) -> str:
        """Start a worker (one thread, no nanny: a killed worker stays dead); return its address."""
        self._start(name, "worker", self.address, "--name", name, "--nthreads", "1", "--no-nanny", "--no-dashboard",
                    "--memory-limit", "0", "--local-directory", ".")
        return wait_for(lambda: self.workers().get(name), f"worker {name} to join")

    def workers(self) -> dict[str, str]:
        """name -> address of the workers the scheduler has now."""
        info = self.client.scheduler_info()["workers"]
        return {worker["name"]: address for address, worker in info.items()}

    def kill(self, name: str) -> None:
        process = self.processes.pop(name)
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()

    def close(self) -> None:
        self.client.close()
        for name in list(self.processes):
            self.kill(name)


@pytest.fixture
def reference(shared_sweep) -> Path:
    """:data:`GRID`'s sweep on one local job (tests/test_plot.py's, built once per session)."""
    return shared_sweep("s", **GRID)


def test_sweeps_and_fleets_on_a_cluster_that_shares_no_folder_with_the_client(reference, shared_fleet, tmp_path,
                                                                                monkeypatch, subtests):
    """One test on one cluster (pytest-xdist would start a cluster in each of its workers that
    got one of several tests), each case a subtest: a sweep and a fleet equal the local ones, a
    shared folder, a worker killed mid-run, the client killed mid-run, and the monitor's outputs on
    the cluster equal one local job's (tests/test_monitor_cluster.py's case, in a folder of its own)."""
    client_folder = tmp_path / "client"  # the client's working directory, OUT in out/; no worker gets its path
    (client_folder / "out").mkdir(parents=True)
    (tmp_path / "cluster").mkdir()
    # the local one-job references, made before the cluster starts (its processes idle meanwhile): the
    # small fleet, built once a session (tests/test_fleet.py compares with it too), and the monitor case's run
    local_fleet = shared_fleet("fleet-small", **FLEET)
    monitored = local_monitor_run(tmp_path / "monitor")
    monkeypatch.chdir(client_folder)
    cluster = Cluster(tmp_path / "cluster")
    try:
        for name in ("w1", "w2"):
            cluster.start_worker(name)
        for case in (sweep_and_fleet_equal_the_local_ones, with_a_shared_folder_the_workers_write_the_parts,
                     a_worker_killed_mid_run_loses_only_that_run_to_another_worker,
                     a_killed_client_resumes_to_the_same_dataset,
                     a_relative_robot_folder_and_program_run_on_the_workers):
            with subtests.test(case.__name__.replace("_", " ")):
                local = {"local_fleet": local_fleet} if case is sweep_and_fleet_equal_the_local_ones else {}
                case(cluster, reference, client_folder, **local)
        # on w1 and w2 (the victim worker is gone)
        with subtests.test(monitor_case.__name__.replace("_", " ")):
            try:
                monitor_case(cluster, monitored, monkeypatch)
            finally:
                monkeypatch.chdir(client_folder)
    finally:
        cluster.close()


def a_relative_robot_folder_and_program_run_on_the_workers(cluster, reference, client_folder):
    """`--robot kr6 --task mine.toml`, paths relative to the client's folder (issue 51: the workers,
    each in a folder of its own, failed with "unknown robot 'kr6'"): the client sends its absolute
    paths, the runs are labelled with the paths as given; a path a worker lacks is named with the
    worker, and a sweep none of whose runs finished does not speak of runs kept."""
    import shutil

    from faultgen.runs import cluster as cluster_runs

    shutil.copytree(REPO / "robots/puma560", client_folder / "kr6")
    runner = CliRunner()
    assert runner.invoke(app, ["tasks", "export", "kr6", "spot_weld", "-o", "mine.toml"]).exit_code == 0
    out = client_folder / "out/kr6.h5"
    result = runner.invoke(app, ["sweep", "--robot", "kr6", "--task", "mine.toml", "--axis", "0", "--axis", "2",
                                 "--cycles", "2", "--scheduler", cluster.address, "--no-progress", "-o", "out/kr6.h5"])
    assert result.exit_code == 0, result.output
    assert dataset.validate(out) == []
    with h5py.File(out) as f:
        assert len(f["runs"]) == 2
        for run in f["runs"].values():
            config = json.loads(run.attrs["config"])
            assert config["robot"] == "kr6" and config["task"] == "mine.toml"
    config = sweep.Grid(robots=["kr6"], tasks=["mine.toml"], axes=[0], cycles=1).runs()[0][1]
    sent = cluster_runs.for_workers(config)
    assert sent.robot == str(client_folder / "kr6") and sent.task == str(client_folder / "mine.toml")
    assert cluster_runs.for_workers(sweep.Grid(robots=["puma560"], tasks=["pick_place"], axes=[0],
                                               cycles=1).runs()[0][1]).robot == "puma560"
    lost = cluster_runs.failure_message(["r1: worker tcp://w has no /x/kr6"], 1, client_folder / "out/p.parts")
    assert "none of the 1 runs finished" in lost and "kept" not in lost
    assert "the 1 that finished are kept in" in cluster_runs.failure_message(["r1: x"], 2, Path("p.parts"))


def assert_same_files(a: Path, b: Path) -> None:
    """Every array of every run of ``a`` equals ``b``'s bit for bit (features and conditions too)."""
    with h5py.File(a) as fa, h5py.File(b) as fb:
        assert list(fa["runs"]) == list(fb["runs"])
        for run_id in fa["runs"]:
            names = []
            fa["runs"][run_id].visit(names.append)
            assert names and names == list(_names(fb["runs"][run_id]))
            for name in names:
                x, y = fa["runs"][run_id][name][()], fb["runs"][run_id][name][()]
                assert x.dtype == y.dtype and np.array_equal(x, y), f"{run_id}/{name}"
            assert fa["runs"][run_id].attrs["config"] == fb["runs"][run_id].attrs["config"]


def _names(group):
    names = []
    group.visit(names.append)
    return names


def where_runs_went(output: str) -> dict[str, str]:
    """run id -> worker address, from the lines the command prints as runs are kept."""
    return dict(re.findall(r"^(\S+): (tcp://[^,]+), ", output, flags=re.MULTILINE))


def sweep_and_fleet_equal_the_local_ones(cluster, reference, client_folder, local_fleet):
    runner = CliRunner()
    result = runner.invoke(app, ["sweep", *GRID_ARGS, "--scheduler", cluster.address, "--no-progress",
                                 "-o", "out/s.h5"])
    assert result.exit_code == 0, result.output
    assert cluster.address.startswith("tcp://127.0.0.1:")  # on loopback
    assert f"4 runs -> out/s.h5 on {cluster.address}" in result.output
    went = where_runs_went(result.output)
    assert sorted(went) == dataset.list_runs(reference)
    assert set(went.values()) <= set(cluster.workers().values())
    assert dataset.validate("out/s.h5") == []
    assert_same_datasets(reference, Path("out/s.h5"))

    result = runner.invoke(app, ["fleet", *FLEET_ARGS, "--scheduler", cluster.address, "--no-progress",
                                 "-o", "out/f.h5"])
    assert result.exit_code == 0, result.output
    assert len(where_runs_went(result.output)) == 2
    assert dataset.validate("out/f.h5") == []
    assert_same_files(local_fleet, Path("out/f.h5"))
    for name in ("w1", "w2"):  # the workers wrote nothing where OUT would be, seen from their folders
        assert not (cluster.root / name / "out").exists()


def with_a_shared_folder_the_workers_write_the_parts(cluster, reference, client_folder):
    result = CliRunner().invoke(app, ["sweep", *GRID_ARGS[:4], "--axis", "0", "--axis", "2", *GRID_ARGS[-4:],
                                      "--scheduler", cluster.address, "--shared-folder", "--no-progress",
                                      "-o", "out/shared.h5"])
    assert result.exit_code == 0, result.output
    runs = dataset.list_runs("out/shared.h5")
    assert len(runs) == 2 and set(runs) < set(dataset.list_runs(reference))
    with h5py.File(reference) as f, h5py.File("out/shared.h5") as g:
        for run_id in runs:
            for name in dataset.ARRAYS:
                assert np.array_equal(f["runs"][run_id][name][()], g["runs"][run_id][name][()]), name


def a_worker_killed_mid_run_loses_only_that_run_to_another_worker(cluster, reference, client_folder):
    victim = cluster.start_worker("victim")
    kept, failure = [], []

    def client() -> None:
        try:
            sweep.run(sweep.Grid(**GRID), "out/k.h5", ExecutionContext(scheduler=cluster.address),
                      progress=False, on_run=kept.append)
        except Exception as err:  # reported below
            failure.append(err)

    thread = threading.Thread(target=client)
    thread.start()
    running = wait_for(lambda: cluster.client.run(
        lambda dask_worker: [str(ts.key) for ts in dask_worker.state.executing], workers=[victim])[victim],
        "the victim worker to run a run")
    cluster.kill("victim")
    thread.join(timeout=300)
    assert not thread.is_alive() and not failure, failure
    went = {stats.run_id: stats.worker for stats in kept}
    (lost,) = [run_id for run_id in went if running[0].startswith(f"faultgen-{run_id}-")]
    assert went[lost] != victim and went[lost] in cluster.workers().values()  # done again elsewhere
    assert victim not in cluster.workers().values()
    assert dataset.validate("out/k.h5") == []
    assert_same_datasets(reference, Path("out/k.h5"))


def a_killed_client_resumes_to_the_same_dataset(cluster, reference, client_folder):
    command = [sys.executable, "-m", "faultgen.cli", "sweep", *GRID_ARGS, "--scheduler", cluster.address,
               "--no-progress", "-o", "out/c.h5"]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.Popen(command, cwd=client_folder, env=env, start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    parts = sweep.parts_folder(Path("out/c.h5"))
    wait_for(lambda: any(parts.glob("*.h5")) or proc.poll() is not None, "the client to keep a run")
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    assert not Path("out/c.h5").exists()  # nothing that looks finished
    kept = sorted(parts.glob("*.h5"))
    assert 1 <= len(kept) < 4
    assert all(dataset.validate(part) == [] for part in kept)

    result = CliRunner().invoke(app, ["sweep", *GRID_ARGS, "--scheduler", cluster.address, "--no-progress",
                                      "-o", "out/c.h5"])
    assert result.exit_code == 0, result.output
    assert f"resuming: {len(kept)} of 4 runs already finished" in result.output
    assert len(where_runs_went(result.output)) == 4 - len(kept)  # the kept runs are not simulated again
    assert dataset.validate("out/c.h5") == []
    assert_same_datasets(reference, Path("out/c.h5"))


def test_a_shared_folder_needs_a_scheduler(tmp_path):
    result = CliRunner().invoke(app, ["fleet", *FLEET_ARGS, "--shared-folder", "-o", str(tmp_path / "f.h5")])
    assert result.exit_code == 2
    assert "--shared-folder is for the workers of a Dask cluster: add --scheduler ADDRESS" in result.output
