"""Replay the measured log of benchmarks/calibration_example.py on the nominal model: does the
simulated torque along the replayed motion leave the gap `faultgen calibrate` reports before
calibration (docs/simulation.md, "Your own programs")?

The log (``OUT/measured.csv`` of ``calibration_example.py``: a PUMA 560 with a hidden 2.2 kg payload
and extra Coulomb friction on axis 5) is replayed as a task (``--task measured.csv``) on the nominal
``puma560``, one cycle, no load disturbance; the arm-side motor torque (tau_m x G) at the log's times
is compared with the log's torque on the calibration's held-out samples (``calibrate.search.Split``,
``search.gap``), and set beside ``report.json``'s ``gap_before`` (the nominal model's inverse
dynamics along the same motion).

    python benchmarks/calibration_example.py --out calib_example
    python benchmarks/replay_calibration_gap.py calib_example
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from faultgen.calibrate import search
from faultgen.logs import measured
from faultgen.model import robots
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim
from faultgen.simulation.resolve import resolve
from faultgen.simulation.spec import RunSpec


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", type=Path, help="OUT of calibration_example.py")
    args = parser.parse_args()
    log = args.folder / "measured.csv"
    report = json.loads((args.folder / "calibration" / "report.json").read_text())
    robot = robots.load("puma560")
    data = measured.read(log, robot)
    config = resolve(RunSpec(robot="puma560", task=str(log), cycles=1, seed=0, friction="stribeck",
                             noise=sensors.NoiseConfig(disturbance=0.0, encoder=0.0)), resolved=robot).config
    result = sim.simulate(config, progress=False)
    t_log = data.t - data.t[0]  # the run starts at the log's first sample (faultgen.operation.replay)
    inside = t_log <= result.t[-1]
    tau_sim = np.column_stack([np.interp(t_log, result.t, result.tau_m[0, :, k] * robot.gear_ratio[k])
                               for k in range(6)])
    split = search.Split.of(data.t, data.qd)
    mask = split.held_out & inside[:, None]
    replayed = search.gap(data.tau, tau_sim, mask)
    before = report["gap_before"]
    print(f"log {log}: {len(data.t)} samples, {data.t[-1] - data.t[0]:.2f} s; "
          f"{int(inside.sum())} samples inside the replayed cycle")
    print(f"{'':24}" + "".join(f"{'axis ' + str(k + 1):>10}" for k in range(6)) + f"{'total':>10}")
    print(f"{'calibrate gap_before':24}" + "".join(f"{v:10.4f}" for v in before["nrmse"])
          + f"{before['total_nrmse']:10.4f}")
    print(f"{'replayed on nominal':24}" + "".join(f"{v:10.4f}" for v in replayed["nrmse"])
          + f"{replayed['total_nrmse']:10.4f}")
    print(f"{'rmse calibrate, N m':24}" + "".join(f"{v:10.3f}" for v in before["rmse_Nm"]))
    print(f"{'rmse replayed, N m':24}" + "".join(f"{v:10.3f}" for v in replayed["rmse_Nm"]))


if __name__ == "__main__":
    main()
