"""The units of ``faultgen monitor`` scored in parallel (:func:`map_groups`): one after another in
this process, in local processes (on Linux forked from this one, which has made the imports and the
shared twins; elsewhere joblib's loky), or on a Dask cluster that shares no file system with this
process (:mod:`faultgen.monitor.remote`); every group's arithmetic is the same wherever it runs, so
the outputs are those of one job, bit for bit.

Why forked processes and not joblib's loky on Linux: a loky worker is a fresh interpreter that
imports the scoring code again (faultgen, MuJoCo, SciPy, matplotlib, ProgPy), 2-3 s per worker on
an idle core and about 13 s at a load average of 8, which was most of ``--jobs 2``'s loss on a
small fleet (docs/performance.md); joblib's fork-based backend (``multiprocessing``) yields no
results before the last, so the standard library's ``ProcessPoolExecutor`` with the fork context
is used (:func:`faultgen.pools.forked_pool`), its tasks a group's index into what the workers inherit.
"""

from __future__ import annotations

import os
from pathlib import Path

from faultgen import pools
from faultgen.model.robot import Robot
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import state as stored
from faultgen.monitor.feed import Context, idle_outputs, score_group
from faultgen.monitor.history import UnitHistory
from faultgen.monitor.twin import Twin, base_cycles
from faultgen.monitor.unit import log_of, model_of
from faultgen.simulation.backends import Stepper


def groups_of(pending: dict[str, tuple[UnitHistory, list]]) -> list[list[tuple[str, UnitHistory, list]]]:
    """The units to score, one group each, in the folder's order (a twin's simulated cycles are
    shared through the disk cache: :func:`prepare_twins` simulates them once before)."""
    return [[(name, unit, logs)] for name, (unit, logs) in pending.items()]


def prepare_twins(context: Context, groups: list, pool=None, source: fleet_logs.Source | None = None) -> None:
    """Simulate, once, the cycles of every twin that several units share (the nominal or a given
    model on one program), so that parallel workers read them from the cache instead of simulating
    them side by side: each of its :func:`faultgen.monitor.twin.base_cycles` as a task of ``pool``
    (a ``concurrent.futures`` executor) when given, then the twin made here from the cache. A twin
    that cannot be built is left to each unit's own fallback (:func:`twin_of`). The programs come
    parsed from ``source`` (the run's; a new one when None) and go to the tasks as they are."""
    source = source if source is not None else context.new_source()
    seen = set()
    for (name, unit, _), in groups:
        key = (unit.model, unit.program)
        if unit.model not in ("given", "nominal") or unit.program is None or key in seen:
            continue
        seen.add(key)
        cache = context.out / ".cache" / "cycles"
        try:
            model = model_of(source, unit.model, unit.first, None, context.out, False)  # as twin_of has it
            program = source.get(log_of(context.units, *unit.program))
            twin = Twin(model, program, cache, root=context.out, cycles=False, stepper=context.stepper)
            missing = [c for c in base_cycles(twin.robot.n_axes) if not twin.cached(*c)]
            if pool is not None and len(missing) > 1:
                list(pool.map(_twin_cycle, *zip(*[(model, program, cache, context.out, context.stepper, *c)
                                                 for c in missing], strict=True)))
            twin.complete()
        except stored.StateError:
            raise
        except ValueError:
            continue


def _twin_cycle(model: Robot, program: fleet_logs.Parsed, cache: Path, root: Path, stepper: Stepper,
                temperature: float, payload: float, worn_axis: int) -> None:
    """Worker task: one cycle of a shared twin (its robot and its program as this run resolved and
    parsed them, pickled: a robot read from a file is parsed again from it on arrival) into the cache
    (:meth:`faultgen.monitor.twin.Twin.cycle`), simulated on ``stepper``. A cycle that
    cannot be simulated (or a cache file refused) is left to the twin made after all of them, which
    says why."""
    try:
        twin = Twin(model, program, cache, root=root, cycles=False, stepper=stepper)
        twin.cycle(temperature, payload, worn_axis)
    except ValueError:
        return


#: What the forked workers read instead of receiving it with every task: the run's context and its
#: groups, set in this process before the workers are forked (:func:`map_groups`).
_SHARED: dict = {}


def _score_shared(index: int) -> list:
    groups = _SHARED["groups"]
    if index < len(groups):
        return score_group(_SHARED["context"], groups[index], _SHARED["source"])
    return idle_outputs(_SHARED["idle"][index - len(groups)], _SHARED["context"].failure_wear)


def preload() -> None:
    """Import, in this process, what scoring a group imports on first use (matplotlib for the
    charts, ProgPy for the remaining life, as :mod:`faultgen.monitor.report` and
    :mod:`faultgen.monitor.prognosis` import them), so that forked workers start with it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot

    from faultgen.monitor import prognosis

    prognosis.import_progpy()


def map_groups(run, context: Context, groups: list, idle: list | tuple = (), source: fleet_logs.Source | None = None):
    """Each group of ``run`` (a :class:`faultgen.monitor.run.MonitorRun`) scored (:func:`score_group`,
    on its workers' ``context``), then each ``idle`` monitor's (a unit with no new log) chart and
    remaining life made (:func:`idle_outputs`), yielded in that order, on the run's execution
    context (``run.context``): in this process; in ``jobs`` local processes when ``jobs`` > 1 (on
    Linux forked from this one, after the shared twins are simulated: :func:`prepare_twins`, and
    the scoring's imports made: :func:`preload`; elsewhere joblib's loky, started without the user's folders on their path:
    :func:`faultgen.children.safe_path`; either way each worker ends within a second of this process,
    as a sweep's do: :func:`faultgen.pools.watch_parent`); or on the Dask cluster of ``scheduler``
    (:func:`faultgen.monitor.remote.execute`; the robot as the user named it). Every group's
    arithmetic is the same wherever it runs, so the outputs are those of one job, bit for bit.
    ``source``: the run's logs as read so far (:class:`faultgen.monitor.logs.Source`), which this
    process and forked workers read from; loky's and Dask's workers read the logs they score."""
    idle = list(idle)
    jobs, scheduler = run.context.jobs, run.context.scheduler
    source = source if source is not None else context.new_source()
    if scheduler is not None:
        if groups:
            prepare_twins(context, groups, source=source)
        from faultgen.monitor import remote

        yield from remote.execute(context, groups, scheduler, run.named, idle)
        return
    if jobs <= 1 or len(groups) + len(idle) <= 1:
        yield from (score_group(context, group, source) for group in groups)
        yield from (idle_outputs(m, context.failure_wear) for m in idle)
        return
    n_jobs = min(jobs, len(groups) + len(idle))
    if pools.FORK:
        # Forked workers start with this process's imports and state (faultgen, MuJoCo, SciPy,
        # matplotlib, ProgPy: 2-3 s of a fresh interpreter's start on an idle core, 13 s at a load
        # average of 8), and read the context and groups from it: a task is an index. They
        # simulate the shared twins' cycles first (in ``jobs`` processes, not one after another).
        preload()
        _SHARED.update(context=context, groups=groups, idle=idle, source=source)
        # each worker ends within a second of this process, whatever ended it (SIGKILL, SIGTERM), as the
        # sweep's do (forked workers waiting on the task queue would otherwise run on for good), and
        # leaves a Ctrl-C or SIGTERM of the process group to this process (faultgen.pools.start_worker); an
        # interrupt or a failure stops them at once (faultgen.pools.stop)
        try:
            with pools.forked_pool(n_jobs) as pool:
                if groups:
                    prepare_twins(context, groups, pool, source)
                yield from pool.map(_score_shared, range(len(groups) + len(idle)))
        finally:
            _SHARED.clear()
        return
    if groups:
        prepare_twins(context, groups, source=source)
    from joblib import Parallel, delayed
    from joblib._parallel_backends import LokyBackend

    from faultgen import children

    tasks = [delayed(score_group)(context, group) for group in groups]
    tasks += [delayed(idle_outputs)(m, context.failure_wear) for m in idle]
    with children.safe_path():  # elsewhere (no fork): loky's fresh workers, without the user's folders on their path
        backend = LokyBackend(initializer=pools.watch_parent, initargs=(os.getpid(),))
        yield from Parallel(n_jobs=n_jobs, return_as="generator", backend=backend)(tasks)
