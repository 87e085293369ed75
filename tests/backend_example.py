"""A stepping backend of the tests' own, added as docs/architecture.md ("Adding a stepping backend")
says: its class and its registration, in this one file. It is the default ``batch`` backend
(``mujoco.batch``) counting the batches and runs it makes, so a test can tell that a sweep, a fleet
or the monitor's twin stepped on it (a wrapper of the plain ``loop`` backend would do as well, at
ten times the tests' time). Importing this module registers it; from then on every caller reaches
it by its name, ``counting`` (tests/test_backend_context.py), and tests/test_backends.py, collected
after it, holds it to ``loop`` as it holds every registered backend."""

from __future__ import annotations

from faultgen.simulation import backends


class CountingBackend(backends.BatchBackend):
    """:class:`faultgen.simulation.backends.BatchBackend`, counting what it makes: ``batches``
    (calls of :meth:`new`) and ``runs`` (simulations in them, one per recorded cycle)."""

    name = "counting"

    def __init__(self) -> None:
        self.batches = 0
        self.runs = 0

    def new(self, model, nsim, nthread):
        self.batches += 1
        self.runs += nsim
        return super().new(model, nsim, nthread)


#: The registered instance (its counts are this process's).
COUNTING = backends.register(CountingBackend())
