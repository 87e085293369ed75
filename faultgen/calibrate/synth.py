"""Hidden-effect data: a "measured" torque log made by our own simulator with one effect switched on.

This is how the calibration workflow is checked (tests/test_calibrate_hidden.py,
``benchmarks/calibration_accuracy.py``, docs/calibration.md): an effect of the library is drawn
at a random size on random axes, written into a copy of the robot's MJCF with the same
:meth:`Effect.apply` the workflow uses, and that model is simulated closed-loop (PID drives,
flexible gearboxes, static Stribeck friction with stiction, load disturbance, encoder noise;
:func:`faultgen.simulation.stepping.simulate`) over several cycles of a task, back to back in one
simulation as on a robot (each cycle starts where the previous one ended: a dead band's flank, a gearbox still
ringing). The log is what a robot controller
records: ``q = theta_m / G`` from the motor encoders, ``tau = G tau_m`` from the drive torque,
plus torque-sensor noise. The workflow then gets only that file and the robot's name.

Sizes are drawn relative to the robot: the effect's torque RMS on a chosen axis is a fraction
``size`` (drawn from :data:`SIZE_RANGE`) of the RMS of that axis's nominal torque along the
task; nonlinear parameters (Stribeck velocity, cogging poles, warm-up time constant) are drawn
within the range the workflow searches.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from faultgen import axes
from faultgen.calibrate.effects import Effect, Motion, get
from faultgen.calibrate.effects import motion as motion_of
from faultgen.data import logfiles
from faultgen.model import robot as robot_model
from faultgen.model import robots
from faultgen.operation import programs
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim
from faultgen.simulation.resolve import resolve
from faultgen.simulation.spec import RunSpec

#: Range of the effect's torque RMS over the axis's nominal torque RMS.
SIZE_RANGE = (0.5, 1.2)
#: Physical bounds on drawn parameters are each effect's
#: :attr:`~faultgen.effects.Effect.draw_limits`: past one, the effect on that axis is shrunk to the
#: bound, and an axis left below :data:`MIN_SIZE` is not drawn (e.g. load-dependent friction on a
#: wrist axis that carries almost no load).
#: Largest share of a motor's torque limit the hidden friction, offset or cogging may take, so
#: the drive can still move the axis (a stuck axis shows nothing).
MOTOR_SHARE = 0.4
#: Smallest size an axis may carry after the bounds.
MIN_SIZE = 0.45
#: Torque-sensor noise, standard deviation as a fraction of each axis's torque RMS.
TORQUE_NOISE = 0.01
#: An effect not linear in its parameter (backlash) is drawn by that parameter's range instead of
#: a torque size (:attr:`~faultgen.effects.Effect.draw_range`): an axis is eligible when the torque
#: the effect changes along the nominal task (its :meth:`~faultgen.effects.Effect.columns`) has an
#: RMS of at least the smallest size times the axis's torque RMS.
#: Most axes an effect is hidden on.
MAX_AXES = 3
#: Physics step of the hidden-effect simulation, s (the robot models use 0.5 ms), and its
#: integrator. The logs must resolve what the per-cycle features of a dataset average away: the
#: cogging ripple (poles x motor speed, hundreds of Hz) and the landings in a dead band. The robots'
#: ``discrete`` integrator treats springs implicitly and damps such content at 0.1 ms (IRB-6700-like
#: cogging, seed 0: held-out gap ratio 0.765 at 0.1 ms, 0.591 at 0.025 ms), while ``implicitfast``
#: gives 0.563 at 0.1 ms and 0.560 at 0.025 ms; its extra inertia ``h D / G^2`` from the gearbox
#: dampers (docs/simulation.md, "Numerical convergence") is at most 0.8 % of a rotor's at 0.1 ms.
TIMESTEP = 1e-4
INTEGRATOR = mujoco.mjtIntegrator.mjINT_IMPLICITFAST


@dataclass(frozen=True)
class Hidden:
    """What was hidden in a log.

    Attributes
    ----------
    effect : Effect or None
        The robot's effect with the hidden parameters (absolute, SI units) on ``axes``; None when
        nothing is hidden.
    axes : list of int
        The axes it was hidden on, 0-based (all six for a robot-wide effect).
    size : float
        The smallest size on those axes (effect torque RMS over the axis's nominal torque RMS).
    """

    effect: Effect | None
    axes: list[int] = field(default_factory=list)
    size: float = 0.0

    @classmethod
    def of(cls, robot: robots.Robot, effect: str, params: dict[int | None, dict[str, float]],
           size: float = 0.0) -> Hidden:
        """``robot``'s effect ``effect`` with ``params`` in place, keyed by axis (0-based; None for
        a robot-wide effect, which is hidden on all of the robot's axes)."""
        kind = get(effect)
        hidden_on = list(range(robot.n_axes)) if not kind.per_axis else sorted(params)
        return cls(kind.fitted(robot, params), hidden_on, size)

    def record(self) -> dict:
        """As ``report.json`` gives a step: effect id, axes numbered 1..N and the parameters on them."""
        if self.effect is None:
            return {"effect": None, "axes": [], "params": {}}
        return {"effect": self.effect.id, "axes": axes.numbers(self.axes), "params": self.effect.report(self.axes)}

    def __str__(self) -> str:
        return str(self.record())


def nominal_motion(robot: robots.Robot, task: str, cycles: int) -> tuple[Motion, np.ndarray]:
    """The task's reference motion repeated ``cycles`` times at the log rate, and its nominal torque."""
    duration = sim.cycle_duration(robot, task)
    path = programs.load(robot, task).trajectory(sensors.LOG_PERIOD)
    n = round(duration / sensors.LOG_PERIOD)
    # the path held at its last sample to the cycle's end, as the simulator does
    q, qd, qdd = (np.tile(sim.hold_end(a, n - 1), (cycles, 1)) for a in (path.q, path.qd, path.qdd))
    t = np.arange(len(q)) * sensors.LOG_PERIOD
    tau = robot.inverse_dynamics(q, qd, qdd, t=t)
    return motion_of(robot, t, q, qd, qdd), tau


#: Amplitude of the slower sine on axes 1..7 (a robot of N axes takes the first N).
EXCITATION_SHARES = np.array([1.0, 0.8, 0.6, 1.0, 0.7, 1.0, 0.8])


def excitation(robot_list: list[robots.Robot], duration: float, period: float
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A smooth motion inside the joint ranges of every robot of ``robot_list`` (two sines per axis,
    0.1 and 0.23 Hz, over 35 % of the common range around its middle), sampled every ``period`` s
    for ``duration`` s: ``t`` (n,), ``q`` (rad), ``qd`` (rad/s), ``qdd`` (rad/s^2), each (n, N).
    A log along it passes every robot's joint-range check, so only its torque tells the robots
    apart (the plausibility guard's check, :mod:`faultgen.calibrate.plausibility`)."""
    n_axes = {r.n_axes for r in robot_list}
    if len(n_axes) != 1:
        raise ValueError(f"robots {', '.join(r.name for r in robot_list)} differ in their number of axes "
                         f"({sorted(n_axes)}); one excitation fits robots of one N")
    low = np.max([r.joint_range[:, 0] for r in robot_list], axis=0)
    high = np.min([r.joint_range[:, 1] for r in robot_list], axis=0)
    t = np.arange(0.0, duration, period)
    shape = (np.sin(2 * np.pi * 0.1 * t)[:, None] * EXCITATION_SHARES[: len(low)]
             + 0.3 * np.sin(2 * np.pi * 0.23 * t + 1.0)[:, None])
    q = (low + high) / 2 + 0.35 * (high - low) / 2 * shape
    qd = np.gradient(q, t, axis=0)
    return t, q, qd, np.gradient(qd, t, axis=0)


def draw(robot: robots.Robot, effect: str | None, rng: np.random.Generator, task: str = "pick_place",
         cycles: int = 4, size_range: tuple[float, float] = SIZE_RANGE) -> Hidden:
    """Draw a hidden effect of kind ``effect`` (None: nothing) at a random size on random axes.

    ``size_range`` bounds the size (effect torque RMS over the axis's nominal torque RMS); an axis
    the physical bounds shrink below ``min(MIN_SIZE, 0.9 * size_range[0])`` is not drawn. An
    effect with a :attr:`~faultgen.effects.Effect.draw_range` (backlash) is drawn by its parameter
    instead, on axes where it shows.

    Raises
    ------
    ValueError
        For an unknown effect id.
    """
    if effect is None:
        return Hidden(None)
    kind = get(effect)
    motion, tau = nominal_motion(robot, task, cycles)
    scale = np.sqrt(np.mean(tau**2, axis=0))
    if kind.draw_range is not None:
        name, low, high, min_size, fallback = kind.draw_range
        params, sizes = {}, np.zeros(robot.n_axes)
        for axis in range(robot.n_axes):
            value = float(rng.uniform(low, high))
            _, change = kind.columns(motion, axis, value)
            params[axis] = {name: value}
            sizes[axis] = np.sqrt(np.mean(change**2)) / scale[axis]
        return _choose(robot, effect, rng, params, sizes, min_size if np.any(sizes >= min_size) else fallback)
    size = float(rng.uniform(*size_range))
    min_size = min(MIN_SIZE, 0.9 * size_range[0])
    if not kind.per_axis:
        phi, _ = kind.columns(motion, None, None)
        direction = kind.draw_direction(rng)  # (k,): the payload's barycentric parameters
        relative = np.sqrt(np.mean((phi @ direction) ** 2, axis=0)) / scale
        theta = size / relative.max() * direction
        return Hidden.of(robot, effect, {None: kind.params(motion, None, theta, None)}, size)
    params, sizes = {}, np.zeros(robot.n_axes)
    for axis in range(robot.n_axes):
        grid = kind.draw_grid(motion, axis)
        if grid == [None]:
            h = None
        elif isinstance(grid[0], (int, np.integer)):
            h = int(rng.choice(grid))
        else:  # a continuous parameter: log-uniform inside the searched range, off the grid points
            h = float(np.exp(rng.uniform(np.log(grid[1]), np.log(grid[-2]))))
        phi, _ = kind.columns(motion, axis, h)
        direction = kind.draw_direction(rng)  # (k,): the cogging phase, or 1
        unit = phi @ direction
        if not np.any(unit):  # the effect cannot show on this axis (e.g. no Stribeck range)
            params[axis] = {}
            continue
        sign = -1.0 if kind.signed and rng.random() < 0.5 else 1.0
        amplitude = sign * size * scale[axis] / np.sqrt(np.mean(unit**2))
        theta = amplitude * direction
        drawn = kind.params(motion, axis, theta, h)
        # past a physical bound, shrink the effect to the bound (and note the smaller size)
        share = kind.motor_torque(motion, axis, drawn) / robot.motor_torque_limit[axis]
        excess = max([abs(drawn[k]) / limit for k, limit in kind.draw_limits.items()] + [1.0, share / MOTOR_SHARE])
        params[axis] = kind.params(motion, axis, theta / excess, h)
        sizes[axis] = size / excess
    return _choose(robot, effect, rng, params, sizes, min_size)


def _choose(robot: robots.Robot, effect: str, rng: np.random.Generator, params: dict, sizes: np.ndarray,
            min_size: float) -> Hidden:
    """1 to :data:`MAX_AXES` random axes among those whose drawn effect has ``sizes >= min_size``."""
    eligible = [a for a in range(robot.n_axes) if sizes[a] >= min_size]
    if not eligible:
        raise ValueError(f"{robot.name}: no axis can carry {effect} at a size >= {min_size} within "
                         f"{get(effect).draw_limits}")
    n_axes = int(rng.integers(1, min(MAX_AXES, len(eligible)) + 1))
    chosen = sorted(int(a) for a in rng.choice(eligible, size=n_axes, replace=False))
    return Hidden.of(robot, effect, {a: params[a] for a in chosen}, float(min(sizes[chosen])))


def _hide(robot: robots.Robot, hidden: Hidden, spec: mujoco.MjSpec) -> None:
    """Edit ``spec`` (the robot's) in place: ``hidden`` applied, the physics step :data:`TIMESTEP`
    and the :data:`INTEGRATOR`."""
    spec.option.timestep = TIMESTEP
    spec.option.integrator = INTEGRATOR
    if hidden.effect is not None:
        hidden.effect.write(spec, robot, hidden.axes)


def hidden_model(robot: robots.Robot, hidden: Hidden) -> tuple[str, robots.Robot]:
    """The robot with ``hidden`` applied, the physics step :data:`TIMESTEP` and the
    :data:`INTEGRATOR`, edited in memory: ``(text, robot)``, the MJCF text :func:`write_model`
    writes and the robot compiled from that text in memory (named by ``robot``'s file, whose
    folder's tasks.toml it plans with; no file read). Compiled from the text, not from the edited
    spec itself: MuJoCo's XML writer rounds numbers (the puma560's gear ratios in their 7th digit),
    and the log must be that of the model written beside it, bit for bit."""
    spec = robot.new_spec()
    _hide(robot, hidden, spec)
    text = spec.to_xml()
    spec = mujoco.MjSpec.from_string(text)
    spec.modelfiledir = str(robot.path.parent)
    return text, robot_model.from_spec(spec, robot.path)


def write_model(robot: robots.Robot, hidden: Hidden, folder: str | Path, text: str | None = None) -> Path:
    """Write the robot's MJCF with ``hidden`` applied, the physics step :data:`TIMESTEP` and the
    :data:`INTEGRATOR` (:func:`hidden_model`'s ``text``, made here when not given) and its
    tasks.toml into ``folder``."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{robot.name}_hidden.xml"
    path.write_text(hidden_model(robot, hidden)[0] if text is None else text)
    shutil.copyfile(robot.path.parent / "tasks.toml", folder / "tasks.toml")
    return path


#: Why faultgen's own null logs leave an inertia-like remainder (:func:`simulator_remainder`): measured on
#: the PUMA 560's null log of seed 3 (docs/calibration.md, "An axis left unexplained").
STEP_REMAINDER = ("at the simulation's {step:g} ms physics step (implicit in the speeds) the simulated arm carries an "
                  "extra inertia of the step's order, which no model of the robot holds (on the PUMA 560's null log "
                  "of seed 3 its wrist axes 4-6 follow their accelerations at 0.1 ms, and nothing is left "
                  "unexplained at 0.025 ms): the remainder is the simulator's, not the robot's; docs/calibration.md, "
                  "\"An axis left unexplained\"")


def simulator_remainder(measured: str | Path, unexplained: list[dict], nominal: robots.Robot) -> str | None:
    """Why the axes ``unexplained`` (:meth:`faultgen.calibrate.result.Calibration.unexplained`) are left
    on a log :func:`record` wrote with nothing hidden, or None. None unless ``measured`` has the model
    :func:`record` writes beside it (``STEM_model/*_hidden.xml``), that model's effects and friction
    are the ``nominal`` robot's (nothing hidden), and every such axis's remainder follows an
    acceleration at lag 0 (an inertia)."""
    path = Path(measured)
    models = sorted((path.parent / f"{path.stem}_model").glob("*_hidden.xml"))
    inertia = all(str((u.get("follows") or {}).get("variable", "")).startswith("qdd")
                  and (u.get("follows") or {}).get("lag") == 0 for u in unexplained)
    if not unexplained or not inertia or len(models) != 1:
        return None
    try:
        simulated = robots.load(models[0])
    except (OSError, ValueError):
        return None
    if simulated.n_axes != nominal.n_axes or (repr(simulated.effects), repr(simulated.friction)) != (
            repr(nominal.effects), repr(nominal.friction)):
        return None
    axes_left = ", ".join(str(u["axis"]) for u in unexplained)
    return (f"why axes {axes_left}: {path.name} is faultgen's own simulation with nothing hidden "
            f"({models[0].parent.name}/ beside it); " + STEP_REMAINDER.format(step=1e3 * simulated.model.opt.timestep))


def record(robot: robots.Robot, hidden: Hidden, out: str | Path, task: str = "pick_place",
           cycles: int = 4, seed: int = 0, progress: bool = False) -> Path:
    """Simulate ``cycles`` cycles of ``task`` on the robot with ``hidden`` switched on and write
    the log in the measured-data format (CSV, the design document's columns) to ``out``; the
    model with the hidden effect goes beside it, in ``OUT-STEM_model/`` (written, not read back: the
    run simulates :func:`hidden_model`'s robot, compiled in memory from the text written). ``progress`` draws the
    simulation's progress bar (``faultgen hidden-log``).

    Returns
    -------
    Path
        ``out``.

    Raises
    ------
    TypeError
        If ``robot`` is not a :class:`~faultgen.model.robot.Robot` (resolve a name once:
        :func:`faultgen.model.robots.load`).
    """
    robots.require(robot, "synth.record")
    out = Path(out)
    text, model = hidden_model(robot, hidden)
    write_model(robot, hidden, out.parent / f"{out.stem}_model", text)
    spec = RunSpec(robot=robots.source_of(model), task=task, friction="stribeck", cycles=cycles, seed=seed,
                   back_to_back=True)
    run = resolve(spec, resolved=model).simulate(progress=progress)
    G = robot.gear_ratio
    duration = sim.cycle_duration(model, task)
    t = np.concatenate([(c - 1) * duration + run.t for c in run.cycles])
    t = t - t[0]
    # MuJoCo computes a step's drive torque from the state at the step's start, and the log
    # holds the angle at its end: pair the torque with the angle it was computed at (semi-implicit
    # Euler: q_start = q_end - dt v_end). At 1 kHz cogging ripple half a millisecond is half a turn.
    q = (np.concatenate(run.q_m) - TIMESTEP * np.concatenate(run.qd_m)) / G
    tau = np.concatenate(run.tau_m) * G
    rng = np.random.default_rng([seed, 7])
    tau = tau + rng.normal(size=tau.shape) * TORQUE_NOISE * np.sqrt(np.mean(tau**2, axis=0))
    logfiles.write_csv(out, t, q, tau)
    return out
