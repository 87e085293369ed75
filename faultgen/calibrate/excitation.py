"""Excitation design: a periodic joint trajectory on which a torque log tells the library's effects apart.

A finite Fourier series per axis (Swevers, Ganseman, Tukel, De Schutter & Van Brussel 1997,
"Optimal robot excitation and identification", IEEE Trans. Robot. Autom. 13(5), eq. 5)::

    q_i(t) = q0_i + sum_l a_il / (w l) sin(w l t) - b_il / (w l) cos(w l t),   l = 1..L, w = 2 pi / T

so ``qd_i = sum_l a_il cos(w l t) + b_il sin(w l t)``. The coefficients are chosen to minimise
the condition number of the stacked regressors of the effects the calibration searches
(:func:`regressor`: per axis the columns of each effect, :meth:`faultgen.effects.Effect.columns`,
block-diagonal over the axes, with the robot-wide payload's columns across them; every column
scaled to unit norm), the criterion of Swevers et al. (sec. IV.A; Gautier & Khalil 1992): two
effects whose columns are nearly parallel on a motion cannot be told apart on a log of it, and the
condition number is large. Limits hold by construction: the velocity and acceleration are zero at
``t = 0`` (``sum_l a_il = 0``, ``sum_l l b_il = 0``, so the trajectory starts and ends at rest and
can be repeated), and each axis's series is scaled down until it stays within its share of the
joint range and within the planning velocity and acceleration limits of the robot's
``tasks.toml`` (:func:`faultgen.operation.programs.robot_limits`). The optimiser (:func:`design`) scores
:data:`STARTS` seeded random coefficient sets and runs scipy's L-BFGS-B on the logarithm of the
condition number from the best, with the regressor columns and their grid values fixed (a
criterion continuous in the coefficients) and a finite-difference step (:data:`STEP`) wide enough
to average over the jumps of the ``sign(qd)`` columns: same seed, same trajectory.
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import minimize

from faultgen.calibrate.effects import EFFECTS as ALL_EFFECTS
from faultgen.calibrate.effects import REST_SPEED, get
from faultgen.calibrate.effects import motion as motion_of
from faultgen.data import atomic, cells
from faultgen.model import robots
from faultgen.operation import programs, tasks

#: Effects whose regressors the design separates, simplest first: every effect of the library
#: that is :attr:`~faultgen.effects.Effect.designable` (left out: the warm-up, told apart by the
#: log's length from a cold start, not by the motion; cogging and backlash, whose regressors need
#: the motor angle and gearbox state at the log's rate, not the plan's).
EFFECTS = tuple(effect.id for effect in ALL_EFFECTS.values() if effect.designable)
#: Harmonics and fundamental period (s) of the series (Swevers et al. 1997 use 5 and 10 s).
HARMONICS = 5
PERIOD = 10.0
#: Share of each axis's half range around its middle the excitation may use.
RANGE_SHARE = 0.8
#: Share of the planning velocity and acceleration limits the excitation may use.
LIMIT_SHARE = 0.9
#: Samples per period on which the condition number is evaluated while optimising, and on which
#: the design's figure is reported (:attr:`Excitation.condition_number`).
SAMPLES = 100
FINE_SAMPLES = 1000
#: Seeded random starts scored, how many of the best are optimised, and the most L-BFGS-B
#: iterations of each (:func:`design`).
STARTS = 8
LOCAL = 1
ITERATIONS = 8
#: Finite-difference step of the gradient, in the coefficients (of order 1 at the start). The
#: criterion jumps where a zero crossing of a joint speed passes a sample (the Coulomb and
#: Stribeck columns hold ``sign(qd)``): a step of 1e-4 (the first cut) saw mostly those jumps, and
#: L-BFGS-B's line search failed at once (PUMA 560, 5 harmonics: 75.0 -> 75.0 in 976 evaluations);
#: 1e-2 averages over them (75.0 -> 17.7 in 3 iterations, 244 evaluations).
STEP = 1e-2


@dataclass(frozen=True)
class Excitation:
    """A periodic excitation trajectory (module docstring).

    Attributes
    ----------
    robot : str
    period : float
        Fundamental period T, s.
    q0 : ndarray of shape (N,)
        Offsets, rad.
    a, b : ndarray of shape (L, N)
        Sine and cosine coefficients of the velocity, rad/s.
    condition_number : float
        Of the stacked, column-normalised regressors (:func:`condition_number`) on one period
        sampled :data:`FINE_SAMPLES` times.
    start_condition_number, best_start_condition_number : float
        The same of the first random start (what an unoptimised random excitation within the
        same limits gives) and of the best of the random starts, before the local optimisation.
    columns : tuple
        The regressor columns of the criterion (:func:`regressor`'s ``keep``: effect id, axis,
        grid value, column); ``condition_number(robot, t, q, qd, qdd, keep=list(columns))`` scores
        any other motion on the same columns.
    """

    robot: str
    period: float
    q0: np.ndarray
    a: np.ndarray
    b: np.ndarray
    condition_number: float = float("nan")
    start_condition_number: float = float("nan")
    best_start_condition_number: float = float("nan")
    columns: tuple = ()

    def sample(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Angles (rad), velocities (rad/s), accelerations (rad/s^2) at times ``t`` (n,) s, each (n, N)."""
        return _series(self.q0, self.a, self.b, self.period, np.asarray(t, dtype=float))

    def to_csv(self, dt: float = tasks.PLAN_PERIOD, periods: int = 1) -> str:
        """The trajectory as CSV text: columns ``t, q1..qN`` (s, rad) every ``dt`` s over ``periods``
        periods, the last sample back at the first pose (a program for ``--task log.csv``).

        Raises
        ------
        ValueError
            If ``dt`` is not positive or ``periods`` < 1.
        """
        if not dt > 0 or periods < 1:
            raise ValueError(f"dt = {dt} s and periods = {periods}; expected dt > 0 and periods >= 1")
        steps = int(round(periods * self.period / dt))
        t = np.arange(steps + 1) * dt
        q = self.sample(t)[0]
        buffer = io.StringIO()
        np.savetxt(buffer, np.column_stack([t, q]), delimiter=",", comments="", fmt="%.9g",
                   header=cells.line(["t", *[f"q{i + 1}" for i in range(q.shape[1])]]))
        return buffer.getvalue()

    def write(self, path: str | Path, dt: float = tasks.PLAN_PERIOD, periods: int = 1) -> Path:
        """Write :meth:`to_csv` to ``path`` atomically; returns the path."""
        path = Path(path)
        atomic.write_text(path, self.to_csv(dt, periods))
        return path


def _series(q0, a, b, period, t):
    w = 2 * np.pi / period
    harmonics = np.arange(1, a.shape[0] + 1)
    phase = np.outer(t, w * harmonics)  # (n, L)
    s, c = np.sin(phase), np.cos(phase)
    wl = (w * harmonics)[:, None]
    q = q0 + s @ (a / wl) - c @ (b / wl)
    qd = c @ a + s @ b
    qdd = -(s * (w * harmonics)) @ a + (c * (w * harmonics)) @ b
    return q, qd, qdd


def limits(robot: robots.Robot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint range (N, 2) rad, velocity (N,) rad/s and acceleration (N,) rad/s^2 limits: the
    model's joint ranges and the planning limits of its ``tasks.toml``."""
    velocity, acceleration, _ = programs.robot_limits(robot)
    return np.asarray(robot.joint_range, dtype=float), velocity, acceleration


def _at_rest(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Project the coefficients onto zero velocity (``sum_l a_l = 0``) and zero acceleration
    (``sum_l l b_l = 0``) at ``t = 0``."""
    harmonics = np.arange(1, a.shape[0] + 1, dtype=float)[:, None]
    a = a - a.mean(axis=0)
    b = b - harmonics * np.sum(harmonics * b, axis=0) / np.sum(harmonics**2)
    return a, b


def _within_limits(robot_limits, a, b, period, t):
    """Scale each axis's coefficients so the series stays within its limits; returns q0, a, b."""
    joint_range, velocity, acceleration = robot_limits
    middle = joint_range.mean(axis=1)
    zero = np.zeros_like(middle)
    q, qd, qdd = _series(zero, a, b, period, t)
    q = q - (q.max(axis=0) + q.min(axis=0)) / 2  # centred on the range's middle
    half = RANGE_SHARE * (joint_range[:, 1] - joint_range[:, 0]) / 2
    tiny = 1e-12
    scale = np.minimum.reduce([half / np.maximum(np.abs(q).max(axis=0), tiny),
                               LIMIT_SHARE * velocity / np.maximum(np.abs(qd).max(axis=0), tiny),
                               LIMIT_SHARE * acceleration / np.maximum(np.abs(qdd).max(axis=0), tiny)])
    a, b = a * scale, b * scale
    raw = _series(zero, a, b, period, t)[0]
    q0 = middle - (raw.max(axis=0) + raw.min(axis=0)) / 2
    return q0, a, b


def regressor(robot: robots.Robot, t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
              effects: tuple[str, ...] = EFFECTS, keep: list | None = None) -> tuple[np.ndarray, list]:
    """The stacked regressors of ``effects`` along a motion: rows ``(n N)`` (axis by axis), columns
    the per-axis effects' columns on each axis (block-diagonal) and the robot-wide ones across
    the axes, each scaled to unit norm. A per-axis effect with a nonlinear parameter is taken at
    the middle of its search grid (:meth:`faultgen.effects.Effect.grid`), every value when the grid
    has at most three (the load-friction forms).

    ``keep``: the columns to take, as returned by an earlier call, at the grid values chosen then (so
    a design keeps one set and its criterion does not jump where this motion's grid would move);
    None: every column that is not (to 1e-6) a combination of earlier ones on the samples of this
    motion where the axis moves (Coulomb's "positive direction" column is one with the offset and
    Coulomb's own).

    Returns
    -------
    (ndarray of shape (n N, k), list)
        The matrix and the keys of its columns ``(effect id, axis or None, grid value, column)``.
    """
    motion = motion_of(robot, t, q, qd, qdd)
    n, n_axes = q.shape
    if keep is not None:  # the same columns at the same grid values: a criterion continuous in the motion
        matrix = np.zeros((n * n_axes, len(keep)))
        for c, (effect_id, axis, h, k) in enumerate(keep):
            phi, _ = get(effect_id).columns(motion, axis, h)
            if axis is None:
                matrix[:, c] = phi[:, :, k].T.reshape(-1)
            else:
                matrix[axis * n:(axis + 1) * n, c] = phi[:, k]
        return _normalised(matrix), list(keep)
    columns, keys = [], []
    for effect_id in effects:
        effect = get(effect_id)
        if not effect.per_axis:
            phi, _ = effect.columns(motion, None, None)  # (n, N, k)
            for c in range(phi.shape[2]):
                columns.append(phi[:, :, c].T.reshape(-1))
                keys.append((effect_id, None, None, c))
            continue
        for axis in range(n_axes):
            grid = effect.grid(motion, axis)
            chosen = grid if len(grid) <= 3 else [grid[len(grid) // 2]]
            for h in chosen:
                phi, _ = effect.columns(motion, axis, h)
                for c in range(phi.shape[1]):
                    column = np.zeros((n_axes, n))
                    column[axis] = phi[:, c]
                    columns.append(column.reshape(-1))
                    keys.append((effect_id, axis, h, c))
    matrix = _normalised(np.column_stack(columns))
    # which columns are combinations of earlier ones is judged on the samples where the axis moves:
    # Coulomb's "positive direction" column is the offset's minus Coulomb's own there, and differs
    # only at the few samples at rest, which come and go as the motion changes
    moving = (np.abs(qd) >= REST_SPEED).T.reshape(-1)
    judged = _normalised(np.where(moving[:, None], matrix, 0.0))
    kept, basis = [], np.zeros((matrix.shape[0], 0))
    for i in range(matrix.shape[1]):  # Gram-Schmidt: keep a column with a part outside the span so far
        rest = judged[:, i] - basis @ (basis.T @ judged[:, i])
        size = float(np.linalg.norm(rest))
        if size > 1e-6:
            kept.append(i)
            basis = np.column_stack([basis, rest / size])
    return matrix[:, kept], [keys[i] for i in kept]


def _normalised(matrix: np.ndarray) -> np.ndarray:
    norms = np.linalg.norm(matrix, axis=0)
    return matrix / np.where(norms > 0, norms, 1.0)


def condition_number(robot: robots.Robot, t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                     effects: tuple[str, ...] = EFFECTS, keep: list | None = None) -> float:
    """Condition number (largest over smallest singular value) of :func:`regressor` along a motion
    (inf when a column is zero or two are parallel)."""
    matrix, _ = regressor(robot, t, q, qd, qdd, effects, keep)
    # singular values as the square roots of the Gram matrix's eigenvalues (k x k, k << n): the
    # same to well within the design's needs up to a condition number of about 1e7
    eigen = np.linalg.eigvalsh(matrix.T @ matrix)
    return float(np.sqrt(eigen[-1] / eigen[0])) if eigen[0] > 0 else float("inf")


def design(robot: robots.Robot, harmonics: int = HARMONICS, period: float = PERIOD, seed: int = 0,
           iterations: int = ITERATIONS, effects: tuple[str, ...] = EFFECTS, starts: int = STARTS) -> Excitation:
    """An excitation for the resolved ``robot`` (:func:`faultgen.model.robots.load`) optimised for a small
    regressor condition number (module docstring): ``starts`` seeded random coefficient sets are
    scored, and the best :data:`LOCAL` of them optimised by L-BFGS-B on the logarithm of the
    condition number (finite-difference gradients), the columns and grid values fixed at those of
    the first start (:func:`regressor`'s ``keep``) so the criterion is continuous in the coefficients.

    Parameters
    ----------
    harmonics : int
        L, at least 1.
    period : float
        T in s, > 0.
    seed : int
        Of the random starts.
    iterations : int
        Most L-BFGS-B iterations per optimised start (each costs about ``2 L N`` evaluations of
        the regressors); 0: the best start as it is.
    starts : int
        Random starts scored, at least 1.

    Raises
    ------
    TypeError
        If ``robot`` is not a :class:`~faultgen.model.robot.Robot` (a name is resolved once, at the boundary).
    ValueError
        For ``harmonics`` < 1, ``period`` <= 0, ``iterations`` < 0 or ``starts`` < 1.
    """
    if harmonics < 1 or not period > 0 or iterations < 0 or starts < 1:
        raise ValueError(f"harmonics = {harmonics}, period = {period} s, iterations = {iterations}, starts = "
                         f"{starts}; expected harmonics >= 1, period > 0, iterations >= 0 and starts >= 1")
    model = robots.require(robot, "excitation.design")
    bounds = limits(model)
    n_axes = len(model.gear_ratio)
    t = np.linspace(0.0, period, SAMPLES, endpoint=False)
    rng = np.random.default_rng(seed)
    draws = [(rng.normal(size=(2, harmonics, n_axes)) / np.arange(1, harmonics + 1)[None, :, None]).ravel()
             for _ in range(starts)]

    def trajectory(x):
        a, b = _at_rest(*x.reshape(2, harmonics, n_axes))
        return _within_limits(bounds, a, b, period, t)

    q0, a, b = trajectory(draws[0])
    _, keep = regressor(model, t, *_series(q0, a, b, period, t), effects)

    def cost(x):
        q0, a, b = trajectory(x)
        value = condition_number(model, t, *_series(q0, a, b, period, t), effects, keep)
        return float(np.log(value)) if np.isfinite(value) else 50.0

    scored = sorted((cost(x), k) for k, x in enumerate(draws))
    best_cost, best = scored[0][0], draws[scored[0][1]]
    if iterations > 0:
        for _, k in scored[:LOCAL]:
            found = minimize(cost, draws[k], method="L-BFGS-B", options={"maxiter": iterations, "eps": STEP})
            if found.fun < best_cost:
                best_cost, best = float(found.fun), found.x
    fine = np.linspace(0.0, period, FINE_SAMPLES, endpoint=False)  # the figures reported: on a fine sampling

    def reported(x):
        q0, a, b = trajectory(x)
        return q0, a, b, condition_number(model, fine, *_series(q0, a, b, period, fine), effects, keep)

    q0, a, b, value = reported(best)
    return Excitation(model.name, period, q0, a, b, value, start_condition_number=reported(draws[0])[3],
                      best_start_condition_number=reported(draws[scored[0][1]])[3], columns=tuple(keep))
