"""A stepping backend of the tests' own, added as docs/architecture.md ("Adding a stepping backend")
says: its class and its registration, in this one file. It is the default ``batch`` backend
(``mujoco.batch``) counting the batches and runs it makes, so a test can tell that a sweep, a fleet
or the monitor's twin stepped on it (a wrapper of the plain ``loop`` backend would do as well, at
ten times the tests' time). Importing this module registers its class under its name, ``counting``,
for the CLI's ``--backend``; sweeps, fleets and the monitor receive the object (:data:`COUNTING`,
tests/test_backend_context.py), and tests/test_backends.py, collected after it, holds it to ``loop``
as it holds every registered backend."""

from __future__ import annotations

from faultgen.simulation import backends


@backends.register
class CountingBackend(backends.BatchStepper):
    """:class:`faultgen.simulation.backends.BatchStepper`, counting what it makes: ``batches``
    (calls of :meth:`new`) and ``runs`` (simulations in them, one per recorded cycle)."""

    name = "counting"

    def __init__(self) -> None:
        self.batches = 0
        self.runs = 0

    def new(self, model, nsim, nthread):
        self.batches += 1
        self.runs += nsim
        return super().new(model, nsim, nthread)


#: The instance the tests hand to sweeps and the monitor (its counts are this process's).
COUNTING = CountingBackend()
