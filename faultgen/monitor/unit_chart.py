"""A unit's chart on the monitor's page (:mod:`faultgen.monitor.page`): a plotly figure as a JSON-able
dict, every text HTML-escaped (plotly reads labels as HTML), drawn in the browser when the unit's
panel first opens.

With the twin, each axis's wear at each scored log with its 90 % interval (wear.csv's ``wear_5``,
``wear_95``; without wear.csv the lower one-sided 90 % bound of scores.csv) and the wear limit,
above T2 and Q over their limits; the learning logs shaded, each relearning after maintenance or
after an unlogged program change (units.csv's reason names its stamp) shaded and named as which, the open alarm and every closed one marked, and the friction-test days
(:func:`faultgen.monitor.friction_panel.markers`: dotted lines, each axis's test wear a diamond with
its interval). The wear axis names the scale (units.csv's and wear.csv's ``wear_scale``).
"""

from __future__ import annotations

import math

from faultgen.monitor import friction_panel, lights
from faultgen.monitor.html_cells import escaped, number, short

#: Line colours of the axes (plotly's default sequence).
COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22",
           "#17becf")





def _rgba(colour: str, alpha: float) -> str:
    r, g, b = (int(colour[i:i + 2], 16) for i in (1, 3, 5))
    return f"rgba({r},{g},{b},{alpha})"


def _spans(phases: list[str], phase: str) -> list[tuple[int, int]]:
    """The runs (first, last index) of consecutive rows in ``phase``."""
    spans, start = [], None
    for i, p in enumerate([*phases, ""]):
        if p == phase and start is None:
            start = i
        elif p != phase and start is not None:
            spans.append((start, i - 1))
            start = None
    return spans


def _interval(unit, axis: int, rows: list) -> tuple[list, list] | None:
    """An axis's 90 % interval of wear.csv along the unit's scored logs (``wear_5``, ``wear_95``),
    matched by stamp (a stamp's rows in order); None without wear.csv's rows of the axis."""
    found: dict[str, list[dict]] = {}
    for r in unit.wear.get(axis, []):
        found.setdefault(r["stamp"], []).append(r)
    if not found:
        return None
    seen: dict[str, int] = {}
    low, high = [], []
    for r in rows:
        k = seen[r.stamp] = seen.get(r.stamp, -1) + 1
        match = found.get(r.stamp, [])
        w = match[min(k, len(match) - 1)] if match else {}
        low.append(short(number(w.get("wear_5"))))
        high.append(short(number(w.get("wear_95"))))
    return low, high


def figure(unit, settings: dict) -> dict:
    """The chart of ``unit`` (a :class:`faultgen.monitor.page.Unit`) as a plotly figure (module
    docstring; a JSON-able dict, every text HTML-escaped), ``settings`` the run's (its
    ``wear_limit``, ``alpha``)."""
    rows = unit.scores
    x = list(range(len(rows)))
    stamps = [escaped(r.stamp) for r in rows]
    twin = bool(rows) and not math.isnan(rows[0].wear_at(1))
    data, shapes, annotations = [], [], []
    stat_axis = "y2" if twin else "y"
    n_axes = len(rows[0].scores) if rows else 0
    if twin:
        for i in range(1, n_axes + 1):
            colour = COLOURS[(i - 1) % len(COLOURS)]
            wear = [short(r.wear_at(i)) for r in rows]
            interval = _interval(unit, i, rows)
            if interval is None:  # no wear.csv: the lower one-sided bound of scores.csv
                lower = [short(r.wear_at(i, "lower")) for r in rows]
                data.append({"type": "scatter", "mode": "lines", "x": x, "y": lower, "line": {"width": 0, "color": colour},
                             "legendgroup": f"axis{i}", "showlegend": False, "name": f"axis {i} lower bound",
                             "customdata": stamps, "hovertemplate": "%{customdata}: lower bound %{y:.3g} %<extra></extra>"})
            else:
                for end, values in zip(("5 %", "95 %"), interval):
                    data.append({"type": "scatter", "mode": "lines", "x": x, "y": values,
                                 "line": {"width": 0, "color": colour}, "legendgroup": f"axis{i}", "showlegend": False,
                                 "name": f"axis {i} {end}", "customdata": stamps,
                                 **({"fill": "tonexty", "fillcolor": _rgba(colour, 0.15)} if end == "95 %" else {}),
                                 "hovertemplate": "%{customdata}: " + end + " %{y:.3g} %<extra></extra>"})
            data.append({"type": "scatter", "mode": "lines", "x": x, "y": wear, "line": {"width": 1.5, "color": colour},
                         **({"fill": "tonexty", "fillcolor": _rgba(colour, 0.15)} if interval is None else {}),
                         "legendgroup": f"axis{i}",
                         "name": f"axis {i} wear", "customdata": stamps,
                         "hovertemplate": "%{customdata}: axis " + str(i) + " wear %{y:.3g} %<extra></extra>"})
        limit = number(settings.get("wear_limit"))
        if not math.isnan(limit):
            data.append({"type": "scatter", "mode": "lines", "x": [-0.5, len(rows) - 0.5], "y": [limit, limit],
                         "line": {"color": "black", "dash": "dash", "width": 1}, "name": f"wear limit {limit:g} %",
                         "hoverinfo": "skip"})
    for name, dash, colour in (("Q", "solid", "#1f3a93"), ("T2", "dot", "#9467bd")):
        ratio = [short(getattr(r, name) / getattr(r, f"{name}_limit")) if getattr(r, f"{name}_limit") else None
                 for r in rows]
        data.append({"type": "scatter", "mode": "lines", "x": x, "y": ratio, "yaxis": stat_axis,
                     "line": {"width": 1.2, "dash": dash, "color": colour}, "name": f"{name} / its limit", "customdata": stamps,
                     "hovertemplate": "%{customdata}: " + name + " / limit %{y:.3g}<extra></extra>"})
    if rows:
        alpha = settings.get("alpha")
        data.append({"type": "scatter", "mode": "lines", "x": [-0.5, len(rows) - 0.5], "y": [1, 1], "yaxis": stat_axis,
                     "line": {"color": "black", "width": 1}, "hoverinfo": "skip",
                     "name": "limit" + (f" (alpha {alpha:g})" if isinstance(alpha, (int, float)) else "")})
    phases = [r.phase for r in rows]

    def band(first: int, last: int, colour: str, text: str) -> None:
        shapes.append({"type": "rect", "xref": "x", "yref": "paper", "x0": first - 0.5, "x1": last + 0.5, "y0": 0,
                       "y1": 1, "fillcolor": colour, "opacity": 0.35, "line": {"width": 0}, "layer": "below"})
        annotations.append({"x": first - 0.5, "xref": "x", "xanchor": "left", "y": 1, "yref": "paper",
                            "yanchor": "bottom", "text": text, "showarrow": False, "font": {"size": 10}})

    def line(at: int, colour: str, dash: str, text: str, y: float) -> None:
        shapes.append({"type": "line", "xref": "x", "yref": "paper", "x0": at, "x1": at, "y0": 0, "y1": 1,
                       "line": {"color": colour, "width": 1.5, "dash": dash}})
        # the label inside the chart, on the side with room, in lines short enough for half a 400 px chart
        side = "right" if at > (len(rows) - 1) / 2 else "left"
        annotations.append({"x": at, "xref": "x", "xanchor": side, "y": y, "yref": "paper", "yanchor": "top",
                            "align": side, "text": text,
                            "showarrow": False, "font": {"size": 10, "color": colour}, "bgcolor": "rgba(255,255,255,0.7)"})

    for first, last in _spans(phases, "training"):
        band(first, last, "#bbbbbb", "learning")
    for first, last in _spans(phases, "relearning"):  # after a program change (units.csv's reason says so) or maintenance
        changed = f"program changed at {rows[first].stamp} " in (unit.row or {}).get("reason", "")
        band(first, last, "#f5c27a", "program change: learned again" if changed else "maintenance: offset learned again")
    raw: dict[str, int] = {}  # a stamp's first row: one look-up per alarm (a list's index was rows x alarms)
    for k, r in enumerate(rows):
        raw.setdefault(r.stamp, k)
    for k, alarm in enumerate(unit.closed):
        if alarm["first_alarm"] in raw:
            line(raw[alarm["first_alarm"]], "#7f7f7f", "dash",
                 escaped(f"alarm, axis {alarm['source_axis']}:") + "<br>"
                 + escaped(f"closed by {alarm['closed_by']} ({alarm['closed']})"), 0.9 - 0.1 * (k % 3))
    if unit.open_alarm and unit.current["first_alarm"] in raw:
        line(raw[unit.current["first_alarm"]], "#d62728", "solid",
             escaped(f"alarm, axis {unit.current['source_axis']}:") + "<br>" + escaped(lights.alarm_dates(unit.current)),
             0.97)
    if unit.tests:
        traces, lines, notes = friction_panel.markers(friction_panel.by_axis(unit.tests), [r.stamp for r in rows],
                                                      COLOURS, twin)
        data += traces
        shapes += lines
        annotations += notes
    step = max(1, len(rows) // 8)
    layout = {
        "height": 560 if twin else 340, "margin": {"l": 72, "r": 20, "t": 30, "b": 90},
        "hovermode": "closest", "showlegend": True,
        "legend": {"orientation": "h", "y": -0.2 if twin else -0.35, "font": {"size": 10}},
        "xaxis": {"tickvals": x[::step], "ticktext": stamps[::step], "tickangle": -30,
                  "range": [-0.5, max(len(rows), 1) - 0.5], "anchor": stat_axis, "zeroline": False},
        "shapes": shapes, "annotations": annotations,
    }
    if twin:
        scale = {unit.wear_now(i).scale for i in range(1, n_axes + 1) if unit.wear_now(i) is not None}
        # each title in two short lines: one line of the longest ran past its panel into the other's at 400 px
        title = "wear, %<br>friction-test scale" if scale == {"friction test"} else (
            "wear estimate, %<br>of own dry friction" if scale <= {"twin"} else "wear, %<br>test or twin scale: panel")
        layout["yaxis"] = {"domain": [0.45, 1.0], "title": {"text": title, "font": {"size": 12}}}
        layout["yaxis2"] = {"domain": [0.0, 0.38], "type": "log",
                            "title": {"text": "statistic /<br>its limit", "font": {"size": 12}}}
    else:
        layout["yaxis"] = {"type": "log", "title": {"text": "statistic / its limit"}}
    return {"data": data, "layout": layout}
