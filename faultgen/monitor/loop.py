"""``faultgen monitor``: a fleet's measured logs in, alarms and the worn axis out (issues 46, 60).

For each unit (a folder of ``LOGS``, its logs in stamp order, :mod:`faultgen.monitor.logs`, in
the measured format or an adapter's):

(a) the model: calibrated on the unit's first log (:func:`faultgen.calibrate.calibrate`, cached,
    refused when implausible), or a calibrated model given for every unit, or the nominal model;
(b) the twin (:class:`faultgen.monitor.twin.Twin`): the model replaying the unit's own first log,
    at each payload the logs declare, healthy and with each axis in turn worn; a unit whose twin
    cannot be built falls back to the nominal model, then to protocol own (:func:`_twin`);
(c)-(d) the unit's monitor (:class:`faultgen.monitor.scoring.UnitMonitor`): learned on the first
    logs, then every later log scored in stamp order; a log that cannot be read or replayed is
    skipped, a repair or gearbox change of ``events.csv`` closes the open alarm and the unit's
    offset is learned again, and a log whose motion left the twin's program starts a new program
    (:func:`_new_program`).

Units are scored one after another, or in ``jobs`` processes (:func:`_map`), with the same outputs.
Outputs in OUT, written together (:func:`faultgen.data.atomic.atomic_folder`): ``units.csv`` (each
unit's status and why), ``alarms.csv``, ``scores.csv``, ``rul.csv`` (:mod:`faultgen.monitor.prognosis`),
``report.html`` (:mod:`faultgen.monitor.page`), ``<unit>.png`` and the monitors' state in
``.state`` (a rerun on a grown folder scores only the new logs; JSON, never a pickle:
:mod:`faultgen.monitor.state`). Simulated cycles, calibrations and the twins' filtered program
logs are cached in ``OUT/.cache``, each checked against what it was made from; units whose first
logs trace the same motion (angles within :data:`SAME_PROGRAM` rad) and share a model share their
simulated cycles.
"""

from __future__ import annotations

import io
import shutil
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np
from tqdm.auto import tqdm

from faultgen.calibrate import plausibility
from faultgen.data import atomic, logfolder
from faultgen.effects.payload import Payload
from faultgen.model import robots
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import page, prognosis, report
from faultgen.monitor import state as stored
from faultgen.monitor.scoring import Settings, UnitMonitor
from faultgen.monitor.twin import REFERENCE_TEMPERATURE, Twin

#: Two units run the same program when their first logs have the same samples and angles within this, rad.
SAME_PROGRAM = 1e-3
#: A log whose angles lie more than this off its twin's program, rad, or whose length differs by more
#: than PROGRAM_LENGTH of it, runs another program (noise and tracking: about 1e-3 rad).
PROGRAM_CHANGE, PROGRAM_LENGTH = 0.05, 0.05
#: Effects searched when a unit's model is calibrated on its first log (faultgen.calibrate).
CALIBRATION_STEPS = 3


#: Exit status of ``faultgen monitor`` when some unit is degraded or not monitored (every output is
#: still written); 0 when every unit is monitored or still learning, 2 a refusal before any work.
EXIT_SOME_UNITS_NOT_MONITORED = 3
#: Events of ``events.csv`` after which a unit's offset is learned again and its open alarm closed.
MAINTENANCE = ("repair", "gearbox_change")
#: A unit's status in units.csv.
#: ``degraded``: under protocol own where the twin was asked for, or with logs skipped; a unit whose
#: twin uses the nominal model because its calibration failed or was implausible is ``monitored``,
#: the model column and the reason say so.
STATUSES = ("monitored", "learning", "degraded", "not monitored")


@dataclass
class _Unit:
    monitor: UnitMonitor
    model: str  # "given", "calibrated", "nominal" or "none" (protocol own)
    program: tuple[str, str] | None  # (unit, stamp) of the log the twin replays
    first: tuple[str, str]  # (stamp, SHA-256) of the unit's first log, which its calibration is made from
    entries: list[stored.Entry] = field(default_factory=list)
    skipped: list[stored.Skipped] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    maintenance: list[stored.Maintenance] = field(default_factory=list)
    program_changes: list[stored.ProgramChange] = field(default_factory=list)
    program_q: np.ndarray | None = None  # the program log's angles (read when needed; not kept in the state)
    initial_signatures: np.ndarray | None = None  # the first program's twin's, which a replay starts with


@dataclass(frozen=True)
class UnitStatus:
    """A unit's row of units.csv: its ``status`` (:data:`STATUSES`), the ``protocol`` and ``model``
    its monitor uses, the ``reason`` (fallbacks taken, logs skipped, learning progress), the number
    of logs scored (learning logs included) and the stamp of the last one."""

    unit: str
    status: str
    protocol: str
    model: str
    reason: str
    logs_scored: int
    last_log: str


@dataclass
class Outcome:
    """What :func:`monitor` did: each unit's ``monitors`` (:class:`UnitMonitor`) and ``statuses``
    (:class:`UnitStatus`), in the fleet folder's order."""

    monitors: list[UnitMonitor]
    statuses: list[UnitStatus]

    @property
    def exit_status(self) -> int:
        """0 when every unit is monitored or learning, :data:`EXIT_SOME_UNITS_NOT_MONITORED` else."""
        bad = any(s.status in ("degraded", "not monitored") for s in self.statuses)
        return EXIT_SOME_UNITS_NOT_MONITORED if bad else 0


def monitor(robot: str | Path, logs_dir: str | Path, out: str | Path, *, calibrated: str | Path | None = None,
            calibrate: bool = True, settings: Settings = Settings(), twin_temperature: bool = False,
            progress: bool = True, log_format=None, jobs: int = 1,
            failure_wear: float = prognosis.FAILURE_WEAR) -> Outcome:
    """Monitor every unit of ``logs_dir`` (module docstring).

    No unit stops the fleet: a unit whose twin cannot be built falls back (the calibrated or given
    model, then the nominal model, then ``--protocol own``: the unit against its own first logs),
    and a log that cannot be read or that the twin cannot replay is skipped; both are named in
    ``units.csv`` (:class:`UnitStatus`) and the unit's state keeps them, so a rerun does not try again.

    Parameters
    ----------
    robot : str or Path
        The robot the logs were recorded on (name, folder or MJCF).
    logs_dir : str or Path
        ``LOGS/<unit>/<stamp>.csv``.
    out : str or Path
        Output folder; an earlier run's output there is continued (its settings must match).
    calibrated : path, optional
        A ``faultgen calibrate`` output folder (or its model file) used as every unit's model.
    calibrate : bool
        Without ``calibrated``: calibrate each unit's model on its first log (True) or use the
        nominal model (False). Only the ``twin`` protocol uses a model.
    settings : Settings
    twin_temperature : bool
        The twin also predicts the temperature's effect (the model's own temperature law) instead
        of the unit's learned slope alone.
    progress : bool
    log_format : faultgen.data.adapters.Adapter, optional
        The logs' layout (``ur-rtde``, ``voraus``); the measured format when None.
    jobs : int
        Local processes scoring units in parallel (groups of units sharing a twin); the outputs are
        those of one job, bit for bit.
    failure_wear : float
        The wear estimate, % of the axis's own dry friction, that ends an axis's life: ``rul.csv`` gives each
        axis's remaining life until it (:mod:`faultgen.monitor.prognosis`).

    Returns
    -------
    Outcome
        Each unit's monitor and status; :attr:`Outcome.exit_status` for the command line.

    Raises
    ------
    ValueError
        Before any work, for the run as a whole: ``out`` that is, lies in or holds ``logs_dir``
        (:func:`faultgen.data.atomic.check_apart`), the robot, the fleet folder, a log older than the
        last one scored, a scored log that changed since, or ``out`` holding a run with other
        settings or a state or cache that does not match them (:mod:`faultgen.monitor.state`, the
        file named).
    """
    atomic.check_apart(out, logs_dir)
    prognosis.check_failure_wear(failure_wear)
    nominal = robots.load(robot)
    read_with, suffixes = fleet_logs.reader_of(log_format)
    units = fleet_logs.fleet(logs_dir, suffixes)
    out = Path(out)
    cache = out / ".cache"
    calibrated_model = _given_model(calibrated) if settings.protocol == "twin" and calibrated is not None else None
    model_source = "nominal" if settings.protocol != "twin" else (
        stored.sha256_file(calibrated_model) if calibrated_model is not None else "per-unit" if calibrate else "nominal")
    key = stored.settings_digest(settings, model_source, twin_temperature, stored.sha256_file(nominal.path),
                                 "measured" if log_format is None else repr(log_format))
    n_features = len(fleet_logs.FEATURES) * nominal.n_axes
    state = _load_state(out, units, key, settings, nominal.n_axes, n_features)
    pending = {name: _pending(name, unit_logs, state.get(name), out, logs_dir) for name, unit_logs in units.items()}
    maintenance = _maintenance_events(Path(logs_dir), units, nominal.n_axes)
    cache.mkdir(parents=True, exist_ok=True)
    programs: list[tuple[np.ndarray, tuple[str, str]]] = []
    for name, unit_logs in pending.items():  # in the folder's order: a unit may replay an earlier one's log
        if unit_logs and name not in state:
            state[name] = _new_unit(name, units, nominal, settings, calibrated_model, calibrate, programs, read_with)
    context = _Context(nominal.path, settings, calibrated_model, out, twin_temperature, log_format, units, maintenance,
                       failure_wear)
    groups = _groups({name: (state[name], logs) for name, logs in pending.items() if logs})
    bar = tqdm(total=sum(len(v) for v in pending.values()), desc="monitor", unit="log", disable=not progress)
    made: dict[str, tuple[bytes, list]] = {}  # unit -> its chart (PNG) and rows of rul.csv, made where it was scored
    for done in _map(context, groups, jobs):
        for name, unit, outputs in done:
            state[name], made[name] = unit, outputs
            bar.update(len(pending[name]))
    bar.close()
    monitors = [state[name].monitor for name in units if name in state]
    for m in monitors:
        if m.unit not in made:  # a unit with no new log
            made[m.unit] = _unit_outputs(m, failure_wear)
    statuses = [_status(name, state.get(name), settings) for name in units]
    with atomic.atomic_folder(out) as staging:
        report.write_alarms(staging / "alarms.csv", monitors)
        report.write_scores(staging / "scores.csv", monitors, nominal.n_axes)
        report.write_wear(staging / "wear.csv", monitors)
        report.write_units(staging / "units.csv", statuses)
        prognosis.write_rul(staging / "rul.csv", [row for m in monitors for row in made[m.unit][1]])
        # LOGS by its name: a report meant to be shared keeps no path of this machine (as `logs import`)
        page.write(staging, settings, robot=Path(str(robot)).name, logs=Path(logs_dir).resolve().name,
                   model=model_source, twin_temperature=twin_temperature)
        for m in monitors:
            (staging / f"{m.unit}.png").write_bytes(made[m.unit][0])
        (staging / ".state").mkdir()
        for name in units:
            if name in state:
                unit = state[name]
                stored.write_unit(staging / ".state" / f"{name}.json",
                                  stored.UnitState(name, key, unit.program,
                                                   unit.monitor.signatures if unit.initial_signatures is None
                                                   else unit.initial_signatures, unit.entries,
                                                   unit.model, unit.first, unit.skipped, unit.notes,
                                                   unit.maintenance, unit.program_changes))
    return Outcome(monitors, statuses)


@dataclass(frozen=True)
class _Context:
    """What scoring a group of units needs (sent to a worker process as it is)."""

    robot: Path
    settings: Settings
    calibrated: Path | None
    out: Path
    twin_temperature: bool
    log_format: object
    units: dict
    maintenance: dict
    failure_wear: float


def _groups(pending: dict[str, tuple[_Unit, list]]) -> list[list[tuple[str, _Unit, list]]]:
    """The units to score, one group each, in the folder's order (a twin's simulated cycles are
    shared through the disk cache: :func:`_prepare_twins` simulates them once before)."""
    return [[(name, unit, logs)] for name, (unit, logs) in pending.items()]


def _prepare_twins(context: _Context, groups: list) -> None:
    """Simulate, once and in this process, the cycles of every twin that several units share (the
    nominal or a given model on one program), so that parallel workers read them from the cache
    instead of simulating them side by side. A twin that cannot be built is left to each unit's
    own fallback (:func:`_twin`)."""
    nominal = robots.load(context.robot)
    read_with, _ = fleet_logs.reader_of(context.log_format)
    seen = set()
    for (name, unit, _), in groups:
        key = (unit.model, unit.program)
        if unit.model not in ("given", "nominal") or unit.program is None or key in seen:
            continue
        seen.add(key)
        model = str(context.calibrated) if unit.model == "given" else str(nominal.path)
        try:
            Twin(model, _log(context.units, *unit.program).path, context.out / ".cache" / "cycles", root=context.out,
                 reader=read_with)
        except stored.StateError:
            raise
        except ValueError:
            continue


def _map(context: _Context, groups: list, jobs: int):
    """Each group scored (:func:`_score_group`), in order; in ``jobs`` local processes (joblib's
    loky, started without the user's folders on their path: :func:`faultgen.children.safe_path`)
    when ``jobs`` > 1. Every group's arithmetic is the same wherever it runs, so the outputs are
    those of one job, bit for bit."""
    if jobs <= 1 or len(groups) <= 1:
        yield from (_score_group(context, group) for group in groups)
        return
    _prepare_twins(context, groups)
    from joblib import Parallel, delayed

    from faultgen import children

    with children.safe_path():
        yield from Parallel(n_jobs=min(jobs, len(groups)), return_as="generator")(
            delayed(_score_group)(context, group) for group in groups)


def _unit_outputs(monitor: UnitMonitor, failure_wear: float) -> tuple[bytes, list]:
    """A unit's control chart (PNG bytes, :func:`faultgen.monitor.report.chart`) and its rows of
    rul.csv (:func:`faultgen.monitor.prognosis.of_monitor`): made where the unit was scored, so that
    they are made in parallel too."""
    note = "wear signature match" if monitor.signatures is not None else "share of Q"
    buffer = io.BytesIO()
    report.chart(buffer, monitor, note)
    return buffer.getvalue(), prognosis.of_monitor(monitor, failure_wear)


def _score_group(context: _Context, group: list[tuple[str, _Unit, list]]) -> list[tuple[str, _Unit, tuple]]:
    """Score each unit's new logs in stamp order against the group's twin, a unit's maintenance
    events given before the first log at or after them; returns the units with their chart and
    remaining life (:func:`_unit_outputs`)."""
    nominal = robots.load(context.robot)
    read_with, _ = fleet_logs.reader_of(context.log_format)
    twins: dict[tuple, Twin] = {}
    for name, unit, unit_logs in group:
        twin = _twin(unit, context.units, nominal, context.calibrated, context.out, twins, False, read_with)
        for log in unit_logs:
            for event in context.maintenance.get(name, ()):
                done = stored.Maintenance(event.stamp, event.event, event.axis, 0)
                if event.key <= log.key and not any(m.same(done) for m in unit.maintenance):
                    unit.monitor.maintenance(event.stamp, event.event, event.axis)
                    unit.maintenance.append(stored.Maintenance(event.stamp, event.event, event.axis,
                                                               len(unit.entries)))
            twin = _score_log(unit, log, nominal, twin, context.twin_temperature, read_with, context)
    return [(name, unit, _unit_outputs(unit.monitor, context.failure_wear)) for name, unit, _ in group]


def _pending(name: str, unit_logs: list, unit: _Unit | None, out: Path, logs_dir) -> list:
    """The logs of ``name`` not yet scored (or skipped) by the run whose state is ``unit``.

    Raises
    ------
    ValueError
        The last log handled is gone, a handled log changed since (SHA-256), or a new log is older
        than the last one handled (the monitor scores in stamp order).
    """
    if unit is None:
        return unit_logs
    handled = [(e.stamp, e.sha256) for e in unit.entries] + [(k.stamp, k.sha256) for k in unit.skipped]
    by_stamp = {g.stamp: g for g in unit_logs}
    stamps = [g.stamp for g in unit_logs]
    position = {stamp: i for i, stamp in enumerate(stamps)}
    done = max((s for s, _ in handled), key=lambda s: position.get(s, -1))
    if done not in by_stamp:
        raise ValueError(f"{name}: its last scored log ({done}) is no longer in {logs_dir}; put it back or "
                         "score this folder into a new OUT")
    for stamp, sha256 in handled:
        log = by_stamp.get(stamp)
        if log is not None and stored.sha256_file(log.path) != sha256:
            raise ValueError(f"{log.path} changed since it was scored into {out} (SHA-256 {sha256[:12]}..., "
                             "now another): score this folder into a new OUT")
    seen = {s for s, _ in handled}
    late = [g for g in unit_logs[: position[done]] if g.stamp not in seen]
    if late:
        raise ValueError(f"{late[0].path} is older than the last scored log of {name} ({done}); the monitor "
                         "scores logs in stamp order: score this folder into a new OUT")
    return unit_logs[position[done] + 1:]


def _new_unit(name, units, nominal, settings: Settings, calibrated_model, calibrate: bool, programs: list,
              read_with: fleet_logs.Reader) -> _Unit:
    """A unit seen for the first time: its program (the log its twin replays) and the kind of model
    asked for (given, calibrated on its first log, nominal); protocol ``own`` without a twin or
    when its first log cannot be read. The model itself is made with the twin (:func:`_twin`),
    which falls back when it cannot be."""
    monitor = UnitMonitor(name, settings, nominal.n_axes)
    first = units[name][0]
    first_key = (first.stamp, stored.sha256_file(first.path))
    if settings.protocol != "twin":
        return _Unit(monitor, "none", None, first_key)
    try:
        program = _program(nominal, first, name, programs, read_with)
    except ValueError as err:
        return _Unit(monitor, "none", None, first_key,
                     notes=[f"its first log cannot be replayed ({_short(err)}): protocol own"])
    kind = "given" if calibrated_model is not None else "calibrated" if calibrate else "nominal"
    return _Unit(monitor, kind, program, first_key)


def _twin(unit: _Unit, units, nominal, calibrated_model, out: Path, twins: dict, progress: bool,
          read_with: fleet_logs.Reader) -> Twin | str | None:
    """The unit's twin, or None for a unit under protocol ``own``. A unit not yet scored falls back
    from its model to the nominal one and then to protocol ``own`` when its twin cannot be built;
    a unit already scored against a twin that cannot be built again gets the reason (a str), and
    its new logs are skipped with it. Each fallback is noted in the unit's reason."""
    while unit.model != "none":
        try:
            first_path = _log(units, unit.monitor.unit, unit.first[0]).path if any(
                g.stamp == unit.first[0] for g in units[unit.monitor.unit]) else None
            model = _model(nominal, unit.model, calibrated_model, unit.first, first_path, out, progress, read_with)
            twin_key = (model, unit.program)
            if twin_key not in twins:
                twins[twin_key] = Twin(model, _log(units, *unit.program).path, out / ".cache" / "cycles", root=out,
                                       reader=read_with)
            twin = twins[twin_key]
        except stored.StateError:
            raise
        except ValueError as err:
            if unit.entries:
                return f"the twin of the {unit.model} model cannot be built again ({_short(err)})"
            fallback = "nominal" if unit.model in ("given", "calibrated") else "none"
            unit.notes.append(f"the twin of the {unit.model} model failed ({_short(err)}); "
                              f"{'nominal model' if fallback == 'nominal' else 'protocol own'} used")
            unit.model = fallback
            continue
        if unit.monitor.signatures is not None and not np.array_equal(unit.monitor.signatures, twin.signatures):
            raise stored.StateError(f"{out / '.state' / (unit.monitor.unit + '.json')}: its wear signatures are not those of "
                             f"the twin of {unit.monitor.unit} now (another model or program); score this folder "
                             "into a new OUT")
        unit.monitor.signatures = twin.signatures
        if unit.initial_signatures is None and not unit.program_changes:
            unit.initial_signatures = twin.signatures
        return twin
    unit.program = None
    return None


def _program_changed(q: np.ndarray, program: np.ndarray) -> bool:
    """Whether a log's angles ``q`` (n, N) trace another motion than the program's (m, N): a length
    more than :data:`PROGRAM_LENGTH` apart, or an angle more than :data:`PROGRAM_CHANGE` rad off
    over their common samples (noise and tracking stay far below it)."""
    n = min(len(q), len(program))
    if abs(len(q) - len(program)) > PROGRAM_LENGTH * max(len(q), len(program)):
        return True
    return bool(np.max(np.abs(q[:n] - program[:n])) > PROGRAM_CHANGE)


def _new_program(unit: _Unit, log, reading, twin: Twin, context) -> Twin:
    """The twin of the program ``log`` starts (an unlogged program change): the unit's monitor
    restarts its learning against it, its open alarm closed by the change; noted in its reason.

    Raises
    ------
    ValueError
        The new program's twin cannot be built (the log is then skipped, named).
    """
    new = Twin(twin.model, log.path, context.out / ".cache" / "cycles", root=context.out, reader=twin.reader)
    unit.monitor.restart(log.stamp, stored.PROGRAM_CHANGED)
    unit.monitor.signatures = new.signatures
    unit.program, unit.program_q = (unit.monitor.unit, log.stamp), reading.q
    unit.program_changes.append(stored.ProgramChange(log.stamp, unit.program, len(unit.entries), new.signatures))
    unit.notes.append(f"program changed at {log.stamp} (not logged: its motion left the twin's program): the twin "
                      "replays that log, and the unit learns its normal operation again")
    return new


def _score_log(unit: _Unit, log, nominal, twin: Twin | str | None, twin_temperature: bool,
               read_with: fleet_logs.Reader, context=None) -> Twin | str | None:
    """Read one log and feed it to the unit's monitor; a log that cannot be read, or that the twin
    cannot replay (``twin`` a str: the reason no twin can be had), is skipped and kept in the
    unit's state with its reason. A log whose motion left the twin's program starts a new one
    (:func:`_new_program`). Returns the twin for the next log."""
    sha256 = stored.sha256_file(log.path)
    if isinstance(twin, str):
        unit.skipped.append(stored.Skipped(log.stamp, sha256, twin))
        return twin
    try:
        reading = fleet_logs.read(nominal, log, read_with)
        if twin is not None and context is not None and unit.program is not None:
            if unit.program_q is None:
                unit.program_q = np.asarray(read_with(_log(context.units, *unit.program).path, nominal).q)
            if _program_changed(reading.q, unit.program_q):
                twin = _new_program(unit, log, reading, twin, context)
        residual, expected = reading.vector, None
        if twin is not None:
            at = reading.temperature if twin_temperature else REFERENCE_TEMPERATURE
            expected = twin.expected(at, reading.payload)
            residual = residual - expected
    except stored.StateError:
        raise
    except ValueError as err:
        unit.skipped.append(stored.Skipped(log.stamp, sha256, _short(err)))
        return twin
    if not unit.entries and not unit.skipped:  # what the reader chose (an adapter's torque source), said once
        unit.notes.extend(n for n in reading.notes if n.startswith("torque from"))
    unit.monitor.add(log.stamp, residual, reading.temperature, reading.payload, expected)
    unit.entries.append(stored.Entry(log.stamp, sha256, residual, reading.temperature, reading.payload, expected))
    return twin


def _short(err: Exception, limit: int = 300) -> str:
    text = " ".join(str(err).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _status(name: str, unit: _Unit | None, settings: Settings) -> UnitStatus:
    """The unit's row of units.csv (:class:`UnitStatus`)."""
    if unit is None:
        return UnitStatus(name, "not monitored", settings.protocol, "", "no log", 0, "")
    protocol = "own" if unit.model == "none" else "twin"
    reasons = list(unit.notes)
    if unit.skipped:
        first = unit.skipped[0]
        more = f" (and {len(unit.skipped) - 1} more)" if len(unit.skipped) > 1 else ""
        reasons.append(f"{len(unit.skipped)} logs skipped: {first.stamp}: {first.reason}{more}")
    learning = unit.monitor.pca is None
    if learning:
        reasons.append(f"learning: {len(unit.monitor.training)} of {settings.train} logs")
    if not unit.entries:
        status = "not monitored"
    elif unit.skipped or protocol != settings.protocol:  # another model (said in the reason) is not degraded
        status = "degraded"
    else:
        status = "learning" if learning else "monitored"
    last = unit.entries[-1].stamp if unit.entries else ""
    return UnitStatus(name, status, protocol, unit.model if unit.model != "none" else "",
                      "; ".join(reasons), len(unit.entries), last)


def _maintenance_events(logs_dir: Path, units: dict, n_axes: int) -> dict[str, list]:
    """Each unit's repairs and gearbox changes of ``LOGS/events.csv`` (none without the file), in
    stamp order (:func:`faultgen.data.logfolder.read_events`; a bad file stops the run, named)."""
    path = logs_dir / "events.csv"
    if not path.exists():
        return {}
    found: dict[str, list] = {}
    for event in logfolder.read_events(path, units, n_axes, folder=logs_dir):
        if event.event in MAINTENANCE:
            found.setdefault(event.unit, []).append(event)
    return {unit: sorted(events, key=lambda e: e.key) for unit, events in found.items()}


def _log(units: dict[str, list[fleet_logs.Log]], unit: str, stamp: str) -> fleet_logs.Log:
    """The log ``stamp`` of ``unit`` in the fleet folder (a state names logs, never paths)."""
    for log in units.get(unit, ()):
        if log.stamp == stamp:
            return log
    raise ValueError(f"the log {unit}/{stamp} that an earlier run scored or replays is no longer in the fleet folder; "
                     "put it back or score this folder into a new OUT")


def _load_state(out: Path, units: dict, key: dict, settings: Settings, n_axes: int, n_features: int) -> dict[str, _Unit]:
    """The earlier run's state of every unit of the fleet folder that has one (a state file is
    looked for by the unit's name, never listed), replayed (:func:`faultgen.monitor.state.replay`).
    A state left by an earlier faultgen (``*.pkl``) is refused unread: pickles run code."""
    folder = out / ".state"
    if not folder.is_dir():
        return {}
    stored.inside(folder, out)
    pickles = sorted(p.name for p in folder.glob("*.pkl"))
    if pickles:
        raise ValueError(f"{folder}: holds {pickles[0]}, a monitor state of an earlier faultgen (a pickle, which can run "
                         "code when read, so it is not read); score the logs into a new OUT")
    state = {}
    for name in units:
        path = folder / f"{name}.json"
        if not (path.exists() or path.is_symlink()):
            continue
        kept = stored.read_unit(path, out, name, key, n_axes, n_features)
        if not (kept.entries or kept.skipped):
            continue
        state[name] = _Unit(stored.replay(kept, settings, n_axes), kept.model, kept.program, kept.first,
                            list(kept.entries), list(kept.skipped), list(kept.notes), list(kept.maintenance),
                            list(kept.program_changes), initial_signatures=kept.signatures)
    return state


def _given_model(calibrated: str | Path) -> Path:
    """The model file of a ``faultgen calibrate`` output folder (or the file itself)."""
    path = Path(calibrated)
    if path.is_dir():
        found = sorted((path / "model").glob("*_calibrated.xml")) or sorted(path.glob("*_calibrated.xml"))
        if not found:
            raise ValueError(f"{path}: no model/<robot>_calibrated.xml; give a `faultgen calibrate` output "
                             "folder or its model file")
        path = found[0]
    return path


def _model(nominal, kind: str, calibrated: Path | None, first: tuple[str, str], first_path: Path | None, out: Path,
           progress: bool, read_with: fleet_logs.Reader) -> str:
    """The unit's model file of ``kind``: "given" (``calibrated``), "nominal", or "calibrated" on
    the unit's first log (``first``: its stamp and SHA-256; ``first_path`` the file, needed only
    when the calibration is not cached), cached in ``OUT/.cache/calibrated`` under the digest of
    the nominal model, the log and the search's length, beside a record of the calibrated model's
    SHA-256 that a later run checks.

    Raises
    ------
    ValueError
        The calibration fails, or its cache does not match its record.
    """
    if kind == "nominal":
        return str(nominal.path)
    if kind == "given":
        return str(calibrated)
    key = {"robot": stored.sha256_file(nominal.path), "log": first[1], "steps": CALIBRATION_STEPS}
    digest = stored.key_name(key)
    root = out / ".cache" / "calibrated"
    folder, record = root / digest, root / f"{digest}.json"
    model = folder / "model" / f"{nominal.name}_calibrated.xml"
    if record.exists() or record.is_symlink():
        stored.read_calibration(record, out, key, model)
    else:
        if first_path is None:
            raise ValueError(f"the first log of the unit ({first[0]}), which its model was calibrated on, is no longer "
                             "in the fleet folder and its calibration is not cached")
        if folder.exists() or folder.is_symlink():  # a run killed before its record: ours to redo
            stored.inside(folder, out)
            shutil.rmtree(folder) if folder.is_dir() and not folder.is_symlink() else folder.unlink()
        from faultgen.calibrate import calibrate as run_calibration

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            run_calibration(str(nominal.path), read_with(first_path, nominal), folder, max_steps=CALIBRATION_STEPS,
                            progress=False)
        stored.write_calibration(record, key, model)
    implausible = plausibility.implausible_parameters(nominal, robots.load(model))
    if implausible:
        raise ValueError(f"its calibration on the first log is implausible: {'; '.join(implausible)}")
    return str(_without_payload(model))


def _without_payload(path: Path) -> Path:
    """The calibrated model without the part its log carried (the calibration's payload effect,
    written again with no mass: :class:`faultgen.effects.payload.Payload` removes its bodies): the
    twin carries each log's declared part instead. Written beside it (same assets and
    ``tasks.toml``) as ``<name>_twin.xml``, from the model checked as any robot description
    (:func:`faultgen.model.robots.load`: no file outside its folder) before MuJoCo parses it."""
    target = path.with_name(path.name.replace("_calibrated.xml", "_twin.xml"))
    if not target.is_file():
        robot = robots.load(path)
        spec = mujoco.MjSpec.from_file(str(path))
        Payload(mass=0.0).write(spec, robot)
        atomic.write_text(target, spec.to_xml())
    return target


def _program(nominal, first: fleet_logs.Log, unit: str, programs: list, read_with: fleet_logs.Reader) -> tuple[str, str]:
    """The log (unit, stamp) to replay for ``unit`` whose first log is ``first``: an earlier unit's
    when the motion is the same (:data:`SAME_PROGRAM`), so their twins share simulated cycles."""
    q = np.asarray(read_with(first.path, nominal).q)
    for other, other_program in programs:
        if other.shape == q.shape and np.max(np.abs(other - q)) < SAME_PROGRAM:
            return other_program
    programs.append((q, (unit, first.stamp)))
    return (unit, first.stamp)
