"""Where and on what a set of runs is computed: :class:`ExecutionContext`.

Sweeps and fleets (:func:`faultgen.runs.sweep.run`, :func:`faultgen.runs.cluster.execute`) and the
monitor (:func:`faultgen.monitor.run.resolve_run`) take one instead of separate ``jobs``,
``scheduler`` and stepper parameters; none of the three changes an output (docs/architecture.md,
"Stepping backends")."""

from __future__ import annotations

from dataclasses import dataclass, field

from faultgen.simulation import backends


@dataclass(frozen=True)
class ExecutionContext:
    """How runs are computed, not what they are (frozen, picklable).

    Attributes
    ----------
    jobs : int
        Local worker processes, >= 1 (ignored by a sweep on a ``scheduler``; the monitor refuses
        both).
    scheduler : str or None
        Address of a Dask distributed scheduler (``tcp://HOST:PORT`` or ``tls://HOST:PORT``) whose
        workers compute instead of local processes; None: local.
    stepper : Stepper
        What steps the simulations (:class:`faultgen.simulation.backends.Stepper`; default
        ``BatchStepper()``), pickled to the workers as it is. A sweep puts it on every run once,
        where it starts (:func:`faultgen.runs.sweep.run`: a
        :class:`~faultgen.simulation.resolve.Run` each); the layers below take the runs, not a
        stepper.

    Raises
    ------
    ValueError
        ``jobs`` not a whole number >= 1, ``scheduler`` neither None nor a non-empty string, or
        ``stepper`` not a Stepper object (each named).
    """

    jobs: int = 1
    scheduler: str | None = None
    stepper: backends.Stepper = field(default_factory=lambda: backends.DEFAULT_STEPPER)

    def __post_init__(self) -> None:
        if isinstance(self.jobs, bool) or not isinstance(self.jobs, int) or self.jobs < 1:
            raise ValueError(f"jobs {self.jobs!r}: expected a whole number >= 1")
        if self.scheduler is not None and (not isinstance(self.scheduler, str) or not self.scheduler):
            raise ValueError(f"scheduler {self.scheduler!r}: expected None or an address such as tcp://HOST:PORT")
        backends.checked(self.stepper)


#: Run in this process on the default stepper.
LOCAL = ExecutionContext()
