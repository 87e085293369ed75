"""Sim-vs-measured calibration: find where the model and a robot's torque log disagree, name the
missing physical effect, add it to the model, and show the gap shrink.

The workflow (:func:`calibrate`, ``faultgen calibrate``):

1. read and check the measured file (:func:`faultgen.data.measured.read`; velocities and
   accelerations from a Savitzky-Golay filter when the file has none), and refuse a log the robot
   cannot explain (:mod:`faultgen.calibrate.plausibility`) before writing anything;
2. predict the torque with the nominal model (:func:`predict`: the inverse dynamics plus what the
   flexible gearboxes change, :mod:`faultgen.calibrate.gearbox`) and split the record in time into a fitting part and a held-out part
   (:class:`faultgen.calibrate.search.Split`); every gap is reported on the held-out part;
3. fit every effect of the library (:mod:`faultgen.effects`) to the residual and pick
   the one that explains it best by its held-out information criterion; when the log cannot tell
   two effects apart, fit the simpler and say so, with both candidates' evidence and the motion
   that would separate them (:mod:`faultgen.calibrate.search`, :meth:`Calibration.ambiguous`);
4. write it into the model (MJCF), recompute the residual with the augmented model, search every
   axis still above its noise floor again for the effects already named (:func:`_complete`), and
   repeat until no effect is significant; with two or more effects, fit each again with the
   others in place (backfitting, :func:`_refit`);
5. write the augmented model, ``report.json`` (design document contract) and a figure.

docs/calibration.md explains the method and lists its accuracy on hidden-effect data.
"""

from __future__ import annotations

import json
import shutil
import tempfile
from dataclasses import dataclass, field, replace
from pathlib import Path

import mujoco
import numpy as np

from faultgen import axes
from faultgen.calibrate import plausibility, search
from faultgen.calibrate.effects import EFFECTS, Effect, Motion, get
from faultgen.calibrate.effects import motion as motion_of
from faultgen.calibrate.leftover import UNEXPLAINED_RATIO, unexplained, unexplained_line
from faultgen.calibrate.plausibility import ImplausibleLogError
from faultgen.calibrate.prediction import predict, predicted_motion
from faultgen.data import atomic, longlog
from faultgen.data import measured as measured_io
from faultgen.effects.friction import FIELDS as FRICTION_FIELDS
from faultgen.effects.friction import UNITS as FRICTION_UNITS
from faultgen.model import robots

__all__ = ["EFFECTS", "Calibration", "Effect", "ImplausibleLogError", "Step", "calibrate", "get", "parameters",
           "predict"]

#: Most effects added in one calibration.
MAX_STEPS = 6
#: Backfitting rounds over the steps (:func:`_refit`). On the independent logs with a payload and
#: friction growing with the load, a second round moved the payload's mass by 0.2 %, a third by 0.
REFIT_ROUNDS = 2


@dataclass(frozen=True)
class Step:
    """One effect added to the model.

    Attributes
    ----------
    effect : Effect
        The effect as the model holds it after the step: absolute parameters on every axis, in SI
        units (:attr:`faultgen.effects.Effect.units`); the step changed them on ``axes`` only.
    axes : list of int
        Axes it was added on, 0-based (:meth:`record` numbers them 1..6).
    evidence : dict
        Why it was chosen: held-out gain per axis, the score, the runner-up, the margin (score
        minus the runner-up's, in held-out total nrmse) and every effect's score (axes numbered 1..6).
    gap_after : dict
        Held-out gap of the model with this and all earlier effects (see :func:`search.gap`).
    standard_errors : dict
        Standard error of each fitted parameter (:func:`search.standard_errors`), keyed by axis
        (0-based; None when robot-wide), in the parameter's unit.
    """

    effect: Effect
    axes: list[int]
    evidence: dict
    gap_after: dict
    standard_errors: dict = field(default_factory=dict)

    def record(self) -> dict:
        """The step in ``report.json``: effect id, axes numbered 1..6, the parameters on them
        (:meth:`faultgen.effects.Effect.report`) with their standard errors (keyed the same way)
        and units, the evidence and the gap after."""
        errors = {"robot" if key is None else str(axes.number(key)): values
                  for key, values in self.standard_errors.items()}
        return {"effect": self.effect.id, "axes": axes.numbers(self.axes), "params": self.effect.report(self.axes),
                "standard_errors": errors, "units": dict(self.effect.units), "evidence": self.evidence,
                "gap_after": self.gap_after}


@dataclass(frozen=True)
class Calibration:
    """What :func:`calibrate` found.

    Attributes
    ----------
    robot : str
    measured : str
        The measured file.
    gap_before, gap_after : dict
        Held-out gap of the nominal and of the augmented model.
    steps : list of Step
        Effects in the order they were added; empty when nothing significant was missing.
    model_out : Path
        The augmented MJCF (a copy of the nominal one when no effect was added).
    time : ndarray of shape (n,)
    held_out : ndarray of shape (n, 6)
        Mask of the held-out samples per axis (moving, in the held-out part).
    moving : ndarray of shape (n, 6)
        Mask of the samples where the axis moves (faster than the rest speed).
    tau, nominal, calibrated : ndarray of shape (n, 6)
        Measured torque and the torque of the nominal and of the augmented model, N m.
    searches : int or None
        How many times every effect was fitted to the residual (the steps, and the search that
        found nothing more when there was one).
    """

    robot: str
    measured: str
    gap_before: dict
    steps: list[Step]
    gap_after: dict
    model_out: Path
    time: np.ndarray
    held_out: np.ndarray
    moving: np.ndarray
    tau: np.ndarray
    nominal: np.ndarray
    calibrated: np.ndarray
    searches: int | None = None

    def report(self) -> dict:
        """The ``report.json`` record of the design document."""
        return {
            "robot": self.robot,
            "measured": self.measured,
            "gap_before": self.gap_before,
            "steps": [s.record() for s in self.steps],
            "gap_after": self.gap_after,
            "model_out": str(self.model_out),
            "ambiguous": self.ambiguous(),
            "unexplained": self.unexplained(),
        }

    def unexplained(self) -> list[dict]:
        """The axes left unexplained after the search (:func:`unexplained`)."""
        return unexplained(self.gap_before, self.gap_after, self.steps, self.searches)

    def ambiguous(self) -> list[dict]:
        """The steps whose effect this log cannot tell apart from another (held-out AIC within
        :data:`search.SEPARABLE`, :func:`search.compare`): step number (1..), the effect fitted (the
        simplest), every candidate with its evidence, and per candidate the motion that would
        separate them (:attr:`faultgen.effects.Effect.excited_by`)."""
        found = []
        for k, step in enumerate(self.steps, start=1):
            if step.evidence.get("separable", True):
                continue
            found.append({"step": k, "fitted": step.effect.id,
                          "candidates": [c for c in step.evidence["candidates"] if not c["separable"]],
                          "separate_by": step.evidence["separate_by"],
                          "excitation": f"faultgen excitation {self.robot} -o excitation.csv"})
        return found

    def summary(self) -> str:
        """A few lines for a terminal: each effect, its axes and parameters, the gap before -> after."""
        lines = [f"{self.robot}: held-out total nrmse {self.gap_before['total_nrmse']:.4f} (nominal model)"]
        if not self.steps:
            lines.append("no significant missing effect found")
        for k, step in enumerate(self.steps, start=1):
            s = step.record()
            values = "; ".join(
                f"{'axis ' + where if where != 'robot' else 'robot'}: "
                + ", ".join(f"{name} = {value:.4g} ± {s['standard_errors'].get(where, {}).get(name, np.nan):.2g}"
                            f"{_unit(s['units'][name])}" for name, value in p.items())
                for where, p in s["params"].items())
            lines.append(f"{k}. {s['effect']} on axes {', '.join(map(str, s['axes']))} -> total nrmse "
                         f"{s['gap_after']['total_nrmse']:.4f}  ({values})")
            refined = step.evidence.get("sysid")
            if refined is not None and refined["used"]:
                lines.append(f"   refined by mujoco.sysid: held-out total nrmse "
                             f"{refined['gap_after']['faultgen']['total_nrmse']:.4f} (faultgen's fit) -> "
                             f"{refined['gap_after']['sysid']['total_nrmse']:.4f}; "
                             + ("sysid's values kept" if refined["kept"] else "faultgen's fit kept"))
            elif refined is not None:
                lines.append(f"   not refined by mujoco.sysid: {refined['reason']}")
            if not step.evidence.get("separable", True):
                tied = [c for c in step.evidence["candidates"] if not c["separable"]]
                lines.append("   NOT SEPARABLE on this log: " + ", ".join(
                    f"{c['effect']} (delta AIC {c['delta_aic']:.1f}, weight {c['weight']:.2f})" for c in tied)
                    + f"; fitted the simplest, {s['effect']}")
                for name, motion in step.evidence["separate_by"].items():
                    lines.append(f"   to tell {name} apart: {motion}")
                lines.append(f"   a designed excitation: faultgen excitation {self.robot} -o excitation.csv")
        lines.append(f"gap {self.gap_before['total_nrmse']:.4f} -> {self.gap_after['total_nrmse']:.4f}; "
                     f"model: {self.model_out}")
        for u in self.unexplained():
            lines.append(unexplained_line(u, self.robot))
        # the static model: for a per-step friction update, or a Stribeck curve MuJoCo's LuGre
        # (Gaussian only) cannot represent
        static_only = any(s.effect.stepped for s in self.steps) or any(
            p.get("stribeck_exponent", 2.0) != 2.0 for s in self.steps for p in s.record()["params"].values())
        friction = " --friction stribeck" if static_only else ""
        lines.append(f"simulate it: faultgen simulate --model {self.model_out}{friction}")
        return "\n".join(lines)


#: Most rows the search works on. A longer log is averaged down to this many (:func:`decimate`):
#: the search's regressors take about 28 kB per row (a 10^6-row log asked for 25.7 GiB), so
#: 25 000 rows keep ``faultgen calibrate`` within 3 GB (60 000 took 5.7 GB; docs/calibration.md, "Long logs").
MAX_ROWS = 25_000


def calibrate(robot: str | Path, measured: str | Path | measured_io.MeasuredData, out: str | Path,
              max_steps: int = MAX_STEPS, progress: bool = False, use_sysid: bool = True) -> Calibration:
    """:func:`_calibrate` into a hidden folder beside ``out``, renamed to ``out`` once every output
    is written (:func:`faultgen.data.atomic.atomic_folder`): a failed, refused or interrupted run
    leaves nothing at ``out`` (an existing ``out`` untouched) and nothing that blocks a rerun. A
    log longer than :data:`MAX_ROWS` rows is first averaged down to that many (:func:`decimate`),
    so memory stays bounded whatever the log's length. A log on which no joint moves is refused
    (:class:`ImplausibleLogError`, naming the joints and how little they move). ``use_sysid``: a
    Stribeck hump's parameters refined by ``mujoco.sysid`` when it is installed (:func:`_calibrate`)."""
    nominal = robots.load(robot)
    if isinstance(measured, measured_io.MeasuredData):
        data, moves = measured, longlog.motion(measured.qd, search.REST_SPEED)
    else:
        if progress:
            print(f"reading {measured}", flush=True)
        # a log longer than MAX_ROWS is averaged down while it is read: memory flat in its length
        data, moves = longlog.read(measured, nominal, MAX_ROWS, search.REST_SPEED)
        if progress and moves.rows > len(data):
            print(data.notes[-1], flush=True)
    _check_motion(data.source, moves)
    if len(data) > MAX_ROWS:
        data = decimate(data, MAX_ROWS)
        if progress:
            print(data.notes[-1], flush=True)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with atomic.atomic_folder(out) as staging:
        result = _calibrate(robot, data, staging, max_steps=max_steps, progress=progress, use_sysid=use_sysid)
        result = replace(result, model_out=out / result.model_out.relative_to(staging))
        atomic.write_text(staging / "report.json", json.dumps(result.report(), indent=2) + "\n")
    return result


def decimate(data: measured_io.MeasuredData, rows: int) -> measured_io.MeasuredData:
    """A long log reduced to at most ``rows`` rows: every column averaged over blocks of ``k`` =
    ceil(n / rows) consecutive samples (one filter for the angles, speeds, accelerations and
    torques alike, so a relation linear in them holds between the averages as between the
    samples), one row per block. The velocities and accelerations were estimated at the full rate
    before. Cost: sign changes of the speed (Coulomb friction) and ripple faster than k samples
    (cogging) are smoothed over a block; the torque noise averages down by sqrt(k), but the fit has
    k times fewer rows, so parameter standard errors are about those of the whole log.
    """
    n = len(data)
    k = -(-n // rows)
    if k <= 1:
        return data
    m = n // k

    def blocks(a: np.ndarray) -> np.ndarray:
        return longlog.block_mean(a, k, m)

    note = longlog.decimation_note(n, k, m, MAX_ROWS)
    return measured_io.MeasuredData(t=blocks(data.t), q=blocks(data.q), qd=blocks(data.qd), qdd=blocks(data.qdd),
                                    tau=blocks(data.tau), source=data.source,
                                    velocity_estimated=data.velocity_estimated, robot=data.robot,
                                    notes=(*data.notes, note))


#: Fewest samples at which a joint must move (|qd| >= REST_SPEED) for the log to calibrate anything.
MIN_MOVING = 100


def _check_motion(source: Path, moves: longlog.Motion) -> None:
    """Refuse a log on which no joint moves: nothing can be identified (raises ImplausibleLogError
    naming each joint's largest speed). ``moves``: the log's speeds at its full rate."""
    moving, peak = moves.moving, moves.peak
    if np.all(moving < MIN_MOVING):
        joints = ", ".join(f"{a} (largest |qd| {v:.2g} rad/s)" for a, v in zip(axes.numbers(range(len(moving))), peak))
        raise ImplausibleLogError(
            f"{source}: no joint moves: joints {joints} stay below {search.REST_SPEED:g} rad/s in all but "
            f"{int(np.max(moving))} of {moves.rows} samples (at least {MIN_MOVING} needed); give a log in which the "
            "robot moves (an excitation or a task program)")


def _calibrate(robot: str | Path, measured: str | Path | measured_io.MeasuredData, out: str | Path,
               max_steps: int = MAX_STEPS, progress: bool = False, use_sysid: bool = True) -> Calibration:
    """Run the calibration workflow and write its outputs into ``out``.

    Parameters
    ----------
    robot : str or Path
        Robot name (``faultgen robots``) or MJCF file of the nominal model.
    measured : str, Path or MeasuredData
        The measured file (design document format) or data already read.
    out : str or Path
        Output folder, created if needed: ``model/<robot>_calibrated.xml`` (with the robot's
        ``tasks.toml``, so ``faultgen simulate --model`` runs it), ``model/parameters.json``
        (the augmented model's parameters per axis, SI units), ``report.json`` and
        ``calibration.png``.
    max_steps : int
        Most effects to add.
    progress : bool
        Show a progress bar while the effects are fitted and print one line per step.
    use_sysid : bool
        Refine a Stribeck hump's parameters with ``mujoco.sysid`` when the ``mujoco[sysid]`` extra
        is installed (:func:`_sysid_stribeck`); False: faultgen's own fit only.

    Returns
    -------
    Calibration

    Raises
    ------
    UnknownRobotError, ModelError
        For an unknown robot or a broken model file.
    MeasuredDataError
        For a measured file the reader refuses (the message names the column or row).
    ImplausibleLogError
        For a log the nominal model cannot explain (another robot, motor-side torque, a column in
        another unit or sign; :mod:`faultgen.calibrate.plausibility`); nothing is written.
    ValueError
        If ``max_steps`` < 0.
    """
    if max_steps < 0:
        raise ValueError(f"max_steps (--max-steps) = {max_steps}; expected a whole number >= 0")
    nominal = robots.load(robot)
    data = measured if isinstance(measured, measured_io.MeasuredData) else measured_io.read(measured, nominal)
    split = search.Split.of(data.t, data.qd)
    tau = np.asarray(data.tau)
    current = nominal
    predicted, motion = predicted_motion(nominal, data)
    nominal_prediction = predicted
    moving = np.abs(data.qd) >= search.REST_SPEED
    plausibility.check(nominal, tau, predicted, moving)  # before anything is written

    out = Path(out)
    model_dir = out / "model"
    model_dir.mkdir(parents=True, exist_ok=True)
    model_out = model_dir / f"{nominal.name}_calibrated.xml"
    tasks_file = nominal.path.parent / "tasks.toml"
    if tasks_file.is_file():
        shutil.copyfile(tasks_file, model_dir / "tasks.toml")
    gap_before = search.gap(tau, predicted, split.held_out)
    steps: list[Step] = []
    spec = mujoco.MjSpec.from_file(str(nominal.path))
    befores: list[Effect] = []  # each step's effect as the model held it before the step
    with tempfile.TemporaryDirectory(dir=model_dir) as work:
        trial_path = Path(work) / model_out.name
        if tasks_file.is_file():
            shutil.copyfile(tasks_file, Path(work) / "tasks.toml")
        searches = 0
        for k in range(max_steps):
            residual = tau - predicted
            searches += 1
            ranked = search.rank(motion, residual, tau, split, progress=progress,
                                 label=f"step {k + 1}: fitting effects")
            best = ranked[0]
            if not best.axes:
                break
            trial_spec, trial, trial_prediction, trial_motion, after = _with_effect(
                spec, current, best.effect, best.axes, trial_path, data, tau, split.held_out)
            previous = steps[-1].gap_after if steps else gap_before
            if after["total_nrmse"] >= previous["total_nrmse"]:
                if steps:  # the model file keeps the last model taken, not this trial
                    _write(spec, trial_path)
                break  # the written model does not do what the fit promised: stop, keep what works
            errors = search.standard_errors(best.effect, motion, tau - predicted, tau, split, best.axes)
            befores.append(best.effect.current(current))
            spec, current, predicted, motion = trial_spec, trial, trial_prediction, trial_motion
            steps.append(Step(best.effect, best.axes, _evidence(best, ranked, residual, split), after, errors))
            if progress:
                print(f"step {k + 1}: {best.effect.id} on axes {axes.numbers(best.axes)}, held-out total nrmse "
                      f"{previous['total_nrmse']:.4f} -> {after['total_nrmse']:.4f}", flush=True)
            spec, current, predicted, motion = _complete(spec, current, predicted, motion, steps, data, tau, split,
                                                         trial_path, progress)
        if len(steps) > 1:
            current, predicted = _refit(spec, current, predicted, steps, befores, data, tau, split, trial_path)
            current, predicted = _extend(current, predicted, steps, data, tau, split, trial_path)
        if any(s.effect.id == "stribeck" for s in steps):
            current, predicted = _sysid_stribeck(current, predicted, steps, data, tau, split, use_sysid, progress)
        atomic.write_text(model_out, Path(current.path).read_text())
    atomic.write_text(model_dir / "parameters.json", json.dumps(parameters(robots.load(model_out)), indent=2) + "\n")

    result = Calibration(
        robot=nominal.name,
        measured=str(data.source),
        gap_before=gap_before,
        steps=steps,
        gap_after=search.gap(tau, predicted, split.held_out),
        model_out=model_out,
        time=np.asarray(data.t),
        held_out=split.held_out,
        moving=moving,
        tau=tau,
        nominal=nominal_prediction,
        calibrated=predicted,
        searches=searches,
    )
    atomic.write_text(out / "report.json", json.dumps(result.report(), indent=2) + "\n")
    from faultgen.calibrate import figure

    figure.save(result, out / "calibration.png")
    return result


def parameters(robot: robots.Robot) -> dict:
    """A robot's parameters as plain lists over axes 1..6, with their units (``parameters.json``):
    gear ratios, the motor-side friction (:data:`faultgen.effects.friction.FIELDS`) and every effect the
    robot carries in its own MJCF elements, by effect id and parameter name
    (:attr:`faultgen.effects.Effect.units`)."""
    friction = {name: [float(v) for v in getattr(robot.friction, name)] for name in FRICTION_FIELDS}
    return {
        "robot": robot.name,
        "units": {"gear_ratio": "1", "friction": {name: f"{unit} (motor side)" for name, unit in FRICTION_UNITS.items()},
                  "effects": {e.id: dict(e.units) for e in robot.effects.values()}},
        "gear_ratio": [float(v) for v in robot.gear_ratio],
        "friction": friction,
        "effects": {e.id: e.table() for e in robot.effects.values()},
    }


def _unit(unit: str) -> str:
    """`` <unit>`` for a summary line; nothing for a dimensionless parameter."""
    return "" if unit == "1" else f" {unit}"


def _refit(spec: mujoco.MjSpec, current: robots.Robot, predicted: np.ndarray, steps: list[Step],
           befores: list[Effect], data: measured_io.MeasuredData, tau: np.ndarray, split: search.Split,
           path: Path) -> tuple[robots.Robot, np.ndarray]:
    """Backfitting over the steps (Hastie & Tibshirani 1990), :data:`REFIT_ROUNDS` rounds: each
    step's effect is taken out of the final model (back to ``befores``), fitted again on its axes to the residual
    the *other* effects leave, and put back when that lowers the held-out gap. A step fitted while
    a later effect was still missing (a payload's mass taking up part of a friction change) comes
    back to its own size. ``steps`` is updated in place (effect and standard errors; the evidence
    and the gap after each step stay those of the forward pass). ``spec``, ``current`` (written at
    ``path``) and ``predicted`` are the final model; returns the model kept and its prediction."""
    best_gap = search.gap(tau, predicted, split.held_out)["total_nrmse"]
    for j, step in [(j, s) for _ in range(REFIT_ROUNDS) for j, s in enumerate(steps)]:
        without = mujoco.MjSpec.from_string(spec.to_xml())
        befores[j].write(without, current, step.axes)
        reduced = robots.load(_write(without, path))
        reduced_prediction, motion = predicted_motion(reduced, data)
        residual = tau - reduced_prediction
        kind = get(step.effect.id)
        if "completed" in step.evidence:  # fitted on its re-searched axes as the re-search did
            kind = kind.reopened()
        candidate = search.fit_effect(kind, motion, residual, tau, split)
        params = ({a: candidate.effect.values(a) for a in step.axes} if candidate.effect.per_axis
                  else {None: candidate.effect.values()})
        effect = kind.fitted(reduced, params)  # of the type fitted (its grid for the jackknife)
        trial_spec, trial, trial_prediction, _, trial_gap = _with_effect(
            without, reduced, effect, step.axes, path, data, tau, split.held_out)
        trial_gap = trial_gap["total_nrmse"]
        if trial_gap < best_gap:
            errors = search.standard_errors(effect, motion, residual, tau, split, step.axes)
            steps[j] = Step(effect, step.axes, step.evidence, step.gap_after, errors)
            spec, current, predicted, best_gap = trial_spec, trial, trial_prediction, trial_gap
    _write(spec, path)  # the model file (``current.path``) holds what was kept
    return current, predicted


def _extend(current: robots.Robot, predicted: np.ndarray, steps: list[Step], data: measured_io.MeasuredData,
            tau: np.ndarray, split: search.Split, path: Path) -> tuple[robots.Robot, np.ndarray]:
    """Each step's effect tried on the axes it is not on yet where another step put a level effect
    (offset, Coulomb, viscous: linear parameters), fitted together with a change of that level
    (:func:`search.fit_jointly`): a level fitted while the effect was still missing may have taken
    part of it up (Coulomb added first during a warm-up takes the warm-up's early excess, and the
    warm-up alone then fits worse than nothing on that axis). Kept when significant and the written
    model lowers the held-out gap. ``steps`` is updated in place (axes, the effects as the model
    holds them, standard errors on the new axis, an ``extended`` record in the evidence); ``current``
    is the model written at ``path``; returns the model kept (written there) and its prediction."""
    best_gap = search.gap(tau, predicted, split.held_out)["total_nrmse"]
    motion = motion_of(current, data.t, data.q, data.qd, data.qdd)
    for j, axis in [(j, a) for j in range(len(steps)) for a in range(len(current.gear_ratio))]:
        kind = get(steps[j].effect.id)
        levels = [i for i, s in enumerate(steps) if i != j and axis in s.axes
                  and get(s.effect.id).per_axis and get(s.effect.id).grid(motion, axis) == [None]]
        own_search = type(kind).search is not Effect.search  # backlash, Stribeck: not a column fit
        if own_search or not kind.per_axis or axis in steps[j].axes or not levels:
            continue
        others = [get(steps[i].effect.id) for i in levels]
        found = search.fit_jointly(kind, others, motion, tau - predicted, tau, split, axis)
        if found is None:
            continue
        kept = path.read_text()
        spec = mujoco.MjSpec.from_file(str(path))
        for other, params in zip(others, found.others, strict=True):
            other.apply(spec, current, axis, params)
        levelled = robots.load(_write(spec, path))  # the effect is written over the new levels
        kind.apply(spec, levelled, axis, found.params)
        trial = robots.load(_write(spec, path))
        trial_prediction, trial_motion = predicted_motion(trial, data)
        trial_gap = search.gap(tau, trial_prediction, split.held_out)
        if trial_gap["total_nrmse"] >= best_gap:
            path.write_text(kept)  # the model file keeps the model kept
            continue
        best_gap, current, predicted, motion = trial_gap["total_nrmse"], trial, trial_prediction, trial_motion
        for i in [j, *levels]:
            step = steps[i]
            evidence, errors = dict(step.evidence), dict(step.standard_errors)
            errors[axis] = found.standard_errors[0 if i == j else 1 + levels.index(i)]
            if i == j:
                evidence["extended"] = [*evidence.get("extended", []), {
                    "axis": axes.number(axis), "heldout_gain_nrmse": found.gain, "relative_gain": found.relative_gain,
                    "jointly_with": [steps[k].effect.id for k in levels], "gap_after": trial_gap}]
            steps[i] = Step(get(step.effect.id).current(trial), sorted({*step.axes, axis}) if i == j else step.axes,
                            evidence, step.gap_after, errors)
    return current, predicted


def _sysid_stribeck(current: robots.Robot, predicted: np.ndarray, steps: list[Step], data: measured_io.MeasuredData,
                    tau: np.ndarray, split: search.Split, use_sysid: bool, progress: bool
                    ) -> tuple[robots.Robot, np.ndarray]:
    """Where ``mujoco.sysid`` does a step better, use it: the Stribeck step's level, velocity and
    exponent refined by it (:func:`faultgen.calibrate.refit.refine_stribeck`: on the benchmark's
    ``irb6700-07`` its joint, continuous fit left a held-out gap of 0.0171 against faultgen's
    0.0187, docs/calibration.md), written into the model (at ``current.path``) and kept when the
    written model lowers the held-out gap. The step's evidence gets a ``sysid`` record (sysid's
    values and 95 % half widths, faultgen's from which it started, both gaps, whether it was kept,
    the wall time); when kept, the step's effect and standard errors (half width / 1.96) are
    sysid's. Without the ``mujoco[sysid]`` extra (or with ``use_sysid`` False) the record says why
    and faultgen's fit stays; with ``progress`` a console line says so. ``steps`` is updated in
    place; returns the model kept and its prediction."""
    from faultgen.calibrate import refit

    path = Path(current.path)
    for j, step in enumerate(steps):
        if step.effect.id != "stribeck":
            continue
        record: dict = {"used": False}
        if not use_sysid:
            record["reason"] = "turned off (use_sysid=False, --no-sysid)"
            steps[j] = replace(step, evidence={**step.evidence, "sysid": record})
            continue
        motion = motion_of(current, data.t, data.q, data.qd, data.qdd)
        try:
            found = refit.refine_stribeck(motion, tau - predicted, tau, split, step.axes)
        except refit.SysidUnavailable as error:
            record["reason"] = str(error)
            steps[j] = replace(step, evidence={**step.evidence, "sysid": record})
            if progress:
                print(f"stribeck: kept faultgen's own fit, not refined by mujoco.sysid: {error}", flush=True)
            continue
        before = search.gap(tau, predicted, split.held_out)
        kept_text = path.read_text()
        spec = mujoco.MjSpec.from_string(kept_text)
        kind = get("stribeck")
        for axis, values in found.params.items():
            kind.apply(spec, current, axis, values)
        trial = robots.load(_write(spec, path))
        trial_prediction, _ = predicted_motion(trial, data)
        after = search.gap(tau, trial_prediction, split.held_out)
        kept = after["total_nrmse"] < before["total_nrmse"]

        def by_axis(table):
            return {str(axes.number(a)): v for a, v in table.items()}

        record.update({
            "used": True, "kept": kept,
            "solver": "mujoco.sysid.optimize (mujoco.minimize.least_squares), intervals sysid.calculate_intervals",
            "params": by_axis(found.params), "half_width_95": by_axis(found.half_width),
            "faultgen_params": by_axis(found.start),
            "faultgen_standard_errors": by_axis({a: step.standard_errors.get(a, {}) for a in step.axes}),
            "fit_cost": {"faultgen": found.start_cost, "sysid": found.cost},
            "gap_after": {"faultgen": before, "sysid": after}, "seconds": found.seconds})
        if kept:
            errors = {**step.standard_errors, **{a: {k: v / refit.Z_95 for k, v in w.items()}
                                                  for a, w in found.half_width.items()}}
            steps[j] = Step(kind.current(trial), step.axes, {**step.evidence, "sysid": record}, step.gap_after, errors)
            current, predicted = trial, trial_prediction
        else:
            path.write_text(kept_text)  # the model file keeps the model kept
            steps[j] = replace(step, evidence={**step.evidence, "sysid": record})
        if progress:
            print(f"stribeck refined by mujoco.sysid on axes {axes.numbers(step.axes)}: held-out total nrmse "
                  f"{before['total_nrmse']:.4f} -> {after['total_nrmse']:.4f} "
                  f"({'kept' if kept else 'not kept: faultgen fit kept'}, {found.seconds:.1f} s)", flush=True)
    return current, predicted


def _with_effect(spec: mujoco.MjSpec, robot: robots.Robot, effect, axes, path: Path,
                 data: measured_io.MeasuredData, tau: np.ndarray, held_out: np.ndarray) -> tuple:
    """A copy of ``spec`` with ``effect`` written on ``axes`` (array indices), saved at ``path`` and
    loaded: the trial spec, its robot, its prediction and motion along the log, and its held-out gap
    (:func:`search.gap`)."""
    trial_spec = mujoco.MjSpec.from_string(spec.to_xml())
    effect.write(trial_spec, robot, axes)
    trial = robots.load(_write(trial_spec, path))
    prediction, motion = predicted_motion(trial, data)
    return trial_spec, trial, prediction, motion, search.gap(tau, prediction, held_out)


def _write(spec: mujoco.MjSpec, path: Path) -> Path:
    path.write_text(spec.to_xml())
    return path


def _evidence(best: search.Candidate, ranked: list[search.Candidate], residual: np.ndarray,
              split: search.Split) -> dict:
    runner_up = next((c for c in ranked[1:] if c.axes), None)
    compared = search.compare(ranked, residual, split)
    candidates = [{"effect": c.effect.id, **compared[c.effect.id]} for c in ranked if c.effect.id in compared]
    tied = [c for c in candidates if not c["separable"]]
    ambiguous = len(tied) > 1
    evidence = {
        "rule": (f"held-out nrmse gain >= {search.MIN_GAIN} and >= {search.MIN_RELATIVE_GAIN:.0%} of the axis's "
                 f"nrmse; fitted on the first {search.FIT_FRACTION:.0%} of the record"),
        "score": best.score,
        "heldout_gain_nrmse": [float(g) for g in best.gain],
        "relative_gain": [float(g) for g in best.relative_gain],
        "runner_up": None if runner_up is None else {"effect": runner_up.effect.id, "score": runner_up.score,
                                                       "axes": axes.numbers(runner_up.axes)},
        # how far ahead of the runner-up the chosen effect is, in held-out total nrmse
        "margin": best.score - (runner_up.score if runner_up is not None else 0.0),
        "scores": {c.effect.id: c.score for c in ranked},
        # the selection (search.order): held-out AIC with effective sample sizes
        "criterion": {"name": "held-out AIC, Gaussian per axis, effective sample size",
                      "source": ("Akaike 1974; Burnham & Anderson 2002, Model Selection and Multimodel Inference, "
                                 "sec. 2.6 (delta <= 2: both supported)"),
                      "separable_above": search.SEPARABLE},
        "candidates": candidates,
        "separable": not ambiguous,
    }
    if ambiguous:
        others = [c["effect"] for c in tied if c["effect"] != best.effect.id]
        evidence["ambiguous_with"] = others
        evidence["separate_by"] = {name: get(name).excited_by for name in [best.effect.id, *others]}
    return evidence


def _complete(spec: mujoco.MjSpec, current: robots.Robot, predicted: np.ndarray, motion: Motion, steps: list[Step],
              data: measured_io.MeasuredData, tau: np.ndarray, split: search.Split, path: Path, progress: bool = False
              ) -> tuple[mujoco.MjSpec, robots.Robot, np.ndarray, Motion]:
    """Per-axis completeness: every axis whose held-out nrmse is still above
    :data:`search.ABOVE_FLOOR` times its noise floor (:func:`search.noise_floor`) is searched again
    for each per-axis effect the model already holds on other axes, judged by its held-out evidence
    on that axis (:func:`search.reopen`) rather than the absolute gain threshold, and kept where the
    written model lowers the held-out gap. A multi-axis effect found on some axes after a large
    effect took most of the torque (a payload) is then found on the rest. ``steps`` is updated in
    place (axes, the effect as the model holds it, standard errors on the new axes and a
    ``completed`` record in the evidence); returns the model spec, the model, its prediction and
    motion."""
    floor = search.noise_floor(tau, split.held_out)
    for j, step in enumerate(steps):
        kind = get(step.effect.id)
        now = search.gap(tau, predicted, split.held_out)
        open_axes = [a for a in range(len(floor)) if now["nrmse"][a] > search.ABOVE_FLOOR * floor[a]
                     and a not in step.axes]
        if not kind.per_axis or not open_axes:
            continue
        residual = tau - predicted
        found, gains = search.reopen(kind, motion, residual, tau, split, open_axes, floor)
        if not found.axes:
            continue
        trial_spec, trial, trial_prediction, trial_motion, after = _with_effect(
            spec, current, found.effect, found.axes, path, data, tau, split.held_out)
        if after["total_nrmse"] >= now["total_nrmse"]:
            _write(spec, path)
            continue
        errors = dict(step.standard_errors)
        errors.update(search.standard_errors(found.effect, motion, residual, tau, split, found.axes))
        evidence = dict(step.evidence)
        evidence["completed"] = [*evidence.get("completed", []), {
            "axes": axes.numbers(found.axes), "aic_gain": {str(axes.number(a)): gains[a] for a in found.axes},
            "noise_floor_nrmse": [float(v) for v in floor], "gap_after": after}]
        steps[j] = Step(get(step.effect.id).current(trial), sorted({*step.axes, *found.axes}), evidence,
                        step.gap_after, errors)
        spec, current, predicted, motion = trial_spec, trial, trial_prediction, trial_motion
        if progress:
            print(f"  {kind.id} also on axes {axes.numbers(found.axes)} (still above the noise floor), held-out "
                  f"total nrmse {now['total_nrmse']:.4f} -> {after['total_nrmse']:.4f}", flush=True)
    return spec, current, predicted, motion
