"""A walk over every file ``faultgen monitor`` keeps in its OUT: each in turn replaced by a link to
a copy outside OUT, the run continued, and every file the process opened, made, renamed or removed
watched through Python's audit hooks (PEP 578, ``sys.addaudithook``: the interpreter reports each
``open``, ``os.mkdir``, ``os.rename``, ... before it happens). No event may reach the outside copy
(read or written through the link); the run refuses the link by name (exit 2) or, for an output
it replaces whole, replaces the link itself. The same hook records every process the run starts
(``subprocess.Popen``, ``os.posix_spawn``, ``os.exec``): each Python among them has ``-P`` (no
current folder on its path, :mod:`faultgen.children`).

The walk runs in one child interpreter (an audit hook cannot be removed once added), over a small
fleet of faultgen's own puma560 (tests/shipped_fleet.py)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from faultgen import children

sys.path.insert(0, str(Path(__file__).parent))
import shipped_fleet

WALK = textwrap.dedent(r'''
    import json, os, shutil, sys
    from pathlib import Path

    logs, earlier, base, work, report = map(Path, sys.argv[1:6])
    watched = {"outside": None}
    hits, starts = [], []

    NOT_FOLLOWED = ("os.rename", "os.replace", "os.remove", "os.symlink")  # they act on a link itself

    def where(event, path):
        path = os.fsdecode(path)
        if event in NOT_FOLLOWED:
            return os.path.join(os.path.realpath(os.path.dirname(path)), os.path.basename(path))
        return os.path.realpath(path)

    def hook(event, args):
        if event in ("subprocess.Popen", "os.posix_spawn", "os.exec"):
            index = 3 if event == "subprocess.Popen" else 2  # (executable, args, cwd, env) or (path, args, env)
            env = args[index] if len(args) > index else None
            env = os.environ if env is None else env
            safe = any(os.fsdecode(k) == "PYTHONSAFEPATH" and os.fsdecode(v) == "1" for k, v in dict(env).items())
            starts.append([event, [os.fsdecode(a) for a in (args[1] or [])], safe])
            return
        if watched["outside"] is None or event not in (
                "open", "os.mkdir", "os.rename", "os.replace", "os.remove", "os.rmdir", "os.symlink",
                "os.truncate", "os.chmod", "os.utime", "shutil.rmtree", "shutil.copyfile", "os.listdir", "os.scandir"):
            return
        for path in args[:2]:
            if isinstance(path, (str, bytes, os.PathLike)) and where(event, path).startswith(watched["outside"]):
                hits.append([event, os.fsdecode(path)])

    sys.addaudithook(hook)
    from typer.testing import CliRunner
    from faultgen.cli import app

    runner = CliRunner()
    # OUT as the fleet's logs a day before left it (the walk's runs each score one new log a unit)
    done = runner.invoke(app, ["monitor", str(earlier), "--robot", "puma560", "-o", str(base), "--no-calibrate"])
    if done.exit_code != 0:
        sys.exit(f"the first run: exit {done.exit_code}\n{done.output[-2000:]}")
    results = []
    kept = sorted(str(p.relative_to(base)) for p in base.rglob("*") if p.is_file())
    for i, rel in enumerate(kept):
        out, outside = work / f"out{i}", work / f"outside{i}"
        shutil.copytree(base, out)
        outside.mkdir()
        copy = outside / Path(rel).name
        shutil.move(out / rel, copy)
        (out / rel).symlink_to(copy)
        before = copy.read_bytes()
        watched["outside"] = os.path.realpath(outside)
        done = runner.invoke(app, ["monitor", str(logs), "--robot", "puma560", "-o", str(out), "--no-calibrate"])
        watched["outside"] = None
        results.append({"file": rel, "exit": done.exit_code, "output": done.output[-600:], "hits": hits[:],
                        "unchanged": copy.read_bytes() == before, "link_kept": (out / rel).is_symlink()})
        hits.clear()
    # a new OUT with the first run's twin cycles (not simulated again: the run's processes are the check)
    shutil.copytree(base / ".cache" / "cycles", work / "jobs" / ".cache" / "cycles")
    done = runner.invoke(app, ["monitor", str(logs), "--robot", "puma560", "-o", str(work / "jobs"), "--no-calibrate",
                               "--jobs", "2"])
    report.write_text(json.dumps({"results": results, "starts": starts, "jobs_exit": done.exit_code,
                                  "jobs_output": done.output[-600:]}))
''')


@pytest.fixture(scope="module")
def walked(tmp_path_factory) -> dict:
    root = tmp_path_factory.mktemp("walk")
    spec = shipped_fleet.ShippedFleet(robot="puma560", units=1, days=3, worn={}, parts=(1.0,), no_payload=0)
    logs = shipped_fleet.write_fleet(root, spec)[0]
    earlier = root / "earlier" / "logs"  # the fleet a day before: the walk's runs each score one new log a unit
    shutil.copytree(logs, earlier)
    for unit in earlier.iterdir():
        sorted(unit.iterdir())[-1].unlink()
    base = root / "base"  # made by the walk's interpreter (one start of faultgen less)
    report = root / "report.json"
    plain = {k: v for k, v in os.environ.items() if k != "PYTHONSAFEPATH"}  # as a user's shell starts faultgen
    done = subprocess.run(children.command("-c", WALK, str(logs), str(earlier), str(base), str(root), str(report)),
                          env=plain, capture_output=True, text=True, check=False, cwd=root,
                          timeout=900)
    assert done.returncode == 0, done.stderr[-3000:]
    return {"base": base, **json.loads(report.read_text())}


def test_every_file_of_out_is_walked(walked):
    files = {r["file"] for r in walked["results"]}
    assert any(f.startswith(".state/") for f in files) and any(f.startswith(".cache/cycles/") for f in files)
    assert not any(f.startswith(".cache/programs/") for f in files) and "alarms.csv" in files and "report.html" in files


def test_no_file_is_read_or_written_through_a_link_leading_out_of_out(walked):
    bad = [r for r in walked["results"] if r["hits"] or not r["unchanged"]]
    assert not bad, bad
    refused = set()
    for r in walked["results"]:
        if r["exit"] == 2:  # refused: one line naming the link, nothing of the run written
            assert f"{r['file']}: a link leading outside the monitor output folder" in r["output"], r
            assert "Traceback" not in r["output"], r
            refused.add(r["file"].split("/")[0] if r["file"].startswith(".state") else r["file"].rsplit("/", 1)[0])
        else:  # not needed by the run (a cycle of another condition), or an output written whole: the link replaced
            assert r["exit"] == 0, r
    assert refused >= {".state", ".cache/cycles"}, refused


def test_every_python_the_monitor_starts_has_no_current_folder_on_its_path(walked):
    assert walked["jobs_exit"] == 0, walked["jobs_output"]
    pythons = [(args, safe) for _, args, safe in walked["starts"] if args and "python" in Path(args[0]).name]
    assert pythons  # MuJoCo's import of glfw starts one: with the current folder on its path before
    assert all(safe or "-P" in args[1:3] or "-I" in args[1:3] for args, safe in pythons), pythons
