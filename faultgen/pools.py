"""Local worker processes tied to the process that started them (a sweep, ``faultgen monitor
--jobs``, ``classify``): each ends within a second of its parent (:func:`watch_parent`) and leaves a
group-wide SIGTERM and Ctrl-C to it (:func:`start_worker`); on Linux a pool of them forked from this
process (:func:`forked_pool`), which start with its imports and state instead of importing them again
(a fresh interpreter's scikit-learn, SciPy and pandas, or MuJoCo and matplotlib: 2-3 s a worker on an
idle core, about 13 s at a load average of 8), stopped at once by an interrupt (:func:`stop`)."""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager

#: Whether worker pools are forked from this process (Linux; elsewhere fork is missing or unsafe, and
#: the callers start fresh interpreters with joblib's loky).
FORK = sys.platform.startswith("linux")


@contextmanager
def forked_pool(n_jobs: int) -> Iterator[ProcessPoolExecutor]:
    """A pool of ``n_jobs`` worker processes forked from this one (the standard library's
    ``ProcessPoolExecutor`` with the fork context; Linux only, :data:`FORK`), each started by
    :func:`start_worker`: they inherit this process's imports and state, so what is set here before
    the first task is submitted is theirs too. Shut down when the block ends; stopped at once
    (:func:`stop`) when it ends by an exception, a Ctrl-C or a closed generator."""
    pool = ProcessPoolExecutor(n_jobs, mp_context=multiprocessing.get_context("fork"),
                               initializer=start_worker, initargs=(os.getpid(),))
    try:
        yield pool
    except BaseException:  # Ctrl-C, SIGTERM, a failure, or the caller closing its generator
        stop(pool)
        raise
    pool.shutdown()


def stop(pool: ProcessPoolExecutor) -> None:
    """Stop a forked pool at once: its queued tasks cancelled and its workers (this process's
    ``multiprocessing`` children) killed, not waited for: a task being run would otherwise hold a
    Ctrl-C for as long as it takes. Nothing they made is kept."""
    pool.shutdown(wait=False, cancel_futures=True)
    for child in multiprocessing.active_children():
        child.kill()  # reaped by the pool's own thread


def start_worker(parent_pid: int) -> None:
    """A worker's initializer (loky's or :func:`forked_pool`'s): watch the parent process from the
    worker's start (:func:`watch_parent`); a worker whose parent ended while it started (it has another
    parent already) ends at once. A SIGTERM sent to the whole process group (``timeout``, a process
    manager, a closed terminal) is the parent's to handle: a sweep stops its workers and says what is
    kept and how to resume; a worker that ended on it first left loky's semaphores for Python to report
    as leaked, and the sweep no word. The Ctrl-C of a terminal (SIGINT to the group) likewise: raised in
    a worker it printed a traceback into the sweep's message wherever it landed (in h5py's write of a
    part, "Process LokyProcess-2:" while the worker waited for its next run; tests/test_sweep.py failed
    on 2 of 6 tries without this), so a worker ignores it and the parent stops its workers."""
    if os.getpid() == parent_pid:
        return
    if os.getppid() != parent_pid:
        os._exit(1)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    watch_parent(parent_pid)


_WATCHED: set[int] = set()


def watch_parent(parent_pid: int, period: float = 0.5) -> None:
    """End this worker process within ``period`` s once its parent ``parent_pid`` is gone.

    A killed sweep or monitor (SIGKILL, or SIGTERM under a process manager) cannot stop its workers,
    and they would go on with the rest of the work, then idle for minutes. The kernel is asked to send
    this process SIGKILL when its parent ends (``PR_SET_PDEATHSIG``, Linux), and a daemon thread checks
    every ``period`` s that the parent is still ``parent_pid`` (another OS); either way the worker ends
    at once (a sweep's unfinished part left as a hidden temporary file that the next sweep removes).
    Set once per worker process, from its start (:func:`start_worker`); a process whose parent is not
    ``parent_pid`` is left alone.
    """
    if parent_pid in _WATCHED or os.getppid() != parent_pid:  # not a worker it started: nothing to watch
        return
    _WATCHED.add(parent_pid)
    try:
        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # not Linux: the thread below does it
        pass
    if os.getppid() != parent_pid:  # the parent ended before the request was made
        os._exit(1)

    def watch() -> None:
        while True:
            time.sleep(period)
            try:
                os.kill(parent_pid, 0)
            except ProcessLookupError:
                os._exit(1)
            except PermissionError:
                pass
            if os.getppid() != parent_pid:  # orphaned (reparented to init or a subreaper): the parent is gone
                os._exit(1)

    threading.Thread(target=watch, name="faultgen-watch-parent", daemon=True).start()
