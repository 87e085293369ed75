"""Alarms timed as a daily run sees them, and no numbers where there is nothing to say (issue 72, items
4 and 5): the stamp an alarm became known on beside the one it started from, an alarm at once when the
wear's lower bound passes the limit by its own width, an alarm under way closed by a gearbox change,
an axis the program does not excite called not observable (no wear, trend or remaining life),
rul.csv's wear that of wear.csv, the chance statement only where it says something, and a program
change's relearning logs listed as such. On a unit's record (:func:`faultgen.monitor.steps.start`) fed
synthetic residuals along known wear signatures (each axis's friction torque only), the alarms
checked against a reading of its own rows that does not use its persistence logic."""

import csv
import io
import os
from statistics import NormalDist

import numpy as np
import pytest

from faultgen.monitor import lights, page, prognosis, report, steps
from faultgen.monitor.loop import UnitStatus
from faultgen.monitor.history import UnitHistory
from faultgen.monitor.scoring import FEATURES, NOT_OBSERVABLE, NOT_OBSERVABLE_LIMITS, WEAR_INTERVAL, Settings

N_AXES = 3
NOISE = 0.05  # feature noise (N m)
SETTINGS = Settings(train=20)


def _signatures(per_axis: np.ndarray) -> np.ndarray:
    """(n_axes, len(FEATURES) * n_axes): axis k's wear moves its own friction torque by per_axis[k] per %."""
    n = len(per_axis)
    signatures = np.zeros((n, len(FEATURES) * n))
    column = FEATURES.index("friction_torque") * n
    for k, s in enumerate(per_axis):
        signatures[k, column + k] = s
    return signatures


def _feed(unit: UnitHistory, wear: np.ndarray, rng, first: int = 0, stop=None, noise: float = NOISE) -> None:
    """Logs ``first``.. with true wear ``wear`` (n_logs, n_axes) %, stamps their index, features with
    ``noise``; ``stop(unit)`` True ends the feed after a log."""
    for i, w in enumerate(wear):
        steps.add(unit, f"{first + i:03d}", rng.normal(0, noise, unit.stages.baseline.signatures.shape[1]) + w @ unit.stages.baseline.signatures, 30.0, 0.0,
                 np.zeros(unit.stages.baseline.signatures.shape[1]))
        if stop is not None and stop(unit):
            return


def _ramp(n: int, axis: int, onset: int, rate: float) -> np.ndarray:
    wear = np.zeros((n, N_AXES))
    wear[:, axis - 1] = np.maximum(np.arange(n) - onset, 0) * rate
    return wear


def _monitoring(unit):
    return [r for r in unit.rows if r.phase == "monitoring"]


def _reference(rows, limit: float = SETTINGS.wear_limit, persistence: int = SETTINGS.persistence):
    """The alarm read off the monitoring rows alone: (first, known, at once) stamps, the first log
    that ends ``persistence`` logs whose largest lower bound reaches the limit, or one log whose
    lower bound passes it by its own width (the bound less the filtered wear's distance to it)."""
    run = 0
    for k, r in enumerate(rows):
        lower, wear = r.wear.lower, r.wear.estimate
        run = run + 1 if lower.max() >= limit else 0
        far = run and (2 * lower - wear).max() >= limit
        if run >= persistence or far:
            run = min(run, persistence)
            return rows[k - run + 1].stamp, r.stamp, bool(far and run < persistence)
    return None, None, False


def test_the_alarm_is_known_on_the_fifth_alarming_log_and_starts_from_the_first():
    """A slow ramp (0.1 % per log) read with 3 points of error a log: the bound crosses the limit
    long before it passes it by its own width, so persistence makes the alarm."""
    rng = np.random.default_rng(1)
    unit = steps.start("u", SETTINGS, N_AXES, _signatures(np.full(N_AXES, 0.05)))
    _feed(unit, _ramp(200, 2, 35, 0.1), rng, noise=0.15)
    first, known, at_once = _reference(_monitoring(unit))
    assert (unit.stages.alarm.first_alarm, unit.stages.alarm.known, at_once) == (first, known, False)
    stamps = [r.stamp for r in unit.rows]
    assert stamps.index(known) - stamps.index(first) == SETTINGS.persistence - 1
    row = steps.alarm_row(unit)
    assert (row["first_alarm"], row["known"], row["source_axis"]) == (first, known, 2)
    assert lights.alarm_dates(row) == f"known {known} (from {first})"


def test_a_lower_bound_past_the_limit_by_its_own_width_alarms_at_once():
    rng = np.random.default_rng(2)
    unit = steps.start("u", SETTINGS, N_AXES, _signatures(np.full(N_AXES, 0.05)))
    wear = np.zeros((60, N_AXES))
    wear[40:, 0] = np.linspace(40.0, 60.0, 20)  # a gearbox damaged at once
    _feed(unit, wear, rng)
    first, known, at_once = _reference(_monitoring(unit))
    assert (unit.stages.alarm.first_alarm, unit.stages.alarm.known, at_once, unit.stages.alarm.source_axis) == (first, known, True, 1)
    stamps = [r.stamp for r in unit.rows]
    assert "040" <= first and stamps.index(known) - stamps.index(first) < SETTINGS.persistence - 1
    assert "at once" in unit.stages.alarm.evidence


def test_an_alarm_under_way_at_a_gearbox_change_is_closed_by_it_not_forgotten():
    rng = np.random.default_rng(3)
    unit = steps.start("u", SETTINGS, N_AXES, _signatures(np.full(N_AXES, 0.05)))
    wear = _ramp(200, 3, 35, 0.1)

    def two_alarming(u):
        return len(u.rows) >= 2 and u.rows[-1].alarm and u.rows[-2].alarm and u.rows[-1].phase == "monitoring"

    _feed(unit, wear, rng, stop=two_alarming, noise=0.15)
    assert unit.stages.alarm.first_alarm is None and unit.stages.alarm.run == 2
    first, last = unit.rows[-2].stamp, unit.rows[-1].stamp
    change = f"{len(unit.rows):03d}"
    steps.maintenance(unit, change, "gearbox change", 3)
    closed, current = steps.alarm_rows(unit)
    assert (closed["first_alarm"], closed["known"], closed["source_axis"]) == (first, last, 3)
    assert closed["closed"] == change and closed["closed_by"] == "gearbox change of axis 3"
    assert f"not yet persistent (2 of {SETTINGS.persistence} logs)" in closed["evidence"]
    assert current["first_alarm"] == "" and current["evidence"].startswith(
        f"no persistent alarm since the gearbox change of axis 3 of {change}"), current
    _feed(unit, np.zeros((8, N_AXES)), rng, first=len(unit.rows))
    assert "(8 logs since" in steps.alarm_row(unit)["evidence"]


def test_an_axis_the_program_does_not_excite_is_not_observable_and_gets_no_numbers(tmp_path):
    """Axis 2's signature is 1/50 of the others': one log's 90 % interval of its wear is about
    2 x 1.645 x noise / signature wide (the weighted least squares' standard error of one feature),
    110 points against 2 for the others; the rule's threshold is 6 wear limits (60 points)."""
    rng = np.random.default_rng(4)
    per_axis = np.array([0.08, 0.0015, 0.08])
    unit = steps.start("u", SETTINGS, N_AXES, _signatures(per_axis))
    wear = np.zeros((50, N_AXES))
    wear[30:, 1] = 300.0  # even a huge change along it: the noise's, not wear the logs can tell
    _feed(unit, wear, rng)
    z = NormalDist().inv_cdf(0.5 + WEAR_INTERVAL / 2)
    np.testing.assert_allclose(unit.stages.baseline.width_, 2 * z * NOISE / per_axis, rtol=0.35)
    assert unit.stages.baseline.observable_.tolist() == [True, False, True]
    assert unit.stages.baseline.width_[1] > NOT_OBSERVABLE_LIMITS * SETTINGS.wear_limit > unit.stages.baseline.width_[0]
    assert all(np.isnan(r.wear.estimate[1]) and np.isnan(r.wear.log[1]) and np.isfinite(r.wear.estimate[0])
               for r in unit.rows)
    assert not any(r.alarm for r in unit.rows) and unit.stages.alarm.first_alarm is None
    assert "axis 2 " + NOT_OBSERVABLE in steps.not_observable_note(unit.stages)
    report.wear_table([unit]).write(tmp_path)
    report.scores_table([unit], N_AXES).write(tmp_path)
    wear_rows = list(csv.DictReader(open(tmp_path / "wear.csv")))
    assert {r["wear"] for r in wear_rows if r["axis"] == "2"} == {""}
    assert all(r["wear"] for r in wear_rows if r["axis"] != "2")
    assert {r["wear2"] for r in csv.DictReader(open(tmp_path / "scores.csv"))} == {""}
    rul = prognosis.of_monitor(unit, samples=50)
    assert rul[1].verdict.startswith(NOT_OBSERVABLE) and rul[1].wear is None and rul[1].rul is None
    assert not rul[0].verdict.startswith(NOT_OBSERVABLE)
    report.chart(io.BytesIO(), unit, "wear signature match")  # an axis without wear drawn as none
    # the page: the axis named as such in the unit's panel, no wear number for it
    report.alarms_table([unit]).write(tmp_path)
    report.units_table([UnitStatus("u", "monitored", "twin", "nominal", steps.not_observable_note(unit.stages), 50,
                                   "049")]).write(tmp_path)
    html = page.build(page.read(tmp_path), {})
    assert f"<li>axis 2: {NOT_OBSERVABLE} (no wear" in html and "<li>axis 1: " in html


def test_rul_csv_wear_is_wear_csv_wear(tmp_path):
    rng = np.random.default_rng(5)
    unit = steps.start("u", SETTINGS, N_AXES, _signatures(np.full(N_AXES, 0.05)))
    _feed(unit, _ramp(70, 1, 30, 0.8), rng)
    report.wear_table([unit]).write(tmp_path)
    prognosis.rul_table(prognosis.of_monitor(unit, samples=100)).write(tmp_path)
    last = {r["axis"]: r["wear"] for r in csv.DictReader(open(tmp_path / "wear.csv")) if r["stamp"] == "069"}
    rul = {r["axis"]: r["wear"] for r in csv.DictReader(open(tmp_path / "rul.csv"))}
    assert rul == last and len(rul) == N_AXES


def test_the_chance_statement_only_where_it_says_something():
    # the twin, 6 axes: a log alarms with chance <= 0.6, five in a row <= 0.078: over 42 logs the bound is > 1
    assert page.false_alarm_statement("twin", 0.01, 5, 28, 6, 42) == ""
    # own: <= 0.02 per log, 5 in a row, or one past T2 or Q at alpha^5; 42 logs
    text = page.false_alarm_statement("own", 0.01, 5, 28, 6, 42)
    assert f"<= {42 * (0.02**5 + 2 * 0.01**5):.2g} " in text  # or one log past the limits at 0.01^5
    # the twin, one axis: <= 0.1 per log, or one at once at <= 1 - Phi(2 x 1.2816)
    once = 1 - NormalDist().cdf(2 * NormalDist().inv_cdf(0.9))
    text = page.false_alarm_statement("twin", 0.01, 5, 28, 1, 42)
    assert f"<= {42 * (0.1**5 + once):.2g} " in text and f"at <= {once:.2g}" in text


@pytest.mark.parametrize("known", [True, False])
def test_the_page_says_when_the_alarm_was_known_and_reads_a_folder_without_it(tmp_path, known):
    rng = np.random.default_rng(1)
    unit = steps.start("u", SETTINGS, N_AXES, _signatures(np.full(N_AXES, 0.05)))
    _feed(unit, _ramp(200, 2, 35, 0.1), rng, noise=0.15)
    report.alarms_table([unit]).write(tmp_path)
    report.scores_table([unit], N_AXES).write(tmp_path)
    report.units_table([UnitStatus("u", "monitored", "twin", "nominal", "", 200, "199")]).write(tmp_path)
    if not known:  # an output folder written before the column
        rows = list(csv.DictReader(open(tmp_path / "alarms.csv")))
        with open(tmp_path / "alarms.csv", "w", newline="") as f:
            writer = csv.DictWriter(f, [c for c in report.ALARM_COLUMNS if c != "known"], extrasaction="ignore")
            writer.writeheader()
            writer.writerows(rows)
    html = page.build(page.read(tmp_path), {"protocol": "twin", "alpha": 0.01, "persistence": 5, "train": 20})
    when = f"known {unit.stages.alarm.known} (from {unit.stages.alarm.first_alarm})" if known else f"from {unit.stages.alarm.first_alarm}"
    assert f"<b>Open alarm</b> {when} on axis 2" in html
    assert f"open alarm {when} on axis 2" in html  # the light's rule
    assert "1 of 1 units alarm.</p>" in html  # the chance statement says nothing here: left out



def test_forked_workers_draw_on_figures_of_their_own():
    """``--jobs``' forked workers (:mod:`faultgen.monitor.parallel`) draw charts at the same time in a
    process that has drawn some: each draws on a figure of its own and gives the parent's bytes.
    Until 2026-11-28 a worker drew on the parent's figure, whose mathtext layouts kept fonts reading
    the font file through a file offset all the workers share: side by side they read each other's
    glyph bytes, and a CI run failed with ``FT_Load_Glyph ... too many hints``
    (:func:`faultgen.monitor.report._forget_figures`). The race itself is rare (a script of two
    forked children drawing a log axis 40 times each: 2 bad draws in each), so the test asserts its
    cause: the parent's figure in the child."""
    rng = np.random.default_rng(7)
    unit = steps.start("u", SETTINGS, N_AXES, _signatures(np.full(N_AXES, 0.05)))
    _feed(unit, _ramp(40, 1, 25, 0.8), rng)

    def png() -> bytes:
        buffer = io.BytesIO()
        report.chart(buffer, unit, "wear signature match")
        return buffer.getvalue()

    expected = png()  # drawn on this process's figure, its log axis's mathtext laid out
    parents = list(report._FIGURES.by_height.values())
    pid = os.fork()
    if pid == 0:  # the child exits with 1 if it drew other bytes, + 2 if on a figure of the parent's
        try:
            drawn = png()
            figures = report._FIGURES.by_height.values()
            os._exit((drawn != expected) + 2 * any(f is p for f in figures for p in parents))
        finally:
            os._exit(4)
    assert os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1]) == 0
