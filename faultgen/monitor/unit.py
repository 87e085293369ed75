"""A unit of ``faultgen monitor`` (:func:`faultgen.monitor.loop.monitor`): its record, made here for
a unit seen for the first time (:func:`new_unit`, a :class:`faultgen.monitor.history.UnitHistory`),
its program (the log its twin replays, shared with an earlier unit
that runs the same motion: :func:`program_of`), its model (given, calibrated on its first log and
cached, or nominal: :func:`model_of`) and its twin with the fallbacks (calibrated or given model ->
nominal model -> protocol own: :func:`twin_of`). Logs come parsed from the run's
:class:`faultgen.monitor.logs.Source`, which reads each once.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import mujoco
import numpy as np

from faultgen.calibrate import plausibility
from faultgen.effects.payload import Payload
from faultgen.logs import formats
from faultgen.model import robots
from faultgen.monitor import history
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import programs as unit_programs
from faultgen.monitor import state as stored
from faultgen.monitor.history import UnitHistory
from faultgen.monitor.scoring import Settings, Stages
from faultgen.monitor.twin import Twin

#: Two units run the same program when their first logs have the same samples and angles within this, rad.
SAME_PROGRAM = unit_programs.SAME_PROGRAM
#: Effects searched when a unit's model is calibrated on its first log (faultgen.calibrate).
CALIBRATION_STEPS = 3
#: Whether the unit's calibration fits the dry and viscous friction of every moving axis, always
#: (:func:`faultgen.calibrate.loop.own_friction`), so each axis's wear is read in % of its own
#: fitted dry friction rather than the nominal one where the search leaves an axis.
#: On: on the four fleets of docs/analysis.md ("Wear in the robot's own scale"; with
#: ``friction_torque`` among the features and the twin's reference at 35 deg C) the second-law
#: fleet's median error fell from 3.90 to 2.87 points and its coverage rose from 73.9 to 95.9 %, the
#: first law's three fleets within their criteria (1.98, 1.72, 2.39 points), no healthy unit
#: alarming. With the twin's reference at 20 deg C it must be off: the shipped irb6700 fleet's unit02
#: (axis 2's dry level fitted 56 % above nominal, viscous at about half) saturates there with its
#: 35 kg part (:data:`faultgen.monitor.twin.REFERENCE_TEMPERATURE`).
OWN_FRICTION = True


#: The kinds of model a unit's twin falls back through, each to the next when its twin cannot be
#: built (:func:`twin_of`): "given" and "calibrated" to "friction", "friction" to "nominal",
#: "nominal" to "none" (protocol own).
FALLBACK = {"given": "nominal", "calibrated": "friction", "friction": "nominal", "nominal": "none"}
#: What each kind is called in a unit's reason.
KIND_NAMES = {"given": "given model", "calibrated": "calibrated model", "nominal": "nominal model",
              "friction": "nominal model with the unit's own friction", "none": "protocol own"}


def calibration_steps(kind: str) -> int:
    """The search's length of a unit's calibration of ``kind``: :data:`CALIBRATION_STEPS` for
    "calibrated", none for "friction" (its own friction on the nominal model only)."""
    return 0 if kind == "friction" else CALIBRATION_STEPS


def calibration_key(nominal_sha256: str, first_sha256: str, kind: str = "calibrated",
                    log_format: str = formats.DEFAULT) -> dict:
    """The key of a unit's cached calibration of ``kind`` ("calibrated" or "friction"): the nominal
    model's and the first log's SHA-256, the search's length (:func:`calibration_steps`), the logs'
    format with its options (:attr:`faultgen.logs.formats.LogFormat.key`: other torque constants read
    other torques from the same file) and, when on, :data:`OWN_FRICTION` (a calibration of the
    default format or without it keeps its key)."""
    key = {"robot": nominal_sha256, "log": first_sha256, "steps": calibration_steps(kind)}
    if log_format != formats.DEFAULT:
        key["format"] = log_format
    if OWN_FRICTION:
        key["friction"] = "every axis: one dry level and viscous"
    return key


def new_unit(name, units, nominal, settings: Settings, calibrated_model, calibrate: bool, programs: list,
              source: fleet_logs.Source) -> UnitHistory:
    """A unit seen for the first time: its first log (with the twin, its first log that can be read:
    an empty or broken log before it is skipped, named, and the twin built on the next), its program
    (the log its twin replays) and the kind of model asked for (given, calibrated on its first log,
    nominal); protocol ``own`` without a twin or when no log of it can be read. A first log the
    nominal model cannot explain takes the unit off the monitor (:func:`plausible`, :func:`refuse`),
    whatever the model, and is no program for other units. The model itself is made with the twin
    (:func:`twin_of`), which falls back when it cannot be. The first log is read here, once
    (``source``)."""
    stages = Stages.new(name, settings, nominal.n_axes)

    def unit(kind: str, program: tuple[str, str] | None, notes=()) -> UnitHistory:
        return UnitHistory(name, kind, program, first_key, notes=list(notes), stages=stages)

    first = units[name][0]
    if settings.protocol == "twin":
        first = next((log for log in units[name] if source.get(log).error is None), first)
    first_key = (first.stamp, source.get(first).sha256)
    if settings.protocol != "twin":
        return unit("none", None)
    kind = "given" if calibrated_model is not None else "calibrated" if calibrate else "nominal"
    if source.get(first).error is None:
        try:
            plausible(nominal, source.get(first).checked())
        except plausibility.ImplausibleLogError as err:
            refused = unit(kind, None)
            refuse(refused, err)
            return refused
    try:
        program = program_of(first, name, programs, source)
    except ValueError as err:
        return unit("none", None, [history.Note(f"no log of it can be read to replay ({short(err)}): protocol own")])
    return unit(kind, program)


#: The start of the note (units.csv's reason) of a unit whose first log the nominal model cannot
#: explain (:func:`plausible`, the calibration's own check): the unit is not monitored, whatever
#: model was asked for: a twin of any model would read its torque in the wrong scale (a log
#: logged motor-side read 0.16 % wear where the truth was 44 %).
REFUSED = "not monitored: its first log is refused"


def plausible(nominal: robots.Robot, data) -> None:
    """Refuse a unit's first log (checked, :class:`faultgen.logs.measured.MeasuredData`) that the
    ``nominal`` model cannot explain, as ``faultgen calibrate`` refuses it, with its message
    (:func:`faultgen.calibrate.plausibility.check` on the nominal model's torque along the log's
    motion; a log longer than :data:`faultgen.calibrate.MAX_ROWS` averaged down first, as the
    calibration does). Whatever model the unit's twin is of: a refusal is the unit's error, never a
    reason to fall back to another model.

    Raises
    ------
    faultgen.calibrate.plausibility.ImplausibleLogError
        Motor-side torque, another robot's log, a torque column in another unit or sign.
    """
    from faultgen.calibrate import MAX_ROWS, decimate, search
    from faultgen.calibrate.prediction import predicted_motion

    data = decimate(data, MAX_ROWS) if len(data) > MAX_ROWS else data
    tau = np.asarray(data.tau)
    plausibility.check(nominal, tau, predicted_motion(nominal, data)[0], np.abs(data.qd) >= search.REST_SPEED)


def refuse(unit: UnitHistory, err: ValueError) -> str:
    """Take ``unit`` off the monitor for its first log's refusal ``err`` (:data:`REFUSED`, the
    message kept whole): noted in its reason; returns the reason its logs are skipped with."""
    unit.notes.append(history.Note(f"{REFUSED} ({unit.first[0]}): {' '.join(str(err).split())}", history.REFUSED))
    return REFUSED_SKIP


#: The reason each log of a unit refused (:data:`REFUSED`) is skipped with.
REFUSED_SKIP = "the unit is not monitored: its first log is refused (the unit's reason says why)"


def refused_note(unit: UnitHistory) -> history.Note | None:
    """The note that took ``unit`` off the monitor for its first log (:func:`refuse`), or None."""
    return next((n for n in unit.notes if n.kind == history.REFUSED), None)


def fallback_notes(unit: UnitHistory) -> list[history.Note]:
    """The unit's notes that say its twin fell back to another model (written by :func:`twin_of`,
    :func:`chain_notes`)."""
    return [n for n in unit.notes if n.kind == history.FALLBACK]


def chain_notes(tried: list[tuple[str, str]], final: str) -> list[history.Note]:
    """The notes of a twin's fallbacks: ``tried``, the kinds of model (:data:`FALLBACK`) whose twin
    failed, in order, each with its error; ``final`` the kind used at last. Kinds that failed one
    after another on the same error share one note that says it once, with their count (a replay
    no model can follow fails alike for each: three times 300 characters before)."""
    groups: list[tuple[list[str], str]] = []
    for kind, error in tried:
        if groups and groups[-1][1] == error:
            groups[-1][0].append(kind)
        else:
            groups.append(([kind], error))
    notes = []
    for i, (kinds, error) in enumerate(groups):
        then = KIND_NAMES[groups[i + 1][0][0] if i + 1 < len(groups) else final]
        if len(kinds) == 1:
            notes.append(history.Note(f"the twin of the {KIND_NAMES[kinds[0]]} failed ({error}); {then} used",
                                      history.FALLBACK))
            continue
        names = [KIND_NAMES[k] for k in kinds]
        notes.append(history.Note(f"the twins of the {', the '.join(names[:-1])} and the {names[-1]} failed "
                                  f"({len(kinds)} times, each on the same: {error}); {then} used", history.FALLBACK))
    return notes


def twin_of(unit: UnitHistory, context, twins: dict, progress: bool, source: fleet_logs.Source) -> Twin | str | None:
    """The unit's twin (its program among the fleet's logs, ``context.units``, its cycles cached in
    ``context.out`` and simulated on the run's ``context.stepper``: a
    :class:`faultgen.monitor.feed.Context`), or None for a unit under protocol ``own``; its model
    comes from :func:`model_of` (the robots of ``source``, or the unit's calibration). A unit not
    yet scored falls back
    through :data:`FALLBACK` when its twin cannot be built (its calibration refused as implausible,
    say: to its own friction on the nominal model, then to the nominal model, then to protocol ``own``);
    a unit already scored against a twin that cannot be built again gets the reason (a str), and
    its new logs are skipped with it. Each fallback is noted in the unit's reason, the kinds that
    failed on the same error in one note (:func:`chain_notes`). A first log refused by the
    calibration (:class:`faultgen.calibrate.plausibility.ImplausibleLogError`) is no reason to fall
    back: the unit is taken off the monitor (:func:`refuse`) and the reason returned."""
    tried: list[tuple[str, str]] = []  # (kind, error) that failed in this call, noted by chain_notes
    start = len(unit.notes)
    units, out = context.units, context.out
    while unit.model != "none":
        try:
            first_log = next((g for g in units[unit.unit] if g.stamp == unit.first[0]), None)
            model = model_of(source, unit.model, unit.first, first_log, out, progress)
            twin_key = (str(model.path), unit.program)
            if twin_key not in twins:
                twins[twin_key] = Twin(model, source.get(log_of(units, *unit.program)), out / ".cache" / "cycles",
                                       root=out, stepper=context.stepper)
            twin = twins[twin_key]
        except stored.StateError:
            raise
        except plausibility.ImplausibleLogError as err:  # the log refused: the unit's error, never a fallback
            if unit.entries:
                return f"the twin of the {KIND_NAMES[unit.model]} cannot be built again ({short(err)})"
            return refuse(unit, err)
        except ValueError as err:
            if unit.entries:
                return f"the twin of the {KIND_NAMES[unit.model]} cannot be built again ({short(err)})"
            fallback = FALLBACK[unit.model]
            if fallback == "friction" and not OWN_FRICTION:
                fallback = "nominal"
            tried.append((unit.model, short(err)))
            unit.notes[start:] = chain_notes(tried, fallback)
            unit.model = fallback
            continue
        baseline = unit.stages.baseline
        if baseline.signatures is not None and not np.array_equal(baseline.signatures, twin.signatures):
            raise stored.StateError(f"{out / '.state' / (unit.unit + '.json')}: its wear signatures are not those of "
                             f"the twin of {unit.unit} now (another model or program); score this folder "
                             "into a new OUT")
        baseline.signatures = twin.signatures
        if unit.signatures is None and not unit.program_changes:
            unit.signatures = twin.signatures
        return twin
    unit.program = None
    return None



def short(err: Exception, limit: int = 300) -> str:
    text = " ".join(str(err).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."



def log_of(units: dict[str, list[fleet_logs.Log]], unit: str, stamp: str) -> fleet_logs.Log:
    """The log ``stamp`` of ``unit`` in the fleet folder (a state names logs, never paths)."""
    for log in units.get(unit, ()):
        if log.stamp == stamp:
            return log
    raise ValueError(f"the log {unit}/{stamp} that an earlier run scored or replays is no longer in the fleet folder; "
                     "put it back or score this folder into a new OUT")



def model_of(source: fleet_logs.Source, kind: str, first: tuple[str, str], first_log: fleet_logs.Log | None,
             out: Path, progress: bool) -> robots.Robot:
    """The robot a unit's twin simulates, of ``kind``: "nominal" and "given" (``--calibrated``) are
    the robots ``source`` holds, resolved once where it was made; "calibrated": calibrated on the
    unit's first log (``first``: its stamp and SHA-256; ``first_log`` the log, parsed by ``source``
    and needed only when the calibration is not cached); "friction": the same with no search, only
    every moving axis's own dry and viscous friction fitted on the nominal model
    (:func:`faultgen.calibrate.loop.own_friction`), the fallback of a calibration whose search fitted
    something implausible (a Stribeck velocity 20 x nominal: docs/analysis.md, "A calibration refused
    as implausible"). Both are cached (the model and report, not the calibration's figure nor its
    residual tests, which nothing reads there and cost 1.6 s and up to 1.4 s a unit) in
    ``OUT/.cache/calibrated`` under the digest of the nominal model, the log and the search's
    length, beside a record of the calibrated model's SHA-256 that a later run checks; the robot is
    that model without its log's part (:func:`without_payload`), as its writer returned it (or,
    cached, as an earlier run wrote it: :func:`cached_model`).

    Raises
    ------
    ValueError
        The given model did not load, the calibration fails or is implausible, or its cache does
        not match its record.
    """
    nominal = source.robot
    if kind == "nominal":
        return nominal
    if kind == "given":
        if not isinstance(source.given, robots.Robot):
            raise ValueError(str(source.given) if source.given is not None else "no --calibrated model given")
        return source.given
    key = calibration_key(stored.sha256_file(nominal.path), first[1], kind, source.format_key)
    digest = stored.key_name(key)
    confined = stored.out_folder(out)
    root = out / ".cache" / "calibrated"
    folder, record = root / digest, root / f"{digest}.json"
    model = folder / "model" / f"{nominal.name}_calibrated.xml"
    if record.exists() or record.is_symlink():
        stored.read_calibration(record, out, key, model)
        calibrated = cached_model(confined.path(model))
    else:
        if first_log is None:
            raise ValueError(f"the first log of the unit ({first[0]}), which its model was calibrated on, is no longer "
                             "in the fleet folder and its calibration is not cached")
        confined.remove(folder)  # a run killed before its record: ours to redo
        confined.mkdir(root)
        from faultgen.calibrate import calibrate as run_calibration

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            calibrated = run_calibration(nominal, source.get(first_log).checked(), folder,
                                         max_steps=calibration_steps(kind), progress=False,
                                         friction_every_axis=OWN_FRICTION or kind == "friction", figure=False,
                                         tests=False).model
        stored.write_calibration(record, out, key, model)
    implausible = plausibility.implausible_parameters(nominal, calibrated)
    if implausible:
        raise ValueError(f"its calibration on the first log is implausible: {'; '.join(implausible)}")
    return without_payload(calibrated, out)


def cached_model(path: Path) -> robots.Robot:
    """A model file that an earlier run of the monitor wrote into ``OUT/.cache/calibrated`` (the
    calibrated model, checked against its record first, or its twin model): state this process did
    not make, read once here with :func:`faultgen.model.robots.load`'s checks."""
    return robots.load(path)


def without_payload(calibrated: robots.Robot, out: Path) -> robots.Robot:
    """The calibrated model without the part its log carried (the calibration's payload effect,
    written again with no mass: :class:`faultgen.effects.payload.Payload` removes its bodies): the
    twin carries each log's declared part instead. Written beside it (same assets and
    ``tasks.toml``) as ``<name>_twin.xml`` (:func:`faultgen.model.robots.write`, which returns the
    robot written), from the calibrated model's file (checked as any robot description when it
    was read: no file outside its folder) parsed again by MuJoCo; one an earlier run wrote is
    read (:func:`cached_model`). Both stay inside ``out`` (:func:`faultgen.monitor.state.out_folder`:
    a ``_twin.xml`` linked out of it is refused, never parsed)."""
    path = calibrated.path
    confined = stored.out_folder(out)
    target = confined.path(path.with_name(path.name.replace("_calibrated.xml", "_twin.xml")))
    if target.is_file():
        return cached_model(target)
    spec = mujoco.MjSpec.from_file(str(confined.path(path)))
    Payload(mass=0.0).write(spec, calibrated)
    return robots.write(target, spec.to_xml(), confined.write_text)


def same_times(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two logs of as many samples are sampled at the same times from their starts (within
    half the shortest sample interval): the same angles at another pace are another program (a
    motion three times faster asks nine times the torque of inertia)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if len(a) < 2:
        return True
    return bool(np.max(np.abs((a - a[0]) - (b - b[0]))) <= 0.5 * np.min(np.diff(a)))


def program_of(first: fleet_logs.Log, unit: str, programs: list, source: fleet_logs.Source) -> tuple[str, str]:
    """The log (unit, stamp) to replay for ``unit`` whose first log is ``first`` (parsed by
    ``source``, which keeps a program for the twins that replay it): an earlier unit's when the
    motion is the same (:data:`SAME_PROGRAM`: the same samples at the same times, :func:`same_times`, or a whole number of cycles of the
    earlier one at another rate, :func:`faultgen.monitor.programs.same_program`), so their twins share simulated
    cycles. ``programs``: the (checked log, program) of the earlier units' programs, appended to.

    Raises
    ------
    ValueError
        The first log cannot be read (file and row named).
    """
    data = source.get(first).checked()
    q = np.asarray(data.q)
    for other, other_program in programs:
        other_q = np.asarray(other.q)
        if other_q.shape == q.shape and np.max(np.abs(other_q - q)) < SAME_PROGRAM and same_times(other.t, data.t):
            return other_program
        if other_q.shape != q.shape and unit_programs.same_program(other.t, other_q, other.cycle, data.t, q):
            return other_program
    source.keep(first)
    programs.append((data, (unit, first.stamp)))
    return (unit, first.stamp)
