"""The calibration loop (:func:`run`): the forward search that adds one effect per step, the
passes after it (:mod:`faultgen.calibrate.improve`), and the outputs.

Every model tried is held in memory (:mod:`faultgen.calibrate.trial`); the model kept is written
once, at the end, with its parameter table, ``report.json`` and the figure.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from faultgen import axes, inputs
from faultgen.calibrate import delay as delays
from faultgen.calibrate import guard, plausibility, remainder, residual_tests, search, separable
from faultgen.calibrate.effects import Effect, get
from faultgen.calibrate.improve import backfit, complete, extend, sysid_stribeck
from faultgen.calibrate.prediction import predicted_motion
from faultgen.calibrate.result import Calibration, Step, parameters
from faultgen.calibrate.trial import Model, judge
from faultgen.data import atomic
from faultgen.logs import measured as measured_io
from faultgen.effects.coulomb import Coulomb
from faultgen.effects.viscous import Viscous
from faultgen.model import robots

#: Most effects added in one calibration.
MAX_STEPS = 6


def run(robot: robots.Robot, measured: str | Path | measured_io.MeasuredData, out: str | Path,
        max_steps: int = MAX_STEPS, progress: bool = False, use_sysid: bool = True,
        friction_every_axis: bool = False, figure: bool = True, delay: str | float | None = None,
        tests: bool = True) -> Calibration:
    """Run the calibration workflow and write its outputs into ``out``. Every model tried is
    compiled in memory (:mod:`faultgen.calibrate.trial`); the model kept is written once, at the end.

    Parameters
    ----------
    robot : Robot
        The nominal model, resolved by the caller (:func:`faultgen.calibrate.calibrate`).
    measured : str, Path or MeasuredData
        The measured file (design document format) or data already read.
    out : str or Path
        Output folder, created if needed: ``model/<robot>_calibrated.xml`` (with the robot's
        ``tasks.toml``, so ``faultgen simulate --model`` runs it), ``model/parameters.json``
        (the augmented model's parameters per axis, SI units), ``report.json`` and, with
        ``figure``, ``calibration.png``.
    max_steps : int
        Most effects to add.
    progress : bool
        Show a progress bar while the effects are fitted and print one line per step.
    use_sysid : bool
        Refine a Stribeck hump's parameters with ``mujoco.sysid`` when the ``mujoco[sysid]`` extra
        is installed (:func:`faultgen.calibrate.improve.sysid_stribeck`); False: faultgen's own fit only.
    friction_every_axis : bool
        After the search, fit the Coulomb (dry) and viscous friction levels of every moving axis to
        what the model leaves, always, not by model selection (:func:`own_friction`): each axis's friction
        is then the unit's own, where the search would leave an axis at nominal (``faultgen
        monitor`` reads wear in % of it).
    figure : bool
        Draw ``calibration.png`` (measured against model torque per axis, about 1.6 s for a day's
        log of six axes); ``faultgen monitor`` caches its units' calibrations without it (nothing
        reads it there).
    delay : None, "auto" or float
        The channel delay check (:mod:`faultgen.calibrate.delay`), made on every log before the
        search and reported: None reports it only; ``"auto"`` moves the torque columns by the
        estimate; a number by that many seconds (positive: the torque was logged late).
    tests : bool
        Run the residual tests (:mod:`faultgen.calibrate.residual_tests`) of the nominal model, after
        each step and of the calibrated model, and explain what each unexplained axis's remainder
        follows (:func:`faultgen.calibrate.remainder.explain`): they choose nothing, they report
        (about 1.4 s on a KR210 log of three cycles; a log too short to test costs nothing). False:
        the report says they were not run (``unexplained`` and ``residual_tests`` null);
        ``faultgen monitor`` calibrates its units without them (it reads only the model).

    Returns
    -------
    Calibration
        With the calibrated robot as written (:attr:`Calibration.model`).

    Raises
    ------
    TypeError
        If ``robot`` is not a :class:`~faultgen.model.robot.Robot` (a name is resolved once, at the boundary).
    MeasuredDataError
        For a measured file the reader refuses (the message names the column or row).
    ImplausibleLogError
        For a log the nominal model cannot explain (another robot, motor-side torque, a column in
        another unit or sign; :mod:`faultgen.calibrate.plausibility`); nothing is written.
    ValueError
        If ``max_steps`` < 0, ``delay`` is neither None, "auto" nor a number of at most half the
        log's length, or is "auto" on a log too short to estimate it.
    """
    if max_steps < 0:
        raise ValueError(f"max_steps (--max-steps) = {max_steps}; expected a whole number >= 0")
    nominal = robots.require(robot, "calibrate.loop.run")
    data = measured if isinstance(measured, measured_io.MeasuredData) else measured_io.read(measured, nominal)
    data, channel_delay, (predicted, motion) = check_delay(nominal, data, delay)
    split = search.Split.of(data.t, data.qd)
    tau = np.asarray(data.tau)
    model = Model.nominal(nominal)

    after_steps: list[dict] = []  # the tests' summary of the nominal model, after each step and calibrated

    def tested(after: str, prediction: np.ndarray) -> list[dict] | None:
        """The residual tests of ``prediction`` (None: not run), their summary kept under ``after``."""
        if not tests:
            return None
        found = residual_tests.run(data.t, tau - prediction, split.held_out, tau, data.q, data.qd, data.qdd)
        after_steps.append({"after": after, "axes": residual_tests.summary(found)})
        return found

    nominal_prediction = predicted
    moving = np.abs(data.qd) >= search.REST_SPEED
    plausibility.check(nominal, tau, predicted, moving)  # before anything is written
    # a delay of the torque channels left on the log calibrated: unexplained on the axes it shows on
    checked = channel_delay.get("after_correction", channel_delay.get("estimate"))
    # the 99 % interval, from the same bootstrap replicates, holds the 95 % one: no need when that covers 0;
    # nor for a delay whose correction would raise the held-out gap (delays.verify)
    taken = checked and not checked["covers_zero"] and checked.get("verified", {}).get("lowers", True)
    found_delay = (delays.shown(data.t, tau, predicted, moving) or {}) if taken else {}
    shifted = found_delay.get("axes", [])
    if found_delay:
        channel_delay["shown"] = found_delay
        channel_delay["line"] = channel_delay.get("line", "") + "; " + shown_words(found_delay)
    if progress:
        print(channel_delay.get("line", channel_delay.get("reason")), flush=True)
    tested("nominal model", predicted)

    out = Path(out)
    model_dir = out / "model"
    model_dir.mkdir(parents=True, exist_ok=True)
    model_out = model_dir / f"{nominal.name}_calibrated.xml"  # every trial is named as the model written
    tasks_file = nominal.path.parent / "tasks.toml"
    if tasks_file.is_file():  # copied through faultgen.inputs: its size bound first (a sparse one was copied whole)
        (model_dir / "tasks.toml").write_bytes(inputs.read_bytes(tasks_file, "tasks file", inputs.TOML_MAX_BYTES))
    gap_before = search.gap(tau, predicted, split.held_out)
    steps: list[Step] = []
    befores: list[Effect] = []  # each step's effect as the model held it before the step
    searches = 0
    declined: list[dict] = []  # (no forced fit) library effects not written on an axis, guard.check
    for k in range(max_steps):
        residual = tau - predicted
        searches += 1
        ranked = search.rank(motion, residual, tau, split, progress=progress, label=f"step {k + 1}: fitting effects")
        previous = steps[-1].gap_after if steps else gap_before
        chosen = choose(ranked, model, predicted, data, tau, split, model_out, previous, declined, nominal.gear_ratio)
        if chosen is None:
            break  # nothing left, or the model with it does not do what the fit promised: keep what works
        best, on, trial = chosen
        after = trial.gap
        errors = search.standard_errors(best.effect, motion, tau - predicted, tau, split, on)
        befores.append(best.effect.current(model.robot))
        model, predicted, motion = trial.model, trial.prediction, trial.motion
        steps.append(Step(best.effect, on, evidence(best, ranked, residual, split), after, errors))
        tested(f"step {k + 1}: {best.effect.id}", predicted)
        if progress:
            print(f"step {k + 1}: {best.effect.id} on axes {axes.numbers(on)}, held-out total nrmse "
                  f"{previous['total_nrmse']:.4f} -> {after['total_nrmse']:.4f}", flush=True)
        model, predicted, motion = complete(model, predicted, motion, steps, data, tau, split, model_out, progress,
                                           {(d["effect"], d["axis"] - 1) for d in declined})
    if len(steps) > 1:
        model, predicted = backfit(model, predicted, steps, befores, data, tau, split, model_out)
        model, predicted = extend(model, predicted, steps, data, tau, split, model_out)
    if any(s.effect.id == "stribeck" for s in steps):
        model, predicted = sysid_stribeck(model, predicted, steps, data, tau, split, use_sysid, progress)
    if friction_every_axis:
        model, predicted, motion = own_friction(model, predicted, motion, steps, data, tau, split, model_out, nominal,
                                               progress)
    # the one model file a calibration writes, and the robot it is (read back once, by its writer)
    calibrated = robots.write(model_out, model.text, atomic.write_text)
    atomic.write_text(model_dir / "parameters.json", json.dumps(parameters(calibrated), indent=2) + "\n")

    final_tests = tested("calibrated model", predicted)
    # what each unexplained axis's remainder follows (the generic library's terms, in words)
    left = [] if final_tests is None else residual_tests.unexplained(
        final_tests, tau, split.held_out, search.gap(tau, predicted, split.held_out), also=shifted)
    follows = {u["axis"]: remainder.explain(data.t, data.q, data.qd, data.qdd, tau, predicted, nominal.gear_ratio,
                                            split.fit, split.held_out, u["axis"] - 1,
                                            log_delay=(found_delay["seconds"], found_delay["interval_s"])
                                            if u["axis"] in shifted else None) for u in left}
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
        model=calibrated,
        nominal_digest=nominal.digest,
        residual_tests=final_tests,
        tests_after_steps=after_steps,
        delay=channel_delay,
        follows=follows,
        declined=declined,
    )
    if data.source is not None:
        from faultgen.calibrate import synth  # the simulator's own logs (hidden-log): why an axis is left

        result = replace(result, why_unexplained=synth.simulator_remainder(data.source, result.unexplained(), nominal))
    atomic.write_text(out / "report.json", json.dumps(result.report(), indent=2) + "\n")
    if figure:
        from faultgen.calibrate import figure as figures

        figures.save(result, out / "calibration.png")
    return result


def choose(ranked: list[search.Candidate], model: Model, predicted: np.ndarray, data: measured_io.MeasuredData,
           tau: np.ndarray, split: search.Split, path: Path, previous: dict, declined: list[dict],
           gear_ratio: np.ndarray):
    """The step to take: the first candidate of ``ranked`` with axes left where it may be written
    (no forced fit, :func:`faultgen.calibrate.guard.check`; ``declined``, updated in place, holds
    the (effect, axis) pairs already refused), as ``(candidate, axes, trial)``; None when there is
    none, or when the first whose axes are all allowed does not lower the held-out gap (as before
    the guard: stop and keep what works)."""
    refused = {(d["effect"], d["axis"] - 1) for d in declined}
    for candidate in (c for c in ranked if c.axes):
        on = [a for a in candidate.axes if (candidate.effect.id, a) not in refused]
        if not on:
            continue
        trial = judge(model.with_effect(candidate.effect, on, path), data, tau, split.held_out)
        if trial.gap["total_nrmse"] >= previous["total_nrmse"]:
            return None
        allowed, refusals = guard.check(candidate, on, trial, predicted, data, tau, split, gear_ratio)
        declined += refusals
        refused |= {(d["effect"], d["axis"] - 1) for d in refusals}
        if not allowed and not candidate.effect.per_axis:  # a robot-wide effect is declined whole
            refused |= {(candidate.effect.id, a) for a in on}
        if allowed == on:
            return candidate, on, trial
        if not allowed:
            continue
        trial = judge(model.with_effect(candidate.effect, allowed, path), data, tau, split.held_out)
        if trial.gap["total_nrmse"] < previous["total_nrmse"]:
            return candidate, allowed, trial
    return None


def check_delay(nominal: robots.Robot, data: measured_io.MeasuredData, delay: str | float | None):
    """The channel delay check of :func:`run`: the delay of the torque behind the motion estimated
    on the log as given (:func:`faultgen.calibrate.delay.estimate`, the nominal model's torque),
    then the correction ``delay`` asks for (None: none; "auto": the estimate; a number, s) and,
    after a correction, the delay left. Returns the log to calibrate, the ``report.json``
    record (``estimate``, ``applied_s``, ``after_correction``, ``line``; ``reason`` instead when
    the log is too short to estimate it) and the nominal model's prediction and motion on the
    log returned (:func:`faultgen.calibrate.prediction.predicted_motion`)."""
    if delay is not None and delay != "auto" and (isinstance(delay, bool) or not isinstance(delay, (int, float))):
        raise ValueError(f"--delay {delay!r}: expected auto or a delay in seconds, e.g. 0.012")
    given = predicted_motion(nominal, data)
    try:
        found = delays.estimate(data.t, data.tau, given[0])
    except ValueError as err:
        if delay == "auto":
            raise ValueError(f"--delay auto: {err}") from None
        found = None
    record = {"mode": "report only" if delay is None else str(delay), "applied_s": 0.0}
    if found is None:
        record["reason"] = "channel delay: not estimated, the log is too short"
    else:
        checked = None if found.covers_zero else delays.verify(data.t, data.tau, given[0], data.qd, found.seconds)
        record.update(estimate={**found.record(), **({"verified": checked} if checked else {})},
                      line=found.line(checked))
    if delay is None:
        return data, record, given
    seconds = found.seconds if delay == "auto" else float(delay)
    data = delays.shift(data, seconds)
    record["applied_s"] = seconds
    record["line"] = (f"{record.get('line', record.get('reason'))}; torque moved {1e3 * seconds:+.1f} ms "
                      f"(--delay {delay})")
    corrected = predicted_motion(nominal, data)
    try:
        left = delays.estimate(data.t, data.tau, corrected[0])
    except ValueError:
        return data, record, corrected
    again = None if left.covers_zero else delays.verify(data.t, data.tau, corrected[0], data.qd, left.seconds)
    record["after_correction"] = {**left.record(), **({"verified": again} if again else {})}
    record["line"] += "; left: " + left.line(again).removeprefix("channel delay: ")
    return data, record, corrected


def shown_words(found: dict) -> str:
    """The delay check's words on a delay of :func:`faultgen.calibrate.delay.shown`: the axes it is
    left unexplained on, or why it is not taken for a channel delay."""
    level = f"{found['level']:.0%}"
    if not found["channel"]:
        return (f"not a channel delay: its {level} interval leaves out 0, but moving the torque by it makes the "
                f"model's error larger ({found['error_before']:.4f} -> {found['error_after']:.4f})")
    where = f"axes {', '.join(map(str, found['axes']))}" if found["axes"] else "no single axis"
    return f"at {level} it shows on {where}: left unexplained there unless corrected"


#: Fewest moving samples of an axis (fitting and held-out parts together) for :func:`own_friction`
#: to fit its dry (Coulomb) and viscous levels.
OWN_FRICTION_SAMPLES = 200


def own_friction(model: Model, predicted: np.ndarray, motion, steps: list[Step], data: measured_io.MeasuredData,
                 tau: np.ndarray, split: search.Split, path: Path, nominal: robots.Robot, progress: bool = False):
    """The dry (Coulomb: one level both ways, the difference of the two directions set back to the
    ``nominal`` model's) and viscous friction levels of every axis
    that moves (at least :data:`OWN_FRICTION_SAMPLES` samples above the rest speed), fitted
    together by least squares to the residual the model leaves, on the whole moving record
    (fitting and held-out parts: no selection is made, so none is held out), and written whatever
    the held-out gap does: the unit's own friction on every axis, the scale ``faultgen monitor``
    reads wear in. Fitted together because on a motion of few steady speeds a
    lower dry level and a higher viscous one give nearly the same torque: a dry level fitted alone
    takes up the viscous one's change. An axis whose joint fit is not admissible (a level below
    zero) gets its Coulomb level alone. An axis whose dry level the log cannot place
    (:func:`faultgen.calibrate.separable.dry_and_viscous`: its interval wider than the unit spread)
    keeps the ``nominal`` model's dry level (the prior) and gets its viscous level alone; the step's
    evidence names it (``not_separable``: per axis, the check's figures). Appended to ``steps`` as
    one step per effect whose evidence says so (``"every_axis": true``). Returns the model, its
    prediction and motion."""
    coulomb, viscous = get(Coulomb.id), get(Viscous.id)
    moving = split.fit | split.held_out
    rows = moving & (moving.sum(axis=0) >= OWN_FRICTION_SAMPLES)
    dry, wet, held, checks = {}, {}, {}, {}
    for a in np.flatnonzero(rows.any(axis=0)):
        c, v, check = _own_axis(int(a), motion, tau - predicted, rows[:, int(a)], nominal, residual_tests.stride(data.t))
        checks[str(axes.number(int(a)))] = check
        if c is not None:
            dry[int(a)] = c
        if v is not None:
            wet[int(a)] = v
        if not check["separable"]:
            held[str(axes.number(int(a)))] = check
    if not dry and not wet:
        return model, predicted, motion
    rule = ("fitted on every moving axis, always (friction_every_axis; not by model selection), dry and viscous "
            "together on the whole moving record")
    for effect, params in ((coulomb, dry), (viscous, wet)):
        if not params:
            continue
        fitted = effect.fitted(model.robot, params)
        chosen = sorted(params)
        trial = judge(model.with_effect(fitted, chosen, path), data, tau, split.held_out)
        record = {"rule": rule, "every_axis": True, "separable": True, "not_separable": held,
                  "dry_level_check": checks}
        steps.append(Step(fitted, chosen, record, trial.gap, {}))
        model, predicted, motion = trial.model, trial.prediction, trial.motion
        if progress:
            print(f"own friction: {effect.id} on axes {axes.numbers(chosen)}, held-out total nrmse "
                  f"{trial.gap['total_nrmse']:.4f}", flush=True)
    if held and progress:
        print(f"own friction: the dry level of axes {', '.join(held)} not separable on this motion: held at the nominal "
              "model's", flush=True)
    return model, predicted, motion


def _own_axis(a: int, motion, residual: np.ndarray, keep: np.ndarray, nominal: robots.Robot, stride: int):
    """One axis of :func:`own_friction`: its Coulomb and viscous parameters (None: not fitted) and
    the identifiability check of the dry level (:func:`faultgen.calibrate.separable.dry_and_viscous`)."""
    coulomb, viscous = get(Coulomb.id), get(Viscous.id)
    columns_c = coulomb.columns(motion, a, None)[0]  # (n, 2): both directions, the positive one's excess
    phi_c, phi_v = columns_c[:, :1], viscous.columns(motion, a, None)[0]
    # the two directions' difference set back to the nominal model's: the search's per-direction fit
    # read out of one log is not kept (docs/analysis.md, "Every axis's own friction")
    f, g = motion.robot.friction, nominal.friction
    skew = float((f.coulomb_neg[a] - f.coulomb_pos[a]) - (g.coulomb_neg[a] - g.coulomb_pos[a]))
    r = residual[:, a] - columns_c[:, 1] * skew
    design = np.column_stack([phi_c, phi_v])
    # the model's level both directions' mean with the difference set back to the nominal's (coulomb.params)
    level = float(f.coulomb_neg[a] - (g.coulomb_neg[a] - g.coulomb_pos[a]) / 2)
    check = separable.dry_and_viscous(design, r, keep, stride, float(g.coulomb_pos[a] + g.coulomb_neg[a]) / 2, level)
    if not check["separable"]:  # the dry level at the nominal model's, the viscous level fitted alone
        to_nominal = float(g.coulomb_neg[a] - f.coulomb_neg[a])
        c = coulomb.params(motion, a, np.array([to_nominal, skew]), None)
        theta = np.linalg.lstsq(phi_v[keep], (r - phi_c[:, 0] * to_nominal)[keep], rcond=None)[0]
        v = viscous.params(motion, a, theta, None)
        return c, (v if viscous.admissible(motion, a, v) else None), check
    theta = np.linalg.lstsq(design[keep], r[keep], rcond=None)[0]
    c = coulomb.params(motion, a, np.array([theta[0], skew]), None)
    v = viscous.params(motion, a, theta[1:], None)
    if not (coulomb.admissible(motion, a, c) and viscous.admissible(motion, a, v)):
        theta = np.linalg.lstsq(phi_c[keep], r[keep], rcond=None)[0]
        c, v = coulomb.params(motion, a, np.array([theta[0], skew]), None), None
    if not coulomb.admissible(motion, a, c):
        return None, None, check
    return c, v, check


def evidence(best: search.Candidate, ranked: list[search.Candidate], residual: np.ndarray,
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

