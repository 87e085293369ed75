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
from faultgen.logs import formats
from faultgen.model import robots
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import cycles, friction_tests, life, report
from faultgen.monitor import state as stored
from faultgen.monitor.scoring import Settings, UnitMonitor
from faultgen.monitor.twin import REFERENCE_TEMPERATURE, Twin
from faultgen.monitor.unit import REFUSED_SKIP, Unit, log_of, refused_note, short, twin_of
from faultgen.simulation import backends

#: A log whose cycles' angles lie more than this off its twin's program, rad, or whose span differs by
#: more than PROGRAM_LENGTH of a whole number of its cycles, runs another program (:mod:`faultgen.monitor.cycles`).
PROGRAM_CHANGE, PROGRAM_LENGTH = cycles.PROGRAM_CHANGE, cycles.PROGRAM_LENGTH
#: A unit's note (units.csv's reason) when a feature of its learning logs is the same in every log
#: (:func:`constant_torque`): no PCA model can be fitted on it and no wear can show in it (the
#: ``ur-rtde`` commanded moment of a fixed program, the same every day). The unit is not monitored,
#: and the fleet goes on.
CONSTANT_TORQUE = "not monitored: the torque column does not vary from log to log (commanded moment?)"


@dataclass(frozen=True)
class Context:
    """What scoring a group of units needs (sent to a worker process as it is); ``stepper``: what
    steps the twins' cycles (a :class:`faultgen.simulation.backends.Stepper`; ValueError on
    construction for anything else)."""

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

    def new_source(self, nominal: robots.Robot | None = None) -> fleet_logs.Source:
        """A log source of this run holding its robots: ``nominal`` (the robot the run's command or
        library call resolved), else :attr:`robot` resolved here, for a worker that did not inherit
        the run's source (loky, Dask); and the model given for every unit (:attr:`calibrated`),
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


def unit_outputs(monitor: UnitMonitor, failure_wear: float) -> tuple[bytes, list]:
    """A unit's control chart (PNG bytes, :func:`faultgen.monitor.report.chart`) and its rows of
    rul.csv (:func:`faultgen.monitor.friction_tests.remaining_life`: on the unit's friction tests'
    scale when it has tests, else :func:`faultgen.monitor.prognosis.of_monitor`): made where the unit was scored, so that
    they are made in parallel too."""
    note = "wear signature match" if monitor.signatures is not None else "RBC of Q"
    buffer = io.BytesIO()
    report.chart(buffer, monitor, note)
    return buffer.getvalue(), friction_tests.remaining_life(monitor, failure_wear)


def idle_outputs(monitor: UnitMonitor, failure_wear: float) -> list:
    """The chart and rows of rul.csv of a unit with no new log (:func:`unit_outputs`), as
    :func:`score_group` returns a unit's: ``[(unit, None, outputs)]`` (None: its state unchanged)."""
    return [(monitor.unit, None, unit_outputs(monitor, failure_wear))]


def score_group(context: Context, group: list[tuple[str, Unit, list]],
                source: fleet_logs.Source | None = None) -> list[tuple[str, Unit, tuple]]:
    """Score each unit's new logs in stamp order against the group's twin, a unit's maintenance
    events given before the first log at or after them; returns the units with their chart and
    remaining life (:func:`unit_outputs`). ``source``: the run's logs as read so far (this
    process's; a new one when None, as in a worker that did not inherit it)."""
    source = source if source is not None else context.new_source()
    nominal = source.robot
    twins: dict[tuple, Twin] = {}
    for name, unit, unit_logs in group:
        off = unit.off_monitor or (REFUSED_SKIP if refused_note(unit) else None)  # an earlier run's
        twin = off or twin_of(unit, context.units, context.out, twins, False, source, context.stepper)
        events = context.maintenance.get(name, ())  # in stamp order, as the logs: each looked at once
        given = {m.identity for m in unit.maintenance}
        i = 0
        for log in unit_logs:
            while i < len(events) and events[i].key <= log.key:
                event = events[i]
                i += 1
                if (event.stamp, event.event, event.axis) not in given:
                    given.add((event.stamp, event.event, event.axis))
                    unit.monitor.maintenance(event.stamp, event.event, event.axis)
                    unit.maintenance.append(stored.Maintenance(event.stamp, event.event, event.axis,
                                                               len(unit.entries)))
            twin = score_log(unit, log, nominal, twin, context.twin_temperature, source, context)
    return [(name, unit, unit_outputs(unit.monitor, context.failure_wear)) for name, unit, _ in group]



def program_changed(data, program: cycles.Program) -> bool:
    """Whether a checked log ``data`` (:class:`faultgen.logs.measured.MeasuredData`) traces another
    motion than ``program``'s: its cycles (its ``cycle`` column, else a whole number of the program's
    periods) match neither the program's cycle nor a multiple of it
    (:meth:`faultgen.monitor.cycles.Program.log_cycles`; noise and tracking stay far below it)."""
    return program.log_cycles(data.t, data.q, data.cycle) is None


def program_of(data) -> cycles.Program:
    """The :class:`faultgen.monitor.cycles.Program` of a checked program log ``data``."""
    return cycles.Program.of(data.t, data.q, data.cycle)


def new_program(unit: Unit, log, twin: Twin, context, source: fleet_logs.Source) -> Twin:
    """The twin of the program ``log`` starts (an unlogged program change): the unit's monitor
    restarts its learning against it, its open alarm closed by the change; noted in its reason.

    Raises
    ------
    ValueError
        The new program's twin cannot be built (the log is then skipped, named).
    """
    new = Twin(twin.robot, source.get(log), context.out / ".cache" / "cycles", root=context.out,
               stepper=twin.stepper)
    source.keep(log)
    unit.monitor.restart(log.stamp, stored.PROGRAM_CHANGED)
    unit.monitor.signatures = new.signatures
    unit.program, unit.program_cycle = (unit.monitor.unit, log.stamp), program_of(source.get(log).checked())
    unit.program_changes.append(stored.ProgramChange(log.stamp, unit.program, len(unit.entries), new.signatures))
    unit.notes.append(f"program changed at {log.stamp} (not logged: its motion left the twin's program): the twin "
                      "replays that log, and the unit learns its normal operation again")
    return new


def score_log(unit: Unit, log, nominal, twin: Twin | str | None, twin_temperature: bool,
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


def _score(unit: Unit, log, parsed: fleet_logs.Parsed, nominal, twin, twin_temperature: bool, source, context):
    sha256 = parsed.sha256
    if isinstance(twin, str):
        unit.skipped.append(stored.Skipped(log.stamp, sha256, twin))
        return twin
    try:
        reading = fleet_logs.reading_of(nominal, parsed.checked())
        load = _load(parsed.checked())
        if twin is not None and context is not None and unit.program is not None:
            if unit.program_cycle is None:
                unit.program_cycle = program_of(source.get(log_of(context.units, *unit.program)).checked())
            if program_changed(parsed.checked(), unit.program_cycle):
                twin = new_program(unit, log, twin, context, source)
        residual, expected = reading.vector, None
        if twin is not None:
            at = reading.temperature if twin_temperature else REFERENCE_TEMPERATURE
            expected = twin.expected(at, reading.payload)
            residual = residual - expected
    except stored.StateError:
        raise
    except ValueError as err:
        unit.skipped.append(stored.Skipped(log.stamp, sha256, short(err)))
        return twin
    if not unit.entries and not unit.skipped:  # what the reader chose (an adapter's torque source), said once
        unit.notes.extend(n for n in reading.notes if isinstance(n, formats.TorqueNote))
        unit.torque_source = formats.torque_source(reading.notes)
    unit.notes.extend(fleet_logs.log_notes(log.stamp, reading.notes, unit.notes))  # each column's kind once
    constant = constant_torque(unit, reading.vector, nominal.n_axes)
    if constant:
        return not_monitored(unit, log.stamp, sha256, constant)
    unit.monitor.add(log.stamp, residual, reading.temperature, reading.payload, expected)
    unit.entries.append(stored.Entry(log.stamp, sha256, residual, reading.temperature, reading.payload, expected,
                                     *load))
    return twin



def constant_torque(unit: Unit, vector: np.ndarray, n_axes: int) -> str:
    """Why the unit cannot be monitored when the log of feature ``vector`` (its
    :data:`faultgen.monitor.logs.FEATURES`, by name then axis) completes its learning and a feature
    is the same in every learning log (:func:`analysis.monitoring.varying_columns`: beyond
    rounding), which the PCA model cannot standardise: :data:`CONSTANT_TORQUE` and the features;
    "" otherwise (or before the learning's last log). The features are the residuals plus the
    twin's expectation, which may vary with the logs' conditions while the torque does not."""
    monitor = unit.monitor
    if monitor.pca is not None or len(monitor.training) + 1 < monitor.settings.train:
        return ""
    expected = monitor.learned_expectations or [0.0] * len(monitor.training)
    features = np.stack([e + x for (_, e, _), x in zip(monitor.training, expected)] + [vector])
    constant = np.setdiff1d(np.arange(features.shape[1]), varying_columns(features))
    if not constant.size:
        return ""
    named = [f"{fleet_logs.FEATURES[j // n_axes]} of axis {j % n_axes + 1}" for j in constant]
    more = f" and {len(named) - 3} more" if len(named) > 3 else ""
    return (f"{CONSTANT_TORQUE}: {', '.join(named[:3])}{more} the same in all {len(features)} learning logs, "
            "which can show no wear")


def not_monitored(unit: Unit, stamp: str, sha256: str, why: str) -> str:
    """Take the unit off the monitor (:func:`constant_torque`): its logs scored so far and the log
    ``stamp`` (its SHA-256 ``sha256``) kept as skipped, its monitor emptied (its status then "not monitored", its reason ``why``);
    returns the reason its later logs are skipped with, in this run and the next."""
    skipped = "the unit is not monitored: its torque does not vary from log to log"
    unit.skipped.extend(stored.Skipped(e.stamp, e.sha256, skipped) for e in unit.entries)
    unit.skipped.append(stored.Skipped(stamp, sha256, skipped))
    unit.entries.clear()
    unit.monitor = UnitMonitor(unit.monitor.unit, unit.monitor.settings, unit.monitor.n_axes, unit.monitor.signatures)
    unit.notes.append(why)
    unit.off_monitor = why
    return why


def _load(data) -> tuple[np.ndarray | None, float]:
    """The log's load (:func:`faultgen.monitor.life.load_integrals`) and its duration, s; (None,
    NaN) for a log it cannot take (one sample): the log is still scored."""
    try:
        return life.load_integrals(data.t, data.qd, data.tau), float(data.t[-1] - data.t[0])
    except ValueError:
        return None, float("nan")
