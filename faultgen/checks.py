"""One definition of "a whole number" and of "a number within a range" for every check of a
setting at a boundary.

The messages stay with the checks (each names its setting and what it expects); only the test
is shared, so that ``True``, ``2.0``, ``"3"`` or NaN are refused the same way everywhere.
"""

from __future__ import annotations

import numpy as np


def is_whole(value, least: int | None = None) -> bool:
    """Whether ``value`` is an integer (Python or NumPy; a bool is not one) of at least ``least``
    (no lower bound when None)."""
    return (not isinstance(value, bool) and isinstance(value, (int, np.integer))
            and (least is None or value >= least))


def is_number(value, low: float = -np.inf, high: float = np.inf) -> bool:
    """Whether ``value`` is a finite real number (Python or NumPy; a bool is not one) within
    ``low..high``."""
    return (not isinstance(value, bool) and isinstance(value, (int, float, np.integer, np.floating))
            and bool(np.isfinite(value)) and low <= value <= high)


#: The largest seed anywhere (command line, grid files, the library): the seeds NumPy's legacy
#: generators and scikit-learn's ``random_state`` take (0..2**32 - 1), so one seed means the same
#: run in every part of faultgen and fits an HDF5 integer attribute.
MAX_SEED = 2**32 - 1
