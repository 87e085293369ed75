"""Gearbox backlash: a dead band between motor and arm."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from faultgen import axes
from faultgen.effects.base import Effect, ModelError, register


@register
class Backlash(Effect):
    """Gearbox backlash ``width`` (rad, arm side): a dead band of that width in the gearbox spring;
    MJCF: tendon ``gearbox{i}`` with ``springlength="-width/2 width/2"``.

    It acts through MuJoCo's tendon spring in the simulation; in the rigid inverse dynamics the arm
    rests on the loaded flank, ``width/2`` behind the motor (:meth:`arm_offset`).

    The torque of a dead band is not linear in its width. Two parts, both what a model with
    backlash predicts (:func:`faultgen.calibrate.predict`):

    * the gearbox with the dead band (:attr:`Motion.compliance`,
      :func:`faultgen.calibrate.gearbox.compliance_torque`): when the load reverses, the arm
      crosses the gap and lands on the other flank, and while it crosses the motor's motion does
      not reach it. On the soft axes whose resonance the measured accelerations resolve (the
      IRB-6700-like axes 1-3) the gearbox equation carries it, with the dead band in its spring:
      the drive torque loses the ringing of the linear model. On the stiff axes (the PUMA 560's)
      it is rigid contact: the floating arm's load is missing from the drive torque while it
      crosses;
    * quasi-statically, the arm rests on the loaded flank ``width/2`` behind the motor, so its
      rigid-body terms are those at ``q - (width/2) sign(load)``
      (:meth:`faultgen.model.robots.Robot.inverse_dynamics`), taken here to first order in the width.

    The effect has no linear parameter, and the axes are coupled: a dead band on the
    IRB-6700-like axis 2 changes the torque of axis 3 through the arm's inertia. :meth:`search`
    therefore adds dead bands one axis at a time (coordinate-wise): every axis not yet chosen
    is tried at every width of :data:`GRID` (geometric, steps of 6 %; all in one pass), the best
    is refined over :data:`REFINE` widths between its neighbours (steps of 0.4 %), and it is
    kept when it lowers the fitting part's error over all axes (each weighted by its torque
    RMS) by at least :data:`MIN_DROP` and lies inside the searched range; then the next axis.
    The held-out error is sharp in the width (an IRB-6700-like log with 19.3 mrad on axis 2: total
    nrmse 0.080 at 17.1 mrad, 0.047 at 18.4, 0.124 at 19.9), so a coarse grid alone misses it.
    """

    id = "backlash"
    rank = 90
    designable = False
    excited_by = (
        "reversals of the transmitted torque (accelerations that change the gearbox load's sign)")
    summary = "gearbox backlash (dead band between motor and arm)"
    units: ClassVar[dict[str, str]] = {"width": "rad (arm side)"}
    affine_mjcf: ClassVar[bool] = True
    absent = (0.0,)
    n_parameters = 0
    draw_limits: ClassVar[dict[str, float]] = {"width": 0.05}
    #: Drawn by its width, 0.3 to 1.1 degrees at the arm; an axis is eligible when the torque the
    #: dead band changes along the nominal task (:meth:`columns`) has an RMS of at least 15 % of the
    #: axis's torque RMS: a dead band on an axis whose load never reverses leaves no trace to find.
    #: On the IRB-6700-like arm (soft gearboxes) axes 1 and 2 reach it; on the PUMA 560 (stiff
    #: gearboxes: rigid contact) no axis does, its waist 4-9 % at 5-20 mrad, about 3-7 times the
    #: 1 % torque-sensor noise, so there the axes above 4 %.
    draw_range = ("width", 0.005, 0.02, 0.15, 0.04)
    #: Dead-band widths searched first, rad at the arm side: 0.2 mrad (0.7 arcmin) to 50 mrad (2.9 deg).
    GRID = tuple(float(b) for b in np.geomspace(2e-4, 0.05, 96))
    #: Widths in the second pass, between the best grid width's neighbours.
    REFINE = 33
    #: Factor either side of a fitted width over which a jackknife replicate refines it (two
    #: :data:`GRID` steps).
    SPAN = 1.06**2
    #: Smallest relative drop of the weighted fitting error for which a dead band on one more
    #: axis is kept. A dead band on one axis leaves coupled ringing on its neighbours that a
    #: small dead band there stands in for: at 0.01 a hidden-backlash log of the IRB-6700-like
    #: arm with dead bands on axes 1 and 2 got a third, of 0.9 mrad, on axis 3 (7 % drop); at 0.1,
    #: on the back-to-back log of seed 4 (19.2 / 12.7 mrad on axes 1 / 2), one of 3.7 mrad on
    #: axis 3, which 0.2 leaves out (held-out total nrmse 0.0600 with it, 0.0599 without).
    MIN_DROP = 0.2

    @classmethod
    def read(cls, model, path):
        ids = [model.tendon(f"gearbox{k + 1}").id for k in range(axes.count(model))]
        width = np.diff(model.tendon_lengthspring[ids], axis=1)[:, 0]
        if np.any(width < 0):
            raise ModelError(f"{path}: a gearbox tendon's springlength must be an interval -b/2 b/2 with b >= 0")
        return cls(width=width)

    def apply(self, spec, robot, axis, params):
        half = max(params["width"], 0.0) / 2
        spec.tendon(f"gearbox{axis + 1}").springlength = [-half, half]

    def arm_offset(self, load):
        return -(self.width / 2 * np.sign(load))

    def grid(self, motion, axis):
        return list(self.GRID)

    def _change(self, motion, widths: np.ndarray, end: int | None = None) -> np.ndarray:
        """Torque change, (m, n, N) N m, of the dead-band widths ``widths`` (m, N) rad over the
        current model: the gearbox equation's and, to first order, the quasi-static shift's.
        ``end``: over the first ``end`` samples only, (m, end, N) (:meth:`_prefix`)."""
        robot = motion.robot
        current, shift = self._current(motion, end)
        change = motion.compliance(robot, motion.t[:end], motion.q[:end], motion.load[:end], widths) - current
        change += (widths - self.current(robot).width)[:, None, :] * shift  # in place: one (m, n, N) array less
        return change

    def _current(self, motion, end: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The current model's gearbox torque (:attr:`Motion.compliance`) and the quasi-static
        shift's torque per unit of width, (end, N) each, over the first ``end`` samples (all for
        None), computed once per motion and ``end``."""
        key = "backlash" if end is None else ("backlash", end)
        if key in motion.memo:
            return motion.memo[key]
        if "backlash" in motion.memo:  # the same bits as over the prefix (:meth:`_prefix`)
            motion.memo[key] = tuple(part[:end] for part in motion.memo["backlash"])
            return motion.memo[key]
        robot = motion.robot
        t, q, qd, qdd, load = (x[:end] for x in (motion.t, motion.q, motion.qd, motion.qdd, motion.load))
        current = motion.compliance(robot, t, q, load)
        step = 1e-4
        rigid = robot.inverse_dynamics(q, qd, qdd, friction=False)
        slope = np.empty_like(rigid)
        for axis in range(robot.n_axes):  # d(rigid torque of the axis)/d(its angle), the arm moved alone
            moved = q.copy()
            moved[:, axis] += step
            shifted = robot.inverse_dynamics(moved, qd, qdd, friction=False)
            slope[:, axis] = (shifted - rigid)[:, axis] / step
        motion.memo[key] = current, -0.5 * np.sign(load) * slope
        return motion.memo[key]

    #: How far past the fitting part's last sample a trial of :meth:`search` runs, s: the measured
    #: accelerations' filter (:func:`faultgen.logs.measured.acceleration`, a 50 ms window)
    #: reaches half its window ahead.
    MARGIN = 0.5

    def _prefix(self, motion, rows: np.ndarray) -> int | None:
        """Samples the trials of a search on ``rows`` (n, N) need: up to the fitting part's last
        sample and :data:`MARGIN` past it; None for all of them. A trial is judged on ``rows``
        only, and the gearbox equation runs forward in time (the contacts' filter reaches
        :data:`MARGIN` ahead at most), so the trials stop there instead of running through the
        held-out part (with ``rows`` the first 70 % of the log, about a quarter fewer samples),
        with the same costs to the bit. Checked once per motion and end, not assumed: the gearbox
        torque of a dead band on every axis, over the prefix and over the whole log, must agree to
        the bit on ``rows`` (the compliance takes its settings, such as its sub-step or which
        axes it integrates, from the samples it is given; the rigid-body terms are per sample);
        None where it does not."""
        used = np.flatnonzero(rows.any(axis=1))
        if not len(used):
            return None
        end = int(np.searchsorted(motion.t, motion.t[used[-1]] + self.MARGIN, side="right"))
        if end >= len(motion.t):
            return None
        key = ("backlash prefix", end)
        if key not in motion.memo:
            probe, last = np.full((1, motion.robot.n_axes), self.GRID[len(self.GRID) // 2]), used[-1] + 1
            whole = motion.compliance(motion.robot, motion.t, motion.q, motion.load, probe)[:, :last]
            part = motion.compliance(motion.robot, motion.t[:end], motion.q[:end], motion.load[:end], probe)
            motion.memo[key] = np.array_equal(whole, part[:, :last])
        return end if motion.memo[key] else None

    def columns(self, motion, axis, h):
        widths = self.current(motion.robot).width.copy()
        widths[axis] = h
        return np.zeros((len(motion.t), 0)), self._change(motion, widths[None])[0, :, axis]

    @staticmethod
    def _cost(residual, rows, scale, end=None):
        """Weighted squared error on the fitting part of a torque change, (k, n, N) -> (k,); with
        ``end``, of the change on the first ``end`` samples, (k, end, N) -> (k,), the same figure
        (rows past ``end`` count nothing). In place on one temporary, summed over the samples in
        order (numpy adds along a non-contiguous axis one sample after the other): the samples
        outside ``rows`` add zeros, so the span of ``rows`` alone gives the same sums."""
        weights = 1.0 / scale**2
        used = np.flatnonzero(rows.any(axis=1))
        span = slice(used[0], used[-1] + 1) if len(used) else slice(0, 0)
        residual, outside = residual[:end][span], ~rows[:end][span]

        def cost(change):
            error = residual - change[:, span]
            np.copyto(error, 0.0, where=outside)
            return np.sum(np.square(error, out=error), axis=1) @ weights

        return cost

    def search(self, motion, residual, rows, scale):
        end = self._prefix(motion, rows)  # the trials judged on the fitting part only
        cost, judged = self._cost(residual, rows, scale), self._cost(residual, rows, scale, end)
        widths = self.current(motion.robot).width.copy()
        change = np.zeros_like(residual)
        error = float(cost(change[None])[0])
        free = list(range(motion.robot.n_axes))
        grid = np.array(self.GRID)
        while free:
            trials = np.tile(widths, (len(free) * len(grid), 1))
            for block, axis in enumerate(free):
                trials[block * len(grid):(block + 1) * len(grid), axis] = grid
            k = int(np.argmin(judged(self._change(motion, trials, end))))
            axis, k = free[k // len(grid)], k % len(grid)
            fine = np.tile(widths, (self.REFINE, 1))
            fine[:, axis] = np.geomspace(grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)], self.REFINE)
            changes = self._change(motion, fine, end)
            costs = judged(changes)
            j = int(np.argmin(costs))
            if costs[j] > (1 - self.MIN_DROP) * error or not self._identified(fine[j, axis]):
                break
            if end is not None:  # the width kept: its change over the whole log, in the same batch
                changes = self._change(motion, fine)
            widths, change, error = fine[j], changes[j], float(costs[j])
            free.remove(axis)
        return [(float(widths[a]), np.zeros(0), change[:, a]) for a in range(len(widths))]

    def replicate(self, motion, residual, rows, scale, axes):
        # each fitted axis refined over REFINE widths within SPAN of its value (re-centred while
        # the best is at an edge), then over REFINE widths between the best one's neighbours (steps
        # of 0.05 %), one axis after the other: 12-25 times fewer trials than :meth:`search`;
        # the replicates' widths move by 0.3-3 % (2-cycle hidden-effect logs)
        end = self._prefix(motion, rows)
        cost = self._cost(residual, rows, scale, end)
        widths = self.width.copy()

        def best(axis, low, high):
            fine = np.tile(widths, (self.REFINE, 1))
            fine[:, axis] = np.geomspace(low, high, self.REFINE)
            j = int(np.argmin(cost(self._change(motion, fine, end))))
            return fine, j

        for axis in axes:
            for _ in range(4):
                fine, j = best(axis, widths[axis] / self.SPAN, widths[axis] * self.SPAN)
                widths = fine[j]
                if 0 < j < self.REFINE - 1:
                    break
            fine, j = best(axis, fine[max(j - 1, 0), axis], fine[min(j + 1, self.REFINE - 1), axis])
            widths = fine[j]
        change = self._change(motion, widths[None])[0]
        return [(float(widths[a]), np.zeros(0), change[:, a]) for a in range(len(widths))]

    def params(self, motion, axis, theta, h):
        return {"width": float(h)}

    def admissible(self, motion, axis, params):
        # an axis whose width the search left as it was only carries the others' coupling; a
        # width at either end of the range is not identified (in the logs with no dead band,
        # the smallest width's ringing at load reversals stood in for stick-slip ringing, and
        # took axis 2 of the IRB-6700-like arm from 0.046 to 0.032)
        width = params["width"]
        return self._identified(width) and width != self.current(motion.robot).width[axis]

    def _identified(self, width: float) -> bool:
        """False for a width at either end of :data:`GRID` (the optimum may lie outside it)."""
        return self.GRID[1] < width < self.GRID[-2]
