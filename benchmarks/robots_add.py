"""`faultgen robots add` on rtb-data's URDFs and the UR5 DH table: what the sizing rules give, how long
adding takes (tasks generated and checked included), and the largest inverse-dynamics error against
Pinocchio (URDF) per robot.

    python benchmarks/robots_add.py [--out DIR]
"""

from __future__ import annotations

import argparse
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import rtbdata

from faultgen.model import builder, folder
from faultgen.operation import taskgen

XACRO = Path(rtbdata.__file__).parent / "xacro"
ROOT = Path(__file__).resolve().parents[1]
SOURCES = {
    "kr210": XACRO / "kuka_description/kuka_kr210/urdf/kr210l150.urdf",
    "irb140": XACRO / "abb_irb140_description/urdf/irb140.urdf",
    "iiwa14": XACRO / "kuka_description/kuka_lbr_iiwa/urdf/lbr_iiwa_14_r820.urdf",
    "ur5": ROOT / "docs/examples/ur5_dh.toml",
}
#: The ROS packages their meshes name, as `--package NAME=DIR` gives them (the source reads only
#: its own folder and these).
PACKAGES = {
    "kuka_kr210_support": XACRO / "kuka_description/kuka_kr210",
    "abb_irb140_support": XACRO / "abb_irb140_description",
    "kuka_lbr_iiwa_support": XACRO / "kuka_description/kuka_lbr_iiwa",
}


def pinocchio_error(added) -> float:
    if not added.arm.urdf:
        return float("nan")
    robot = added.robot
    model = pin.buildModelFromXML(added.arm.urdf)
    data = model.createData()
    idx = [model.joints[model.getJointId(j.name)].idx_q for j in added.arm.joints]
    rng = np.random.default_rng(0)
    q = rng.uniform(*robot.joint_range.T, (50, robot.n_axes))
    qd, qdd = rng.normal(0, 1, q.shape), rng.normal(0, 2, q.shape)
    ref = np.empty_like(q)
    reflected = robot.gear_ratio**2 * (robot.motor_inertia + builder.ROTOR_INERTIA)
    for k in range(len(q)):
        qq, vv, aa = np.zeros(model.nq), np.zeros(model.nv), np.zeros(model.nv)
        qq[idx], vv[idx], aa[idx] = q[k], qd[k], qdd[k]
        ref[k] = pin.rnea(model, data, qq, vv, aa)[idx] + reflected * qdd[k]
    ours = robot.inverse_dynamics(q, qd, qdd, friction=False)
    return float(np.max(np.sqrt(np.mean((ours - ref) ** 2, 0)) / np.sqrt(np.mean(ref**2, 0))))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path)
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp())
    warnings.simplefilter("ignore")
    for name, source in SOURCES.items():
        start = time.perf_counter()
        added = folder.add(name, source, out / name, tasks=taskgen.generate, packages=PACKAGES)
        seconds = time.perf_counter() - start
        r = added.robot
        fmt = lambda a: "[" + ", ".join(f"{v:.3g}" for v in a) + "]"  # noqa: E731
        print(f"{name}: {r.n_axes} axes, payload {added.payload:.3g} kg, added in {seconds:.1f} s; "
              f"G {fmt(r.gear_ratio)}; capacity G*T [N m] {fmt(r.gear_ratio * r.motor_torque_limit)}; "
              f"Jm [kg m^2] {fmt(r.motor_inertia)}; Pinocchio error {pinocchio_error(added):.1e}")


if __name__ == "__main__":
    main()
