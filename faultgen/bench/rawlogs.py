"""A track's test split written again as raw logs, the input of ``faultgen monitor``, each monitored
unit tied to the test unit of ``test.h5`` it is (docs/bench.md, "The twin on the leaderboard").

``test.h5`` holds per-record features; the monitor's twin reads each unit's logs (``t``, ``q1..qN``
rad, ``tau1..tauN`` N m at the arm side, ``temperature1..N`` deg C, ``payload`` kg:
docs/dataset.md's measured format with the conditions' columns). So the test split is made again
from the track version's recipe with its seeds, as ``faultgen bench make`` makes it, keeping what
it drops:

- a part of kind ``logs`` (the sim-to-real track's fleet): the independent simulator writes the same
  fleet again (:func:`faultgen.bench.independent.write_fleet`, the same spec and seed), one log a
  day; it is imported as ``faultgen logs import`` does, for the features that tie each fleet unit to
  its test unit;
- a sweep part (the conditions track): each test run is simulated again with its 250 Hz signals
  (:func:`faultgen.simulation.stepping.simulate`), one log per cycle. A run with a task mix keeps no
  signals (its tasks' cycles differ in length), so each task's cycles are simulated as a run of
  that task alone that records just them: the conditions of a cycle depend on the run's seed and the
  cycle only (:meth:`faultgen.operation.conditions.Conditions.evaluate`), so these are the track's
  cycles. Each task's logs are then a unit of their own for the monitor (``<test unit>-<task>``):
  the monitor follows one program per unit, and a program change restarts its learning
  (``faultgen monitor --help``), which the track's blocks of 10 cycles would do every block.

A regenerated unit is tied to the test unit whose features (:data:`faultgen.bench.files.FEATURES`,
every record) are closest; refused unless they agree within :data:`MATCH_RTOL` (the data are made
outside the track's numeric profile, so the last bits may differ: docs/bench.md, "Two machines")
and each test unit gets one unit. The labels are never read.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from faultgen.bench import files, tracks
from faultgen.data import cells
from faultgen.logs.columns import PAYLOAD_COLUMN, T_COLUMN, column_names, temperature_columns

#: Largest relative difference (to the feature's scale) between a regenerated unit's features and
#: its test unit's: other BLAS or NumPy kernels move the last bits (1e-15 rad on a weld path's joint
#: reference, docs/bench.md); a different draw moves them by percents.
MATCH_RTOL = 1e-6


@dataclass
class Written:
    """The test split as the monitor's input.

    Attributes
    ----------
    logs : Path
        ``LOGS/<unit>/<stamp>.csv``: the folder ``faultgen monitor`` reads.
    robot : str
        The robot the logs come from (a name or a robot folder), ``faultgen monitor --robot``.
    records : dict of test unit id -> dict of monitor unit -> ndarray of int
        For each test unit, the monitor units its records are and, per monitor unit, the rows of
        the test unit's records its logs are, in the monitor unit's stamp order.
    """

    logs: Path
    robot: str
    records: dict[str, dict[str, np.ndarray]]


def match(regenerated: dict[str, np.ndarray], test: list[files.Unit]) -> dict[str, str]:
    """``{test unit id: regenerated name}``: each test unit tied to the regenerated unit whose features
    ``(n_records, 4 N)`` agree with its own.

    Raises
    ------
    ValueError
        A test unit none agrees with within :data:`MATCH_RTOL` (naming it and the closest), or two
        test units tied to one regenerated unit.
    """
    out: dict[str, str] = {}
    for unit in test:
        mine = unit.features()
        scale = np.maximum(np.max(np.abs(mine), axis=0), 1e-12)
        gaps = {name: float(np.max(np.abs(X - mine) / scale)) if X.shape == mine.shape else np.inf
                for name, X in regenerated.items()}
        best = min(gaps, key=gaps.get)
        if gaps[best] > MATCH_RTOL:
            raise ValueError(f"test unit {unit.id}: no regenerated unit has its features (closest {best}, "
                             f"relative difference {gaps[best]:.3g} > {MATCH_RTOL:g}); is the folder of this track "
                             "version and size?")
        if best in out.values():
            raise ValueError(f"test units {next(k for k, v in out.items() if v == best)} and {unit.id} both match {best}")
        out[unit.id] = best
    return out


def write(track: str, version: int | None, size: str, test: list[files.Unit], work: Path) -> Written:
    """Write the test split of ``track`` (version, ``size``) again as raw logs under ``work`` and tie
    its units to ``test`` (the units of the track folder's ``test.h5``).

    Raises
    ------
    ValueError
        A track version with both a sweep part and a logs part in its test split, or none; a
        regenerated unit that does not match (:func:`match`).
    """
    recipe = tracks.load(track).version(version)
    work = Path(work)
    sweeps, fleets = recipe.grids("test", size), recipe.fleets("test", size)
    if bool(sweeps) == bool(fleets):
        raise ValueError(f"track {track} version {recipe.number}: its test split has {len(sweeps)} sweep parts and "
                         f"{len(fleets)} fleets; the twin's logs are written for one kind")
    if fleets:
        return _fleet(recipe, size, test, work)
    return _sweeps(sweeps, test, work)


def _fleet(recipe: tracks.Version, size: str, test: list[files.Unit], work: Path) -> Written:
    import faultgen
    from faultgen.bench import independent, make
    from faultgen.data import fleetlogs

    (_, fleet), = recipe.fleets("test", size)  # one fleet per test seed: the tracks have one
    robot = make.add_robots(recipe, work / "robots")[fleet["robot"]]
    spec = independent.FleetSpec(**{k: tuple(v) if isinstance(v, list) else v for k, v in fleet["spec"].items()})
    logs, _ = independent.write_fleet(work / "fleet", spec, robot)
    dataset = work / "fleet.h5"
    fleetlogs.import_logs(logs, dataset, robot=str(robot), progress=False)
    with faultgen.open(dataset) as data:
        regenerated = {run.id: np.concatenate([run.array(n) for n in files.FEATURES], axis=1) for run in data}
    tied = match(regenerated, test)
    return Written(logs, str(robot), {uid: {name: np.arange(len(regenerated[name]))} for uid, name in tied.items()})


def _sweeps(parts: list[tuple[str, dict]], test: list[files.Unit], work: Path) -> Written:
    import faultgen
    from faultgen.simulation import stepping

    runs, robot = [], None
    for _, fields in parts:
        fields = dict(fields)
        preset = fields.pop("preset", None)
        grid = faultgen.Grid.from_preset(preset, **fields) if preset else faultgen.Grid(**fields)
        runs += grid.runs()
    regenerated, rows = {}, {}
    staged = work / "runs"
    staged.mkdir(parents=True, exist_ok=True)
    for run_id, config in runs:
        if robot not in (None, config.robot):
            raise ValueError(f"the test split runs robots {robot} and {config.robot}; the monitor takes one")
        if config.daily:
            raise ValueError(f"run {run_id} records one sample a day: its records are no logs")
        robot = config.robot
        done = staged / f"{run_id}.npz"  # a run whose logs are all written: kept (a stopped write resumes)
        if not done.is_file():
            features, tasks = [], {}
            for task, part in _simulate(config, stepping).items():  # written at once: a run's signals, not all
                _write_logs(staged / f"{run_id}-{task}", part)
                features.append((part["rows"], np.concatenate([part["features"][n] for n in files.FEATURES], axis=1)))
                tasks[task] = part["rows"]
            order = np.concatenate([r for r, _ in features])
            partial = staged / f"{run_id}.part.npz"
            np.savez(partial, features=np.concatenate([f for _, f in features])[np.argsort(order)],
                     **{f"rows_{task}": r for task, r in tasks.items()})
            os.replace(partial, done)
        with np.load(done) as held:
            regenerated[run_id] = held["features"]
            rows[run_id] = {name[5:]: held[name] for name in held.files if name.startswith("rows_")}
    tied = match(regenerated, test)
    logs = work / "logs"
    logs.mkdir(parents=True, exist_ok=True)
    records = {}
    for uid, run_id in sorted(tied.items()):
        records[uid] = {}
        for task, task_rows in rows[run_id].items():
            name = f"{uid}-{task}"  # the test unit's id: the run's (its worn axis) stays out of the monitor's input
            target = logs / name
            if target.exists():
                raise ValueError(f"{target} exists; give an empty work folder")
            os.replace(staged / f"{run_id}-{task}", target)
            records[uid][name] = task_rows
    return Written(logs, str(robot), records)


def _simulate(config, stepping) -> dict[str, dict]:
    """Per task of one run, its cycles simulated with their signals (module docstring): ``rows``
    (the run's recorded cycles, its records in ``test.h5``, that the task ran), ``cycles``, ``t``
    (n_log,) s, ``q`` and ``tau`` (n, n_log, N) rad and N m at the arm side, ``joint_temperature``
    (n, N) deg C or None, ``payload_mass`` (n,) kg and ``features`` (name -> (n, N))."""
    cycles = config.recorded_cycles
    conditions = config.conditions
    mix = conditions.task_mix
    n_axes = config.model.n_axes
    if mix is None:
        tasks = np.array([config.task] * len(cycles), dtype=object)
    else:
        tasks = conditions.evaluate(config.seed, cycles, n_axes).tasks(mix)
    out = {}
    for task in dict.fromkeys(tasks):
        rows = np.flatnonzero(tasks == task)
        alone = replace(config, task=str(task), record=tuple(int(c) for c in cycles[rows]), signals=True,
                        conditions=replace(conditions, task_mix=None))
        result = stepping.simulate(alone, progress=False)
        held = result.conditions
        out[str(task)] = {
            "rows": rows, "cycles": result.cycles, "t": result.t, "q": result.q_a,
            "tau": result.tau_m * config.model.gear_ratio,  # arm side: the motor torque through the gear ratio
            "joint_temperature": None if held is None or np.isnan(held.joint_temperature).all()
            else held.joint_temperature,
            "payload_mass": np.zeros(len(rows)) if held is None else held.payload_mass,
            "features": {n: result.features[n] for n in files.FEATURES}}
    return out


def _write_logs(folder: Path, part: dict) -> None:
    """One CSV log per cycle, ``<cycle>.csv`` (the stamp a sequence number): t, q, tau, and the joint
    temperatures and payload when the run has them."""
    folder.mkdir(parents=True, exist_ok=True)
    n = part["q"].shape[2]
    q_names, _, tau_names = column_names(n)
    header = [T_COLUMN, *q_names, *tau_names]
    formats = ["%.4f"] + ["%.8f"] * n + ["%.5f"] * n
    has_temperature = part["joint_temperature"] is not None
    if has_temperature:
        header += list(temperature_columns(n))
        formats += ["%.3f"] * n
    header.append(PAYLOAD_COLUMN)
    formats.append("%.3f")
    t = part["t"]
    for i, cycle in enumerate(part["cycles"]):
        columns = [t[:, None], part["q"][i], part["tau"][i]]
        if has_temperature:
            columns.append(np.broadcast_to(part["joint_temperature"][i], (len(t), n)))
        columns.append(np.full((len(t), 1), part["payload_mass"][i]))
        path = folder / f"{int(cycle):04d}.csv"
        partial = path.with_name(path.name + ".part")
        np.savetxt(partial, np.hstack(columns), fmt=formats, delimiter=",", header=cells.line(header), comments="")
        os.replace(partial, path)
