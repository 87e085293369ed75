"""A fleet of robots recorded as daily remote-monitoring features, like the thesis's 26 (ch. 5.3.1).

The thesis's classifiers (ch. 5) were trained on 26 six-axis robots, 13 that reported a gearbox
failure and 13 that did not, in different processes, of different sizes and loads, each reporting
once to four times a day 12-bin histograms of angle, speed and torque per axis plus speed and
torque indicators, resampled to the day's maximum (ch. 5.3.1-5.3.2). :class:`Fleet` draws such a
fleet from one seed and gives its runs to :func:`faultgen.runs.sweep.run`, one run per robot:

- both robot models, in turn; a process (task) per robot, or with ``task_mix`` two, its own and a
  second drawn from the others, one of them drawn for each cycle; parts of two sizes that the robot picks
  at random, sized to the model; its own hall climate (mean, seasonal swing, the day of the year
  its record starts), warm-up over each shift, its daily records taken at the same hours every day;
  its own unit-to-unit spread of friction and link masses, and with ``gear_loss`` of gear efficiency
  (:mod:`faultgen.operation.conditions`);
- a failing robot's gearbox wears on one drawn axis, its Coulomb and static friction rising on the
  exp4 schedule (thesis eq. 6.6) from a drawn onset day to ``failure_wear`` percent on its last
  day, the failure day (or, with ``fault``, another effect's parameter grows on that axis on the
  same schedule, :mod:`faultgen.operation.faults`); a healthy robot does not wear;
- every day ``cycles_per_day`` cycles are simulated and reduced to one daily record, the day's
  maximum (:func:`faultgen.simulation.stepping.daily_record`): the histograms and each axis's
  duty (average speed and load torque, from which ``analysis.features.duty_indicators`` makes the
  speed and torque indicators); no 250 Hz signals are kept.

- with ``friction_test_every`` ``= D`` (0, none, by default) each robot also runs the
  friction test of its model (:func:`faultgen.operation.friction_test.program`, as ``faultgen tasks
  friction-test`` writes it) on days 1, 1 + D, 1 + 2 D, ...: one more run per robot,
  ``<run id>-friction-test``, whose recorded cycles are the first cycle of each test day (its wear,
  fault, hall climate, warm-up and unit spread those of the robot's records at that cycle; no part
  carried), with its 250 Hz signals, labelled a test (run attribute ``record = "friction_test"``,
  :data:`faultgen.data.schema.RECORD_ATTRIBUTE`); the typed reader keeps a fleet's tests beside its
  runs (``Dataset.friction_tests``), not among them. The program travels in the test runs' configuration
  as its text (:func:`friction_test_program`: no file, no cache folder).

Labels: a run's ``worn_axes`` (empty: healthy), its wear schedule (``last_cycle`` /
``cycles_per_day`` is the failure day) and the true wear per day (``friction_multiplier``); the
draws of every robot are in the dataset's grid JSON (:meth:`Fleet.to_json`).
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, replace

import numpy as np

from faultgen.effects import friction as friction_models
from faultgen.effects.payload import Payload
from faultgen.effects import temperature as temperature_law
from faultgen.model import robots as robot_models
from faultgen.model import sizing
from faultgen.operation import conditions, faults, programs, tasks, wear
from faultgen.operation.conditions import check_number
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim
from faultgen.simulation.resolve import resolve
from faultgen.simulation.spec import RunSpec

#: Parts of two sizes of the shipped robot models: (mass range kg, edge range m) of the small and
#: the big part. Ours, sized to each model's rated load (IRB-6700-like: 200 kg; PUMA 560: 2.5 kg).
#: Any other model's parts come from its rated payload (:func:`sized_parts`), no entry needed.
PARTS = {
    "irb6700": (((10.0, 40.0), (0.15, 0.3)), ((60.0, 120.0), (0.3, 0.5))),
    "puma560": (((0.2, 0.8), (0.03, 0.06)), ((1.0, 2.0), (0.06, 0.1))),
}
#: The fallback rated payload is this share of the static payload capacity (:func:`rated_payload`):
#: the share that puts the rule within a factor of two of both shipped arms' rated payloads.
PAYLOAD_SHARE = 0.25


def rated_payload(robot) -> float:
    """A robot's rated payload, kg: the MJCF custom numeric ``rated_payload`` (one value, kg) when
    the model has one, else :data:`PAYLOAD_SHARE` of its static payload capacity: the largest
    mass at the flange whose gravity torque, added to the arm's own, stays within every axis's
    peak arm-side torque (gear ratio x motor torque limit) over the home pose and 200 poses drawn
    (seed 0) within the joint ranges. Rule against the shipped arms: PUMA 560 4.6 kg (rated 2.5 kg),
    IRB-6700-like 99 kg (rated 150-300 kg by variant; ours 200 kg).

    Raises
    ------
    ValueError
        If the numeric is not one positive finite value, or no axis carries a payload's weight.
    """
    given = robot.rated_payload  # NaN when the model has no such numeric
    if not np.isnan(given):
        if not (np.isfinite(given) and given > 0):
            raise ValueError(f"{robot.path}: numeric 'rated_payload' = {given!r}; expected one mass > 0 kg")
        return given
    low, high = robot.joint_range.T
    q = np.vstack([robot.home, low + (high - low) * np.random.default_rng(0).random((200, robot.n_axes))])
    arm = np.abs(robot.static_load(q)).max(axis=0)
    carrying = robot.edited(lambda spec: Payload(mass=1.0).write(spec, robot))
    per_kg = np.abs(carrying.static_load(q) - robot.static_load(q)).max(axis=0)  # N m per kg
    loaded = per_kg > 1e-6 * per_kg.max() if per_kg.max() > 0 else per_kg > 0
    if not np.any(loaded):
        raise ValueError(f"{robot.name}: no axis carries the weight of a payload at its flange")
    capacity = (robot.gear_ratio * robot.motor_torque_limit - arm)[loaded] / per_kg[loaded]
    return float(PAYLOAD_SHARE * max(capacity.min(), 0.0))


def sized_parts(robot) -> tuple:
    """(mass range kg, edge range m) of the small and the big part of a robot model: its
    :data:`PARTS` entry, else :func:`faultgen.model.sizing.fleet_parts` of its :func:`rated_payload`
    (shares of it, as aluminium cubes).

    Raises
    ------
    ValueError
        As :func:`rated_payload`, or for a rated payload of zero.
    """
    if robot.name in PARTS and robot.path.parent.parent == robot_models.robots_dir():
        return PARTS[robot.name]
    payload = rated_payload(robot)
    if payload <= 0:
        raise ValueError(f"{robot.name}: the arm's own weight leaves no payload within its motor torque limits")
    return sizing.fleet_parts(payload)
#: The conditions a fleet's robot has, as :class:`faultgen.operation.conditions.Conditions` names
#: them: hall climate and warm-up, parts, unit spread (``Fleet.without`` leaves some out).
CONDITIONS = ("thermal", "payloads", "spread")
#: A robot's friction tests are the run of this id suffix (``<run id>-friction-test``).
TEST_SUFFIX = "-friction-test"


def friction_test_program(robot) -> programs.TextProgram:
    """The friction test of ``robot`` (a :class:`~faultgen.model.robot.Robot`) as a program given by
    its text (:class:`faultgen.operation.tasks.TextProgram`, named ``<robot>-<sha 12>.toml`` by the
    robot and its text's SHA-256): it travels in each test run's configuration, so the runs' keys and
    files are the same on every machine (a fleet's runs used to name a file written into a cache folder,
    whose path entered their keys). The same robot gives the same program, so a resumed fleet finds
    its runs finished; the dataset keeps the program's text.

    Raises
    ------
    ValueError
        As :func:`faultgen.operation.friction_test.program` (an axis whose stroke leaves no speed).
    """
    from faultgen.operation import friction_test

    return programs.TextProgram(robot.name, friction_test.text(robot))


@dataclass(frozen=True)
class Fleet:
    """The fleet's settings; every draw comes from ``seed``.

    Attributes
    ----------
    size : int
        Robots in the fleet (thesis: 26).
    failing : int, optional
        Of them, robots whose gearbox fails (thesis: 13 of 26); default half the fleet, rounded down.
    days : int
        Days each robot is recorded; a failing robot fails on the last one.
    cycles_per_day : int
        Cycles simulated per day, reduced to the day's maximum (thesis: 1 to 4 samples a day).
    failure_wear : float
        Coulomb and static friction increase of the failing axis on the failure day, %.
    onset : tuple of int, optional
        First and last day on which a failing robot's wear may start (drawn uniformly); default
        from a sixth to seven twelfths of the days (10 to 35 of 60), so that every failing robot
        wears for at least its last 25 days.
    models : tuple of str
        Robot models (names, robot folders or MJCF paths, mixed; any number of axes), taken in turn
        (robot i is ``models[i % len(models)]``); their parts from :func:`sized_parts`. Default both
        shipped arms, the IRB-6700-like arm first.
    seed : int
    friction : str
        Friction model of every run.
    conditions : bool
        Each robot's operating conditions (climate, parts, unit spread); False: none, the robots
        differ only by model, process and fault (an ablation: what the conditions do).
    without : tuple of str
        Conditions left out of every robot, some of :data:`CONDITIONS` (``thermal``: the hall
        climate and warm-up; ``payloads``: the parts; ``spread``: the unit spread), the others kept
        with the same draws: the ablation of one condition at a time. Default none.
    tasks : tuple of str
        The pool each robot draws its process from: thesis task names, program files or joint logs
        (:func:`faultgen.operation.programs.load`). Default the three thesis tasks (the draws and
        stored settings of the fleets made before the pool could be set).
    task_mix : bool
        Each robot runs a second task, drawn from the other two, in a random half of its cycles
        (:class:`faultgen.operation.conditions.TaskMix`); False: one task per robot. Off by default,
        so the fleet's draws and records are those of the fleets measured before it existed.
    fault : FaultSpec or None
        Instead of friction wear, a failing robot's drawn axis gets this fault
        (:class:`faultgen.operation.faults.FaultSpec`; its text, parsed once on construction, is the
        one fault text of every command, ``EFFECT:each:PARAMETER:FINAL[:key=value,...]``, AXIS
        ``each``: the drawn axis; e.g. ``backlash:each:width:0.01``), growing on the exp4 schedule from its onset day to FINAL on the
        failure day; FINAL is the same on both robot models. None (default): friction wear.
    gear_loss : float
        Each unit's gearboxes lose a share of the transmitted torque as Coulomb friction, drawn per
        axis in 0..``gear_loss`` (:attr:`faultgen.operation.conditions.UnitSpread.gear_loss`); needs
        ``friction="stribeck"`` and the conditions. Default 0: off, the fleet's draws and records
        those of the fleets measured before it existed.
    dry_share : float
        Exponent of the gear oil viscosity's ratio that every robot's dry friction follows with its
        joint temperature, 0..1 (:attr:`faultgen.operation.conditions.Temperature.dry_share`;
        default :data:`faultgen.effects.temperature.DRY_SHARE`, chosen, not measured); needs the
        conditions. At the default the fleet's draws, records and stored settings are those of the
        fleets measured before it could be set.
    friction_test_every : int
        Days between a robot's friction tests (module docstring), the first on day 1; 0 (default):
        none, and the fleet's runs, records and stored settings are those of the fleets made
        before tests existed.

    Raises
    ------
    ValueError
        On construction, for a value outside its range (named), an onset window that does not fit
        the days, no robot model or one named twice, a model that is unknown or whose parts cannot
        be sized (:func:`sized_parts`), a gear loss without the conditions or under the ``lugre`` friction model, a
        dry share other than the default without the conditions, a ``without`` naming an unknown
        condition, given with the conditions off or dropping what the gear loss or dry share needs,
        or a bad ``fault`` spec (one that sets its own ``kind`` or ``onset`` included: the fleet
        sets them).
    """

    size: int = 26
    failing: int | None = None
    days: int = 60
    cycles_per_day: int = 2
    failure_wear: float = 50.0
    onset: tuple[int, int] | None = None
    models: tuple[str, ...] = ("irb6700", "puma560")
    seed: int = 0
    friction: str = "lugre"
    conditions: bool = True
    task_mix: bool = False
    gear_loss: float = 0.0
    fault: faults.FaultSpec | None = None
    dry_share: float = temperature_law.DRY_SHARE
    without: tuple[str, ...] = ()
    tasks: tuple[str, ...] = tasks.TASKS
    friction_test_every: int = 0

    def __post_init__(self) -> None:
        check_number("fleet size", self.size, 2, 10000, whole=True)
        if self.failing is None:
            object.__setattr__(self, "failing", self.size // 2)
        check_number("fleet failing", self.failing, 1, self.size - 1, whole=True)
        # the smallest fleet record whose default onset window (days // 6 .. 7 days // 12) holds a day
        check_number("fleet days (--days)", self.days, 6, 3650, whole=True)
        check_number("fleet cycles_per_day (--cycles-per-day)", self.cycles_per_day, 1, 24, whole=True)
        check_number("fleet failure_wear (--failure-wear)", self.failure_wear, 0, 100 * wear.MAX_INCREASE)
        check_number("fleet seed", self.seed, 0, 2**31, whole=True)
        check_number("fleet friction_test_every (--friction-test-every)", self.friction_test_every, 0, 3650,
                     whole=True)
        friction_models.check_model(self.friction)
        check_number("fleet gear_loss", self.gear_loss, 0, 0.5)
        if self.gear_loss and (self.friction != "stribeck" or not self.conditions):
            raise ValueError(f"fleet gear_loss = {self.gear_loss!r} needs friction 'stribeck' (--friction stribeck; "
                             f"got {self.friction!r}) and the conditions (got conditions = {self.conditions}): "
                             "the gear loss is a part of the unit spread, updated every step by the static model")
        object.__setattr__(self, "dry_share", check_number("fleet dry_share", self.dry_share, 0, 1))
        if self.dry_share != temperature_law.DRY_SHARE and not self.conditions:
            raise ValueError(f"fleet dry_share = {self.dry_share!r} sets how friction follows the joint temperature, "
                             "one of the conditions (got conditions = False): drop one of the two")
        self._check_without()
        onset = self.onset if self.onset is not None else (self.days // 6, self.days * 7 // 12)
        first, last = (check_number("fleet onset day", d, 1, self.days - 1, whole=True) for d in onset)
        if first > last:
            raise ValueError(f"fleet onset = {self.onset!r}: expected (first day, last day) with first <= last")
        if isinstance(self.models, str) or not self.models or len(set(self.models)) != len(tuple(self.models)):
            raise ValueError(f"fleet models = {self.models!r}: expected one or more different robot model names, "
                             f"e.g. ('irb6700',) or {tuple(PARTS)!r}")
        for model in self.models:
            try:
                sized_parts(robot_models.load(model))  # UnknownRobotError names the known ones
            except robot_models.UnknownRobotError:
                raise
            except ValueError as err:
                raise ValueError(f"fleet model {model!r}: its parts cannot be sized: {err}") from None
        object.__setattr__(self, "onset", (first, last))
        if isinstance(self.fault, str):
            object.__setattr__(self, "fault", faults.FaultSpec.parse(self.fault))
        elif self.fault is not None and not isinstance(self.fault, faults.FaultSpec):
            raise ValueError(f"fleet fault = {self.fault!r}: expected a fault text such as 'backlash:each:width:0.01' "
                             "(or a FaultSpec)")
        spec = self.fault
        if spec is not None:
            if spec.axis is not None or spec.kind is not None or spec.onset is not None:
                raise ValueError(f"fleet fault {str(spec)!r}: the fleet sets the kind (exp4) and onset (the drawn "
                                 "onset day) and draws each failing robot's axis; give EFFECT:each:PARAMETER:FINAL"
                                 f"[:key=value,...] without them, e.g. "
                                 f"{str(replace(spec, axis=None, kind=None, onset=None))!r}")
            self._fault(1, first)  # a bad spec is named now, not when the runs are built
        object.__setattr__(self, "models", tuple(self.models))
        pool = self.tasks
        if isinstance(pool, str) or not pool or len(set(pool)) != len(tuple(pool)):
            raise ValueError(f"fleet tasks = {pool!r}: expected one or more different tasks (thesis task names, "
                             "program files or joint logs)")
        for task in pool:
            programs.check_name(task)
        if self.task_mix and len(pool) < 2:
            raise ValueError(f"fleet task_mix draws a second task from the pool, which holds only {tuple(pool)!r}; "
                             "give two or more tasks")
        object.__setattr__(self, "tasks", tuple(pool))

    def _check_without(self) -> None:
        """Refuse a ``without`` that names an unknown condition, comes with the conditions off, or
        drops what the gear loss or the dry share needs; store it in :data:`CONDITIONS` order."""
        without = self.without
        if not isinstance(without, tuple | list) or any(name not in CONDITIONS for name in without):
            raise ValueError(f"fleet without = {without!r}: expected some of {', '.join(CONDITIONS)}")
        if without and not self.conditions:
            raise ValueError(f"fleet without = {tuple(without)!r} leaves out some of the conditions, which are all off "
                             "(conditions = False): drop one of the two")
        if "spread" in without and self.gear_loss:
            raise ValueError(f"fleet without 'spread' and gear_loss = {self.gear_loss!r}: the gear loss is a part of "
                             "the unit spread")
        if "thermal" in without and self.dry_share != temperature_law.DRY_SHARE:
            raise ValueError(f"fleet without 'thermal' and dry_share = {self.dry_share!r}: the dry share sets how "
                             "friction follows the joint temperature")
        object.__setattr__(self, "without", tuple(name for name in CONDITIONS if name in without))

    def _resolved(self) -> dict:
        """Each of :attr:`models` resolved to its :class:`~faultgen.model.robot.Robot`, by name."""
        return {model: robot_models.load(model) for model in self.models}

    def robots(self) -> list[dict]:
        """The draws of every robot, in order: ``run`` id, ``model``, ``task`` (its own; with a task
        mix the second is in the conditions table), ``failing``, ``axis`` (worn axis 1..N of its model, 0 for a
        healthy robot), ``onset_day``, ``failure_day``, ``seed`` and the operating ``conditions`` table."""
        order = np.random.default_rng([self.seed, 0]).permutation(self.size)
        failing = set(order[: self.failing].tolist())
        out = []
        resolved = self._resolved()
        for i in range(self.size):
            rng = np.random.default_rng([self.seed, i + 1])
            model = self.models[i % len(self.models)]
            task = str(rng.choice(self.tasks))
            robot_model = resolved[model]
            axis = int(rng.integers(1, robot_model.n_axes + 1))
            onset_day = int(rng.integers(self.onset[0], self.onset[1] + 1))
            (small_mass, small_size), (big_mass, big_size) = sized_parts(robot_model)
            parts = {"masses": [round(float(rng.uniform(*small_mass)), 2), round(float(rng.uniform(*big_mass)), 2)],
                     "sizes": [round(float(rng.uniform(*small_size)), 3), round(float(rng.uniform(*big_size)), 3)],
                     "pattern": "random"}
            climate = {"ambient": round(float(rng.uniform(16.0, 24.0)), 1),
                       "seasonal": round(float(rng.uniform(2.0, 8.0)), 1)}
            if self.dry_share != temperature_law.DRY_SHARE:
                climate["dry_share"] = self.dry_share
            spread = {"gear_loss": self.gear_loss} if self.gear_loss else {}
            table = {"thermal": climate, "payloads": parts, "spread": spread, "cycles_per_day": self.cycles_per_day,
                     "start_day": float(rng.integers(0, 365)), "hours": self.hours()}
            if not self.conditions:  # the same draws, none of them used: only the calendar
                table = {"cycles_per_day": self.cycles_per_day, "hours": self.hours()}
            for name in self.without:  # drawn all the same, so the kept conditions are as in the full fleet
                del table[name]
            second = str(rng.choice([t for t in self.tasks if t != task]))  # drawn last: the draws above stay
            if self.task_mix:
                table["task_mix"] = {"tasks": [task, second], "pattern": "random"}
            fails = i in failing
            out.append({"run": f"robot{i + 1:02d}-{robot_model.name}-{programs.label(task)}-{'failing' if fails else 'healthy'}",
                        "model": model, "task": task, "failing": fails, "axis": axis if fails else 0,
                        "onset_day": onset_day if fails else None, "failure_day": self.days if fails else None,
                        "seed": self.seed * 10000 + i, "conditions": table})
        return out

    def hours(self) -> list[float]:
        """Times of day of a day's cycles, h: spread evenly over the production hours (6 to 22),
        the same every day, as a controller collects its data on a schedule (thesis ch. 5.3.2)."""
        start, end = conditions.Temperature().shift
        step = (end - start) / self.cycles_per_day
        return [start + step * (k + 0.5) for k in range(self.cycles_per_day)]

    def runs(self) -> list[tuple[str, sim.RunConfig]]:
        """``(run id, RunConfig)`` of every robot (:meth:`robots`), daily records without signals; with
        :attr:`friction_test_every`, each robot's friction-test run right after it (:meth:`_tests`)."""
        cycles = self.days * self.cycles_per_day
        out = []
        resolved = self._resolved()
        for robot in self.robots():
            plan, fault = wear.WearPlan({}), None
            if robot["failing"] and self.fault is not None:
                fault = self._fault(robot["axis"], robot["onset_day"])
            elif robot["failing"]:
                # the percent as the fleet has always written it (:g, 6 significant digits)
                onset = (robot["onset_day"] - 1) * self.cycles_per_day
                plan = wear.WearPlan({robot["axis"]: wear.Schedule("exp4", float(f"{self.failure_wear:g}") / 100.0,
                                                                    cycles, {"onset": onset})})
            config = resolve(RunSpec(robot=robot["model"], task=robot["task"], friction=self.friction, wear=plan,
                                     cycles=cycles, seed=robot["seed"], noise=sensors.NoiseConfig(), nthread=1,
                                     conditions=conditions.Conditions.from_dict(robot["conditions"]),
                                     signals=False, daily=True, fault=fault), resolved=resolved[robot["model"]]).config
            out.append((robot["run"], config))
            if self.friction_test_every:
                out.append(self._tests(robot, config))
        return out

    def test_days(self) -> list[int]:
        """The days (1-based) of each robot's friction tests: 1, 1 + D, ... for D = :attr:`friction_test_every`."""
        return list(range(1, self.days + 1, self.friction_test_every)) if self.friction_test_every else []

    def _tests(self, robot: dict, daily: sim.RunConfig) -> tuple[str, sim.RunConfig]:
        """The friction-test run of ``robot`` (:meth:`robots`' entry) beside its ``daily`` run: the
        model's test program, the same cycles, wear, fault, seed and conditions (its climate and unit
        spread, no part, no task mix), the first cycle of each test day recorded with its signals."""
        table = {k: v for k, v in robot["conditions"].items() if k not in ("payloads", "task_mix")}
        test = friction_test_program(daily.model)
        record = tuple((day - 1) * self.cycles_per_day + 1 for day in self.test_days())
        config = resolve(RunSpec(robot=daily.robot, task=test, friction=self.friction, wear=daily.wear,
                                 cycles=daily.cycles, record=record, seed=daily.seed, noise=daily.noise, nthread=1,
                                 conditions=conditions.Conditions.from_dict(table), signals=True, fault=daily.fault),
                         resolved=daily.model).config
        return robot["run"] + TEST_SUFFIX, config

    def _fault(self, axis: int, onset_day: int) -> faults.Fault:
        """The fault of a robot failing on ``axis`` from ``onset_day``."""
        try:
            return self.fault.fault(
                self.days * self.cycles_per_day, axis=axis, kind="exp4", onset=(onset_day - 1) * self.cycles_per_day)
        except ValueError as err:
            raise ValueError(f"fleet fault {str(self.fault)!r}: {err}") from None

    def to_json(self) -> str:
        """The settings and every robot's draws, stored with the dataset."""
        settings = {**asdict(self), "fault": None if self.fault is None else str(self.fault)}
        later = {"gear_loss": 0.0, "fault": None, "dry_share": temperature_law.DRY_SHARE, "without": (),
                 "tasks": tasks.TASKS, "friction_test_every": 0}
        for name, default in later.items():  # at their defaults, the settings of fleets made before they existed
            if settings[name] == default:
                del settings[name]
        return json.dumps({"fleet": settings, "robots": self.robots()}, sort_keys=True)
