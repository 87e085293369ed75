"""The monitor's outputs on a fixed list of small runs, as a manifest (relative path -> sha256) that a
refactoring of faultgen.monitor must leave unchanged (issue 84, "What it must show").

    PYTHONPATH=. python benchmarks/golden_monitor.py --work /tmp/golden            # print the manifest
    PYTHONPATH=. python benchmarks/golden_monitor.py --work /tmp/golden -o benchmarks/golden_monitor.json
    PYTHONPATH=. python benchmarks/golden_monitor.py --work /tmp/golden --check benchmarks/golden_monitor.json

The runs (``faultgen monitor`` by its command line, in-process; the fleets of tests/independent_fleet.py
and tests/test_monitor_ur_logs.py at a small size, every twin on the nominal model, --no-calibrate, to
keep the whole under a few minutes):

- ``kr210-tests``: the clean KR210 fleet with friction tests (2 units x 18 days, one worn, tests every
  8 days);
- ``kr210-own``: the same logs, ``--protocol own``;
- ``kr210-continued``: the same logs, first up to day 14, then the rest into the same OUT;
- ``kr210-changes``: a KR210 fleet with a gearbox change (worn unit) and an unlogged program change
  (healthy unit);
- ``iiwa-cycles``: an LBR iiwa 14 fleet whose logs hold 1 or 2 cycles at 250 or 500 Hz;
- ``ur-rtde``: a UR5 fleet in the RTDE recorder's layout (``--format ur-rtde --torque-constants``).

Every file under each OUT is hashed, with these exclusions, named: ``.state/`` (the saved state,
whose format issue 84 item 2 changes; the continued run checks what it carries), ``.cache/`` (content-addressed
simulated cycles and calibrations: inputs the run keeps, not its outputs), and in ``report.html`` and
``settings.json`` the absolute paths of this machine's work folder (replaced by ``<WORK>`` before
hashing). Nothing else is volatile: the monitor writes no wall times.

The script runs in the numeric profile ``x86-64-v3`` (:mod:`faultgen.bench.profile`; it starts itself
again with it where the processor can take it): NumPy's own AVX-512 loops give other last bits than its
AVX2 ones, and the manifest, recorded on an AVX2 machine, differed on 7 of its 63 files on an AVX-512 one
(the KR210 runs with friction tests; 0 with the profile pinned, 2026-11-29).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import shutil
import tempfile
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import independent_fleet  # noqa: E402
from typer.testing import CliRunner  # noqa: E402

from faultgen.cli import app  # noqa: E402

COMMON = ["--no-calibrate", "--train", "10", "--persistence", "3", "--no-progress"]
#: Files whose text names the work folder (absolute paths), compared with it replaced by <WORK>.
PATH_BEARING = {"report.html", "settings.json"}
#: Folders under OUT not hashed: the content-addressed cache, and the saved state (issue 84 item 2 changes
#: its format on purpose; the continued run checks what it carries through its outputs).
SKIPPED = (".cache", ".state")
KR210 = independent_fleet.FleetSpec(units=2, worn=1, days=18, seed=3, onset=(11, 11), friction_test_every=8)
CHANGES = independent_fleet.FleetSpec(units=2, worn=1, days=22, seed=4, onset=(4, 4), final_wear=100.0,
                                      gearbox_changes=1, program_changes=1)
IIWA = independent_fleet.FleetSpec(units=2, worn=1, days=14, seed=5, onset=(5, 5), final_wear=100.0,
                                   wearable=(1, 2, 3, 4, 5, 6, 7), max_part=14.0, rated_part=True, rate=250.0,
                                   cycles=(1, 2), rates=(250.0, 500.0))


def monitor(logs: Path, robot: Path, out: Path, *extra: str) -> None:
    result = CliRunner().invoke(app, ["monitor", str(logs), "--robot", str(robot), "-o", str(out), *COMMON, *extra])
    if result.exit_code not in (0, 3):
        raise RuntimeError(f"monitor {out.name}: exit {result.exit_code}\n{result.output}\n{result.exception!r}")


def continued(logs: Path, robot: Path, out: Path, cut: str) -> None:
    """The fleet's logs up to stamp ``cut`` first, then all of them into the same OUT."""
    early = out.parent / f"{out.name}-logs"
    shutil.copytree(logs, early)
    for path in sorted(early.rglob("*.csv")):
        if path.parent.name != "friction-test" and path.name[:10] > cut and path.name[:2] == "20":
            path.unlink()
    monitor(early, robot, out)
    shutil.rmtree(early)
    monitor(logs, robot, out)


def ur_fleet(root: Path) -> tuple[Path, Path, str]:
    """Two UR5 units x 12 days in the RTDE layout, unit ur-01's axis 2 wearing from day 6."""
    import datetime

    import test_monitor_ur_logs as ur
    import ur_rtde_logs
    from faultgen.model import robots
    from faultgen.operation import wear

    robot_dir, logs = ur_rtde_logs.add_ur5(root), root / "logs"
    gear = robots.load(robot_dir).gear_ratio
    plans = {"ur-01": [(6, wear.WearPlan({})), (6, wear.WearPlan.from_specs(["2:linear:30"], last_cycle=6))],
             "ur-02": [(12, wear.WearPlan({}))]}
    command = None
    for seed, (unit, runs) in enumerate(plans.items(), start=1):
        day = 0
        for cycles, plan in runs:
            run = ur._simulate(robot_dir, seed, cycles, 91.0 + day, plan)
            command = run.tau_m[0] * gear if command is None else command
            for c in range(cycles):
                stamp = str(ur.START + datetime.timedelta(days=day + c))
                ur_rtde_logs.write_ur_log(logs / unit / f"{stamp}.csv", run.t, run.q_a[c], run.tau_m[c] * gear,
                                          run.conditions.joint_temperature[c], command, ur.TORQUE_CONSTANTS)
            day += cycles
    return robot_dir, logs, ",".join(f"{k:g}" for k in ur.TORQUE_CONSTANTS)


def run_all(work: Path) -> dict[str, Path]:
    """Every run of the list under ``work`` (emptied first); returns name -> OUT."""
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    outs = {}
    robot, logs, _ = independent_fleet.write_fleet(work / "kr210-fleet", KR210)
    outs["kr210-tests"] = work / "kr210-tests"
    monitor(logs, robot, outs["kr210-tests"])
    outs["kr210-own"] = work / "kr210-own"
    monitor(logs, robot, outs["kr210-own"], "--protocol", "own")
    outs["kr210-continued"] = work / "kr210-continued"
    continued(logs, robot, outs["kr210-continued"], "2026-01-18")
    changes, _ = independent_fleet.independent.write_fleet(work / "changes-fleet", CHANGES, robot)
    outs["kr210-changes"] = work / "kr210-changes"
    monitor(changes, robot, outs["kr210-changes"])
    iiwa = independent_fleet.add_robot(work / "iiwa14", "iiwa14", payload=14.0)
    iiwa_logs, _ = independent_fleet.independent.write_fleet(work / "iiwa-fleet", IIWA, iiwa)
    outs["iiwa-cycles"] = work / "iiwa-cycles"
    monitor(iiwa_logs, iiwa, outs["iiwa-cycles"])
    ur_robot, ur_logs, constants = ur_fleet(work / "ur-fleet")
    outs["ur-rtde"] = work / "ur-rtde"
    monitor(ur_logs, ur_robot, outs["ur-rtde"], "--format", "ur-rtde", "--torque-constants", constants)
    return outs


def digest(path: Path, work: Path) -> str:
    data = path.read_bytes()
    if path.name in PATH_BEARING:
        for form in {str(work.resolve()), str(work.absolute()), str(work)}:
            data = data.replace(form.encode(), b"<WORK>")
    return hashlib.sha256(data).hexdigest()


def manifest(outs: dict[str, Path], work: Path) -> dict[str, str]:
    files = {}
    for name, out in outs.items():
        for path in sorted(p for p in out.rglob("*") if p.is_file()):
            rel = path.relative_to(out)
            if rel.parts[0] in SKIPPED:
                continue
            files[f"{name}/{rel.as_posix()}"] = digest(path, work)
    return files


#: The numeric profile the manifest is made and checked in (module docstring).
PROFILE = "x86-64-v3"


def pin() -> None:
    """Start this script again in :data:`PROFILE` (:func:`faultgen.bench.profile.restart_pinned`)."""
    from faultgen.bench import profile

    profile.restart_pinned(PROFILE, sys.argv[1:], (str(Path(__file__).resolve()),))


def main() -> int:
    pin()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--work", type=Path, help="run in this folder (emptied first) and keep it; "
                        "default: a temporary folder, removed at the end (never the checkout)")
    parser.add_argument("-o", "--output", type=Path, help="write the manifest here (JSON)")
    parser.add_argument("--check", type=Path, help="compare with this manifest; exit 1 on any difference")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="golden-monitor-") as temporary:
        work = args.work or Path(temporary) / "work"
        files = manifest(run_all(work), work)
    if args.output:
        args.output.write_text(json.dumps(files, indent=1, sort_keys=True) + "\n")
    if args.check:
        expected = json.loads(args.check.read_text())
        differ = sorted(k for k in set(files) | set(expected) if files.get(k) != expected.get(k))
        for key in differ:
            print(f"DIFFERS: {key} ({'missing' if key not in files else 'new' if key not in expected else 'content'})")
        print(f"golden check: {len(files)} files, {len(differ)} differ: {'PASS' if not differ else 'FAIL'}")
        return 1 if differ else 0
    if not args.output:
        print(json.dumps(files, indent=1, sort_keys=True))
    print(f"{len(files)} files", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
