"""The page's cells (:mod:`faultgen.monitor.page` and the modules it draws with): a CSV cell read as a
number, a value escaped for HTML, a chart's number rounded."""

from __future__ import annotations

import html
import math


def number(cell) -> float:
    """``cell`` (a CSV cell: text, None) as a float; NaN when it is not a number."""
    try:
        return float(cell)
    except (TypeError, ValueError):
        return math.nan


def escaped(value) -> str:
    """``value`` as text safe inside HTML, attributes included (None: empty)."""
    return html.escape("" if value is None else str(value), quote=True)


def short(value: float | None) -> float | None:
    """A chart's number: 4 significant digits (the page stays small), None for None, NaN or an
    infinity (JSON null)."""
    if value is None or not math.isfinite(value):
        return None
    return float(f"{value:.4g}")
