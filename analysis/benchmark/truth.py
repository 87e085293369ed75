"""A dataset opened for analysis, and the truth each table scores against: the true axis of a run
without wear, a run's fault progress per recorded cycle, the cycle at which it reaches a wear level."""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from faultgen import axes
from faultgen.data import reader

#: The true axis of a run without wear, in the tables.
NO_FAULT = 0


@contextmanager
def opened(source):
    """A :class:`faultgen.data.reader.Dataset` from a path (opened here, closed after) or as given."""
    if isinstance(source, reader.Dataset):
        yield source
    else:
        with reader.open(source) as data:
            yield data


def fault_progress(run: reader.Run, axis: int) -> np.ndarray:
    """Per recorded cycle, the worn axis's true friction multiplier; for a run whose fault is not
    friction wear (``run.fault``: a growing backlash, cogging, offset), 1 + its parameter's
    change as a fraction of the final change, so that a level of L % means L % of the final value."""
    if run.fault is None:
        return run.array("friction_multiplier")[:, axes.index(axis)]
    return 1.0 + run.fault_level / 100.0


def level_cycle(multiplier: np.ndarray, level: float) -> int | None:
    """Index of the first recorded cycle whose true wear reaches ``level`` percent, or None."""
    reached = np.flatnonzero((multiplier - 1.0) * 100.0 >= level - 1e-9)
    return int(reached[0]) if reached.size else None
