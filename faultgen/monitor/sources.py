"""A unit's torque source per log (issue 90, item 5): the source of each log
(:func:`faultgen.logs.formats.torque_source`: the ``ur-rtde`` reader's measured current x torque
constant, the controller's current as torque, or the commanded moment, chosen per file from its
header) is part of what a baseline is for, as the program is.

- **Baselines by program and source.** A unit's baselines are its programs' (:mod:`faultgen.monitor.
  programs`): baseline 0 its first program's, read from its first log's source
  (:attr:`faultgen.monitor.history.UnitHistory.torque_source`); baseline ``k`` the ``k``-th of its
  :attr:`~faultgen.monitor.history.UnitHistory.program_changes`, of the source it records
  (:attr:`faultgen.monitor.history.ProgramChange.source`). A log of a known program read from a
  source that program has no baseline for starts one (:func:`change`): a program change whose
  program log is the program's own (the same motion, the same twin), learned on its own first logs
  as a new program's baseline is, while the unit's other baselines go on; a log is never scored
  against a baseline of another source (a torque read with other constants, or a command instead
  of a measurement, would read as wear or hide it).
- **Said on its day.** The change is noted (the unit's reason, the console's and the page's notes)
  with its stamp, the source before and after; units.csv's ``torque_source`` names every source the
  unit's scored logs were read from, in order, each after the first with the day it began
  (:func:`seen`).
"""

from __future__ import annotations

from faultgen.monitor import history

#: More source changes than this in a unit's scored logs are named as a mix (each source and its
#: count of logs) rather than one by one (:func:`seen`).
MAX_NAMED_CHANGES = 3


def program_log(unit, k: int) -> tuple[str, str]:
    """The (unit, stamp) of the log that baseline ``k`` of ``unit`` replays (0: the unit's program)."""
    return unit.program if k == 0 else unit.program_changes[k - 1].program


def of_baseline(unit, k: int) -> str:
    """The torque source of ``unit``'s baseline ``k`` ("": unnamed, the measured format's; a
    program change recorded without one, by a run before sources were kept, is the unit's first's)."""
    if k == 0:
        return unit.torque_source
    return unit.program_changes[k - 1].source or unit.torque_source


def motion_of(unit, k: int) -> int:
    """The first baseline of ``unit`` that replays the program of baseline ``k`` (its motion's:
    ``k`` itself for a program new to the unit, that program's first baseline for a source change)."""
    log = program_log(unit, k)
    return next(j for j in range(k + 1) if program_log(unit, j) == log)


def baseline_of(unit, motion: int, source: str) -> int | None:
    """The baseline of ``unit`` for the program of baseline ``motion`` read from ``source``, or None."""
    return next((j for j in range(1 + len(unit.program_changes))
                 if motion_of(unit, j) == motion and of_baseline(unit, j) == source), None)


def distinct(references: list) -> list:
    """``references`` (:attr:`faultgen.monitor.history.UnitHistory.references`, one per baseline) without the
    repeats a source change adds (the same object as its program's): one per program, in order."""
    return [r for i, r in enumerate(references) if all(r is not other for other in references[:i])]


def change(unit, log, motion: int, source: str, signatures, changed) -> int:
    """A new baseline of ``unit`` for its program of baseline ``motion`` read from ``source`` from
    ``log`` on (a program change on that program's own log, :class:`faultgen.monitor.state.
    ProgramChange` with ``source``; ``signatures`` its twin's), made empty by ``changed`` (the
    baselines' ``new``, :class:`faultgen.monitor.programs.Baselines`) and noted with the source
    before it. Returns its index."""
    before = of_baseline(unit, unit.entries[-1].program) if unit.entries else unit.torque_source
    unit.references.append(unit.references[motion])
    unit.program_changes.append(history.ProgramChange(log.stamp, program_log(unit, motion), len(unit.entries),
                                                      signatures, source))
    changed(signatures)
    name = unit.references[motion].name
    unit.notes.append(history.Note(f"torque source changed at {log.stamp}: {source or 'the logged torque'} (before: "
                                   f"{before or 'the logged torque'}); {name}'s logs of this source learn their own "
                                   "baseline on their own first logs, never scored against the other source's"))
    return len(unit.program_changes)


def seen(unit) -> str:
    """The torque sources of ``unit``'s scored logs in stamp order (units.csv's ``torque_source``):
    one source as it is named; a few changes as ``"A, B from 2026-03-14"`` (each source after the
    first with the stamp of its first log); more than :data:`MAX_NAMED_CHANGES` as a mix (each source
    and its count of logs, and the first change's stamp); "" when none is named."""
    runs: list[list] = []  # [source, first stamp, logs]
    counts: dict[str, int] = {}
    for entry in unit.entries:
        source = of_baseline(unit, entry.program)
        counts[source] = counts.get(source, 0) + 1
        if runs and runs[-1][0] == source:
            continue
        runs.append([source, entry.stamp])
    if not runs:
        return unit.torque_source
    if len(runs) == 1:
        return runs[0][0]
    named = [source or "the logged torque" for source, _ in runs]
    if len(runs) - 1 <= MAX_NAMED_CHANGES:
        return ", ".join([named[0]] + [f"{n} from {stamp}" for n, (_, stamp) in zip(named[1:], runs[1:])])
    mix = ", ".join(f"{source or 'the logged torque'}: {n} logs" for source, n in counts.items())
    return f"a mix of {mix} ({len(runs) - 1} changes from {runs[1][1]})"


def labels(unit) -> list[str]:
    """Each baseline's name (``entries``' ``program`` indexes them): ``"program M"``, M its program's
    number in the order met, followed by its torque source where the unit's baselines have more than one."""
    count = 1 + len(unit.program_changes)
    motions = sorted({motion_of(unit, k) for k in range(count)})
    names = [f"program {motions.index(motion_of(unit, k)) + 1}" for k in range(count)]
    if len({of_baseline(unit, k) for k in range(count)}) > 1:
        names = [f"{name} ({of_baseline(unit, k) or 'the logged torque'})" for k, name in enumerate(names)]
    return names

