"""The friction tests in a unit's panel of the monitor's page (``OUT/tests.csv``): the test days marked on the wear chart, and the friction curve of each alarming axis, the
first test against the latest.

``tests.csv`` has one row per unit, friction test and axis read: ``unit, stamp, axis,
temperature_degC, coulomb_Nm, coulomb_Nm_low, coulomb_Nm_high, static_excess_Nm,
stribeck_velocity_rad_s, viscous_Nms_rad, viscous_Nms_rad_low, viscous_Nms_rad_high, wear,
wear_lower, wear_upper, verdict`` (the arm-side fit of ``faultgen friction-test``,
:mod:`faultgen.calibrate.friction_fit`, 95 % intervals; ``wear`` the temperature-corrected increase
of the dry level over the unit's first test since its last gearbox change, %, with its 90 %
interval; empty cells where there is no number). Without the file the page shows no test data.

- **Test days** (:func:`markers`): each test is a dotted vertical line on the unit's chart, placed
  between the scored logs by its stamp (linear in the stamps' time between the logs before and
  after it; before the first log at its left edge, after the last at its right; a stamp of
  another kind than the logs' is left out), and each axis's test wear a diamond with its 90 %
  interval on the wear panel.
- **Alarming axes** (:func:`alarming_axes`): the open alarm's axis and every axis whose lower wear
  bound at the last log is at or above the run's wear limit.
- **The curve** (:func:`curve_figure`): ``F(v)`` of :func:`faultgen.calibrate.friction_fit.curve`
  for the reference test and the latest, each with a band from the low to the high ends of the dry
  level's and the viscous coefficient's intervals, at speeds from 0 to four Stribeck velocities or
  1 rad/s, whichever is more (tests.csv does not keep the speeds tested). The reference is the
  latest test at or before the latest whose wear is 0 (the first since the last gearbox change),
  else the first.
"""

from __future__ import annotations

import math

import numpy as np

from faultgen.monitor import lights
from faultgen.monitor.html_cells import escaped, number, short

#: The columns of tests.csv the page needs (the others are read when present).
REQUIRED = ("unit", "stamp", "axis", "coulomb_Nm", "viscous_Nms_rad", "wear")
#: Speeds of a drawn friction curve.
CURVE_POINTS = 60





def by_axis(rows: list[dict]) -> dict[int, list[dict]]:
    """A unit's rows of tests.csv by axis, each axis's in stamp order (unreadable stamps and axes
    left out)."""
    found: dict[int, list[tuple[float, dict]]] = {}
    for r in rows:
        axis, key = number(r.get("axis")), lights.stamp_key(r.get("stamp", ""))
        if key is not None and math.isfinite(axis) and axis == int(axis) and axis >= 1:
            found.setdefault(int(axis), []).append((key[0], r))
    return {a: [r for _, r in sorted(v, key=lambda kv: kv[0])] for a, v in sorted(found.items())}


def positions(log_stamps: list[str], test_stamps: list[str]) -> list[float | None]:
    """Each test's place on the chart's axis of scored logs (module docstring): a fractional log
    index, None for a stamp that cannot be placed."""
    keys = [lights.stamp_key(s) for s in log_stamps]
    if not keys or any(k is None for k in keys):
        return [None] * len(test_stamps)
    kind = keys[0][1]
    x = np.array([k[0] for k in keys])
    if any(k[1] != kind for k in keys) or np.any(np.diff(x) < 0):
        return [None] * len(test_stamps)
    out: list[float | None] = []
    for stamp in test_stamps:
        key = lights.stamp_key(stamp)
        if key is None or key[1] != kind:
            out.append(None)
        elif key[0] <= x[0]:
            out.append(-0.5 if key[0] < x[0] else 0.0)
        elif key[0] >= x[-1]:
            out.append(len(x) - 0.5 if key[0] > x[-1] else float(len(x) - 1))
        else:
            # a run of equal stamps: the first of them (np.interp needs increasing x)
            unique, first = np.unique(x, return_index=True)
            out.append(float(np.interp(key[0], unique, first)))
    return out


def markers(tests: dict[int, list[dict]], log_stamps: list[str], colours, wear_panel: bool) -> tuple[list, list, list]:
    """The test days on a unit's chart: plotly traces (each axis's test wear with its interval, on
    the wear panel when ``wear_panel``), shapes and annotations (module docstring)."""
    data, shapes, annotations = [], [], []
    stamps = sorted({r["stamp"] for rows in tests.values() for r in rows},
                    key=lambda s: lights.stamp_key(s) or (math.inf, ""))
    places = dict(zip(stamps, positions(log_stamps, stamps)))
    for k, stamp in enumerate(s for s in stamps if places[s] is not None):
        shapes.append({"type": "line", "xref": "x", "yref": "paper", "x0": places[stamp], "x1": places[stamp],
                       "y0": 0, "y1": 1, "line": {"color": "#2ca02c", "width": 1, "dash": "dot"}})
        if k == 0:
            annotations.append({"x": places[stamp], "xref": "x", "xanchor": "left", "y": 0.0, "yref": "paper",
                                "yanchor": "bottom", "text": "friction test", "showarrow": False,
                                "font": {"size": 10, "color": "#2ca02c"}})
    if not wear_panel:
        return data, shapes, annotations
    for axis, rows in tests.items():
        kept = [r for r in rows if places.get(r["stamp"]) is not None]
        if not kept:
            continue
        wear = [number(r.get("wear")) for r in kept]
        low = [number(r.get("wear_lower")) for r in kept]
        high = [number(r.get("wear_upper")) for r in kept]
        data.append({"type": "scatter", "mode": "markers", "x": [places[r["stamp"]] for r in kept],
                     "y": [short(w) for w in wear], "legendgroup": f"axis{axis}",
                     "marker": {"symbol": "diamond", "size": 8, "color": colours[(axis - 1) % len(colours)],
                                "line": {"color": "black", "width": 0.5}},
                     "error_y": {"type": "data", "symmetric": False,
                                 "array": [short(h - w) for h, w in zip(high, wear)],
                                 "arrayminus": [short(w - lo) for lo, w in zip(low, wear)], "width": 3},
                     "name": f"axis {axis} friction test", "customdata": [escaped(r["stamp"]) for r in kept],
                     "hovertemplate": "%{customdata}: friction test, axis " + str(axis)
                                      + " wear %{y:.3g} %<extra></extra>"})
    return data, shapes, annotations


def alarming_axes(unit, wear_limit: float) -> list[int]:
    """The axes whose friction curve the panel draws (module docstring)."""
    axes = set()
    if unit.open_alarm:
        axis = number(unit.current.get("source_axis"))
        if math.isfinite(axis) and axis == int(axis):
            axes.add(int(axis))
    if unit.scores and math.isfinite(wear_limit):
        last = unit.scores[-1]
        for axis in unit.axes():
            if last.wear_at(axis, "lower") >= wear_limit:
                axes.add(axis)
    return sorted(axes)


def reference(rows: list[dict]) -> dict:
    """The test the latest is compared with (module docstring); ``rows`` in stamp order."""
    zero = [r for r in rows if number(r.get("wear")) == 0.0]
    return zero[-1] if zero else rows[0]


def _params(row: dict, end: str = "") -> tuple[float, float, float, float]:
    static, stribeck = number(row.get("static_excess_Nm")), number(row.get("stribeck_velocity_rad_s"))
    if not (math.isfinite(static) and math.isfinite(stribeck) and stribeck > 0):
        static, stribeck = 0.0, 1.0  # no hump fitted
    coulomb = number(row.get(f"coulomb_Nm{end}")) if end else math.nan
    viscous = number(row.get(f"viscous_Nms_rad{end}")) if end else math.nan
    return (coulomb if math.isfinite(coulomb) else number(row.get("coulomb_Nm")), static, stribeck,
            viscous if math.isfinite(viscous) else number(row.get("viscous_Nms_rad")))


def curve_figure(rows: list[dict], axis: int) -> dict | None:
    """The friction curve figure of one axis (module docstring; a JSON-able plotly dict, every
    text HTML-escaped); None when no test of the axis has a dry level and a viscous coefficient."""
    from faultgen.calibrate.friction_fit import curve

    rows = [r for r in rows if math.isfinite(number(r.get("coulomb_Nm"))) and math.isfinite(number(r.get("viscous_Nms_rad")))]
    if not rows:
        return None
    first, last = reference(rows), rows[-1]
    shown = [(first, "#1f77b4", "reference test")] + ([(last, "#d62728", "latest test")] if last is not first else [])
    top = max([1.0] + [4 * _params(r)[2] for r, _, _ in shown if number(r.get("static_excess_Nm")) > 0])
    v = np.linspace(0.0, top, CURVE_POINTS)
    speeds = [short(s) for s in v]
    data = []
    for r, colour, what in shown:
        temperature = number(r.get("temperature_degC"))
        name = escaped(f"{what} {r['stamp']}" + (f", {temperature:.3g} °C" if math.isfinite(temperature) else "")
                  + (f", wear {number(r.get('wear')):.3g} %" if math.isfinite(number(r.get("wear"))) else ""))
        with np.errstate(over="ignore", invalid="ignore"):  # a planted number: inf or NaN, drawn as a gap (None)
            low, high, mid = curve(v, *_params(r, "_low")), curve(v, *_params(r, "_high")), curve(v, *_params(r))
        fill = _rgba(colour)
        data.append({"type": "scatter", "mode": "lines", "x": speeds, "y": [short(f) for f in low],
                     "line": {"width": 0, "color": colour}, "showlegend": False, "hoverinfo": "skip",
                     "legendgroup": name})
        data.append({"type": "scatter", "mode": "lines", "x": speeds, "y": [short(f) for f in high],
                     "line": {"width": 0, "color": colour}, "fill": "tonexty", "fillcolor": fill, "showlegend": False,
                     "hoverinfo": "skip", "legendgroup": name})
        data.append({"type": "scatter", "mode": "lines", "x": speeds, "y": [short(f) for f in mid],
                     "line": {"width": 2, "color": colour}, "name": name, "legendgroup": name,
                     "hovertemplate": "%{x:.3g} rad/s: %{y:.4g} N m<extra>" + name + "</extra>"})
    note = "" if last is not first else "<br>" + escaped("(one test: nothing to compare yet)")
    # the title below plotly's toolbar (its top 26 px), which covered it at 400 px
    return {"data": data, "layout": {
        "height": 360, "margin": {"l": 60, "r": 20, "t": 72, "b": 110}, "showlegend": True,
        "title": {"text": escaped(f"axis {axis}: friction torque, arm side") + note, "font": {"size": 13}, "x": 0.01,
                  "xanchor": "left", "y": 1 - 30 / 360, "yref": "container", "yanchor": "top"},
        "legend": {"orientation": "h", "y": -0.45, "font": {"size": 10}},
        "xaxis": {"title": {"text": "speed, rad/s"}, "rangemode": "tozero"},
        "yaxis": {"title": {"text": "friction, N m"}, "rangemode": "tozero"}}}


def _rgba(colour: str, alpha: float = 0.15) -> str:
    r, g, b = (int(colour[i:i + 2], 16) for i in (1, 3, 5))
    return f"rgba({r},{g},{b},{alpha})"


def panel_text(tests: dict[int, list[dict]], drawn: list[int]) -> str:
    """The panel's paragraph on the unit's friction tests (HTML): how many, their days, and which
    axes' curves follow."""
    stamps = sorted({r["stamp"] for rows in tests.values() for r in rows},
                    key=lambda s: lights.stamp_key(s) or (math.inf, ""))
    if not stamps:
        return '<p class="muted">No friction test of this unit in tests.csv.</p>'
    shown = ", ".join(stamps[:3] + (["..."] if len(stamps) > 4 else []) + stamps[3:][-1:])
    curves = (f" Friction curves of the alarming axes, reference test against the latest: axis "
              f"{', '.join(str(a) for a in drawn)}." if drawn else " No alarming axis: no friction curve drawn.")
    return f"<p>{len(stamps)} friction tests (tests.csv): {escaped(shown)}; dotted green lines on the chart.{escaped(curves)}</p>"
