"""Shared by the benchmarks: MuJoCo stepping a run's workload with no Python in the loop (the
baseline), the peak memory of a process and its workers, the options of a benchmark's
independent fleet, and those of a benchmark over logs of the independent-simulator set."""

from __future__ import annotations

import argparse
import threading
import time
from pathlib import Path
from typing import Self

import mujoco
import numpy as np
from mujoco import batch as mjbatch

from faultgen.model import robots
from faultgen.operation import programs
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim


def fleet_options(parser: argparse.ArgumentParser, units: int, worn: int, days: int = 120, seed: int = 0) -> None:
    """Add the options of a benchmark's independent fleet (tests/independent_fleet.py's ``FleetSpec``)
    to ``parser``: ``--units``, ``--worn`` (of them, units wearing one axis), ``--days`` (one log a
    day), ``--seed`` and ``--work`` (the folder to keep the fleet and outputs in; default none)."""
    parser.add_argument("--units", type=int, default=units)
    parser.add_argument("--worn", type=int, default=worn)
    parser.add_argument("--days", type=int, default=days)
    parser.add_argument("--seed", type=int, default=seed)
    parser.add_argument("--work", type=Path, default=None, help="Folder to keep the fleet and outputs in.")


def table_options(parser: argparse.ArgumentParser) -> None:
    """Add ``--csv`` (write the rows there, as they finish) and ``--from-csv`` (print the table of an
    earlier run's CSV, run nothing) to ``parser``."""
    parser.add_argument("--csv", type=Path, help="write the rows here, as they finish")
    parser.add_argument("--from-csv", type=Path, help="print the table of an earlier run's CSV, run nothing")


def chosen_cases(parser: argparse.ArgumentParser, cases: list, parts: list[str]) -> list:
    """The ``cases`` (objects with a ``name``) whose name contains one of ``parts``, in the order of
    ``parts`` (every case for none); a parser error naming ``parts`` and the names where none does."""
    chosen = [c for c in cases if not parts or any(n in c.name for n in parts)]
    if parts:  # in the order given
        chosen.sort(key=lambda c: min(k for k, n in enumerate(parts) if n in c.name))
    if not chosen:
        parser.error(f"no log name contains any of {parts}; names: {[c.name for c in cases]}")
    return chosen


def tree_rss() -> int:
    """Resident set of this process and all its children, bytes."""
    import psutil

    me = psutil.Process()
    total = me.memory_info().rss
    for child in me.children(recursive=True):
        try:
            total += child.memory_info().rss
        except psutil.NoSuchProcess:
            pass
    return total


class PeakRSS:
    """Context manager sampling :func:`tree_rss` every 50 ms; ``peak`` (bytes) after it exits."""

    def __enter__(self) -> Self:
        self.peak, self._stop = 0, threading.Event()

        def sample() -> None:
            while not self._stop.is_set():
                self.peak = max(self.peak, tree_rss())
                time.sleep(0.05)

        self._thread = threading.Thread(target=sample, daemon=True)
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._stop.set()
        self._thread.join()


def _prepared(config: sim.RunConfig):
    robot = robots.load(config.robot)
    model_sim = sim.build(robot, config.friction)
    path = programs.load(robot, config.task).trajectory(model_sim.model.opt.timestep)
    per_log = int(round(sensors.LOG_PERIOD / model_sim.model.opt.timestep))
    n_steps = -(-(len(path.t) - 1) // per_log) * per_log
    return robot, model_sim, path, n_steps


def _batch(model_sim: sim.SimModel, q0: np.ndarray, n_sim: int, nthread: int) -> mjbatch.Batch:
    batch = mjbatch.Batch(model_sim.model, nsim=n_sim, nthread=nthread)
    batch.qpos, batch.qvel = sim.start_state(model_sim.robot, q0)
    batch.act = 0.0
    return batch


def same_work_seconds(config: sim.RunConfig) -> float:
    """Seconds for one ``Batch.rollout`` of a run's workload: its recorded cycles, the same
    set-points and disturbance inputs, the same records, ``config.nthread`` threads."""
    robot, model_sim, path, n_steps = _prepared(config)
    model = model_sim.model
    n_sim = len(config.recorded_cycles)
    inputs = model_sim.setpoints(path.q, path.qd, path.qdd)
    inputs = np.vstack([inputs, np.repeat(inputs[-1:], max(0, n_steps - len(inputs)), axis=0)])[:n_steps]
    control_in = np.zeros((n_sim, n_steps, model.nu + model.nv))
    control_in[:, :, : model.nu][:, :, model_sim.drive_ctrl] = inputs
    control_in[:, :, model.nu + robot.arm_dof] = np.random.default_rng(0).standard_normal((n_sim, n_steps, 6))
    batch = _batch(model_sim, path.q[0], n_sim, config.nthread)
    spec = mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_QFRC_APPLIED
    started = time.perf_counter()
    batch.rollout(n_steps, control=control_in, control_spec=spec, record=("qpos", "qvel", "actuator_force"))
    return time.perf_counter() - started


def hold_seconds(config: sim.RunConfig) -> float:
    """Seconds for one ``Batch.step`` call stepping the run's cycles with the drives holding still."""
    robot, model_sim, path, n_steps = _prepared(config)
    batch = _batch(model_sim, path.q[0], len(config.recorded_cycles), config.nthread)
    ctrl = np.zeros(model_sim.model.nu)
    ctrl[model_sim.drive_ctrl[:, 0]] = robot.gear_ratio * path.q[0]
    batch.ctrl = ctrl
    started = time.perf_counter()
    batch.step(nstep=n_steps)
    return time.perf_counter() - started


def simulated_seconds(config: sim.RunConfig) -> float:
    """Simulated time of a run's recorded cycles, s."""
    _, model_sim, _, n_steps = _prepared(config)
    return len(config.recorded_cycles) * n_steps * model_sim.model.opt.timestep
