"""Run the steps of a reproduction: each a ``faultgen`` command in its own process (or a small call
in this one), at most ``jobs`` at a time, each as soon as the steps it needs are done, the
costliest first. A step whose outputs exist is kept (a killed reproduction resumes); each step's
output goes to ``DIR/logs/NAME.log`` and its time to ``DIR/times.csv``.
"""

from __future__ import annotations

import signal
import subprocess
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path

from faultgen import children


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
    """

    name: str
    args: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()
    needs: tuple[str, ...] = ()
    cost: float = 0.1
    call: Callable[[Path], None] | None = field(default=None, compare=False)
    makes_data: bool = False

    @property
    def log_name(self) -> str:
        return self.name.replace(" ", "-").replace("/", "-") + ".log"

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


def execute(steps: Sequence[Step], folder: Path, jobs: int = 2,
            report: Callable[[Outcome, int, int], None] | None = None) -> list[Outcome]:
    """Run ``steps`` in ``folder``; return their outcomes in the order they ended.

    ``report(outcome, done, total)`` is called as each step ends (the progress display). Raises
    :class:`StepFailed` after the running steps end if any step failed; steps that need a failed
    one are not started.
    """
    check_plan(steps)
    (folder / "logs").mkdir(parents=True, exist_ok=True)
    pending = list(steps)
    done: dict[str, Outcome] = {}
    running: dict[Future, Step] = {}
    failed: list[Outcome] = []
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        try:
            _schedule(pool, steps, folder, jobs, report, pending, done, running, failed)
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


def _schedule(pool, steps, folder, jobs, report, pending, done, running, failed) -> None:
    """Start ready steps as slots free up, until none is pending or running (:func:`execute`)."""
    while pending or running:
        ready = [s for s in pending if all(n in done and done[n].status != "failed" for n in s.needs)]
        blocked = [s for s in pending if any(n in done and done[n].status == "failed" for n in s.needs)]
        for step in blocked:
            pending.remove(step)
        for step in [s for s in ready if _kept(s, folder)]:  # outputs there: no slot, reported at once
            pending.remove(step)
            ready.remove(step)
            done[step.name] = Outcome(step, "kept", 0.0)
            if report is not None:
                report(done[step.name], len(done), len(steps))
        if any(_kept(s, folder) for s in pending if all(n in done for n in s.needs)):
            continue  # a kept step made others ready
        # analyses first (short, and their tables appear early), then the costliest dataset
        for step in sorted(ready, key=lambda s: (s.makes_data, -s.cost))[: max(0, jobs - len(running))]:
            pending.remove(step)
            running[pool.submit(_run_step, step, folder)] = step
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


def _kept(step: Step, folder: Path) -> bool:
    """Whether every output of ``step`` is there (each is written atomically: there means whole)."""
    return bool(step.outputs) and all((folder / o).exists() for o in step.outputs)


def _run_step(step: Step, folder: Path) -> Outcome:
    started = time.perf_counter()
    log = folder / "logs" / step.log_name
    if step.call is not None:
        try:
            with _IN_PROCESS:
                step.call(folder)
        except Exception as err:  # noqa: BLE001 - reported with the step's name, the run goes on
            log.write_text(f"{type(err).__name__}: {err}\n")
            return Outcome(step, "failed", time.perf_counter() - started)
        return Outcome(step, "ran", time.perf_counter() - started)
    with log.open("w") as sink:
        sink.write(step.command() + "\n")
        sink.flush()
        # -P and PYTHONSAFEPATH: `python -m` puts its current folder, the output folder here, first on
        # the path, and an h5py.py or typer.py there would be imported (issue 61; faultgen.children)
        child = subprocess.Popen(children.command("-m", "faultgen.cli", *step.args), cwd=folder,
                                 env=children.environment(), stdout=sink, stderr=subprocess.STDOUT)
        _CHILDREN.add(child)
        try:
            code = child.wait()
        finally:
            _CHILDREN.discard(child)
    missing = [o for o in step.outputs if not (folder / o).exists()]
    status = "failed" if code != 0 or missing else "ran"
    return Outcome(step, status, time.perf_counter() - started)
