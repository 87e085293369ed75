"""The units of ``faultgen monitor`` scored in parallel (:func:`mapgroups_of`): one after another in
this process, in local processes (joblib's loky), or on a Dask cluster that shares no file system
with this process (:mod:`faultgen.monitor.remote`); every group's arithmetic is the same wherever
it runs, so the outputs are those of one job, bit for bit.
"""

from __future__ import annotations

from pathlib import Path

from faultgen.model import robots
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import state as stored
from faultgen.monitor.feed import Context, score_group
from faultgen.monitor.twin import Twin
from faultgen.monitor.unit import Unit, log_of


def groups_of(pending: dict[str, tuple[Unit, list]]) -> list[list[tuple[str, Unit, list]]]:
    """The units to score, one group each, in the folder's order (a twin's simulated cycles are
    shared through the disk cache: :func:`prepare_twins` simulates them once before)."""
    return [[(name, unit, logs)] for name, (unit, logs) in pending.items()]


def prepare_twins(context: Context, groups: list) -> None:
    """Simulate, once and in this process, the cycles of every twin that several units share (the
    nominal or a given model on one program), so that parallel workers read them from the cache
    instead of simulating them side by side. A twin that cannot be built is left to each unit's
    own fallback (:func:`twin_of`)."""
    nominal = robots.load(context.robot)
    read_with, _ = fleet_logs.reader_of(context.log_format)
    seen = set()
    for (name, unit, _), in groups:
        key = (unit.model, unit.program)
        if unit.model not in ("given", "nominal") or unit.program is None or key in seen:
            continue
        seen.add(key)
        model = str(context.calibrated) if unit.model == "given" else str(nominal.path)
        try:
            Twin(model, log_of(context.units, *unit.program).path, context.out / ".cache" / "cycles", root=context.out,
                 reader=read_with)
        except stored.StateError:
            raise
        except ValueError:
            continue


class Workers:
    """``jobs`` local worker processes (joblib's loky) started at once in a background thread, each
    importing the scoring code, while this process goes on with its serial part (reading the fleet
    folder, each new unit's first log, the shared twins): on 2 cores the workers' start (about as
    long as this process's own imports) then no longer adds to the run's wall time.
    :func:`map_groups` waits for them and joblib reuses them (the same ``n_jobs``: loky's reusable
    executor). With ``jobs`` <= 1 nothing is started."""

    def __init__(self, jobs: int):
        self.jobs = jobs
        self._thread = None
        if jobs > 1:
            import threading

            self._thread = threading.Thread(target=self._start, daemon=True)
            self._thread.start()

    def _start(self) -> None:
        from joblib import Parallel, delayed

        from faultgen import children

        with children.safe_path():
            Parallel(n_jobs=self.jobs)(delayed(_import_scoring)() for _ in range(self.jobs))

    def wait(self) -> None:
        if self._thread is not None:
            self._thread.join()
            self._thread = None


def _import_scoring() -> None:
    import faultgen.monitor.feed  # noqa: F401  (what a group's scoring imports: faultgen, MuJoCo, SciPy, ...)


def map_groups(context: Context, groups: list, jobs: int = 1, scheduler: str | None = None,
               robot: str | Path | None = None, workers: Workers | None = None):
    """Each group scored (:func:`score_group`), yielded in order: in this process; in ``jobs``
    local processes (joblib's loky, started without the user's folders on their path:
    :func:`faultgen.children.safe_path`) when ``jobs`` > 1; or on the Dask cluster of
    ``scheduler`` (:func:`faultgen.monitor.remote.execute`; ``robot`` as the user named it). Every
    group's arithmetic is the same wherever it runs, so the outputs are those of one job, bit for bit.
    ``workers``: the local processes started ahead (:class:`Workers`, of ``min(jobs, len(groups))``)."""
    if scheduler is not None:
        prepare_twins(context, groups)
        from faultgen.monitor import remote

        yield from remote.execute(context, groups, scheduler, context.robot if robot is None else robot)
        return
    if jobs <= 1 or len(groups) <= 1:
        yield from (score_group(context, group) for group in groups)
        return
    prepare_twins(context, groups)
    if workers is not None:
        workers.wait()
    from joblib import Parallel, delayed

    from faultgen import children

    with children.safe_path():
        yield from Parallel(n_jobs=min(jobs, len(groups)), return_as="generator")(
            delayed(score_group)(context, group) for group in groups)
