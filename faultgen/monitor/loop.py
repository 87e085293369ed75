"""``faultgen monitor``: a fleet's measured logs in, alarms and the worn axis out (issue 46).

For each unit (a folder of ``LOGS``, its logs in stamp order, :mod:`faultgen.monitor.logs`):

(a) the model: calibrated on the unit's first log (:func:`faultgen.calibrate.calibrate`, cached),
    or a calibrated model given for every unit, or the nominal model;
(b) the twin (:class:`faultgen.monitor.twin.Twin`): the model replaying the unit's own first log,
    at each payload the logs declare, healthy and with each axis in turn worn;
(c)-(d) the unit's monitor (:class:`faultgen.monitor.scoring.UnitMonitor`): learned on the first
    logs, then every later log scored in stamp order.

Outputs in OUT, written together (:func:`faultgen.data.atomic.atomic_folder`): ``alarms.csv``,
``scores.csv``, ``<unit>.png`` and the monitors' state in ``.state`` (a rerun on a grown folder
scores only the new logs; JSON, never a pickle: :mod:`faultgen.monitor.state`). Simulated cycles
and calibrations are cached in ``OUT/.cache``, each checked against what it was made from; units
whose first logs trace the same motion (angles within :data:`SAME_PROGRAM` rad) and share a model
share their simulated cycles.
"""

from __future__ import annotations

import hashlib
import json
import shutil
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np
from tqdm.auto import tqdm

from faultgen.data import atomic, measured
from faultgen.effects.payload import Payload
from faultgen.model import robots
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import report
from faultgen.monitor import state as stored
from faultgen.monitor.scoring import Settings, UnitMonitor
from faultgen.monitor.twin import REFERENCE_TEMPERATURE, Twin

#: Two units run the same program when their first logs have the same samples and angles within this, rad.
SAME_PROGRAM = 1e-3
#: Effects searched when a unit's model is calibrated on its first log (faultgen.calibrate).
CALIBRATION_STEPS = 3


@dataclass
class _Unit:
    monitor: UnitMonitor
    model: str
    program: tuple[str, str] | None  # (unit, stamp) of the log the twin replays
    entries: list[stored.Entry] = field(default_factory=list)


def monitor(robot: str | Path, logs_dir: str | Path, out: str | Path, *, calibrated: str | Path | None = None,
            calibrate: bool = True, settings: Settings = Settings(), twin_temperature: bool = False,
            progress: bool = True) -> list[UnitMonitor]:
    """Monitor every unit of ``logs_dir`` (module docstring); returns the units' monitors.

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

    Raises
    ------
    ValueError
        A bad log (the file and row named), a log older than the last one scored, a scored log that
        changed since, or ``out`` holding a run with other settings or a state or cache that does
        not match them (:mod:`faultgen.monitor.state`, the file named).
    """
    nominal = robots.load(robot)
    units = fleet_logs.fleet(logs_dir)
    out = Path(out)
    cache = out / ".cache"
    calibrated_model = _given_model(calibrated) if settings.protocol == "twin" and calibrated is not None else None
    model_source = "nominal" if settings.protocol != "twin" else (
        stored.sha256_file(calibrated_model) if calibrated_model is not None else "per-unit" if calibrate else "nominal")
    key = stored.settings_digest(settings, model_source, twin_temperature, stored.sha256_file(nominal.path))
    n_features = len(fleet_logs.FEATURES) * nominal.n_axes
    state = _load_state(out, units, key, settings, nominal.n_axes, n_features)
    pending = {}
    for name, unit_logs in units.items():
        if name not in state:
            pending[name] = unit_logs
            continue
        entries = state[name].entries
        by_stamp = {g.stamp: g for g in unit_logs}
        done = entries[-1].stamp
        if done not in by_stamp:
            raise ValueError(f"{name}: its last scored log ({done}) is no longer in {logs_dir}; put it back or "
                             "score this folder into a new OUT")
        for entry in entries:
            log = by_stamp.get(entry.stamp)
            if log is not None and stored.sha256_file(log.path) != entry.sha256:
                raise ValueError(f"{log.path} changed since it was scored into {out} (SHA-256 {entry.sha256[:12]}..., "
                                 "now another): score this folder into a new OUT")
        seen = {e.stamp for e in entries}
        stamps = [g.stamp for g in unit_logs]
        late = [g for g in unit_logs[: stamps.index(done)] if g.stamp not in seen]
        if late:
            raise ValueError(f"{late[0].path} is older than the last scored log of {name} ({done}); the monitor "
                             "scores logs in stamp order: score this folder into a new OUT")
        pending[name] = unit_logs[stamps.index(done) + 1:]
    cache.mkdir(parents=True, exist_ok=True)
    total = sum(len(v) for v in pending.values())
    bar = tqdm(total=total, desc="monitor", unit="log", disable=not progress)
    programs: list[tuple[np.ndarray, tuple[str, str]]] = []
    twins: dict[tuple, Twin] = {}
    for name, unit_logs in pending.items():
        if not unit_logs:
            continue
        first = units[name][0] if name not in state else _log(units, name, state[name].entries[0].stamp)
        model = _model(nominal, settings, calibrated_model, calibrate, first, out, progress)
        if name not in state:
            program = _program(nominal, first, name, programs) if settings.protocol == "twin" else None
            state[name] = _Unit(UnitMonitor(name, settings, nominal.n_axes), model, program)
        unit = state[name]
        twin = None
        if settings.protocol == "twin":
            twin_key = (model, unit.program)
            if twin_key not in twins:
                bar.set_postfix_str(f"twin of {name}")
                twins[twin_key] = Twin(model, _log(units, *unit.program).path, cache / "cycles", root=out)
            twin = twins[twin_key]
            if unit.monitor.signatures is not None and not np.array_equal(unit.monitor.signatures, twin.signatures):
                raise ValueError(f"{out / '.state' / (name + '.json')}: its wear signatures are not those of the twin "
                                 f"of {name} now (another model or program); score this folder into a new OUT")
            unit.monitor.signatures = twin.signatures
        bar.set_postfix_str(name)
        for log in unit_logs:
            sha256 = stored.sha256_file(log.path)
            reading = fleet_logs.read(nominal, log)
            residual, expected = reading.vector, None
            if twin is not None:
                at = reading.temperature if twin_temperature else REFERENCE_TEMPERATURE
                expected = twin.expected(at, reading.payload)
                residual = residual - expected
            unit.monitor.add(log.stamp, residual, reading.temperature, reading.payload, expected)
            unit.entries.append(stored.Entry(log.stamp, sha256, residual, reading.temperature, reading.payload,
                                             expected))
            bar.update()
    bar.close()
    monitors = [state[name].monitor for name in units if name in state]
    note = "wear signature match" if settings.protocol == "twin" else "share of Q"
    with atomic.atomic_folder(out) as staging:
        report.write_alarms(staging / "alarms.csv", monitors)
        report.write_scores(staging / "scores.csv", monitors, nominal.n_axes)
        for m in monitors:
            report.chart(staging / f"{m.unit}.png", m, note)
        (staging / ".state").mkdir()
        for name in units:
            if name in state:
                unit = state[name]
                stored.write_unit(staging / ".state" / f"{name}.json",
                                  stored.UnitState(name, key, unit.program, unit.monitor.signatures, unit.entries))
    return monitors


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
        if not kept.entries:
            continue
        state[name] = _Unit(stored.replay(kept, settings, n_axes), "", kept.program, list(kept.entries))
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


def _model(nominal, settings: Settings, calibrated: Path | None, calibrate: bool, first, out: Path,
           progress: bool) -> str:
    """The unit's model file: given, calibrated on its first log (cached in ``OUT/.cache/calibrated``
    under the digest of the nominal model, the log and the search's length, beside a record of
    the calibrated model's SHA-256 that a later run checks), or nominal."""
    if settings.protocol != "twin" or (calibrated is None and not calibrate):
        return str(nominal.path)
    if calibrated is not None:
        return str(calibrated)
    key = {"robot": stored.sha256_file(nominal.path), "log": stored.sha256_file(first.path),
           "steps": CALIBRATION_STEPS}
    digest = hashlib.sha256(json.dumps(key, sort_keys=True).encode()).hexdigest()[:24]
    root = out / ".cache" / "calibrated"
    folder, record = root / digest, root / f"{digest}.json"
    model = folder / "model" / f"{nominal.name}_calibrated.xml"
    if record.exists() or record.is_symlink():
        stored.read_calibration(record, out, key, model)
    else:
        if folder.exists() or folder.is_symlink():  # a run killed before its record: ours to redo
            stored.inside(folder, out)
            shutil.rmtree(folder) if folder.is_dir() and not folder.is_symlink() else folder.unlink()
        from faultgen.calibrate import calibrate as run_calibration

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            run_calibration(str(nominal.path), first.path, folder, max_steps=CALIBRATION_STEPS, progress=False)
        stored.write_calibration(record, key, model)
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


def _program(nominal, first: fleet_logs.Log, unit: str, programs: list) -> tuple[str, str]:
    """The log (unit, stamp) to replay for ``unit`` whose first log is ``first``: an earlier unit's
    when the motion is the same (:data:`SAME_PROGRAM`), so their twins share simulated cycles."""
    q = np.asarray(measured.read(first.path, nominal).q)
    for other, other_program in programs:
        if other.shape == q.shape and np.max(np.abs(other - q)) < SAME_PROGRAM:
            return other_program
    programs.append((q, (unit, first.stamp)))
    return (unit, first.stamp)
