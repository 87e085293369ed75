"""Typed reading of a faultgen dataset: :func:`open` gives a :class:`Dataset` of :class:`Run` records.

The HDF5 layout (:mod:`faultgen.data.schema`, docs/dataset.md) stays behind this module: a run's
labels are typed fields (tuples of 1-based axes, parsed JSON, ints), its per-cycle truth and
features are arrays read when first asked for, and the file is opened once for all reads::

    import faultgen

    with faultgen.open("quick.h5") as data:
        for run in data.runs:
            print(run.id, run.robot, run.task, run.worn_axes, run.wear.max())   # wear: (cycles, axes), %
        table = data.features()                                                 # tidy, one row per cycle and axis

Arrays are named as in :data:`faultgen.data.schema.ARRAYS` (and the duty, count, condition and
fault tables beside it); :meth:`Run.array` reads any of them, :meth:`Run.signal` the 250 Hz
signals (``tau_m``, ``q_a``, ...), and each read is cached on the run.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Iterator, Sequence
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from faultgen import inputs
from faultgen.data import robot_record, schema
from faultgen.data.opening import attr, open_file
from faultgen.data.validator import attribute_problems

if TYPE_CHECKING:
    import pandas as pd

#: Every array a run group may hold -> (units, axes, description), from the tables of
#: :mod:`faultgen.data.schema`.
SCHEMA: dict[str, tuple[str, str, str]] = {
    **schema.ARRAYS, **schema.DUTY_ARRAYS, **schema.COUNT_ARRAYS,
    **{name: spec[:3] for name, spec in schema.CONDITION_ARRAYS.items()}, **schema.FAULT_ARRAYS,
}


def _json(value) -> Any:
    value = attr(value)
    return json.loads(value) if isinstance(value, str) and value else None


@dataclass(frozen=True)
class Run:
    """One run of a dataset: a simulated robot unit doing one task (in a fleet, one robot's record).

    Attributes
    ----------
    id : str
        The run's name in the file (``/runs/<id>``).
    robot, task, friction_model : str
        Robot model, task program and friction model (labels).
    seed : int
        The unit's seed (noise, draws).
    cycles : int
        Cycles simulated (a fleet: days times cycles per day).
    worn_axes : tuple of int
        Axes (1-based, ``faultgen.axes``) that wear or carry the fault; empty for a healthy run.
    wear_schedule : dict
        The wear schedule as written (``faultgen.operation.wear``: kind, per-axis final wear, ...).
    fault : dict or None
        A fault other than friction wear (``faultgen.operation.faults``: effect, parameter, axis,
        start, final, ...), None for friction wear or none.
    conditions : dict or None
        Operating conditions (``faultgen.operation.conditions``), None without.
    noise : dict
        Sensor noise settings.
    sample : {"cycle", "day", "log"}
        What a recorded sample is: one cycle, a day's record (fleets), or a log's record (a fleet
        imported from measured logs, ``faultgen logs import``).
    has_signals : bool
        Whether the 250 Hz signals are stored (False: features and truth only).
    provenance : dict
        faultgen_version, model_sha256, log_period (s), command, config (parsed JSON).
    program_sha256 : str or None
        SHA-256 (hex) of the program's text (:func:`faultgen.operation.programs.identity`). In files
        written before it was recorded: a program file's or log's hash from the ``program``
        attribute, None for a thesis task.
    measured : bool
        True for a unit imported from measured logs (``faultgen logs import``): its records are
        logs, its wear the labels of its events (:data:`faultgen.data.schema.MEASURED_ARRAYS`).
    friction_test : bool
        True for a run whose records are friction tests (attribute ``record = "friction_test"``,
        :data:`faultgen.data.schema.RECORD_ATTRIBUTE`): in a fleet, a robot's tests
        (:attr:`Dataset.friction_tests`); :mod:`faultgen.data.friction_records` reads one as a log.

    What the run stored of its robot, which the analyses read instead of the robot's files:
    :attr:`drivetrain`, :attr:`limits` and :attr:`model_sha256`.
    """

    id: str
    robot: str
    task: str
    friction_model: str
    seed: int
    cycles: int
    worn_axes: tuple[int, ...]
    wear_schedule: dict = field(repr=False)
    fault: dict | None
    conditions: dict | None = field(repr=False)
    noise: dict = field(repr=False)
    sample: str
    has_signals: bool
    provenance: dict = field(repr=False)
    program_sha256: str | None = field(default=None, repr=False)
    measured: bool = False
    friction_test: bool = False
    _stored: dict = field(default_factory=dict, repr=False, compare=False)
    _source: Dataset | None = field(default=None, repr=False, compare=False)
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def failing(self) -> bool:
        """Whether the run wears or carries a fault (a failing robot of a fleet)."""
        return bool(self.worn_axes) or self.fault is not None

    @property
    def model_sha256(self) -> str:
        """SHA-256 (hex) of the robot's MJCF file the run was simulated with (or its logs imported for,
        ``faultgen logs import``): which version of the robot its :attr:`drivetrain` is."""
        return self.provenance.get("model_sha256", "")

    @property
    def drivetrain(self) -> robot_record.Drivetrain:
        """The drivetrain the run stored (gear ratios, motor inertias, gearbox stiffness and damping,
        peak motor torques, nominal motor friction; per axis, SI units:
        :class:`faultgen.data.robot_record.Drivetrain`), read on first use. A file written before runs
        stored it (before robots of 5-7 axes) gives the robot's, loaded from its files by :attr:`robot`
        (``from_files``).

        Raises
        ------
        faultgen.data.schema.DatasetError
            If the stored attribute does not read.
        ValueError
            For such an older file whose robot cannot be loaded on this machine.
        """
        return self._read_once("drivetrain", lambda attrs: robot_record.drivetrain(attrs, self.robot, self._where))

    @property
    def limits(self) -> robot_record.Limits:
        """The limits the run's histograms were binned over (joint range, the robot's and the task's
        speed limit: :class:`faultgen.data.robot_record.Limits`), read on first use. A file written
        before runs stored them gives the robot's, loaded from its files by :attr:`robot` (``from_files``).
        Raises as :attr:`drivetrain` does.
        """
        return self._read_once(
            "limits", lambda attrs: robot_record.limits(attrs, self.robot, self.task, self._where))

    def _read_once(self, key: str, read):
        """``read(attrs)`` of the run's stored attributes, kept under ``key`` after its first use."""
        if key not in self._stored:
            self._stored[key] = read(self._stored.get("attrs", {}))
        return self._stored[key]

    @property
    def _where(self) -> str:
        return f"{self._source.path if self._source is not None else '(no file)'}: run {self.id!r}"

    @property
    def program(self) -> str:
        """What the run's program is: its SHA-256, or, in a file written before runs carried it,
        ``"task:<label>"`` (two programs under one label then look alike: :attr:`Dataset.unhashed`)."""
        return self.program_sha256 or f"task:{self.task}"

    @property
    def setup(self) -> tuple:
        """What two runs must share to be compared (a worn run with its unworn reference, a monitor
        with the runs it judges): robot (name and model hash), program, friction model and
        operating conditions (:attr:`conditions_key`). :func:`difference` says in words what two
        setups do not share."""
        return (self.robot, self.provenance.get("model_sha256", ""), self.program, self.friction_model,
                self.conditions_key)

    @property
    def conditions_key(self) -> str:
        """The operating conditions two runs must share to be compared: all of them for a run of a
        sweep; for a fleet's robot (daily records), which conditions are on, as each robot is a unit
        with its own draw of the fleet's climate, payloads and spread (thesis ch. 4-5 compare
        robots)."""
        if not self.conditions:
            return ""
        if self.sample == "day":
            return json.dumps(sorted(k for k, v in self.conditions.items() if v is not None))
        return json.dumps(self.conditions, sort_keys=True)

    @property
    def names(self) -> tuple[str, ...]:
        """The arrays this run holds, in file order."""
        return tuple(self._group())

    def _group(self):
        if self._source is None:
            raise schema.DatasetError(f"run {self.id!r} is not attached to an open dataset")
        return self._source._group(self.id)

    def array(self, name: str) -> np.ndarray:
        """The stored array ``name`` (:data:`SCHEMA`: units and axes), read on first use, cached.

        Raises
        ------
        faultgen.data.schema.DatasetError
            If the run has no such array (the message says why, e.g. recorded without signals),
            or the dataset was closed.
        """
        if name not in self._cache:
            group = self._group()
            if name not in group:
                why = ""
                if not self.has_signals and SCHEMA.get(name, ("", ""))[1] == schema.SIGNAL_AXES:
                    why = ("; it was recorded without signals (features only): simulate it again with signals "
                           "(`faultgen sweep` without --features-only)")
                raise schema.DatasetError(f"{self._source.path}: run {self.id!r} has no array {name!r}{why}")
            value = inputs.bounded_dataset(group, name, self._source.path, kinds=schema.kinds(name))[()]
            if value.dtype.kind == "f" and not np.all(np.isfinite(value)):
                raise schema.DatasetError(f"{self._source.path}: run {self.id!r}: {name} holds non-finite values; the "
                                           f"file is corrupted (faultgen validate {self._source.path})")
            self._cache[name] = value
        return self._cache[name]

    def units(self, name: str) -> str:
        """The units the file stores for array ``name`` (its ``units`` attribute; "" if it has none).

        Raises
        ------
        faultgen.data.schema.DatasetError
            If the run has no such array, or the dataset was closed.
        """
        group = self._group()
        if name not in group:
            raise schema.DatasetError(f"{self._source.path}: run {self.id!r} has no array {name!r}")
        return str(attr(group[name].attrs.get("units", "")))

    def forget(self, *names: str) -> None:
        """Drop the cached arrays ``names`` (read again if asked for): large signals not kept."""
        for name in names:
            self._cache.pop(name, None)

    def has(self, *names: str) -> bool:
        """Whether the run holds every array of ``names``."""
        group = self._group()
        return all(name in group for name in names)

    def signal(self, name: str = "tau_m") -> np.ndarray:
        """A 250 Hz signal, ndarray of shape (n_cycles, n_log, n_axes) in its units (:data:`SCHEMA`)."""
        if SCHEMA.get(name, ("", ""))[1] != schema.SIGNAL_AXES:
            raise ValueError(f"{name!r} is not a 250 Hz signal; expected one of: "
                             + ", ".join(n for n, s in SCHEMA.items() if s[1] == schema.SIGNAL_AXES))
        return self.array(name)

    @property
    def recorded(self) -> np.ndarray:
        """1-based index of each recorded cycle, ndarray of int of shape (n_cycles,)."""
        return self.array("cycles")

    @property
    def wear(self) -> np.ndarray:
        """True friction wear per recorded cycle and axis, ndarray of shape (n_cycles, n_axes), in %:
        ``(friction_multiplier - 1) * 100``; 20 % is Coulomb and static friction 1.2 times new."""
        return (self.array("friction_multiplier") - 1.0) * 100.0

    @property
    def fault_level(self) -> np.ndarray:
        """Per recorded cycle, how far the run's fault has grown, %: the worn axis's friction wear
        (the largest over its worn axes), or for a fault other than friction wear its parameter's
        change as a share of its final change (0 % at ``start``, 100 % at ``final``). Zeros for a
        healthy run. ndarray of shape (n_cycles,)."""
        if self.fault is not None:
            value = self.array("fault_value")
            return 100.0 * (value - self.fault["start"]) / (self.fault["final"] - self.fault["start"])
        if not self.worn_axes:
            return np.zeros(len(self.recorded))
        return self.wear[:, [a - 1 for a in self.worn_axes]].max(axis=1)

    @property
    def fault_begins(self) -> int | None:
        """Index (0-based) of the first recorded sample at which the fault has begun (``fault_level
        > 0``), None for a healthy run or one whose fault never starts within the record."""
        grown = np.flatnonzero(self.fault_level > 1e-9)
        return int(grown[0]) if self.failing and grown.size else None


def difference(a: Run, b: Run) -> str:
    """What the :attr:`Run.setup` of ``a`` and ``b`` do not share, in words ("" if nothing): the runs
    an analysis must not compare, and why."""
    parts = []
    if (a.robot, a.provenance.get("model_sha256")) != (b.robot, b.provenance.get("model_sha256")):
        parts.append(f"robot {a.robot} vs {b.robot}" if a.robot != b.robot else f"robot model of {a.robot}")
    if a.program != b.program:
        shown = (f"{a.task} ({a.program[:8]}) vs {b.task} ({b.program[:8]})" if a.program_sha256 and b.program_sha256
                 else f"{a.task} vs {b.task}")
        parts.append(f"program {shown}")
    if a.friction_model != b.friction_model:
        parts.append(f"friction model {a.friction_model} vs {b.friction_model}")
    if a.conditions_key != b.conditions_key:
        parts.append("operating conditions")
    return ", ".join(parts)


def _run(run_id: str, attrs: dict, source: Dataset) -> Run:
    config = _json(attrs.get("config")) or {}
    return Run(
        id=run_id, robot=str(attrs["robot"]), task=str(attrs["task"]), friction_model=str(attrs["friction_model"]),
        seed=int(attrs["seed"]), cycles=int(attrs["cycles"]),
        worn_axes=tuple(int(a) for a in np.atleast_1d(attrs["worn_axes"])),
        wear_schedule=_json(attrs.get("wear")) or {}, fault=_json(attrs.get("fault")),
        conditions=_json(attrs.get("conditions")), noise=_json(attrs.get("noise")) or {},
        sample=str(attrs.get("sample", "cycle")), has_signals=bool(attrs.get("signals", True)),
        provenance={"faultgen_version": str(attrs.get("faultgen_version", "")),
                    "model_sha256": str(attrs.get("model_sha256", "")),
                    "log_period": float(attrs.get("log_period", np.nan)), "command": str(attrs.get("command", "")),
                    "config": config},
        # files written before the attribute: a program file's or log's runs kept its hash in `program`
        program_sha256=str(attrs[schema.PROGRAM_ATTRIBUTE]) if schema.PROGRAM_ATTRIBUTE in attrs
        else (_json(attrs.get("program")) or {}).get("sha256"),
        measured=attrs.get("source") == schema.MEASURED, _source=source,
        friction_test=attrs.get(schema.RECORD_ATTRIBUTE) == schema.FRICTION_TEST,
        _stored={"attrs": {key: attrs[key] for key in ("drivetrain", "limits", "source") if key in attrs}})


class Dataset(Sequence):
    """A finished faultgen dataset, opened once (read-only); a sequence of its :class:`Run`.

    Use as a context manager (``with faultgen.open(path) as data:``) or call :meth:`close`. Runs
    are listed at opening (labels only); their arrays are read when asked for.

    Attributes
    ----------
    path : pathlib.Path
    runs : tuple of Run
        In file order; in a fleet (``faultgen fleet``), its robots' runs without their friction tests.
    friction_tests : tuple of Run
        The runs labelled friction tests (:attr:`Run.friction_test`), in file order: in a fleet, a
        robot's is ``<run id>-friction-test``, beside :attr:`runs`; elsewhere also among them.
    command : str
        The command that wrote the file.
    faultgen_version : str
        The version that wrote it.
    grid : dict or None
        The sweep's grid or the fleet's settings (parsed JSON), None if not stored.
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self._stack = ExitStack()
        self._file = self._stack.enter_context(open_file(self.path))
        attrs = self._file.attrs
        self.command = str(attr(attrs.get("command", "")))
        self.faultgen_version = str(attr(attrs.get("faultgen_version", "")))
        self.grid = _json(attrs.get("grid"))
        runs = []
        for run_id in self._file["runs"]:
            group = self._file["runs"][run_id]
            problems = attribute_problems(group)  # labels that do not parse: named, not a crash
            if problems:
                self.close()
                raise schema.DatasetError(f"{self.path}: run {run_id!r}: {problems[0]} (faultgen validate {self.path} "
                                           "lists every problem)")
            runs.append(_run(run_id, {k: attr(v) for k, v in group.attrs.items()}, self))
        fleet = isinstance(self.grid, dict) and "fleet" in self.grid
        self.friction_tests: tuple[Run, ...] = tuple(r for r in runs if r.friction_test)
        self.runs: tuple[Run, ...] = tuple(r for r in runs if not (fleet and r.friction_test))
        self._by_id = {run.id: run for run in runs}

    def _group(self, run_id: str):
        if self._file is None:
            raise schema.DatasetError(f"{self.path} is closed; read runs inside `with faultgen.open(...)`")
        return self._file["runs"][run_id]

    def close(self) -> None:
        """Close the file (runs keep what they read)."""
        self._stack.close()
        self._file = None

    def __enter__(self) -> Dataset:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __len__(self) -> int:
        return len(self.runs)

    def __getitem__(self, key):
        """A run by position (int, slice) or by id (str, a friction test's too); raises KeyError naming the runs."""
        if isinstance(key, str):
            if key not in self._by_id:
                raise KeyError(f"{self.path} has no run {key!r}; runs: {', '.join(list(self._by_id)[:10])}")
            return self._by_id[key]
        return self.runs[key]

    def __iter__(self) -> Iterator[Run]:
        return iter(self.runs)

    def __repr__(self) -> str:
        return f"<faultgen.Dataset {self.path} ({len(self.runs)} runs, {self.kind})>"

    @property
    def kind(self) -> str:
        """"fleet" (daily records of robots, `faultgen fleet`), "sweep" or "run" (one run)."""
        if isinstance(self.grid, dict) and "fleet" in self.grid or any(r.sample in ("day", "log") for r in self.runs):
            return "fleet"
        return "sweep" if len(self.runs) > 1 or self.grid else "run"

    @property
    def unhashed(self) -> str:
        """A note when runs lack the program hash (files written before it): analyses then pair them
        by their ``task`` label alone, which two different programs may share; "" otherwise."""
        old = [r for r in self.runs if r.program_sha256 is None and not r.measured]  # a log has no program
        if not old:
            return ""
        return (f"note: {len(old)} of {len(self.runs)} runs of {self.path.name} were written before runs recorded "
                "their program's hash (program_sha256): they are paired by their task label alone, so two programs "
                "saved under one label would be compared; simulate them again with this version to be sure")

    @property
    def healthy(self) -> tuple[Run, ...]:
        """Runs without wear or fault."""
        return tuple(r for r in self.runs if not r.failing)

    @property
    def failing(self) -> tuple[Run, ...]:
        """Runs with wear or a fault."""
        return tuple(r for r in self.runs if r.failing)

    def labels(self) -> pd.DataFrame:
        """One row per run: id, robot, task, friction_model, seed, cycles, worn_axes (text, "2 5"),
        fault (effect:parameter or ""), sample, has_signals."""
        import pandas as pd

        return pd.DataFrame([dict(run=r.id, robot=r.robot, task=r.task, friction_model=r.friction_model,
                                  seed=r.seed, cycles=r.cycles, worn_axes=" ".join(map(str, r.worn_axes)),
                                  fault="" if r.fault is None else f"{r.fault.get('effect')}:{r.fault.get('parameter')}",
                                  sample=r.sample, has_signals=r.has_signals) for r in self.runs])

    def features(self) -> pd.DataFrame:
        """Every per-cycle quantity as one tidy table: one row per (run, recorded cycle, axis).

        Columns: ``run``, the labels of :data:`faultgen.data.summary.FEATURE_LABELS`, ``worn_axes``
        (text, "2" or "2 5"; "" for none), ``cycle`` (1-based), ``axis`` (1..N), ``worn``,
        ``wear_pct`` (true wear of the axis, %), every "cycle, axis" array of
        :data:`faultgen.data.schema.ARRAYS` and of the duty arrays (empty for runs without), each
        histogram as one column per bin (``torque_hist_1`` ..), and the operating-condition arrays
        of runs that have them. ``DataFrame.attrs["units"]`` maps each column to its unit.
        """
        import pandas as pd

        arrays = schema.ARRAYS
        per_cycle = [name for name, (_, axes, _) in arrays.items() if axes == "cycle, axis"]
        histograms = [name for name, (_, axes, _) in arrays.items() if axes == "cycle, axis, bin"]
        frames = []
        for run in self.runs:
            n_cycles, n_axes = run.array("friction_multiplier").shape
            worn = set(run.worn_axes)
            columns = {"run": run.id, "robot": run.robot, "task": run.task, "friction_model": run.friction_model,
                       "seed": run.seed, "worn_axes": " ".join(str(a) for a in sorted(worn)),
                       "cycle": np.repeat(run.recorded, n_axes), "axis": np.tile(np.arange(1, n_axes + 1), n_cycles),
                       "worn": np.tile([a in worn for a in range(1, n_axes + 1)], n_cycles),
                       "wear_pct": run.wear.ravel()}
            duty = list(schema.DUTY_ARRAYS) if run.has(*schema.DUTY_ARRAYS) else []
            columns.update({name: run.array(name).ravel() if run.has(name) else np.full(n_cycles * n_axes, np.nan)
                            for name in (*per_cycle, *duty)})  # an imported run has no simulated truth: NaN
            for name in schema.condition_arrays(run.conditions):  # per cycle, per axis or per unit, to rows
                values, axes = run.array(name), schema.CONDITION_ARRAYS[name][1]
                columns[name] = (values.ravel() if axes == "cycle, axis" else np.repeat(values, n_axes)
                                 if axes == "cycle" else np.tile(values, n_cycles))
            for name in histograms:
                bins = run.array(name).reshape(n_cycles * n_axes, -1)
                columns.update({f"{name}_{k + 1}": bins[:, k] for k in range(bins.shape[1])})
            frames.append(pd.DataFrame(columns))
        table = pd.concat(frames, ignore_index=True)
        table.attrs["units"] = {"wear_pct": "%", **{name: arrays[name][0] for name in per_cycle},
                                **{name: spec[0] for name, spec in schema.DUTY_ARRAYS.items() if name in table},
                                **{name: spec[0] for name, spec in schema.CONDITION_ARRAYS.items() if name in table},
                                **{c: arrays[c.rsplit("_", 1)[0]][0] for c in table.columns
                                   if c.rsplit("_", 1)[0] in histograms}}
        return table


def list_runs(path: str | Path) -> list[str]:
    """Run ids of a dataset, in file order."""
    with open_file(path) as f:
        return list(f["runs"])


def runs_with(path: str | Path, names: Iterable[str]) -> list[str]:
    """Run ids of a dataset, in file order, that hold every array of ``names`` (e.g. the
    :data:`~faultgen.data.schema.DUTY_ARRAYS`, which runs simulated before they existed lack)."""
    names = list(names)
    with open_file(path) as f:
        return [run_id for run_id in f["runs"] if all(name in f["runs"][run_id] for name in names)]


def read_run(path: str | Path, run_id: str | None = None,
             names: Iterable[str] | None = None) -> tuple[dict[str, np.ndarray], dict]:
    """Read one run: its arrays by name and its attributes (labels and provenance).

    ``run_id`` may be omitted for a file with one run; ``names`` limits the arrays read (default:
    all, see :data:`faultgen.data.schema.ARRAYS`). Raises
    :class:`~faultgen.data.schema.DatasetError` if the file is not a finished faultgen file, has
    no such run, or the run has no such array.
    """
    with open_file(path) as f:
        ids = list(f["runs"])
        if run_id is None:
            if len(ids) != 1:
                raise schema.DatasetError(f"{path} has {len(ids)} runs; name one: {', '.join(ids[:10])}")
            run_id = ids[0]
        if run_id not in f["runs"]:
            raise schema.DatasetError(f"{path} has no run {run_id!r}; runs: {', '.join(ids[:10])}")
        group = f["runs"][run_id]
        wanted = list(group) if names is None else list(names)
        missing = [name for name in wanted if name not in group]
        if missing:
            why = ""
            if not group.attrs.get("signals", True) and schema.ARRAYS.get(missing[0], ("", ""))[1] == schema.SIGNAL_AXES:
                why = ("; it was recorded without signals (features only): simulate it again with signals "
                       "(`faultgen sweep` without --features-only) to use this command")
            raise schema.DatasetError(f"{path}: run {run_id!r} has no array {missing[0]!r}{why}")
        problems = attribute_problems(group)
        if problems:
            raise schema.DatasetError(f"{path}: run {run_id!r}: {problems[0]} (faultgen validate {path} lists every problem)")
        arrays = {name: inputs.bounded_dataset(group, name, path, kinds=schema.kinds(name))[()] for name in wanted}
        for name, value in arrays.items():
            if value.dtype.kind == "f" and not np.all(np.isfinite(value)):
                raise schema.DatasetError(f"{path}: run {run_id!r}: {name} holds non-finite values; the file is corrupted "
                                   f"(faultgen validate {path})")
        attrs = {key: attr(group.attrs[key]) for key in group.attrs}
    return arrays, attrs


def labels(path: str | Path) -> list[dict]:
    """The labels of every run, one dict per run (with its ``run`` id), in file order."""
    with open_file(path) as f:
        for run_id in f["runs"]:
            problems = attribute_problems(f["runs"][run_id])
            if problems:
                raise schema.DatasetError(f"{path}: run {run_id!r}: {problems[0]} (faultgen validate {path} lists every "
                                   "problem)")
        return [{"run": run_id, **{k: attr(v) for k, v in f["runs"][run_id].attrs.items()}} for run_id in f["runs"]]


def open(path: str | Path) -> Dataset:  # noqa: A001 (faultgen.open, as the builtin for files)
    """Open a finished faultgen dataset for reading: a :class:`Dataset` (a context manager).

    Raises
    ------
    faultgen.data.schema.DatasetError
        If ``path`` does not exist, is not HDF5, is not a faultgen file or is incomplete (its
        writer did not finish), or a run's labels do not parse; the message says which. Reading an
        array that holds non-finite values raises it too.
    """
    return Dataset(path)


