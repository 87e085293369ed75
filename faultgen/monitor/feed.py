"""A group of units' new logs scored in stamp order (:func:`score_group`): each log read and fed to
the unit's monitor against its twin (:func:`score_log`), a repair or gearbox change given before the
first log at or after it, a log that cannot be read or replayed skipped and named, a program change
nobody logged starting a new twin (:func:`new_program`); and each unit's chart and remaining life
(:func:`unit_outputs`). Runs wherever the group is scored (this process, a local worker, a Dask
worker: :mod:`faultgen.monitor.parallel`), with the same arithmetic. Each log is read once, by
the process's :class:`faultgen.monitor.logs.Source` (the run's, where it was made).
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from analysis.monitoring import varying_columns
from faultgen.logs import align, formats
from faultgen.model import robots
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import friction_tests, life, report, sources, steps
from faultgen.monitor import programs as unit_programs
from faultgen.monitor import state as stored
from faultgen.monitor.history import Entry, Maintenance, Note, ProgramChange, Skipped, UnitHistory
from faultgen.monitor.scoring import Settings, Stages
from faultgen.monitor.twin import REFERENCE_TEMPERATURE, Twin
from faultgen.monitor.unit import REFUSED_SKIP, log_of, refused_note, short, twin_of
from faultgen.simulation import backends

#: A log more than this RMS angle off each of its unit's programs over a whole cycle, rad, runs a program
#: new to the unit (:func:`faultgen.logs.align.recognise`).
PROGRAM_CHANGE = align.TOLERANCE
#: A unit's note (units.csv's reason) when a feature of its learning logs is the same in every log
#: (:func:`constant_torque`): no PCA model can be fitted on it and no wear can show in it (the
#: ``ur-rtde`` commanded moment of a fixed program, the same every day). The unit is not monitored,
#: and the fleet goes on.
CONSTANT_TORQUE = "not monitored: the torque column does not vary from log to log (commanded moment?)"


@dataclass(frozen=True)
class Context:
    """What scoring a group of units needs (sent to a worker process as it is), made from the
    resolved run (:meth:`of`): its paths, settings and log format, the fleet's ``units`` (their
    logs) and ``maintenance`` events; ``stepper``: what steps the twins' cycles (the run's, a
    :class:`faultgen.simulation.backends.Stepper`; ValueError on construction for anything else)."""

    robot: Path
    settings: Settings
    calibrated: Path | None
    out: Path
    twin_temperature: bool
    log_format: object
    units: dict
    maintenance: dict
    failure_wear: float
    stepper: backends.Stepper = backends.DEFAULT_STEPPER

    def __post_init__(self) -> None:
        backends.checked(self.stepper)

    @classmethod
    def of(cls, run, units: dict, maintenance: dict) -> Context:
        """What a worker needs of ``run`` (a :class:`faultgen.monitor.run.MonitorRun`: its robot and
        given model as paths, each worker resolving them once, :meth:`new_source`) to score the
        fleet's ``units`` (unit -> its logs) with their ``maintenance`` events."""
        return cls(run.robot.path, run.settings, run.calibrated, run.out, run.twin_temperature, run.log_format, units,
                   maintenance, run.failure_wear, run.stepper)

    def new_source(self, nominal: robots.Robot | None = None) -> fleet_logs.Source:
        """A log source of this run in a worker that did not inherit the run's own
        (:meth:`faultgen.monitor.run.MonitorRun.new_source`; loky, Dask), holding its robots:
        ``nominal`` (the robot the worker resolved), else :attr:`robot` resolved here; and the model given for every unit (:attr:`calibrated`),
        resolved here once, or the ValueError its loading raised, which each unit's twin falls back
        from (:func:`faultgen.monitor.unit.twin_of`)."""
        nominal = robots.load(self.robot) if nominal is None else nominal
        given = None
        if self.calibrated is not None:
            try:
                given = robots.load(self.calibrated)
            except ValueError as err:  # UnknownRobotError, ModelError: the units fall back to the nominal model
                given = err
        return fleet_logs.Source(nominal, self.log_format, given)


def unit_outputs(unit: UnitHistory, failure_wear: float) -> tuple[bytes, list]:
    """A unit's control chart (PNG bytes, :func:`faultgen.monitor.report.chart`) and its rows of
    rul.csv (:func:`faultgen.monitor.friction_tests.remaining_life`: on the unit's friction tests'
    scale when it has tests, else :func:`faultgen.monitor.prognosis.of_monitor`): made where the unit was scored, so that
    they are made in parallel too."""
    note = "wear signature match" if unit.stages.baseline.signatures is not None else "RBC of Q"
    buffer = io.BytesIO()
    report.chart(buffer, unit, note)
    return buffer.getvalue(), friction_tests.remaining_life(unit, failure_wear)


def idle_outputs(unit: UnitHistory, failure_wear: float) -> list:
    """The chart and rows of rul.csv of a unit with no new log (:func:`unit_outputs`), as
    :func:`score_group` returns a unit's: ``[(unit, None, outputs)]`` (None: its state unchanged)."""
    return [(unit.unit, None, unit_outputs(unit, failure_wear))]


def score_group(context: Context, group: list[tuple[str, UnitHistory, list]],
                source: fleet_logs.Source | None = None) -> list[tuple[str, UnitHistory, tuple]]:
    """Score each unit's new logs in stamp order against the group's twin, a unit's maintenance
    events given before the first log at or after them; returns the units with their chart and
    remaining life (:func:`unit_outputs`). ``source``: the run's logs as read so far (this
    process's; a new one when None, as in a worker that did not inherit it)."""
    source = source if source is not None else context.new_source()
    nominal = source.robot
    twins: dict[tuple, Twin] = {}
    for name, unit, unit_logs in group:
        off = unit.off_monitor or (REFUSED_SKIP if refused_note(unit) else None)  # an earlier run's
        twin = off or twin_of(unit, context, twins, False, source)
        events = context.maintenance.get(name, ())  # in stamp order, as the logs: each looked at once
        given = {m.identity for m in unit.maintenance}
        i = 0
        for log in unit_logs:
            while i < len(events) and events[i].key <= log.key:
                event = events[i]
                i += 1
                if (event.stamp, event.event, event.axis) not in given:
                    given.add((event.stamp, event.event, event.axis))
                    steps.maintenance(unit, event.stamp, event.event, event.axis)
                    unit.maintenance.append(Maintenance(event.stamp, event.event, event.axis,
                                                        len(unit.entries)))
            twin = score_log(unit, log, nominal, twin, context.twin_temperature, source, context)
    for _, unit, _ in group:
        unit.program_twins.clear()  # made again where needed: a unit travels back from a worker without them
    return [(name, unit, unit_outputs(unit, context.failure_wear)) for name, unit, _ in group]



def references(unit: UnitHistory, units: dict, source: fleet_logs.Source) -> list[align.Reference]:
    """The references of the unit's baselines in the order met (:attr:`UnitHistory.references`), learned
    from their logs (:func:`faultgen.monitor.programs.reference_of`) when first needed in a run; a
    baseline of a program's other torque source has its program's (:mod:`faultgen.monitor.sources`)."""
    if unit.references is None:
        logs = [unit.program] + [c.program for c in unit.program_changes]
        unit.references, learned = [], {}
        for owner, stamp in logs:
            if (owner, stamp) not in learned:
                data = source.get(log_of(units, owner, stamp)).checked()
                learned[owner, stamp] = unit_programs.reference_of(data.t, data.q, data.cycle,
                                                                   f"program {len(learned) + 1}")
            unit.references.append(learned[owner, stamp])
    return unit.references


def place(unit: UnitHistory, log, data, twin: Twin, context, source: fleet_logs.Source, torque: str = ""):
    """The program of a checked log ``data`` of ``unit`` (:func:`faultgen.logs.align.place` among
    its programs), the part of it scored (its whole cycles: :func:`faultgen.monitor.programs.scored`)
    and that program's twin: ``(baseline index, data scored, twin)``, the baseline that of the
    program and the log's torque source ``torque`` (:mod:`faultgen.monitor.sources`); a program new
    to the unit is added (:func:`new_program`), a known program's new source starts its baseline
    (:func:`faultgen.monitor.sources.change`). A log of no whole cycle of a program gives why (a
    str: it is skipped).

    Raises
    ------
    ValueError
        A new program's twin cannot be built (the log is then skipped, named).
    """
    known = references(unit, context.units, source)
    programs = sources.distinct(known)  # one reference a program (a source change repeats its program's)
    found = align.recognise(data.t, data.q, programs)
    if found.status is align.Status.KNOWN:
        k = next(i for i, r in enumerate(known) if r.name == found.program)
        reference = known[k]
    elif found.status is align.Status.NEW:
        k = len(known)
        try:
            reference = unit_programs.reference_of(data.t, data.q, data.cycle,
                                                   f"program {len(programs) + 1}")
        except ValueError as err:
            return f"no whole cycle: a new program that cannot be learned ({short(err)})"
    else:
        return unit_programs.refusal_text(align.untold(found))
    cut = align.whole_cycles(data.t, data.q, reference, data.cycle, fitted=align.known_fit(found, programs))
    span = unit_programs.span_of(data.t, cut, reference.period)
    if span is None:
        return unit_programs.refusal_text(cut)
    if k == len(known):
        new_program(unit, log, twin, context, source, reference, torque)
    k_twin = twin if k == 0 else program_twin(unit, k, twin, context, source)
    baseline = sources.baseline_of(unit, k, torque)
    if baseline is None:
        baseline = sources.change(unit, log, k, torque, k_twin.signatures,
                                  lambda s: unit.stages.programs.new(unit.stages, s))
    return baseline, unit_programs.scored(data, span), k_twin


def program_twin(unit: UnitHistory, k: int, twin: Twin, context, source: fleet_logs.Source) -> Twin:
    """The twin of the unit's program ``k`` (>= 1), made once a run (:attr:`UnitHistory.program_twins`) on
    the model of its first program's ``twin``."""
    if k not in unit.program_twins:
        owner, stamp = unit.program_changes[k - 1].program
        unit.program_twins[k] = Twin(twin.robot, source.get(log_of(context.units, owner, stamp)),
                                     context.out / ".cache" / "cycles", root=context.out, stepper=twin.stepper)
        source.keep(log_of(context.units, owner, stamp))
    return unit.program_twins[k]


def new_program(unit: UnitHistory, log, twin: Twin, context, source: fleet_logs.Source, reference: align.Reference,
                torque: str = "") -> int:
    """A program new to the unit from ``log`` on (its motion within the tolerance of none of its
    programs): reported once (a program change, noted in its reason), its twin made on that log,
    its offset learned on its own first logs (pooled into the unit's learning while the unit learns),
    the other programs' logs scored meanwhile (:class:`faultgen.monitor.programs.Baselines`), for the
    log's torque source ``torque``. Returns its index.

    Raises
    ------
    ValueError
        The new program's twin cannot be built (the log is then skipped, named).
    """
    new = Twin(twin.robot, source.get(log), context.out / ".cache" / "cycles", root=context.out,
               stepper=twin.stepper)
    source.keep(log)
    k = len(unit.references)
    count = len(sources.distinct(unit.references))
    unit.references.append(reference)
    unit.program_twins[k] = new
    unit.program_changes.append(ProgramChange(log.stamp, (unit.unit, log.stamp), len(unit.entries),
                                              new.signatures, torque))
    unit.stages.programs.new(unit.stages, new.signatures)
    unit.notes.append(Note(f"program changed at {log.stamp} (not logged: its motion within {align.TOLERANCE:g} rad RMS "
                           f"of none of the unit's {count} program(s)): {reference.name}, a {reference.period:.3f} s "
                           "cycle; its twin replays that log; it learns its offset on its own first logs (pooled into "
                           "the unit's learning while the unit learns), the other programs' logs scored meanwhile"))
    return k


def score_log(unit: UnitHistory, log, nominal, twin: Twin | str | None, twin_temperature: bool,
               source: fleet_logs.Source, context=None) -> Twin | str | None:
    """Feed one log (read once by ``source``, then forgotten unless a program keeps it) to the
    unit's monitor; a log that cannot be read, or that the twin cannot replay (``twin`` a str: the
    reason no twin can be had), is skipped and kept in the unit's state with its reason. A log
    whose motion left the twin's program starts a new one (:func:`new_program`). Returns the twin
    for the next log."""
    try:
        return _score(unit, log, source.get(log), nominal, twin, twin_temperature, source, context)
    finally:
        source.done(log)


def _score(unit: UnitHistory, log, parsed: fleet_logs.Parsed, nominal, twin, twin_temperature: bool, source, context):
    sha256 = parsed.sha256
    if isinstance(twin, str):
        unit.skipped.append(Skipped(log.stamp, sha256, twin))
        return twin
    program, data, program_twin = 0, parsed.checked() if parsed.error is None else None, twin
    try:
        load = _load(parsed.checked())
        torque = formats.torque_source(data.notes)  # this log's (the reader chooses it per file)
        if not unit.entries or not unit.torque_source:  # its first baseline's (unnamed in a state from before)
            unit.torque_source = torque
        if twin is not None and context is not None and unit.program is not None:
            placed = place(unit, log, data, twin, context, source, torque)
            if isinstance(placed, str):
                unit.skipped.append(Skipped(log.stamp, sha256, placed))
                return twin
            program, data, program_twin = placed
        reading = fleet_logs.reading_of(nominal, data)
        residual, expected = reading.vector, None
        if program_twin is not None:
            at = reading.temperature if twin_temperature else REFERENCE_TEMPERATURE
            expected = program_twin.expected(at, reading.payload)
            residual = residual - expected
    except stored.StateError:
        raise
    except ValueError as err:
        unit.skipped.append(Skipped(log.stamp, sha256, short(err)))
        return twin
    if not unit.entries and not unit.skipped:  # what the reader chose (an adapter's torque source), said once
        unit.notes.extend(Note(n) for n in reading.notes if isinstance(n, formats.TorqueNote))
    unit.notes.extend(fleet_logs.log_notes(log.stamp, reading.notes, unit.notes))  # each column's kind once
    constant = constant_torque(unit, reading.vector, nominal.n_axes) if program == 0 else ""
    if constant:
        return not_monitored(unit, log.stamp, sha256, constant)
    constant = later_constant(unit, program, reading.vector, nominal.n_axes)
    if constant:  # a later baseline (a program's, a torque source's) that can show no wear: its logs skipped
        unit.skipped.append(Skipped(log.stamp, sha256, constant))
        return twin
    steps.run(unit, program, lambda: steps.add(unit, log.stamp, residual, reading.temperature, reading.payload,
                                               expected))
    unit.entries.append(Entry(log.stamp, sha256, residual, reading.temperature, reading.payload, expected,
                              *load, program))
    return twin


def constant_torque(unit: UnitHistory, vector: np.ndarray, n_axes: int) -> str:
    """Why the unit cannot be monitored when the log of feature ``vector`` (its
    :data:`faultgen.monitor.logs.FEATURES`, by name then axis) completes its learning and a feature
    is the same in every learning log (:func:`analysis.monitoring.varying_columns`: beyond
    rounding), which the PCA model cannot standardise: :data:`CONSTANT_TORQUE` and the features;
    "" otherwise (or before the learning's last log). The features are the residuals plus the
    twin's expectation, which may vary with the logs' conditions while the torque does not."""
    baseline = unit.stages.baseline
    if baseline.pca is not None or len(baseline.training) + 1 < baseline.learning_logs:
        return ""
    expected = baseline.learned_expectations or [0.0] * len(baseline.training)
    features = np.stack([e + x for (_, e, _), x in zip(baseline.training, expected)] + [vector])
    constant = np.setdiff1d(np.arange(features.shape[1]), varying_columns(features))
    if not constant.size:
        return ""
    named = [f"{fleet_logs.FEATURES[j // n_axes]} of axis {j % n_axes + 1}" for j in constant]
    more = f" and {len(named) - 3} more" if len(named) > 3 else ""
    return (f"{CONSTANT_TORQUE}: {', '.join(named[:3])}{more} the same in all {len(features)} learning logs, "
            "which can show no wear")


def later_constant(unit: UnitHistory, program: int, vector: np.ndarray, n_axes: int) -> str:
    """:func:`constant_torque` for the unit's baseline ``program`` after the first (a new program's,
    a torque source's: the commanded moment of a fixed program the same every day): its logs are
    then skipped with the reason, the unit's other baselines go on; "" otherwise (and for ``program`` 0)."""
    if program == 0:
        return ""
    found = []
    steps.run(unit, program, lambda: found.append(constant_torque(unit, vector, n_axes)))
    return found[0] and f"the baseline begun at {unit.program_changes[program - 1].stamp} cannot be learned: {found[0].removeprefix('not monitored: ')}"


def not_monitored(unit: UnitHistory, stamp: str, sha256: str, why: str) -> str:
    """Take the unit off the monitor (:func:`constant_torque`): its logs scored so far and the log
    ``stamp`` (its SHA-256 ``sha256``) kept as skipped, its stages and rows emptied (its status then "not monitored", its reason ``why``);
    returns the reason its later logs are skipped with, in this run and the next."""
    skipped = "the unit is not monitored: its torque does not vary from log to log"
    unit.skipped.extend(Skipped(e.stamp, e.sha256, skipped) for e in unit.entries)
    unit.skipped.append(Skipped(stamp, sha256, skipped))
    unit.entries.clear()
    stages = unit.stages
    unit.stages, unit.rows = Stages.new(unit.unit, stages.settings, stages.n_axes, stages.baseline.signatures), []
    unit.notes.append(Note(why))
    unit.off_monitor = why
    return why


def _load(data) -> tuple[np.ndarray | None, float]:
    """The log's load (:func:`faultgen.monitor.life.load_integrals`) and its duration, s; (None,
    NaN) for a log it cannot take (one sample): the log is still scored."""
    try:
        return life.load_integrals(data.t, data.qd, data.tau), float(data.t[-1] - data.t[0])
    except ValueError:
        return None, float("nan")
