"""What ``faultgen monitor`` prints when a run ends: one line per unit (its status, the model its
twin is of, its alarm or its reason, and its program mix where it ran several programs), the
fleet's count of alarms beside the chance of a persistent
alarm on a healthy unit (where that says something), what was passed over (files that are not logs,
events rows of no unit), the files written, and the units that are
degraded or not monitored. Text only: the command prints it (faultgen/cli/monitoring.py)."""

from __future__ import annotations

from pathlib import Path

from faultgen.monitor import lights, page, steps
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor.loop import EXIT_SOME_UNITS_NOT_MONITORED
from faultgen.monitor.scoring import Settings


def summary(outcome, settings: Settings, out: Path) -> tuple[list[str], str]:
    """The lines for standard output, and the line for standard error ("" when every unit is
    monitored), of a finished run's ``outcome`` (:class:`faultgen.monitor.loop.Outcome`: its
    units' records and statuses) with ``settings``, its outputs in ``out``."""
    monitors = outcome.units
    alarmed = [m for m in monitors if m.stages.alarm.first_alarm]
    by_unit = {m.unit: m for m in monitors}
    lines = [f"events.csv changed for {unit} since the last run: re-scored from its first log (the earliest event "
             f"added, changed or removed: {since})" for unit, since in getattr(outcome, "rescored", [])]
    for status in outcome.statuses:
        m = by_unit.get(status.unit)
        alarm = m is not None and m.stages.alarm.first_alarm
        # the fallbacks are said once, beside the status (status.basis), not again in the reason
        reason = status.reason.replace(status.fallback, "").replace("; ; ", "; ").strip("; ") if status.fallback \
            else status.reason
        reason = reason.removeprefix(f"{status.status}: ")  # "not monitored: ..." beside the status said once
        what = f"alarm {lights.alarm_dates(steps.alarm_row(m))}, axis {m.stages.alarm.source_axis}" if alarm else \
            steps.alarm_row(m)["evidence"] if m is not None and status.status == "monitored" else reason
        mix = f"; programs: {status.programs}" if status.programs and status.programs not in what else ""
        lines.append(f"{status.unit}: {status.status} ({status.protocol}"
                     f"{', ' + status.model + ' model' if status.model else ''}{status.basis()}): {what}{mix}")
    logs_scored = max((sum(r.phase == "monitoring" for r in m.rows) for m in monitors), default=0)
    # a log's chance of alarming on a healthy unit: T2 or Q (own), or any of the N axes' lower
    # bounds over a limit the unworn estimate lies below (twin); the report page says the same
    statement = page.false_alarm_statement(settings.protocol, settings.alpha, settings.persistence, settings.train,
                                           monitors[0].stages.n_axes if monitors else 1, logs_scored)  # "" where it says nothing
    lines.append(" ".join(filter(None, (f"{len(alarmed)} of {len(monitors)} units alarm.", statement))))
    passed = getattr(outcome, "passed_over", [])
    if passed:
        name, reason = passed[0]
        more = f" (and {len(passed) - 1} more)" if len(passed) > 1 else ""
        lines.append(f"passed over {len(passed)} entries of the logs folder: {fleet_logs.passed_entry(name, reason)}"
                     f"{more}; a unit folder's are named in the unit's reason in {out / 'units.csv'}")
    tables = ("units.csv", "alarms.csv", "scores.csv", "wear.csv", "rul.csv", "life.csv",
              *(("tests.csv",) if outcome.tests else ()))
    lines.append(f"wrote {', '.join(str(out / name) for name in tables)}, {len(monitors)} charts and the fleet report "
                 f"{out / page.PAGE}")
    short = [s for s in outcome.statuses if s.status in ("degraded", "not monitored")]
    if not short:
        return lines, ""
    return lines, (f"{len(short)} of {len(outcome.statuses)} units are degraded or not monitored "
                   f"({', '.join(s.unit for s in short[:5])}{', ...' if len(short) > 5 else ''}): their reasons are "
                   f"in {out / 'units.csv'}; exit status {EXIT_SOME_UNITS_NOT_MONITORED}")
