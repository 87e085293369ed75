"""The named effects' parameters fitted again by MuJoCo's system identification (``mujoco.sysid``).

faultgen's calibration decides *which* effect is missing and fits it by its regressors
(:mod:`faultgen.calibrate.search`, standard errors by a block jackknife over time).
``mujoco.sysid`` (MuJoCo 4.0, the ``mujoco[sysid]`` extra) identifies the parameters of a model
structure it is given: box-bounded nonlinear least squares (``mujoco.minimize.least_squares``, a
Levenberg-Marquardt-type solver with finite-difference Jacobians) and confidence intervals from the
Jacobian at the optimum (``sysid.calculate_intervals``: ``s^2 (J^T J)^-1``, ``s^2`` the residual
variance, independent samples assumed). :func:`refit` hands it the calibrated model and the
parameters of the steps faultgen named, each a ``sysid.Parameter`` whose modifier writes it into
the model's ``MjSpec`` with the effect's own :meth:`~faultgen.effects.Effect.apply`; the residual
is the measured torque minus the model's inverse dynamics (:func:`faultgen.calibrate.predict`) on
the fitting part, each axis over its torque RMS, so both fits minimise the same quantity and
differ in the solver and the intervals. (sysid's rollouts simulate the model forward from the
logged controls; a drive-torque log of a position-controlled arm has none to give it, so its
custom residual is used, as its documentation allows.) ``benchmarks/calibration_sysid.py``
compares the two on the independent-simulator logs (docs/calibration.md).
"""

from __future__ import annotations

import contextlib
import io
import time
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from faultgen import axes as axis_numbers
from faultgen.calibrate import criterion, search, trial
from faultgen.calibrate.effects import get
from faultgen.logs import measured as measured_io
from faultgen.model import robots

#: Every how many fitting samples the residual keeps (a shorter residual vector for the solver; the
#: model is evaluated on the whole log).
STRIDE = 5
#: Confidence level of the intervals (both fits): 95 %.
ALPHA = 0.05
Z_95 = 1.959964


@dataclass(frozen=True)
class Refit:
    """One parameter fitted by both.

    Attributes
    ----------
    effect, name : str
        Effect id and parameter name.
    axis : int or None
        Axis number 1..N (None when robot-wide).
    faultgen, faultgen_half_width : float
        faultgen's estimate and the half width of its 95 % interval (1.96 jackknife standard errors).
    sysid, sysid_half_width : float
        sysid's estimate and its 95 % half width (``calculate_intervals``).
    """

    effect: str
    name: str
    axis: int | None
    faultgen: float
    faultgen_half_width: float
    sysid: float
    sysid_half_width: float


@contextlib.contextmanager
def _quiet_sysid():
    """``mujoco.sysid``'s absl warnings (a start at a bound, conditioning) kept from the user's
    console while it runs: the calibration reports the refit's outcome itself."""
    from absl import logging as absl_logging

    before = absl_logging.get_verbosity()
    absl_logging.set_verbosity(absl_logging.ERROR)
    try:
        yield
    finally:
        absl_logging.set_verbosity(before)


def _optimize(sysid, residual_of, starts, low, high, max_iters: int):
    """Minimise the stacked residual ``residual_of(x)`` over ``x`` within ``[low, high]`` from
    ``starts`` with ``sysid.optimize`` (MuJoCo's Levenberg-Marquardt); return the optimum, its 95 %
    half widths (``sysid.calculate_intervals`` from the Jacobian) and the wall time in s."""

    def residual_fn(x, params):
        x = np.asarray(x, dtype=float)
        if x.ndim == 2:  # mujoco.minimize asks for several points at once
            return [np.column_stack([residual_of(x[:, k]) for k in range(x.shape[1])])], None, None
        return [residual_of(x)], None, None

    params = sysid.ParameterDict()
    for k, (value, lo, hi) in enumerate(zip(starts, low, high, strict=True)):
        params.add(sysid.Parameter(f"p{k}", value, lo, hi))
    started = time.perf_counter()
    with _quiet_sysid():
        # output=: MuJoCo's Levenberg-Marquardt prints an "iter:" line per step to stdout otherwise
        # (sysid.optimize's own verbose= is its summary table, not the backend's)
        found, outcome = sysid.optimize(params, residual_fn, optimizer="mujoco", verbose=False, max_iters=max_iters,
                                        output=io.StringIO())
    seconds = time.perf_counter() - started
    x = found.as_vector()
    _, half = sysid.calculate_intervals([residual_of(x)], np.asarray(outcome.jac), alpha=ALPHA)
    return x, half, seconds


def _entries(result) -> list[tuple]:
    """The continuous parameters of ``result``'s steps that have a finite standard error, each
    ``(step, axis or None, name, faultgen's value, its standard error)``."""
    entries = []
    for step in result.steps:
        effect = step.effect
        where = step.axes if effect.per_axis else [None]
        for axis in where:
            values = effect.values(axis)
            errors = step.standard_errors.get(axis, {})
            for name, value in values.items():
                if name in effect.counts or isinstance(value, int):
                    continue
                if not np.isfinite(errors.get(name, np.nan)):
                    continue
                entries.append((step, axis, name, float(value), float(errors.get(name, 0.0))))
    return entries


def _spec_with(base_xml: str, robot: robots.Robot, entries: list[tuple], vector: np.ndarray) -> mujoco.MjSpec:
    """The calibrated model's spec (``base_xml``, of ``robot``) with the parameters of ``entries`` set to
    ``vector``, by each effect's own MJCF form."""
    spec = mujoco.MjSpec.from_string(base_xml)
    changed: dict[tuple, dict] = {}
    for (step, axis, name, _, _), value in zip(entries, vector, strict=True):
        changed.setdefault((step.effect.id, axis), step.effect.values(axis))[name] = float(value)
    for (effect_id, axis), values in changed.items():
        get(effect_id).apply(spec, robot, axis, values)
    return spec


def refit(result, data: measured_io.MeasuredData, nominal: robots.Robot,
          max_iters: int = 30) -> tuple[list[Refit], float, float]:
    """Fit the continuous parameters of ``result``'s steps (a :class:`faultgen.calibrate.Calibration`)
    again with ``mujoco.sysid`` on the calibrated model (the robot the calibration wrote,
    :attr:`~faultgen.calibrate.Calibration.model`), starting from the values of ``nominal``, the
    robot the calibration started from, as its caller resolved it (the effect absent; 20 % off
    faultgen's values when the model cannot be compiled there, an absent payload having no
    positive-definite inertia), on the measured ``data`` the calibration used.

    Returns
    -------
    (list of Refit, float, float)
        The parameters, sysid's wall time (s) and the held-out total nrmse of the model with
        sysid's values (:func:`faultgen.calibrate.search.gap`).

    Raises
    ------
    ImportError
        When ``mujoco.sysid`` is not installed (``pip install mujoco[sysid]``).
    TypeError
        If ``nominal`` is not a :class:`~faultgen.model.robot.Robot` (a name is resolved once, by the caller).
    ValueError
        If ``nominal`` is not the robot ``result`` was calibrated from (its name, or its file's
        SHA-1 where the calibration recorded one), or ``result`` holds no calibrated robot.
    """
    from mujoco import sysid

    from faultgen.calibrate.prediction import predict

    nominal = calibrated_from(result, nominal)
    robot = result.model
    model_path = Path(robot.path)
    base_xml = trial.file_text(robot)  # read once, bounded, checked to be the file the robot was compiled from
    split = search.Split.of(data.t, data.qd)
    tau = np.asarray(data.tau)
    scale = criterion.rms(tau, split.held_out)
    scale = np.where(scale > 0, scale, 1.0)
    rows = np.flatnonzero(split.fit.any(axis=1))[::STRIDE]
    mask = split.fit[rows]

    entries = _entries(result)

    def spec_with(vector: np.ndarray) -> mujoco.MjSpec:
        return _spec_with(base_xml, robot, entries, vector)

    size = int(mask.sum())

    def residual_of(vector: np.ndarray) -> np.ndarray:
        try:
            model = robots.from_spec(spec_with(vector), model_path)  # compiled in memory: no rounding to text
        except robots.ModelError:  # e.g. an inertia that is not positive definite: a step to refuse
            return np.full(size, 1e3)
        predicted = predict(model, data)[rows]  # the whole log: the gearbox term integrates in time
        error = (tau[rows] - predicted) / scale
        return error[mask]

    # sysid starts where the nominal model is (the effect absent), not at faultgen's answer; its
    # bounds reach five times past faultgen's change
    starts = np.array([float(get(step.effect.id).current(nominal).values(axis)[name])
                       for step, axis, name, _, _ in entries])
    try:
        robots.from_spec(spec_with(starts), model_path)
    except robots.ModelError:  # an absent payload has no inertia to start from: 20 % off faultgen's values
        starts = np.array([1.2 * value for _, _, _, value, _ in entries])
    width = np.array([max(5 * abs(value - start), 0.5 * abs(start), 1e-3)
                      for (_, _, _, value, _), start in zip(entries, starts, strict=True)])
    x, half, elapsed = _optimize(sysid, residual_of, starts, starts - width, starts + width, max_iters)
    refits = [Refit(step.effect.id, name, None if axis is None else axis_numbers.number(axis), value, Z_95 * se,
                    float(v), float(h)) for (step, axis, name, value, se), v, h in zip(entries, x, half, strict=True)]
    gap = search.gap(tau, predict(robots.from_spec(spec_with(x), model_path), data), split.held_out)["total_nrmse"]
    return refits, elapsed, gap


def calibrated_from(result, nominal: robots.Robot) -> robots.Robot:
    """``nominal`` once checked to be the robot ``result`` (a :class:`faultgen.calibrate.Calibration`)
    was calibrated from, and ``result`` to hold the calibrated robot: the names match, and the
    files' SHA-1 where both are known (:attr:`Robot.digest`).

    Raises
    ------
    TypeError
        ``nominal`` is not a Robot (:func:`faultgen.model.robots.require`).
    ValueError
        Another robot, or a result without its calibrated robot (:attr:`Calibration.model`).
    """
    nominal = robots.require(nominal, "calibrate.refit.refit")
    if result.model is None:
        raise ValueError(f"the calibration into {result.model_out} holds no calibrated robot (Calibration.model); "
                         "refit the result faultgen.calibrate.calibrate returned")
    recorded = getattr(result, "nominal_digest", None)
    if nominal.name != result.robot or (recorded is not None and nominal.digest is not None
                                         and nominal.digest != recorded):
        raise ValueError(f"the nominal robot given ({nominal.name}, {nominal.path}) is not the one the calibration "
                         f"started from ({result.robot}" + (f", its MJCF's SHA-1 {recorded}" if recorded else "")
                         + "); pass the robot it was calibrated from")
    return nominal


# -- inside the calibration: the Stribeck hump refined by sysid -----------------------------------

#: Most Levenberg-Marquardt iterations of the refinement (:func:`refine_stribeck`).
REFINE_ITERATIONS = 50
#: Bounds of the refinement, relative to faultgen's fit: the level 0 to 3 times it, the Stribeck
#: velocity between one rest speed at the motor and twice the 95th-percentile motor speed, the
#: exponent over the literature's range of :data:`faultgen.effects.stribeck.EXPONENTS`.
LEVEL_REACH = 3.0
INSTALL = "pip install 'mujoco[sysid]' (or, in a clone of faultgen, pip install '.[sysid]')"


class SysidUnavailable(ImportError):
    """``mujoco.sysid`` or its optional dependencies (the ``mujoco[sysid]`` extra) are missing."""


def sysid_module():
    """The ``mujoco.sysid`` module, with its optional dependencies.

    Raises
    ------
    SysidUnavailable
        When the module or its dependencies are not installed (MuJoCo imports the module without
        them but leaves it empty); the message says what to install.
    """
    try:
        from mujoco import sysid
    except ImportError as error:  # a MuJoCo older than 4.0
        raise SysidUnavailable(f"mujoco.sysid is not available ({error}); {INSTALL}") from error
    if not hasattr(sysid, "optimize"):
        raise SysidUnavailable(f"mujoco.sysid's optional dependencies are not installed; {INSTALL}")
    return sysid


@dataclass(frozen=True)
class Refined:
    """The Stribeck hump of some axes as ``mujoco.sysid`` fitted it (:func:`refine_stribeck`).

    Attributes
    ----------
    params, start : dict
        Per axis (0-based): ``static`` (N m), ``stribeck_velocity`` (rad/s), both motor side, and
        ``stribeck_exponent``; sysid's values and faultgen's, from which it started.
    half_width : dict
        Per axis, the 95 % half width of each (``sysid.calculate_intervals``), same units.
    cost, start_cost : float
        Sum of squares of the normalised fitting-part residual at sysid's values and at faultgen's.
    seconds : float
        Wall time of ``sysid.optimize``.
    """

    params: dict
    start: dict
    half_width: dict
    cost: float
    start_cost: float
    seconds: float


def refine_stribeck(motion, residual: np.ndarray, tau: np.ndarray, split: search.Split, axes: list[int],
                    max_iters: int = REFINE_ITERATIONS, start: dict | None = None) -> Refined:
    """The Stribeck hump on ``axes`` (0-based) fitted again by ``mujoco.sysid.optimize``: level,
    velocity and exponent of every axis jointly and continuously, from ``start`` (per axis the three
    values; default: those the model of ``motion`` holds, faultgen's fit), to the residual ``residual = tau - prediction`` (n, N, N m)
    of that model on the fitting part of ``split``, each axis over its held-out torque RMS (the
    quantity faultgen's search minimises). The torque change of a hump is the effect's own
    regressor (:meth:`faultgen.effects.stribeck.Stribeck.columns`, which the model written with
    it reproduces, tests/test_calibrate_effects.py), so no model is compiled while fitting;
    parameters are scaled by their start values so the solver sees numbers near 1. Deterministic.

    Raises
    ------
    SysidUnavailable
        Without the ``mujoco[sysid]`` extra.
    """
    sysid = sysid_module()
    from faultgen.effects import REST_SPEED

    kind = get("stribeck")
    robot = motion.robot
    names = ("static", "stribeck_velocity", "stribeck_exponent")
    held = split.held_out
    scale = criterion.rms(tau, held)
    scale = np.where(scale > 0, scale, 1.0)
    if start is None:
        start = {a: {name: float(kind.current(robot).values(a)[name]) for name in names} for a in axes}
    start = {a: {name: float(start[a][name]) for name in names} for a in axes}
    rows = {a: split.fit[:, a] for a in axes}
    low, high, x0 = [], [], []
    for a in axes:
        G = robot.gear_ratio[a]
        p95 = float(np.percentile(np.abs(motion.motor_velocity[:, a]), 95))
        s = start[a]
        bounds = [(0.0, LEVEL_REACH * max(s["static"], 1e-6)),
                  (min(REST_SPEED * G, s["stribeck_velocity"]), max(2 * p95, s["stribeck_velocity"])),
                  (min(0.5, s["stribeck_exponent"]), max(2.0, s["stribeck_exponent"]))]
        for name, (lo, hi) in zip(names, bounds, strict=True):
            unit = max(abs(s[name]), 1e-9)
            low.append(lo / unit)
            high.append(hi / unit)
            x0.append(s[name] / unit)
    units = np.array([max(abs(start[a][name]), 1e-9) for a in axes for name in names])

    def values_of(x) -> dict:
        v = np.asarray(x, dtype=float) * units
        return {a: dict(zip(names, map(float, v[3 * k: 3 * k + 3]), strict=True)) for k, a in enumerate(axes)}

    def residual_of(x) -> np.ndarray:
        parts = []
        for a, p in values_of(x).items():
            phi, offset = kind.columns(motion, a, (p["stribeck_velocity"], p["stribeck_exponent"]))
            change = phi[:, 0] * p["static"] + offset
            parts.append(((residual[:, a] - change) / scale[a])[rows[a]])
        return np.concatenate(parts)

    x, half, seconds = _optimize(sysid, residual_of, x0, low, high, max_iters)
    at_optimum = residual_of(x)
    half = np.asarray(half, dtype=float) * units
    widths = {a: dict(zip(names, map(float, half[3 * k: 3 * k + 3]), strict=True)) for k, a in enumerate(axes)}
    return Refined(values_of(x), start, widths, float(at_optimum @ at_optimum),
                   float(np.sum(residual_of(np.asarray(x0)) ** 2)), seconds)
