"""What a local worker process of a sweep does: simulate one run and write its part file
(:func:`simulate_and_write`), and stay tied to the sweep that started it: it ends within a second
of the sweep's process (:func:`faultgen.pools.watch_parent`), leaves a group-wide SIGTERM and Ctrl-C
to the sweep, and gives its freed memory back to the OS after each run."""

from __future__ import annotations

import contextlib
import ctypes
import gc
import os
import signal
import sys
import threading
import time
from dataclasses import dataclass, replace
from pathlib import Path

from tqdm.auto import tqdm

from faultgen import collection
from faultgen.data import dataset
from faultgen.simulation import stepping as sim
from faultgen.simulation.resolve import Run


@dataclass(frozen=True)
class RunStats:
    """What one worker did: simulated seconds and the wall time of each phase, s; on a Dask
    cluster also where (``worker``, its address) and the worker process's peak resident set so far
    (``memory``, bytes; 0 for local workers). A run sent back through Dask is written by the client:
    ``writing`` is then the client's time."""

    run_id: str
    simulated: float
    total: float
    stepping: float
    writing: float
    worker: str = ""
    memory: int = 0


def simulate_and_write(run_id: str, run: Run, part: Path, command: str = "",
                       labelled: sim.RunConfig | None = None) -> RunStats:
    """Worker task: simulate one resolved run (:class:`faultgen.simulation.resolve.Run`: its
    configuration on its stepper) and write it to its part file (atomically), labelled with
    ``labelled`` (the client's configuration when the run names its robot or program by an absolute
    path for a cluster's workers: :func:`faultgen.runs.cluster.for_workers`). The run arrives
    pickled without its compiled robot (:meth:`RunConfig.__getstate__`): resolved here once."""
    # A worker draws no progress bar: a thread lock for tqdm, not its default process-shared one (a
    # named semaphore, reported as leaked at exit when a Ctrl-C makes the sweep stop its workers).
    tqdm.set_lock(threading.RLock())
    with run_memory():
        started = time.perf_counter()
        result = run.simulate(progress=False)
        writing = time.perf_counter()
        if labelled is not None:
            result = replace(result, config=labelled)
        dataset.write_run(part, result, run_id=run_id, command=command)
        done = time.perf_counter()
        stats = RunStats(run_id, result.tau_m.shape[0] * result.t[-1], done - started, result.stepping_time,
                         done - writing)
        del result
    return stats


def in_worker(sweep_pid: int, *call) -> RunStats:
    """:func:`simulate_and_write` as a joblib worker runs it for the sweep of process ``sweep_pid``.

    A Ctrl-C reaches the workers too (they are in the terminal's process group). One that lands
    in a weakref callback or a ``__del__`` of a worker cannot be raised there, and Python would
    print "Exception ignored ... KeyboardInterrupt" in the middle of the sweep's message; a worker
    does not print it: the sweep's own process handles the Ctrl-C and stops the workers
    (:class:`faultgen.runs.sweep.CtrlC`). In the sweep's own process (joblib with one job) nothing changes.
    """
    if os.getpid() != sweep_pid:
        quiet_unraisable_interrupts()
    return simulate_and_write(*call)


def start_resource_tracker() -> None:
    """Start loky's resource tracker (a process of its own, started once) ignoring SIGTERM, as the
    workers do (:func:`faultgen.pools.start_worker`): a group-wide SIGTERM must not end it before the
    sweep has stopped its workers and released their semaphores (it then reports them as leaked). It
    ends when the sweep's process does."""
    from joblib.externals.loky.backend import resource_tracker

    if threading.current_thread() is not threading.main_thread():
        return
    previous = signal.signal(signal.SIGTERM, signal.SIG_IGN)  # inherited by the process started now
    try:
        resource_tracker.ensure_running()
    finally:
        signal.signal(signal.SIGTERM, previous)


def quiet_unraisable_interrupts() -> None:
    """From now on, a KeyboardInterrupt that cannot be raised is not printed (this process only;
    every other unraisable exception still goes to the hook there was before)."""
    previous = sys.unraisablehook
    if getattr(previous, "quiet_interrupts", False):  # a worker runs many runs: set once
        return

    def hook(unraisable) -> None:
        if not isinstance(unraisable.exc_value, KeyboardInterrupt):
            previous(unraisable)

    hook.quiet_interrupts = True
    sys.unraisablehook = hook


@contextlib.contextmanager
def run_memory():
    """Around one run: the run's freed memory given back to the OS at its end (:func:`release_memory`),
    its collection looking at the objects made during the run only (:func:`faultgen.collection.young_only`:
    what was alive when the run started, modules and prepared models, is left out of it)."""
    with collection.young_only():
        try:
            yield
        finally:
            release_memory()


def release_memory() -> None:
    """Give the run's freed memory back to the OS. glibc keeps freed heap memory, so a worker's
    resident size would ratchet up run after run, and joblib's workers restart themselves (losing
    their prepared models) once it grows 300 MB past its size after the first run."""
    gc.collect()
    try:
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):  # not glibc: nothing to trim
        pass
