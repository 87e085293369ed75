"""Reading a friction test against an independent simulator: the table of docs/analysis.md,
"Reading a friction test".

The log: tests/friction_test_log.py (roboticstoolbox's Newton-Euler on the IRB-6700-like arm, an
exponential Stribeck hump with tanh sign smoothing, dry and viscous levels falling with temperature,
a motion faultgen did not write). Per temperature and torque noise: each axis's dry level and
viscous coefficient read by faultgen (faultgen.calibrate.friction_report) against the truth, with
the verdict (dry within 3 %, viscous within 10 %).

    PYTHONPATH=.:tests python benchmarks/friction_test_independent.py
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import friction_test_log  # noqa: E402
from faultgen.calibrate import friction_report  # noqa: E402
from faultgen.logs import measured  # noqa: E402
from faultgen.model import robots  # noqa: E402


def main() -> None:
    robot = robots.load("irb6700")
    print("| T, degC | torque noise, N m | dry error per axis 1-6, % | viscous error per axis 1-6, % | verdict |")
    print("| --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as folder:
        for noise in (0.5, 5.0):
            for temperature in (20.0, 45.0, 70.0):
                path = friction_test_log.write_log(Path(folder) / "log.csv", temperature, noise=noise)
                fits = friction_report.read(measured.read(path, robot, accelerations=False), robot).fits
                dry, viscous = friction_test_log.truth(temperature)
                e_dry = 100 * (fits["coulomb_Nm"].to_numpy() / dry - 1)
                e_vis = 100 * (fits["viscous_Nms_rad"].to_numpy() / viscous - 1)
                ok = np.all(np.abs(e_dry) < 3) and np.all(np.abs(e_vis) < 10)
                print(f"| {temperature:g} | {noise:g} | {', '.join(f'{e:+.2f}' for e in e_dry)} | "
                      f"{', '.join(f'{e:+.2f}' for e in e_vis)} | "
                      f"{'within 3 % / 10 %' if ok else 'outside 3 % / 10 %'} |")


if __name__ == "__main__":
    main()
