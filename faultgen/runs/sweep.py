"""Wear sweeps: a grid of runs (robot x task x worn axis x wear x schedule x seed) into one dataset.

Every run is simulated by a worker (joblib processes locally, or Dask distributed workers) and
written to its own part file in ``<out>.parts/``, atomically: by a local worker itself, by this
process for a Dask worker, which sends the run back (:mod:`faultgen.runs.cluster`). When every run is
there, the parts are merged into the dataset ``<out>`` (renamed into place last) and the part
folder is removed. Running the same sweep again after a crash, kill or Ctrl-C resumes: finished parts are
kept as they are and only the missing runs are simulated.

A sweep holds a lock on its output (``.<out>.lock`` beside it, an OS file lock, ``flock``)
for as long as it runs, and names itself in ``<out>.parts/sweep.json``: a second sweep on the
same output refuses at once, naming the first. The kernel releases the lock of a killed sweep, so
the next one takes it over (and says so). The lock file is removed when the sweep ends.

Whatever ends the sweep's own process (Ctrl-C, SIGTERM, SIGKILL), its local workers end too:
each watches its parent and exits within a second of it (:func:`_watch_parent`); a SIGTERM is
handled as a Ctrl-C (the workers are stopped, the message says what is kept and how to resume).
"""

from __future__ import annotations

import ctypes
import datetime
import errno
import fcntl
import gc
import itertools
import json
import logging
import os
import shutil
import signal
import socket
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Self

import numpy as np
from tqdm.auto import tqdm

from faultgen import axes as axis_numbers
from faultgen import inputs
from faultgen.checks import MAX_SEED
from faultgen.data import atomic, dataset
from faultgen.effects import friction
from faultgen.model import robots
from faultgen.operation import faults, programs, tasks, wear
from faultgen.operation.conditions import Conditions
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim

log = logging.getLogger(__name__)

#: Named grids. quick: a small grid for a first look (under a minute on 2 cores).
#: j2: thesis ch. 6 (IRB 6700, 3 tasks, no wear + each axis, exp4 to +20 % over 100 cycles).
#: c2: thesis ch. 3 (PUMA 560, 3 tasks x 6 axes x {10, 20} % logistic over 120 hours of one-minute
#: cycles, the first ten cycles of every hour recorded, as the torque of ch. 3.4 is sampled); features
#: only unless ``signals=True`` (the signals would take 16 GB; detection gives the same table without).
PRESETS = {
    "quick": dict(robots=["irb6700"], tasks=list(tasks.TASKS), axes=[0, 1, 2, 3, 4, 5, 6], increases=[20.0],
                  schedules=["exp4"], cycles=100, record=list(range(10, 101, 10))),
    "j2": dict(robots=["irb6700"], tasks=list(tasks.TASKS), axes=[0, 1, 2, 3, 4, 5, 6], increases=[20.0],
               schedules=["exp4"], cycles=100, record="all"),
    "c2": dict(robots=["puma560"], tasks=list(tasks.TASKS), axes=[0, 1, 2, 3, 4, 5, 6], increases=[10.0, 20.0],
               schedules=["logistic"], cycles=120 * 60, record={"period": 60, "first": 10}, signals=False),
}


class SweepError(RuntimeError):
    """A sweep could not finish; the message says what to do. Finished runs are kept."""

    #: The command line's exit code for it (faultgen.cli.base.Command): a run failed.
    exit_code = 1


class SweepRefused(SweepError):
    """A sweep refused to start (its output exists, or another sweep is writing it); nothing ran."""

    exit_code = 2


class SweepInterrupted(SweepError):
    """A sweep was interrupted (Ctrl-C); the message says how many runs are kept and how to resume."""

    exit_code = 130  # as a shell reports a process ended by SIGINT (143 for SIGTERM)
    message_prefix = ""  # a report of what was kept, not an error

    def __init__(self, message: str, exit_code: int = 130) -> None:
        super().__init__(message)
        self.exit_code = exit_code


class _Terminated(KeyboardInterrupt):
    """SIGTERM, raised where a Ctrl-C would be, so that a sweep stops the same way (:class:`_CtrlC`)."""


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
    conditions : dict or None
        Operating conditions of every run (:meth:`faultgen.operation.conditions.Conditions.from_dict`:
        ``thermal``, ``payloads``, ``spread``, ``task_mix`` tables, ``cycles_per_day``, ``start_day``,
        ``hours``); None: none, the runs differ from their references only by wear.
    fault : str or None
        A fault other than friction wear for the worn axes, ``EFFECT:AXIS:PARAMETER:FINAL[:key=value,...]``
        (:class:`faultgen.operation.faults.FaultSpec`, the one fault text of every command): with
        AXIS ``each`` (``backlash:each:width:0.01``) each axis of ``axes`` but 0 gets it instead of friction
        wear; with a number, ``axes`` may wear only that axis (and 0). ``increases`` and
        ``schedules`` are then unused; ``kind=...`` shapes its growth.
    signals : bool
        Keep the 250 Hz signals (False: features and truth only, a fraction of the size; the
        isolators and ``faultgen detect`` then work from the stored per-cycle features; the speed
        window of ``bench-isolators`` needs the signals).

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
    conditions: dict | None = None
    fault: str | None = None
    signals: bool = True

    def __post_init__(self) -> None:
        for name in ("robots", "tasks", "axes", "increases", "schedules", "seeds"):
            value = getattr(self, name)
            if isinstance(value, (str, bytes)) or not isinstance(value, (list, tuple)) or not value:
                raise ValueError(f"grid field {name!r} must be a non-empty list, got {value!r}")
        for axis in self.axes:
            if not isinstance(axis, int) or not 0 <= axis <= axis_numbers.MAX_AXES:
                raise ValueError(f"worn axis {axis!r} is out of range 0..{axis_numbers.MAX_AXES} (0 = no wear)")
        friction.check_model(self.friction)
        if self.fault is not None:
            spec = faults.FaultSpec.parse(self.fault)
            worn = sorted(set(self.axes) - {0})
            if spec.axis is not None and worn != [spec.axis]:
                raise ValueError(
                    f"fault {self.fault!r} is on axis {spec.axis} but the grid wears axes "
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
        # builds and validates every run configuration, once: runs() returns these
        object.__setattr__(self, "_runs", self._build_runs())

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
        known = {f.name for f in fields(cls)} | {"preset"}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(f"{path}: unknown key {unknown[0]!r}; expected: {', '.join(sorted(known))}")
        preset = data.pop("preset", None)
        if not preset:
            missing = [f.name for f in fields(cls) if f.name in ("robots", "tasks", "axes") and f.name not in data]
            if missing:
                raise ValueError(f"{path}: no key {missing[0]!r} (and no preset); a grid file needs robots, tasks "
                                 "and axes, or preset = \"quick\" (or j2, c2)")
        return cls.from_preset(preset, **data) if preset else cls(**data)

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
        if self.conditions is not None and not isinstance(self.conditions, dict):
            raise ValueError(f"grid field 'conditions' must be a table, got {self.conditions!r}")
        conditions = Conditions.from_dict(self.conditions or {})
        out: dict[str, sim.RunConfig] = {}
        named: dict[str, str] = {}  # run ids carry the robot's name: two models of one name would share them
        for robot in self.robots:
            first = named.setdefault(robots.load(robot).name, str(robot))
            if first != str(robot) and robots.load(first).path != robots.load(robot).path:
                raise ValueError(f"robots {first!r} and {str(robot)!r} are both named {robots.load(robot).name!r}; "
                                 "run ids need different names (rename one folder or MJCF file)")
        self._check_programs()
        for robot, task, axis, seed in itertools.product(self.robots, self.tasks, self.axes, self.seeds):
            name, n_axes = robots.load(robot).name, robots.load(robot).n_axes
            if axis > n_axes:
                raise ValueError(f"worn axis {axis} is out of range 0..{n_axes} of robot {name} (0 = no wear)")
            # a run without wear is one run, whatever the wear levels and schedules of the grid
            variants = [(None, 0.0)] if axis == 0 or self.fault else itertools.product(self.schedules, self.increases)
            for kind, pct in variants:
                plan, fault = wear.WearPlan({}), None
                if axis == 0:
                    label = "nowear"
                elif self.fault:
                    fault = faults.FaultSpec.parse(self.fault).fault(self.cycles, axis=axis)
                    label = f"axis{axis}-{fault.effect}{fault.final:g}"
                else:
                    plan = wear.WearPlan.from_specs([f"{axis}:{kind}:{pct:g}"], last_cycle=self.cycles)
                    label = f"axis{axis}-{kind}{pct:g}"
                run_id = f"{name}-{programs.label(task)}-{label}-seed{seed}"
                if run_id in out and out[run_id].task != task:
                    raise ValueError(f"tasks {out[run_id].task!r} and {task!r} would both make run {run_id!r}; "
                                     "give the program files different file names")
                out[run_id] = sim.RunConfig(
                    robot=robot, task=task, friction=self.friction, wear=plan, cycles=self.cycles, record=record,
                    seed=seed, noise=noise, nthread=1, conditions=conditions, signals=bool(self.signals), fault=fault)
        return list(out.items())

    def _check_programs(self) -> None:
        """Refuse two different programs under one label (a run's ``task``): analyses would take
        one for the other (:func:`faultgen.operation.programs.identity` labels an edited export by
        its file name; two files of one ``name`` still collide)."""
        seen: dict[tuple[str, str], tuple[str, str]] = {}  # (robot, label) -> (task as given, program hash)
        for robot, task in itertools.product(self.robots, self.tasks):
            label, digest = programs.identity(robot, task)
            first, first_digest = seen.setdefault((robots.load(robot).name, label), (task, digest))
            if first_digest != digest:
                raise ValueError(f"tasks {first!r} and {task!r} are different programs (sha256 {first_digest[:12]}... "
                                 f"and {digest[:12]}...) under one label {label!r}: give the program file its own "
                                 "`name` (or file name) so the dataset can tell them apart")

    def to_json(self) -> str:
        return json.dumps(asdict(self), sort_keys=True)


@dataclass(frozen=True)
class RunStats:
    """What one worker did: simulated seconds and the wall time of each phase, s; on a Dask
    cluster also where (``worker``, its address) and the worker process's peak resident set so far
    (``memory``, bytes; 0 for local workers). A run sent back through Dask is written by the client:
    ``writing`` is then the client's time."""

    run_id: str
    simulated: float
    total: float
    stepping: float
    writing: float
    worker: str = ""
    memory: int = 0


def simulate_and_write(run_id: str, config: sim.RunConfig, part: Path, command: str = "",
                       labelled: sim.RunConfig | None = None) -> RunStats:
    """Worker task: simulate one run and write it to its part file (atomically), labelled with
    ``labelled`` (the client's configuration when ``config`` names its robot or program by an
    absolute path for a cluster's workers: :func:`faultgen.runs.cluster.for_workers`)."""
    # A worker draws no progress bar: a thread lock for tqdm, not its default process-shared one (a
    # named semaphore, reported as leaked at exit when a Ctrl-C makes the sweep stop its workers).
    tqdm.set_lock(threading.RLock())
    started = time.perf_counter()
    result = sim.simulate(config, progress=False)
    writing = time.perf_counter()
    if labelled is not None:
        result = replace(result, config=labelled)
    dataset.write_run(part, result, run_id=run_id, command=command)
    done = time.perf_counter()
    stats = RunStats(run_id, result.tau_m.shape[0] * result.t[-1], done - started, result.stepping_time,
                     done - writing)
    del result
    _release_memory()
    return stats


def _in_worker(sweep_pid: int, *call) -> RunStats:
    """:func:`simulate_and_write` as a joblib worker runs it for the sweep of process ``sweep_pid``.

    A Ctrl-C reaches the workers too (they are in the terminal's process group). One that lands
    in a weakref callback or a ``__del__`` of a worker cannot be raised there, and Python would
    print "Exception ignored ... KeyboardInterrupt" in the middle of the sweep's message; a worker
    does not print it: the sweep's own process handles the Ctrl-C and stops the workers
    (:class:`_CtrlC`). In the sweep's own process (joblib with one job) nothing changes.
    """
    if os.getpid() != sweep_pid:
        _quiet_unraisable_interrupts()
    return simulate_and_write(*call)


def _start_worker(sweep_pid: int) -> None:
    """A loky worker's initializer: watch the sweep's process from the worker's start; a worker
    whose sweep ended while it started (it has another parent already) ends at once. A SIGTERM
    sent to the whole process group (``timeout``, a process manager, a closed terminal) is the
    sweep's to handle: it stops its workers and says what is kept and how to resume; a worker that
    ended on it first left loky's semaphores for Python to report as leaked, and the sweep no word."""
    if os.getpid() == sweep_pid:
        return
    if os.getppid() != sweep_pid:
        os._exit(1)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    _watch_parent(sweep_pid)


def _start_resource_tracker() -> None:
    """Start loky's resource tracker (a process of its own, started once) ignoring SIGTERM, as the
    workers do (:func:`_start_worker`): a group-wide SIGTERM must not end it before the sweep has
    stopped its workers and released their semaphores (it then reports them as leaked). It ends
    when the sweep's process does."""
    from joblib.externals.loky.backend import resource_tracker

    if threading.current_thread() is not threading.main_thread():
        return
    previous = signal.signal(signal.SIGTERM, signal.SIG_IGN)  # inherited by the process started now
    try:
        resource_tracker.ensure_running()
    finally:
        signal.signal(signal.SIGTERM, previous)


_WATCHED: set[int] = set()


def _watch_parent(sweep_pid: int, period: float = 0.5) -> None:
    """End this worker process within ``period`` s once the sweep's process ``sweep_pid`` is gone.

    A killed sweep (SIGKILL, or SIGTERM under a process manager) cannot stop its workers, and
    loky's workers would go on simulating the rest of the grid, then idle for minutes (issue 42).
    The kernel is asked to send this process SIGKILL when its parent ends (``PR_SET_PDEATHSIG``,
    Linux), and a daemon thread checks every ``period`` s that the parent is still ``sweep_pid``
    (another OS); either way the worker ends at once, its unfinished part left as a hidden
    temporary file that the next sweep removes. Set once per worker process, from its start (the
    loky initializer :func:`_start_worker`); a process whose parent is not the sweep's is left
    alone.
    """
    if sweep_pid in _WATCHED or os.getppid() != sweep_pid:  # not a worker the sweep started: nothing to watch
        return
    _WATCHED.add(sweep_pid)
    try:
        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # not Linux: the thread below does it
        pass
    if os.getppid() != sweep_pid:  # the sweep ended before the request was made
        os._exit(1)

    def watch() -> None:
        while True:
            time.sleep(period)
            try:
                os.kill(sweep_pid, 0)
            except ProcessLookupError:
                os._exit(1)
            except PermissionError:
                pass
            if os.getppid() != sweep_pid:  # orphaned (reparented to init or a subreaper): the sweep is gone
                os._exit(1)

    threading.Thread(target=watch, name="faultgen-watch-sweep", daemon=True).start()


def _quiet_unraisable_interrupts() -> None:
    """From now on, a KeyboardInterrupt that cannot be raised is not printed (this process only;
    every other unraisable exception still goes to the hook there was before)."""
    previous = sys.unraisablehook
    if getattr(previous, "quiet_interrupts", False):  # a worker runs many runs: set once
        return

    def hook(unraisable) -> None:
        if not isinstance(unraisable.exc_value, KeyboardInterrupt):
            previous(unraisable)

    hook.quiet_interrupts = True
    sys.unraisablehook = hook


def _release_memory() -> None:
    """Give the run's freed memory back to the OS. glibc keeps freed heap memory, so a worker's
    resident size would ratchet up run after run, and joblib's workers restart themselves (losing
    their prepared models) once it grows 300 MB past its size after the first run."""
    gc.collect()
    try:
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):  # not glibc: nothing to trim
        pass


def parts_folder(out: Path) -> Path:
    return out.with_name(out.name + ".parts")


def _finished(part: Path, config: sim.RunConfig) -> bool:
    """True if ``part`` is a complete part file of exactly this configuration."""
    try:
        (attrs,) = dataset.labels(part)
    except (dataset.DatasetError, ValueError):
        return False
    return attrs.get("config") == dataset.config_key(config)


def finished_runs(grid: Grid, out: str | Path) -> list[str]:
    """Ids of the runs of ``grid`` already finished in the part folder of ``out``."""
    parts = parts_folder(Path(out))
    return [run_id for run_id, config in grid.runs() if _finished(parts / f"{run_id}.h5", config)]


def run(grid: Grid, out: str | Path, jobs: int = 1, scheduler: str | None = None, progress: bool = True,
        command: str = "", on_run: Callable[[RunStats], None] | None = None,
        timings: dict | None = None, overwrite: bool = False,
        on_start: Callable[[int, int], None] | None = None, shared: bool = False) -> Path:
    """Simulate every run of ``grid`` and write the dataset ``out``; resume if parts exist.

    Parameters
    ----------
    grid : Grid
    out : path of the dataset file to write.
    jobs : int
        Local worker processes (joblib); ignored with ``scheduler``.
    scheduler : str, optional
        Address of a Dask distributed scheduler (``tcp://host:port``). Its workers send each run
        back to this process, which writes it (:mod:`faultgen.runs.cluster`): they need not see
        the folder of ``out``.
    progress : bool
        Show a progress bar over runs, with the time left.
    command : str
        The command line, stored as provenance.
    on_run : callable, optional
        Called in this process with the :class:`RunStats` of each run as it finishes.
    timings : dict, optional
        Filled with the wall time of the final merge (``"merge"``, s), for benchmarks.
    overwrite : bool
        Replace ``out`` if it exists; by default an existing ``out`` is refused.
    on_start : callable, optional
        Called once the sweep holds its output, with (runs in the grid, runs already finished).
    shared : bool
        With ``scheduler``: the workers write the part files themselves, in the folder of ``out``,
        which they must all see at its absolute path (a shared file system; checked first).

    Returns
    -------
    Path of the dataset.

    Raises
    ------
    SweepRefused
        Before anything runs, if ``out`` exists (and not ``overwrite``) or another sweep is
        writing it (the message names that sweep: pid, host, start time, command).
    SweepInterrupted
        On Ctrl-C (KeyboardInterrupt): the workers are stopped, and the message says how many
        runs are kept and how to resume.
    SweepError
        If the output folder cannot be written or a run fails (the message names the run and says
        what to do); every finished run stays in the part folder for the next attempt.
    """
    out = Path(out)
    plan = grid.runs()
    parts = parts_folder(out)
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise SweepRefused(f"jobs {jobs!r}: expected a whole number >= 1")
    with _lock(out, parts):
        if out.exists() and not overwrite:
            raise SweepRefused(f"{out} exists; pass --overwrite to replace it or choose another output")
        try:
            _prepare(out, parts)
            with _claim(out, parts, command):
                todo = [(run_id, config) for run_id, config in plan if not _finished(parts / f"{run_id}.h5", config)]
                todo.sort(key=_expected_cost, reverse=True)  # longest first: workers finish close together
                _check_space(out, parts, plan, todo)
                if on_start is not None:
                    on_start(len(plan), len(plan) - len(todo))
                with _CtrlC() as ctrl_c:
                    try:
                        with tqdm(total=len(plan), initial=len(plan) - len(todo), unit="run", disable=not progress,
                                  desc=f"sweep {out.name}") as bar:
                            for stats in _execute(todo, parts, min(jobs, max(len(todo), 1)), scheduler, command,
                                                  shared, bar):
                                bar.update(1)
                                if on_run is not None:
                                    on_run(stats)
                    except KeyboardInterrupt as interrupt:
                        ctrl_c.stopping = True
                        kept = len(finished_runs(grid, out))
                        what, code = (("terminated (SIGTERM)", 143) if isinstance(interrupt, _Terminated)
                                      else ("interrupted", 130))
                        if not kept:  # the part folder goes too: nothing to point at
                            raise SweepInterrupted(f"{what}: none of the {len(plan)} runs had finished; run the "
                                                   "same command to start again", code) from None
                        raise SweepInterrupted(f"{what}: {kept} of {len(plan)} runs kept in {parts}; run the "
                                               "same command to resume", code) from None
                started = time.perf_counter()
                try:
                    dataset.merge([(run_id, parts / f"{run_id}.h5") for run_id, _ in plan], out, command=command,
                                  grid=grid.to_json())
                except OSError as err:
                    raise SweepError(f"cannot write {out}: {err.strerror or err}; every run is kept in {parts}: "
                                     "free space or fix permissions and run the same command again") from None
                if timings is not None:
                    timings["merge"] = time.perf_counter() - started
        except BaseException:
            _remove_if_empty(parts)  # no debris: a sweep that kept nothing leaves no part folder
            raise
        shutil.rmtree(parts)
    return out


def lock_path(out: Path) -> Path:
    """The lock file a sweep holds while it writes ``out``: hidden, beside it, removed when the
    sweep ends (a killed sweep's stays, empty, until the next sweep of ``out`` ends)."""
    return out.with_name(f".{out.name}.lock")


@contextmanager
def _lock(out: Path, parts: Path) -> Iterator[None]:
    """Hold the lock of ``out`` (:func:`lock_path`); refuse at once, naming the holder, if it is taken.

    An exclusive ``flock`` on the lock file. The holder removes the file before it lets the lock
    go, so a sweep that opened the file just before must find, once it holds the lock, that the
    path still names the file it locked; if not, it tries again on the new file.
    """
    if not (out.parent if str(out.parent) else Path(".")).is_dir():
        raise SweepError(f"cannot write {out}: folder {out.parent} does not exist")
    path = lock_path(out)
    while True:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as err:
            raise SweepError(f"cannot write to {out.parent}: {err.strerror}; choose another output path") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise SweepRefused(f"another sweep is writing {out}: {_describe_holder(parts)}; wait for it to finish "
                               "or stop it (a killed sweep's lock is taken over by the next one)") from None
        try:
            if os.stat(path).st_ino == os.fstat(fd).st_ino:
                break
        except FileNotFoundError:
            pass
        os.close(fd)  # the holder removed the file we opened: lock the new one
    try:
        yield
    finally:
        try:
            path.unlink(missing_ok=True)
        finally:
            os.close(fd)


def _remove_if_empty(folder: Path) -> None:
    try:
        folder.rmdir()
    except OSError:  # holds finished runs, or is gone
        pass


def _check_space(out: Path, parts: Path, plan, todo) -> None:
    """Refuse, before any run, a sweep whose parts and merged dataset would not fit on the disk."""
    needed = sum(dataset.estimated_size(config) for _, config in todo)
    needed += sum(dataset.estimated_size(config) for _, config in plan)  # the merged dataset
    try:
        atomic.check_writable(parts / "x.h5", needed)
    except OSError as err:
        raise SweepRefused(f"{err.strerror}; free some space or choose another output (finished runs are kept "
                           f"in {parts})" if err.errno == errno.ENOSPC else f"{err.strerror}") from None


@contextmanager
def _claim(out: Path, parts: Path, command: str) -> Iterator[None]:
    """Name this sweep in ``<parts>/sweep.json`` while it runs (what a refused second sweep prints).

    The record is removed whenever this sweep ends, even by an error or Ctrl-C, so a record found
    here was left by a killed sweep: that is said, and stale temporary files of ``out`` removed.
    """
    record = parts / "sweep.json"
    try:
        if record.exists():
            log.warning("took over %s from a sweep that was killed (%s); its finished runs are kept", out,
                        _describe_holder(parts))
        try:
            atomic.write_text(record, json.dumps({
                "pid": os.getpid(), "host": socket.gethostname(), "command": command,
                "started": datetime.datetime.now().astimezone().isoformat(timespec="seconds")}))
        except OSError as err:
            raise SweepError(f"cannot write {record}: {err.strerror or err}; free some space or choose another "
                             "output") from None
        atomic.remove_stale(out)
        yield
    finally:
        record.unlink(missing_ok=True)


def _describe_holder(parts: Path) -> str:
    """'pid 123 on host, started 2026-11-22T12:00:00+00:00: faultgen sweep ...', from the record."""
    try:
        holder = json.loads((parts / "sweep.json").read_text())
        text = f"pid {holder['pid']} on {holder['host']}, started {holder['started']}"
        return text + (f": {holder['command']}" if holder.get("command") else "")
    except (OSError, ValueError, KeyError):
        return "a sweep that has not named itself yet"


def _expected_cost(item: tuple[str, sim.RunConfig]) -> float:
    """Simulated seconds of a run: recorded cycles times the task's cycle time."""
    config = item[1]
    return len(config.recorded_cycles) * sim.cycle_duration(config.robot, config.task)


def _prepare(out: Path, parts: Path) -> None:
    """Make the part folder, check it is writable, and drop temporary files of killed writers."""
    try:
        parts.mkdir(parents=False, exist_ok=True)
        probe = parts / ".write-test"
        probe.write_bytes(b"")
        probe.unlink()
    except FileNotFoundError:
        raise SweepError(f"cannot write {out}: folder {out.parent} does not exist") from None
    except OSError as err:
        _remove_if_empty(parts)
        raise SweepError(f"cannot write to {out.parent}: {err.strerror}; choose another output path") from None
    for stale in parts.glob(".*.part"):  # no worker runs while this sweep holds the lock: a killed one left it
        log.warning("removed %s, an unfinished part left by a killed worker", stale)
        stale.unlink()


class _CtrlC:
    """While a sweep runs, every Ctrl-C stops it once, wherever in this process it lands.

    Python raises a SIGINT as KeyboardInterrupt in whatever the main thread runs at that moment.
    If that is a weakref callback or a ``__del__`` (joblib and loky free locks and queues through
    such callbacks while the workers' results are collected), the exception cannot propagate:
    Python prints "Exception ignored in ... KeyboardInterrupt" and goes on as if no key had been
    pressed. A SIGTERM is raised as :class:`_Terminated`, a KeyboardInterrupt, and stops the sweep
    the same way. Within this block such an interrupt is not printed but sent again as SIGINT 0.1 s
    later, once the callback is over, so it reaches the sweep. And once the sweep stops (a
    KeyboardInterrupt is being handled, or :attr:`stopping` is set), a further SIGINT (a second
    Ctrl-C, or one sent again after the workers' own interrupts already stopped the sweep) is not
    raised inside the clean-up. Only in the main thread; SIGINT only when it raises
    KeyboardInterrupt (not under ``nohup`` or in a background job), SIGTERM always.
    """

    RESEND_AFTER = 0.1  # s: a callback is over long before; a person does not notice

    def __enter__(self) -> Self:
        self.stopping = False
        self._resends: list[threading.Timer] = []
        self._previous_handler = signal.getsignal(signal.SIGINT)
        self._main = threading.current_thread() is threading.main_thread()
        # SIGTERM is handled in any case (a sweep started in the background, where SIGINT is
        # ignored, died on it silently, issue 51); SIGINT only where it raises KeyboardInterrupt
        self._active = self._main and self._previous_handler is signal.default_int_handler
        if self._main:
            self._previous_hook = sys.unraisablehook
            sys.unraisablehook = self._unraisable
            self._previous_term = signal.signal(signal.SIGTERM, self._on_sigterm)
        if self._active:
            signal.signal(signal.SIGINT, self._on_sigint)
        return self

    def __exit__(self, *exc) -> None:
        if not self._main:
            return
        for resend in self._resends:
            resend.cancel()
        if self._active:
            signal.signal(signal.SIGINT, self._previous_handler)  # a pending SIGINT is handled before, by ours
        signal.signal(signal.SIGTERM, self._previous_term)
        sys.unraisablehook = self._previous_hook

    def _on_sigint(self, signum, frame) -> None:
        if self.stopping or isinstance(sys.exc_info()[1], KeyboardInterrupt):
            return
        raise KeyboardInterrupt

    def _on_sigterm(self, signum, frame) -> None:
        if self.stopping or isinstance(sys.exc_info()[1], KeyboardInterrupt):
            return
        raise _Terminated

    def _unraisable(self, unraisable) -> None:
        if not isinstance(unraisable.exc_value, KeyboardInterrupt):
            self._previous_hook(unraisable)
        elif not self.stopping:
            again = signal.SIGTERM if isinstance(unraisable.exc_value, _Terminated) else signal.SIGINT
            resend = threading.Timer(self.RESEND_AFTER, os.kill, (os.getpid(), again))
            resend.daemon = True
            resend.start()
            self._resends.append(resend)


def _execute(todo, parts: Path, jobs: int, scheduler: str | None, command: str, shared: bool = False,
             bar=None) -> Iterator[RunStats]:
    """Run the missing runs; yield the stats of each as it finishes, in completion order."""
    if not todo:
        return
    # absolute: a worker process keeps the folder it started in, which need not be this one's now
    calls = [(run_id, config, parts.absolute() / f"{run_id}.h5", command) for run_id, config in todo]
    try:
        if scheduler:
            from faultgen.runs import cluster

            yield from cluster.execute(todo, parts, scheduler, command, shared=shared, bar=bar)
        else:
            from joblib import Parallel, delayed
            from joblib._parallel_backends import LokyBackend

            _start_resource_tracker()
            # every worker watches the sweep from its start, idle or not (:func:`_watch_parent`)
            backend = LokyBackend(initializer=_start_worker, initargs=(os.getpid(),))
            parallel = Parallel(n_jobs=jobs, return_as="generator_unordered", backend=backend)
            yield from parallel(delayed(_in_worker)(os.getpid(), *call) for call in calls)
    except KeyboardInterrupt:
        if not scheduler:
            _stop_local_workers()
        raise
    except OSError as err:
        raise SweepError(f"a run could not be written: {err}. Finished runs are kept in {parts}; free space "
                         "or fix permissions and run the same command again") from err


def _stop_local_workers() -> None:
    """Shut joblib's worker processes down and wait for them, so that nothing they hold (loky's
    semaphores) is left for Python's resource tracker to report as leaked at exit."""
    from joblib.externals.loky import get_reusable_executor

    get_reusable_executor().shutdown(wait=True, kill_workers=True)
