"""Wear sweeps: a grid of runs (robot x task x worn axis x wear x schedule x seed) into one dataset.

Every run is simulated by a worker (joblib processes locally, or Dask distributed workers) and
written to its own part file in ``<out>.parts/``, atomically: by a local worker itself, by this
process for a Dask worker, which sends the run back (:mod:`faultgen.runs.cluster`). When every run is
there, the parts are merged into the dataset ``<out>`` (renamed into place last) and the part
folder is removed. Running the same sweep again after a crash, kill or Ctrl-C resumes: finished parts are
kept as they are and only the missing runs are simulated.

A sweep holds a lock on its output (``.<out>.lock`` beside it, an OS file lock, ``flock``)
for as long as it runs, and names itself in ``<out>.parts/sweep.json``: a second sweep on the
same output refuses at once, naming the first. The kernel releases the lock of a killed sweep, so
the next one takes it over (and says so). The lock file is removed when the sweep ends.

Whatever ends the sweep's own process (Ctrl-C, SIGTERM, SIGKILL), its local workers end too:
each watches its parent and exits within a second of it (:func:`faultgen.pools.watch_parent`); a SIGTERM is
handled as a Ctrl-C (the workers are stopped, the message says what is kept and how to resume).
"""


from __future__ import annotations

import datetime
import errno
import fcntl
import json
import logging
import os
import shutil
import signal
import socket
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Self

from tqdm.auto import tqdm

from faultgen import children, inputs, pools
from faultgen.data import atomic, dataset
from faultgen.runs import cluster, worker
from faultgen.runs.context import LOCAL, ExecutionContext
from faultgen.runs.errors import SweepError, SweepInterrupted, SweepRefused
from faultgen.runs.grid import PRESETS, Grid
from faultgen.runs.worker import RunStats, simulate_and_write
from faultgen.simulation import stepping as sim
from faultgen.simulation.resolve import Run

__all__ = ["PRESETS", "Grid", "RunStats", "SweepError", "SweepInterrupted", "SweepRefused", "finished_runs",
           "lock_path", "parts_folder", "run", "simulate_and_write"]

log = logging.getLogger(__name__)


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where a Ctrl-C would be, so that a sweep stops the same way (:class:`CtrlC`)."""



def parts_folder(out: Path) -> Path:
    return out.with_name(out.name + ".parts")


def _finished(part: Path, config: sim.RunConfig) -> bool:
    """True if ``part`` is a complete part file of exactly this configuration."""
    try:
        (attrs,) = dataset.labels(part)
    except (dataset.DatasetError, ValueError):
        return False
    return attrs.get("config") == dataset.config_key(config)


def finished_runs(grid: Grid, out: str | Path) -> list[str]:
    """Ids of the runs of ``grid`` already finished in the part folder of ``out``."""
    parts = parts_folder(Path(out))
    return [run_id for run_id, config in grid.runs() if _finished(parts / f"{run_id}.h5", config)]


def run(grid: Grid, out: str | Path, context: ExecutionContext = LOCAL, progress: bool = True,
        command: str = "", on_run: Callable[[RunStats], None] | None = None,
        timings: dict | None = None, overwrite: bool = False,
        on_start: Callable[[int, int], None] | None = None, shared: bool = False) -> Path:
    """Simulate every run of ``grid`` and write the dataset ``out``; resume if parts exist.

    Parameters
    ----------
    grid : Grid
    out : path of the dataset file to write.
    context : ExecutionContext
        Where and on what the runs are computed (:class:`faultgen.runs.context.ExecutionContext`;
        default: this process, ``BatchStepper()``): ``jobs`` local worker processes (joblib),
        ignored with a ``scheduler``, the address of a Dask distributed scheduler
        (``tcp://host:port``) whose workers send each run back to this process, which writes it
        (:mod:`faultgen.runs.cluster`: they need not see the folder of ``out``), and the
        ``stepper`` every run is stepped on, put on each run here once (a resolved run,
        :class:`~faultgen.simulation.resolve.Run`, is what the layers below and the workers take),
        pickled to the workers (a stepper class defined outside faultgen must be importable in their
        processes too). Every stepper gives the same
        dataset to float tolerance; it is not stored.
    progress : bool
        Show a progress bar over runs, with the time left.
    command : str
        The command line, stored as provenance.
    on_run : callable, optional
        Called in this process with the :class:`RunStats` of each run as it finishes.
    timings : dict, optional
        Filled with the wall time of the final merge (``"merge"``, s), for benchmarks.
    overwrite : bool
        Replace ``out`` if it exists; by default an existing ``out`` is refused.
    on_start : callable, optional
        Called once the sweep holds its output, with (runs in the grid, runs already finished).
    shared : bool
        With a ``scheduler``: the workers write the part files themselves, in the folder of ``out``,
        which they must all see at its absolute path (a shared file system; checked first).

    Returns
    -------
    Path of the dataset.

    Raises
    ------
    SweepRefused
        Before anything runs, if ``out`` exists (and not ``overwrite``) or another sweep is
        writing it (the message names that sweep: pid, host, start time, command), or for a
        ``context`` that is not an ExecutionContext.
    SweepInterrupted
        On Ctrl-C (KeyboardInterrupt): the workers are stopped, and the message says how many
        runs are kept and how to resume.
    SweepError
        If the output folder cannot be written or a run fails (the message names the run and says
        what to do); every finished run stays in the part folder for the next attempt.
    """
    out = Path(out)
    parts = parts_folder(out)
    if not isinstance(context, ExecutionContext):
        raise SweepRefused(f"context {context!r}: expected an ExecutionContext(jobs, scheduler, stepper) "
                           "(faultgen.runs.context)")
    # the stepper put on every run, once: below here each run carries it (a Run), no layer takes a stepper
    plan = [(run_id, Run(config, context.stepper)) for run_id, config in grid.runs()]
    with _lock(out, parts):
        if out.exists() and not overwrite:
            raise SweepRefused(f"{out} exists; pass --overwrite to replace it or choose another output")
        try:
            _prepare(out, parts)
            with _claim(out, parts, command):
                todo = [(run_id, run) for run_id, run in plan if not _finished(parts / f"{run_id}.h5", run.config)]
                todo.sort(key=_expected_cost, reverse=True)  # longest first: workers finish close together
                _check_space(out, parts, plan, todo)
                if on_start is not None:
                    on_start(len(plan), len(plan) - len(todo))
                with CtrlC() as ctrl_c:
                    try:
                        with tqdm(total=len(plan), initial=len(plan) - len(todo), unit="run", disable=not progress,
                                  desc=f"sweep {out.name}") as bar:
                            jobs = min(context.jobs, max(len(todo), 1))
                            for stats in _execute(todo, parts, jobs, context.scheduler, command, shared, bar):
                                bar.update(1)
                                if on_run is not None:
                                    on_run(stats)
                    except KeyboardInterrupt as interrupt:
                        ctrl_c.stopping = True
                        kept = len(finished_runs(grid, out))
                        what, code = (("terminated (SIGTERM)", 143) if isinstance(interrupt, Terminated)
                                      else ("interrupted", 130))
                        if not kept:  # the part folder goes too: nothing to point at
                            raise SweepInterrupted(f"{what}: none of the {len(plan)} runs had finished; run the "
                                                   "same command to start again", code) from None
                        raise SweepInterrupted(f"{what}: {kept} of {len(plan)} runs kept in {parts}; run the "
                                               "same command to resume", code) from None
                started = time.perf_counter()
                try:
                    dataset.merge([(run_id, parts / f"{run_id}.h5") for run_id, _ in plan], out, command=command,
                                  grid=grid.to_json())
                except OSError as err:
                    raise SweepError(f"cannot write {out}: {err.strerror or err}; every run is kept in {parts}: "
                                     "free space or fix permissions and run the same command again") from None
                if timings is not None:
                    timings["merge"] = time.perf_counter() - started
        except BaseException:
            _remove_if_empty(parts)  # no debris: a sweep that kept nothing leaves no part folder
            raise
        shutil.rmtree(parts)
    return out


def lock_path(out: Path) -> Path:
    """The lock file a sweep holds while it writes ``out``: hidden, beside it, removed when the
    sweep ends (a killed sweep's stays, empty, until the next sweep of ``out`` ends)."""
    return out.with_name(f".{out.name}.lock")


@contextmanager
def _lock(out: Path, parts: Path) -> Iterator[None]:
    """Hold the lock of ``out`` (:func:`lock_path`); refuse at once, naming the holder, if it is taken.

    An exclusive ``flock`` on the lock file. The holder removes the file before it lets the lock
    go, so a sweep that opened the file just before must find, once it holds the lock, that the
    path still names the file it locked; if not, it tries again on the new file.
    """
    if not (out.parent if str(out.parent) else Path(".")).is_dir():
        raise SweepError(f"cannot write {out}: folder {out.parent} does not exist")
    path = lock_path(out)
    while True:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as err:
            raise SweepError(f"cannot write to {out.parent}: {err.strerror}; choose another output path") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise SweepRefused(f"another sweep is writing {out}: {_describe_holder(parts)}; wait for it to finish "
                               "or stop it (a killed sweep's lock is taken over by the next one)") from None
        try:
            if os.stat(path).st_ino == os.fstat(fd).st_ino:
                break
        except FileNotFoundError:
            pass
        os.close(fd)  # the holder removed the file we opened: lock the new one
    try:
        yield
    finally:
        try:
            path.unlink(missing_ok=True)
        finally:
            os.close(fd)


def _remove_if_empty(folder: Path) -> None:
    try:
        folder.rmdir()
    except OSError:  # holds finished runs, or is gone
        pass


def _check_space(out: Path, parts: Path, plan, todo) -> None:
    """Refuse, before any run, a sweep whose parts and merged dataset would not fit on the disk."""
    needed = sum(dataset.estimated_size(run.config) for _, run in todo)
    needed += sum(dataset.estimated_size(run.config) for _, run in plan)  # the merged dataset
    try:
        atomic.check_writable(parts / "x.h5", needed)
    except OSError as err:
        raise SweepRefused(f"{err.strerror}; free some space or choose another output (finished runs are kept "
                           f"in {parts})" if err.errno == errno.ENOSPC else f"{err.strerror}") from None


@contextmanager
def _claim(out: Path, parts: Path, command: str) -> Iterator[None]:
    """Name this sweep in ``<parts>/sweep.json`` while it runs (what a refused second sweep prints).

    The record is removed whenever this sweep ends, even by an error or Ctrl-C, so a record found
    here was left by a killed sweep: that is said, and stale temporary files of ``out`` removed.
    """
    record = parts / "sweep.json"
    try:
        if record.exists():
            log.warning("took over %s from a sweep that was killed (%s); its finished runs are kept", out,
                        _describe_holder(parts))
        try:
            atomic.write_text(record, json.dumps({
                "pid": os.getpid(), "host": socket.gethostname(), "command": command,
                "started": datetime.datetime.now().astimezone().isoformat(timespec="seconds")}))
        except OSError as err:
            raise SweepError(f"cannot write {record}: {err.strerror or err}; free some space or choose another "
                             "output") from None
        atomic.remove_stale(out)
        yield
    finally:
        record.unlink(missing_ok=True)


#: Size bound of a sweep's record ``<parts>/sweep.json`` (a pid, a host, a time and the command line), bytes.
HOLDER_MAX_BYTES = 2**20


def _describe_holder(parts: Path) -> str:
    """'pid 123 on host, started 2026-11-22T12:00:00+00:00: faultgen sweep ...', from the record, read
    through :func:`faultgen.inputs.read_text` (a regular file of at most :data:`HOLDER_MAX_BYTES`, its
    size checked first: a sparse record planted in OUT's part folder was read whole)."""
    try:
        holder = json.loads(inputs.read_text(parts / "sweep.json", "sweep record", HOLDER_MAX_BYTES))
        text = f"pid {holder['pid']} on {holder['host']}, started {holder['started']}"
        return text + (f": {holder['command']}" if holder.get("command") else "")
    except (OSError, ValueError, KeyError, TypeError, AttributeError, RecursionError):
        return "a sweep that has not named itself yet"


def _expected_cost(item: tuple[str, Run]) -> float:
    """Simulated seconds of a run: recorded cycles times the task's cycle time."""
    config = item[1].config
    return len(config.recorded_cycles) * sim.cycle_duration(config.model, config.task)


def _prepare(out: Path, parts: Path) -> None:
    """Make the part folder, check it is writable, and drop temporary files of killed writers."""
    try:
        parts.mkdir(parents=False, exist_ok=True)
        probe = parts / ".write-test"
        probe.write_bytes(b"")
        probe.unlink()
    except FileNotFoundError:
        raise SweepError(f"cannot write {out}: folder {out.parent} does not exist") from None
    except OSError as err:
        _remove_if_empty(parts)
        raise SweepError(f"cannot write to {out.parent}: {err.strerror}; choose another output path") from None
    for stale in parts.glob(".*.part"):  # no worker runs while this sweep holds the lock: a killed one left it
        log.warning("removed %s, an unfinished part left by a killed worker", stale)
        stale.unlink()


class CtrlC:
    """While a sweep runs, every Ctrl-C stops it once, wherever in this process it lands.

    Python raises a SIGINT as KeyboardInterrupt in whatever the main thread runs at that moment.
    If that is a weakref callback or a ``__del__`` (joblib and loky free locks and queues through
    such callbacks while the workers' results are collected), the exception cannot propagate:
    Python prints "Exception ignored in ... KeyboardInterrupt" and goes on as if no key had been
    pressed. A SIGTERM is raised as :class:`Terminated`, a KeyboardInterrupt, and stops the sweep
    the same way. Within this block such an interrupt is not printed but sent again as SIGINT 0.1 s
    later, once the callback is over, so it reaches the sweep. And once the sweep stops (a
    KeyboardInterrupt is being handled, or :attr:`stopping` is set), a further SIGINT (a second
    Ctrl-C, or one sent again after the workers' own interrupts already stopped the sweep) is not
    raised inside the clean-up. Only in the main thread; SIGINT only when it raises
    KeyboardInterrupt (not under ``nohup`` or in a background job), SIGTERM always.
    """

    RESEND_AFTER = 0.1  # s: a callback is over long before; a person does not notice

    def __enter__(self) -> Self:
        self.stopping = False
        self._resends: list[threading.Timer] = []
        self._previous_handler = signal.getsignal(signal.SIGINT)
        self._main = threading.current_thread() is threading.main_thread()
        # SIGTERM is handled in any case (a sweep started in the background, where SIGINT is
        # ignored, died on it silently); SIGINT only where it raises KeyboardInterrupt
        self._active = self._main and self._previous_handler is signal.default_int_handler
        if self._main:
            self._previous_hook = sys.unraisablehook
            sys.unraisablehook = self._unraisable
            self._previous_term = signal.signal(signal.SIGTERM, self._on_sigterm)
        if self._active:
            signal.signal(signal.SIGINT, self._on_sigint)
        return self

    def __exit__(self, *exc) -> None:
        if not self._main:
            return
        for resend in self._resends:
            resend.cancel()
        if self._active:
            signal.signal(signal.SIGINT, self._previous_handler)  # a pending SIGINT is handled before, by ours
        signal.signal(signal.SIGTERM, self._previous_term)
        sys.unraisablehook = self._previous_hook

    def _on_sigint(self, signum, frame) -> None:
        if self.stopping or isinstance(sys.exc_info()[1], KeyboardInterrupt):
            return
        raise KeyboardInterrupt

    def _on_sigterm(self, signum, frame) -> None:
        if self.stopping or isinstance(sys.exc_info()[1], KeyboardInterrupt):
            return
        raise Terminated

    def _unraisable(self, unraisable) -> None:
        if not isinstance(unraisable.exc_value, KeyboardInterrupt):
            self._previous_hook(unraisable)
        elif not self.stopping:
            again = signal.SIGTERM if isinstance(unraisable.exc_value, Terminated) else signal.SIGINT
            resend = threading.Timer(self.RESEND_AFTER, os.kill, (os.getpid(), again))
            resend.daemon = True
            resend.start()
            self._resends.append(resend)


def _execute(todo: list[tuple[str, Run]], parts: Path, jobs: int, scheduler: str | None, command: str,
             shared: bool = False, bar=None) -> Iterator[RunStats]:
    """Run the missing runs (each on its own stepper) on ``jobs`` local processes, or on the Dask
    cluster of ``scheduler``; yield the stats of each as it finishes, in completion order."""
    if not todo:
        return
    # absolute: a worker process keeps the folder it started in, which need not be this one's now
    calls = [(run_id, run, parts.absolute() / f"{run_id}.h5", command) for run_id, run in todo]
    try:
        if scheduler:
            yield from cluster.execute(todo, parts, scheduler, command, shared=shared, bar=bar)
        else:
            from joblib import Parallel, delayed
            from joblib._parallel_backends import LokyBackend

            # loky starts its workers (`python -m`) and resource trackers (`python -c`) in this folder:
            # without PYTHONSAFEPATH a joblib.py here ran in each of them (faultgen.children)
            with children.safe_path():
                worker.start_resource_tracker()
                # every worker watches the sweep from its start, idle or not
                # (:func:`faultgen.pools.watch_parent`)
                loky = LokyBackend(initializer=pools.start_worker, initargs=(os.getpid(),))
                parallel = Parallel(n_jobs=jobs, return_as="generator_unordered", backend=loky)
                yield from parallel(delayed(worker.in_worker)(os.getpid(), *call) for call in calls)
    except KeyboardInterrupt:
        if not scheduler:
            _stop_local_workers()
        raise
    except RuntimeError as err:
        # an interrupt while loky was starting its manager thread: joblib's abort could not join it
        # ("cannot join thread before it is started") and raised that instead, the interrupt as its context
        if scheduler or not isinstance(err.__context__, KeyboardInterrupt):
            raise
        _stop_local_workers()
        raise err.__context__ from None
    except OSError as err:
        raise SweepError(f"a run could not be written: {err}. Finished runs are kept in {parts}; free space "
                         "or fix permissions and run the same command again") from err


def _stop_local_workers() -> None:
    """Stop joblib's worker processes and wait until nothing of loky's runs in this process any more,
    so that every semaphore loky made is released here, before the exit: none is left for its
    resource tracker to report as leaked under the sweep's message.

    - The executor joblib ran (loky's reusable one), never a new one: ``get_reusable_executor()``
      replaced the executor joblib's own abort had shut down with a new one, six semaphores more. The
      abort fails if the interrupt came while loky was starting its manager thread ("cannot join
      thread before it is started", :func:`_execute`): that thread starts within moments.
    - The feeder thread of its call queue: a daemon thread, which loky does not join in the process
      that made the queue. It holds the queue's three semaphores and releases them when it ends, each
      release a message to the resource tracker; a release still under way when the interpreter
      finalizes is cut off (a daemon thread does not run again), and the tracker reported "1 leaked
      semlock objects" (CI, under load).
    - A garbage collection: a semaphore in a reference cycle is released by whichever thread collects
      it, possibly one of those.
    """
    import gc

    from joblib.externals.loky import reusable_executor

    executor = reusable_executor._executor  # the one joblib ran, or None
    if executor is not None:
        stop = getattr(executor, "terminate", executor.shutdown)  # joblib's also removes its temporary folders
        for _ in range(200):
            try:
                stop(kill_workers=True)
                break
            except RuntimeError:  # "cannot join thread before it is started" (seen under load)
                time.sleep(0.05)
        else:
            for process in list((getattr(executor, "_processes", None) or {}).values()):  # it never started
                try:
                    os.kill(process.pid, signal.SIGKILL)  # loky's process has no kill(); SIGTERM is ignored
                except ProcessLookupError:
                    pass
                process.join()
            executor.shutdown(wait=False, kill_workers=True)
    deadline = time.monotonic() + 5  # a closed queue's feeder ends within moments; never hang the exit on one
    for thread in threading.enumerate():
        if thread.daemon and thread.name == "QueueFeederThread":
            thread.join(max(0.0, deadline - time.monotonic()))
    gc.collect()
