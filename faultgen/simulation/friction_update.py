"""The static friction model's per-step update as data a stepping backend can hold.

Before every physics step the static (``stribeck``) friction model sets the rotors' friction loss
(``dof_frictionloss``) from the state: the dry level of thesis eq. 6.3 at the rotor speed, times
each run's dry multiplier at that step (wear, operating conditions, a stepped effect's drift in
time), plus the friction that grows with the gearbox load (a load-dependent friction effect, the
unit's gear loss). :class:`FrictionUpdate` holds everything that update reads except the state, as
NumPy arrays, one chunk of steps at a time, and :func:`apply` is the update: one vectorised
function of those arrays and the state, over all runs at once, with no effect object in it. A
batched backend copies the arrays to its device once per chunk and runs :func:`apply` as a kernel
before each step (:attr:`faultgen.simulation.backends.Stepper.applies_friction_update`).
:class:`Schedule` makes a batch's updates chunk by chunk. docs/architecture.md, "Stepping backends".
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from faultgen.effects.base import Effect
from faultgen.model import robot as robot_module

#: The MjData fields of the last step's kinematics the static load is computed from
#: (:func:`faultgen.model.robot.static_load_from`).
KINEMATICS = ("subtree_com", "xanchor", "xaxis")


@dataclass(frozen=True)
class FrictionUpdate:
    """The rotors' friction loss before every step of one chunk of ``nstep`` steps of ``nsim``
    runs, as arrays (N the robot's axes, T the load-dependent terms). The friction loss before
    step ``k`` is, per run and axis (:func:`apply`), with ``v = qvel[rotor_dof]``::

        (f_c(v) + static_friction exp(-|v / stribeck_velocity| ^ stribeck_exponent)) level[k]
        + sum over t of load_outer[t] (load_inner[t] |load_t| / gear_ratio)

    with ``f_c`` ``coulomb_pos`` for ``v > 0``, ``coulomb_neg`` for ``v < 0`` and the larger at
    rest, and ``load_t`` the gearbox's transmitted load ``stiffness (q_m / G - q_a)`` (eq. 6.2a,
    from ``qpos[rotor_qpos]`` and ``qpos[arm_qpos]``) or, where ``load_static[t]``, the static load
    (:func:`faultgen.model.robot.static_load_from` with ``static_terms``, from the last step's
    :data:`KINEMATICS`).

    Attributes
    ----------
    rotor_dof, rotor_qpos, arm_qpos : ndarray of int, shape (N,)
        Where the friction loss is written and the rotor speed read (``dof_frictionloss`` and
        ``qvel``), and the rotor and arm angles in ``qpos``.
    coulomb_pos, coulomb_neg, static_friction : ndarray of shape (N,)
        The robot's Coulomb levels by direction and static (Stribeck) friction, N m at the
        motor: the same in every run.
    stribeck_velocity : ndarray of shape (N,)
        rad/s at the motor.
    stribeck_exponent : ndarray of shape (N,)
        The shape exponent, 1.
    level : ndarray of shape (nsim, nstep, N)
        Each run's multiplier of the dry friction at each step of the chunk (wear, conditions and
        the stepped effects' factors, :meth:`faultgen.effects.base.Effect.dry_friction_factor`), 1.
    gear_ratio : ndarray of shape (N,)
        Motor turns per arm turn.
    stiffness : ndarray of shape (N,)
        Gearbox stiffness, N m/rad at the arm.
    load_inner, load_outer : ndarray of shape (nsim, T, N)
        Each run's coefficients of each load term, 1 (their product is the term's coefficient; a
        robot's effect holds its coefficient in ``load_inner``, a per-cycle one in ``load_outer``,
        so that the rounding is the same as the effect's own formula).
    load_static : ndarray of bool, shape (T, N)
        Whether a term reads the static load instead of the transmitted one.
    static_terms : tuple of ndarray
        :attr:`faultgen.model.robot.Robot.static_terms` (arm joint and body ids, subtree masses,
        gravity, joint springs): what the static load is computed from.
    """

    rotor_dof: np.ndarray
    rotor_qpos: np.ndarray
    arm_qpos: np.ndarray
    coulomb_pos: np.ndarray
    coulomb_neg: np.ndarray
    static_friction: np.ndarray
    stribeck_velocity: np.ndarray
    stribeck_exponent: np.ndarray
    level: np.ndarray
    gear_ratio: np.ndarray
    stiffness: np.ndarray
    load_inner: np.ndarray
    load_outer: np.ndarray
    load_static: np.ndarray
    static_terms: tuple

    @property
    def nstep(self) -> int:
        """Steps of the chunk."""
        return self.level.shape[1]

    @property
    def reads_kinematics(self) -> bool:
        """Whether :func:`apply` needs the last step's :data:`KINEMATICS` (a static-load term)."""
        return bool(np.any(self.load_static))

    def take(self, rows) -> FrictionUpdate:
        """The update of the runs ``rows`` (an index array or slice of the leading axis)."""
        return replace(self, level=self.level[rows], load_inner=self.load_inner[rows],
                       load_outer=self.load_outer[rows])


def apply(update: FrictionUpdate, k: int, qvel: np.ndarray, qpos: np.ndarray,
          kinematics: tuple | None = None) -> np.ndarray:
    """The rotors' friction loss before step ``k`` (0-based, of the chunk), N m at the motor,
    ``(nsim, N)``: the formula of :class:`FrictionUpdate`, from ``qvel`` ``(nsim, nv)`` (rad/s),
    ``qpos`` ``(nsim, nq)`` and, when :attr:`FrictionUpdate.reads_kinematics`, ``kinematics``: the
    :data:`KINEMATICS` fields ``(nsim, nbody, 3)``, ``(nsim, njnt, 3)``, ``(nsim, njnt, 3)`` of the
    last step (of ``mj_forward`` before the first). The reference of :func:`writer`, which
    computes the same bits with less Python per step."""
    u = update
    v = qvel[:, u.rotor_dof]
    coulomb = np.where(v > 0, u.coulomb_pos,
                       np.where(v < 0, u.coulomb_neg, np.maximum(u.coulomb_pos, u.coulomb_neg)))
    stribeck = u.static_friction * np.exp(-np.abs(v / u.stribeck_velocity) ** u.stribeck_exponent)
    return _with_load(u, (coulomb + stribeck) * u.level[:, k], qpos, kinematics)


def _with_load(u: FrictionUpdate, loss: np.ndarray, qpos: np.ndarray, kinematics: tuple | None) -> np.ndarray:
    """``loss`` plus the load-dependent terms of :class:`FrictionUpdate` (a new array; ``loss``
    itself when there are none)."""
    if len(u.load_static):
        G = u.gear_ratio
        transmitted = u.stiffness * (qpos[:, u.rotor_qpos] / G - qpos[:, u.arm_qpos])
        static = (robot_module.static_load_from(u.static_terms, *kinematics, qpos[:, u.arm_qpos])
                  if u.reads_kinematics else None)
        for t, uses_static in enumerate(u.load_static):
            load = np.where(uses_static, static, transmitted) if np.any(uses_static) else transmitted
            loss = loss + u.load_outer[:, t] * (u.load_inner[:, t] * np.abs(load) / G)
    return loss


def as_slice(indices: np.ndarray) -> slice | np.ndarray:
    """``indices`` (1-D, int) as the slice that picks the same elements, where they are evenly
    spaced and increasing (indexing with it gives a view, not a copy); else ``indices``."""
    i = np.asarray(indices)
    if len(i) == 0 or (len(i) > 1 and (i[1] <= i[0] or np.any(np.diff(i) != i[1] - i[0]))):
        return i
    step = int(i[1] - i[0]) if len(i) > 1 else 1
    return slice(int(i[0]), int(i[-1]) + 1, step)


@dataclass(frozen=True)
class Writer:
    """``write(k)``, made by :func:`writer`: the friction loss of step ``k`` of a chunk into the
    model. ``arrays`` are the compiled update's arguments after ``k``
    (:func:`faultgen.simulation.friction_kernel.write`, which a stepping loop may call inside its
    own kernel: :func:`faultgen.simulation.friction_kernel.before_step`), ``compiled`` whether
    that update is the one written, ``rest`` what Python adds after it (the static-load terms,
    the NumPy update where the compiled one would not give NumPy's bits, a plug-in's extra), or
    None."""

    arrays: tuple
    compiled: bool
    rest: Callable[[int], None] | None
    kernel: Callable

    def __call__(self, k: int) -> None:
        if self.compiled:
            self.kernel(k, *self.arrays)
        if self.rest is not None:
            self.rest(k)

    def then(self, more: Callable[[int], None]) -> Writer:
        """This writer with ``more(k)`` run after it."""
        rest = self.rest
        if rest is None:
            return replace(self, rest=more)

        def both(k: int) -> None:
            rest(k)
            more(k)
        return replace(self, rest=both)


def writer(update: FrictionUpdate, qvel: np.ndarray, qpos: np.ndarray, kinematics: tuple | None,
           frictionloss: np.ndarray) -> Writer:
    """``write(k)``: :func:`apply` of ``update`` at step ``k`` written into ``frictionloss``
    ``(nsim, nv)`` at the rotors, the same bits, from the live ``qvel``, ``qpos`` and
    ``kinematics`` (the per-step fallback of a backend that does not apply the update itself).

    The update is compiled (:mod:`faultgen.simulation.friction_kernel`: one call a step, the same
    operations in the same order on each element) where its ``exp`` and ``**`` give NumPy's bits
    (:func:`faultgen.simulation.friction_kernel.matches_numpy`); elsewhere NumPy's calls
    (:func:`_numpy_writer`). A static-load term (:attr:`FrictionUpdate.reads_kinematics`) is
    added from Python after the compiled part (all load terms then, in their order, as in
    :func:`apply`); the transmitted-load ones are compiled."""
    from faultgen.simulation import friction_kernel
    u = update
    nsim, n = u.level.shape[0], len(u.rotor_dof)
    _check_sizes(u, qvel, qpos, frictionloss)
    axis = np.array([u.coulomb_pos, u.coulomb_neg, np.maximum(u.coulomb_pos, u.coulomb_neg),
                     np.abs(u.stribeck_velocity), u.stribeck_exponent, u.static_friction, u.gear_ratio,
                     u.stiffness], dtype=float)
    compiled = friction_kernel.numpy_bits()
    rest = None if compiled else _numpy_writer(u, qvel, qpos, kinematics, frictionloss)
    if u.reads_kinematics:  # the compiled part into a buffer; every load term from Python
        target, columns, load = np.empty((nsim, n)), np.arange(n), np.zeros((2, nsim, 0, n))
        rest = rest or _loads_after(u, target, qpos, kinematics, frictionloss)
    else:
        target, columns = frictionloss, u.rotor_dof
        load = np.stack([u.load_inner, u.load_outer]).astype(float, copy=False)
    cols = np.array([u.rotor_dof, u.rotor_qpos, u.arm_qpos, columns], dtype=np.int64)
    return Writer((qvel, qpos, u.level, axis, cols, load, target), compiled, rest, friction_kernel.write)


def _loads_after(u: FrictionUpdate, loss: np.ndarray, qpos: np.ndarray, kinematics: tuple,
                 frictionloss: np.ndarray) -> Callable[[int], None]:
    """``add(k)``: the rotors' friction loss set to ``loss`` (the compiled part, written before)
    plus every load term (:func:`_with_load`)."""
    rotor = as_slice(u.rotor_dof)

    def add(k: int) -> None:
        frictionloss[:, rotor] = _with_load(u, loss, qpos, kinematics)
    return add


def _check_sizes(u: FrictionUpdate, qvel: np.ndarray, qpos: np.ndarray, frictionloss: np.ndarray) -> None:
    """Refuse state arrays that do not hold ``u``'s runs and columns (the compiled update does
    not check its indices)."""
    nsim = u.level.shape[0]
    for name, values, index in (("qvel", qvel, u.rotor_dof), ("qpos", qpos, u.rotor_qpos),
                                ("qpos", qpos, u.arm_qpos), ("frictionloss", frictionloss, u.rotor_dof)):
        if values.ndim != 2 or values.shape[0] != nsim or (len(index) and not 0 <= np.min(index) <= np.max(index)
                                                           < values.shape[1]):
            raise ValueError(f"{name} has shape {values.shape}; expected ({nsim}, > {np.max(index, initial=-1)}) "
                             f"for the update's {nsim} runs")


def _numpy_writer(update: FrictionUpdate, qvel: np.ndarray, qpos: np.ndarray, kinematics: tuple | None,
                  frictionloss: np.ndarray) -> Callable[[int], None]:
    """:func:`writer`'s step as NumPy calls, where the compiled one would not give NumPy's bits.

    What does not change from step to step is done here once: the rotor columns as views where
    they are evenly spaced, the larger Coulomb level, one Coulomb level where both directions'
    are the same bits (no branch on the speed's sign), one level where the chunk's does not change
    with the step, and buffers for the exact operations (absolute value, quotient, sum, product),
    so a step costs a few NumPy calls; the larger level at rest is put in only when a speed is 0. The transcendental ones (power, exp) run on fresh arrays as
    in :func:`apply`; ``|v / v_s|`` is taken as ``|v| / |v_s|`` and ``-(x^g)`` negated in place,
    both exact in IEEE arithmetic."""
    u = update
    rotor = as_slice(u.rotor_dof)
    cp, cn = u.coulomb_pos, u.coulomb_neg
    one_coulomb = cp.tobytes() == cn.tobytes()  # then np.where picks these bits whatever the speed
    larger = np.maximum(cp, cn)
    speed_scale, exponent, static = np.abs(u.stribeck_velocity), u.stribeck_exponent, u.static_friction
    one_level = u.nstep > 0 and u.level.strides[1] == 0  # broadcast over the steps: the same every step
    level0 = u.level[:, 0] if one_level else None
    scaled = np.empty((u.level.shape[0], len(u.rotor_dof)))
    direct = isinstance(rotor, slice) and not len(u.load_static)
    target = frictionloss[:, rotor] if direct else None

    def coulomb(v: np.ndarray) -> np.ndarray:  # apply's choice; a speed of exactly 0 is rare: fixed after
        level = np.where(v > 0, cp, cn)  # (NaN takes cn, not the larger: its loss is NaN either way)
        return np.where(v == 0, larger, level) if np.count_nonzero(v) < v.size else level

    def write(k: int) -> None:
        v = qvel[:, rotor]
        np.abs(v, out=scaled)
        np.divide(scaled, speed_scale, out=scaled)
        term = scaled ** exponent
        np.negative(term, out=term)
        term = np.exp(term)
        np.multiply(static, term, out=term)
        np.add(cp if one_coulomb else coulomb(v), term, out=term)
        level = level0 if one_level else u.level[:, k]
        if direct:
            np.multiply(term, level, out=target)
        else:
            frictionloss[:, rotor] = _with_load(u, np.multiply(term, level, out=term), qpos, kinematics)

    return write


def _overrides(effect: Effect, method: str) -> bool:
    return getattr(type(effect), method) is not getattr(Effect, method)


class Schedule:
    """The friction updates of one batch (``work``, :class:`faultgen.simulation.batch.Work`, on
    ``sim``), chunk by chunk (:meth:`chunk`). A plug-in stepped effect whose extra friction is not
    exported as arrays (:meth:`faultgen.effects.base.Effect.dry_friction_load_terms` None) is kept
    in :attr:`python_extras`: such a run is not :attr:`in_arrays` and its extra is added from
    Python before every step (:meth:`setter`)."""

    def __init__(self, sim, work, stepped: list[Effect]) -> None:
        robot, dt = sim.robot, sim.model.opt.timestep
        self.robot, self.dt, self.dry = robot, dt, work.plant.dry
        nsim, n = self.dry.shape
        # a drift with time runs over the whole run: cycle c starts (c - 1) cycles in
        self.run_start = (work.cycles[:, None] - 1) * (len(work.inputs) - 1) * dt
        self.factors = [e for e in stepped if _overrides(e, "dry_friction_factor")]
        extras = [e for e in stepped if _overrides(e, "dry_friction_extra")]
        #: Stepped effects whose extra friction Python adds before every step (after the others).
        self.python_extras = []
        terms = []  # (inner, outer, static) of each load term, in the effects' order, the gear loss last
        for effect in extras:
            exported = effect.dry_friction_load_terms()
            if exported is None:
                self.python_extras.append(effect)
            else:
                coefficient, static = exported
                terms.append((np.broadcast_to(coefficient, (nsim, n)), np.ones((nsim, n)),
                              np.asarray(static, bool)))
        gear_loss = work.plant.gear_loss
        if np.any(gear_loss):  # the unit's gearbox loss: the load-dependent effect's transmitted form
            inner, outer = (gear_loss, 1.0) if np.ndim(gear_loss) == 1 else (1.0, gear_loss)
            terms.append((np.broadcast_to(inner, (nsim, n)), np.broadcast_to(outer, (nsim, n)),
                          np.zeros(n, bool)))
        f = robot.friction

        def stacked(i: int) -> np.ndarray:  # part i of every term, (nsim, T, N)
            return np.stack([t[i] for t in terms], axis=1) if terms else np.zeros((nsim, 0, n))

        #: The update's arrays but the chunk's ``level``.
        self.base = FrictionUpdate(
            rotor_dof=robot.rotor_dof, rotor_qpos=robot.rotor_qpos, arm_qpos=robot.arm_qpos,
            coulomb_pos=f.coulomb_pos, coulomb_neg=f.coulomb_neg, static_friction=f.static,
            stribeck_velocity=f.stribeck_velocity, stribeck_exponent=f.stribeck_exponent,
            level=np.zeros((nsim, 0, n)), gear_ratio=robot.gear_ratio, stiffness=robot.gearbox_stiffness,
            load_inner=stacked(0), load_outer=stacked(1),
            load_static=np.array([t[2] for t in terms], dtype=bool).reshape(len(terms), n),
            static_terms=robot.static_terms)

    @property
    def in_arrays(self) -> bool:
        """Whether the whole update is in :class:`FrictionUpdate` (no :attr:`python_extras`)."""
        return not self.python_extras

    @property
    def reads_start_state(self) -> bool:
        """Whether the first step's update reads kinematics: ``runs.forward()`` before stepping."""
        return len(self.base.load_static) > 0 or bool(self.python_extras)

    def chunk(self, start: int, stop: int) -> FrictionUpdate:
        """The update of steps ``start`` to ``stop`` (physics steps from the cycle's start)."""
        nsim, n = self.dry.shape
        level = np.broadcast_to(self.dry[:, None], (nsim, stop - start, n))
        if self.factors:
            time = self.run_start[:, None, :] + (np.arange(start, stop) * self.dt)[None, :, None]
            for effect in self.factors:  # each factor a function of the time alone: all steps at once
                level = level * effect.dry_friction_factor(time.reshape(-1, 1)).reshape(nsim, stop - start, n)
        return replace(self.base, level=level)

    def setter(self, runs, update: FrictionUpdate) -> Writer:
        """``set_level(k)`` (a :class:`Writer`): :func:`apply` of ``update`` into ``runs``' friction
        loss before step ``k`` of its chunk, then the :attr:`python_extras` (the stepping loop's
        fallback for a backend that does not apply the update itself, and for a plug-in's extra)."""
        robot, rotor = self.robot, update.rotor_dof
        frictionloss, qvel, qpos = runs.expand("dof_frictionloss"), runs.bind("qvel"), runs.bind("qpos")
        kinematics = tuple(runs.bind(name) for name in KINEMATICS) if self.reads_start_state else None
        write = writer(update, qvel, qpos, kinematics, frictionloss)
        if not self.python_extras:
            return write

        def static_load() -> np.ndarray:
            return robot.static_load_of(*kinematics, qpos)

        def extras(k: int) -> None:
            deflection = qpos[:, robot.rotor_qpos] / robot.gear_ratio - qpos[:, robot.arm_qpos]
            for effect in self.python_extras:
                frictionloss[:, rotor] += effect.dry_friction_extra(robot, deflection, static_load)

        return write.then(extras)
