"""faultgen's own parameter fit beside ``mujoco.sysid`` on the same logs (issue 39, item 4).

For each log of the independent-simulator set (tests/independent_set.py) named here, the
calibration runs as usual; then the continuous parameters of the effects it named are fitted again
by ``mujoco.sysid`` on the calibrated model (:func:`faultgen.calibrate.refit.refit`: its
least-squares solver and its Jacobian intervals, on the same residual), starting from faultgen's
values. Prints a markdown table: per parameter the truth where the log's form has the same
parameter, faultgen's estimate and 95 % half width (1.96 jackknife standard errors), sysid's, the
held-out total nrmse with each, and the times (faultgen: the whole calibration, which also chooses
the effects; sysid: the refit alone). The calibration runs without its own sysid refinement of a
Stribeck hump (``use_sysid=False``), so faultgen's column is faultgen's fit.

    python benchmarks/calibration_sysid.py                    # the six default logs, about 10 min
    python benchmarks/calibration_sysid.py --cases puma560-03 --csv sysid.csv
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import independent_set  # tests/independent_set.py
from benchmarks_common import chosen_cases, table_options  # sibling module

from faultgen.calibrate import MAX_ROWS, calibrate, decimate
from faultgen.calibrate.refit import refit
from faultgen.logs import measured as measured_io
from faultgen.model import robots

DEFAULT = ["puma560-03-payload", "puma560-06-coulomb_per_direction", "puma560-09-load_gravity",
           "irb6700-05-coulomb_per_direction", "irb6700-07-stribeck_exponent", "irb6700-11-warm_up"]


def _truth(hidden: independent_set.Hidden, effect: str, name: str, axis: int | None) -> float | None:
    """The hidden value of a parameter where the log's form has it with the same meaning."""
    for form, p in hidden.forms.items():
        if form == "payload" and effect == "payload":
            com = p["com"]
            return {"mass": p["mass"], "com_x": com[0], "com_y": com[1], "com_z": com[2]}.get(name)
        if form in ("load_gravity", "load_total") and effect == "load_dependent_friction" and name == "coefficient":
            if axis is not None and axis - 1 in p["axes"]:
                return float(p["coefficient"][p["axes"].index(axis - 1)])
    return None


def run(name: str) -> list[dict]:
    case = next(c for c in independent_set.CASES if c.name == name)
    with tempfile.TemporaryDirectory() as folder:
        path, hidden = independent_set.make(case, folder)
        started = time.perf_counter()
        # both fits on the same rows: a long log averaged down as calibrate does (MAX_ROWS)
        nominal = robots.load(case.robot)  # resolved once, for the calibration and the refit
        data = measured_io.read(path, nominal)
        if len(data) > MAX_ROWS:
            data = decimate(data, MAX_ROWS)
        # faultgen's own fit on every effect: calibrate's sysid refinement of a Stribeck hump off
        result = calibrate(nominal, data, Path(folder) / "out", use_sysid=False)
        own = time.perf_counter() - started
        refits, elapsed, gap = refit(result, data, nominal)
    rows = []
    for r in refits:
        truth = _truth(hidden, r.effect, r.name, r.axis)
        rows.append({"log": name, "effect": r.effect, "axis": r.axis if r.axis is not None else "robot",
                     "parameter": r.name, "truth": truth, "faultgen": r.faultgen, "faultgen_95": r.faultgen_half_width,
                     "sysid": r.sysid, "sysid_95": r.sysid_half_width,
                     "gap_faultgen": result.gap_after["total_nrmse"], "gap_sysid": gap,
                     "faultgen_s": own, "sysid_s": elapsed})
    if not refits:
        rows.append({"log": name, "effect": "-", "axis": "-", "parameter": "-", "truth": None,
                     "faultgen": np.nan, "faultgen_95": np.nan, "sysid": np.nan, "sysid_95": np.nan,
                     "gap_faultgen": result.gap_after["total_nrmse"], "gap_sysid": np.nan,
                     "faultgen_s": own, "sysid_s": elapsed})
    return rows


def table(rows: pd.DataFrame) -> str:
    lines = ["| log | effect | axis | parameter | truth | faultgen ± 95 % | sysid ± 95 % | held-out gap faultgen / sysid "
             "| time faultgen (whole calibration) / sysid (refit), s |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows.itertuples():
        truth = "-" if pd.isna(r.truth) else f"{r.truth:.4g}"
        lines.append(f"| {r.log} | {r.effect} | {r.axis} | {r.parameter} | {truth} | {r.faultgen:.4g} ± "
                     f"{r.faultgen_95:.2g} | {r.sysid:.4g} ± {r.sysid_95:.2g} | {r.gap_faultgen:.4f} / "
                     f"{r.gap_sysid:.4f} | {r.faultgen_s:.0f} / {r.sysid_s:.0f} |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cases", nargs="*", default=DEFAULT, help="logs (names or parts of names) to run")
    table_options(parser)
    args = parser.parse_args()
    if args.from_csv:
        print(table(pd.read_csv(args.from_csv)))
        return
    names = [c.name for c in chosen_cases(parser, independent_set.CASES, args.cases)]
    done = []
    for name in names:  # the CSV grows log by log: a run cut short keeps what finished
        done += run(name)
        if args.csv:
            pd.DataFrame(done).to_csv(args.csv, index=False)
    print(table(pd.DataFrame(done)))


if __name__ == "__main__":
    main()
