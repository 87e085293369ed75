"""``faultgen monitor --scheduler`` on a real Dask cluster that shares no folder with the client
(issue 60, part 6): a ``dask scheduler`` and two ``dask worker`` processes, each in its own
temporary folder (tests/test_cluster.py's :class:`Cluster`). The client names LOGS and OUT
relative to its own working directory, so a worker given either path would look in its own
folder, where neither is: the units' logs and cached twins go to the workers as bytes, and their
results come back. The outputs are those of the local ``--jobs 1`` run, byte for byte.

The cluster case, :func:`a_monitor_without_a_shared_folder_gives_one_local_jobs_outputs`,
runs as a subtest of tests/test_cluster.py's one cluster test, on the cluster its sweeps and fleets
ran on (a scheduler and two workers started once for both files: the suite's time)."""

import os
from pathlib import Path

import independent_fleet
import pytest
from typer.testing import CliRunner

from faultgen.cli import app

# two units, 24 days, one of them worn from day 10-11; parts on some days (cycles the workers simulate);
# with the planted unit98, three units for the two workers
SPEC = independent_fleet.FleetSpec(units=2, worn=1, days=24, seed=5, onset=(10, 11))
# the default twin: each unit's model calibrated on its first log (on the workers, sent back with the cache)
COMMON = ["--train", "10", "--persistence", "3", "--no-progress"]


def _outputs(out: Path) -> dict[str, bytes]:
    """Every file of OUT but its cache, by path: the CSVs, charts, report page, settings and state."""
    return {p.relative_to(out).as_posix(): p.read_bytes() for p in sorted(out.rglob("*"))
            if p.is_file() and ".cache" not in p.relative_to(out).parts}


def _linked(source: Path, target: Path, days: slice) -> None:
    for unit in sorted(source.iterdir()):
        (target / unit.name).mkdir(parents=True, exist_ok=True)
        for log in sorted(unit.iterdir())[days]:
            os.link(log, target / unit.name / log.name)


def local_monitor_run(tmp_path: Path) -> dict:
    """The fleet (two units and the planted unit98) and the local ``--jobs 1`` run on every log, in
    ``tmp_path`` (an empty folder): made before the cluster starts, which then does not wait on it.
    Returns what :func:`a_monitor_without_a_shared_folder_gives_one_local_jobs_outputs` needs."""
    robot, logs, _ = independent_fleet.write_fleet(tmp_path / "fleet", SPEC)
    # a planted unit whose every log the reader refuses, naming the log's path as the client has it
    (logs / "unit98").mkdir()
    for log in sorted((logs / "unit01").iterdir()):
        header, *rows = log.read_text().splitlines()
        rows[5] = ",".join([rows[3].split(",")[0], *rows[5].split(",")[1:]])  # time goes back
        (logs / "unit98" / log.name).write_text("\n".join([header, *rows]) + "\n")
    client, remote = tmp_path / "client", tmp_path / "remote"  # each a working directory with its own logs/
    _linked(logs, client / "logs", slice(None))
    _linked(logs, remote / "logs", slice(0, 16))  # the cluster's: 16 days, then all of them
    robot = str(robot)  # an added robot's folder: the workers see it at the same path (the same machine)
    here = Path.cwd()
    os.chdir(client)
    try:
        local = CliRunner().invoke(app, ["monitor", "logs", "--robot", robot, "-o", "local", *COMMON])
    finally:
        os.chdir(here)
    return {"robot": robot, "logs": logs, "client": client, "remote": remote, "local": local}


def a_monitor_without_a_shared_folder_gives_one_local_jobs_outputs(cluster, local: dict, monkeypatch):
    """The local run on every log (``local``: :func:`local_monitor_run`'s) against two runs on the
    cluster (``cluster``: tests/test_cluster.py's :class:`Cluster` with its two workers, w1 and w2),
    the second after the rest of the logs arrived (it scores only those): every output but the cache
    the same bytes, the state included; the cluster's workers simulated the parts' twin cycles and
    sent them back. A third run with no new log makes every chart again on the workers, the same
    bytes. ``monkeypatch`` changes the working directory (the caller's restores it)."""
    robot, logs, client, remote = local["robot"], local["logs"], local["client"], local["remote"]
    assert local["local"].exit_code == 3, local["local"].output  # unit98 is not monitored
    monkeypatch.chdir(remote)
    assert sorted(cluster.workers()) == ["w1", "w2"]
    on_cluster = ["--robot", robot, "-o", "remote", *COMMON, "--scheduler", cluster.address]
    first = CliRunner().invoke(app, ["monitor", "logs", *on_cluster])
    assert first.exit_code == 3, first.output
    _linked(logs, remote / "logs", slice(16, None))
    again = CliRunner().invoke(app, ["monitor", "logs", *on_cluster])
    assert again.exit_code == 3, again.output
    grown = _outputs(remote / "remote")
    for chart in (remote / "remote").glob("*.png"):
        chart.unlink()
    # no new log: the charts made again there
    idle = CliRunner().invoke(app, ["monitor", "logs", *on_cluster])
    assert idle.exit_code == 3, idle.output
    both = CliRunner().invoke(app, ["monitor", "logs", "--robot", robot, "-o", "other", *COMMON,
                                    "--scheduler", cluster.address, "--jobs", "2"])
    expected = _outputs(client / "local")
    assert {"units.csv", "alarms.csv", "scores.csv", "wear.csv", "rul.csv", "report.html", "unit01.png",
            ".state/unit01.json", ".state/unit98.json"} <= set(expected)
    assert grown == expected
    assert _outputs(remote / "remote") == expected
    units = (client / "local" / "units.csv").read_text()
    assert f"{Path('logs') / 'unit98' / min((logs / 'unit01').iterdir()).name}: column t goes back" in units
    # the same cycles and calibrations cached: the workers calibrated each unit and simulated its twin,
    # and sent them back
    for entry in ("cycles", "calibrated"):
        assert sorted(p.name for p in (remote / "remote" / ".cache" / entry).iterdir()) == \
            sorted(p.name for p in (client / "local" / ".cache" / entry).iterdir()), entry
    assert "calibrated" in (remote / "remote" / "units.csv").read_text()
    # --jobs with --scheduler is refused before any work
    assert both.exit_code == 2 and "--jobs 2 with --scheduler" in both.output, both.output
    assert not (remote / "other").exists()


@pytest.mark.parametrize("address", ["foo", "tcp://127.0.0.1:99999"])
def test_a_bad_scheduler_address_is_refused_before_any_work(tmp_path, address):
    (tmp_path / "logs" / "unit01").mkdir(parents=True)
    result = CliRunner().invoke(app, ["monitor", str(tmp_path / "logs"), "--robot", "puma560", "-o",
                                      str(tmp_path / "out"), "--scheduler", address])
    assert result.exit_code == 2, result.output
    assert f"--scheduler {address!r}" in result.output or f"'{address}'" in result.output, result.output
    assert not (tmp_path / "out").exists()
