"""The twin of a unit: its model (calibrated or nominal) replaying the unit's own logged motion,
healthy under the logged conditions and with each axis in turn worn.

What the monitor asks of it (:class:`Twin`):

- :meth:`Twin.expected`: the features a healthy unit shows at a joint temperature and payload:
  the replayed cycle simulated at :data:`REFERENCE_TEMPERATURE` (the monitor's default, where the
  unit's own learned slope carries the temperature; faultgen's temperature law leaves the model's
  friction as it is there, so that cycle is the one at the model's own friction, simulated and
  cached once under that key), or, asked for another temperature
  (``--twin-temperature``), at :data:`TEMPERATURES` (a quadratic through the three, so any
  temperature in between and a little beyond), for every payload the unit's logs declare (an
  aluminium cube of that mass hanging from the flange: the log gives the mass only);
- :attr:`Twin.signatures`: how each axis's wear moves the features, per percent of the model's own
  dry friction: one cycle with the axis's Coulomb and static friction at :data:`WEAR` % above the
  model's (thesis eq. 6.6's exp4 schedule at its final value), minus the healthy cycle, both at the
  model's own friction (no temperature law on top: the features' change per % grows with the rest
  of the friction) without a part.

The replayed motion is one cycle of the program log (its first, or with a ``cycle`` column its first
whole one as the motion places it, when the log holds several or is cut anywhere:
:func:`faultgen.monitor.programs.first_cycle`; the cache key then says which), its angles
through a cubic Savitzky-Golay filter of :data:`REFERENCE_WINDOW`
(:func:`faultgen.derivatives.smoothed`): a drive tracking an encoder's noise as its reference
saturates where the real one did not. A replay of measured arm angles still asks more
of the drives than the run that logged them (it tracks the elastic arm's own lag and ripple as its
reference): near a drive's limit the twin refuses a part the robot carried, and that unit's logs
with the part are skipped and named.

Every simulated cycle goes through the same feature code as a measured log
(:func:`faultgen.monitor.logs.features_of` on the simulated angles and arm-side torque, the
velocity estimated from the angles as for a log without ``qd``), without sensor noise (the twin
gives the expectation). Cycles are cached on disk by what determines them (model file, program
file, temperature, payload, worn axis), each file holding its key beside the features
(:func:`faultgen.monitor.state.read_cycle` refuses one whose key differs): units that share a model
and a program share them. The stepper (:mod:`faultgen.simulation.backends`) is not in the
key: every stepper gives the same cycle to float tolerance. The signature cycles a twin has not
cached yet (healthy at the model's own friction and one per worn axis) are stepped together as the
runs of one batch, which costs little more than one of them (the static friction's update before
each step is Python, the same for one run or seven): the same bits as one by one
(tests/test_twin_batch.py).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from faultgen import derivatives
from faultgen.logs import measured
from faultgen.effects import temperature as temperature_law
from faultgen.model import robots
from faultgen.monitor import programs as unit_programs
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import state as stored
from faultgen.operation import conditions, faults, tasks, wear
from faultgen.simulation import backends, sensors
from faultgen.simulation import stepping as sim

#: Joint temperatures the healthy cycle is simulated at, deg C.
TEMPERATURES = (0.0, 20.0, 40.0)
#: Reference joint temperature of the healthy expectation, deg C (the unit's own learned slope
#: carries the temperature from there): the one at which faultgen's temperature law leaves the
#: model's friction as it is (:data:`faultgen.effects.temperature.REFERENCE_TEMPERATURE`), a
#: calibrated model's being the unit's at its first log. It was 20 deg C, where the law puts 1.30
#: times the dry and 2.86 times the viscous friction on the model: a unit of the shipped irb6700
#: fleet whose calibration fitted every axis's own friction (:data:`faultgen.monitor.unit.OWN_FRICTION`)
#: saturated axis 2's drive there with its 35 kg part (peak 1.00 of the limit, 0.84 in the log
#: at its 28.7 deg C) and was degraded; at 35 deg C it is monitored (tests/test_monitor_shipped.py).
REFERENCE_TEMPERATURE = temperature_law.REFERENCE_TEMPERATURE
#: Wear of the signature cycles, % increase of Coulomb and static friction.
WEAR = 40.0
#: Friction model of the twin's simulation.
FRICTION = "stribeck"
#: Window of the cubic Savitzky-Golay filter the program log's angles pass before the twin replays
#: them, s. An irb6700 pick and place with a 35 kg part logged at faultgen's default encoder noise
#: (1e-4 rad) and replayed with that part: axis 2's peak motor torque 1.0 of its limit (saturated)
#: as logged, 1.0 through the derivative filter's 0.05 s, 0.942 through 0.1 s, 0.934 replaying the
#: noise-free log; the original run: 0.861. The filtered angles moved by at most 0.37 mrad.
REFERENCE_WINDOW = 0.1
#: Density of the declared part, kg/m^3 (aluminium), which sets its edge from its mass.
PART_DENSITY = 2700.0


def part_edge(mass: float) -> float:
    """Edge of an aluminium cube of ``mass`` kg, m."""
    return float((mass / PART_DENSITY) ** (1 / 3))


def setup(temperature: float | None, payload: float, worn_axis: int = 0) -> tuple[conditions.Conditions, wear.WearPlan]:
    """The conditions and the wear plan of one twin cycle, built as typed objects: the joints held
    at ``temperature`` deg C (None: the model's nominal friction, no thermal condition), a part of
    ``payload`` kg (an aluminium cube, :func:`part_edge`, its edge rounded to 0.1 mm; 0: none), and
    ``worn_axis`` (1..N; 0: none) at :data:`WEAR` % by thesis eq. 6.6's exp4 schedule reached at
    the one cycle."""
    thermal = (None if temperature is None
               else conditions.Temperature(ambient=temperature, seasonal=0.0, daily=0.0, rise=0.0))
    part = conditions.Payloads((payload,), (round(part_edge(payload), 4),)) if payload > 0 else None
    plan = wear.WearPlan({worn_axis: wear.Schedule("exp4", WEAR / 100.0, 1)}) if worn_axis else wear.WearPlan({})
    return conditions.Conditions(thermal=thermal, payloads=part), plan


def base_cycles(n_axes: int) -> list[tuple[float, float, int]]:
    """The (temperature deg C or NaN, payload kg, worn axis) of the cycles every :class:`Twin` of a
    robot of ``n_axes`` axes simulates when it is made: the healthy cycle at the model's own friction
    (also the healthy expectation without a part at :data:`REFERENCE_TEMPERATURE`) and one per worn
    axis (its :attr:`Twin.signatures`)."""
    return [(float("nan"), 0.0, axis) for axis in range(n_axes + 1)]


class Twin:
    """A unit's twin (module docstring): ``model`` the robot it simulates (a
    :class:`~faultgen.model.robot.Robot`: the nominal, a given or a calibrated one, as the monitor
    resolved or wrote it; :func:`faultgen.monitor.unit.model_of`), ``program`` the
    log whose motion is replayed, as the run parsed it (:class:`faultgen.monitor.logs.Parsed`: its
    SHA-256 keys the cache, its angles are replayed; a log that could not be read raises its
    error) or a path read here by ``reader`` (:data:`faultgen.monitor.logs.Reader`; the measured
    format's by default), ``cache`` the folder of simulated cycles (created if needed) inside
    ``root`` (default: the folder holding ``cache``), out of which no cached file may lead (read or
    written), ``stepper`` what steps its cycles (a :class:`faultgen.simulation.backends.Stepper`;
    the default ``BatchStepper()``). The replayed motion stays in memory (:meth:`_smoothed_program`).

    Raises
    ------
    ValueError
        A ``stepper`` that is not a Stepper object, the program cannot be read (file and row
        named), or a base cycle cannot be simulated.
    TypeError
        ``model`` is not a Robot (a name or path: resolve it once with
        :func:`faultgen.model.robots.load`).
    """

    def __init__(self, model: robots.Robot, program: Path | fleet_logs.Parsed, cache: Path,
                 root: Path | None = None,
                 reader: fleet_logs.Reader | None = None, cycles: bool = True,
                 stepper: backends.Stepper = backends.DEFAULT_STEPPER):
        self.stepper = backends.checked(stepper)
        self.robot = robots.require(model, "monitor.twin.Twin")
        self.model = str(self.robot.path)
        self.cache = Path(cache)
        self.root = self.cache.parent if root is None else Path(root)
        self.folder = stored.out_folder(self.root)  # every cache path checked: no link leading out of root
        self.folder.mkdir(self.cache)
        if not isinstance(program, fleet_logs.Parsed):
            reader = reader or (lambda path, robot: measured.read(path, robot, accelerations=False))
            program = fleet_logs.Parsed(Path(program), stored.sha256_file(program), None)
            data = reader(program.path, self.robot)
        else:
            data = program.checked()
        self.program = program.path
        self._files = {"model": stored.sha256_file(self.robot.path), "program": program.sha256,
                       "friction": FRICTION, "wear": WEAR, "features": list(fleet_logs.FEATURES),
                       "moving_speed": fleet_logs.MOVING_SPEED,  # friction_torque's standstill threshold
                       "reference": f"savgol {REFERENCE_WINDOW:g} s"}
        t, q, which = unit_programs.first_cycle(data.t, data.q, data.cycle)
        if not which:
            self._reference = self._smoothed_program(program.sha256[:24], data.t, data.q)
        else:  # a log of several cycles, or cut anywhere: one cycle replayed (the features are per sample)
            self._files["cycle"] = which
            name = which.replace(" of ", "of").replace("samples ", "s").replace(":", "-")
            self._reference = self._smoothed_program(f"{program.sha256[:24]}-{name}", t, q)
        self._healthy: dict[float, np.ndarray] = {}
        self._cycles: dict[tuple, np.ndarray] = {}  # (temperature key, payload, worn axis) -> features, read or simulated once
        self._refused: dict[tuple, str] = {}  # (temperature, payload, worn_axis) -> why it cannot be simulated
        if cycles:
            self.complete()

    def complete(self) -> None:
        """Simulate (or read from the cache) the :func:`base_cycles` and set :attr:`signatures`: done
        when the twin is made, unless it was made with ``cycles=False`` (to know which base cycles
        are cached, :meth:`cached`, and simulate the others in parallel first)."""
        # The signatures at the model's own friction (a calibrated model's, as identified on the
        # unit's first log, or the nominal one's), with no temperature law on top: the features are
        # not linear in friction (an RMS and a 10/3-norm of the torque), so their change per % of dry
        # friction grows with the rest of the friction. At 20 deg C faultgen's oil law puts 1.30 times
        # the dry and 2.86 times the viscous friction on the model: the KR210's signatures were 1.6-2.1
        # times those at its own friction, and the independent fleet's units answered 0.49-0.66 % per %
        # of their own dry friction's wear (0.85-1.15 now: tests/test_wear_scale.py).
        at_own = float("nan")
        self._simulate_together(base_cycles(self.robot.n_axes))
        healthy = self.cycle(at_own, 0.0)  # also the monitor's healthy expectation without a part
        #: (N, F): change of each feature per % wear of each axis, % of the model's own dry friction
        #: (without a part: the signatures are shared by every unit of the model and program).
        self.signatures = np.stack([(self.cycle(at_own, 0.0, axis) - healthy) / WEAR
                                    for axis in range(1, self.robot.n_axes + 1)])

    def _smoothed_program(self, name: str, t: np.ndarray, q: np.ndarray) -> tasks.Motion:
        """The program log's motion as the twin replays it, in memory (a
        :class:`faultgen.operation.tasks.Motion` named ``name``, replayed by
        :meth:`faultgen.operation.replay.Replay.from_motion` with a log's checks): its angles through
        the Savitzky-Golay filter of :data:`REFERENCE_WINDOW` (:func:`faultgen.derivatives.smoothed`).
        A logged cycle was executed by the real drive, so the twin must not saturate on the encoder's
        noise, which the replay tracks as its reference (faultgen's default 1e-4 rad saturated the
        irb6700's axis 2 on its own pick and place)."""
        t = np.asarray(t, dtype=float)
        q = derivatives.smoothed(t, np.asarray(q, dtype=float), REFERENCE_WINDOW)
        # the program is named by no path: units that run it share the twin, and each one's reason names its own log
        return tasks.Motion(name, t, q, source="the program's log (smoothed, replayed by the twin)")

    def _key(self, temperature: float, payload: float, worn_axis: int) -> tuple[dict, Path]:
        """A cycle's cache key and file; :data:`REFERENCE_TEMPERATURE` is the model's own friction
        (NaN): faultgen's temperature law's factors are 1 there (one over itself)."""
        own = np.isnan(temperature) or float(temperature) == REFERENCE_TEMPERATURE
        temperature = None if own else round(float(temperature), 2)
        key = {**self._files, "temperature_C": temperature, "payload_kg": float(payload), "worn_axis": int(worn_axis)}
        return key, self.cache / f"{stored.key_name(key)}.json"

    def cached(self, temperature: float, payload: float, worn_axis: int = 0) -> bool:
        """Whether the cycle :meth:`cycle` would return is in the cache (as a file; read and checked by it)."""
        path = self._key(temperature, payload, worn_axis)[1]
        return path.exists() or path.is_symlink()

    def _config(self, temperature: float | None, payload: float, plan: wear.WearPlan, cycles: int = 1) -> sim.RunConfig:
        """The run of ``cycles`` replayed cycles at ``temperature`` (rounded; None: the model's own
        friction) with a ``payload`` kg part and wear ``plan``, without noise."""
        from faultgen.simulation.resolve import RunSpec, resolve

        held, _ = setup(temperature, payload)
        return resolve(RunSpec(robot=robots.source_of(self.robot), task=self._reference, friction=FRICTION, wear=plan,
                               cycles=cycles, seed=0, noise=sensors.NoiseConfig(disturbance=0.0, encoder=0.0),
                               nthread=1, conditions=held, signals=True), resolved=self.robot).config

    def _features(self, result: sim.RunResult, index: int = 0) -> np.ndarray:
        """The feature vector of simulated cycle ``index`` of ``result``, as a measured log's."""
        data = measured.from_arrays(result.t, result.q_a[index], result.tau_m[index] * self.robot.gear_ratio,
                                    self.robot, source="a cycle of the twin")
        return fleet_logs.features_of(self.robot, data)

    def _simulate_together(self, cycles: list[tuple[float, float, int]]) -> None:
        """Simulate the ``cycles`` (temperature, payload, worn axis) that are not cached, all at one
        temperature and payload and differing only in their worn axis, as one batch
        (:func:`faultgen.simulation.stepping.simulate`'s ``dry_multipliers``, each row the one-cycle
        run's wear plan gives: the same bits as simulating them one by one, in about half the time;
        docs/performance.md) and cache them. Where a drive saturates nothing is cached:
        :meth:`cycle` simulates them one by one, naming the one that saturates."""
        missing = [(key, path) for key, path in (self._key(*c) for c in cycles)
                   if not (path.exists() or path.is_symlink())]  # not cached
        held = {(key["temperature_C"], key["payload_kg"]) for key, _ in missing}
        if len(missing) < 2 or len(held) > 1:
            return
        ((temperature, payload),) = held
        n = self.robot.n_axes
        rows = np.stack([faults.dry_multipliers(setup(temperature, payload, key["worn_axis"])[1].faults(),
                                                np.array([1]), n)[0] for key, _ in missing])
        config = self._config(temperature, payload, wear.WearPlan({}), cycles=len(missing))
        result = sim.simulate(config, progress=False, stepper=self.stepper, dry_multipliers=rows)
        if result.saturated.size:
            return
        for index, (key, path) in enumerate(missing):
            stored.write_cycle(path, self.root, key, self._features(result, index))

    def cycle(self, temperature: float, payload: float, worn_axis: int = 0) -> np.ndarray:
        """The feature vector of one replayed cycle at ``temperature`` deg C (NaN: the model's
        nominal friction) with a part of ``payload`` kg, ``worn_axis`` (1..N) at :data:`WEAR` %: read
        from the cache (checked) or simulated the first time this twin is asked, then kept in memory
        (a copy returned each time: a twin is not read again per log)."""
        key, path = self._key(temperature, payload, worn_axis)
        temperature = key["temperature_C"]
        held = (temperature, key["payload_kg"], key["worn_axis"])
        if held not in self._cycles:
            self._cycles[held] = self._read_or_simulate(key, path)
        return self._cycles[held].copy()

    def _read_or_simulate(self, key: dict, path: Path) -> np.ndarray:
        """The features of the cycle of cache ``key`` (at ``path``): read and checked when cached,
        else simulated and cached (:meth:`cycle`)."""
        temperature, payload, worn_axis = key["temperature_C"], key["payload_kg"], key["worn_axis"]
        n_features = len(fleet_logs.FEATURES) * self.robot.n_axes
        if path.exists() or path.is_symlink():
            return stored.read_cycle(path, self.root, key, n_features)
        if (temperature, payload, worn_axis) in self._refused:  # a part it cannot carry: said once, not simulated again
            raise ValueError(self._refused[temperature, payload, worn_axis])
        config = self._config(temperature, payload, setup(temperature, payload, worn_axis)[1])
        result = sim.simulate(config, progress=False, stepper=self.stepper)
        if result.saturated.size:
            rated = self.robot.rated_payload
            sized = (f"its drives were sized for a rated payload of {rated:g} kg (`faultgen robots add ... --payload KG` "
                     "sizes an added robot for the one you know)" if np.isfinite(rated) else "")
            self._refused[temperature, payload, worn_axis] = (
                f"the twin with a {payload:g} kg part (aluminium cube at the flange) saturates "
                f"the drive of axis {', '.join(map(str, result.saturated))}: the model cannot carry that part along "
                f"this motion; {sized + '; ' if sized else ''}check the log's payload column (kg) and the model")
            raise ValueError(self._refused[temperature, payload, worn_axis])
        vector = self._features(result)
        stored.write_cycle(path, self.root, key, vector)
        return vector

    def expected(self, temperature: float, payload: float) -> np.ndarray:
        """Features of the healthy twin at ``temperature`` deg C (NaN: nominal) and ``payload`` kg."""
        payload = round(float(payload), 1)
        if np.isnan(temperature) or temperature == REFERENCE_TEMPERATURE:  # the monitor's default: one cycle
            return self.cycle(float(temperature), payload)
        if payload not in self._healthy:
            points = np.stack([self.cycle(t, payload) for t in TEMPERATURES])
            self._healthy[payload] = np.polyfit(np.asarray(TEMPERATURES), points, 2)
        c = self._healthy[payload]
        return c[0] * temperature**2 + c[1] * temperature + c[2]
