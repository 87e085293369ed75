"""One definition of "a whole number" for every check of a setting at a boundary.

The messages stay with the checks (each names its setting and what it expects); only the test
is shared, so that ``True``, ``2.0`` or ``"3"`` are refused the same way everywhere.
"""

from __future__ import annotations

import numpy as np


def is_whole(value, least: int | None = None) -> bool:
    """Whether ``value`` is an integer (Python or NumPy; a bool is not one) of at least ``least``
    (no lower bound when None)."""
    return (not isinstance(value, bool) and isinstance(value, (int, np.integer))
            and (least is None or value >= least))
