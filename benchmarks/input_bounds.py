"""Peak memory and time of faultgen on long logs and on hostile files (issue 50, item 4): a
benchmark, not a test.

Each case runs as its own process; its peak resident memory is the ``ru_maxrss`` that ``os.wait4``
returns for that process alone (the interpreter and faultgen's imports included, about 0.2-0.3 GB).
Prints one Markdown row per case with its verdict:

* ``calibrate`` on CSV logs of 10^5, 10^6 and 10^7 rows at 1 kHz (100 s, 17 min, 2.8 h). Goal: the
  peak flat within 20 % of the 10^5-row one. The logs: the PUMA 560 along
  :func:`faultgen.calibrate.synth.excitation` (sines of 0.1 and 0.23 Hz, so 100 s is one period), its
  torque from our own inverse dynamics plus 1 % noise over one period, tiled (so the motion is smooth
  across the joins); written once into FOLDER (1.7 GB for 10^7 rows) and reused.
* a replay on CSV logs of 10^5, 10^6 and 10^7 rows over the same 50 s (2, 20 and 200 kHz; the
  PUMA 560 moving on every axis, sines of 0.05-0.1 Hz): ``replay`` is the reading and the reference
  path at the robot's time step (``programs.load(...).trajectory(dt)``), ``simulate`` one whole cycle
  of ``faultgen simulate --task LOG`` in memory. A replayed cycle lasts at most an hour
  (MAX_CYCLE_DURATION) and the simulation's cost follows its duration, so the duration is held and
  the rows (the sampling rate) vary. Goal: the peak flat within 20 % of the 10^5-row one.
* reading each bomb: TOML with a dotted key of 10^5 and of 2x10^4 parts and with 5x10^4 nested
  brackets (as a drivetrain table, as a DH table, as a program), ``--drivetrain /dev/zero``, a
  gzip-bomb log (3.9 MB inflating to 4 GB of valid-looking rows, through ``calibrate``), a
  dataset declaring a (10^10, 6) array (``faultgen.open`` and ``validate``), a measured log
  declaring 10^10 rows (``calibrate``). Goal: refused (exit 2 / ValueError) in under 5 s and
  under 500 MB.
* reading three hostile xacros as ``robots add`` does (``importers.read``: expanded, parsed,
  compiled; :func:`xacro_bombs`; issue 61, item 5): a 2.4 kB macro fan-out of 16^10 calls, a 103 kB
  file expanding to a 600 MB URDF, an expression of 50 000 minus signs. Each runs with its address
  space capped at 2 GB and is killed after 60 s. Goal: refused or completed within both.
* bounded work (issue 61, item 5): a CSV log whose header has 32 000 extra columns (``calibrate``), an
  HDF5 log declaring 10^8 rows (``calibrate``, and ``logs import``'s reader, ``measured.read``, the
  monitor's too), a voraus-AD Parquet table of 10^8 rows (a few MB: constant columns), an RTDE
  recorder log of one-character cells (the ``ur-rtde`` adapter), ``events.csv`` at the old 64 MiB
  bound and at the new bound (minimal rows), a program of 10^4 moves (``programs.read`` and its
  path). Goal: refused or completed within 2 GB and 60 s.

Every case runs under a cap (``--cap-mb``, default 4000 MB resident, and ``--cap-s``, 120 s): a
process above it is killed and reported as such, so a case that blows up on old code is measured
without taking the machine down.

    python benchmarks/input_bounds.py [FOLDER]          # default /tmp/faultgen-input-bounds
    python benchmarks/input_bounds.py FOLDER --quick    # the bombs and the 10^5/10^6 logs only
    python benchmarks/input_bounds.py FOLDER --no-bombs --sizes 100000 10000000
    python benchmarks/input_bounds.py FOLDER --no-bombs --kinds replay simulate
    python benchmarks/input_bounds.py FOLDER --xacro    # the xacro bombs only
"""

from __future__ import annotations

import argparse
import gzip
import json
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from faultgen import children

PERIOD = 0.001
BASE_ROWS = 100_000  # one period of the excitation at 1 kHz
SIZES = (100_000, 1_000_000, 10_000_000)
FLAT = 0.20
BOMB_MB, BOMB_S = 500, 5.0
XACRO_MB, XACRO_S = 2048, 60.0
WORK_MB, WORK_S = 2000, 60.0
CAP_MB, CAP_S = 4000, 120.0


def make_log(folder: Path, rows: int) -> Path:
    """The PUMA 560 excitation log of ``rows`` rows (module docstring), written once."""
    path = folder / f"log-{rows}.csv"
    if path.exists():
        return path
    from faultgen.calibrate import predict, synth
    from faultgen.logs import measured
    from faultgen.model import robots

    puma = robots.load("puma560")
    t, q, qd, _ = synth.excitation([puma, robots.load("irb6700")], BASE_ROWS * PERIOD, PERIOD)
    tau = np.empty_like(q)
    for start in range(0, BASE_ROWS, 25_000):
        part = slice(start, start + 25_000)
        tau[part] = predict(puma, measured.from_arrays(t[part], q[part], np.zeros_like(q[part]), robot=puma,
                                                       qd=qd[part]))
    tau += np.random.default_rng(0).normal(size=tau.shape) * 0.01 * np.sqrt(np.mean(tau**2, axis=0))
    rest = [",".join(row) for row in np.char.mod("%.9g", np.column_stack([q, tau]))]
    header = "t," + ",".join([f"q{i}" for i in range(1, 7)] + [f"tau{i}" for i in range(1, 7)]) + "\n"
    tmp = path.with_suffix(".part")
    with open(tmp, "w") as fh:
        fh.write(header)
        for tile in range(-(-rows // BASE_ROWS)):
            n = min(BASE_ROWS, rows - tile * BASE_ROWS)
            times = np.char.mod("%.3f", (tile * BASE_ROWS + np.arange(n)) * PERIOD)
            fh.write("\n".join(f"{a},{b}" for a, b in zip(times, rest[:n])) + "\n")
    tmp.rename(path)
    return path


REPLAY_SECONDS = 50.0


def make_replay_log(folder: Path, rows: int) -> Path:
    """``rows`` rows of the PUMA 560 moving over :data:`REPLAY_SECONDS` (module docstring), written
    once, in pieces (times to 1e-11 s, angles to 12 digits)."""
    path = folder / f"replay-{rows}.csv"
    if path.exists():
        return path
    import pandas as pd

    from faultgen.model import robots

    home = robots.load("puma560").home
    frequency = 0.05 * (1 + np.arange(6) / 5)
    tmp = path.with_suffix(".part")
    with open(tmp, "w") as fh:
        fh.write("t," + ",".join(f"q{i}" for i in range(1, 7)) + "\n")
        for start in range(0, rows, 1_000_000):
            t = np.arange(start, min(start + 1_000_000, rows)) * (REPLAY_SECONDS / rows)
            q = home + 0.3 * np.sin(2 * np.pi * frequency * t[:, None])
            pd.DataFrame(np.column_stack([t, q])).to_csv(fh, header=False, index=False, float_format="%.12g")
    tmp.rename(path)
    return path


def make_bombs(folder: Path) -> dict[str, Path]:
    import h5py

    out = {}
    for name, text in {"dotted-1e5.toml": "axis" + ".a" * 100_000 + " = 1\n",
                       "dotted-2e4.toml": "axis" + ".a" * 20_000 + " = 1\n",
                       "brackets-5e4.toml": "a = " + "[" * 50_000 + "]" * 50_000 + "\n"}.items():
        out[name] = folder / name
        out[name].write_text(text)
    bomb = folder / "bomb.csv.gz"
    if not bomb.exists():
        header = b"t," + ",".join([f"q{i}" for i in range(1, 7)] + [f"tau{i}" for i in range(1, 7)]).encode() + b"\n"
        with gzip.open(bomb, "wb", compresslevel=9) as g:
            g.write(header)
            row = b"0,0,0,0,0,0,0,0,0,0,0,0,0\n"
            for _ in range(160):
                g.write(row * 1_000_000)
    out["bomb.csv.gz"] = bomb
    log = folder / "declared-1e10.h5"
    with h5py.File(log, "w") as f:
        for name in ["t", *(f"q{i}" for i in range(1, 7)), *(f"tau{i}" for i in range(1, 7))]:
            f.create_dataset(name, shape=(10**10,), dtype="f8", chunks=(4096,))
    out["declared-1e10.h5"] = log
    data = folder / "dataset-1e10.h5"
    if not data.exists():
        from faultgen.runs import sweep

        base = folder / "dataset-base.h5"
        if not base.exists():
            sweep.run(sweep.Grid(robots=["puma560"], tasks=["pick_place"], axes=[0], cycles=2), base,
                      progress=False)
        data.write_bytes(base.read_bytes())
        with h5py.File(data, "r+") as f:
            group = f["runs"][next(iter(f["runs"]))]
            del group["tau_m"]
            group.create_dataset("tau_m", shape=(10**10, 6), dtype="f8", chunks=(1024, 6))
    out["dataset-1e10.h5"] = data
    return out


XACRO_NS = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'


def six_axis_urdf() -> str:
    """The links and joints of a valid six-axis arm (what `robots add` takes), for the xacro bombs."""
    parts = ['<link name="base"/>']
    axes = ["0 0 1", "0 1 0", "0 1 0", "1 0 0", "0 1 0", "1 0 0"]  # a six-axis industrial arm's
    offsets = ["0 0 0.4", "0.1 0 0.2", "0 0 0.6", "0.3 0 0.1", "0.3 0 0", "0.1 0 0"]
    for k in range(6):
        parts.append(f'<link name="l{k}"><inertial><mass value="{10 - k}"/><origin xyz="0.05 0 0.05"/>'
                     '<inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>'
                     f'<joint name="j{k}" type="revolute"><parent link="{"base" if k == 0 else f"l{k - 1}"}"/>'
                     f'<child link="l{k}"/><origin xyz="{offsets[k]}"/><axis xyz="{axes[k]}"/>'
                     '<limit lower="-3" upper="3" effort="0" velocity="2"/></joint>')
    return "".join(parts)


def xacro_bombs(folder: Path) -> dict[str, Path]:
    """Three hostile xacros (issue 61, item 5):

    * ``fanout.xacro`` (2.4 kB): ten macros, each calling the one below 16 times: 16^10 (10^12)
      macro calls producing nothing (so no element bound is reached);
    * ``wide.xacro`` (103 kB): a property of 10^5 characters written out, in one attribute of
      6000 ``<gazebo>`` elements from three macros of ten calls each, beside a valid six-axis arm: a
      600 MB URDF;
    * ``unary.xacro`` (50 kB): ``${-----...-1}`` with 50 000 minus signs.
    """
    texts = {
        "fanout.xacro": '<xacro:macro name="m0" params=""/>\n' + "".join(
            f'<xacro:macro name="m{k}" params="">{f"<xacro:m{k - 1}/>" * 16}</xacro:macro>\n' for k in range(1, 11))
        + "<xacro:m10/>",
        "wide.xacro": f'<xacro:property name="w" value="{"x" * 100_000}"/>\n'
        '<xacro:macro name="g1" params="">' + '<gazebo reference="${w}"/>' * 10 + "</xacro:macro>\n"
        '<xacro:macro name="g2" params="">' + "<xacro:g1/>" * 10 + "</xacro:macro>\n"
        '<xacro:macro name="g3" params="">' + "<xacro:g2/>" * 10 + "</xacro:macro>\n" + "<xacro:g3/>" * 6,
        "unary.xacro": '<link name="${' + "-" * 50_000 + '1}"/>',
    }
    out = {}
    for name, body in texts.items():
        out[name] = folder / name
        arm = six_axis_urdf() + "\n" if name == "wide.xacro" else ""
        out[name].write_text(f'<robot name="{name.split(".")[0]}" {XACRO_NS}>\n{arm}{body}\n</robot>\n')
    return out


PUMA_COLUMNS = ["t", *(f"q{i}" for i in range(1, 7)), *(f"tau{i}" for i in range(1, 7))]


def make_work_bombs(folder: Path) -> dict[str, Path]:
    """The hostile files of bounded work (module docstring), written once each."""
    import h5py

    out = {}
    wide = out["wide-32000.csv"] = folder / "wide-32000.csv"
    if not wide.exists():
        names = PUMA_COLUMNS + [f"x{i}" for i in range(32_000)]
        rows = [",".join([f"{k * 0.001:.3f}"] + ["0"] * (len(names) - 1)) for k in range(3)]
        wide.write_text(",".join(names) + "\n" + "\n".join(rows) + "\n")
    declared = out["declared-1e8.h5"] = folder / "logs-1e8" / "unit1" / "1.h5"
    if not declared.exists():
        declared.parent.mkdir(parents=True, exist_ok=True)
        with h5py.File(declared, "w") as f:
            for name in PUMA_COLUMNS:
                f.create_dataset(name, shape=(10**8,), dtype="f8", chunks=(4096,))
    out["logs-1e8"] = folder / "logs-1e8"
    voraus = out["voraus-1e8.parquet"] = folder / "voraus-1e8.parquet"
    if not voraus.exists():
        import pyarrow as pa
        import pyarrow.parquet as pq

        names = ["time", *(f"{c}_{k}" for c in ("joint_position", "joint_velocity", "motor_torque")
                           for k in range(1, 7)), "sample"]
        zeros = pa.array(np.zeros(10**6))
        table = pa.table({name: zeros for name in names})
        tmp = voraus.with_suffix(".part")
        with pq.ParquetWriter(tmp, table.schema) as writer:
            for _ in range(100):
                writer.write_table(table, row_group_size=10**6)
        tmp.rename(voraus)
    rtde = out["rtde-bomb.csv"] = folder / "rtde-bomb.csv"
    if not rtde.exists():  # 1.5x10^6 rows of 100 one-character cells (and the time): 300 MB
        names = ["timestamp", *(f"{c}_{k}" for c in ("actual_q", "actual_qd", "target_moment", "actual_current")
                                for k in range(6))]
        names += [f"output_{i}" for i in range(100 - len(names) + 1)]
        tail = " 0" * (len(names) - 1) + "\n"
        tmp = rtde.with_suffix(".part")
        with open(tmp, "w") as fh:
            fh.write(" ".join(names) + "\n")
            for start in range(0, 1_500_000, 100_000):
                fh.write("".join(f"{k * 0.002:.3f}{tail}" for k in range(start, start + 100_000)))
        tmp.rename(rtde)
    for name, size in (("events-64MiB.csv", 64 * 2**20), ("events-16MiB.csv", 16 * 2**20)):
        events = out[name] = folder / name.removesuffix(".csv") / "events.csv"
        if not events.exists():
            events.parent.mkdir(exist_ok=True)
            (events.parent / "u").mkdir(exist_ok=True)
            (events.parent / "u" / "1.csv").write_text("")
            header, row = b"unit,stamp,event,axis\n", b"u,1,onset,1\n"
            events.write_bytes(header + row * ((size - len(header)) // len(row)))
    program = out["program-1e4.toml"] = folder / "program-1e4.toml"
    moves = ["[[segment]]\ntype = \"move\"\nto = [" + ("10, 80, -110, 20, 10, 10" if k % 2 else "0, 92, -122, 30, 0, 0")
             + "]\n" for k in range(10_000)]
    program.write_text('name = "many"\nstart = [0, 92, -122, 30, 0, 0]\n\n' + "\n".join(moves))
    return out


#: kind -> (imports, the case): only the case is timed (imports took 2-5 s on the loaded machine).
CASES_CODE = {
    "calibrate": ("from faultgen.calibrate import calibrate", "calibrate('puma560', {log!r}, {out!r})"),
    "replay": ("from faultgen.operation import programs\nfrom faultgen.model import robots",
               "programs.load(robots.load('puma560'), {log!r}).trajectory(robots.load('puma560').model.opt.timestep)"),
    "simulate": ("from faultgen.simulation.resolve import resolve\nfrom faultgen.simulation.spec import RunSpec",
                 ("resolve(RunSpec(robot='puma560', task={log!r}, cycles=1, seed=0, nthread=1))"
                  ".simulate(progress=False)")),
    "drivetrain": ("from faultgen.model import drivetrain", "drivetrain.read({log!r}, 6)"),
    "dh": ("from pathlib import Path\nfrom faultgen.model import import_dh", "import_dh.read_dh(Path({log!r}))"),
    "program": ("from faultgen.operation import programs\nfrom faultgen.model import robots",
                "programs.read({log!r}, robots.load('puma560'))"),
    "open": ("import faultgen", "faultgen.open({log!r}).features()"),
    "validate": ("from faultgen.data import dataset", "dataset.validate({log!r})"),
    # what `robots add` reads (expanded, parsed, compiled by MuJoCo); the URDF it would write, its size
    "xacro": ("from faultgen.model import importers",
              "print(len(importers.read({log!r}).urdf), 'characters of urdf_used.urdf', file=sys.stderr)"),
    "measured": ("from faultgen.logs import measured\nfrom faultgen.model import robots", "measured.read({log!r}, robots.load('puma560'), accelerations=False)"),
    "logs-import": ("from faultgen.data import fleetlogs",
                    "fleetlogs.import_logs({log!r}, {out!r} + '.h5', robot='puma560', progress=False)"),
    "voraus": ("from faultgen.logs import formats as adapters\nfrom faultgen.model import robots",
               "adapters.make('voraus').read({log!r}, robots.load('puma560'), accelerations=False)"),
    "ur-rtde": ("from faultgen.logs import formats as adapters\nfrom faultgen.model import robots",
                "adapters.make('ur-rtde').read({log!r}, robots.load('puma560'), accelerations=False)"),
    "events": ("from pathlib import Path\nfrom faultgen.data import logfolder",
               "logfolder.read_events(Path({log!r}), {{'u': [logfolder.LogFile('u', '1', 1.0, 'sequence', "
               "Path({log!r}).parent / 'u' / '1.csv', 'u/1.csv')]}}, 6)"),
    "program-path": ("from faultgen.operation import programs\nfrom faultgen.model import robots",
                     "programs.read({log!r}, robots.load('puma560')).trajectory(robots.load('puma560').model.opt.timestep)"),
}


def run_case(kind: str, log: Path, out: Path, cap_mb: int | None = None, timeout: float | None = None) -> dict:
    """Run one case in a fresh interpreter; its peak resident memory from os.wait4, the case's own
    time (after the imports), and whether it was refused (a ValueError: the CLI's exit 2) or completed.
    ``cap_mb``: its address space is capped (RLIMIT_AS: past it, a MemoryError); ``timeout``: it is
    killed after that many seconds. The time of a killed or crashed case is the process's, imports
    included."""
    imports, call = CASES_CODE[kind]
    cap = f"import resource\nresource.setrlimit(resource.RLIMIT_AS, ({cap_mb << 20}, {cap_mb << 20}))\n" if cap_mb else ""
    code = (f"{cap}import json, sys, time\n{imports}\nstart = time.perf_counter()\ntry:\n"
            f"    {call.format(log=str(log), out=str(out))}\n"
            "    result = {'outcome': 'completed'}\n"
            "except ValueError as err:\n    result = {'outcome': 'refused', 'message': str(err)[:160]}\n"
            "print(json.dumps({**result, 'seconds': time.perf_counter() - start}))\n")
    shutil.rmtree(out, ignore_errors=True)
    Path(str(out) + ".h5").unlink(missing_ok=True)
    killed = None
    with tempfile.TemporaryFile("w+") as stdout, tempfile.TemporaryFile("w+") as stderr:
        start = time.monotonic()
        proc = subprocess.Popen(children.command("-c", code), env=children.environment(), stdout=stdout,
                                stderr=stderr, text=True)
        limit = timeout if timeout else CAP[1]
        while True:  # the cap: resident memory and time polled, the process killed above either
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            rss = _rss_mb(proc.pid)
            if killed is None and (rss > CAP[0] or time.monotonic() - start > limit):
                killed = (f"killed at the cap ({rss:.0f} MB resident after {time.monotonic() - start:.0f} s; cap "
                          f"{CAP[0]:g} MB, {limit:g} s)")
                proc.kill()
            time.sleep(0.02)
        seconds = time.monotonic() - start
        proc.returncode = os.waitstatus_to_exitcode(status)
        stdout.seek(0)
        stderr.seek(0)
        lines, errors = stdout.read().strip().splitlines(), stderr.read().strip().splitlines()
    if killed:
        result = {"outcome": killed, "seconds": seconds}
    else:
        result = json.loads(lines[-1]) if lines else {
            "outcome": f"crashed (exit {proc.returncode}): {errors[-1][:160] if errors else ''}", "seconds": seconds}
        if result["outcome"] == "completed" and errors:
            result["message"] = errors[-1][:160]  # what the case printed of its result (the xacro's URDF size)
    return {**result, "peak_mb": usage.ru_maxrss / 1024}


#: The cap every case runs under: resident MB, seconds (set by --cap-mb, --cap-s).
CAP = [CAP_MB, CAP_S]


def _rss_mb(pid: int) -> float:
    try:
        with open(f"/proc/{pid}/status") as fh:
            for line in fh:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    return 0.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folder", nargs="?", default="/tmp/faultgen-input-bounds")
    parser.add_argument("--quick", action="store_true", help="skip the 10^7-row log")
    parser.add_argument("--sizes", type=int, nargs="+", help="log lengths (rows) to run; the first is the baseline")
    parser.add_argument("--no-bombs", action="store_true", help="only the logs")
    parser.add_argument("--no-logs", action="store_true", help="only the bombs")
    parser.add_argument("--xacro", action="store_true", help="only the xacro bombs")
    parser.add_argument("--kinds", nargs="+", default=["calibrate", "replay", "simulate"],
                        help="what to run on the logs")
    parser.add_argument("--no-work", action="store_true", help="skip the bounded-work cases (issue 61, item 5)")
    parser.add_argument("--only-work", action="store_true", help="only the bounded-work cases")
    parser.add_argument("--cap-mb", type=float, default=CAP_MB, help="kill a case above this resident memory, MB")
    parser.add_argument("--cap-s", type=float, default=CAP_S, help="kill a case running longer, s")
    args = parser.parse_args()
    CAP[:] = [args.cap_mb, args.cap_s]
    if args.only_work:
        args.no_bombs = args.no_logs = True
    folder = Path(args.folder)
    folder.mkdir(parents=True, exist_ok=True)
    print(f"# {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load average "
          f"{os.getloadavg()[0]:.1f}, {os.cpu_count()} cores\n")
    print("| case | file | outcome | seconds | peak MB | verdict |\n| --- | --- | --- | --- | --- | --- |")
    for name, path in ({} if args.no_bombs else xacro_bombs(folder)).items():
        r = run_case("xacro", path, folder / "out-bomb", cap_mb=XACRO_MB, timeout=XACRO_S)
        ok = r["outcome"] in ("refused", "completed") and r["seconds"] < XACRO_S and r["peak_mb"] < XACRO_MB
        print(f"| xacro | {name} ({path.stat().st_size / 1e3:.1f} kB) | {r['outcome']}: {r.get('message', '')[:200]} | "
              f"{r['seconds']:.2f} | {r['peak_mb']:.0f} | {'met' if ok else 'NOT met'} (goal: refused or completed, "
              f"< {XACRO_S:g} s, < {XACRO_MB} MB, address space capped there) |", flush=True)
    if args.xacro:
        return
    bombs = {} if args.no_bombs else make_bombs(folder)
    for kind, name in [] if args.no_bombs else [("drivetrain", "dotted-1e5.toml"), ("drivetrain", "dotted-2e4.toml"),
                       ("dh", "dotted-1e5.toml"), ("program", "brackets-5e4.toml"), ("drivetrain", "brackets-5e4.toml"),
                       ("drivetrain", "/dev/zero"), ("calibrate", "bomb.csv.gz"), ("calibrate", "declared-1e10.h5"),
                       ("replay", "declared-1e10.h5"), ("open", "dataset-1e10.h5"), ("validate", "dataset-1e10.h5")]:
        path = bombs.get(name, Path(name))
        r = run_case(kind, path, folder / "out-bomb")
        ok = r["outcome"] == "refused" and r["seconds"] < BOMB_S and r["peak_mb"] < BOMB_MB
        print(f"| {kind} | {name} ({path.stat().st_size / 1e6:.2f} MB) | {r['outcome']}: {r.get('message', '')[:90]} | "
              f"{r['seconds']:.1f} | {r['peak_mb']:.0f} | {'met' if ok else 'NOT met'} (goal: refused, < {BOMB_S:g} s, "
              f"< {BOMB_MB} MB) |", flush=True)
    work = {} if args.no_work else make_work_bombs(folder)
    for kind, name in [] if args.no_work else [
            ("calibrate", "wide-32000.csv"), ("calibrate", "declared-1e8.h5"), ("measured", "declared-1e8.h5"),
            ("logs-import", "logs-1e8"), ("voraus", "voraus-1e8.parquet"), ("ur-rtde", "rtde-bomb.csv"),
            ("events", "events-64MiB.csv"), ("events", "events-16MiB.csv"), ("program", "program-1e4.toml"),
            ("program-path", "program-1e4.toml")]:
        path = work[name]
        r = run_case(kind, path, folder / "out-work")
        ok = r["outcome"] in ("refused", "completed") and r["seconds"] < WORK_S and r["peak_mb"] < WORK_MB
        size = sum(p.stat().st_size for p in path.rglob("*") if p.is_file()) if path.is_dir() else path.stat().st_size
        print(f"| {kind} | {name} ({size / 1e6:.2f} MB) | {r['outcome']}{': ' + r['message'][:110] if 'message' in r else ''}"
              f" | {r['seconds']:.1f} | {r['peak_mb']:.0f} | {'met' if ok else 'NOT met'} (goal: refused or completed, "
              f"< {WORK_S:g} s, < {WORK_MB} MB) |", flush=True)
    sizes = [] if args.no_logs else args.sizes or (SIZES[:2] if args.quick else SIZES)
    for kind in args.kinds:
        base = None
        for rows in sizes:
            log = make_log(folder, rows) if kind == "calibrate" else make_replay_log(folder, rows)
            out = folder / f"out-{kind}-{rows}"
            r = run_case(kind, log, out)
            base = base or r["peak_mb"]
            ratio = r["peak_mb"] / base
            verdict = (f"{'met' if ratio <= 1 + FLAT else 'NOT met'}: {ratio:.2f} x the {sizes[0]:.0e}-row peak (goal <= "
                       f"{1 + FLAT:.2f})")
            print(f"| {kind} | {rows:.0e} rows ({log.stat().st_size / 1e6:.0f} MB) | {r['outcome']}"
                  f"{': ' + r['message'][:90] if 'message' in r else ''} | {r['seconds']:.0f} | {r['peak_mb']:.0f} | "
                  f"{verdict} |", flush=True)


if __name__ == "__main__":
    main()
