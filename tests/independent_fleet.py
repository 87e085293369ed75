"""A "real" fleet's measured logs made by a simulator that is not faultgen (issue 46, item 5).

The check of ``faultgen monitor`` against data the project did not simulate. What is independent
and what is ours:

- **Rigid-body dynamics: Pinocchio's** recursive Newton-Euler (``pin.rnea``) on the KR210 L150
  URDF of rtb-data (ROS-Industrial's), the robot added to faultgen as a user would (``faultgen
  robots add kr210 --from kr210l150.urdf``, :func:`pinocchio_log.add_kr210`), the payload a box
  at the flange placed by Pinocchio (:func:`pinocchio_log.pinocchio_model`).
- **Motor-side friction: ours, written here, in a form faultgen does not use**: at motor speed
  ``w = G qd`` (rad/s), ``f(w) = (Fc + Fs / (1 + (w / ws)^2)) (2 / pi) atan(w / we) + Fv(T) w``
  (a Lorentzian Stribeck hump and an arctangent sign, where faultgen's eq. 6.3 has an exponential
  hump and its own smoothing), referred to the arm through the gear ratio, ``G f(G qd)``; viscous
  friction falling with the joint temperature, ``Fv(T) = Fv0 exp(-VISCOUS_PER_K (T - 20 C))``
  (an Andrade-like law, ours). The magnitudes of ``Fc``, ``Fs``, ``Fv0`` are the robot folder's
  nominal ones (``drivetrain.toml``), each unit drawing its own (log-normal, :data:`SPREAD`), each
  log scattering about them (:data:`JITTER`); the reflected motor inertia ``G^2 Jm qdd`` with the folder's
  ``Jm``.
- **Conditions: ours**: a seasonal hall temperature (each unit its own mean and swing, on the
  calendar of its stamps: January cold) plus the joints' warm-up; a product change every week
  between two parts per unit (drawn masses; aluminium cubes hanging from the flange, as declared
  in the robot's load data), and from a drawn day between 5/12 and 2/3 of the record a third part
  (a new product) among them; Gaussian torque noise (:data:`NOISE` of each axis's
  torque RMS) and angle noise.
- **Wear: ours**: on a worn unit, one axis's Coulomb and Stribeck friction grow linearly from an
  onset day to :attr:`FleetSpec.final_wear` percent on the last day.
- The motion: the robot folder's generated ``pick_place`` cycle (faultgen's planner; the motion is
  logged, so any would do), one cycle per log.

Output (:func:`write_fleet`), the layout ``faultgen logs import`` reads: ``ROOT/logs/<unit>/<stamp>.csv``
with ``t, q1..qN, tau1..tauN, temperature1..N, payload`` (s, rad, N m arm side, deg C, kg), the
stamps ISO dates, one log a day; and the truth apart, ``ROOT/truth.csv``: ``unit, stamp,
worn_axis, wear_percent`` for every log (worn_axis 0 on a healthy unit). Same seed, identical
files. Used by ``tests/test_monitor.py`` and ``benchmarks/monitor_loop.py``; never by faultgen.
"""

from __future__ import annotations

import csv
import datetime
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import pinocchio as pin

import pinocchio_log
from faultgen.model import robots
from faultgen.operation import programs

#: Unit-to-unit spread of each friction parameter (log-normal sigma) and its day-to-day scatter,
#: drawn per log and parameter and not logged (the state of the lubricant film, the warm-up the
#: log's hour caught): ours. At 1 % the features of a log repeat to about 0.3 %, and the monitor
#: flagged worn units at 3-8 % wear, before the issue's window (docs/analysis.md).
SPREAD = 0.15
JITTER = 0.03
#: Stribeck speed and sign-smoothing speed of the motor-side friction, rad/s at the motor.
STRIBECK_SPEED = 8.0
SIGN_SPEED = 0.5
#: Viscous friction's fall per kelvin of joint temperature (ours: gear oil thins as it warms).
VISCOUS_PER_K = 0.02
#: Torque noise per sample, a share of each axis's torque RMS; angle noise, rad.
NOISE = 0.005
ANGLE_NOISE = 1e-5
#: The parts are aluminium cubes hanging from the flange (their centre half an edge from it, along
#: the z axis of the URDF's ``tool0`` frame, as faultgen's payload condition places a part): the
#: load data a robot's program declares, which the monitor is told. Their masses (5-35 kg) keep
#: faultgen's twin of the motion within its drives' capacity (the KR210's axis 6: 366 N m at the arm,
#: which the twin reached with a 60 kg part, Pinocchio's dynamics needing about 230 N m).
PART_DENSITY = 2700.0
#: Axes that may wear (the KR210's axis 6 motor is rated 3 N m: its friction is at the noise floor).
WEARABLE = (1, 2, 3, 4, 5)


@dataclass(frozen=True)
class FleetSpec:
    """The fleet: ``units`` robots (``worn`` of them wearing), one log a day for ``days`` days from
    ``start``; logs at ``rate`` Hz; a worn unit's wear starts on a day drawn in ``onset`` (1-based)
    and reaches ``final_wear`` % on the last day. Every draw comes from ``seed``."""

    units: int = 12
    worn: int = 8
    days: int = 120
    seed: int = 0
    rate: float = 125.0
    start: str = "2026-01-05"
    onset: tuple[int, int] = (20, 50)
    final_wear: float = 60.0


def unit_names(spec: FleetSpec) -> list[str]:
    return [f"unit{i + 1:02d}" for i in range(spec.units)]


def stamps(spec: FleetSpec) -> list[str]:
    first = datetime.date.fromisoformat(spec.start)
    return [(first + datetime.timedelta(days=d)).isoformat() for d in range(spec.days)]


@lru_cache(maxsize=4)
def _motion(folder: str, rate: float):
    """The pick-and-place cycle planned at 250 Hz (the planner's 4 ms), taken at ``rate`` Hz."""
    step = int(round(250.0 / rate))
    if step < 1 or abs(250.0 / step - rate) > 1e-9:
        raise ValueError(f"rate = {rate!r} Hz; expected 250 Hz divided by a whole number (250, 125, ...)")
    path = programs.load(robots.load(folder), "pick_place").trajectory(pinocchio_log.RATE ** -1)
    q, qd, qdd = (x[::step] for x in (path.q, path.qd, path.qdd))
    return np.arange(len(q)) / rate, q, qd, qdd


@lru_cache(maxsize=64)
def _rigid(folder: str, rate: float, mass: float) -> np.ndarray:
    """Pinocchio's RNEA torque of the motion with a part of ``mass`` kg (:data:`PART_DENSITY`)."""
    _, q, qd, qdd = _motion(folder, rate)
    edge = (mass / PART_DENSITY) ** (1 / 3)
    payload = pinocchio_log.HiddenPayload(mass=mass, com=(0.0, 0.0, edge / 2), size=(edge, edge, edge))
    model = pinocchio_log.pinocchio_model(Path(folder) / "urdf_used.urdf", payload if mass > 0 else None)
    data = model.createData()
    return np.array([pin.rnea(model, data, q[k], qd[k], qdd[k]) for k in range(len(q))])


def motor_friction(w: np.ndarray, coulomb, static, viscous) -> np.ndarray:
    """Motor-side friction torque, N m, at motor speed ``w`` rad/s (module docstring's form)."""
    hump = coulomb + static / (1.0 + (w / STRIBECK_SPEED) ** 2)
    return hump * (2.0 / np.pi) * np.arctan(w / SIGN_SPEED) + viscous * w


def _units(spec: FleetSpec, n_axes: int) -> list[dict]:
    names = unit_names(spec)
    worn = set(np.random.default_rng([spec.seed, 0]).permutation(spec.units)[: spec.worn].tolist())
    out = []
    for i, name in enumerate(names):
        rng = np.random.default_rng([spec.seed, i + 1])
        spread = np.exp(rng.normal(0.0, SPREAD, (3, n_axes)))
        out.append({
            "unit": name, "spread": spread,
            "axis": int(rng.choice(WEARABLE)) if i in worn else 0,
            "onset": int(rng.integers(spec.onset[0], spec.onset[1] + 1)),
            "ambient": float(rng.uniform(17.0, 23.0)), "swing": float(rng.uniform(4.0, 8.0)),
            "rise": rng.uniform(5.0, 15.0, n_axes),
            "parts": (float(rng.uniform(5.0, 15.0)), float(rng.uniform(20.0, 35.0)), float(rng.uniform(10.0, 35.0))),
            "weeks": rng.integers(0, 2, spec.days // 7 + 1),
            "seed": int(rng.integers(2**31)),
            "new_part_day": int(rng.integers(spec.days * 5 // 12, spec.days * 2 // 3 + 1)),
            "new_weeks": rng.integers(0, 3, spec.days // 7 + 1),
        })
    return out


def wear_percent(spec: FleetSpec, onset: int, day: int) -> float:
    """True wear (% increase of Coulomb and Stribeck friction) on day ``day`` (1-based)."""
    if day < onset:
        return 0.0
    return spec.final_wear * (day - onset) / max(spec.days - onset, 1)


def write_fleet(root: Path, spec: FleetSpec = FleetSpec(), robot: Path | None = None) -> tuple[Path, Path, Path]:
    """Write the fleet under ``root``: ``root/kr210`` (the robot folder, unless ``robot`` is given),
    ``root/logs/<unit>/<stamp>.csv`` and ``root/truth.csv``. Returns (robot folder, logs, truth)."""
    root = Path(root)
    folder = Path(robot) if robot is not None else pinocchio_log.add_kr210(root / "kr210")
    model = robots.load(folder)
    G, jm, nominal = model.gear_ratio, model.motor_inertia, model.friction
    fc0, fs0, fv0 = (np.asarray(x, dtype=float) for x in (nominal.coulomb_pos, nominal.static, nominal.viscous))
    n = model.n_axes
    t, q, qd, qdd = _motion(str(folder), spec.rate)
    logs = root / "logs"
    truth_rows = []
    header = ["t", *(f"q{i}" for i in range(1, n + 1)), *(f"tau{i}" for i in range(1, n + 1)),
              *(f"temperature{i}" for i in range(1, n + 1)), "payload"]
    for unit in _units(spec, n):
        rng = np.random.default_rng(unit["seed"])
        (logs / unit["unit"]).mkdir(parents=True, exist_ok=True)
        for d, stamp in enumerate(stamps(spec), start=1):
            date = datetime.date.fromisoformat(stamp)
            season = np.cos(2 * np.pi * (date.timetuple().tm_yday - 200) / 365.25)
            ambient = unit["ambient"] + unit["swing"] * season + rng.normal(0.0, 1.0)
            temperature = ambient + unit["rise"]
            week = (d - 1) // 7
            new_product = d >= unit["new_part_day"]
            mass = unit["parts"][int((unit["new_weeks"] if new_product else unit["weeks"])[week])]
            wear = wear_percent(spec, unit["onset"], d) if unit["axis"] else 0.0
            grow = np.ones(n)
            if unit["axis"]:
                grow[unit["axis"] - 1] += wear / 100.0
            jitter = np.exp(rng.normal(0.0, JITTER, (3, n)))
            fc = fc0 * unit["spread"][0] * grow * jitter[0]
            fs = fs0 * unit["spread"][1] * grow * jitter[1]
            fv = fv0 * unit["spread"][2] * jitter[2] * np.exp(-VISCOUS_PER_K * (temperature - 20.0))
            tau = (_rigid(str(folder), spec.rate, round(mass, 1)) + G**2 * jm * qdd
                   + G * motor_friction(G * qd, fc, fs, fv))
            tau = tau + rng.normal(0.0, 1.0, tau.shape) * NOISE * np.sqrt(np.mean(tau**2, axis=0))
            angles = q + rng.normal(0.0, ANGLE_NOISE, q.shape)
            _write_csv(logs / unit["unit"] / f"{stamp}.csv", header, t, angles, tau,
                       np.round(temperature, 2), round(mass, 1))
            truth_rows.append([unit["unit"], stamp, unit["axis"], f"{wear:.4f}"])
    truth = root / "truth.csv"
    with open(truth, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["unit", "stamp", "worn_axis", "wear_percent"])
        writer.writerows(truth_rows)
    return folder, logs, truth


def _write_csv(path: Path, header, t, q, tau, temperature, mass) -> None:
    rows = len(t)
    table = np.hstack([t[:, None], q, tau, np.broadcast_to(temperature, (rows, len(temperature))),
                       np.full((rows, 1), mass)])
    formats = ["%.4f"] + ["%.6f"] * q.shape[1] + ["%.4f"] * tau.shape[1] + ["%.2f"] * len(temperature) + ["%.1f"]
    np.savetxt(path, table, fmt=formats, delimiter=",", header=",".join(header), comments="")


def read_truth(path: Path) -> dict[str, dict]:
    """``{unit: {"axis": worn axis (0 healthy), "stamps": [...], "wear": ndarray %}}`` from truth.csv."""
    out: dict[str, dict] = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            unit = out.setdefault(row["unit"], {"axis": int(row["worn_axis"]), "stamps": [], "wear": []})
            unit["stamps"].append(row["stamp"])
            unit["wear"].append(float(row["wear_percent"]))
    for unit in out.values():
        unit["wear"] = np.array(unit["wear"])
    return out


def evaluate(truth_path: Path, alarms_path: Path) -> dict[str, dict]:
    """Each unit's outcome from ``truth.csv`` and a monitor's ``alarms.csv``: ``axis`` (worn, 0
    healthy), ``alarm`` (first_alarm stamp or ""), ``day`` of the alarm (1-based) and ``wear`` at it
    (%), ``day10`` / ``day40`` (first day with wear >= 10 / 40 %), ``delay`` (alarm day - day10),
    ``source`` (the alarm's axis or 0), ``in_window`` (10 % <= wear at alarm < 40 %)."""
    truth = read_truth(truth_path)
    out = {}
    with open(alarms_path, newline="") as f:
        alarms = {row["unit"]: row for row in csv.DictReader(f)}
    for unit, t in truth.items():
        row = alarms.get(unit, {})
        stamp = row.get("first_alarm", "")
        day = t["stamps"].index(stamp) + 1 if stamp else None
        wear = t["wear"]
        day10 = int(np.argmax(wear >= 10)) + 1 if np.any(wear >= 10) else None
        day40 = int(np.argmax(wear >= 40)) + 1 if np.any(wear >= 40) else None
        at = float(wear[day - 1]) if day else None
        out[unit] = {"axis": t["axis"], "alarm": stamp, "day": day, "wear": at, "day10": day10, "day40": day40,
                     "delay": (day - day10) if day and day10 else None,
                     "source": int(row["source_axis"]) if row.get("source_axis") else 0,
                     "in_window": at is not None and 10.0 <= at < 40.0}
    return out
