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

import time
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from faultgen import axes as axis_numbers
from faultgen.calibrate import search
from faultgen.calibrate.effects import get
from faultgen.data import measured as measured_io
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


def refit(result, data: measured_io.MeasuredData, max_iters: int = 30) -> tuple[list[Refit], float, float]:
    """Fit the continuous parameters of ``result``'s steps (a :class:`faultgen.calibrate.Calibration`)
    again with ``mujoco.sysid`` on the calibrated model, starting from the nominal model's values
    (the effect absent; 20 % off faultgen's values when the model cannot be compiled there, an
    absent payload having no positive-definite inertia), on the measured ``data`` the calibration
    used.

    Returns
    -------
    (list of Refit, float, float)
        The parameters, sysid's wall time (s) and the held-out total nrmse of the model with
        sysid's values (:func:`faultgen.calibrate.search.gap`).

    Raises
    ------
    ImportError
        When ``mujoco.sysid`` is not installed (``pip install mujoco[sysid]``).
    """
    from mujoco import sysid

    from faultgen.calibrate import predict

    model_path = Path(result.model_out)
    base_xml = model_path.read_text()
    robot = robots.load(model_path)
    split = search.Split.of(data.t, data.qd)
    tau = np.asarray(data.tau)
    scale = search._rms(tau, split.held_out)
    scale = np.where(scale > 0, scale, 1.0)
    rows = np.flatnonzero(split.fit.any(axis=1))[::STRIDE]
    mask = split.fit[rows]

    entries = []  # (step, axis or None, name, faultgen value, faultgen se)
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

    def spec_with(vector: np.ndarray) -> mujoco.MjSpec:
        spec = mujoco.MjSpec.from_string(base_xml)
        changed: dict[tuple, dict] = {}
        for (step, axis, name, _, _), value in zip(entries, vector, strict=True):
            changed.setdefault((step.effect.id, axis), step.effect.values(axis))[name] = float(value)
        for (effect_id, axis), values in changed.items():
            get(effect_id).apply(spec, robot, axis, values)
        return spec

    size = int(mask.sum())

    def residual_of(vector: np.ndarray) -> np.ndarray:
        try:
            model = robots.from_spec(spec_with(vector), model_path)  # compiled in memory: no rounding to text
        except robots.ModelError:  # e.g. an inertia that is not positive definite: a step to refuse
            return np.full(size, 1e3)
        predicted = predict(model, data)[rows]  # the whole log: the gearbox term integrates in time
        error = (tau[rows] - predicted) / scale
        return error[mask]

    def residual_fn(x, params):
        x = np.asarray(x, dtype=float)
        if x.ndim == 2:  # mujoco.minimize asks for several points at once
            return [np.column_stack([residual_of(x[:, k]) for k in range(x.shape[1])])], None, None
        return [residual_of(x)], None, None

    # sysid starts where the nominal model is (the effect absent), not at faultgen's answer; its
    # bounds reach five times past faultgen's change
    nominal = robots.load(result.robot)
    starts = np.array([float(get(step.effect.id).current(nominal).values(axis)[name])
                       for step, axis, name, _, _ in entries])
    try:
        robots.from_spec(spec_with(starts), model_path)
    except robots.ModelError:  # an absent payload has no inertia to start from: 20 % off faultgen's values
        starts = np.array([1.2 * value for _, _, _, value, _ in entries])
    params = sysid.ParameterDict()
    for k, ((step, axis, name, value, se), start) in enumerate(zip(entries, starts, strict=True)):
        width = max(5 * abs(value - start), 0.5 * abs(start), 1e-3)
        params.add(sysid.Parameter(f"p{k}", start, start - width, start + width))
    started = time.perf_counter()
    found, outcome = sysid.optimize(params, residual_fn, optimizer="mujoco", verbose=False, max_iters=max_iters)
    elapsed = time.perf_counter() - started
    x = found.as_vector()
    residual = residual_of(x)
    _, half = sysid.calculate_intervals([residual], np.asarray(outcome.jac), alpha=ALPHA)
    refits = [Refit(step.effect.id, name, None if axis is None else axis_numbers.number(axis), value, Z_95 * se,
                    float(v), float(h)) for (step, axis, name, value, se), v, h in zip(entries, x, half, strict=True)]
    gap = search.gap(tau, predict(robots.from_spec(spec_with(x), model_path), data), split.held_out)["total_nrmse"]
    return refits, elapsed, gap

