"""Sweeps and fleets on a Dask cluster whose workers share no file system with this process.

A worker simulates a run (a grid point of a sweep, a robot of a fleet) and hands its result back
through Dask: the arrays and labels of :class:`faultgen.simulation.stepping.RunResult`, with the
signals already as the dataset stores them (float32) or left out when the run keeps none. This
process, the Dask client, writes each result to the run's part file as it arrives, atomically,
and :func:`faultgen.runs.sweep.run` merges the parts as it does for local workers. So:

- a run is kept once the client has written it. A client that is killed loses only the runs
  its workers were simulating; the same command run again resumes from the part files;
- a worker that is lost mid-run (killed, its machine gone) loses only that run: the scheduler
  gives it to another worker (Dask's own rescheduling; a run that has lost
  ``distributed.scheduler.allowed-failures`` workers, 3 by default, fails with ``KilledWorker``);
- a run that raises (a simulation that diverged) is not retried, as the simulation is
  deterministic; the other runs go on and are kept, and the sweep then fails naming it.

A task is a run id and its resolved run (:class:`~faultgen.simulation.resolve.Run`: the
:class:`RunConfig` and the stepper it is stepped on). A robot or program given as a relative path (a
robot folder ``kr6``, a program ``mine.toml``) is sent as this process's absolute path
(:func:`for_workers`): a worker runs in a folder of its own, so it must see that path (the same
machine, or the folder at the same path on every worker); the part files are labelled with the
configuration as given. A worker that cannot find it fails the run naming the worker and the
path. The workers need the same faultgen (and robot models) installed; a worker whose robot model
differs from this process's (its SHA-256) is refused, as its run would be labelled with the wrong
model.

With ``shared=True`` the workers instead write their part files themselves into the part
folder, which every worker must see at the same absolute path (a shared file system, checked
before any run is sent): the client then only merges. docs/performance.md says when that is
faster.
"""

from __future__ import annotations

import hashlib
import re
import resource
import time
from collections.abc import Iterator
from concurrent.futures import CancelledError
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from faultgen import __version__
from faultgen.data import dataset
from faultgen.model import robots
from faultgen.operation import programs
from faultgen.runs.errors import SweepError, SweepRefused
from faultgen.runs.worker import RunStats, run_memory, simulate_and_write
from faultgen.simulation import backends, spec
from faultgen.simulation import stepping as sim
from faultgen.simulation.resolve import Run

#: The run arrays of shape (cycle, sample, axis): the 250 Hz signals.
SIGNALS = tuple(name for name, (_, axes, _) in dataset.ARRAYS.items() if axes == dataset.SIGNAL_AXES)


@dataclass(frozen=True)
class Outcome:
    """What a worker hands back for one run.

    Attributes
    ----------
    result : RunResult
        The run, as :func:`for_transfer` slims it.
    worker : str
        Address of the worker that simulated it (``tcp://host:port``).
    model_sha256 : str
        SHA-256 of the robot's MJCF file on that worker.
    faultgen_version : str
    simulated, total, stepping : float
        Simulated seconds of the run; the worker's wall time for it and of its stepping, s.
    memory : int
        Peak resident set of the worker process so far, bytes.
    """

    result: sim.RunResult
    worker: str
    model_sha256: str
    faultgen_version: str
    simulated: float
    total: float
    stepping: float
    memory: int


def for_transfer(result: sim.RunResult) -> sim.RunResult:
    """``result`` with no more than its part file stores: the signals as float32 (the dataset's
    type for them, so the file is bit for bit the same), or empty (``(n_cycles, 0, n_axes)``) when
    the run keeps no signals. A run with signals then crosses the network at half the size."""
    if result.config.signals:
        return replace(result, **{name: np.asarray(getattr(result, name), dtype=np.float32) for name in SIGNALS})
    return replace(result, **{name: np.asarray(getattr(result, name))[:, :0] for name in SIGNALS})


def for_workers(config: sim.RunConfig) -> sim.RunConfig:
    """``config`` with its robot and task, where they are paths on this machine (a robot folder or
    MJCF file that is not a known robot name, a program or log file), made absolute: a worker's
    folder is not this process's."""
    changes = {}
    if str(config.robot) not in robots.available() and Path(config.robot).exists():
        changes["robot"] = str(Path(config.robot).absolute())
    if programs.kind(config.task) in programs.FILE_KINDS and Path(config.task).is_file():
        changes["task"] = spec.absolute_task(config.task)
    return replace(config, **changes) if changes else config


def _missing_on_worker(config: sim.RunConfig) -> str:
    """The path of ``config`` this worker does not have ('' if it has them)."""
    for path in (config.robot, config.task):
        if Path(path).is_absolute() and not Path(path).exists():
            return path
    return ""


def simulate_remote(run_id: str, run: Run) -> Outcome:
    """Worker task: simulate one resolved run on its stepper (whose class must be importable on the
    worker) and return it (:class:`Outcome`); writes nothing."""
    from distributed import get_worker

    config = run.config
    missing = _missing_on_worker(config)
    if missing:
        raise FileNotFoundError(f"worker {get_worker().address} has no {missing} (the robot or program path as the "
                                "client sees it): put it at the same path on every worker, or run the sweep there")
    with run_memory():
        started = time.perf_counter()
        result = run.simulate(progress=False)
        total = time.perf_counter() - started
        slim = for_transfer(result)
        simulated = result.tau_m.shape[0] * result.t[-1]
        del result
    return Outcome(slim, get_worker().address, dataset.model_hash(config.model.path), __version__,
                   simulated, total, slim.stepping_time, _peak_memory())


def write_shared(run_id: str, run: Run, part: str, command: str, labelled: sim.RunConfig | None = None) -> RunStats:
    """Worker task with a shared file system: simulate one resolved run on its stepper and write its
    part file there, labelled with ``labelled`` (the client's configuration)."""
    from distributed import get_worker

    missing = _missing_on_worker(run.config)
    if missing:
        raise FileNotFoundError(f"worker {get_worker().address} has no {missing} (the robot or program path as the "
                                "client sees it): put it at the same path on every worker")
    stats = simulate_and_write(run_id, run, Path(part), command, labelled=labelled)
    return replace(stats, worker=get_worker().address, memory=_peak_memory())


def _peak_memory() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # kB on Linux


def task_key(run_id: str, run: Run) -> str:
    """The Dask key of a resolved run: its id and a digest of its configuration (and of its stepper
    when not the default: :func:`faultgen.simulation.backends.key_text`), so that the dashboard names
    the run, and two sweeps on one cluster share a task only when it is the same simulation on the
    same stepper."""
    extra = backends.key_text(run.stepper)
    text = dataset.config_key(run.config) + (f"\n{extra}" if extra else "")
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    return f"faultgen-{run_id}-{digest}"


#: The protocols ``--scheduler`` takes: plain TCP, and TLS (Dask's ``distributed.comm.tls``
#: certificates from its configuration). Dask's others (inproc, ucx, ws) are not for a sweep.
PROTOCOLS = ("tcp", "tls")
_ADDRESS = re.compile(r"(?P<protocol>[a-z]+)://(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9][A-Za-z0-9._-]*):(?P<port>[0-9]{1,5})")
#: Seconds to wait for a scheduler to accept the connection and send its greeting.
PROBE_TIMEOUT = 5.0
#: The largest greeting a Dask scheduler sends (its handshake is under 100 bytes): a peer that
#: announces more is not one (a web server's first bytes read as a length ask for exabytes).
MAX_GREETING = 65536


def check_address(address: str) -> tuple[str, str, int]:
    """(protocol, host, port) of a scheduler's address ``tcp://HOST:PORT`` or ``tls://HOST:PORT``.

    Raises
    ------
    ValueError
        Saying what is wrong and the form expected (the caller names the address).
    """
    match = _ADDRESS.fullmatch(address.strip())
    expected = "expected tcp://HOST:PORT or tls://HOST:PORT, e.g. tcp://10.0.0.5:8786"
    if match is None:
        raise ValueError(f"not a Dask scheduler's address; {expected}")
    if match["protocol"] not in PROTOCOLS:
        raise ValueError(f"protocol {match['protocol']!r} is not taken; {expected}")
    port = int(match["port"])
    if not 1 <= port <= 65535:
        raise ValueError(f"port {port} is out of range 1..65535")
    return match["protocol"], match["host"].strip("[]"), port


def probe(address: str, timeout: float | None = None) -> None:
    """Check, in at most about ``2 * timeout`` seconds (default :data:`PROBE_TIMEOUT`) and before
    any Dask client is made, that a Dask scheduler answers at ``address``: its greeting, a Dask
    handshake message, is read (over TLS with Dask's configured certificates for ``tls://``) and
    checked, its announced length first, so that another server's bytes are never taken for the
    length of a message to allocate (a web server's: 3 EiB).

    Raises
    ------
    SweepRefused
        If the address is malformed (:func:`check_address`), ``tls://`` without Dask's TLS
        configuration, nothing listens there, nothing answers within ``timeout`` (or the TLS
        handshake fails), or what answers is not a Dask scheduler; one line naming the address.
    """
    import socket
    import struct

    timeout = PROBE_TIMEOUT if timeout is None else timeout
    try:
        protocol, host, port = check_address(address)
    except ValueError as err:
        raise SweepRefused(f"scheduler {address!r}: {err}") from None
    context = None
    if protocol == "tls":
        from distributed.security import Security

        context = Security().get_connection_args("client").get("ssl_context")
        if context is None:
            raise SweepRefused(f"scheduler {address!r}: tls:// needs Dask's TLS configuration (distributed.comm.tls: "
                               "ca-file, and the client's cert and key); none is set")
    fail = f"no Dask scheduler answers at {address}"
    try:
        with socket.create_connection((host, port), timeout=timeout) as plain:
            conn = plain if context is None else context.wrap_socket(plain, server_hostname=host)
            conn.settimeout(timeout)
            size = struct.unpack("<Q", _read(conn, 8))[0]
            if size > MAX_GREETING:
                raise SweepRefused(f"{fail}: what answers there is not a Dask scheduler (it sent no Dask handshake)")
            greeting = _read(conn, size)
    except OSError as err:  # refused, unreachable, timed out, closed early, a failed TLS handshake
        raise SweepRefused(f"{fail}: {' '.join(str(err.strerror or err).split())}") from None
    if not _is_handshake(greeting):
        raise SweepRefused(f"{fail}: what answers there is not a Dask scheduler (it sent no Dask handshake)")


def _read(conn, size: int) -> bytes:
    data = bytearray()
    while len(data) < size:
        chunk = conn.recv(size - len(data))
        if not chunk:
            raise OSError("the connection was closed")
        data += chunk
    return bytes(data)


def _is_handshake(message: bytes) -> bool:
    """Whether ``message`` is a Dask handshake: frames (a count, their lengths, the frames) whose
    first is a msgpack map naming the peer's pickle protocol (distributed.comm.core.Comm.handshake_info)."""
    import struct

    import msgpack

    try:
        count = struct.unpack_from("<Q", message)[0]
        if not 1 <= count <= 16:
            return False
        lengths = struct.unpack_from(f"<{count}Q", message, 8)
        start = 8 * (count + 1)
        info = msgpack.unpackb(message[start:start + lengths[0]])
    except (struct.error, ValueError, msgpack.UnpackException, TypeError):
        return False
    return isinstance(info, dict) and "pickle-protocol" in info


def execute(todo: list[tuple[str, Run]], parts: Path, scheduler: str, command: str = "",
            shared: bool = False, bar=None) -> Iterator[RunStats]:
    """Run ``todo`` on the Dask cluster of ``scheduler``; yield each run's :class:`RunStats` (with
    the worker's address) once its part file is written, in completion order.

    Parameters
    ----------
    todo : list of (run id, Run)
        The resolved runs (:class:`~faultgen.simulation.resolve.Run`: the configuration and the
        stepper the workers step it on, pickled: its class must be importable in their processes),
        in the order to submit them (longest first).
    parts : Path
        The sweep's part folder (this process's; ``shared``: the workers' too).
    scheduler : str
        ``tcp://host:port`` of a Dask scheduler.
    command : str
        Provenance stored with every run.
    shared : bool
        The workers write the part files themselves (they must see ``parts`` at its absolute path).
    bar : tqdm, optional
        A progress bar whose postfix shows the workers the scheduler has after each run.

    Raises
    ------
    SweepRefused
        If the address is malformed, or no Dask scheduler answers there (:func:`probe`; nothing ran).
    SweepError
        If the scheduler is lost, a worker runs another robot model, with
        ``shared`` if a worker cannot see ``parts``, or (after every other run finished) if runs
        failed: the message names the first and how many; every finished run is kept.
    OSError
        If a part file cannot be written (from :func:`faultgen.data.dataset.write_run`).
    """
    from distributed import Client, KilledWorker, as_completed

    probe(scheduler)
    try:
        client = Client(scheduler, timeout="10s", set_as_default=False)
    except Exception as err:  # TLS without certificates, a scheduler gone since the probe, ...
        raise SweepRefused(f"cannot reach the Dask scheduler at {scheduler}: {' '.join(str(err).split())}") from None
    folder = parts.resolve()
    with client:
        if shared:
            _check_shared(client, folder)
        run_of, futures = _submit(client, todo, folder, command, shared)
        configs = {run_id: run.config for run_id, run in todo}
        failed: list[str] = []
        finished = as_completed(futures, loop=client.loop)
        del futures  # as_completed holds each future until it is handed out: a written run's result is freed
        for future in finished:
            run_id = run_of[future.key]
            try:
                value = future.result()
            except KilledWorker as err:
                failed.append(f"{run_id} lost every worker that ran it ({err})")
                continue
            except CancelledError as err:
                raise SweepError(f"lost the Dask scheduler at {scheduler} ({err or 'cancelled'}); finished runs are "
                                 f"kept in {parts}: run the same command again") from None
            except Exception as err:  # the run's own error, raised on its worker
                failed.append(f"{run_id}: {type(err).__name__}: {err}")
                continue
            finally:
                future.release()
            if shared:
                yield value
            else:
                problem = _mismatch(value, configs[run_id])
                if problem:
                    failed.append(f"{run_id}: {problem}")
                    continue
                yield _write(run_id, replace(value, result=replace(value.result, config=configs[run_id])),
                             parts / f"{run_id}.h5", command)
            if bar is not None:
                bar.set_postfix_str(_cluster_state(client), refresh=False)
        if failed:
            raise SweepError(failure_message(failed, len(todo), parts))


def _submit(client, todo: list[tuple[str, Run]], folder: Path, command: str,
            shared: bool) -> tuple[dict[str, str], list]:
    """Submit every resolved run of ``todo`` (:class:`~faultgen.simulation.resolve.Run`, its stepper
    on it) to ``client``, in order: (task key -> run id, the futures). A run's worker simulates it
    and sends it back, or with ``shared`` writes its part file into ``folder``."""
    run_of = {}
    futures = []
    for run_id, run in todo:
        key = task_key(run_id, run)  # the client's configuration, as the dashboard shows it
        sent = replace(run, config=for_workers(run.config))
        run_of[key] = run_id
        if shared:
            futures.append(client.submit(write_shared, run_id, sent, str(folder / f"{run_id}.h5"), command,
                                         None if sent.config is run.config else run.config, key=key))
        else:
            futures.append(client.submit(simulate_remote, run_id, sent, key=key))
    return run_of, futures


def failure_message(failed: list[str], n_runs: int, parts: Path) -> str:
    """What a sweep whose ``failed`` runs (one line each) of ``n_runs`` failed on the cluster says."""
    if len(failed) == n_runs:
        kept = f"none of the {n_runs} runs finished"
    else:
        kept = f"the {n_runs - len(failed)} that finished are kept in {parts}"
    return f"{len(failed)} of {n_runs} runs failed on the cluster; {kept}. First: {failed[0]}"


def _write(run_id: str, outcome: Outcome, part: Path, command: str) -> RunStats:
    """Write a worker's run to its part file (atomically, :func:`faultgen.data.dataset.write_run`)."""
    started = time.perf_counter()
    dataset.write_run(part, outcome.result, run_id=run_id, command=command)
    return RunStats(run_id, outcome.simulated, outcome.total, outcome.stepping, time.perf_counter() - started,
                    worker=outcome.worker, memory=outcome.memory)


def _mismatch(outcome: Outcome, config: sim.RunConfig) -> str:
    """Why a worker's run cannot be labelled as this process would label it ('' if it can)."""
    ours = dataset.model_hash(config.model.path)
    if outcome.model_sha256 != ours:
        return (f"worker {outcome.worker} simulated another {config.robot} model (MJCF SHA-256 "
                f"{outcome.model_sha256[:12]}, here {ours[:12]}, faultgen {outcome.faultgen_version} there, "
                f"{__version__} here): install the same faultgen and robot models on every worker")
    return ""


def _check_shared(client, folder: Path) -> None:
    """Refuse ``shared`` unless every worker sees ``folder`` (at the same absolute path)."""
    seen = client.run(_sees, str(folder))
    blind = sorted(address for address, ok in seen.items() if not ok)
    if blind:
        raise SweepError(f"worker {blind[0]} cannot see {folder} ({len(blind)} of {len(seen)} workers): drop "
                         "--shared-folder to send the runs back through Dask, or mount the folder at the same path "
                         "on every worker")


def _sees(path: str) -> bool:
    return Path(path).is_dir()


def _cluster_state(client) -> str:
    """'2 workers, 2 threads' as the scheduler has them now."""
    workers = client.scheduler_info()["workers"].values()
    return f"{len(workers)} workers, {sum(w.get('nthreads', 0) for w in workers)} threads"
