"""A second independent fleet for the wear scale (issues 59 and 75): the generator of
:mod:`faultgen.bench.independent` (Pinocchio RNEA on the KR210 URDF, seasons, parts, unit spread,
per-log scatter, noise, the same draws from the same seed) with a friction law and a wear law of
its own, unlike faultgen's and unlike the first fleet's.

**Friction** (``law="exponential"``, the default; issue 75), motor side at motor speed ``w`` rad/s
and joint temperature ``T`` deg C::

    f(w) = (Fc (1 - DRY_PER_K (T - 20)) + Fs exp(-|w| / ws)) tanh(w / TANH_SPEED)
           + Fv0 w / (1 + VISCOUS_PER_K (T - 20))

an exponential Stribeck hump (exponent 1; faultgen's eq. 6.3 is Gaussian, the first fleet's
Lorentzian), a tanh sign (the first fleet's is an arctangent), a dry level that falls with the
temperature (the first fleet's does not) and a viscous coefficient falling as ``1 / (1 + b dT)``
(the first fleet's as ``exp(-b dT)``). **Wear** ``c`` % (the Coulomb level's growth) on the worn
axis grows the Stribeck hump ``Fs`` by :data:`HUMP_GROWTH` ``c`` %, widens it (``ws`` by
:data:`SPEED_GROWTH` ``c`` %: a worn gear's mixed lubrication reaching higher speeds) and grows the
viscous coefficient by :data:`VISCOUS_GROWTH` ``c`` % (the first fleet's wear grows the dry friction
only: there wear grows dry friction more than viscous; here the Coulomb level and the viscous
coefficient alike). Neither is faultgen's law (thesis eq. 6.6 grows Coulomb and static friction
alike, eq. 6.3's Gaussian hump of fixed speed).

``law="lorentzian"``: issue 59's second fleet (the figures of docs/analysis.md made before issue
75): the first fleet's friction law (:func:`faultgen.bench.independent.motor_friction`: Lorentzian
hump, arctangent sign, viscous ``exp(-0.02 dT)``, dry level not moving with temperature) with the
growing, widening hump and no viscous growth; its files are those of that time.

The truth, ``truth.csv`` (``unit, stamp, worn_axis, wear_percent``), is the wear as the monitor
states it, the increase of the axis's dry friction in % of the unit's own: here the dry friction
torque (Coulomb plus hump, at 20 deg C, without the per-log scatter) averaged over the cycle's
motion, worn over healthy, minus one, in %; it lies above ``c`` (the hump grows faster) by what the
motion's slow stretches weigh.

**Friction tests** (``spec.friction_test_every``, as the first fleet's:
:mod:`faultgen.bench.independent`): ``logs/<unit>/friction-test/<stamp>.csv``, faultgen's test
motion driven through this law (the day's levels, wear, scatter, the test's drawn temperature) and
``truth_tests.csv``: per test and axis the Coulomb level ``Fc (1 - DRY_PER_K (T - 20))`` and the
viscous coefficient, arm side (``G`` and ``G^2`` times the motor side's), at the test's temperature.

    python benchmarks/wear_hump_fleet.py ROOT --seed 4 [--units 12 --worn 8 --days 120]
        [--friction-test-every 14] [--law exponential|lorentzian]
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

#: Growth of the Stribeck hump, of its speed and (law "exponential") of the viscous coefficient per %
#: of Coulomb growth (ours).
HUMP_GROWTH = 3.0
SPEED_GROWTH = 1.0
VISCOUS_GROWTH = 1.0
#: Law "exponential": the dry level's fall per kelvin, the viscous coefficient's ``b`` per kelvin, and
#: the tanh sign's speed, rad/s at the motor (ours).
DRY_PER_K = 0.004
VISCOUS_PER_K = 0.03
TANH_SPEED = 0.3
#: The friction laws of this fleet (module docstring); the first is the default.
LAWS = ("exponential", "lorentzian")


def dry_friction(w: np.ndarray, coulomb, static, speed, law: str = "lorentzian") -> np.ndarray:
    """Motor-side dry friction, N m, at motor speed ``w`` rad/s: law ``"lorentzian"`` the first law's
    Lorentzian hump of speed ``speed`` and arctangent sign
    (:func:`faultgen.bench.independent.motor_friction`); ``"exponential"`` an exponential hump and a
    tanh sign (module docstring; ``coulomb`` already at the temperature)."""
    if law == "exponential":
        return (coulomb + static * np.exp(-np.abs(w) / speed)) * np.tanh(w / TANH_SPEED)
    hump = coulomb + static / (1.0 + (w / speed) ** 2)
    return hump * (2.0 / np.pi) * np.arctan(w / ind.SIGN_SPEED)


def grown(coulomb, static, wear: float) -> tuple:
    """Coulomb level, hump and hump speed of an axis at Coulomb growth ``wear`` %."""
    c = wear / 100.0
    return coulomb * (1 + c), static * (1 + HUMP_GROWTH * c), ind.STRIBECK_SPEED * (1 + SPEED_GROWTH * c)


def true_wear(w_motor: np.ndarray, coulomb: float, static: float, wear: float, law: str = "lorentzian") -> float:
    """The truth (module docstring): % increase of the mean |dry friction| over the motion."""
    healthy = np.mean(np.abs(dry_friction(w_motor, coulomb, static, ind.STRIBECK_SPEED, law)))
    return 100.0 * (np.mean(np.abs(dry_friction(w_motor, *grown(coulomb, static, wear), law))) / healthy - 1.0)


def levels(law: str, nominal, unit: dict, wear: float, jitter: np.ndarray, temperature) -> tuple:
    """The motor-side levels of a unit's axes (each (N,)): Coulomb (law "exponential": at
    ``temperature`` deg C), hump, hump speed and viscous coefficient (at ``temperature``), the
    ``nominal`` ones times the unit's spread and the log's ``jitter`` (3, N), grown by ``wear`` % on
    the worn axis (module docstring)."""
    fc0, fs0, fv0 = nominal
    fc = fc0 * unit["spread"][0] * jitter[0]
    fs = fs0 * unit["spread"][1] * jitter[1]
    speed = np.full(len(fc0), ind.STRIBECK_SPEED)
    a = unit["axis"] - 1
    if unit["axis"]:
        fc[a], fs[a], speed[a] = grown(fc[a], fs[a], wear)
    if law == "lorentzian":  # issue 59's: as written then, so that its files stay the same
        return fc, fs, speed, fv0 * unit["spread"][2] * jitter[2] * np.exp(-ind.VISCOUS_PER_K * (temperature - 20.0))
    grow = np.ones(len(fc0))
    if unit["axis"]:
        grow[a] += VISCOUS_GROWTH * wear / 100.0
    dt = np.asarray(temperature, dtype=float) - 20.0
    return fc * (1.0 - DRY_PER_K * dt), fs, speed, fv0 * unit["spread"][2] * jitter[2] * grow / (1.0 + VISCOUS_PER_K * dt)


def write_fleet(root: Path, spec: ind.FleetSpec, robot: Path, law: str = LAWS[0]) -> tuple[Path, Path]:
    """As :func:`faultgen.bench.independent.write_fleet` (same draws from the same seed, same
    layout, friction tests included; no gearbox or program changes) with this fleet's ``law``
    (:data:`LAWS`); returns (logs, truth). ValueError for another law."""
    if law not in LAWS:
        raise ValueError(f"law = {law!r}; expected one of {', '.join(LAWS)}")
    root, folder = Path(root), Path(robot)
    model = robots.load(folder)
    G, jm, nominal = model.gear_ratio, model.motor_inertia, model.friction
    nominal = tuple(np.asarray(x, dtype=float) for x in (nominal.coulomb_pos, nominal.static, nominal.viscous))
    n = model.n_axes
    t, q, qd, qdd = ind._motion(model, spec.rate)
    logs = root / "logs"
    header = ind.log_header(n)
    days = ind.stamps(spec)
    tested = set(ind.friction_test_days(spec))
    rows, test_rows = [], []
    for unit in ind._units(spec, n):
        folder_of_unit = logs / unit["unit"]
        folder_of_unit.mkdir(parents=True, exist_ok=True)
        rng = np.random.default_rng(unit["seed"])
        a = unit["axis"] - 1
        for d, stamp in enumerate(days, start=1):
            temperature, mass = ind.day_conditions(unit, d, stamp, rng)
            wear = ind.wear_percent(spec, unit["onset"], d) if unit["axis"] else 0.0
            jitter = np.exp(rng.normal(0.0, ind.JITTER, (3, n)))
            fc, fs, speed, fv = levels(law, nominal, unit, wear, jitter, temperature)
            truth = 0.0
            if unit["axis"]:
                truth = true_wear(G[a] * qd[:, a], nominal[0][a] * unit["spread"][0][a],
                                  nominal[1][a] * unit["spread"][1][a], wear, law)
            w = G * qd
            friction = dry_friction(w, fc, fs, speed, law) + fv * w
            tau = ind._rigid(model, spec.rate, round(mass, 1)) + G**2 * jm * qdd + G * friction
            tau = tau + rng.normal(0.0, 1.0, tau.shape) * ind.NOISE * np.sqrt(np.mean(tau**2, axis=0))
            angles = q + rng.normal(0.0, ind.ANGLE_NOISE, q.shape)
            ind._write_csv(folder_of_unit / f"{stamp}.csv", header, t, angles, tau, np.round(temperature, 2),
                           round(mass, 1))
            rows.append([unit["unit"], stamp, unit["axis"], f"{truth:.4f}"])
            if d in tested:
                warmth, test_jitter, test_rng = ind.friction_test_draws(unit, d, temperature, n, spec.test_jitter)
                c, s, v, b = levels(law, nominal, unit, wear, test_jitter, warmth)
                ind.write_friction_test(folder_of_unit / ind.TEST_FOLDER / f"{stamp}.csv", header, model, spec.rate,
                                        lambda w, c=c, s=s, v=v, b=b: dry_friction(w, c, s, v, law) + b * w,
                                        warmth, test_rng)
                test_rows += ind.friction_test_truth(unit["unit"], stamp, G, c, b, warmth)
    text = io.StringIO(newline="")
    writer = csv.writer(text)
    writer.writerow(ind.TRUTH_COLUMNS)
    writer.writerows(rows)
    truth_path = root / "truth.csv"
    part = truth_path.with_name(truth_path.name + ".part")
    part.write_text(text.getvalue())
    os.replace(part, truth_path)
    if tested:
        ind._write_table(root / "truth_tests.csv", ind.TEST_TRUTH_COLUMNS, test_rows)
    return logs, truth_path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", type=Path)
    parser.add_argument("--seed", type=int, default=4)
    parser.add_argument("--units", type=int, default=12)
    parser.add_argument("--worn", type=int, default=8)
    parser.add_argument("--days", type=int, default=120)
    parser.add_argument("--friction-test-every", type=int, default=0, metavar="DAYS",
                        help="A friction test every DAYS days per unit (0: none).")
    parser.add_argument("--test-scatter", type=float, default=ind.JITTER, metavar="SIGMA",
                        help="The friction tests' day-to-day friction scatter, log-normal sigma (default: a log's, "
                             f"{ind.JITTER:g}).")
    parser.add_argument("--law", choices=LAWS, default=LAWS[0])
    parser.add_argument("--robot", type=Path, default=None, help="The KR210 folder (made in ROOT/kr210 if not given).")
    args = parser.parse_args()
    robot = args.robot or pinocchio_log.add_kr210(args.root / "kr210")
    spec = ind.FleetSpec(units=args.units, worn=args.worn, days=args.days, seed=args.seed,
                         friction_test_every=args.friction_test_every, test_jitter=args.test_scatter)
    logs, truth = write_fleet(args.root, spec, robot, args.law)
    print(f"{logs}\n{truth}")


if __name__ == "__main__":
    main()
