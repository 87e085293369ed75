"""The fleet table of the monitor's page (``OUT/report.html``, :mod:`faultgen.monitor.page`): one
line per unit that a service engineer reads in ten seconds, as the makers' dashboards
show it, a state light, the "service by" date with its interval, the axis, its wear with its
interval, the life consumed by load and the last log, the units ordered by that date.

**The state light**, colour and word (never colour alone), the first rule a unit meets in this
order (:data:`STATES`; every rule it meets is named on hover and in its panel):

- **service due**: the "service by" date lies within :data:`DUE_DAYS` days of the fleet's latest
  log, or past it; or the unit has an open alarm and the alarm axis's wear estimate is at or past
  the failure wear (rul.csv's ``failure_wear`` of that axis, else
  :data:`faultgen.monitor.prognosis.FAILURE_WEAR`);
- **watch**: an open alarm, or the "service by" date within :data:`WATCH_DAYS` days of the fleet's
  latest log;
- **stale**: the unit's last log is :data:`STALE_DAYS` days or more before the fleet's latest log
  (the latest ``last_log`` of units.csv; sequence-number stamps count one step as one day, and are
  compared with sequence-number stamps only);
- **unknown**: still learning, not monitored, or no wear estimate where the run has the twin (its
  protocol, else the unit's, is ``twin``);
- **ok**: none of these.

**"service by"** is the earlier of the load-based life (life.csv's days left) and the
condition-based remaining life at its 5 % quantile (rul.csv's ``rul_5``, in days: the day the wear's
95 % path reaches the failure wear, never a median; issue 90), counted from the unit's last log
(:func:`faultgen.monitor.life.service_window`), with its interval: each end the earliest of the
sources' 5 % and 95 % ends (the rated-life formula gives one number: a load-based source is its own
ends). A date for date stamps, "in N days" for sequence numbers.

**The axis** is the open alarm's axis, else the axis that sets "service by", else the axis whose
lower wear bound is largest at the last log; **the wear** is that axis's at the last log with its
90 % interval (wear.csv's ``wear_5``, ``wear_95``; without wear.csv the lower one-sided 90 % bound of
scores.csv, "≥"), the scale named on hover.

**The order**: units with a "service by" date first, the earliest first (counted from the fleet's
latest log; a unit whose open alarm is past the failure wear counts as due now, its date or the
fleet's latest log, whichever is earlier, and says "now" where it has no date), then the units
without one by their light in :data:`STATES`' order, ties by the order
of :meth:`faultgen.monitor.page.Unit.attention` (the surest open alarm first, then degraded, not
monitored, learning and quiet units).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from faultgen.data import logfolder
from faultgen.monitor import life, prognosis
from faultgen.monitor.html_cells import escaped, number
from faultgen.monitor.scoring import NOT_OBSERVABLE

#: The lights, in the order the rules are tried and the undated units are listed.
STATES = ("service due", "watch", "stale", "unknown", "ok")
#: A "service by" date within this many days of the fleet's latest log makes a unit "service due".
DUE_DAYS = 14.0
#: ... within this many days, "watch".
WATCH_DAYS = 60.0
#: A unit whose last log is this many days or more before the fleet's latest is "stale".
STALE_DAYS = 7.0
#: The fleet table's columns.
COLUMNS = ("state", "unit", "service by (5-95 %)", "axis", "wear, % (90 %)", "life consumed", "last log")
#: What a wear scale means (units.csv's and wear.csv's ``wear_scale``; absent: ``twin``).
SCALES = {"friction test": "friction-test scale: the increase of the axis's dry friction over the unit's first "
                           "friction test since its last gearbox change, temperature-corrected",
          "twin": "twin scale: the increase of the axis's dry friction in % of the unit's own, estimated by the "
                  "production-log twin",
          "nominal model": "nominal-model scale: the unit's own model's twin failed (its reason says why) and the "
                           "twin of the nominal model took its place: the increase of the axis's dry friction in % of "
                           "the nominal model's, not the unit's own"}

CSS = """
.light{display:inline-block;padding:.1em .5em;border-radius:.8em;font-size:.9em;font-weight:600;white-space:nowrap}
.light::before{content:"\\25CF\\00A0"}
.l-service-due{background:#d62728;color:#fff} .l-watch{background:#ffbf00;color:#222}
.l-stale{background:#6c757d;color:#fff} .l-unknown{background:#e2e2e2;color:#222} .l-ok{background:#2ca02c;color:#fff}
#fleet td[data-column="unit"]{overflow-wrap:anywhere} small.muted{display:block}
@media (max-width:700px){
 body{margin:.5em .6em} #fleet td{overflow-wrap:anywhere}
 #settings,#settings tbody,#settings tr,#settings th,#settings td{display:block;border:none;overflow-wrap:anywhere}
 #settings tr{border-bottom:1px solid #ddd;padding:.2em 0} #settings th{background:none;padding-bottom:0}
 #fleet thead{display:none} #fleet,#fleet tbody,#fleet tr,#fleet td{display:block}
 #fleet tr{border:1px solid #ddd;border-radius:.3em;margin:.4em 0;padding:.2em 0}
 #fleet td{border:none;padding:.1em .5em} #fleet td:empty{display:none}
 #fleet td::before{content:attr(data-column) ": ";color:#777;font-size:.85em}
 #fleet td[data-column="state"]::before,#fleet td[data-column="unit"]::before{content:none}
 #fleet td[data-column="state"],#fleet td[data-column="unit"]{display:inline-block}
 #fleet small.muted{display:inline}
}
"""




def stamp_key(stamp: str) -> tuple[float, str] | None:
    """``(days, kind)`` of a stamp (:func:`faultgen.data.logfolder.parse_stamp`: date stamps in
    days since 1970, sequence numbers one step a day); None for an empty or unreadable one."""
    try:
        key, kind = logfolder.parse_stamp(stamp, "stamp")
    except (ValueError, TypeError):
        return None
    return (key / 86400.0 if kind == logfolder.TIME else key), kind


def latest(units) -> dict[str, tuple[float, str]]:
    """The fleet's latest last log per stamp kind: ``{kind: (days, stamp)}``."""
    found: dict[str, tuple[float, str]] = {}
    for unit in units:
        stamp = unit.row.get("last_log", "") or ""
        key = stamp_key(stamp)
        if key is not None and (key[1] not in found or key[0] > found[key[1]][0]):
            found[key[1]] = (key[0], stamp)
    return found


@dataclass
class Light:
    """A unit's light (:data:`STATES`), every rule it meets in words, its "service by"
    (:class:`faultgen.monitor.life.Service`, None without), the days from the fleet's latest log
    to it (NaN without) and the axis the table shows (None without)."""

    state: str
    reasons: list[str] = field(default_factory=list)
    service: life.Service | None = None
    to_service: float = math.nan
    axis: int | None = None
    past_failure: bool = False

    def order(self, attention: tuple) -> tuple:
        """Sort key of the fleet table (module docstring)."""
        rank = STATES.index(self.state)
        if self.past_failure:  # due now, whatever rul.csv could tell
            return (0, min(self.to_service, 0.0) if math.isfinite(self.to_service) else 0.0, rank, *attention)
        if math.isfinite(self.to_service):
            return (0, self.to_service, rank, *attention)
        return (1, 0.0, rank, *attention)


def alarm_dates(alarm: dict) -> str:
    """When an alarm (a row of alarms.csv) became known and the log it started from, in words:
    "known K (from F)"; "from F" for a folder written without ``known``, or when they are
    the same log."""
    known, first = alarm.get("known") or "", alarm.get("first_alarm") or ""
    return f"known {known} (from {first})" if known and known != first else f"from {first}"


def _failure_wear(unit, axis: int) -> float:
    row = unit.remaining.get(axis) or {}
    value = number(row.get("failure_wear"))
    return value if math.isfinite(value) else prognosis.FAILURE_WEAR


def shown_axis(unit, service: life.Service | None) -> int | None:
    """The axis of the table's line (module docstring)."""
    if unit.open_alarm:
        axis = number(unit.current.get("source_axis"))
        if math.isfinite(axis) and axis == int(axis):
            return int(axis)
    if service is not None and service.axis is not None:
        return service.axis
    wear = unit.axis_wear()
    return wear[0] if wear is not None else None


def light(unit, now: dict[str, tuple[float, str]], protocol: str = "") -> Light:
    """A unit's light by the module docstring's rules; ``now`` the fleet's latest log
    (:func:`latest`), ``protocol`` the run's (empty: the unit's own, units.csv)."""
    service = life.service_window(unit.life, list(unit.remaining.values()))
    last = unit.row.get("last_log", "") or ""
    key = stamp_key(last)
    fleet = now.get(key[1]) if key is not None else None
    behind = fleet[0] - key[0] if key is not None and fleet is not None else 0.0
    out = Light("ok", service=service, axis=shown_axis(unit, service))
    met: dict[str, list[str]] = {s: [] for s in STATES}
    if service is not None:
        out.to_service = service.days - behind
        date = life.date_after(last, service.days)
        when = (f"service by {date} ({service.why}), {out.to_service:.0f} days from the fleet's latest log"
                + (f" {fleet[1]}" if fleet else ""))
        if out.to_service <= DUE_DAYS:
            met["service due"].append(f"{when}: within {DUE_DAYS:g} days")
        elif out.to_service <= WATCH_DAYS:
            met["watch"].append(f"{when}: within {WATCH_DAYS:g} days")
    if unit.open_alarm:
        axis = out.axis
        alarm = f"open alarm {alarm_dates(unit.current)} on axis {unit.current.get('source_axis', '')}"
        wear = unit.wear_now(axis) if axis is not None else None
        failure = _failure_wear(unit, axis) if axis is not None else math.nan
        if wear is not None and math.isfinite(wear.estimate) and wear.estimate >= failure:
            met["service due"].append(f"{alarm}, its wear {wear.estimate:.3g} % at or past the failure wear {failure:g} %")
            out.past_failure = True
        else:
            met["watch"].append(alarm)
    if fleet is not None and behind >= STALE_DAYS:
        met["stale"].append(f"no log for {behind:.0f} days before the fleet's latest ({fleet[1]}): "
                            f"{STALE_DAYS:g} days or more")
    status = unit.row.get("status", "")
    if status in ("learning", "not monitored"):
        reason = unit.row.get("reason", "")
        met["unknown"].append(f"{status}" + (f" ({reason})" if reason else "") + ": no wear estimate")
    elif (protocol or unit.row.get("protocol", "")) == "twin" and unit.axis_wear() is None:
        met["unknown"].append("no wear estimate")
    for state in STATES:
        if met[state] and out.state == "ok":
            out.state = state
        out.reasons += [f"{state}: {r}" for r in met[state]]
    if not out.reasons:
        out.reasons = ["ok: no rule of service due, watch, stale or unknown met"]
    return out


def badge(state: str, title: str = "") -> str:
    """The light as HTML: a coloured pill with the word."""
    return f'<span class="light l-{"-".join(state.split())}" title="{escaped(title)}">{escaped(state)}</span>'


def _short_date(text: str, like: str) -> str:
    """``text`` without the year ``like`` shares (``2026-04-05`` beside ``2026-04-12``: ``04-05``)."""
    if len(text) == len(like) == 10 and text[:5] == like[:5] and text[4] == "-":
        return text[5:]
    return text


def service_cell(unit, lit: Light) -> str:
    """The "service by" cell: the date, its 5-95 % interval and what sets it (HTML)."""
    service = lit.service
    if service is None:
        return "now <small class=\"muted\">wear past the failure wear</small>" if lit.past_failure else ""
    last = unit.row.get("last_log", "") or ""
    date = life.date_after(last, service.days)
    if service.low == service.high == service.days:
        interval = "no interval (rated life)"
    else:
        low = _short_date(life.date_after(last, service.low), date)
        high = _short_date(life.date_after(last, service.high), date) if math.isfinite(service.high) else "later"
        interval = f"{low} – {high}"
    return f'{escaped(date)} <small class="muted">{escaped(interval)}; by {service.basis}, axis {escaped(service.axis)}</small>'


def wear_cell(unit, axis: int | None) -> str:
    """The wear cell of the table's axis: the estimate and its 90 % interval, the scale on hover."""
    wear = unit.wear_now(axis) if axis is not None else None
    if wear is None or not math.isfinite(wear.estimate):
        return ""
    if wear.interval:
        text = f"{wear.estimate:.3g} ({wear.low:.3g} – {wear.high:.3g})"
    else:
        text = f"{wear.estimate:.3g} (≥ {wear.low:.3g})"
    if wear.scale == "nominal model":  # the twin's fallback, said where the number is
        text += ", nominal model"
    return f'<span title="{escaped(SCALES.get(wear.scale, wear.scale))}">{escaped(text)}</span>'


def row(index: int, unit, lit: Light) -> str:
    """The unit's line of the fleet table (:data:`COLUMNS`), every data text HTML-escaped."""
    cells = [badge(lit.state, "; ".join(lit.reasons)),
             f'<a class="unit-link" href="#unit-{index}">{escaped(unit.name)}</a>',
             service_cell(unit, lit), escaped(lit.axis if lit.axis is not None else ""), wear_cell(unit, lit.axis),
             escaped(life.table_cell(unit.life)), escaped(unit.row.get("last_log", ""))]
    return "<tr>" + "".join(f'<td data-column="{c}">{v}</td>' for c, v in zip(COLUMNS, cells)) + "</tr>"


def panel_html(unit, lit: Light) -> str:
    """The light's paragraph of a unit's panel: the state and every rule met, and each axis's wear
    at the last log with its interval and the scale it is in (HTML)."""
    reasons = "".join(f"<li>{escaped(r)}</li>" for r in lit.reasons)
    parts = [f"<p>{badge(lit.state)} the rules met:</p><ul>{reasons}</ul>"]
    found = [(axis, w) for axis in unit.axes() if (w := unit.wear_now(axis)) is not None and math.isfinite(w.estimate)]
    scales = {w.scale for _, w in found}
    items = []
    for axis, wear in found:
        bound = (f"90 % interval {wear.low:.3g} – {wear.high:.3g} %" if wear.interval
                 else f"lower 90 % bound {wear.low:.3g} %")
        scale = f", {wear.scale} scale" if len(scales) > 1 else ""
        items.append(f"<li>axis {axis}: {wear.estimate:.3g} % ({escaped(bound)}){escaped(scale)}</li>")
    items += [f"<li>axis {axis}: {NOT_OBSERVABLE} (no wear: units.csv says why)</li>" for axis in unit.axes()
              if (w := unit.wear_now(axis)) is not None and not math.isfinite(w.estimate)]  # wear.csv's cells empty
    if items:
        source = "wear.csv" if unit.wear else "scores.csv"
        what = "; ".join(SCALES.get(s, s) for s in sorted(scales))
        parts.append(f"<p>Wear at the last log ({source}), {escaped(what)}:</p><ul>{''.join(items)}</ul>")
    return "\n".join(parts)
