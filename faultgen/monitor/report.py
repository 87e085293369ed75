"""The monitor's outputs: ``units.csv``, ``alarms.csv``, ``scores.csv``, ``wear.csv`` (each a
:class:`faultgen.monitor.record.Table` made from what the run holds, written from it and shown on the
page from it) and one control chart per unit.

Text cells that a spreadsheet would take for a formula (starting with ``=``, ``+``, ``-``, ``@``, a
tab or a carriage return: a unit folder named ``=HYPERLINK(...)``) are written with a leading
``'`` (OWASP, "CSV Injection", :mod:`faultgen.data.cells`, as every CSV faultgen writes); numbers
are written as numbers."""

from __future__ import annotations

import os
import threading

import numpy as np

from faultgen.figure_text import plain
from faultgen.monitor import scoring, steps
from faultgen.monitor.record import Table

#: ``first_alarm``: the first of the alarming logs the alarm started from; ``known``: the log on which it
#: became known (persistent), as a daily run sees it.
ALARM_COLUMNS = ("unit", "first_alarm", "known", "source_axis", "statistic", "limit", "evidence", "closed", "closed_by")
SCORE_COLUMNS = ("unit", "stamp", "phase", "Q", "Q_limit", "T2", "T2_limit", "alarm", "ranking")


UNIT_COLUMNS = ("unit", "status", "protocol", "model", "reason", "logs_scored", "last_log")
#: Longest text cell the monitor writes, characters (the fleet report reads none longer,
#: :data:`faultgen.monitor.tables.CELL_MAX_CHARS`): a longer text (a unit's reason gathers a note per
#: program change) is cut there, saying how many characters were left out.
CELL_MAX_CHARS = 4096


def _fmt(value) -> str:
    if isinstance(value, float):
        return f"{value:.6g}" if not np.isnan(value) else ""  # no number (an axis not observable): empty
    if not isinstance(value, str):
        return str(value)
    if len(value) > CELL_MAX_CHARS:
        cut = CELL_MAX_CHARS - 40
        value = f"{value[:cut]} ... ({len(value) - cut} more characters)"
    return value  # neutralised by faultgen.data.cells.writer


def units_table(statuses, scales: dict[str, str] | None = None) -> Table:
    """``units.csv``: one row per unit of the fleet folder (:class:`faultgen.monitor.loop.UnitStatus`): its
    status, the protocol and model its monitor uses, why (fallbacks, skipped logs, learning), the
    logs scored and the last one; with ``scales`` (a fleet with friction tests, or a unit whose twin
    fell back to the nominal model) also the scale of its wear, ``wear_scale`` (a unit not in it:
    ``twin``; :mod:`faultgen.monitor.friction_tests`); where a log format says which torque it read
    (``ur-rtde``), ``torque_source`` (:func:`faultgen.logs.formats.torque_source`); where a unit
    ran several programs, ``programs`` (its program mix: :func:`faultgen.monitor.programs.mix`)."""
    sources = any(getattr(s, "torque_source", "") for s in statuses)
    mixes = any(getattr(s, "programs", "") for s in statuses)  # a unit of several programs: each one's logs
    columns = (UNIT_COLUMNS + (("wear_scale",) if scales is not None else ()) + (("torque_source",) if sources else ())
               + (("programs",) if mixes else ()))
    rows = []
    for s in statuses:
        extra = [scales.get(s.unit, "twin")] if scales is not None else []
        extra += [s.torque_source] if sources else []
        extra += [s.programs] if mixes else []
        rows.append([_fmt(getattr(s, c)) for c in UNIT_COLUMNS] + extra)
    return Table("units.csv", columns, rows)


def alarms_table(units) -> Table:
    """``alarms.csv``: each unit's alarms (``units``: their records; :func:`faultgen.monitor.steps.alarm_rows`)."""
    return Table("alarms.csv", ALARM_COLUMNS, [[_fmt(row[c]) for c in ALARM_COLUMNS] for m in units
                                               for row in steps.alarm_rows(m)])


def scores_table(units, n_axes: int) -> Table:
    """``scores.csv``: every scored log's row (``units``: their records); with the twin also each axis's wear, % (``wearI``: filtered over the
    logs, :class:`faultgen.monitor.wear_trend.WearTrend`), its lower one-sided 90 % bound
    (``wearI_lower``, :data:`faultgen.monitor.scoring.WEAR_ALARM_CONFIDENCE`), what the alarm is judged
    on, and the log's own estimate (less the learned slope errors' part at its conditions,
    :meth:`faultgen.monitor.wear_trend.WearTrend.condition_part`) and its lower ``1 - alpha`` bound
    (``wearI_log``, ``wearI_log_lower``), what the remaining life is fitted on."""
    columns = SCORE_COLUMNS + tuple(f"score{i}" for i in range(1, n_axes + 1))
    if any(m.stages.baseline.signatures is not None for m in units):
        columns += tuple(f"wear{i}{end}" for end in ("", "_lower", "_log", "_log_lower") for i in range(1, n_axes + 1))
    rows = []
    for m in units:
        for row in m.rows:
            cells_ = score_cells(row)
            rows.append([_fmt(cells_.get(c, "")) for c in columns])
    return Table("scores.csv", columns, rows)


def score_cells(row) -> dict:
    """scores.csv's cells of a :class:`faultgen.monitor.record.LogRow`, by column name."""
    out = {"unit": row.unit, "stamp": row.stamp, "phase": row.phase, "Q": row.Q, "Q_limit": row.Q_limit, "T2": row.T2,
           "T2_limit": row.T2_limit, "alarm": row.alarm, "ranking": " ".join(str(a) for a in row.ranking),
           **{f"score{i + 1}": float(v) for i, v in enumerate(row.scores)}}
    if row.wear is not None:
        w = row.wear
        for end, values in (("", w.estimate), ("_lower", w.lower), ("_log", w.log), ("_log_lower", w.log_lower)):
            out.update({f"wear{i + 1}{end}": float(v) for i, v in enumerate(values)})
    return out


WEAR_COLUMNS = ("unit", "stamp", "phase", "axis", "wear", "wear_5", "wear_95", "wear_lower", "wear_log")
#: wear.csv's columns with friction tests (or a unit on the nominal model's scale).
SCALE_COLUMNS = ("wear_scale", "scale_factor", "scale_factor_sd")


def wear_table(units, scales: bool = False, nominal=frozenset()) -> Table:
    """``wear.csv``: per unit (``units``: their records), scored log and axis (1..N), the wear, % increase of the axis's dry
    friction in % of the unit's own (``wear``: filtered over the logs so far,
    :class:`faultgen.monitor.wear_trend.WearTrend`), its 90 % interval with the twin's model
    uncertainty (``wear_5``, ``wear_95``; :meth:`faultgen.monitor.wear.WearEstimator.wear_interval`),
    the lower one-sided 90 % bound the alarm is judged on, the filter's error and the scale's doubt
    together (``wear_lower``, as ``wearI_lower`` of scores.csv; :mod:`faultgen.monitor.bounds`) and the log's own estimate (``wear_log``). Only units with a twin
    have rows. With ``scales`` (a fleet with friction tests, or units in ``nominal``) also each
    row's ``wear_scale``: ``friction test``, ``twin``, or for a unit in ``nominal`` (its twin fell
    back to the nominal model) ``nominal model`` (:mod:`faultgen.monitor.friction_tests`), and on the
    tests' scale the factor that puts the twin's wear on it with its standard error (``scale_factor``,
    ``scale_factor_sd``; :class:`faultgen.monitor.friction_tests.Rescale`), else empty."""
    rows = []
    for m in units:
        for row in m.rows:
            w = row.wear
            if w is None:
                continue
            for k in range(m.stages.n_axes):
                default = "nominal model" if m.unit in nominal else "twin"
                t = w.tests
                extra = ([t.scale[k], *(_fmt(float(v[k])) for v in (t.factor, t.factor_error))]
                         if t is not None else [default, "", ""]) if scales else []
                rows.append([_fmt(row.unit), _fmt(row.stamp), row.phase, k + 1,
                             *(_fmt(float(v[k])) for v in (w.estimate, w.p5, w.p95, w.lower, w.log)), *extra])
    return Table("wear.csv", WEAR_COLUMNS + (SCALE_COLUMNS if scales else ()), rows)


def chart(path, unit, axis_note: str) -> None:
    """The control chart of ``unit`` (its record): T2 and Q over their limits per log, the persistent alarm, with the
    twin each axis's wear estimate with the limit its lower bound is judged against, and each
    axis's isolation score."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with plt.style.context("default"):  # whatever another library set globally (ProgPy sets fonts on import)
        _draw(path, unit, axis_note)


#: This thread's figures, by height (inches): one per chart size, cleared for each chart, so that its
#: canvas's renderer, with the text sizes and mathtext (the log axis's labels) it has laid out, serves
#: the next chart of that size (:func:`_figure`).
_FIGURES = threading.local()
#: The charts' resolution, dots per inch.
DPI = 90


def _forget_figures() -> None:
    """In a forked child (``--jobs``' workers, :mod:`faultgen.monitor.parallel`): no figure of the
    parent's. A figure the parent drew keeps, in its renderer's mathtext layouts, the parent's fonts
    (matplotlib's ``FT2Font``), which read the font file through a file offset the parent and every
    forked child share: two children drawing at once read each other's glyph bytes (``FT_Load_Glyph
    ... failed with error 0x16: too many hints``, or wrong pixels). matplotlib empties its own font
    cache at a fork for that reason (``matplotlib.font_manager``)."""
    global _FIGURES
    _FIGURES = threading.local()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_figures)


def _figure(height: float):
    """This thread's figure of 9 x ``height`` inches at :data:`DPI`, cleared, with constrained layout
    (matplotlib's Agg canvas; no pyplot figure). The same bytes as a new figure's: the chart's
    laying out and drawing set everything it depends on, and a renderer keeps only caches of the
    sizes of texts in a font (matplotlib's ``_get_text_metrics_with_cache``, the mathtext parser's)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figures = getattr(_FIGURES, "by_height", None)
    if figures is None:
        figures = _FIGURES.by_height = {}
    if height not in figures:
        figures[height] = Figure(figsize=(9, height), dpi=DPI)
        FigureCanvasAgg(figures[height])
    fig = figures[height]
    for ax in fig.axes:  # removed, not cleared first (Figure.clear clears each Axes it then removes)
        fig.delaxes(ax)
    fig.clear()
    fig.set_layout_engine("constrained")
    return fig


def _draw(path, unit, axis_note: str) -> None:
    rows, stages = unit.rows, unit.stages
    twin = bool(rows) and rows[0].wear is not None
    fig = _figure(8.5 if twin else 6)
    panels = fig.subplots(3 if twin else 2, 1, sharex=True)
    top, bottom = panels[0], panels[-1]
    if rows:
        x = np.arange(len(rows))
        for name, style in (("Q", "-"), ("T2", "--")):
            top.plot(x, [getattr(r, name) / getattr(r, f"{name}_limit") for r in rows], style, lw=1,
                     label=f"{name} / limit")
        top.axhline(1.0, color="k", lw=0.8, label="limit (alpha {:g})".format(stages.settings.alpha))
        training = sum(r.phase == "training" for r in rows)
        top.axvspan(-0.5, training - 0.5, color="0.9", label="learning (own first logs)")
        stamps = [r.stamp for r in rows]
        alarm = stages.alarm
        if alarm.first_alarm:
            k = stamps.index(alarm.first_alarm)
            for ax in panels:
                ax.axvline(k, color="r", lw=1.2)
            known = f" known {alarm.known}" if alarm.known and alarm.known != alarm.first_alarm else ""
            top.text(k, 1.0, plain(f" alarm {alarm.first_alarm}{known}, axis {alarm.source_axis}"), color="r",
                     va="bottom")
        top.set_yscale("log")
        if twin:
            middle = panels[1]
            nan = np.full(stages.n_axes, np.nan)
            wear = [(r.wear.estimate, r.wear.lower) if r.wear is not None else (nan, nan) for r in rows]
            for i in range(stages.n_axes):
                middle.plot(x, [w[0][i] for w in wear], lw=1, label=f"axis {i + 1}")
            best = [max((v for v in w[1] if np.isfinite(v)), default=np.nan) for w in wear]
            middle.plot(x, best, "k:", lw=1, label=f"largest lower {100 * scoring.WEAR_ALARM_CONFIDENCE:g} % bound")
            middle.axhline(stages.settings.wear_limit, color="k", lw=0.8, label="wear limit")
            middle.set_ylabel("wear estimate, % of own dry friction")
            middle.legend(fontsize=7, loc="upper left", ncol=4)
        scores = np.array([r.scores for r in rows])
        for i in range(stages.n_axes):
            bottom.plot(x, scores[:, i], lw=1, label=f"axis {i + 1}")
        step = max(1, len(rows) // 8)
        bottom.set_xticks(x[::step], [plain(s) for s in stamps[::step]], rotation=30, ha="right", fontsize=8)
    else:
        top.text(0.5, 0.5, "no log scored: see units.csv", ha="center", va="center", transform=top.transAxes)
    top.set_ylabel("statistic / its limit")
    protocol = "twin" if stages.baseline.signatures is not None else "own"
    top.set_title(plain(f"{unit.unit}: PCA monitor of the per-log features ({protocol} protocol)"))
    bottom.set_ylabel(f"isolation score ({axis_note if protocol == 'twin' else 'RBC of Q'})")
    if rows:
        top.legend(fontsize=7, loc="upper left")
        bottom.legend(fontsize=7, loc="upper left", ncol=3)
    # laid out here, then saved without a layout engine: savefig would otherwise draw the figure
    # twice, once without output to lay it out (the same positions, the same bytes)
    fig.get_layout_engine().execute(fig)
    fig.set_layout_engine("none")
    fig.savefig(path, format="png", dpi=DPI, metadata={"Software": None})
