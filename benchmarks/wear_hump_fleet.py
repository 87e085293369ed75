"""A second independent fleet for the wear scale (issue 59): the generator of
:mod:`faultgen.bench.independent` (Pinocchio RNEA on the KR210 URDF, our own motor-side friction,
seasons, parts, unit spread, per-log scatter, noise) with another wear law, a **Stribeck hump that
grows**: on the worn axis, wear ``c`` % (the Coulomb friction's growth) grows the Stribeck hump
``Fs`` by :data:`HUMP_GROWTH` ``c`` % and widens it, its speed ``ws`` by :data:`SPEED_GROWTH`
``c`` % (a worn gear's mixed lubrication reaching higher speeds), where the first law grows ``Fc``
and ``Fs`` alike. Neither is faultgen's law (thesis eq. 6.6 grows Coulomb and static friction
alike, eq. 6.3's Gaussian hump of fixed speed).

The truth, ``truth.csv`` (``unit, stamp, worn_axis, wear_percent``), is the wear as the monitor
states it, the increase of the axis's dry friction in % of the unit's own: here the dry friction
torque (Coulomb plus hump, without the per-log scatter) averaged over the cycle's motion, worn
over healthy, minus one, in %. For the first law this is the generator's own wear (both parts
grow alike); for this one it lies above ``c`` (the hump grows faster) by what the motion's slow
stretches weigh.

    python benchmarks/wear_hump_fleet.py ROOT --seed 4 [--units 12 --worn 8 --days 120]
"""

from __future__ import annotations

import argparse
import csv
import io
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import pinocchio_log

from faultgen.bench import independent as ind
from faultgen.model import robots
from faultgen.operation import jointlog as columns

#: Growth of the Stribeck hump and of its speed per % of Coulomb growth (ours).
HUMP_GROWTH = 3.0
SPEED_GROWTH = 1.0


def dry_friction(w: np.ndarray, coulomb, static, speed) -> np.ndarray:
    """Motor-side dry friction, N m, at motor speed ``w`` rad/s: the first law's Lorentzian hump
    of speed ``speed`` and arctangent sign (:func:`faultgen.bench.independent.motor_friction`)."""
    hump = coulomb + static / (1.0 + (w / speed) ** 2)
    return hump * (2.0 / np.pi) * np.arctan(w / ind.SIGN_SPEED)


def grown(coulomb, static, wear: float) -> tuple:
    """Coulomb level, hump and hump speed of an axis at Coulomb growth ``wear`` %."""
    c = wear / 100.0
    return coulomb * (1 + c), static * (1 + HUMP_GROWTH * c), ind.STRIBECK_SPEED * (1 + SPEED_GROWTH * c)


def true_wear(w_motor: np.ndarray, coulomb: float, static: float, wear: float) -> float:
    """The truth (module docstring): % increase of the mean |dry friction| over the motion."""
    healthy = np.mean(np.abs(dry_friction(w_motor, coulomb, static, ind.STRIBECK_SPEED)))
    return 100.0 * (np.mean(np.abs(dry_friction(w_motor, *grown(coulomb, static, wear)))) / healthy - 1.0)


def write_fleet(root: Path, spec: ind.FleetSpec, robot: Path) -> tuple[Path, Path]:
    """As :func:`faultgen.bench.independent.write_fleet` (same draws from the same seed, same
    layout) with the growing hump; returns (logs, truth)."""
    root, folder = Path(root), Path(robot)
    model = robots.load(folder)
    G, jm, nominal = model.gear_ratio, model.motor_inertia, model.friction
    fc0, fs0, fv0 = (np.asarray(x, dtype=float) for x in (nominal.coulomb_pos, nominal.static, nominal.viscous))
    n = model.n_axes
    t, q, qd, qdd = ind._motion(model, spec.rate)
    logs = root / "logs"
    q_names, _, tau_names = columns.column_names(n)
    header = [columns.T_COLUMN, *q_names, *tau_names, *columns.temperature_columns(n), columns.PAYLOAD_COLUMN]
    days = ind.stamps(spec)
    rows = []
    for unit in ind._units(spec, n):
        folder_of_unit = logs / unit["unit"]
        folder_of_unit.mkdir(parents=True, exist_ok=True)
        rng = np.random.default_rng(unit["seed"])
        a = unit["axis"] - 1
        for d, stamp in enumerate(days, start=1):
            temperature, mass = ind.day_conditions(unit, d, stamp, rng)
            wear = ind.wear_percent(spec, unit["onset"], d) if unit["axis"] else 0.0
            jitter = np.exp(rng.normal(0.0, ind.JITTER, (3, n)))
            fc = fc0 * unit["spread"][0] * jitter[0]
            fs = fs0 * unit["spread"][1] * jitter[1]
            speed = np.full(n, ind.STRIBECK_SPEED)
            truth = 0.0
            if unit["axis"]:
                fc[a], fs[a], speed[a] = grown(fc[a], fs[a], wear)
                truth = true_wear(G[a] * qd[:, a], fc0[a] * unit["spread"][0][a], fs0[a] * unit["spread"][1][a], wear)
            fv = fv0 * unit["spread"][2] * jitter[2] * np.exp(-ind.VISCOUS_PER_K * (temperature - 20.0))
            w = G * qd
            friction = dry_friction(w, fc, fs, speed) + fv * w
            tau = ind._rigid(model, spec.rate, round(mass, 1)) + G**2 * jm * qdd + G * friction
            tau = tau + rng.normal(0.0, 1.0, tau.shape) * ind.NOISE * np.sqrt(np.mean(tau**2, axis=0))
            angles = q + rng.normal(0.0, ind.ANGLE_NOISE, q.shape)
            ind._write_csv(folder_of_unit / f"{stamp}.csv", header, t, angles, tau, np.round(temperature, 2),
                           round(mass, 1))
            rows.append([unit["unit"], stamp, unit["axis"], f"{truth:.4f}"])
    text = io.StringIO(newline="")
    writer = csv.writer(text)
    writer.writerow(ind.TRUTH_COLUMNS)
    writer.writerows(rows)
    truth_path = root / "truth.csv"
    part = truth_path.with_name(truth_path.name + ".part")
    part.write_text(text.getvalue())
    os.replace(part, truth_path)
    return logs, truth_path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", type=Path)
    parser.add_argument("--seed", type=int, default=4)
    parser.add_argument("--units", type=int, default=12)
    parser.add_argument("--worn", type=int, default=8)
    parser.add_argument("--days", type=int, default=120)
    parser.add_argument("--robot", type=Path, default=None, help="The KR210 folder (made in ROOT/kr210 if not given).")
    args = parser.parse_args()
    robot = args.robot or pinocchio_log.add_kr210(args.root / "kr210")
    spec = ind.FleetSpec(units=args.units, worn=args.worn, days=args.days, seed=args.seed)
    logs, truth = write_fleet(args.root, spec, robot)
    print(f"{logs}\n{truth}")


if __name__ == "__main__":
    main()
