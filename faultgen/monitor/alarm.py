"""The alarm stage (:class:`AlarmRule`): a unit's alarm from its logs' alarming flags. A unit's alarm
is persistent from the first of ``persistence`` consecutive alarming logs (thesis ch. 3.4.1,
:func:`analysis.monitoring.detect_onset`), known on the last of them (``known`` in alarms.csv: the
log on which a daily run sees it); with the twin a log whose lower bound passes the limit by its own
width alarms at once (without it, a log whose T2 or Q passes its limit at ``alpha ** persistence``: as
unlikely in normal operation as ``persistence`` independent logs in a row past the ``alpha`` limits),
and an alarm under way when a repair or program change comes is closed by it, not forgotten. The
source axis of a persistent alarm is the first of the ranking of the mean residual over the logs
that made it persistent (the ranking: :mod:`faultgen.monitor.scoring`'s docstring)."""

from __future__ import annotations

from collections import deque
from statistics import NormalDist

import numpy as np

#: One-sided confidence with which the filtered wear must have reached ``wear_limit`` for a log to
#: alarm: its lower bound is the filtered wear less this normal quantile (1.28) of its standard
#: error (``wearI_lower`` in scores.csv). Before the slope errors were in the trend's state an unworn
#: axis's filtered wear drifted with the season by up to 14 points, and the bound had to be the
#: ``1 - alpha`` one (2.33 errors at alpha 0.01) for no healthy unit to alarm, which put the alarms
#: at 10.8-29.2 % true wear for a 10 % limit. Chosen on seeds 0 and 1 of the independent fleet's
#: first law (alarms in 10-15 % true wear on 14 of 16 worn units at 0.90, 14 at 0.69, 13 at 0.84,
#: 12 at 0.95, 10 at 0.99; no healthy unit alarming at any), checked on a held-out seed, the second
#: law and the KR210 L150 and iiwa 14 fleets (docs/analysis.md, "Wear in the robot's own scale").
WEAR_ALARM_CONFIDENCE = 0.90


def alarm_quantile() -> float:
    """The standard normal's :data:`WEAR_ALARM_CONFIDENCE` quantile: the lower bound of the
    filtered wear (``wearI_lower``), which the alarm is judged on, is the filtered wear minus this
    many standard errors."""
    return float(NormalDist().inv_cdf(WEAR_ALARM_CONFIDENCE))


class AlarmRule:
    """Unit ``unit``'s alarm under ``settings`` (``persistence``, ``wear_limit``, ``alpha``): its run of
    alarming logs (:attr:`run`, the last ``persistence`` in :attr:`window`), its open alarm
    (:attr:`first_alarm`, :attr:`known`, :attr:`source_axis`, :attr:`statistic`, :attr:`limit`,
    :attr:`evidence`) and the alarms closed by maintenance or a program change (:attr:`closed`)."""

    def __init__(self, unit: str, settings):
        self.unit, self.settings = unit, settings
        self.window: deque = deque(maxlen=settings.persistence)
        self.run = 0
        self.first_alarm: str | None = None
        #: The stamp of the log on which the open alarm became known (persistent), as a daily run sees it.
        self.known: str | None = None
        self.source_axis: int | None = None
        self.statistic = ""
        self.limit = float("nan")
        self.evidence = ""
        #: Alarms closed by a maintenance event, oldest first (rows of alarms.csv).
        self.closed: list[dict] = []

    def reset(self) -> None:
        """No run of alarming logs (after maintenance or a program change)."""
        self.run = 0
        self.window.clear()

    def step(self, baseline, stamp: str, z, t2: float, q: float, wear, alarm: bool, at_once: bool) -> None:
        """A monitoring log ``stamp`` (standardised residual ``z``, ``t2``, ``q``, its filtered ``wear``
        (estimate, the bound's error) or None) alarming or not (``alarm``; ``at_once``: its bound past the
        limit by its own width), on the program's ``baseline``: the alarm raised when it persists."""
        self.run = self.run + 1 if alarm else 0
        self.window.append((stamp, z, t2, q, wear))
        far = baseline.far_
        if self.first_alarm is None and self.run >= self.settings.persistence:
            self.raise_(baseline)
        elif self.first_alarm is None and alarm and (at_once or (far is not None and (t2 > far[0] or q > far[1]))):
            self.raise_(baseline, "at once: " + ("its lower bound above the limit by more than its own width" if at_once
                                                 else f"T2 or Q past its limit at alpha^{self.settings.persistence}"))

    def raise_(self, baseline, how: str = "") -> None:
        """The alarm of the last ``run`` monitoring logs (at most ``persistence``): from the first
        of them, known on the last; ``how`` says how it was raised when not by ``persistence`` logs."""
        stamps, Z, t2, q, wear = zip(*list(self.window)[-min(self.run, len(self.window)):])
        self.first_alarm, self.known = stamps[0], stamps[-1]
        span = f"mean of {len(stamps)} logs from {stamps[0]} to {stamps[-1]}" + (f"; {how}" if how else "")
        if wear[0] is not None:  # the twin: the wear estimate alarmed
            estimate = np.mean([w[0] for w in wear], axis=0)
            bound = np.mean([w[0] - alarm_quantile() * w[1] for w in wear], axis=0)
            order = np.argsort(-np.where(baseline.observable_, estimate, -np.inf), kind="stable")
            self.source_axis = int(order[0]) + 1
            self.statistic, self.limit = "wear", float(self.settings.wear_limit)
            self.evidence = (f"axis {self.source_axis} wear estimate {estimate[order[0]]:.3g} %, its lower "
                             f"{100 * WEAR_ALARM_CONFIDENCE:g} % bound {bound[order[0]]:.3g} % ({span}) >= limit "
                             f"{self.limit:g} % (% of the axis's own dry friction, weighted least squares of the friction "
                             f"torques along each axis's wear signature, filtered over the logs; the bound carries the scale's "
                             f"doubt and its reads' day-to-day scatter, {baseline.day_scatter_[order[0]]:.2g} points on its "
                             f"learning days); next axis {order[1] + 1}: {estimate[order[1]]:.3g} %")
            return
        mean = np.mean(Z, axis=0)
        scores = baseline.axis_scores(mean)
        order = np.argsort(-scores, kind="stable")
        self.source_axis = int(order[0]) + 1
        pca = baseline.pca
        q_ratio, t2_ratio = np.mean(q) / pca.q_limit_, np.mean(t2) / pca.t2_limit_
        self.statistic = "Q" if q_ratio >= t2_ratio else "T2"
        value = float(np.mean(q) if self.statistic == "Q" else np.mean(t2))
        self.limit = float(pca.q_limit_ if self.statistic == "Q" else pca.t2_limit_)
        self.evidence = (f"{self.statistic} {value:.3g} ({span}) > limit {self.limit:.3g} at alpha "
                         f"{self.settings.alpha:g}; axis {self.source_axis} first by reconstruction-based "
                         "contribution to Q "
                         f"({scores[order[0]]:.3g}; next axis {order[1] + 1}: {scores[order[1]]:.3g})")

    def close(self, baseline, stamp: str, by: str) -> None:
        """Close the open alarm by ``by`` (a maintenance event or a program change) at ``stamp``; an
        alarm under way, the wear's lower bound over the limit on the last logs but fewer than
        ``persistence`` of them, is raised as it stands first and closed with it: a unit whose
        bound crossed the limit before its gearbox change does not end without an alarm."""
        if self.first_alarm is None and self.run and self.window and self.window[-1][4] is not None:
            self.raise_(baseline, f"not yet persistent ({min(self.run, len(self.window))} of "
                        f"{self.settings.persistence} logs) when it was closed")
        if self.first_alarm is not None:
            self.closed.append({**self.open_alarm(), "closed": stamp, "closed_by": by})
            self.first_alarm, self.known, self.source_axis, self.statistic = None, None, None, ""
            self.limit, self.evidence = float("nan"), ""

    def open_alarm(self) -> dict:
        """The open alarm as a row of alarms.csv (without ``closed``, ``closed_by``)."""
        return {"unit": self.unit, "first_alarm": self.first_alarm or "", "known": self.known or "",
                "source_axis": "" if self.source_axis is None else self.source_axis,
                "statistic": self.statistic, "limit": "" if np.isnan(self.limit) else f"{self.limit:.6g}",
                "evidence": self.evidence}
