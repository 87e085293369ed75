"""`faultgen calibrate` on a 10^6-row log (4000 s at 250 Hz, about 67 minutes): time, peak memory
and accuracy against the first 25 000 rows of the same log calibrated whole (issue 42), and the first
60 000 (averaged down as well, by 3: ``calibrate.MAX_ROWS`` is 25 000).

The log: the PUMA 560 along the smooth excitation of :func:`faultgen.calibrate.synth.excitation`,
its torque from our own inverse dynamics (:func:`faultgen.calibrate.predict`; a check of memory
and of what decimation costs, not an independent check of the model), 1 % torque noise, and the
Coulomb friction of axis 2 raised by 30 % of the model's level (as in calibration_speed.py). Each
calibration runs as its own process under ``/usr/bin/time -v`` (peak resident memory of the
whole command). Prints one Markdown row per log: rows, seconds, peak GB, the Coulomb change
found on axis 2 (truth +30 %) and the held-out gap after.

    python benchmarks/calibration_long_log.py [folder]
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from faultgen import children
from faultgen.calibrate import MAX_ROWS, predict, synth
from faultgen.logs import measured
from faultgen.data import logfiles
from faultgen.model import robots

ROWS, PERIOD = 1_000_000, 0.004
#: Shorter logs calibrated whole: the first rows of the long log (the same excitation and noise draw).
WHOLE = (25_000, 60_000)


def make_log(path: Path, rows: int) -> None:
    puma = robots.load("puma560")
    t, q, qd, qdd = synth.excitation([puma, robots.load("irb6700")], rows * PERIOD, PERIOD)
    t, q = t[:rows], q[:rows]
    tau = np.empty_like(q)
    for start in range(0, rows, 50_000):  # our inverse dynamics, in chunks
        chunk = slice(start, start + 50_000)
        tau[chunk] = predict(puma, measured.from_arrays(t[chunk], q[chunk], np.zeros_like(q[chunk]), robot=puma,
                                                        qd=qd[chunk]))
    tau += np.random.default_rng(0).normal(size=tau.shape) * 0.01 * np.sqrt(np.mean(tau**2, axis=0))
    coulomb = 0.5 * (puma.friction.coulomb_pos[1] + puma.friction.coulomb_neg[1])
    tau[:, 1] += 0.3 * coulomb * puma.gear_ratio[1] * np.sign(qd[:rows, 1])
    logfiles.write_csv(path, t, q, tau)


def calibrate(log: Path, out: Path) -> dict:
    run = subprocess.run(["/usr/bin/time", "-v", *children.command("-m", "faultgen.cli"), "calibrate", "--robot",
                          "puma560", "--measured", str(log), "--out", str(out)], env=children.environment(),
                         capture_output=True, text=True)
    if run.returncode != 0:
        raise SystemExit(run.stdout + run.stderr)
    peak = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", run.stderr)[1]) * 1e3
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)", run.stderr)[1]
    seconds = sum(float(x) * 60**i for i, x in enumerate(reversed(wall.split(":"))))
    report = json.loads((out / "report.json").read_text())
    calibrated = json.loads((out / "model" / "parameters.json").read_text())
    return {"seconds": seconds, "peak_gb": peak / 1e9, "report": report, "parameters": calibrated}


def main() -> None:
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp())
    long_log = folder / "long.csv"
    if not long_log.exists():
        make_log(long_log, ROWS)
    logs = [("10^6 rows, averaged down (calibrate.MAX_ROWS)", long_log, ROWS)]
    for rows in WHOLE:
        path = folder / f"whole-{rows}.csv"
        if not path.exists():
            make_log(path, rows)
        logs.append((f"first {rows} rows" + (", whole" if rows <= MAX_ROWS else ", averaged down"), path, rows))
    puma = robots.load("puma560")
    nominal = 0.5 * (puma.friction.coulomb_pos[1] + puma.friction.coulomb_neg[1])
    print("| log | rows | calibrate (s) | peak memory (GB) | axis-2 Coulomb found (truth +30 %) | held-out total nrmse after | effects added |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for name, log, rows in logs:
        out = folder / f"out-{log.stem}"
        if out.exists():
            shutil.rmtree(out)
        found = calibrate(log, out)
        friction = found["parameters"]["friction"]
        change = 0.5 * (friction["coulomb_pos"][1] + friction["coulomb_neg"][1]) / nominal - 1
        added = ", ".join(f"{step['effect']} on {step['axes']}" for step in found["report"].get("steps", []))
        gap = found["report"].get("gap_after", {}).get("total_nrmse", float("nan"))
        print(f"| {name} | {rows} | {found['seconds']:.0f} | {found['peak_gb']:.2f} | {100 * change:+.1f} % | "
              f"{gap:.4f} | {added} |", flush=True)


if __name__ == "__main__":
    main()
