"""The monitor's fleet report: ``OUT/report.html``, one page a service engineer opens in a browser.

The page is built from the monitor's outputs alone, ``units.csv``, ``alarms.csv`` and
``scores.csv`` (:mod:`faultgen.monitor.report`), where present ``wear.csv``, ``rul.csv``,
``life.csv`` and ``tests.csv`` (the friction tests), and the run's settings (a small dict, kept
beside it as ``OUT/settings.json``): a monitor run draws it from the tables it holds and writes
(:class:`faultgen.monitor.record.Table`, :func:`fleet_of`), reading none back; ``faultgen report OUT``
draws the same page again from an output folder's files (:func:`read`,
:func:`faultgen.monitor.run_settings.read_settings`); scores.csv's rows are typed
(:class:`faultgen.monitor.record.LogRow`). It holds:

- the fleet table (:mod:`faultgen.monitor.lights`, where its rules are stated): one line per unit,
  a state light (service due, watch, stale, unknown, ok: colour and word), the "service by" date
  with its 5-95 % interval, the axis, its wear with its 90 % interval, the life consumed by load
  and the last log; the earliest service first, then the units without a date by their light;
- a panel per unit (a ``<details>``, opened by clicking the unit in the table): the rules its light
  met, each axis's wear and the scale it is in, the status, the alarm's evidence in words, the
  long verdicts (each axis's remaining life, rul.csv, and life consumed, life.csv), closed alarms
  and the maintenance that closed them, a chart (:mod:`faultgen.monitor.unit_chart`: each axis's
  wear with its interval and the wear limit, T2 and Q over their limits, the learning logs shaded,
  the relearning after maintenance marked, the friction-test days) and, with friction tests, each
  alarming axis's friction curve, the reference test against the latest
  (:mod:`faultgen.monitor.friction_panel`);
- the run's settings and the false-alarm statement the command line prints, where its bound is
  below 1 (:func:`false_alarm_statement`);
- each alarm as a daily run sees it: "known K (from F)", the log it became known on and the one it
  started from (alarms.csv's ``known`` and ``first_alarm``).

At 400 px wide (a phone) the table's lines become cards, each cell under its column's name: no
column leaves the screen (tests/test_monitor_page_lights.py checks it in headless Chromium).

It is one self-contained file that works offline: plotly.js is embedded once (no CDN, no server),
each unit's chart is kept as JSON in the page and drawn when its panel is first opened (a page of
hundreds of units opens at once). Every text taken from the data (unit names are a stranger's
folder names, stamps file names) is HTML-escaped (:func:`html.escape`), in the page and in the
charts, whose labels plotly reads as HTML too; no data text becomes an element id.
"""

from __future__ import annotations

import json
import math
from statistics import NormalDist
from dataclasses import dataclass, field
from pathlib import Path

from faultgen.data import atomic
from faultgen.monitor import friction_panel, life, lights, record, report, scoring, tables
from faultgen.monitor.html_cells import escaped, number
from faultgen.monitor.run_settings import SETTINGS, settings_dict
from faultgen.monitor.unit_chart import figure

#: The page's file name in OUT.
PAGE = "report.html"
#: Settings shown on the page, in this order, with their meaning.
SETTING_NAMES = {
    "robot": "robot the logs were recorded on",
    "logs": "fleet folder",
    "protocol": "protocol (twin: residuals against each unit's twin; own: the unit's own first logs)",
    "model": "model of the twins (per-unit: calibrated on each unit's first log; nominal; or a given model's SHA-256)",
    "train": "logs of normal operation each unit learns from",
    "alpha": "significance level",
    "variance": "PCA variance kept",
    "persistence": "consecutive alarming logs that make an alarm (with the twin, one log whose lower bound passes the limit by its own width alarms at once)",
    "wear_limit": "wear limit, % of the axis's own dry friction: the lower bound of the wear, filtered over the logs, must reach to alarm",
    "twin_temperature": "the twin's temperature law predicts the seasonal change",
    "scale_prior_mean": "the factor onto the friction tests' scale, its prior's mean (--scale-prior; 1)",
    "scale_prior_sd": "its prior's standard deviation (--scale-prior; default 0.3)",
}
#: Order of the fleet table: what needs attention first (an open alarm before any status).
ATTENTION = ("degraded", "not monitored", "learning", "monitored")


def false_alarm_statement(protocol: str, alpha: float, persistence: int, train: int, n_axes: int,
                          logs_scored: int) -> str:
    """The chance that a healthy unit raises a persistent alarm over ``logs_scored`` logs if its
    residuals were independent and normal, in words: a log alarms with chance <= 2 alpha without a
    twin (T2 or Q) and <= N (1 - c) with it (any of the ``n_axes`` axes' lower one-sided ``c`` bounds
    over a limit the unworn wear lies below, ``c`` =
    :data:`faultgen.monitor.scoring.WEAR_ALARM_CONFIDENCE`), and an alarm needs ``persistence`` in a
    row, or one log far past: with the twin one whose bound passes the limit by its own width (<= N
    (1 - Phi(2 z_c)) per log), without it one whose T2 or Q passes its limit at ``alpha ** persistence``
    (<= 2 alpha^persistence per log). "" where the bound is 1 or more: it says nothing."""
    per_log = 2 * alpha if protocol == "own" else min(1.0, n_axes * (1.0 - scoring.WEAR_ALARM_CONFIDENCE))
    z = NormalDist().inv_cdf(scoring.WEAR_ALARM_CONFIDENCE)
    at_once = 2 * alpha**persistence if protocol == "own" else n_axes * (1.0 - NormalDist().cdf(2 * z))
    chance = logs_scored * (per_log**persistence + at_once)
    if chance >= 1.0:
        return ""
    once = f" or one far past the limit at <= {at_once:.2g}" if at_once else ""
    return (f"Chance of a persistent alarm on a healthy unit over {logs_scored} logs if its residuals were "
            f"independent and normal: <= {chance:.2g} ({persistence} in a row at <= {per_log:g} per log{once}); "
            f"drift the first {train} logs did not show raises it.")


# -- reading the outputs ----------------------------------------------------------------------------


@dataclass(frozen=True)
class WearNow:
    """An axis's wear at a unit's last log, %: the ``estimate``, its 90 % interval (``low``,
    ``high``; ``interval`` False: ``low`` the lower one-sided 90 % bound and no ``high``) and the
    ``scale`` it is in (:data:`faultgen.monitor.lights.SCALES`)."""

    estimate: float
    low: float
    high: float
    interval: bool
    scale: str


@dataclass
class Unit:
    """One unit as the outputs give it: its row of units.csv, its current row of alarms.csv (None
    for a unit never scored), the alarms maintenance closed and its rows of scores.csv."""

    row: dict
    current: dict | None = None
    closed: list[dict] = field(default_factory=list)
    scores: list[record.LogRow] = field(default_factory=list)  # its scored logs (scores.csv's rows)
    remaining: dict[int, dict] = field(default_factory=dict)  # axis -> its row of rul.csv
    life: list[dict] = field(default_factory=list)  # its rows of life.csv
    wear: dict[int, list[dict]] = field(default_factory=dict)  # axis -> its rows of wear.csv, in order
    tests: list[dict] = field(default_factory=list)  # its rows of tests.csv (friction tests)

    @property
    def name(self) -> str:
        return self.row["unit"]

    def service_by(self) -> str:
        """The earlier of the load- and the condition-based life, a date (:func:`faultgen.monitor.life.service_by`)."""
        return life.service_by_html(self.row.get("last_log", ""), self.life, list(self.remaining.values()))

    @property
    def open_alarm(self) -> bool:
        return bool(self.current and self.current.get("first_alarm"))

    def axis_wear(self) -> tuple[int, float, float] | None:
        """The axis whose wear the table shows and its last log's wear estimate and lower bound, %:
        the alarm's axis, else the axis with the largest lower bound; None without the twin."""
        if not self.scores or math.isnan(self.scores[-1].wear_at(1)):
            return None
        last = self.scores[-1]
        axis = number(self.current["source_axis"]) if self.open_alarm else math.nan
        axis = int(axis) if math.isfinite(axis) and axis == int(axis) else None
        if axis is None or not 1 <= axis <= len(last.wear.estimate):
            lowers = {i: last.wear_at(i, "lower") for i in range(1, len(last.wear.estimate) + 1)}
            axis = max(lowers, key=lambda i: -math.inf if math.isnan(lowers[i]) else lowers[i])
        return axis, last.wear_at(axis), last.wear_at(axis, "lower")

    def axes(self) -> list[int]:
        """The unit's axes (1..N of scores.csv's ``scoreI`` columns, else of wear.csv)."""
        if self.scores:
            return list(range(1, len(self.scores[-1].scores) + 1)) or sorted(self.wear)
        return sorted(self.wear)

    def wear_now(self, axis: int) -> WearNow | None:
        """An axis's wear at the unit's last log: wear.csv's last row (its 90 % interval and
        ``wear_scale``) where there is one, else scores.csv's estimate and lower bound; the scale
        wear.csv's, else units.csv's ``wear_scale``, else ``twin``. None without either."""
        scale = self.row.get("wear_scale") or "twin"
        if self.wear.get(axis):
            r = self.wear[axis][-1]
            return WearNow(number(r.get("wear")), number(r.get("wear_5")), number(r.get("wear_95")), True,
                           r.get("wear_scale") or scale)
        if self.scores and not math.isnan(self.scores[-1].wear_at(axis)):
            last = self.scores[-1]
            return WearNow(last.wear_at(axis), last.wear_at(axis, "lower"), math.nan, False, scale)
        return None

    def attention(self) -> tuple:
        """Sort key of the fleet table (:data:`ATTENTION`): an open alarm first, the surest wear first."""
        if self.open_alarm:
            wear = self.axis_wear()
            lower = wear[2] if wear is not None and not math.isnan(wear[2]) else -math.inf
            return (0, -lower, self.current["first_alarm"])
        status = self.row.get("status", "")
        return (1 + (ATTENTION.index(status) if status in ATTENTION else len(ATTENTION)), 0.0, "")


@dataclass
class Fleet:
    """The outputs of one monitor run: its units in the table's order, the axes' count."""

    units: list[Unit]
    n_axes: int
    twin: bool


#: The columns the page needs of each table it is drawn from (``known`` of alarms.csv is optional: a
#: folder written without it is still read); rul.csv, life.csv, wear.csv and tests.csv may be absent
#: (a run before them, a fleet without friction tests).
REQUIRED = {"units.csv": report.UNIT_COLUMNS, "alarms.csv": tuple(c for c in report.ALARM_COLUMNS if c != "known"),
            "rul.csv": ("unit", "axis", "rul", "rul_5", "rul_95", "time_unit", "verdict"),
            "life.csv": ("unit", "axis", "consumed_pct", "days_left", "verdict"), "wear.csv": report.WEAR_COLUMNS,
            "tests.csv": friction_panel.REQUIRED}


def read(folder: str | Path, max_bytes: int | None = tables.CSV_MAX_BYTES) -> Fleet:
    """The units of a monitor output folder (``units.csv``, ``alarms.csv``, ``scores.csv``; and
    ``rul.csv``, ``life.csv``, ``wear.csv``, ``tests.csv`` where present), each table read by
    :func:`faultgen.monitor.tables.read` (``max_bytes`` as there): ``faultgen report OUT``'s
    :func:`fleet_of` (a monitor run gives it the tables it holds instead).

    Raises
    ------
    ValueError
        A file is missing, a link out of the folder, or a table refused by that reader (named).
    """
    folder = Path(folder)
    found = {name: tables.read(folder, name, REQUIRED[name], max_bytes)[1] for name in ("units.csv", "alarms.csv")}
    score_rows = tables.log_rows(tables.read(folder, "scores.csv", report.SCORE_COLUMNS, max_bytes)[1])
    for name in ("rul.csv", "life.csv", "wear.csv", "tests.csv"):  # optional: older folders lack them
        if (folder / name).exists():
            found[name] = tables.read(folder, name, REQUIRED[name], max_bytes)[1]
    return fleet_of(found, score_rows)


def fleet_of(found: dict[str, list[dict]], score_rows: list[record.LogRow]) -> Fleet:
    """The fleet of the page from the rows of its tables by file name (text cells by column, as
    :func:`faultgen.monitor.tables.read` gives them or :meth:`faultgen.monitor.record.Table.records`;
    units.csv and alarms.csv required, the others of :data:`REQUIRED` where present) and scores.csv's
    typed rows (:class:`faultgen.monitor.record.LogRow`), its units in the order of
    :meth:`Unit.attention` (the page orders them by :mod:`faultgen.monitor.lights`)."""
    units = {r["unit"]: Unit(r) for r in found["units.csv"] if r.get("unit") is not None}
    alarm_rows = found["alarms.csv"]
    for r in alarm_rows:
        unit = units.setdefault(r["unit"], Unit({"unit": r["unit"], "status": "", "last_log": ""}))
        if r.get("closed"):
            unit.closed.append(r)
        else:
            unit.current = r
    for r in score_rows:
        if r.unit in units:
            units[r.unit].scores.append(r)
    for r in found.get("rul.csv", ()):  # remaining useful life
        axis = number(r["axis"])
        if r["unit"] in units and math.isfinite(axis):
            units[r["unit"]].remaining[int(axis)] = r
    for r in found.get("life.csv", ()):  # the rated life consumed by load
        if r["unit"] in units:
            units[r["unit"]].life.append(r)
    for r in found.get("wear.csv", ()):  # the wear's 90 % interval and scale
        axis = number(r["axis"])
        if r["unit"] in units and math.isfinite(axis) and axis == int(axis):
            units[r["unit"]].wear.setdefault(int(axis), []).append(r)
    for r in found.get("tests.csv", ()):  # friction tests
        if r["unit"] in units:
            units[r["unit"]].tests.append(r)
    n_axes = max((len(r.scores) for r in score_rows), default=0)
    ordered = sorted(units.values(), key=Unit.attention)
    return Fleet(ordered, n_axes if alarm_rows else 1, any(r.wear is not None for r in score_rows))


# -- the page ---------------------------------------------------------------------------------------


def _script_json(value) -> str:
    """``value`` as JSON safe inside a ``<script>`` element (no ``<``: no ``</script>``, no comment)."""
    return json.dumps(value, separators=(",", ":"), allow_nan=False).replace("<", "\\u003c").replace(
        "\u2028", "\\u2028").replace("\u2029", "\\u2029")


STYLE = """
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;margin:1.2em 2em;color:#222;font-size:14px}
h1{font-size:1.5em;margin-bottom:.2em} h2{font-size:1.2em;margin-top:1.6em}
table{border-collapse:collapse;margin:.5em 0} th,td{border-bottom:1px solid #ddd;padding:.3em .6em;text-align:left;
vertical-align:top} th{background:#f3f3f3}
#fleet tbody tr:hover{background:#f8f8ff} td[data-column="last log"]{white-space:nowrap}
.muted{color:#777} .evidence{background:#fff4f4;border-left:3px solid #d62728;padding:.4em .7em}
details.unit{border:1px solid #ddd;border-radius:.3em;margin:.4em 0;padding:.3em .7em}
details.unit summary{cursor:pointer;font-weight:600} .chart{width:100%;min-height:300px}
.statement{background:#f6f6f6;padding:.5em .8em}
"""

SCRIPT = """
(function(){
  var config={responsive:true,displaylogo:false,typesetMath:false};
  function render(d){
    if(!d.open)return;
    d.querySelectorAll('.chart').forEach(function(div){
      if(div.getAttribute('data-drawn'))return;
      var fig=JSON.parse(document.getElementById(div.getAttribute('data-figure')).textContent);
      Plotly.newPlot(div,fig.data,fig.layout,config);
      div.setAttribute('data-drawn','1');
    });
  }
  function show(id){
    var d=document.getElementById(id);
    if(d&&d.tagName==='DETAILS'){d.open=true;render(d);d.scrollIntoView();}
  }
  document.querySelectorAll('details.unit').forEach(function(d){
    d.addEventListener('toggle',function(){render(d);});
  });
  document.querySelectorAll('a.unit-link').forEach(function(a){
    a.addEventListener('click',function(){show(a.getAttribute('href').slice(1));});
  });
  document.getElementById('open-all').addEventListener('click',function(){
    document.querySelectorAll('details.unit').forEach(function(d){d.open=true;render(d);});
  });
  document.getElementById('close-all').addEventListener('click',function(){
    document.querySelectorAll('details.unit').forEach(function(d){d.open=false;});
  });
  window.addEventListener('hashchange',function(){show(location.hash.slice(1));});
  if(location.hash)show(location.hash.slice(1));
})();
"""

#: The fleet table's columns (:mod:`faultgen.monitor.lights`).
COLUMNS = lights.COLUMNS
#: The page's reading guide above the table (the rules of :mod:`faultgen.monitor.lights`).
LEGEND = (f"Each line: the state (service due: service by within {lights.DUE_DAYS:g} days of the fleet's latest log, "
          "or an open alarm past the failure wear; watch: an open alarm, or service by within "
          f"{lights.WATCH_DAYS:g} days; stale: no log for {lights.STALE_DAYS:g} days or more before the fleet's "
          "latest; unknown: learning, not monitored or no wear estimate; ok: none; hover for the rules met), the "
          "service-by date, the earlier of the condition-based remaining life (rul.csv) and the load-based life "
          "(life.csv), with its 5-95 % interval, the axis (the open alarm's, else the one setting service by, else the "
          "largest lower wear bound), its wear at the last log, % increase of its dry friction, with its 90 % "
          "interval, the life its gearbox consumed by load, the last log. Earliest service first (an open alarm past "
          "the failure wear: now), then units without a date by state. Click a unit for its panel: the rules met, every axis's wear, remaining life and life "
          "verdicts, the alarm's evidence, the maintenance, its chart and its friction tests.")


def _remaining(row: dict | None) -> str:
    """A row of rul.csv in words: the median remaining life and its 5-95 % interval, or its verdict."""
    if not row:
        return ""
    rul = number(row.get("rul"))
    if not math.isfinite(rul):
        return row.get("verdict", "")
    unit = row.get("time_unit", "")
    return f"{rul:.0f} {unit} ({number(row.get('rul_5')):.0f}-{number(row.get('rul_95')):.0f})"


def _closed_text(alarm: dict) -> str:
    return (f"alarm {lights.alarm_dates(alarm)}, axis {alarm['source_axis']}, closed {alarm['closed']} by "
            f"{alarm['closed_by']}")


def _chart(name: str, fig: dict) -> str:
    """A chart drawn when its panel opens: its div and its figure as JSON (``name`` no data text)."""
    return (f'<div class="chart" id="chart-{name}" data-figure="figure-{name}"></div>\n'
            f'<script type="application/json" id="figure-{name}">{_script_json(fig)}</script>')


def _source_notes(row: dict) -> list[str]:
    """A unit's panel's words on what its numbers rest on: the torque its logs
    were read from (units.csv's ``torque_source``, a warning for the commanded moment) and a twin that
    fell back to the nominal model (``wear_scale`` ``nominal model``)."""
    notes = []
    source = row.get("torque_source") or ""
    if source:
        style = ' class="evidence"' if "cannot show wear" in source else ""
        notes.append(f"<p{style}><b>Torque</b>: {escaped(source)}.</p>")
    if row.get("wear_scale") == "nominal model":
        notes.append('<p class="evidence"><b>Twin fallback</b>: the twin of the unit\'s own model failed (the reason '
                     "above); the nominal model's twin took its place, so its wear is in % of the nominal model's dry "
                     "friction, not its own.</p>")
    return notes


def _panel(index: int, unit: Unit, settings: dict, lit: lights.Light) -> str:
    row = unit.row
    model = f", {row['model']} model" if row.get("model") else ""
    head = (f"{escaped(unit.name)} — {escaped(lit.state)} — {escaped(row.get('status', ''))}"
            + (f" — alarm {escaped(lights.alarm_dates(unit.current))}, axis {escaped(unit.current['source_axis'])}"
               if unit.open_alarm else ""))
    parts = [f'<details class="unit" id="unit-{index}" data-index="{index}"><summary>{head}</summary>',
             lights.panel_html(unit, lit),
             f"<p>{escaped(row.get('status', ''))} ({escaped(row.get('protocol', ''))}{escaped(model)}); "
             f"{escaped(row.get('logs_scored', ''))} logs scored, the last {escaped(row.get('last_log', '') or '–')}."
             + (f" {escaped(row['reason'])}." if row.get("reason") else "") + "</p>", *_source_notes(row)]
    if unit.open_alarm:
        parts.append(f'<p class="evidence"><b>Open alarm</b> {escaped(lights.alarm_dates(unit.current))} on axis '
                     f'{escaped(unit.current["source_axis"])} ({escaped(unit.current["statistic"])}): '
                     f'{escaped(unit.current["evidence"])}</p>')
    elif unit.current is not None:
        parts.append(f"<p>No open alarm: {escaped(unit.current['evidence'])}.</p>")
    if lit.service is not None:
        parts.append(f"<p>Service by {lights.service_cell(unit, lit)} ({escaped(lit.service.why)}).</p>")
    if unit.remaining:
        items = "".join(f"<li>axis {axis}: {escaped(_remaining(r))}"
                        + (f" ({escaped(r['model'])} trend of {escaped(r.get('logs_fitted', ''))} logs)" if r.get("model") else "")
                        + (f"; {escaped(r['verdict'])}" if r.get("verdict") and _remaining(r) != r["verdict"] else "")
                        + "</li>" for axis, r in sorted(unit.remaining.items()))
        parts.append("<p>Remaining life (5-95 %) until the wear estimate reaches the failure wear (rul.csv):</p>"
                     f"<ul>{items}</ul>")
    if unit.life:
        parts.append(life.panel_html(unit.life, unit.service_by()))
    if unit.closed:
        items = "".join(f"<li>{escaped(_closed_text(a))}: {escaped(a['evidence'])}</li>" for a in unit.closed)
        parts.append(f"<p>Alarms closed by maintenance (the unit's offset learned again after each):</p><ul>{items}</ul>")
    if unit.scores:
        parts.append(_chart(str(index), figure(unit, settings)))
    else:
        parts.append('<p class="muted">No log scored: no chart.</p>')
    tests = friction_panel.by_axis(unit.tests)
    if tests:
        limit = settings.get("wear_limit")
        drawn = [(a, f) for a in friction_panel.alarming_axes(unit, float(limit) if isinstance(limit, (int, float))
                                                              else math.nan)
                 if (f := friction_panel.curve_figure(tests.get(a, []), a)) is not None]
        parts.append(friction_panel.panel_text(tests, [a for a, _ in drawn]))
        parts += [_chart(f"{index}-axis{a}", f) for a, f in drawn]
    parts.append("</details>")
    return "\n".join(parts)


def build(fleet: Fleet, settings: dict) -> str:
    """The page's HTML (module docstring): the units in the order of :meth:`faultgen.monitor.lights.Light.order`."""
    from plotly.offline import get_plotlyjs

    now = lights.latest(fleet.units)
    protocol = str(settings.get("protocol", "") or "")
    lit = [(u, lights.light(u, now, protocol)) for u in fleet.units]
    lit.sort(key=lambda ul: ul[1].order(ul[0].attention()))
    units = [u for u, _ in lit]
    counts = {s: sum(l_.state == s for _, l_ in lit) for s in lights.STATES}
    alarmed = sum(u.open_alarm for u in units)
    monitors = [u for u in units if u.current is not None]
    summary = (f"{len(units)} units: " + ", ".join(f"{n} {s}" for s, n in counts.items() if n)
               + f"; {alarmed} with an open alarm.")
    statement = ""
    if all(isinstance(settings.get(k), (int, float)) for k in ("alpha", "persistence", "train")):
        logs_scored = max((sum(r.phase == "monitoring" for r in u.scores) for u in monitors), default=0)
        statement = " ".join(filter(None, (f"{alarmed} of {len(monitors)} units alarm.", false_alarm_statement(
            str(settings.get("protocol", "twin")), float(settings["alpha"]), int(settings["persistence"]),
            int(settings["train"]), fleet.n_axes, logs_scored))))
    setting_rows = "".join(f"<tr><th>{escaped(k)}</th><td>{escaped(settings[k])}</td><td class='muted'>{escaped(v)}</td></tr>"
                           for k, v in SETTING_NAMES.items() if k in settings)
    setting_rows += "".join(f"<tr><th>{escaped(k)}</th><td>{escaped(v)}</td><td></td></tr>"
                            for k, v in settings.items() if k not in SETTING_NAMES)
    run = (f'<p class="statement" id="statement">{escaped(statement)}</p>' if statement else
           '<p class="muted">The run&#x27;s settings were not found (no settings.json): the false-alarm statement '
           'is left out.</p>')
    table = "\n".join(lights.row(i, u, l_) for i, (u, l_) in enumerate(lit))
    panels = "\n".join(_panel(i, u, settings, l_) for i, (u, l_) in enumerate(lit))
    header = "".join(f"<th>{escaped(c)}</th>" for c in COLUMNS)
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>faultgen fleet report</title>
<style>{STYLE}{lights.CSS}</style>
<script type="text/javascript">{get_plotlyjs()}</script>
</head>
<body>
<h1>Fleet report</h1>
<p>{escaped(summary)} Service due and the earliest service first; click a unit for its panel.</p>
<table id="fleet">
<thead><tr>{header}</tr></thead>
<tbody>
{table}
</tbody>
</table>
<p class="muted" id="legend">{escaped(LEGEND)}</p>
<h2>Units</h2>
<p><button id="open-all" type="button">open all</button> <button id="close-all" type="button">close all</button></p>
{panels}
<h2>The run</h2>
{run}
<table id="settings">{setting_rows}</table>
<p class="muted">Written by faultgen from units.csv, alarms.csv and scores.csv of this folder (and wear.csv, rul.csv,
life.csv, tests.csv where present); <code>faultgen report FOLDER</code> writes it again. Each unit's control chart is
also FOLDER/&lt;unit&gt;.png.</p>
<script type="text/javascript">{SCRIPT}</script>
</body>
</html>
"""


def _write(path: Path, text: str) -> None:
    with atomic.atomic_path(path) as tmp:
        tmp.write_bytes(text.encode("utf-8"))


def write(folder: str | Path, settings=None, *, table_max_bytes: int | None = tables.CSV_MAX_BYTES,
          fleet: Fleet | None = None, **extra) -> Path:
    """Write ``folder/report.html`` from ``fleet`` (a monitor run's, :func:`fleet_of` the tables it
    holds) or else the monitor outputs in ``folder`` (:func:`read`), and the run's
    ``settings`` (a :class:`faultgen.monitor.scoring.Settings` or a dict; ``extra`` adds to it: the
    robot, the logs folder, the model source), kept beside it as ``folder/settings.json`` (unless empty).
    Both files are written whole or not at all (:func:`faultgen.data.atomic.atomic_path`), UTF-8.
    ``table_max_bytes``: each table's size bound when read (:data:`faultgen.monitor.tables.CSV_MAX_BYTES`;
    None: no bound).

    Raises
    ------
    ValueError
        A table refused by :func:`faultgen.monitor.tables.read` (named, with the row or column at fault).

    Returns
    -------
    Path
        The page.
    """
    folder = Path(folder)
    settings = settings_dict(settings, extra)
    page = folder / PAGE
    _write(page, build(fleet if fleet is not None else read(folder, table_max_bytes), settings))
    if settings:
        _write(folder / SETTINGS, json.dumps(settings, indent=1, sort_keys=True) + "\n")
    return page
