"""Check that the built-in robots rebuilt by faultgen.model.builder are today's models, bit for bit.

Compares every array field of the compiled MjModel of ``robots/NAME/NAME.xml`` with that of the
hand-written MJCF at a git revision (default 4a0c437, the last before the builder), then the
inverse dynamics along a random trajectory and 2000 steps of simulation under a fixed control.

    python benchmarks/rebuild_identical.py [--rev 4a0c437]
"""

from __future__ import annotations

import argparse
import subprocess
import tempfile
from pathlib import Path

import mujoco
import numpy as np

from faultgen.model import robots

ROOT = Path(__file__).resolve().parents[1]


def fields(model: mujoco.MjModel) -> dict[str, np.ndarray]:
    return {
        k: getattr(model, k)
        for k in dir(model)
        if not k.startswith("_") and isinstance(getattr(model, k), np.ndarray)
    }


def simulate(model: mujoco.MjModel, steps: int = 2000) -> np.ndarray:
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    rng = np.random.default_rng(0)
    data.ctrl[:] = 0.3 * rng.uniform(-1, 1, model.nu) * model.actuator_ctrlrange[:, 1]
    for _ in range(steps):
        mujoco.mj_step(model, data)
    return np.concatenate([data.qpos, data.qvel])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rev", default="4a0c437")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        for name in ("puma560", "irb6700"):
            old_text = subprocess.run(
                ["git", "-C", str(ROOT), "show", f"{args.rev}:robots/{name}/{name}.xml"],
                check=True,
                capture_output=True,
                text=True,
            ).stdout
            folder = Path(tmp) / name
            folder.mkdir()
            (folder / f"{name}.xml").write_text(old_text)
            old = robots.load(folder / f"{name}.xml")
            new = robots.load(name)
            f_old, f_new = fields(old.model), fields(new.model)
            differ = [
                k for k in f_old if f_old[k].shape != f_new[k].shape or not np.array_equal(f_old[k], f_new[k])
            ]
            rng = np.random.default_rng(1)
            low, high = new.joint_range.T
            q = rng.uniform(low, high, (200, new.n_axes))
            qd, qdd = rng.normal(0, 1, q.shape), rng.normal(0, 3, q.shape)
            tau_equal = np.array_equal(old.inverse_dynamics(q, qd, qdd), new.inverse_dynamics(q, qd, qdd))
            sim_equal = np.array_equal(simulate(old.model), simulate(new.model))
            print(
                f"{name}: {len(f_old)} model arrays, differing: {differ or 'none'}; inverse dynamics "
                f"identical: {tau_equal}; 2000 simulation steps identical: {sim_equal}"
            )


if __name__ == "__main__":
    main()
