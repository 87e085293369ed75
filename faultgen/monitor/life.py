"""The life each axis's gearbox has consumed by its load: ``OUT/life.csv``.

The gearbox makers' rated life, for a gear run at output speed ``n`` and output torque ``T``::

    L = L_n (n_N / n_av) (T_N / T_av)^p

(Harmonic Drive engineering data, "Life of the wave generator bearing": ``L50 = Ln (nN / n_av)
(TN / T_av)^3``; Nabtesco's RV catalogue, "Service life": the same form with ``p = 10/3``, as ISO 281
for roller bearings), ``L_n``, ``n_N``, ``T_N`` the rated life, speed and torque
(:mod:`faultgen.model.rating`), the averages over the duty

    n_av = sum |n_i| t_i / sum t_i,    T_av = (sum |n_i| t_i |T_i|^p / sum |n_i| t_i)^(1/p).

A duty of duration ``t`` consumes ``t / L`` of the rated life, which is, the sums written as
integrals over a log's samples (trapezoidal, ``numpy.trapezoid``),

    consumed = integral (|qd| / n_N) (|tau| / T_N)^p dt / L_n        (:func:`consumption`)

with ``qd`` (rad/s) and ``tau`` (N m) the log's arm-side speed and torque, the gear's output (a
``qd`` column logged motor-side, ``G`` times the joint's speed, is divided by the gear ratio ``G``
by the log's reader, :func:`faultgen.logs.measured.velocity_verdicts`, which notes it: without it
the consumption would be ``G`` times too high; a unit whose first log's torque is motor-side is not
monitored, :func:`faultgen.monitor.unit.refuse`). The reader's notes on an axis's columns end its
verdict (:func:`column_notes`). A standing axis consumes nothing (the bearings turn with the output). A
unit's state keeps each scored log's ``integral |qd| |tau|^p dt`` for both exponents
(:func:`load_integrals`), not its share, so each run judges the whole history against the ratings
the robot's ``drivetrain.toml`` gives now.

A log records minutes of a unit's operation, not all of it, so the monitor counts each log as the
unit's duty from the log before it up to it: the log's consumption per second of operation times
the operating seconds in between, ``hours_per_day`` (default :data:`HOURS_PER_DAY`, two shifts: an
assumption, written in every row) per calendar day of the stamps; sequence-number stamps count one
step as one day. Summed from the axis's last gearbox change in ``events.csv`` (``gearbox_change``
of that axis or of every axis: a ``repair`` leaves the gearbox's bearings, and their life, as they
were), else from the unit's first log (what ran before it is not known: the row says so). The
**duty** is the mean consumption per day over the last :data:`WINDOW` logs since then, and the
**days left** the time to 100 % at that duty. :func:`service_by` sets a unit's "service by" as the
earlier of that and the condition-based remaining life (``rul.csv``). Beyond :data:`HORIZON_DAYS`
(30 years) from the last log no days left and no date are given (the row says "not within 30
years"): a rated life read from defaults or a light duty cannot carry a date that far, and no page or
CSV shows one (:func:`date_after`). An axis without a rated torque
(:attr:`faultgen.model.rating.GearboxRating.unrated`: no catalogue size fits its load) gets no
consumption and no date: its row says why and how to give one.
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass
from datetime import datetime, timedelta, timezone
from functools import lru_cache

import numpy as np

from faultgen.data import cells, logfolder
from faultgen.logs import measured
from faultgen.model import rating
from faultgen.monitor.html_cells import number
from faultgen.monitor.record import Table

#: Operating hours per calendar day the consumption between logs assumes (two 8 h shifts).
HOURS_PER_DAY = 16.0
#: Logs whose mean consumption per day is the unit's recent duty.
WINDOW = 10
#: The farthest a load-based life or any service date is given, years and days from the last log.
HORIZON_YEARS = 30
HORIZON_DAYS = HORIZON_YEARS * 365.25
#: The life exponents a log's load is integrated with (:func:`load_integrals`): strain-wave, cycloid.
EXPONENTS = tuple(rating.EXPONENTS.values())
#: Events that fit a new gearbox (its consumption starts again at 0).
RESETS = ("gearbox_change",)
COLUMNS = ("unit", "axis", "gearbox_type", "exponent", "rated_torque_Nm", "rated_speed_rad_s", "rated_life_h",
           "defaults", "since", "consumed_pct", "duty_pct_per_day", "days_left", "hours_per_day", "logs", "stamp",
           "verdict")


@lru_cache(maxsize=4)
def ratings_of(robot) -> tuple[rating.GearboxRating, ...]:
    """:func:`faultgen.model.rating.of_robot`, once per robot and process."""
    return rating.of_robot(robot)


def _checked(t, qd, tau) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t, qd, tau = (np.asarray(a, dtype=float) for a in (t, qd, tau))
    if t.ndim != 1 or len(t) < 2 or qd.ndim != 2 or len(qd) != len(t) or tau.shape != qd.shape:
        raise ValueError(f"t {t.shape}, qd {qd.shape}, tau {tau.shape}; expected (n,), (n, N) and (n, N) with n >= 2")
    if not (np.all(np.isfinite(t)) and np.all(np.diff(t) > 0)):
        raise ValueError("t: expected finite sample times in s, strictly increasing")
    return t, qd, tau


def consumption(t, qd, tau, ratings) -> np.ndarray:
    """The share of each axis's rated life a log consumed (module docstring).

    Parameters
    ----------
    t : array of shape (n,)
        Sample times, s, strictly increasing (n >= 2).
    qd, tau : arrays of shape (n, N)
        Arm-side speed (rad/s) and torque (N m) of each axis.
    ratings : sequence of N :class:`faultgen.model.rating.GearboxRating`

    Returns
    -------
    ndarray of shape (N,)
        Fractions of the rated life (1 = all of it).

    Raises
    ------
    ValueError
        Shapes that do not match, or times not strictly increasing.
    """
    t, qd, tau = _checked(t, qd, tau)
    if len(ratings) != qd.shape[1]:
        raise ValueError(f"{len(ratings)} ratings for {qd.shape[1]} axes; expected one per axis")
    return consumed(load_integrals(t, qd, tau), ratings)


def load_integrals(t, qd, tau) -> np.ndarray:
    """``integral |qd| |tau|^p dt`` over a log for each exponent p of :data:`EXPONENTS` (rows) and
    each axis (columns), rad (N m)^p: what the rated life consumed needs of the log, whatever the
    rating (:func:`consumed`); each scored log's is kept in the unit's state.

    Returns
    -------
    ndarray of shape (len(EXPONENTS), N)

    Raises
    ------
    ValueError
        As :func:`consumption`.
    """
    t, qd, tau = _checked(t, qd, tau)
    speed, torque = np.abs(qd), np.abs(tau)
    return np.stack([np.trapezoid(speed * torque ** p, t, axis=0) for p in EXPONENTS])


def consumed(integrals: np.ndarray, ratings) -> np.ndarray:
    """The share of each axis's rated life of :func:`load_integrals` ``integrals`` (len(EXPONENTS),
    N): ``integral / (n_N T_N^p L_n)`` with each axis's rating's p, shape (N,)."""
    return np.array([integrals[EXPONENTS.index(r.exponent), k]
                     / (r.rated_speed * r.rated_torque ** r.exponent * r.rated_life * 3600.0)
                     for k, r in enumerate(ratings)])


def average_load(t, qd, tau, ratings) -> tuple[np.ndarray, np.ndarray]:
    """The catalogue's average output speed ``n_av`` (rad/s) and torque ``T_av`` (N m) of each axis
    over a log (module docstring; each shape (N,)): ``duration / L`` with ``L`` from them is
    :func:`consumption`."""
    t, qd, tau = _checked(t, qd, tau)
    speed = np.abs(qd)
    turned = np.trapezoid(speed, t, axis=0)
    p = np.array([r.exponent for r in ratings])
    n_av = turned / (t[-1] - t[0])
    with np.errstate(invalid="ignore", divide="ignore"):
        t_av = (np.trapezoid(speed * np.abs(tau) ** p, t, axis=0) / turned) ** (1 / p)
    return n_av, np.where(turned > 0, t_av, 0.0)


@dataclass
class LifeRow:
    """One unit's axis in ``life.csv`` (:data:`COLUMNS`): the rating, ``since`` (stamp of the
    gearbox change, or of the unit's first log), ``consumed`` %, ``duty`` % per day, ``days_left``
    (None without load) and the ``verdict`` in words."""

    unit: str
    axis: int
    rating: rating.GearboxRating
    since: str
    consumed: float
    duty: float
    days_left: float | None
    hours_per_day: float
    logs: int
    stamp: str
    verdict: str

    def cells(self) -> list:
        r = self.rating

        def known(x):  # no rating: empty cells, not nan
            return None if isinstance(x, float) and math.isnan(x) else x
        return [self.unit, self.axis, r.gearbox_type, r.exponent, known(r.rated_torque), r.rated_speed, r.rated_life,
                " ".join(r.defaults), self.since, known(self.consumed), known(self.duty), self.days_left,
                self.hours_per_day, self.logs, self.stamp, self.verdict]


def _key(stamp: str, unit: str) -> tuple[float, str]:
    return logfolder.parse_stamp(stamp, f"{unit}/{stamp}")


def check_hours(hours_per_day: float) -> None:
    """Raises ValueError unless ``hours_per_day`` is in (0, 24]."""
    if not (isinstance(hours_per_day, (int, float)) and math.isfinite(hours_per_day) and 0 < hours_per_day <= 24):
        raise ValueError(f"hours_per_day = {hours_per_day!r}; expected operating hours per calendar day in (0, 24]")


def of_unit(unit: str, entries, maintenance, ratings, hours_per_day: float = HOURS_PER_DAY,
            window: int = WINDOW, notes=()) -> list[LifeRow]:
    """Each axis's row of ``life.csv`` from a unit's scored logs (``entries``: each with ``stamp``,
    ``load`` of :func:`load_integrals` or None, ``duration`` s) and its ``maintenance``
    (``stamp``, ``event``, ``axis``, ``at``: the index of the first entry after it); module
    docstring. An entry without a load record (a state written before it) is left out, counted in
    the verdict. ``notes``: the unit's notes, whose notes of the log reader on an axis's columns
    (:func:`faultgen.monitor.logs.log_notes`) end that axis's verdict (:func:`column_notes`)."""
    check_hours(hours_per_day)
    rows = []
    for axis, r in enumerate(ratings, start=1):
        changes = [m for m in maintenance if m.event in RESETS and m.axis in (axis, 0)]
        start = changes[-1].at if changes else 0
        since = changes[-1].stamp if changes else (entries[0].stamp if entries else "")
        previous = _key(since, unit)[0] if changes else None
        total, rates, missing = 0.0, [], 0
        for e in entries[start:]:
            key, kind = _key(e.stamp, unit)
            day = 86400.0 if kind == logfolder.TIME else 1.0
            days = 0.0 if previous is None else max(key - previous, 0.0) / day
            previous = key
            if e.load is None:
                missing += 1
                continue
            share = float(consumed(e.load[:, axis - 1:axis], (r,))[0])
            per_day = share / e.duration * hours_per_day * 3600.0 * 100.0  # % per day
            total += per_day * days
            rates.append(per_day)
        if r.unrated:  # no rated torque: no consumption, no date
            rows.append(LifeRow(unit, axis, r, since, math.nan, math.nan, None, hours_per_day, len(rates),
                                entries[-1].stamp if entries else "", r.unrated))
            continue
        duty = float(np.mean(rates[-window:])) if rates else 0.0
        left = (100.0 - total) / duty if duty > 0 else None
        if left is not None and left > HORIZON_DAYS:
            left = None  # not within the horizon: no number, no date (module docstring)
        rows.append(LifeRow(unit, axis, r, since, total, duty, left, hours_per_day, len(rates),
                            entries[-1].stamp if entries else "", ""))
        rows[-1].verdict = _verdict(rows[-1], bool(changes), missing, window)
    for row in rows:
        row.verdict += column_notes(notes, row.axis)
    return rows


def column_notes(notes, axis: int) -> str:
    """What the log reader said of ``axis``'s speed and torque columns (the unit's ``notes`` of kind
    :data:`faultgen.monitor.history.COLUMN`, :func:`faultgen.monitor.logs.log_notes`: picked by
    their fields), as the end of its verdict: a speed column read motor-side as converted with the
    gear ratio before the load was counted, any other note as the reader's; "" without one."""
    out = []
    for note in notes:
        if note.column is None or note.column.axis != axis:
            continue
        if note.column.kind == measured.MOTOR_SIDE_SPEED:
            out.append(f"speeds joint side: column qd{axis} logged motor-side from log {note.log} on, divided "
                       f"by the gear ratio before its load was counted (the reader: {note.column})")
        else:
            out.append(f"the reader of log {note.log}: {note.column}; the load counted as logged")
    return "".join(f"; {text}" for text in out)


def _verdict(row: LifeRow, changed: bool, missing: int, window: int) -> str:
    r = row.rating
    default = ", default" if "rated_life" in r.defaults or "rated_torque" in r.defaults else ""
    origin = "the gearbox change" if changed else "the unit's first log: what ran before it is not known"
    text = (f"{row.consumed:.3g} % of the rated life ({r.rated_life:g} h L10 at {r.rated_torque:.5g} N m, "
            f"{r.gearbox_type}{default}) consumed since {row.since} ({origin})")
    left_out = f" ({missing} logs without a load record left out: a state written before it)" if missing else ""
    if not row.logs:
        return text + ": no log with a load record since" + left_out
    if row.days_left is None and row.duty > 0:
        text += (f"; at {row.duty:.3g} % per day ({row.hours_per_day:g} h of operation a day) 100 % not within "
                 f"{HORIZON_YEARS} years of the last log: no date given")
    elif row.days_left is None:
        text += "; no load in the last logs: no end of the rated life at this duty"
    elif row.days_left <= 0:
        text += f"; past the rated life (100 %), at {row.duty:.3g} % per day"
    else:
        text += (f"; at {row.duty:.3g} % per day (last {min(row.logs, window)} logs, {row.hours_per_day:g} h of "
                 f"operation a day) 100 % in {row.days_left:.0f} days")
    return text + left_out


def life_table(rows: list[LifeRow]) -> Table:
    """``life.csv``: one row per unit and axis (:data:`COLUMNS`; ``days_left`` empty without load;
    ``defaults`` the rating keys that are defaults, space separated)."""
    return Table("life.csv", COLUMNS, [[cells.figure(v) for v in row.cells()] for row in rows])


@dataclass(frozen=True)
class Service:
    """A unit's "service by" in days from its last log (:func:`service_window`): ``days`` the
    earliest source, ``low`` and ``high`` the earliest of the sources' 5 % and 95 % ends (a
    load-based life is one number, its own ends; ``math.inf`` beyond the horizon), ``why`` the
    source that sets ``days`` in words, ``axis`` its axis, ``basis`` that source's kind: "load" (the
    rated life) or "wear" (the condition-based remaining life)."""

    days: float
    low: float
    high: float
    why: str
    axis: int | None
    basis: str


def service_window(life_rows: list[dict], rul_rows: list[dict]) -> Service | None:
    """The earlier of the load-based days left (rows of life.csv, as read: text cells) and the
    condition-based remaining life (rows of rul.csv in days) **at its 5 % quantile** (``rul_5``: the
    day by which 5 % of the wear's paths have reached the failure wear, the wear's 95 % path: a
    planner who services then is late on 1 unit in 20, where a median is late on every other; issue
    90; the median where ``rul_5`` is empty; ``rul_5`` where the median is, "not yet predictable"
    with its 95 % end beyond the horizon, :mod:`faultgen.monitor.prognosis`), with its interval: each end the
    earliest of the sources' ends (the rated-life formula gives one number, so a load-based source
    is its own ends; a condition-based one its ``rul_5``, ``rul_95``, an empty ``rul_95`` beyond the
    horizon). The upper end so holds with at least the sources' 95 %: the minimum of the times is
    below it whenever the source that gives it is. None when no source gives a number."""
    found = []
    for r in life_rows:
        days = number(r.get("days_left"))
        if math.isfinite(days):
            days = max(days, 0.0)
            found.append((days, days, days, f"load: axis {r.get('axis')}'s rated life", r.get("axis"), "load"))
    for r in rul_rows:
        days, low, high = (number(r.get(k)) for k in ("rul", "rul_5", "rul_95"))
        ends = [v for v in (days, low) if math.isfinite(v)]  # rul_5 alone: the median not yet predictable
        if ends and r.get("time_unit") == "days":
            early, late = min(ends), max(ends + [high]) if math.isfinite(high) else math.inf
            found.append((early, early, late, f"condition: axis {r.get('axis')}'s wear"
                          + (", its 5 % quantile" if not early >= days else ""), r.get("axis"), "wear"))
    if not found:
        return None
    days, _, _, why, axis, basis = min(found, key=lambda f: f[0])
    axis = number(axis)
    return Service(days, min(f[1] for f in found), min(f[2] for f in found), why,
                   int(axis) if math.isfinite(axis) and axis == int(axis) else None, basis)


def date_after(last_stamp: str, days: float) -> str:
    """The day ``days`` after ``last_stamp``: an ISO date for date stamps, else "in N days" (a
    sequence step counts as a day); "not within 30 years" beyond :data:`HORIZON_DAYS`."""
    if not days <= HORIZON_DAYS:
        return f"not within {HORIZON_YEARS} years"
    try:
        key, kind = _key(last_stamp, "unit")
    except ValueError:
        kind = None
    if kind == logfolder.TIME and math.isfinite(days):
        try:
            return (datetime.fromtimestamp(key, timezone.utc) + timedelta(days=days)).date().isoformat()
        except (OverflowError, ValueError):  # beyond the calendar's year 9999
            pass
    return f"in {days:.0f} days"


def service_by(last_stamp: str, life_rows: list[dict], rul_rows: list[dict]) -> tuple[str, str]:
    """A unit's "service by" and what sets it: the earlier of the load-based days left (rows of
    life.csv, as read: text cells) and the condition-based remaining life (rows of rul.csv in days),
    counted from ``last_stamp``; a date for date stamps, else "in N days". ``("", "")`` when neither
    gives a number (:func:`service_window`)."""
    service = service_window(life_rows, rul_rows)
    if service is None:
        return "", ""
    return date_after(last_stamp, service.days), service.why


def table_cell(rows: list[dict]) -> str:
    """The fleet table's cell of a unit's rows of life.csv (as read): the axis that consumed most,
    its % and the days left at the recent duty ("past the rated life" at 0 or fewer, "no load"
    without a number)."""
    found = [(r, number(r.get("consumed_pct"))) for r in rows]
    found = [(r, c) for r, c in found if math.isfinite(c)]
    if not found:
        return ""
    r, consumed = max(found, key=lambda f: f[1])
    days = number(r.get("days_left"))
    duty = number(r.get("duty_pct_per_day"))
    left = ((f"not within {HORIZON_YEARS} years" if math.isfinite(duty) and duty > 0 else "no load")
            if not math.isfinite(days) else "past the rated life" if days <= 0 else f"{days:.0f} days left")
    return f"axis {r.get('axis')}: {consumed:.3g} % ({left})"


def service_by_html(last_stamp: str, life_rows: list[dict], rul_rows: list[dict]) -> str:
    """:func:`service_by` for the page: ``date (what sets it)``, HTML-escaped; "" without one."""
    date, why = service_by(last_stamp, life_rows, rul_rows)
    return f"{html.escape(date)} ({html.escape(why)})" if date else ""


def panel_html(life_rows: list[dict], service: str) -> str:
    """A unit's panel paragraph: every axis's verdict of life.csv and the ``service`` by (HTML)."""
    items = "".join(f"<li>axis {html.escape(r['axis'])}: {html.escape(r['verdict'])}</li>" for r in life_rows)
    return f"<p>Rated life consumed by load (life.csv); service by {service or '–'}:</p><ul>{items}</ul>"
