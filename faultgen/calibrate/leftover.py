"""What a calibration left unexplained: the axes whose held-out residual stays well above the
others' after the search (:func:`unexplained`), named in the summary, report.json and figure."""

from __future__ import annotations

import numpy as np

from faultgen import axes
from faultgen.calibrate.effects import EFFECTS

#: An axis whose held-out nrmse after the search is above this many times the median axis's is
#: named as left unexplained (summary, report.json, figure): the total gap can fall a lot while
#: one axis keeps most of its residual.
UNEXPLAINED_RATIO = 3.0


def unexplained(gap_before: dict, gap_after: dict, steps: list, searches: int | None = None) -> list[dict]:
    """The axes the search left unexplained: held-out nrmse after it above :data:`UNEXPLAINED_RATIO`
    times the median axis's (``gap_before``, ``gap_after``: :func:`faultgen.calibrate.search.gap`
    records; ``steps``: the :class:`faultgen.calibrate.Step` list). Per axis (numbered 1..N): its
    nrmse before and after, the median,
    the ratio, the effects added on it (with their step) and what was tried on it: every effect
    of :data:`faultgen.effects.EFFECTS`, fitted to the residual at each step of the search, none
    significant on it beyond those added; ``searches``: how many times the effects were fitted
    (default: one more than the steps, the search that found nothing more)."""
    nrmse = np.asarray(gap_after["nrmse"], dtype=float)
    median = float(np.median(nrmse))
    if not median > 0:
        return []
    found = []
    for axis in np.flatnonzero(nrmse > UNEXPLAINED_RATIO * median):
        found.append({"axis": axes.number(int(axis)), "nrmse": float(nrmse[axis]),
                      "nrmse_before": float(gap_before["nrmse"][axis]), "median_nrmse": median,
                      "ratio": float(nrmse[axis] / median),
                      "added": [f"{s.effect.id} (step {k})" for k, s in enumerate(steps, start=1) if axis in s.axes],
                      "tried": list(EFFECTS), "searches": len(steps) + 1 if searches is None else searches})
    return found


def unexplained_line(found: dict, robot: str) -> str:
    """One line of the summary for an axis of :func:`unexplained`."""
    added = f"added on it: {', '.join(found['added'])}" if found["added"] else "nothing added on it"
    return (f"axis {found['axis']} LEFT UNEXPLAINED: held-out nrmse {found['nrmse_before']:.4f} -> {found['nrmse']:.4f}, "
            f"{found['ratio']:.1f}x the median axis's {found['median_nrmse']:.4f}; tried: every effect "
            f"({', '.join(found['tried'])}) fitted to its residual at each of {found['searches']} search steps; "
            f"{added}. Its residual is in the figure; an effect the log does not excite, or one outside the "
            f"library: a designed excitation, faultgen excitation {robot} -o excitation.csv")
