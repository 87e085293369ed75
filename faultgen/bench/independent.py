"""A "real" fleet's measured logs made by a simulator that is not faultgen: the test split of the
sim-to-real track (docs/bench/sim-to-real.md) and the check of ``faultgen monitor`` (issue 46,
tests/test_monitor.py, benchmarks/monitor_loop.py). faultgen's simulation never uses it.

What is independent and what is ours:

- **Rigid-body dynamics: Pinocchio's** recursive Newton-Euler (``pin.rnea``) on the robot folder's
  ``urdf_used.urdf`` (the URDF as faultgen compiled it, read by Pinocchio's own URDF parser): for the
  benchmark, rtb-data's KR210 L150 URDF (ROS-Industrial's ``kuka_kr210_support``), the robot added to
  faultgen as a user would (``faultgen robots add kr210 --from kr210l150.urdf``; the bench adds it
  with the track version's sizing rule, :func:`faultgen.bench.make.add_robots`: its drives, and so
  this simulator's friction and motor inertia, are the folder's); the payload a box at
  the flange (the URDF's ``tool0`` frame) placed by Pinocchio (:func:`pinocchio_model`).
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
files. Each log is written atomically and a unit's logs are drawn in one go, so that a write stopped
part-way resumes at the first unit not complete (:func:`write_fleet`).

Needs Pinocchio (``pin``, the ``bench`` extra: ``pip install 'faultgen-robots[bench]'``).
"""

from __future__ import annotations

import csv
import datetime
import io
import os
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from faultgen.model import robots
from faultgen.operation import jointlog, programs

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
#: The flange frame of the URDF (ROS-Industrial's ``tool0``); faultgen's builder puts its ``flange`` site there.
FLANGE_FRAME = "tool0"
#: The rate the motion is planned at, Hz (the planner's 4 ms, the thesis's sampling period).
PLAN_RATE = 250.0
#: The columns of truth.csv.
TRUTH_COLUMNS = ("unit", "stamp", "worn_axis", "wear_percent")


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

    def __post_init__(self) -> None:
        for name, low in (("units", 1), ("worn", 0), ("days", 2), ("seed", 0)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < low:
                raise ValueError(f"fleet {name} = {value!r}: expected a whole number >= {low}")
        if self.worn > self.units:
            raise ValueError(f"fleet worn = {self.worn}: more than its {self.units} units")
        onset = tuple(self.onset)
        if len(onset) != 2 or not all(isinstance(d, int) for d in onset) or not 1 <= onset[0] <= onset[1] <= self.days:
            raise ValueError(f"fleet onset = {self.onset!r}: expected two whole days, 1 <= first <= last <= {self.days}")
        object.__setattr__(self, "onset", onset)
        if not 0.0 < float(self.final_wear) <= 1000.0:
            raise ValueError(f"fleet final_wear = {self.final_wear!r}: expected a percent in (0, 1000]")
        datetime.date.fromisoformat(self.start)


def pinocchio_module():
    """The ``pinocchio`` module; ImportError naming the extra that installs it."""
    try:
        import pinocchio
    except ImportError:
        raise ImportError("the independent simulator needs Pinocchio: pip install 'faultgen-robots[bench]' "
                          "(or: pip install pin)") from None
    return pinocchio


def pinocchio_model(urdf: Path, mass: float = 0.0, com=(0.0, 0.0, 0.0), size=(0.0, 0.0, 0.0)):
    """Pinocchio's model (``pin.Model``) of ``urdf``, with a solid box of ``mass`` kg, centre ``com``
    (m, flange frame) and edges ``size`` (m) added to the inertia of the body that carries the flange
    frame (:data:`FLANGE_FRAME`)."""
    pin = pinocchio_module()
    model = pin.buildModelFromUrdf(str(urdf))
    if mass > 0:
        frame = model.frames[model.getFrameId(FLANGE_FRAME)]
        box = pin.Inertia.FromBox(mass, *size)
        at_flange = pin.SE3(np.eye(3), np.asarray(com, dtype=float)).act(box)
        joint = frame.parentJoint
        model.inertias[joint] = model.inertias[joint] + frame.placement.act(at_flange)
    return model


def unit_names(spec: FleetSpec) -> list[str]:
    return [f"unit{i + 1:02d}" for i in range(spec.units)]


def stamps(spec: FleetSpec) -> list[str]:
    first = datetime.date.fromisoformat(spec.start)
    return [(first + datetime.timedelta(days=d)).isoformat() for d in range(spec.days)]


@lru_cache(maxsize=4)
def _motion(folder: str, rate: float):
    """The pick-and-place cycle planned at 250 Hz (the planner's 4 ms), taken at ``rate`` Hz."""
    step = int(round(PLAN_RATE / rate))
    if step < 1 or abs(PLAN_RATE / step - rate) > 1e-9:
        raise ValueError(f"rate = {rate!r} Hz; expected 250 Hz divided by a whole number (250, 125, ...)")
    path = programs.load(robots.load(folder), "pick_place").trajectory(PLAN_RATE ** -1)
    q, qd, qdd = (x[::step] for x in (path.q, path.qd, path.qdd))
    return np.arange(len(q)) / rate, q, qd, qdd


@lru_cache(maxsize=64)
def _rigid(folder: str, rate: float, mass: float) -> np.ndarray:
    """Pinocchio's RNEA torque of the motion with a part of ``mass`` kg (:data:`PART_DENSITY`)."""
    pin = pinocchio_module()
    _, q, qd, qdd = _motion(folder, rate)
    edge = (mass / PART_DENSITY) ** (1 / 3)
    model = pinocchio_model(Path(folder) / "urdf_used.urdf", mass, (0.0, 0.0, edge / 2), (edge, edge, edge))
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


def truth_rows(spec: FleetSpec, n_axes: int = 6) -> list[list]:
    """The rows of truth.csv (:data:`TRUTH_COLUMNS`), unit by unit and day by day, without writing a log."""
    rows = []
    for unit in _units(spec, n_axes):
        for d, stamp in enumerate(stamps(spec), start=1):
            wear = wear_percent(spec, unit["onset"], d) if unit["axis"] else 0.0
            rows.append([unit["unit"], stamp, unit["axis"], f"{wear:.4f}"])
    return rows


def write_fleet(root: Path, spec: FleetSpec, robot: Path) -> tuple[Path, Path]:
    """Write the fleet of the robot folder ``robot`` under ``root``: ``root/logs/<unit>/<stamp>.csv``
    and ``root/truth.csv``; returns (logs, truth).

    A unit whose folder holds every log (each written atomically) is kept as it is: a write stopped
    part-way resumes at the first unit not complete and gives the same files. Same ``spec``, identical
    files.

    Raises
    ------
    ValueError
        For a rate that is not 250 Hz divided by a whole number.
    ImportError
        Without Pinocchio.
    """
    root = Path(root)
    folder = Path(robot)
    model = robots.load(folder)
    G, jm, nominal = model.gear_ratio, model.motor_inertia, model.friction
    fc0, fs0, fv0 = (np.asarray(x, dtype=float) for x in (nominal.coulomb_pos, nominal.static, nominal.viscous))
    n = model.n_axes
    t, q, qd, qdd = _motion(str(folder), spec.rate)
    logs = root / "logs"
    q_names, _, tau_names = jointlog.column_names(n)  # t, q1..qN, tau1..tauN, temperature1..N, payload
    header = [jointlog.T_COLUMN, *q_names, *tau_names, *jointlog.temperature_columns(n), jointlog.PAYLOAD_COLUMN]
    days = stamps(spec)
    for unit in _units(spec, n):
        folder_of_unit = logs / unit["unit"]
        if all((folder_of_unit / f"{stamp}.csv").is_file() for stamp in days):
            continue  # drawn in one go from its own seed: complete, and as the same seed draws it
        rng = np.random.default_rng(unit["seed"])
        folder_of_unit.mkdir(parents=True, exist_ok=True)
        for d, stamp in enumerate(days, start=1):
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
            _write_csv(folder_of_unit / f"{stamp}.csv", header, t, angles, tau, np.round(temperature, 2), round(mass, 1))
    truth = root / "truth.csv"
    text = io.StringIO(newline="")
    writer = csv.writer(text)
    writer.writerow(TRUTH_COLUMNS)
    writer.writerows(truth_rows(spec, n))
    content = text.getvalue().encode()
    if not truth.is_file() or truth.read_bytes() != content:  # a resumed write leaves it be
        part = truth.with_name(truth.name + ".part")
        part.write_bytes(content)
        os.replace(part, truth)
    return logs, truth


def _write_csv(path: Path, header, t, q, tau, temperature, mass) -> None:
    rows = len(t)
    table = np.hstack([t[:, None], q, tau, np.broadcast_to(temperature, (rows, len(temperature))),
                       np.full((rows, 1), mass)])
    formats = ["%.4f"] + ["%.6f"] * q.shape[1] + ["%.4f"] * tau.shape[1] + ["%.2f"] * len(temperature) + ["%.1f"]
    part = path.with_name(path.name + ".part")  # no reader lists it (a log ends in .csv)
    np.savetxt(part, table, fmt=formats, delimiter=",", header=",".join(header), comments="")
    os.replace(part, path)


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
