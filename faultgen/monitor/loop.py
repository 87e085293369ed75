"""``faultgen monitor``: a fleet's measured logs in, alarms and the worn axis out.

For each unit (a folder of ``LOGS``, its logs in stamp order, :mod:`faultgen.monitor.logs`, in
the measured format or an adapter's):

(a) the model: calibrated on the unit's first log (:func:`faultgen.calibrate.calibrate`, cached,
    refused when implausible), or a calibrated model given for every unit, or the nominal model;
(b) the twin (:class:`faultgen.monitor.twin.Twin`): the model replaying the unit's own first log,
    at each payload the logs declare, healthy and with each axis in turn worn; a unit whose twin
    cannot be built falls back to the nominal model, then to protocol own
    (:func:`faultgen.monitor.unit.twin_of`);
(c)-(d) the unit's monitor (the stages of :mod:`faultgen.monitor.scoring` in its record, fed by
    :mod:`faultgen.monitor.steps`): learned on the first
    logs, then every later log scored in stamp order; a log that cannot be read or replayed is
    skipped, a repair or gearbox change of ``events.csv`` closes the open alarm and the unit's
    offset is learned again; each log is placed among the unit's programs by its motion and scored
    on its whole cycles against its program's own baseline and twin, a program new to the unit
    learning its own (:mod:`faultgen.monitor.programs`, :func:`faultgen.monitor.feed.place`).

Units are scored one after another, in ``jobs`` local processes or on a Dask cluster
(:func:`faultgen.monitor.parallel.map_groups`), with the same outputs.
Outputs in OUT, written together (:func:`faultgen.data.atomic.atomic_folder`): ``units.csv`` (each
unit's status and why), ``alarms.csv``, ``scores.csv``, ``rul.csv`` (:mod:`faultgen.monitor.prognosis`), ``life.csv``
(:mod:`faultgen.monitor.life`: the gearboxes' rated life consumed by their load),
``report.html`` (:mod:`faultgen.monitor.page`), ``<unit>.png`` (a unit name longer than
:data:`faultgen.monitor.state.UNIT_FILE_MAX_BYTES` cut and its digest added:
:func:`faultgen.monitor.state.unit_file`) and the monitors' state in
``.state`` (a rerun on a grown folder scores only the new logs; JSON, never a pickle:
:mod:`faultgen.monitor.state`). Simulated cycles, calibrations and the twins' filtered program
logs are cached in ``OUT/.cache``, each checked against what it was made from; units whose first
logs trace the same motion (angles within :data:`SAME_PROGRAM` rad) and share a model share their
simulated cycles. Each log is read once (:class:`faultgen.monitor.logs.Source`: hashed and
parsed in one pass, the parsed log passed on; a rerun also hashes the logs scored before, to name
one that changed). A log that changed, vanished or came late (stamped before the last one scored)
after an earlier run is named in its unit's reason and not scored; one that vanishes during the
run is skipped, named: neither stops the fleet.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field
from pathlib import Path

from tqdm.auto import tqdm

from faultgen.data import atomic, fleetlogs, logfolder
from faultgen.logs import columns
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import friction_tests, history, life, page, prognosis, programs, report, sources, steps
from faultgen.monitor import state as stored
from faultgen.monitor.feed import PROGRAM_CHANGE, Context
from faultgen.monitor.history import UnitHistory
from faultgen.monitor.parallel import groups_of, map_groups
from faultgen.monitor.run import MonitorRun
from faultgen.monitor.scoring import Settings
from faultgen.monitor.unit import CALIBRATION_STEPS, SAME_PROGRAM, fallback_notes, new_unit, refused_note
from faultgen.runs.errors import SweepInterrupted
from faultgen.runs.sweep import CtrlC, Terminated

__all__ = ["CALIBRATION_STEPS", "EXIT_SOME_UNITS_NOT_MONITORED", "MAINTENANCE", "PROGRAM_CHANGE", "SAME_PROGRAM",
           "STATUSES", "Outcome", "UnitStatus", "monitor"]



#: Exit status of ``faultgen monitor`` when some unit is degraded or not monitored (every output is
#: still written); 0 when every unit is monitored or still learning, 2 a refusal before any work.
EXIT_SOME_UNITS_NOT_MONITORED = 3
#: Events of ``events.csv`` after which a unit's offset is learned again and its open alarm closed.
MAINTENANCE = history.MAINTENANCE
#: A unit's status in units.csv.
#: ``degraded``: under protocol own where the twin was asked for, or with logs skipped; a unit whose
#: twin uses the nominal model because its calibration failed or was implausible is ``monitored``,
#: the model column and the reason say so.
STATUSES = ("monitored", "learning", "degraded", "not monitored")


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
    #: The torque its logs were read from, where the log format says (:func:`faultgen.logs.formats.torque_source`:
    #: measured current x torque constant, or the commanded moment, which cannot show wear); "" otherwise.
    torque_source: str = ""
    #: The fallbacks its twin took (:func:`faultgen.monitor.unit.twin_of`'s notes, also in ``reason``).
    fallback: str = ""
    #: Its program mix where it ran several programs (:func:`faultgen.monitor.programs.mix`); "" otherwise.
    programs: str = ""

    def basis(self) -> str:
        """What the unit's numbers rest on, for the console beside its status: the twin's fallback and
        the torque source, each where there is one ("" otherwise)."""
        return "".join(f"; {what}: {text}" for what, text in (("twin fallback", self.fallback),
                                                              ("torque", self.torque_source)) if text)


@dataclass
class Outcome:
    """What :func:`monitor` did: each unit's record (``units``, :class:`~faultgen.monitor.history.UnitHistory`:
    its stages and rows too) and ``statuses`` (:class:`UnitStatus`), in the fleet folder's order; ``tests``: whether it wrote ``tests.csv``
    (the fleet has friction tests); what it ``passed_over``."""

    units: list[UnitHistory]
    statuses: list[UnitStatus]
    #: ``(name, reason)`` of each file of the folder passed over (not a log, not a friction test:
    #: ``<unit>/<file>``) and each row of ``events.csv`` that names no unit (``events.csv``).
    passed_over: list[tuple[str, str]] = field(default_factory=list)
    tests: bool = False
    #: ``(unit, stamp)`` of each unit scored again from its first log because the events of
    #: ``events.csv`` its saved state was scored with changed since (the earliest event changed).
    rescored: list[tuple[str, str]] = field(default_factory=list)

    @property
    def exit_status(self) -> int:
        """0 when every unit is monitored or learning, :data:`EXIT_SOME_UNITS_NOT_MONITORED` else."""
        bad = any(s.status in ("degraded", "not monitored") for s in self.statuses)
        return EXIT_SOME_UNITS_NOT_MONITORED if bad else 0


def monitor(run: MonitorRun) -> Outcome:
    """Monitor every unit of the run's logs folder (module docstring); ``run`` as
    :func:`faultgen.monitor.run.resolve_run` resolved it (the robot, the settings, the log format,
    the given model, the execution context: checked before any work).

    No unit stops the fleet: a unit whose twin cannot be built falls back (the calibrated or given
    model, then the nominal model, then ``--protocol own``: the unit against its own first logs),
    and a log that cannot be read or that the twin cannot replay is skipped; both are named in
    ``units.csv`` (:class:`UnitStatus`) and the unit's state keeps them, so a rerun does not try again.
    A unit whose first log the nominal model cannot explain (motor-side torque, another robot: the
    calibration's plausibility check, :func:`faultgen.monitor.unit.plausible`) is not monitored, with
    that message, whatever the model: a refusal is never a reason to fall back. A file in a unit
    folder that is not a log (``notes.txt``) is passed over and named (:attr:`Outcome.passed_over`,
    the unit's reason); a bad row of ``events.csv`` leaves its unit not monitored in this run, the
    row named, its earlier state kept (a row that names no unit is passed over, named). Every
    execution context gives the outputs of one local job on the default stepper: bit for bit for
    jobs and scheduler, to float tolerance for a stepper.

    Raises
    ------
    TypeError
        ``run`` is not a :class:`~faultgen.monitor.run.MonitorRun`.
    ValueError
        Before any unit is scored: the fleet folder, ``out`` holding a run with other settings or a
        state or cache that does not match them (:mod:`faultgen.monitor.state`, the file named), a
        bad ``events.csv`` as a whole (its header, encoding, a link out of the logs folder).
    faultgen.runs.errors.SweepError
        The scheduler was lost, or a worker has another robot model (nothing is written).
    MonitorInterrupted
        Ctrl-C or SIGTERM while the units were scored (exit code 130 or 143): the workers are
        stopped and the message says what ``out`` keeps (:func:`interrupted`).
    """
    if not isinstance(run, MonitorRun):
        raise TypeError(f"expected a MonitorRun (faultgen.monitor.run.resolve_run), got {type(run).__name__}")
    n_axes, out = run.robot.n_axes, run.out
    _, suffixes = fleet_logs.reader_of(run.log_format)
    passed: list[tuple[str, str]] = []  # files that are not logs or tests, events rows of no unit: named
    units = fleet_logs.fleet(run.logs, suffixes, passed)
    found = friction_tests.find(run.logs, units, suffixes, passed)
    confined = stored.checked_out(out)  # no link in OUT leads out: refused before anything is read or written
    maintenance, stopped = _maintenance_events(run.logs, units, n_axes, passed)
    tests = friction_tests.read_tests(found, run.robot, out, run.log_format)  # each test read once, cached
    wears = {name: friction_tests.tests_wear(read, n_axes, maintenance.get(name, ())) for name, read in tests.items()}

    def scale_of(name: str):
        if not wears.get(name, ([],))[0]:
            return None
        return friction_tests.Rescale(name, n_axes, wears[name][0], **(
            {"prior": run.scale_prior.pair} if run.scale_prior is not None else {}))

    state = _load_state(out, units, run.digest, run.settings, n_axes, run.n_features, scale_of, run.robot.name)
    rescored = events_changed(state, maintenance, stopped)  # those units scored again from their first log
    with told_on_interrupt(out, state):  # Ctrl-C, SIGTERM: the workers stopped, what OUT keeps said
        pending, stale = {}, {}
        for name, unit_logs in units.items():  # a unit with a bad events row: none of its logs this run
            pending[name], stale[name] = ([], []) if name in stopped else _pending(name, unit_logs, state.get(name))
        source = run.new_source()  # the robots, each resolved once; each log read once, parsed data passed on
        confined.mkdir(out / ".cache")
        programs: list[tuple[object, tuple[str, str]]] = []  # (checked program log, (unit, stamp))
        for name, unit_logs in pending.items():  # in the folder's order: a unit may replay an earlier one's log
            if unit_logs and name not in state:
                state[name] = new_unit(name, units, run.robot, run.settings, run.calibrated, run.calibrate, programs,
                                       source)
                _keep_program(state[name], rescored.get(name))
                state[name].stages.wear.tests = scale_of(name)
        made = _score_units(run, Context.of(run, units, maintenance), state, pending, source)
        statuses = [_status(name, state.get(name), run.settings, stale[name], tests.get(name, ()),
                            fleet_logs.passed_note([p for p in passed if p[0].startswith(f"{name}/")]),
                            stopped.get(name, "")) for name in units]
        _write_outputs(run, units, state, statuses, made, {name: wears[name][0] for name in units if name in wears}
                       if found else None)
    return Outcome([state[name] for name in units if name in state], statuses, passed, tests=bool(found),
                   rescored=[(name, since) for name, (since, _, _) in rescored.items()])


def _score_units(run: MonitorRun, scoring: Context, state: dict[str, UnitHistory], pending: dict[str, list],
                 source: fleet_logs.Source) -> dict[str, tuple[bytes, list]]:
    """Score each unit's ``pending`` logs (:func:`faultgen.monitor.parallel.map_groups`, on the run's
    execution context), updating ``state``; returns unit -> its chart (PNG) and rows of rul.csv,
    made where it was scored (a unit with no new log too)."""
    groups = groups_of({name: (state[name], logs) for name, logs in pending.items() if logs})
    bar = tqdm(total=sum(len(v) for v in pending.values()), desc="monitor", unit="log", disable=not run.progress)
    made: dict[str, tuple[bytes, list]] = {}
    idle = [state[name] for name in pending if name in state and not pending[name]]  # no new log
    # closed at once on an interrupt, which stops its workers (faultgen.pools.stop)
    with contextlib.closing(map_groups(run, scoring, groups, idle, source)) as results:
        for done in results:
            for name, unit, outputs in done:
                made[name] = outputs
                if unit is not None:
                    state[name] = unit
                    bar.update(len(pending[name]))
    bar.close()
    return made


def _write_outputs(run: MonitorRun, units: dict, state: dict[str, UnitHistory], statuses: list[UnitStatus],
                   made: dict[str, tuple[bytes, list]], wears: dict | None) -> None:
    """Write the run's outputs into ``run.out`` together (:func:`faultgen.data.atomic.atomic_folder`):
    each table from memory, the page drawn from the same tables, each unit's chart and state;
    ``wears``: each unit's friction tests' wear when the fleet has friction tests (tests.csv), else None."""
    records = [state[name] for name in units if name in state]
    nominal_scale = _nominal_scale(state, run.settings, run.own_model)
    scales = wears is not None or bool(nominal_scale)
    written = [report.alarms_table(records), report.scores_table(records, run.robot.n_axes),
               report.wear_table(records, scales=scales, nominal=nominal_scale),
               report.units_table(statuses, scales={m.unit: _scale_of(m, m.unit in nominal_scale) for m in records}
                                  if scales else None),
               *([friction_tests.tests_table(wears)] if wears is not None else []),
               prognosis.rul_table([row for m in records for row in made[m.unit][1]]),
               # a unit that scored no log (not monitored) has no life consumed to tell: no row, never "0 %"
               life.life_table([row for name in units if name in state and state[name].entries
                                for row in life.of_unit(name, state[name].entries, state[name].maintenance, run.ratings,
                                                        run.hours_per_day, notes=state[name].notes)])]
    # the page from the tables in memory (none read back), as `faultgen report OUT` draws it from the files
    fleet = page.fleet_of({t.name: t.records() for t in written}, [r.tabled() for m in records for r in m.rows])
    with atomic.atomic_folder(run.out) as staging:
        for table in written:
            table.write(staging)
        # LOGS by its name: a report meant to be shared keeps no path of this machine (as `logs import`)
        page.write(staging, run.settings, fleet=fleet, robot=Path(str(run.named)).name,
                   logs=run.logs.resolve().name, model=run.model_source,
                   twin_temperature=run.twin_temperature,
                   **stored.prior_settings(None if run.scale_prior is None else run.scale_prior.pair))
        for m in records:
            (staging / stored.unit_file(m.unit, ".png")).write_bytes(made[m.unit][0])
        (staging / ".state").mkdir()
        for name in units:
            if name in state:
                history.write_unit(staging / ".state" / stored.unit_file(name, ".json"), state[name], run.digest)



class MonitorInterrupted(SweepInterrupted):
    """``faultgen monitor`` stopped by Ctrl-C (exit code 130) or SIGTERM (143) while it scored the
    units: its workers are stopped, and the message says what ``out`` keeps."""


@contextlib.contextmanager
def told_on_interrupt(out: Path, state: dict[str, UnitHistory]):
    """Within it, Ctrl-C or SIGTERM (:class:`faultgen.runs.sweep.CtrlC`) raises
    :class:`MonitorInterrupted`, which says what ``out`` keeps (:func:`interrupted`) from the
    earlier run's ``state`` as it is on entry."""
    kept = len(state), max((u.entries[-1].stamp for u in state.values() if u.entries), default="")
    with CtrlC() as ctrl_c:
        try:
            yield
        except KeyboardInterrupt as interrupt:
            ctrl_c.stopping = True
            raise interrupted(out, *kept, isinstance(interrupt, Terminated)) from None


def interrupted(out: Path, units: int, last: str, terminated: bool) -> MonitorInterrupted:
    """What an interrupted run tells: ``out`` is written only once every unit is scored
    (:func:`faultgen.data.atomic.atomic_folder`), so it keeps the earlier run's outputs and state as
    they were (its ``units`` units, scored up to the logs of ``last``), or, on a first run (``units``
    0), no output; either way ``OUT/.cache`` keeps the twins' cycles and calibrations made so far,
    and the same command again continues."""
    what, code = ("terminated (SIGTERM)", 143) if terminated else ("interrupted", 130)
    if not units:
        return MonitorInterrupted(f"{what} before every unit was scored: no output is written ({out} gets its outputs "
                                  f"once every unit is scored); {out / '.cache'} keeps the twins made so far; run the "
                                  "same command to continue", code)
    upto = f", scored up to the logs of {last}" if last else ""
    return MonitorInterrupted(f"{what}: {out} is kept as the earlier run left it ({units} units{upto}); "
                              "this run's new logs are not scored; run the same command to score them", code)


def _pending(name: str, unit_logs: list, unit: UnitHistory | None) -> tuple[list, list[str]]:
    """The logs of ``name`` not yet scored (or skipped) by the run whose state is ``unit``: those
    stamped after the last log it handled; and notes naming the logs it handled that changed or
    left the folder since (their earlier scores kept: a log gzipped since, the same content, is not
    changed) and the new logs stamped before its last one (not scored: the monitor scores in stamp
    order). None of these stops the run: the unit's reason in units.csv names them."""
    if unit is None:
        return unit_logs, []
    handled = {logfolder.parse_stamp(k.stamp, name)[0]: (k.stamp, k.sha256) for k in unit.skipped}
    handled |= {logfolder.parse_stamp(e.stamp, name)[0]: (e.stamp, e.sha256) for e in unit.entries}
    last = max(handled)
    by_key = {g.key: g for g in unit_logs}
    gone = [stamp for key, (stamp, _) in handled.items() if key not in by_key]
    changed = [by_key[key].name for key, (_, digest) in handled.items()
               if key in by_key and not _same_log(by_key[key].path, digest)]
    late = [g.name for g in unit_logs if g.key < last and g.key not in handled]
    notes = []
    for found, what in ((changed, "changed since an earlier run scored or skipped them (its results kept)"),
                        (gone, "scored or skipped by an earlier run, now gone from the logs folder (its results kept)"),
                        (late, "older than the last log scored, not scored (logs are scored in stamp order)")):
        if found:
            more = f" (and {len(found) - 1} more)" if len(found) > 1 else ""
            notes.append(f"{len(found)} logs {what}: {found[0]}{more}")
    return [g for g in unit_logs if g.key > last], notes


def _same_log(path: Path, sha256: str) -> bool:
    """Whether the log at ``path`` is the one scored with SHA-256 ``sha256``: the same bytes, or
    the same content gzipped (:func:`faultgen.data.fleetlogs.content_sha256`); False for a file
    that cannot be read. Its size is checked first (:data:`faultgen.logs.columns.LOG_MAX_BYTES`):
    a file above it is never read, the same log when it was above it when handled (``sha256`` empty)."""
    try:
        if path.stat().st_size > columns.LOG_MAX_BYTES:  # never read: the same when it was too large then too
            return sha256 == ""
        return fleet_logs.log_sha256(path) == sha256 or fleetlogs.content_sha256(path) == sha256
    except (OSError, ValueError):
        return False



def _scale_of(unit: UnitHistory, nominal: bool = False) -> str:
    """units.csv's ``wear_scale`` of a unit: ``friction test`` when its last log's wear of some axis
    is on its tests' scale (:mod:`faultgen.monitor.friction_tests`), else ``nominal model`` for a
    unit whose twin fell back to the nominal model (``nominal``: :func:`_nominal_scale`), ``twin``
    otherwise."""
    last = unit.rows[-1].wear if unit.rows else None
    on_tests = last is not None and last.tests is not None and friction_tests.TESTS_SCALE in last.tests.scale
    return friction_tests.TESTS_SCALE if on_tests else friction_tests.NOMINAL_SCALE if nominal else \
        friction_tests.TWIN_SCALE


def _nominal_scale(state: dict[str, UnitHistory], settings: Settings, own_model: bool) -> set[str]:
    """The units whose wear is in the nominal model's scale though the run asked for each unit's own
    model (``own_model``: calibrated on its first log, or given): their twin fell back to the
    nominal model (the reason says why), so their wear is % of the nominal dry friction, not their
    own, and wear.csv says so."""
    if settings.protocol != "twin" or not own_model:
        return set()
    return {name for name, unit in state.items() if unit.model == "nominal"}


def _status(name: str, unit: UnitHistory | None, settings: Settings, stale: list[str] = (), tests=(), passed: str = "",
            stopped: str = "") -> UnitStatus:
    """The unit's row of units.csv (:class:`UnitStatus`); ``stale``: notes on logs handled by an
    earlier run that changed or left the folder, or new logs older than them (:func:`_pending`),
    which make it degraded; ``tests``: its friction tests read (those that could not be read named);
    ``passed``: the note on its files passed over (not logs: named, its status as without them);
    ``stopped``: its bad row of events.csv, which leaves it not monitored in this run (none of its
    logs scored, its earlier state kept)."""
    first = [f"not monitored: {stopped} (its new logs are scored once the row is corrected)"] if stopped else []
    if unit is None:
        return UnitStatus(name, "not monitored", settings.protocol, "", "; ".join([*first, passed] if first or passed
                                                                                  else ["no log"]), 0, "")
    protocol = "own" if unit.model == "none" else "twin"
    reasons = [*first, *unit.notes, *stale]
    unread = [t for t in tests if t.error]
    if unread:
        more = f" (and {len(unread) - 1} more)" if len(unread) > 1 else ""
        reasons.append(f"{len(unread)} friction tests not read: {unread[0].stamp}: {unread[0].error}{more}")
    if unit.skipped:
        reasons.append(skipped_note(unit.skipped))
    learning = unit.stages.baseline.pca is None
    refused = refused_note(unit) is not None  # its first log refused: no model used
    latest = unit.entries[-1].program if unit.entries else 0  # the program it runs now learning too: learning
    still = learning or programs.learning(unit.stages, latest)
    if learning and not unit.off_monitor and not refused:  # not learning: off the monitor
        reasons.append(f"learning: {len(unit.stages.baseline.training)} of {settings.train} logs")
    elif not learning and steps.not_observable_note(unit.stages):
        reasons.append(steps.not_observable_note(unit.stages))
    names = sources.labels(unit)  # one per baseline: 1 + the program changes
    mix = programs.mix_note(unit.stages, unit.entries, names)
    reasons += [mix] if mix else []
    if not unit.entries or stopped:
        status = "not monitored"
    elif unit.skipped or stale or protocol != settings.protocol:  # another model (said in the reason) is not degraded
        status = "degraded"
    else:
        status = "learning" if still else "monitored"
    reasons += [passed] if passed else []  # last: its status is as without them
    last = unit.entries[-1].stamp if unit.entries else ""
    return UnitStatus(name, status, protocol, unit.model if unit.model != "none" and not refused else "",
                      "; ".join(reasons), len(unit.entries), last, sources.seen(unit),
                      "; ".join(fallback_notes(unit)), programs.mix(unit.entries, names) if len(names) > 1 else "")


#: Most distinct reasons a unit's reason names for its skipped logs (:func:`skipped_note`).
SKIPPED_REASONS = 3


def skipped_note(skipped: list) -> str:
    """A unit's note on its skipped logs (each with ``stamp`` and ``reason``): their count, and each
    distinct reason once, with the first log skipped for it and how many more were (at most
    :data:`SKIPPED_REASONS`; the logs of the other reasons counted): an empty first log and a part
    the twin cannot carry are both said, and one reason of many logs only once."""
    groups: dict[str, list] = {}
    for log in skipped:
        groups.setdefault(log.reason, []).append(log)
    shown = [f"{logs[0].stamp}: {reason}" + (f" (and {len(logs) - 1} more)" if len(logs) > 1 else "")
             for reason, logs in list(groups.items())[:SKIPPED_REASONS]]
    rest = sum(len(logs) for logs in list(groups.values())[SKIPPED_REASONS:])
    others = f"; and {rest} more for {len(groups) - SKIPPED_REASONS} other reasons" if rest else ""
    return f"{len(skipped)} logs skipped: {'; '.join(shown)}{others}"


def _maintenance_events(logs_dir: Path, units: dict, n_axes: int,
                        passed: list | None = None) -> tuple[dict[str, list], dict[str, str]]:
    """Each unit's repairs and gearbox changes of ``LOGS/events.csv`` (none without the file), in
    stamp order (:func:`faultgen.data.logfolder.read_events`), and the units a bad row stops: unit ->
    the row named and why (the first; "(and N more)"). A row that names no unit of the folder is
    added to ``passed``; a bad file (its header, its encoding, a link out) stops the run, named."""
    path = logs_dir / "events.csv"
    if not path.exists():
        return {}, {}
    found: dict[str, list] = {}
    bad: list[tuple[str, str]] = []
    for event in logfolder.read_events(path, units, n_axes, folder=logs_dir, bad=bad):
        if event.event in MAINTENANCE:
            found.setdefault(event.unit, []).append(event)
    stopped: dict[str, list[str]] = {}
    for unit, message in bad:
        if unit:
            stopped.setdefault(unit, []).append(message)
        elif passed is not None:
            passed.append((path.name, message))
    return ({unit: sorted(events, key=lambda e: e.key) for unit, events in found.items()},
            {unit: rows[0] + (f" (and {len(rows) - 1} more)" if len(rows) > 1 else "") for unit, rows in stopped.items()})



def _load_state(out: Path, units: dict, key: dict, settings: Settings, n_axes: int, n_features: int,
                scale_of=lambda name: None, robot: str = "") -> dict[str, UnitHistory]:
    """The earlier run's state of every unit of the fleet folder that has one (a state file is
    looked for by the unit's name, never listed), replayed (:func:`faultgen.monitor.steps.replay`).
    A state left by an earlier faultgen (``*.pkl``) is refused unread: pickles run code. ``.state``
    itself was checked to lead inside ``out`` by the caller (:func:`faultgen.monitor.state.checked_out`)."""
    folder = out / ".state"
    if not folder.is_dir():
        return {}
    pickles = sorted(p.name for p in folder.glob("*.pkl"))
    if pickles:
        raise ValueError(f"{folder}: holds {pickles[0]}, a monitor state of an earlier faultgen (a pickle, which can run "
                         "code when read, so it is not read); score the logs into a new OUT")
    state = {}
    for name in units:
        path = folder / stored.unit_file(name, ".json")
        if not (path.exists() or path.is_symlink()):
            continue
        kept = history.read_unit(path, out, name, key, n_axes, n_features, robot)
        if not (kept.entries or kept.skipped):
            continue
        steps.replay(kept, settings, n_axes, scale_of(name))
        state[name] = kept
    return state


def events_changed(state: dict[str, UnitHistory], maintenance: dict, stopped: dict) -> dict[str, tuple]:
    """Drop from ``state`` each unit whose saved maintenance differs from the events of
    ``events.csv`` now (``maintenance``) that its scored or skipped logs would have been given (those
    stamped at or before its last one): the unit is scored again from its first log, as a fresh run
    scores it. Returns unit -> (the stamp of the earliest event added, changed or removed, its
    program, its first log); a unit a bad ``events.csv`` row stops keeps its state.

    From its first log rather than from that day: a state's notes and skipped logs are not kept by
    day, so cutting it at a day could not promise the outputs of a fresh run."""
    changed = {}
    for name, unit in list(state.items()):
        if name in stopped:
            continue
        last = max(logfolder.parse_stamp(e.stamp, name)[0] for e in (*unit.entries, *unit.skipped))
        now: list[tuple[str, str, int]] = []
        for event in maintenance.get(name, ()):  # each given once (faultgen.monitor.feed.score_group)
            if event.key <= last and (event.stamp, event.event, event.axis) not in now:
                now.append((event.stamp, event.event, event.axis))
        then = [m.identity for m in unit.maintenance]
        if now == then:
            continue
        i = next((i for i, (a, b) in enumerate(zip(now, then)) if a != b), min(len(now), len(then)))
        since = min((x[i][0] for x in (now, then) if i < len(x)), key=lambda s: logfolder.parse_stamp(s, name)[0])
        changed[name] = (since, unit.program, unit.first)
        del state[name]
    return changed


def _keep_program(unit: UnitHistory, kept: tuple | None) -> None:
    """A unit scored again (:func:`events_changed`) replays the program its first run found (an
    earlier unit's log, which this run's new units alone would not offer), when its first log is
    the same."""
    if kept is not None and unit.program is not None and kept[1] is not None and tuple(unit.first) == tuple(kept[2]):
        unit.program = kept[1]
