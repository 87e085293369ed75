"""The passes after the forward search of a calibration, each on models held in memory
(:mod:`faultgen.calibrate.trial`): a trial is kept when it lowers the held-out gap, and dropped
otherwise by keeping the model held before it.

* :func:`complete`: an effect already named, searched again on the axes still above their noise
  floor;
* :func:`backfit`: each step fitted again with the others in place (Hastie & Tibshirani 1990);
* :func:`extend`: an effect tried on an axis where a level effect may have taken part of it up;
* :func:`sysid_stribeck`: a Stribeck hump refined by ``mujoco.sysid``.

Each updates the list of steps in place and returns the model kept and its prediction.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from faultgen import axes
from faultgen.calibrate import search
from faultgen.calibrate.effects import Effect, Motion, get
from faultgen.calibrate.effects import motion as motion_of
from faultgen.calibrate.prediction import predicted_motion
from faultgen.calibrate.result import Step
from faultgen.calibrate.trial import Model, compiled, judge
from faultgen.logs import measured as measured_io

#: Backfitting rounds over the steps (:func:`backfit`). On the independent logs with a payload and
#: friction growing with the load, a second round moved the payload's mass by 0.2 %, a third by 0.
REFIT_ROUNDS = 2


def complete(model: Model, predicted: np.ndarray, motion: Motion, steps: list[Step], data: measured_io.MeasuredData,
             tau: np.ndarray, split: search.Split, path: Path, progress: bool = False,
             declined: set[tuple[str, int]] = frozenset()) -> tuple[Model, np.ndarray, Motion]:
    """Per-axis completeness: every axis whose held-out nrmse is still above
    :data:`search.ABOVE_FLOOR` times its noise floor (:func:`search.noise_floor`) is searched again
    for each per-axis effect the model already holds on other axes, judged by its held-out evidence
    on that axis (:func:`search.reopen`) rather than the absolute gain threshold, and kept where the
    model with it lowers the held-out gap. A multi-axis effect found on some axes after a large
    effect took most of the torque (a payload) is then found on the rest. ``steps`` is updated in
    place (axes, the effect as the model holds it, standard errors on the new axes and a
    ``completed`` record in the evidence); trials are named ``path``. Returns the model kept, its
    prediction and motion. ``declined``: (effect id, axis) pairs not to be written (no forced fit,
    :mod:`faultgen.calibrate.guard`)."""
    floor = search.noise_floor(tau, split.held_out)
    for j, step in enumerate(steps):
        kind = get(step.effect.id)
        now = search.gap(tau, predicted, split.held_out)
        open_axes = [a for a in range(len(floor)) if now["nrmse"][a] > search.ABOVE_FLOOR * floor[a]
                     and a not in step.axes and (step.effect.id, a) not in declined]
        if not kind.per_axis or not open_axes:
            continue
        residual = tau - predicted
        found, gains = search.reopen(kind, motion, residual, tau, split, open_axes, floor)
        if not found.axes:
            continue
        trial = judge(model.with_effect(found.effect, found.axes, path), data, tau, split.held_out)
        after = trial.gap
        if after["total_nrmse"] >= now["total_nrmse"]:
            continue
        errors = dict(step.standard_errors)
        errors.update(search.standard_errors(found.effect, motion, residual, tau, split, found.axes))
        evidence = dict(step.evidence)
        evidence["completed"] = [*evidence.get("completed", []), {
            "axes": axes.numbers(found.axes), "aic_gain": {str(axes.number(a)): gains[a] for a in found.axes},
            "noise_floor_nrmse": [float(v) for v in floor], "gap_after": after}]
        steps[j] = Step(get(step.effect.id).current(trial.model.robot), sorted({*step.axes, *found.axes}), evidence,
                        step.gap_after, errors)
        model, predicted, motion = trial.model, trial.prediction, trial.motion
        if progress:
            print(f"  {kind.id} also on axes {axes.numbers(found.axes)} (still above the noise floor), held-out "
                  f"total nrmse {now['total_nrmse']:.4f} -> {after['total_nrmse']:.4f}", flush=True)
    return model, predicted, motion


def backfit(model: Model, predicted: np.ndarray, steps: list[Step], befores: list[Effect],
            data: measured_io.MeasuredData, tau: np.ndarray, split: search.Split, path: Path
            ) -> tuple[Model, np.ndarray]:
    """Backfitting over the steps (Hastie & Tibshirani 1990), :data:`REFIT_ROUNDS` rounds: each
    step's effect is taken out of the final model (back to ``befores``), fitted again on its axes to
    the residual the *other* effects leave, and put back when that lowers the held-out gap. A step
    fitted while a later effect was still missing (a payload's mass taking up part of a friction
    change) comes back to its own size. ``steps`` is updated in place (effect and standard errors;
    the evidence and the gap after each step stay those of the forward pass). ``model`` and
    ``predicted`` are the final model and its prediction; trials are named ``path``. Returns the
    model kept and its prediction."""
    best_gap = search.gap(tau, predicted, split.held_out)["total_nrmse"]
    for j, step in [(j, s) for _ in range(REFIT_ROUNDS) for j, s in enumerate(steps)]:
        without = model.with_effect(befores[j], step.axes, path)
        reduced_prediction, motion = predicted_motion(without.robot, data)
        residual = tau - reduced_prediction
        kind = get(step.effect.id)
        if "completed" in step.evidence:  # fitted on its re-searched axes as the re-search did
            kind = kind.reopened()
        candidate = search.fit_effect(kind, motion, residual, tau, split)
        params = ({a: candidate.effect.values(a) for a in step.axes} if candidate.effect.per_axis
                  else {None: candidate.effect.values()})
        effect = kind.fitted(without.robot, params)  # of the type fitted (its grid for the jackknife)
        trial = judge(without.with_effect(effect, step.axes, path), data, tau, split.held_out)
        trial_gap = trial.gap["total_nrmse"]
        if trial_gap < best_gap:
            errors = search.standard_errors(effect, motion, residual, tau, split, step.axes)
            steps[j] = Step(effect, step.axes, step.evidence, step.gap_after, errors)
            model, predicted, best_gap = trial.model, trial.prediction, trial_gap
    return model, predicted


def extend(model: Model, predicted: np.ndarray, steps: list[Step], data: measured_io.MeasuredData,
           tau: np.ndarray, split: search.Split, path: Path) -> tuple[Model, np.ndarray]:
    """Each step's effect tried on the axes it is not on yet where another step put a level effect
    (offset, Coulomb, viscous: linear parameters), fitted together with a change of that level
    (:func:`search.fit_jointly`): a level fitted while the effect was still missing may have taken
    part of it up (Coulomb added first during a warm-up takes the warm-up's early excess, and the
    warm-up alone then fits worse than nothing on that axis). Kept when significant and the model
    with it lowers the held-out gap. ``steps`` is updated in place (axes, the effects as the model
    holds them, standard errors on the new axis, an ``extended`` record in the evidence); trials are
    named ``path``. Returns the model kept and its prediction."""
    best_gap = search.gap(tau, predicted, split.held_out)["total_nrmse"]
    motion = motion_of(model.robot, data.t, data.q, data.qd, data.qdd)
    for j, axis in [(j, a) for j in range(len(steps)) for a in range(len(model.robot.gear_ratio))]:
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
        spec = model.spec()
        for other, params in zip(others, found.others, strict=True):
            other.apply(spec, model.robot, axis, params)
        levelled = compiled(spec, path)  # the effect is written over the new levels
        kind.apply(spec, levelled.robot, axis, found.params)
        trial = judge(compiled(spec, path), data, tau, split.held_out)
        if trial.gap["total_nrmse"] >= best_gap:
            continue
        best_gap, model, predicted, motion = trial.gap["total_nrmse"], trial.model, trial.prediction, trial.motion
        for i in [j, *levels]:
            step = steps[i]
            evidence, errors = dict(step.evidence), dict(step.standard_errors)
            errors[axis] = found.standard_errors[0 if i == j else 1 + levels.index(i)]
            if i == j:
                evidence["extended"] = [*evidence.get("extended", []), {
                    "axis": axes.number(axis), "heldout_gain_nrmse": found.gain, "relative_gain": found.relative_gain,
                    "jointly_with": [steps[k].effect.id for k in levels], "gap_after": trial.gap}]
            steps[i] = Step(get(step.effect.id).current(model.robot), sorted({*step.axes, axis}) if i == j
                            else step.axes, evidence, step.gap_after, errors)
    return model, predicted


def sysid_stribeck(model: Model, predicted: np.ndarray, steps: list[Step], data: measured_io.MeasuredData,
                   tau: np.ndarray, split: search.Split, use_sysid: bool, progress: bool) -> tuple[Model, np.ndarray]:
    """Where ``mujoco.sysid`` does a step better, use it: the Stribeck step's level, velocity and
    exponent refined by it (:func:`faultgen.calibrate.refit.refine_stribeck`: on the benchmark's
    ``irb6700-07`` its joint, continuous fit left a held-out gap of 0.0171 against faultgen's
    0.0187, docs/calibration.md), put into the model (a trial named as ``model``) and kept when it
    lowers the held-out gap. The step's evidence gets a ``sysid`` record (sysid's values and 95 %
    half widths, faultgen's from which it started, both gaps, whether it was kept, the wall time);
    when kept, the step's effect and standard errors (half width / 1.96) are sysid's. Without the
    ``mujoco[sysid]`` extra (or with ``use_sysid`` False) the record says why and faultgen's fit
    stays; with ``progress`` a console line says so. ``steps`` is updated in place; returns the
    model kept and its prediction."""
    from faultgen.calibrate import refit

    path = Path(model.robot.path)
    for j, step in enumerate(steps):
        if step.effect.id != "stribeck":
            continue
        record: dict = {"used": False}
        if not use_sysid:
            record["reason"] = "turned off (use_sysid=False, --no-sysid)"
            steps[j] = replace(step, evidence={**step.evidence, "sysid": record})
            continue
        motion = motion_of(model.robot, data.t, data.q, data.qd, data.qdd)
        try:
            found = refit.refine_stribeck(motion, tau - predicted, tau, split, step.axes)
        except refit.SysidUnavailable as error:
            record["reason"] = str(error)
            steps[j] = replace(step, evidence={**step.evidence, "sysid": record})
            if progress:
                print(f"stribeck: kept faultgen's own fit, not refined by mujoco.sysid: {error}", flush=True)
            continue
        before = search.gap(tau, predicted, split.held_out)
        spec = model.spec()
        kind = get("stribeck")
        for axis, values in found.params.items():
            kind.apply(spec, model.robot, axis, values)
        trial = judge(compiled(spec, path), data, tau, split.held_out)
        after = trial.gap
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
            steps[j] = Step(kind.current(trial.model.robot), step.axes, {**step.evidence, "sysid": record},
                            step.gap_after, errors)
            model, predicted = trial.model, trial.prediction
        else:
            steps[j] = replace(step, evidence={**step.evidence, "sysid": record})
        if progress:
            print(f"stribeck refined by mujoco.sysid on axes {axes.numbers(step.axes)}: held-out total nrmse "
                  f"{before['total_nrmse']:.4f} -> {after['total_nrmse']:.4f} "
                  f"({'kept' if kept else 'not kept: faultgen fit kept'}, {found.seconds:.1f} s)", flush=True)
    return model, predicted
