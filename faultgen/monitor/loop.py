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
scores only the new logs). Simulated cycles and calibrations are cached in ``OUT/.cache``; units
whose first logs trace the same motion (angles within :data:`SAME_PROGRAM` rad) and share a model
share their simulated cycles.
"""

from __future__ import annotations

import pickle
import warnings
from dataclasses import astuple, dataclass
from pathlib import Path

import mujoco
import numpy as np
from tqdm.auto import tqdm

from faultgen.data import atomic, measured
from faultgen.effects.payload import Payload
from faultgen.model import robots
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import report
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
    program: str
    settings_key: tuple


def _settings_key(settings: Settings, model_source: str) -> tuple:
    return (*astuple(settings), model_source)


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
        A bad log (the file and row named), a log older than the last one scored, or ``out`` holding
        a run with other settings.
    """
    nominal = robots.load(robot)
    units = fleet_logs.fleet(logs_dir)
    out = Path(out)
    cache = out / ".cache"
    model_source = "nominal" if settings.protocol != "twin" else (
        str(Path(calibrated).resolve()) if calibrated is not None else "per-unit" if calibrate else "nominal")
    key = _settings_key(settings, model_source) + (twin_temperature,)
    state = _load_state(out)
    for name, unit in state.items():
        if unit.settings_key != key:
            raise ValueError(f"{out}: holds a monitor run with other settings ({unit.settings_key}, now {key}); "
                             "choose a new OUT or rerun with the same options")
    pending = {}
    for name, unit_logs in units.items():
        done = state[name].monitor.last_stamp if name in state else None
        seen = {r["stamp"] for r in state[name].monitor.rows} | {s for s, _, _ in state[name].monitor.training} \
            if name in state else set()
        if done is not None:
            stamps = [g.stamp for g in unit_logs]
            late = [g for g in unit_logs[: stamps.index(done)] if g.stamp not in seen] if done in stamps else []
            if done not in stamps:
                raise ValueError(f"{name}: its last scored log ({done}) is no longer in {logs_dir}; put it back or "
                                 "score this folder into a new OUT")
            if late:
                raise ValueError(f"{late[0].path} is older than the last scored log of {name} ({done}); the monitor "
                                 "scores logs in stamp order: score this folder into a new OUT")
            unit_logs = unit_logs[stamps.index(done) + 1:]
        pending[name] = unit_logs
    cache.mkdir(parents=True, exist_ok=True)
    total = sum(len(v) for v in pending.values())
    bar = tqdm(total=total, desc="monitor", unit="log", disable=not progress)
    programs: list[tuple[np.ndarray, str]] = []
    twins: dict[tuple, Twin] = {}
    for name, unit_logs in pending.items():
        if not unit_logs:
            continue
        if name not in state:
            first = unit_logs[0]
            model = _model(nominal, settings, calibrated, calibrate, first, cache, name, progress)
            program = _program(nominal, first.path, programs)
            state[name] = _Unit(UnitMonitor(name, settings, nominal.n_axes), model, program, key)
        unit = state[name]
        twin = None
        if settings.protocol == "twin":
            twin_key = (unit.model, unit.program)
            if twin_key not in twins:
                bar.set_postfix_str(f"twin of {name}")
                twins[twin_key] = Twin(unit.model, Path(unit.program), cache / "cycles")
            twin = twins[twin_key]
            unit.monitor.signatures = twin.signatures
        bar.set_postfix_str(name)
        for log in unit_logs:
            reading = fleet_logs.read(nominal, log)
            residual, expected = reading.vector, None
            if twin is not None:
                at = reading.temperature if twin_temperature else REFERENCE_TEMPERATURE
                expected = twin.expected(at, reading.payload)
                residual = residual - expected
            unit.monitor.add(log.stamp, residual, reading.temperature, reading.payload, expected)
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
                with open(staging / ".state" / f"{name}.pkl", "wb") as f:
                    pickle.dump(state[name], f)
    return monitors


def _load_state(out: Path) -> dict[str, _Unit]:
    folder = out / ".state"
    if not folder.is_dir():
        return {}
    state = {}
    for path in sorted(folder.glob("*.pkl")):
        with open(path, "rb") as f:
            state[path.stem] = pickle.load(f)
    return state


def _model(nominal, settings: Settings, calibrated, calibrate: bool, first, cache: Path, unit: str,
           progress: bool) -> str:
    """The unit's model file: given, calibrated on its first log (cached), or nominal."""
    if settings.protocol != "twin":
        return str(nominal.path)
    if calibrated is not None:
        path = Path(calibrated)
        if path.is_dir():
            found = sorted((path / "model").glob("*_calibrated.xml")) or sorted(path.glob("*_calibrated.xml"))
            if not found:
                raise ValueError(f"{path}: no model/<robot>_calibrated.xml; give a `faultgen calibrate` output "
                                 "folder or its model file")
            path = found[0]
        return str(path)
    if not calibrate:
        return str(nominal.path)
    folder = cache / "calibrated" / unit
    if not folder.is_dir():
        from faultgen.calibrate import calibrate as run_calibration

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            run_calibration(str(nominal.path), first.path, folder, max_steps=CALIBRATION_STEPS, progress=False)
    return str(_without_payload(folder / "model" / f"{nominal.name}_calibrated.xml"))


def _without_payload(path: Path) -> Path:
    """The calibrated model without the part its log carried (the calibration's payload effect,
    written again with no mass: :class:`faultgen.effects.payload.Payload` removes its bodies): the
    twin carries each log's declared part instead. Written beside it (same assets and
    ``tasks.toml``) as ``<name>_twin.xml``."""
    target = path.with_name(path.name.replace("_calibrated.xml", "_twin.xml"))
    if not target.is_file():
        spec = mujoco.MjSpec.from_file(str(path))
        Payload(mass=0.0).write(spec, robots.load(path))
        atomic.write_text(target, spec.to_xml())
    return target


def _program(nominal, path: Path, programs: list) -> str:
    """The log to replay for a unit whose first log is ``path``: an earlier unit's when the motion
    is the same (:data:`SAME_PROGRAM`), so their twins share simulated cycles."""
    q = np.asarray(measured.read(path, nominal).q)
    for other, other_path in programs:
        if other.shape == q.shape and np.max(np.abs(other - q)) < SAME_PROGRAM:
            return other_path
    programs.append((q, str(path)))
    return str(path)
