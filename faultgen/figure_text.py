"""Text put into a matplotlib figure shown as it is written.

Matplotlib reads a text holding an even number of unescaped ``$`` as mathtext: a unit folder named
``u$\\foo$`` (legal on every file system) in a chart's title stopped the chart ("Unknown symbol:
\\foo"), and with it every unit's outputs. Every name that reaches a figure (a unit, a file, a robot, a
task, a run, an isolator, an effect) goes through :func:`plain`; faultgen's own figure texts hold no
mathtext. Plotly charts escape their text for HTML instead (:mod:`faultgen.monitor.unit_chart`).
"""

from __future__ import annotations


def plain(text) -> str:
    """``text`` (any object, as ``str``) with every ``$`` escaped (``\\$``): matplotlib draws it as it
    is, mathtext never parsed (``matplotlib.cbook.is_math_text`` counts escaped dollars out, and the
    text drawn has ``\\$`` back to ``$``)."""
    return str(text).replace("$", r"\$")
