"""Run the steps of a reproduction: each a ``faultgen`` command in its own process (or a small call
in this one), at most ``jobs`` at a time, each as soon as the steps it needs are done, the
costliest first. A step whose outputs exist is kept (a killed reproduction resumes) when its record
(``DIR/.steps/NAME.json``: its command, outputs, settings such as the scale, and the records of the
steps it needs) says it made them with the same settings and none of the steps it needs ran again;
else it runs again, replacing them. A file of a step's output name that no record claims (a file
the user made) is refused before anything runs. Each step's output goes to ``DIR/logs/NAME.log``
and its time to ``DIR/times.csv``.
"""

from __future__ import annotations

import hashlib
import json
import signal
import subprocess
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path

from faultgen import children, inputs


@dataclass(frozen=True)
class Step:
    """One piece of work of a reproduction.

    Attributes
    ----------
    name : str
        Unique, e.g. ``"sweep j2"``; its log is ``logs/<name with '-' for spaces>.log``.
    args : tuple of str
        The ``faultgen`` command line (without ``faultgen``), run in the output folder; empty when
        ``call`` does the work.
    outputs : tuple of str
        Files it writes, relative to the output folder; all present means done.
    needs : tuple of str
        Names of the steps that must finish first.
    cost : float
        Expected CPU minutes on one core (ordering only: the costliest ready step starts first).
    call : callable or None
        ``call(folder)`` does the work in this process instead of a command.
    makes_data : bool
        True for a step that simulates (a sweep or fleet), False for an analysis.
    settings : str
        What else decides its outputs (the scale of the plan: ``tiny`` or ``full``), recorded with
        them; outputs recorded with other settings are made again.
    """

    name: str
    args: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()
    needs: tuple[str, ...] = ()
    cost: float = 0.1
    call: Callable[[Path], None] | None = field(default=None, compare=False)
    makes_data: bool = False
    settings: str = ""

    @property
    def log_name(self) -> str:
        return self.name.replace(" ", "-").replace("/", "-") + ".log"

    @property
    def record_name(self) -> str:
        """Its record's file in ``DIR/.steps`` (:func:`records`)."""
        return self.log_name.removesuffix(".log") + ".json"

    def command(self) -> str:
        """The step as a user would type it (for the logs and the tables' captions)."""
        if self.call is not None:
            return f"(faultgen.reproduce: {self.name})"
        return "faultgen " + " ".join(a if " " not in a else repr(a) for a in self.args)


#: Steps done in this process run one at a time: h5py serialises its calls anyway, and a file
#: written through a Python file object (faultgen.data.atomic) calls back into Python from inside
#: HDF5, which another thread's h5py call must not interleave with.
_IN_PROCESS = threading.Lock()
#: The commands running now, stopped (SIGTERM) when the reproduction is stopped.
_CHILDREN: set[subprocess.Popen] = set()


class StepFailed(RuntimeError):
    """A step's command failed; the message names it, its exit code and its log."""

    exit_code = 1


@dataclass
class Outcome:
    """What happened to a step: ``status`` is ``ran``, ``kept`` (outputs there) or ``failed``."""

    step: Step
    status: str
    seconds: float


def check_plan(steps: Sequence[Step]) -> None:
    """Refuse a plan with a duplicate name or a need that names no earlier step (ValueError)."""
    seen: set[str] = set()
    for step in steps:
        if step.name in seen:
            raise ValueError(f"reproduction plan: step {step.name!r} twice")
        missing = [n for n in step.needs if n not in seen]
        if missing:
            raise ValueError(f"reproduction plan: step {step.name!r} needs {missing[0]!r}, which is not before it")
        seen.add(step.name)


#: The folder of the steps' records, in the reproduction's folder.
RECORDS = ".steps"
#: Size bound of one step's record (its command, outputs and settings: a few kB), bytes.
RECORD_MAX_BYTES = 2**20


def records(steps: Sequence[Step]) -> dict[str, dict]:
    """Each step's record: what made its outputs (its name, command, outputs and settings) and the
    digests of the records of the steps it needs, so that a step whose need changed differs too."""
    made: dict[str, dict] = {}
    for step in steps:
        made[step.name] = {"step": step.name, "command": step.command(), "args": list(step.args),
                           "outputs": list(step.outputs), "settings": step.settings,
                           "needs": {n: _digest(made[n]) for n in step.needs}}
    return made


def _digest(record: dict) -> str:
    return hashlib.sha256(json.dumps(record, sort_keys=True).encode()).hexdigest()


def _read_record(step: Step, folder: Path) -> dict | None:
    """The record of ``step`` in ``folder``: ``{"record": ..., "state": "running"|"done"}``, or None
    when there is none or it cannot be read: read through :func:`faultgen.inputs.read_text` (a
    regular file of at most :data:`RECORD_MAX_BYTES`, its size checked first: a sparse record
    planted in the folder was read whole)."""
    path = folder / RECORDS / step.record_name
    try:
        found = json.loads(inputs.read_text(path, "step record", RECORD_MAX_BYTES))
    except (OSError, ValueError, RecursionError):  # InputError is a ValueError
        return None
    return found if isinstance(found, dict) else None


def _write_record(step: Step, folder: Path, record: dict, state: str) -> None:
    from faultgen.data import atomic

    atomic.write_text(folder / RECORDS / step.record_name, json.dumps({"record": record, "state": state}, indent=1))


def check_outputs(steps: Sequence[Step], folder: Path) -> None:
    """Refuse, before anything runs, a file of a step's output name in ``folder`` that no record of
    that step claims (a file the user made, or one an earlier faultgen made without records):
    running the step would replace it.

    Raises
    ------
    ValueError
        Naming the file and the step.
    """
    for step in steps:
        there = [o for o in step.outputs if (folder / o).exists() or (folder / o).is_symlink()]
        if there and _read_record(step, folder) is None:
            raise ValueError(f"{folder / there[0]} is there, and no record in {folder / RECORDS} says a reproduction made "
                             f"it (step {step.name!r} writes it): move it away to let the step make it, or choose "
                             "another folder")


def execute(steps: Sequence[Step], folder: Path, jobs: int = 2,
            report: Callable[[Outcome, int, int], None] | None = None) -> list[Outcome]:
    """Run ``steps`` in ``folder``; return their outcomes in the order they ended.

    ``report(outcome, done, total)`` is called as each step ends (the progress display). Raises
    :class:`StepFailed` after the running steps end if any step failed; steps that need a failed
    one are not started. Raises ValueError before anything runs for an output no record claims
    (:func:`check_outputs`).
    """
    check_plan(steps)
    check_outputs(steps, folder)
    (folder / "logs").mkdir(parents=True, exist_ok=True)
    (folder / RECORDS).mkdir(exist_ok=True)
    pending = list(steps)
    done: dict[str, Outcome] = {}
    running: dict[Future, Step] = {}
    failed: list[Outcome] = []
    made = records(steps)
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        try:
            _schedule(pool, steps, folder, jobs, report, pending, done, running, failed, made)
        except BaseException:  # Ctrl-C or SIGTERM: each command gets a SIGTERM, which a sweep takes as a
            # Ctrl-C (it keeps its finished runs); not SIGINT, which a process started in the background
            # by a shell ignores
            for child in list(_CHILDREN):
                child.send_signal(signal.SIGTERM)
            raise
    if failed:
        first = failed[0].step
        raise StepFailed(f"step {first.name!r} failed ({first.command()}); see {folder / 'logs' / first.log_name}; "
                         "run the same reproduce command again to resume (finished steps are kept)")
    return list(done.values())


def _schedule(pool, steps, folder, jobs, report, pending, done, running, failed, made) -> None:
    """Start ready steps as slots free up, until none is pending or running (:func:`execute`)."""
    while pending or running:
        ready = [s for s in pending if all(n in done and done[n].status != "failed" for n in s.needs)]
        blocked = [s for s in pending if any(n in done and done[n].status == "failed" for n in s.needs)]
        for step in blocked:
            pending.remove(step)
        kept = [s for s in ready if _kept(s, folder, made, done)]
        for step in kept:  # outputs there: no slot, reported at once
            pending.remove(step)
            done[step.name] = Outcome(step, "kept", 0.0)
            if report is not None:
                report(done[step.name], len(done), len(steps))
        if kept:
            continue  # a kept step may have made others ready, to keep or to run
        # analyses first (short, and their tables appear early), then the costliest dataset
        for step in sorted(ready, key=lambda s: (s.makes_data, -s.cost))[: max(0, jobs - len(running))]:
            pending.remove(step)
            running[pool.submit(_run_step, step, folder, made[step.name])] = step
        if not running:
            break
        finished, _ = wait(list(running), return_when=FIRST_COMPLETED)
        for future in finished:
            step = running.pop(future)
            outcome = future.result()
            done[step.name] = outcome
            if outcome.status == "failed":
                failed.append(outcome)
            if report is not None:
                report(outcome, len(done), len(steps))


def _kept(step: Step, folder: Path, made: dict[str, dict], done: dict[str, Outcome]) -> bool:
    """Whether ``step``'s outputs are there (each is written atomically: there means whole), its
    record says it finished them with the settings of this plan (:func:`records`), and every step
    it needs was kept too (one that ran again may have made other data)."""
    if not step.outputs or not all((folder / o).exists() for o in step.outputs):
        return False
    if any(n not in done or done[n].status != "kept" for n in step.needs):
        return False
    found = _read_record(step, folder)
    return found is not None and found.get("state") == "done" and found.get("record") == made[step.name]


def _run_step(step: Step, folder: Path, record: dict) -> Outcome:
    started = time.perf_counter()
    log = folder / "logs" / step.log_name
    # outputs there (made by an earlier step of other settings, or one killed): replaced, and the
    # record says so first, so that a kill meanwhile leaves them to be made again
    replace = any((folder / o).exists() for o in step.outputs)
    _write_record(step, folder, record, "running")
    if step.call is not None:
        try:
            with _IN_PROCESS:
                step.call(folder)
        except Exception as err:  # noqa: BLE001 - reported with the step's name, the run goes on
            log.write_text(f"{type(err).__name__}: {err}\n")
            return Outcome(step, "failed", time.perf_counter() - started)
        return _ended(step, folder, record, "ran", started)
    args = (*step.args, "--overwrite") if replace else step.args
    with log.open("w") as sink:
        sink.write(step.command() + (" --overwrite" if replace else "") + "\n")
        sink.flush()
        # -P and PYTHONSAFEPATH: `python -m` puts its current folder, the output folder here, first on
        # the path, and an h5py.py or typer.py there would be imported (faultgen.children)
        child = subprocess.Popen(children.command("-m", "faultgen.cli", *args), cwd=folder,
                                 env=children.environment(), stdout=sink, stderr=subprocess.STDOUT)
        _CHILDREN.add(child)
        try:
            code = child.wait()
        finally:
            _CHILDREN.discard(child)
    missing = [o for o in step.outputs if not (folder / o).exists()]
    return _ended(step, folder, record, "failed" if code != 0 or missing else "ran", started)


def _ended(step: Step, folder: Path, record: dict, status: str, started: float) -> Outcome:
    """The outcome of a step that ended; a step that ran records its outputs as done."""
    if status == "ran":
        _write_record(step, folder, record, "done")
    return Outcome(step, status, time.perf_counter() - started)
