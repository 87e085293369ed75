"""A sweep's grid: the product of robots, tasks, worn axes, wear levels, schedules and seeds, as
the run configurations :func:`faultgen.runs.sweep.run` simulates, built and validated once."""

from __future__ import annotations

import itertools
import json
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np

from faultgen import axes as axis_numbers
from faultgen import inputs
from faultgen.checks import MAX_SEED
from faultgen.effects import friction
from faultgen.model import robots
from faultgen.operation import faults, programs, tasks, wear
from faultgen.operation.conditions import Conditions
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim
from faultgen.simulation.resolve import resolve
from faultgen.simulation.spec import RunSpec

#: Named grids. quick: a small grid for a first look (under a minute on 2 cores).
#: first-look: quick's spot-weld runs, two seeds, cycles 41-100 recorded, features only: the README's
#: first analyses (bench-isolators, detect with other-seeds, classify) on one dataset (issue 88;
#: docs/performance.md, "A first look").
#: j2: thesis ch. 6 (IRB 6700, 3 tasks, no wear + each axis, exp4 to +20 % over 100 cycles).
#: c2: thesis ch. 3 (PUMA 560, 3 tasks x 6 axes x {10, 20} % logistic over 120 hours of one-minute
#: cycles, the first ten cycles of every hour recorded, as the torque of ch. 3.4 is sampled); features
#: only unless ``signals=True`` (the signals would take 16 GB; detection gives the same table without).
PRESETS = {
    "quick": dict(robots=["irb6700"], tasks=list(tasks.TASKS), axes=[0, 1, 2, 3, 4, 5, 6], increases=[20.0],
                  schedules=["exp4"], cycles=100, record=list(range(10, 101, 10))),
    "first-look": dict(robots=["irb6700"], tasks=["spot_weld"], axes=[0, 1, 2, 3, 4, 5, 6], increases=[20.0],
                       schedules=["exp4"], cycles=100, record=list(range(41, 101)), seeds=[0, 1], signals=False),
    "j2": dict(robots=["irb6700"], tasks=list(tasks.TASKS), axes=[0, 1, 2, 3, 4, 5, 6], increases=[20.0],
               schedules=["exp4"], cycles=100, record="all"),
    "c2": dict(robots=["puma560"], tasks=list(tasks.TASKS), axes=[0, 1, 2, 3, 4, 5, 6], increases=[10.0, 20.0],
               schedules=["logistic"], cycles=120 * 60, record={"period": 60, "first": 10}, signals=False),
}



@dataclass(frozen=True)
class Grid:
    """The runs of a sweep, as the product of its lists.

    Attributes
    ----------
    robots, tasks : list of str
    axes : list of int
        Worn axes, 1..N of every robot of the grid; 0 means a run without wear (one per robot, task and seed).
    increases : list of float
        Final wear in percent (20 = Coulomb and static friction 20 % higher at the last cycle).
    schedules : list of str
        Wear schedules (:data:`faultgen.operation.wear.SCHEDULES`).
    friction : str
        Friction model (:data:`faultgen.effects.friction.MODELS`).
    cycles : int
        Cycles per run.
    record : "all", list of int, or {"period": P, "first": F}
        Cycles to simulate and record: all, the listed ones, or the first F of every P.
    seeds : list of int
    disturbance, encoder : float
        Noise levels (:class:`faultgen.simulation.sensors.NoiseConfig`).
    conditions : Conditions or None
        Operating conditions of every run (:class:`faultgen.operation.conditions.Conditions`); None:
        none, the runs differ from their references only by wear. A table (a grid file's
        ``[conditions]``: ``thermal``, ``payloads``, ``spread``, ``task_mix`` tables,
        ``cycles_per_day``, ``start_day``, ``hours``) is read once into one
        (:meth:`~faultgen.operation.conditions.Conditions.from_dict`).
    fault : FaultSpec or None
        A fault other than friction wear for the worn axes (:class:`faultgen.operation.faults.FaultSpec`);
        its text, ``EFFECT:AXIS:PARAMETER:FINAL[:key=value,...]`` (the one fault text of every
        command), is parsed once into one. With AXIS ``each`` (``backlash:each:width:0.01``) each
        axis of ``axes`` but 0 gets it instead of friction wear; with a number, ``axes`` may wear
        only that axis (and 0). ``increases`` and ``schedules`` are then unused; ``kind=...``
        shapes its growth.
    signals : bool
        Keep the 250 Hz signals (False: features and truth only, a fraction of the size; the
        isolators and ``faultgen detect`` then work from the stored per-cycle features; the speed
        window of ``bench-isolators`` needs the signals).
    wear_schedules : tuple of Schedule
        Not a constructor argument: the wear schedule of a worn axis's runs, one per schedule and
        increase (``schedules`` x ``increases``, in that order), built once on construction.

    Raises
    ------
    ValueError
        On construction, naming the first invalid value; nothing is simulated.
    """

    robots: list[str]
    tasks: list[str]
    axes: list[int]
    increases: list[float] = field(default_factory=lambda: [20.0])
    schedules: list[str] = field(default_factory=lambda: ["exp4"])
    friction: str = "lugre"
    cycles: int = 100
    record: str | list[int] | dict = "all"
    seeds: list[int] = field(default_factory=lambda: [0])
    disturbance: float = 0.01
    encoder: float = 1e-4
    conditions: Conditions | None = None
    fault: faults.FaultSpec | None = None
    signals: bool = True
    wear_schedules: tuple[wear.Schedule, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name in ("robots", "tasks", "axes", "increases", "schedules", "seeds"):
            value = getattr(self, name)
            if isinstance(value, (str, bytes)) or not isinstance(value, (list, tuple)) or not value:
                raise ValueError(f"grid field {name!r} must be a non-empty list, got {value!r}")
        for axis in self.axes:
            if not isinstance(axis, int) or not 0 <= axis <= axis_numbers.MAX_AXES:
                raise ValueError(f"worn axis {axis!r} is out of range 0..{axis_numbers.MAX_AXES} (0 = no wear)")
        friction.check_model(self.friction)
        self._read_conditions_and_fault()
        spec = self.fault
        if spec is not None:
            worn = sorted(set(self.axes) - {0})
            if spec.axis is not None and worn != [spec.axis]:
                raise ValueError(
                    f"fault {str(spec)!r} is on axis {spec.axis} but the grid wears axes "
                    f"{', '.join(map(str, worn)) or 'none'}: give --axis 0 --axis {spec.axis}, or write "
                    f"{str(replace(spec, axis=None))!r} "
                    "to give each worn axis the fault in turn")
        for kind in self.schedules:
            if kind not in wear.SCHEDULES:
                raise ValueError(f"unknown wear schedule {kind!r}; expected one of: {', '.join(wear.SCHEDULES)}")
        for pct in self.increases:
            if isinstance(pct, bool) or not isinstance(pct, (int, float)) or not np.isfinite(pct) or pct < 0:
                raise ValueError(f"grid increases (--wear-pct): {pct!r} % must be a finite number >= 0")
            if pct > 100 * wear.MAX_INCREASE:
                raise ValueError(f"grid increases (--wear-pct): {pct:g} % is beyond the bound of "
                                 f"{100 * wear.MAX_INCREASE:g} % (faultgen.operation.wear.MAX_INCREASE)")
        for name in ("cycles",):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ValueError(f"grid {name} = {value!r} (--{name}): expected a whole number >= 1")
        for seed in self.seeds:
            if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED:
                raise ValueError(f"grid seeds (--seed): {seed!r}: expected a whole number in 0 .. {MAX_SEED}")
        if not isinstance(self.signals, bool):
            raise ValueError(f"grid signals = {self.signals!r}: expected true or false (a TOML boolean, not a string)")
        for name in ("disturbance", "encoder"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value) or value < 0:
                raise ValueError(f"grid {name} = {value!r}: expected a finite number >= 0")
        # the percent as the run id writes it (6 significant digits, :g), as the sweep always made it:
        # the run id names the wear its run has
        object.__setattr__(self, "wear_schedules", tuple(wear.Schedule(kind, float(f"{pct:g}") / 100.0, self.cycles)
                                               for kind, pct in itertools.product(self.schedules, self.increases)))
        # builds and validates every run configuration, once: runs() returns these
        object.__setattr__(self, "_runs", self._build_runs())

    def _read_conditions_and_fault(self) -> None:
        """Hold the conditions and the fault as their types, reading a table or a fault text once."""
        if isinstance(self.conditions, dict):
            object.__setattr__(self, "conditions", Conditions.from_dict(self.conditions))
        elif self.conditions is not None and not isinstance(self.conditions, Conditions):
            raise ValueError(f"grid field 'conditions' must be a table (or a Conditions), got {self.conditions!r}")
        if isinstance(self.fault, str):
            object.__setattr__(self, "fault", faults.FaultSpec.parse(self.fault))
        elif self.fault is not None and not isinstance(self.fault, faults.FaultSpec):
            raise ValueError(f"grid field 'fault' must be a fault text such as 'backlash:each:width:0.01' (or a "
                             f"FaultSpec), got {self.fault!r}")

    @classmethod
    def from_preset(cls, name: str, **overrides) -> Grid:
        """A named grid (:data:`PRESETS`), with fields replaced by ``overrides``."""
        if name not in PRESETS:
            raise ValueError(f"unknown preset {name!r}; expected one of: {', '.join(PRESETS)}")
        return cls(**{**PRESETS[name], **overrides})

    @classmethod
    def from_toml(cls, path: str | Path) -> Grid:
        """Read a grid from a TOML file whose top-level keys are the fields of :class:`Grid`.

        A ``preset = "name"`` key starts from that preset. Unknown keys are refused.
        """
        data = inputs.read_toml(path, "grid file")
        known = {f.name for f in fields(cls) if f.init} | {"preset"}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(f"{path}: unknown key {unknown[0]!r}; expected: {', '.join(sorted(known))}")
        preset = data.pop("preset", None)
        if not preset:
            missing = [name for name in ("robots", "tasks", "axes") if name not in data]
            if missing:
                raise ValueError(f"{path}: no key {missing[0]!r} (and no preset); a grid file needs robots, tasks "
                                 "and axes, or preset = \"quick\" (or j2, c2)")
        return cls.from_preset(preset, **data) if preset else cls(**data)

    @classmethod
    def of(cls, preset: str | None = None, config: str | Path | None = None, **options) -> Grid:
        """The grid of ``faultgen sweep``: the TOML file ``config`` (:meth:`from_toml`), else the named
        ``preset``, each with the fields given in ``options`` replaced; else ``options`` on the run
        without wear of irb6700 on pick_place. A fault on a named axis (``options["fault"]``, a
        :class:`~faultgen.operation.faults.FaultSpec`) without ``axes`` runs beside the run without wear.
        """
        fault = options.get("fault")
        if isinstance(fault, faults.FaultSpec) and fault.axis is not None and "axes" not in options:
            options["axes"] = [0, fault.axis]
        if config is not None:
            grid = cls.from_toml(config)
            return replace(grid, **options) if options else grid
        if preset is not None:
            return cls.from_preset(preset, **options)
        return cls(**{"robots": ["irb6700"], "tasks": ["pick_place"], "axes": [0], **options})

    def recorded_cycles(self) -> tuple[int, ...] | None:
        """The ``record`` field as cycle indices (None: all)."""
        if self.record == "all":
            return None
        if isinstance(self.record, dict):
            if set(self.record) != {"period", "first"}:
                raise ValueError(f"record {self.record!r}: expected {{period = P, first = F}}")
            period, first = int(self.record["period"]), int(self.record["first"])
            if not 1 <= first <= period:
                raise ValueError(f"record {self.record!r}: need 1 <= first <= period")
            return tuple(k for k in range(1, self.cycles + 1) if (k - 1) % period < first)
        if isinstance(self.record, (list, tuple)):
            return tuple(int(c) for c in self.record)
        raise ValueError(f"record {self.record!r}: expected \"all\", a list of cycles or {{period, first}}")

    def runs(self) -> list[tuple[str, sim.RunConfig]]:
        """Every run of the grid as ``(run id, RunConfig)``, in a stable order (built and validated
        once, when the grid is made)."""
        return list(self._runs)

    def _build_runs(self) -> list[tuple[str, sim.RunConfig]]:
        noise = sensors.NoiseConfig(disturbance=self.disturbance, encoder=self.encoder)
        record = self.recorded_cycles()
        conditions = self.conditions or Conditions()
        out: dict[str, sim.RunConfig] = {}
        named: dict[str, str] = {}  # run ids carry the robot's name: two models of one name would share them
        resolved = {str(robot): robots.load(robot) for robot in self.robots}  # once, for every run
        for robot in self.robots:
            first = named.setdefault(resolved[str(robot)].name, str(robot))
            if first != str(robot) and resolved[first].path != resolved[str(robot)].path:
                raise ValueError(f"robots {first!r} and {str(robot)!r} are both named {resolved[str(robot)].name!r}; "
                                 "run ids need different names (rename one folder or MJCF file)")
        self._check_programs(resolved)
        for robot, task, axis, seed in itertools.product(self.robots, self.tasks, self.axes, self.seeds):
            name, n_axes = resolved[str(robot)].name, resolved[str(robot)].n_axes
            if axis > n_axes:
                raise ValueError(f"worn axis {axis} is out of range 0..{n_axes} of robot {name} (0 = no wear)")
            # a run without wear is one run, whatever the wear levels and schedules of the grid
            variants = [None] if axis == 0 or self.fault else self.wear_schedules
            for schedule in variants:
                plan, fault = wear.WearPlan({}), None
                if axis == 0:
                    label = "nowear"
                elif self.fault:
                    fault = self.fault.fault(self.cycles, axis=axis)
                    label = f"axis{axis}-{fault.effect}{fault.final:g}"
                else:
                    plan = wear.WearPlan({axis: schedule})
                    label = f"axis{axis}-{schedule.kind}{100 * schedule.increase:g}"
                run_id = f"{name}-{programs.label(task)}-{label}-seed{seed}"
                if run_id in out and out[run_id].task != task:
                    raise ValueError(f"tasks {out[run_id].task!r} and {task!r} would both make run {run_id!r}; "
                                     "give the program files different file names")
                out[run_id] = resolve(RunSpec(
                    robot=robot, task=task, friction=self.friction, wear=plan, cycles=self.cycles, record=record,
                    seed=seed, noise=noise, nthread=1, conditions=conditions, signals=bool(self.signals), fault=fault),
                    resolved=resolved[str(robot)]).config
        return list(out.items())

    def _check_programs(self, resolved: dict) -> None:
        """Refuse two different programs under one label (a run's ``task``): analyses would take
        one for the other (:func:`faultgen.operation.programs.identity` labels an edited export by
        its file name; two files of one ``name`` still collide)."""
        seen: dict[tuple[str, str], tuple[str, str]] = {}  # (robot, label) -> (task as given, program hash)
        for robot, task in itertools.product(self.robots, self.tasks):
            label, digest = programs.identity(resolved[str(robot)], task)
            first, first_digest = seen.setdefault((resolved[str(robot)].name, label), (task, digest))
            if first_digest != digest:
                raise ValueError(f"tasks {first!r} and {task!r} are different programs (sha256 {first_digest[:12]}... "
                                 f"and {digest[:12]}...) under one label {label!r}: give the program file its own "
                                 "`name` (or file name) so the dataset can tell them apart")

    def to_json(self) -> str:
        """The grid as its file would give it (the dataset keeps it): the fields, the conditions as
        their short table (:meth:`~faultgen.operation.conditions.Conditions.to_table`), the fault as
        its text."""
        table = {f.name: getattr(self, f.name) for f in fields(self) if f.init}
        table["conditions"] = None if self.conditions is None else self.conditions.to_table()
        table["fault"] = None if self.fault is None else str(self.fault)
        return json.dumps(table, sort_keys=True)
