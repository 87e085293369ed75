"""`faultgen logs import` (issue 46): the time to import N logs against the time to read the same
files with pandas alone, in one run, and the import's peak memory at 100 and 1000 logs.

The logs: a fleet of puma560 units, daily logs of two 2.5 s cycles at 250 Hz (1250 rows: t, q1..6,
qd1..6, tau1..6 and cycle; tests/fleetlog_folder.py), CSV. The baseline reads every file with
``pandas.read_csv``; it and the import are timed in this process, alternating, the least of three
kept (the machine is shared). The import's peak memory: a process of its own under
``/usr/bin/time -v`` (the whole process, Python and its imports included). Prints a Markdown table
and, last, ``ratio <import / pandas at the largest N>``.

    python benchmarks/logs_import.py [folder]
"""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[1] / "tests"))

import fleetlog_folder  # noqa: E402

from faultgen import children
from faultgen.model import robots  # noqa: E402

#: Logs per fleet: units x days.
SIZES = {100: (10, 10), 1000: (10, 100)}


def write(folder: Path, units: int, days: int) -> Path:
    if not folder.exists():
        puma = robots.load("puma560")
        fleetlog_folder.write_fleet(folder, puma, units=units, days=days, worn={0: (2, days // 2, 0.01)})
        for unit in folder.iterdir():  # longer logs than the tests': 2 cycles of 2.5 s
            for log in unit.iterdir():
                day = int(log.stem[-2:])
                fleetlog_folder.write_log(log, puma, day, int(unit.name[1:]), fleetlog_folder.np.zeros(6),
                                          cycle_time=2.5)
    return folder


def measured_command(command: list[str]) -> tuple[float, float]:
    """(wall s, peak resident GB) of a command under /usr/bin/time -v."""
    run = subprocess.run(["/usr/bin/time", "-v", *command], env=children.environment(), capture_output=True, text=True)
    if run.returncode != 0:
        raise SystemExit(run.stdout + run.stderr)
    peak = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", run.stderr)[1]) * 1e3
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)", run.stderr)[1]
    return sum(float(x) * 60**i for i, x in enumerate(reversed(wall.split(":")))), peak / 1e9


IMPORT = """
import sys
from pathlib import Path
from faultgen.data import fleetlogs
fleetlogs.import_logs(Path(sys.argv[1]), Path(sys.argv[2]), robot="puma560", progress=False)
"""
#: Repeats of each timing, alternating; the least of each is kept (the machine is shared).
REPEATS = 3


def timings(logs: Path, out: Path) -> tuple[float, float, int]:
    """(pandas s, import s, rows per log): the least of REPEATS alternating runs in this process."""
    import pandas as pd

    from faultgen.data import fleetlogs

    files = sorted(logs.glob("*/*.csv"))
    read, imported = [], []
    for _ in range(REPEATS):
        started = time.perf_counter()
        rows = sum(len(pd.read_csv(f)) for f in files)
        read.append(time.perf_counter() - started)
        out.unlink(missing_ok=True)
        started = time.perf_counter()
        fleetlogs.import_logs(logs, out, robot="puma560", progress=False)
        imported.append(time.perf_counter() - started)
    return min(read), min(imported), rows // len(files)


def main() -> None:
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp())
    print(f"| logs | rows per log | pandas read_csv, s (least of {REPEATS}) | import, s (least of {REPEATS}) | ratio | "
          "import peak memory, GB (whole process) |")
    print("| --- | --- | --- | --- | --- | --- |")
    ratio = None
    for n, (units, days) in SIZES.items():
        logs = write(folder / f"logs-{n}", units, days)
        out = folder / f"import-{n}.h5"
        read_s, import_s, rows = timings(logs, out)
        out.unlink()
        _, peak = measured_command(children.command("-c", IMPORT, str(logs), str(out)))
        ratio = import_s / read_s
        print(f"| {n} | {rows} | {read_s:.2f} | {import_s:.2f} | {ratio:.2f} | {peak:.3f} |")
    print(f"ratio {ratio:.3f}")


if __name__ == "__main__":
    main()
