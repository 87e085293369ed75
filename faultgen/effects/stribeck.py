"""A Stribeck hump of another size, velocity and exponent (thesis eq. 6.3's f_s, v_s and delta)."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from faultgen.effects.base import REST_SPEED, register
from faultgen.effects.motor_friction import FrictionParameter

#: Stribeck exponents tried (``delta`` of eq. 6.3's ``exp(-|v/v_s|^delta)``): the literature's
#: range, 0.5 (Armstrong-Helouvry, Dupont & Canudas de Wit 1994) to 2 (the Gaussian curve of the
#: robot models); the best is refined by a simplex search with the Stribeck velocity.
EXPONENTS = (0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0)
#: Lowest Stribeck velocity tried, in rest speeds (:data:`REST_SPEED`) at the motor: the hump at
#: the rest speed is then at least exp(-(1/2)^delta) of f_s (78 % Gaussian), so most of its fall
#: shows above the rest speed, where the calibration fits.
LOWEST = 2.0
#: Lowest Stribeck velocity of a drawn hidden hump (:meth:`Stribeck.draw_grid`), in rest speeds:
#: 3, the search's lower end before the exponent was fitted. Drawn from 1 or 2 rest speeds, the
#: own-simulator humps sat mostly below the rest speed, sized up to 6-9 times the Coulomb level to
#: reach their torque size, and the PUMA 560 stribeck cases were named in 2 and 4 of 5.
DRAW_LOWEST = 3.0
#: How far (in e-folds of the hump, ``|v/v_s|^delta``) the largest Stribeck velocity tried has
#: fallen at the 95th-percentile motor speed.
DECAY = 4.0
#: :data:`DECAY` of the per-axis re-search (:meth:`Stribeck.reopened`): on an axis searched again
#: for a hump the log already shows on other axes, the largest Stribeck velocity tried has fallen
#: one e-fold at the 95th-percentile motor speed. The first search's 4 keeps a hump from standing
#: in for a Coulomb step on its own evidence; the re-search has the other axes' evidence, and a
#: shoulder that never reaches the speed where its hump has fallen (the IRB-6700-like axis 2 of
#: the independent set's ``irb6700-16``: 95th-percentile motor speed 1.5 Stribeck velocities)
#: would otherwise never be offered the hump.
REOPEN_DECAY = 1.0
#: The refinement's value outside the bounds (finite, so the simplex's convergence test stays defined).
OUTSIDE = 1e300


@register
class Stribeck(FrictionParameter):
    """Static friction excess ``static`` (N m), Stribeck velocity ``stribeck_velocity`` (rad/s),
    motor side, and Stribeck exponent ``stribeck_exponent``: eq. 6.3's
    ``f_s exp(-|v/v_s|^delta) sign(v)``.

    Identified by replacing the model's term with one of a new f_s (linear), v_s and delta, per
    axis: v_s searched over :meth:`grid` (between twice the rest speed, :data:`REST_SPEED`, below
    which nothing is fitted, and the speed where the hump would not have fallen within the log's motor
    speeds) at every exponent of :data:`EXPONENTS`; the best pair refined by a simplex search in
    (log v_s, delta) inside those bounds. An exponent other than 2
    is simulated by the static friction model only (``--friction stribeck``: MuJoCo's LuGre
    has the Gaussian curve).
    """

    id = "stribeck"
    rank = 40
    excited_by = (
        "slow passes from the rest speed to a few times the Stribeck velocity (the hump falls off with "
        "the speed)")
    summary = "Stribeck friction (extra friction at low speed, fading with speed) differs"
    units: ClassVar[dict[str, str]] = {"static": "N m (motor side)", "stribeck_velocity": "rad/s (motor side)",
                                       "stribeck_exponent": "1"}
    absent = (0.0, 1.0, 2.0)
    continuous = True
    #: Fall of the largest Stribeck velocity tried at the 95th-percentile motor speed, e-folds.
    decay = DECAY

    def reopened(self) -> Stribeck:
        """The effect as the per-axis re-search fits it (:func:`faultgen.calibrate.search.reopen`):
        Stribeck velocities up to :data:`REOPEN_DECAY` (an unregistered subclass, so the fits made
        with it, :meth:`fitted`, keep its grid)."""
        return ReopenedStribeck()

    def draw_grid(self, motion, axis):
        return self.grid(motion, axis, lowest=DRAW_LOWEST)

    def grid(self, motion, axis, exponent=None, lowest=LOWEST):
        """Stribeck velocities (rad/s, motor side) to try at ``exponent`` (default: the model's):
        from :data:`LOWEST` rest speeds (so the hump's fall shows where the calibration fits) up
        to where it has fallen to e^-4 (2 %; :attr:`decay`) at the 95th-percentile motor speed (so the hump is
        never a disguised Coulomb step); ``[None]`` when that range is shorter than a factor 2."""
        exponent = float(motion.robot.friction.stribeck_exponent[axis]) if exponent is None else exponent
        key = ("stribeck_p95", axis)
        if key not in motion.memo:
            motion.memo[key] = float(np.percentile(np.abs(motion.motor_velocity[:, axis]), 95))
        top = motion.memo[key] / self.decay ** (1 / exponent)
        low = lowest * REST_SPEED * motion.robot.gear_ratio[axis]
        return list(np.geomspace(low, top, 12)) if top > 2 * low else [None]

    @staticmethod
    def _shape(motion, axis, v_s, exponent):
        v = motion.motor_velocity[:, axis]
        return np.exp(-np.abs(v / v_s) ** exponent) * np.sign(v)

    def _velocity_exponent(self, motion, axis, h):
        """``h`` is a Stribeck velocity (the model's exponent kept) or a (velocity, exponent) pair."""
        return h if isinstance(h, tuple) else (h, float(motion.robot.friction.stribeck_exponent[axis]))

    def columns(self, motion, axis, h):
        G = motion.robot.gear_ratio[axis]
        if h is None:
            return np.zeros((len(motion.t), 1)), np.zeros(len(motion.t))
        v_s, exponent = self._velocity_exponent(motion, axis, h)
        return (G * self._shape(motion, axis, v_s, exponent))[:, None], -self._model_hump(motion, axis)

    def _model_hump(self, motion, axis):
        """The model's own Stribeck term of ``axis`` along the motion, N m at the arm side, (n,)."""
        f = motion.robot.friction
        G = motion.robot.gear_ratio[axis]
        return G * f.static[axis] * self._shape(motion, axis, f.stribeck_velocity[axis], f.stribeck_exponent[axis])

    def search(self, motion, residual, rows, scale):
        return [self._fit_axis(motion, residual[:, a], rows[:, a], a) for a in range(residual.shape[1])]

    def replicate(self, motion, residual, rows, scale, axes):
        # a jackknife replicate: the simplex started from the fit's own (v_s, delta) on ``axes``,
        # no grid; the other axes are not reported
        own = {a: (float(self.values(a)["stribeck_velocity"]), float(self.values(a)["stribeck_exponent"]))
               for a in axes}
        return [self._fit_axis(motion, residual[:, a], rows[:, a], a, own[a]) if a in own
                else (None, np.zeros(1), self.columns(motion, a, None)[1]) for a in range(residual.shape[1])]

    def _fit_axis(self, motion, residual, rows, axis, start=None):
        """``(h, theta, predicted)`` of one axis: least squares in f_s at every (v_s, delta) of
        the grids (or only at ``start``), the best refined (class docstring); ``h = (v_s, delta)``."""
        grids = {exponent: self.grid(motion, axis, exponent) for exponent in EXPONENTS}
        grids = {exponent: grid for exponent, grid in grids.items() if grid != [None]}
        if not grids:
            return None, np.zeros(1), self.columns(motion, axis, None)[1]
        offset = -self._model_hump(motion, axis)
        G = motion.robot.gear_ratio[axis]
        v = motion.motor_velocity[rows, axis]
        speed, direction = np.abs(v), np.sign(v)
        y = residual[rows] - offset[rows]
        yy = float(y @ y)

        def sse(v_s, exponent):  # of the least-squares f_s: |y|^2 - (x.y)^2 / |x|^2
            x = G * np.exp(-((speed / v_s) ** exponent)) * direction
            xx = float(x @ x)
            return yy - float(x @ y) ** 2 / xx if xx > 0 else yy

        def refined(z):  # (log v_s, delta), kept inside the grid of that delta
            v_s, exponent = float(np.exp(z[0])), float(z[1])
            if not EXPONENTS[0] <= exponent <= EXPONENTS[-1]:
                return OUTSIDE
            grid = self.grid(motion, axis, exponent)
            return sse(v_s, exponent) if grid != [None] and grid[0] <= v_s <= grid[-1] else OUTSIDE

        if start is None:
            best = min(((float(v_s), exponent) for exponent, grid in grids.items() for v_s in grid),
                       key=lambda h: sse(*h))
        else:
            best = start
        from scipy.optimize import minimize  # a fit's, not a simulation's: scipy.optimize kept out of a run's import

        found = minimize(refined, [np.log(best[0]), best[1]], method="Nelder-Mead",
                         options={"xatol": 1e-3, "fatol": 1e-9 * yy, "maxiter": 200})
        if found.fun < min(OUTSIDE, sse(*best)):
            best = (float(np.exp(found.x[0])), float(found.x[1]))
        phi, offset = self.columns(motion, axis, best)
        x = phi[rows, 0]
        theta = np.array([x @ y / (x @ x)]) if x @ x > 0 else np.zeros(1)
        return best, theta, phi @ theta + offset

    def params(self, motion, axis, theta, h):
        if h is None:
            return {"static": float(theta[0]), "stribeck_velocity": 1.0,
                    "stribeck_exponent": float(motion.robot.friction.stribeck_exponent[axis])}
        v_s, exponent = self._velocity_exponent(motion, axis, h)
        return {"static": float(theta[0]), "stribeck_velocity": float(v_s), "stribeck_exponent": float(exponent)}

    def admissible(self, motion, axis, params):
        return params["static"] >= 0

    def motor_torque(self, motion, axis, params):
        f = motion.robot.friction
        dry = max(f.coulomb_pos[axis], f.coulomb_neg[axis]) + f.static[axis]
        return dry - f.static[axis] + params["static"]


class ReopenedStribeck(Stribeck):
    """:class:`Stribeck` with the re-search's wider grid (:data:`REOPEN_DECAY`); not registered."""

    decay = REOPEN_DECAY
